"""model.sensitivity(params=[...]) against the closed form of the mass-spring-damper,
differentiated by central differences of the formula (exact to ~1e-10 of scale)."""

import math
from pathlib import Path

import numpy as np
import pytest

import bgsim

MSD = Path(__file__).resolve().parents[3] / "models" / "mass_spring_damper.toml"


def closed_form(t, k=10.0, c=0.5, m=1.0, x0=0.01):
    wn = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    wd = wn * math.sqrt(1 - zeta**2)
    return x0 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t))


def test_sensitivity_returns_a_dataframe_matching_the_closed_form():
    model = bgsim.load(MSD, set={"simulation.rtol": 1e-10, "simulation.atol": 1e-14})
    df = model.sensitivity(params=["k", "c", "x0"], t_end=5.0)
    assert list(df.columns[:4]) == ["t", "x", "v", "F_spring"]
    assert "dx/dk" in df.columns and "dF_spring/dx0" in df.columns
    assert df.attrs["values"] == [10.0, 0.5, 0.01]
    assert df.attrs["steps"] > 0
    t = df["t"].to_numpy()
    base = {"k": 10.0, "c": 0.5, "x0": 0.01}
    for p, v in base.items():
        h = 1e-5 * v
        plus = closed_form(t, **{**base, p: v + h})
        minus = closed_form(t, **{**base, p: v - h})
        ref = (plus - minus) / (2 * h)
        err = np.abs(df[f"dx/d{p}"].to_numpy() - ref).max()
        assert err < 1e-4 * np.abs(ref).max(), (p, err)


def test_sensitivity_to_an_unknown_parameter_is_refused_with_a_suggestion():
    with pytest.raises(bgsim.BgSimError) as e:
        bgsim.load(MSD).sensitivity(params=["zetta"])
    assert "zeta" in str(e.value)
