"""`bg-sim fmu`: FMUs of bg-sim models checked with FMPy (issue 21, docs/fmu.md).

The FMUs are written by `target/debug/bg-sim fmu` with the engine `target/debug/libbg_fmu.so`
(`.ci/run` builds both before the Python part). FMPy validates them (FMI 2.0 and 3.0) and
simulates them; the results must equal `bg-sim run` of the same model and data.
"""

import os
import shutil
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy.validation import validate_fmu  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]
BG_SIM = ROOT / "target" / "debug" / "bg-sim"
LIBRARY = ROOT / "target" / "debug" / "libbg_fmu.so"

# skipped outside CI only: .ci/run (CI=true) must never skip them
pytestmark = pytest.mark.skipif(
    not (BG_SIM.is_file() and LIBRARY.is_file()) and not os.environ.get("CI"),
    reason="needs `cargo build -p bg-sim -p bg-fmu` (.ci/run builds them)",
)


def export(model, out, *extra):
    """`bg-sim fmu MODEL -o OUT EXTRA…`; returns the FMU's path."""
    subprocess.run(
        [str(BG_SIM), "fmu", str(ROOT / model), "-o", str(out), *extra],
        check=True,
        capture_output=True,
        text=True,
    )
    return str(out)


def run_csv(model, out, *extra):
    """`bg-sim run MODEL -o OUT EXTRA…` read back as a structured array."""
    subprocess.run(
        [str(BG_SIM), "run", str(ROOT / model), "-o", str(out), *extra],
        check=True,
        capture_output=True,
        text=True,
    )
    return np.genfromtxt(out, delimiter=",", names=True)


def worst_scaled_error(result, reference, columns):
    """max over columns of max|result − reference| / max(range, |mean|) of the reference."""
    worst = (0.0, None)
    for c in columns:
        ref = reference[c]
        scale = max(np.ptp(ref), abs(np.mean(ref)))
        err = np.max(np.abs(result[c] - ref))
        e = err / scale if scale > 0 else err
        if e > worst[0]:
            worst = (e, c)
    return worst


@pytest.mark.parametrize("fmi", ["2", "3"])
def test_fmpy_validates_and_dumps(tmp_path, fmi, capsys):
    fmu = export("models/msd_force.toml", tmp_path / "msd.fmu", "--fmi", fmi)
    assert validate_fmu(fmu) == []
    md = fmpy.read_model_description(fmu)
    assert md.fmiVersion == ("2.0" if fmi == "2" else "3.0")
    assert md.coSimulation is not None and md.modelExchange is None
    v = {x.name: x for x in md.modelVariables}
    assert v["F"].causality == "input" and float(v["F"].start) == 0.0
    assert v["F"].unit == "N"
    assert v["x"].causality == "output" and v["v"].causality == "output"
    assert v["k"].causality == "parameter" and float(v["k"].start) == 100.0
    assert md.defaultExperiment.stopTime == "20.0" or float(md.defaultExperiment.stopTime) == 20.0
    fmpy.dump(fmu)
    assert "Co-Simulation" in capsys.readouterr().out


@pytest.mark.parametrize("fmi", ["2", "3"])
def test_msd_input_step_matches_the_csv_driven_run(tmp_path, fmi):
    # the 10 N step at t = 1 s of data/msd_force_step.csv, held (zero-order hold)
    ref = run_csv(
        "models/msd_force.toml",
        tmp_path / "run.csv",
        "--inputs",
        str(ROOT / "data" / "msd_force_step.csv"),
        "--inputs-interp",
        "hold",
    )
    fmu = export("models/msd_force.toml", tmp_path / "msd.fmu", "--fmi", fmi)
    # FMPy's input: a repeated time is a jump (the value after it holds from there)
    signal = np.array(
        [(0.0, 0.0), (1.0, 0.0), (1.0, 10.0), (20.0, 10.0)],
        dtype=[("time", np.float64), ("F", np.float64)],
    )
    res = fmpy.simulate_fmu(
        fmu, stop_time=20.0, output_interval=0.01, input=signal, output=["x", "v", "F"]
    )
    assert len(res) == len(ref)
    np.testing.assert_allclose(res["time"], ref["t"], rtol=0, atol=1e-12)
    e, col = worst_scaled_error(res, ref, ["x", "v"])
    assert e < 1e-6, f"{col}: scaled error {e:.3e}"
    # F is the input as last set: FMPy sets 10 N at the communication point t = 1 s, after
    # recording the row of t = 1 s (the run's CSV has the value from t = 1 s on)
    jump = np.abs(res["time"] - 1.0) < 1e-9
    assert res["F"][jump][0] == 0.0 and ref["F"][jump][0] == 10.0
    np.testing.assert_allclose(res["F"][~jump], ref["F"][~jump], rtol=0, atol=1e-12)
    # it did respond: the static deflection F/k = 0.1 m at the end
    assert abs(res["x"][-1] - 0.1) < 1e-4


