"""`bg-sim fatigue` (issue 34, docs/fatigue.md) against an independent rainflow counter: the
PyPI package `rainflow` (ASTM E1049-85, in the CI venv through .ci/run).

The binary `target/debug/bg-sim` counts a column of a CSV; its cycles (range, mean, count)
must be the package's `extract_cycles` of the same history, and its Miner damage the sum
written out here from the EN 1993-1-9 formulas.
"""

import json
import os
import subprocess
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[3]
BG_SIM = ROOT / "target" / "debug" / "bg-sim"

# skipped outside CI only: .ci/run (CI=true) installs `rainflow` and builds bg-sim
if os.environ.get("CI"):
    import rainflow
else:
    rainflow = pytest.importorskip("rainflow")
    pytestmark = pytest.mark.skipif(
        not BG_SIM.is_file(), reason="needs `cargo build -p bg-sim` (.ci/run builds it)"
    )


def write_csv(path, values, name="sigma"):
    lines = ["t," + name] + [f"{k * 0.01!r},{float(v)!r}" for k, v in enumerate(values)]
    path.write_text("\n".join(lines) + "\n")


def fatigue(csv, *extra, column="sigma"):
    """`bg-sim fatigue CSV --column COLUMN --format json EXTRA…`, parsed."""
    out = subprocess.run(
        [str(BG_SIM), "fatigue", str(csv), "--column", column, "--format", "json", *extra],
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(out.stdout)


def merged(cycles):
    """{(range, mean): count} of (range, mean, count) triples."""
    table = defaultdict(float)
    for r, m, c in cycles:
        table[(r, m)] += c
    return table


def ec3_cycles(range_pa, category=71.0):
    """N of EN 1993-1-9 detail category `category` (MPa) at a range in Pa."""
    s = range_pa / 1e6
    d = category * (2 / 5) ** (1 / 3)
    cut = d * (5 / 100) ** (1 / 5)
    if s >= d:
        return 2e6 * (category / s) ** 3
    if s >= cut:
        return 5e6 * (d / s) ** 5
    return np.inf


def test_astm_example_counts(tmp_path):
    csv = tmp_path / "astm.csv"
    write_csv(csv, [-2.0, 1.0, -3.0, 5.0, -1.0, 3.0, -4.0, 4.0, -2.0])
    got = fatigue(csv, "--sn", "ec3-71")
    by_range = defaultdict(float)
    for c in got["cycles"]:
        by_range[c["range"]] += c["count"]
    assert dict(by_range) == {3.0: 0.5, 4.0: 1.5, 6.0: 0.5, 8.0: 1.0, 9.0: 0.5}
    assert dict(by_range) == dict(rainflow.count_cycles([-2, 1, -3, 5, -1, 3, -4, 4, -2]))
    assert set(got) == {"cycles", "damage", "life_repeats"}


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_random_history_matches_the_rainflow_package(tmp_path, seed):
    rng = np.random.default_rng(seed)
    # a wandering stress with peaks of either sign: 3000 samples, tens of MPa
    history = np.cumsum(rng.normal(0.0, 8e6, 3000)) + 20e6 * np.sin(np.arange(3000) / 40)
    csv = tmp_path / "random.csv"
    write_csv(csv, history)
    got = fatigue(csv, "--sn", "ec3-71", "--scf", "1.25")
    ours = merged((c["range"], c["mean"], c["count"]) for c in got["cycles"])
    theirs = merged((r, m, c) for r, m, c, _, _ in rainflow.extract_cycles(history.tolist()))
    assert len(ours) == len(theirs) > 500
    for (r, m), c in theirs.items():
        assert ours[(r, m)] == c, (r, m)
    want = sum(c / ec3_cycles(1.25 * r) for (r, _), c in theirs.items())
    assert got["damage"] == pytest.approx(want, rel=1e-12)
    assert got["life_repeats"] == pytest.approx(1.0 / want, rel=1e-12)


def test_repeated_history_counts_what_each_further_pass_adds(tmp_path):
    rng = np.random.default_rng(7)
    history = np.cumsum(rng.normal(0.0, 10e6, 800))
    csv = tmp_path / "duty.csv"
    write_csv(csv, history)
    got = fatigue(csv, "--sn", "ec3-71", "--repeat-per-year", "2000")

    def damage(k):
        return sum(
            c / ec3_cycles(r)
            for r, _, c, _, _ in rainflow.extract_cycles(np.tile(history, k).tolist())
        )

    per_pass = damage(3) - damage(2)
    assert got["damage"] == pytest.approx(per_pass, rel=1e-9)
    assert got["life_years"] == pytest.approx(1.0 / (2000 * per_pass), rel=1e-9)
    assert all(c["count"] >= 1.0 for c in got["cycles"])


def test_bad_input_exits_2_with_a_hint(tmp_path):
    csv = tmp_path / "bad.csv"
    csv.write_text("t,sigma\n0,1\n0.1,nan\n0.2,3\n")
    for extra, words in [
        (["--column", "sigma", "--sn", "ec3-71"], ["bad.csv:3", "finite"]),
        (["--column", "Sigma", "--sn", "ec3-71"], ["did you mean `sigma`"]),
        (["--column", "sigma", "--sn", "ec3-70"], ["ec3-71", "dnv-w3"]),
    ]:
        out = subprocess.run(
            [str(BG_SIM), "fatigue", str(csv), *extra], capture_output=True, text=True
        )
        assert out.returncode == 2, out.stderr
        for w in words:
            assert w in out.stderr, out.stderr
