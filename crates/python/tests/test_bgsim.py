"""The Python package against the closed form of the mass-spring-damper, its errors, the
local sweep and a Dask LocalCluster with two worker processes."""

import math
from pathlib import Path

import numpy as np
import pytest

import bgsim

MODELS = Path(__file__).resolve().parents[3] / "models"
MSD = MODELS / "mass_spring_damper.toml"


def closed_form(t, k=10.0, c=0.5, m=1.0, x0=0.01):
    wn = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    wd = wn * math.sqrt(1 - zeta**2)
    return x0 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t))


def test_run_returns_a_dataframe_matching_the_closed_form():
    model = bgsim.load(MSD, set={"k": 20.0})
    assert model.parameters["k"] == 20.0
    assert model.columns == ["t", "x", "v", "F_spring"]
    df = model.run(t_end=2.0)
    assert list(df.columns) == model.columns
    assert df["t"].iloc[-1] == pytest.approx(2.0, abs=1e-12)
    # the model's rtol 1e-8, atol 1e-12: 1e-8 m is 1e-6 of the amplitude
    err = np.abs(df["x"].to_numpy() - closed_form(df["t"].to_numpy(), k=20.0))
    assert err.max() < 1e-8
    assert df.attrs["stats"]["steps"] > 0
    assert df.attrs["stats"]["failed_checks"] == []
    arrays = model.run(t_end=1.0, as_dict=True)
    assert isinstance(arrays["x"], np.ndarray) and arrays["t"][-1] == pytest.approx(1.0)


def test_errors_are_exceptions_with_file_line_element_and_hint():
    with pytest.raises(bgsim.BgSimError) as e:
        bgsim.load(MSD, set={"elements.mass.m": -1.0})
    assert e.value.file.endswith("mass_spring_damper.toml")
    assert e.value.element == "mass"
    assert e.value.line == 21
    assert e.value.hint.startswith("fix `m` of `mass`")
    assert "must be > 0" in str(e.value)
    with pytest.raises(bgsim.BgSimError) as e:
        bgsim.load(MODELS / "no_such_model.toml")
    assert "no_such_model.toml" in str(e.value)


def write_spec(tmp_path):
    spec = tmp_path / "sweep.toml"
    spec.write_text(
        '[parameters]\nk = [5.0, 20.0]\nc = [0.2, 0.8]\nm = [1.0, -1.0]\n'
        '[metrics]\nt_half = "first_crossing(v, 0)"\n'
    )
    return spec


def check_rows(df):
    """Every valid row's first zero of v is π/ωd (1e-4 relative: linear interpolation
    between rows 0.01 s apart); every m = -1 row is an error row."""
    assert len(df) == 8
    for _, r in df.iterrows():
        k, c, m = r["parameters.k"], r["parameters.c"], r["parameters.m"]
        if m < 0:
            assert r["status"] == "error" and "`wn` is NaN" in r["error"], r["error"]
            continue
        assert r["status"] == "ok", r["error"]
        wn = math.sqrt(k / m)
        zeta = c / (2 * math.sqrt(k * m))
        wd = wn * math.sqrt(1 - zeta**2)
        assert r["t_half"] == pytest.approx(math.pi / wd, rel=1e-4)


def test_local_sweep_returns_the_summary(tmp_path):
    spec = write_spec(tmp_path)
    df = bgsim.sweep(MSD, spec, out_dir=tmp_path / "out", jobs=2)
    check_rows(df)
    assert df.attrs["sweep"]["ok"] == 4
    again = bgsim.sweep(MSD, spec, out_dir=tmp_path / "out", jobs=2)
    assert again.attrs["sweep"]["skipped"] == 8


def test_dask_sweep_on_a_local_cluster_with_two_workers(tmp_path):
    distributed = pytest.importorskip("distributed")
    spec = write_spec(tmp_path)
    with distributed.LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        df = bgsim.dask_sweep(client, MSD, spec)
        # the work went to both workers' processes
        assert len(client.scheduler_info()["workers"]) == 2
    check_rows(df)
    assert list(df["index"]) == list(range(8))