def test_crane_matches_bg_sim_run(tmp_path):
    ref = run_csv("models/knuckle_boom.toml", tmp_path / "run.csv")
    fmu = export("models/knuckle_boom.toml", tmp_path / "crane.fmu")
    assert validate_fmu(fmu) == []
    res = fmpy.simulate_fmu(fmu, stop_time=20.0, output_interval=0.01)
    assert len(res) == len(ref) == 2001
    columns = [c for c in ref.dtype.names if c != "t"]
    assert set(columns) <= set(res.dtype.names)
    e, col = worst_scaled_error(res, ref, columns)
    assert e < 1e-4, f"{col}: scaled error {e:.3e}"


def test_parameter_start_value_reloads_the_model(tmp_path):
    fmu = export("models/msd_force.toml", tmp_path / "msd.fmu")
    # the model's own step of F_step newtons at t = 1 s, set as a parameter
    res = fmpy.simulate_fmu(fmu, stop_time=20.0, output_interval=0.01, start_values={"F_step": 10.0})
    ref = run_csv("models/msd_force.toml", tmp_path / "run.csv", "--set", "parameters.F_step=10")
    e, col = worst_scaled_error(res, ref, ["x", "v"])
    assert e < 1e-6, f"{col}: scaled error {e:.3e}"


def broken_fmu(tmp_path, fmi):
    """An FMU whose model has an unknown element kind (`Cx`) in resources/."""
    good = export("models/msd_force.toml", tmp_path / "good.fmu", "--fmi", fmi)
    bad = tmp_path / "broken.fmu"
    with zipfile.ZipFile(good) as zin, zipfile.ZipFile(bad, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "resources/msd_force.toml":
                data = data.replace(b'kind = "C", k = "k"', b'kind = "Cx", k = "k"')
                assert b'"Cx"' in data
            zout.writestr(item, data)
    return str(bad)


@pytest.mark.parametrize("fmi", ["2", "3"])
def test_broken_model_gives_an_error_status_and_a_logged_message(tmp_path, fmi):
    fmu = broken_fmu(tmp_path, fmi)
    messages = []
    if fmi == "2":
        def logger(env, name, status, category, message):
            messages.append((status, message.decode()))
    else:
        def logger(env, status, category, message):
            messages.append((status, message.decode()))
    with pytest.raises(Exception, match="(?i)instantiat"):
        fmpy.simulate_fmu(fmu, stop_time=1.0, logger=logger)
    assert messages, "nothing was logged"
    status, text = messages[-1]
    assert status == 3  # fmi2Error / fmi3Error
    # the file, the line of the element, and the hint of the loader's message
    assert "msd_force.toml:" in text
    assert ":28:" in text or "line" in text
    assert "Cx" in text and "hint" in text


def test_two_instances_in_one_process_are_independent(tmp_path):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    fmu = export("models/msd_force.toml", tmp_path / "msd.fmu")
    md = read_model_description(fmu)
    unzipdir = extract(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    a, b = (
        FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName=n)
        for n in ("a", "b")
    )
    for s in (a, b):
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
    a.setReal([vr["F"]], [10.0])
    t = 0.0
    for _ in range(200):
        a.doStep(t, 0.01)
        b.doStep(t, 0.01)
        t += 0.01
    xa, xb = a.getReal([vr["x"]])[0], b.getReal([vr["x"]])[0]
    assert abs(xa) > 1e-2 and xb == 0.0
    for s in (a, b):
        s.terminate()
        s.freeInstance()
    shutil.rmtree(unzipdir, ignore_errors=True)


def test_the_snippet_of_docs_fmu_md_runs(tmp_path, monkeypatch):
    text = (ROOT / "docs" / "fmu.md").read_text()
    blocks = text.split("```python\n")[1:]
    assert len(blocks) == 1, "docs/fmu.md has one Python snippet"
    code = blocks[0].split("```")[0]
    export("models/msd_force.toml", tmp_path / "msd_force.fmu")
    monkeypatch.chdir(tmp_path)
    ns = {}
    exec(compile(code, "docs/fmu.md", "exec"), ns)
    # the 10 N step ends at the static deflection F/k = 0.1 m, whatever the damper
    assert abs(ns["result"]["x"][-1] - 0.1) < 1e-4


def test_bad_input_to_bg_sim_fmu_exits_2_with_file_line_and_hint(tmp_path):
    def fmu(*args):
        return subprocess.run([str(BG_SIM), "fmu", *args], capture_output=True, text=True)

    broken = tmp_path / "broken.toml"
    broken.write_text(
        (ROOT / "models" / "msd_force.toml").read_text().replace('kind = "C", k = "k"', 'kind = "Cx", k = "k"')
    )
    r = fmu(str(broken), "-o", str(tmp_path / "b.fmu"))
    assert r.returncode == 2
    assert "broken.toml:28:" in r.stderr and "hint:" in r.stderr
    assert not (tmp_path / "b.fmu").exists()
    model = str(ROOT / "models" / "msd_force.toml")
    r = fmu(model, "-o", str(tmp_path / "x.fmu"), "--fmi", "4")
    assert r.returncode == 2 and "--fmi 2 or --fmi 3" in r.stderr
    r = fmu(model, "-o", str(tmp_path / "x.fmu"), "--library", str(tmp_path / "none.so"))
    assert r.returncode == 2 and "cargo build -p bg-fmu" in r.stderr
    r = fmu(model, "-o", str(tmp_path / "no" / "dir" / "x.fmu"))
    assert r.returncode == 1 and "cannot write" in r.stderr
