"""Model.fit: the lift circuit's load mass and guide friction recovered from noisy data made
by the model itself at hidden values (docs/fit.md), the report's JSON shape, bad input."""

from pathlib import Path

import numpy as np
import pytest

import bgsim

MODEL = Path(__file__).resolve().parents[3] / "models" / "lift_circuit.toml"
HIDDEN = {"m": 2160.0, "c_load": 3.75e4}


def measured():
    df = bgsim.load(MODEL, set=HIDDEN).run(t_end=6.0)[["t", "s", "p_p", "p_b"]].copy()
    rng = np.random.default_rng(32)
    for c in ["s", "p_p", "p_b"]:
        df[c] += 0.01 * np.sqrt(np.mean(df[c] ** 2)) * rng.standard_normal(len(df))
    return df


def test_fit_recovers_hidden_values_within_the_intervals():
    rep = bgsim.load(MODEL).fit(
        data=measured(),
        params={"m": (1000.0, 4000.0, 1512.0), "c_load": (1e4, 1e5, 26250.0)},
        t_end=6.0,
    )
    assert set(rep) == {"estimates", "correlation", "cost", "iterations", "runs", "converged", "warnings", "covariance"}
    assert rep["converged"] and rep["iterations"] <= 15 and rep["runs"] > 0
    for name, true in HIDDEN.items():
        e = rep["estimates"][name]
        assert set(e) == {"value", "stderr", "ci95", "at_bound"}
        lo, hi = e["ci95"]
        assert lo <= true <= hi, (name, e)
    assert rep["correlation"]["names"] == ["m", "c_load"]


def test_fit_refuses_a_column_that_is_no_output():
    df = measured().rename(columns={"p_p": "p_pp"})
    with pytest.raises(bgsim.BgSimError) as e:
        bgsim.load(MODEL).fit(data=[df], params={"m": (1000.0, 4000.0)}, t_end=6.0)
    assert e.value.line == 1 and "did you mean `p_p`" in str(e.value)