def test_the_python_blocks_of_docs_sweeps_run(tmp_path, monkeypatch):
    """docs/sweeps.md's examples, run as written (the crane, its 55-run sweep, Dask)."""
    root = MODELS.parent
    pytest.importorskip("distributed")
    text = (root / "docs" / "sweeps.md").read_text()
    blocks = [b.split("```", 1)[0] for b in text.split("```python\n")[1:]]
    assert len(blocks) == 2
    # relative paths as in the doc, the outputs in a temporary folder
    for name in ("models", "docs"):
        (tmp_path / name).symlink_to(root / name)
    monkeypatch.chdir(tmp_path)
    scope: dict = {}
    for b in blocks:
        exec(compile(b, "docs/sweeps.md", "exec"), scope)
    assert scope["summary"].attrs["sweep"]["total"] == 55
    assert len(scope["df"]) == 55
    # the Dask rows and the local ones agree run by run
    local = scope["summary"].set_index("run")
    for _, r in scope["df"].iterrows():
        if r["status"] in ("ok", "check-failed"):
            assert r["F_c1_max"] == pytest.approx(local.loc[r["run"], "F_c1_max"], rel=1e-12)


def test_a_run_that_stops_early_raises_with_its_partial_rows():
    # l_d = 6.5 m drives cylinder 1's piston past its 2.7 m stroke at about t = 5 s
    crane = bgsim.load(MODELS / "knuckle_boom.toml", set={"m3": 2000.0, "l_d": 6.5})
    with pytest.raises(bgsim.RunError) as e:
        crane.run()
    assert "upper limit 2.7" in str(e.value)
    partial = e.value.partial
    assert 4.0 < partial["t"].iloc[-1] < 6.0
    assert isinstance(e.value, bgsim.BgSimError)


def test_run_energy_is_the_audit_as_a_dataframe():
    # docs/energy.md: no source, so what the damper dissipates is what the spring and the
    # mass lost
    df = bgsim.load(MSD, set={"simulation.solver": "radau5"}).run(energy=True)
    e = df.energy()
    assert set(e.index) == {"spring", "mass", "damper"}
    assert set(e.columns) >= {"kind", "role", "supplied", "stored", "dissipated", "activity", "share"}
    lost = -(e.loc["spring", "stored"] + e.loc["mass", "stored"])
    assert e.loc["damper", "dissipated"] == pytest.approx(lost, rel=1e-8)
    assert e.loc["damper", "role"] == "dissipation"
    assert e["share"].sum() == pytest.approx(1.0, abs=1e-12)
    totals = df.energy_totals()
    assert totals["relative_residual"] < 1e-8
    assert totals["stored_initial"] == pytest.approx(0.5 * 10.0 * 0.01**2, rel=1e-12)
    # every element, the junction too
    assert "v" in df.energy(expand=True).index
    # a run that was not audited says so
    with pytest.raises(bgsim.BgSimError, match="energy=True"):
        bgsim.load(MSD).run(t_end=0.1).energy()


def test_a_sweep_metric_can_be_an_energy():
    # more damping, more of the initial ½k·x0² dissipated by t_end
    rows = [
        bgsim._run_one(str(MSD), {"c": c}, {"loss": "energy.damper.dissipated", "x_max": "max(x)"}, i)
        for i, c in enumerate([0.2, 2.0])
    ]
    assert [r["status"] for r in rows] == ["ok", "ok"]
    e0 = 0.5 * 10.0 * 0.01**2
    assert 0.0 < rows[0]["loss"] < rows[1]["loss"] <= e0 * (1 + 1e-6)
    bad = bgsim._run_one(str(MSD), {}, {"loss": "energy.nobody.dissipated"}, 0)
    assert bad["status"] == "error" and "nobody" in bad["error"]
    with pytest.raises(bgsim.BgSimError, match="energy metric"):
        bgsim._run_one(str(MSD), {}, {"loss": "energy.damper.heat"}, 0)
