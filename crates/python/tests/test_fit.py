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


def test_a_fit_band_on_dask_matches_the_sweep(tmp_path):
    """The fitted lift circuit's band from its covariance (docs/fit.md) on a Dask
    LocalCluster, 20 runs of the docs' spec: the same quantiles as `bg-sim sweep` computes
    (numpy's default quantile is the same type-7 rule)."""
    distributed = pytest.importorskip("distributed")
    root = MODEL.parents[1]
    spec = tmp_path / "band.toml"
    text = (root / "docs" / "fit" / "lift-band.toml").read_text().replace("samples = 200", "samples = 20")
    spec.write_text(text.replace('file = "lift-fit.json"', f'file = "{root / "docs" / "fit" / "lift-fit.json"}"'))
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        band = bgsim.dask_band(client, MODEL, spec, ["p_p"])
    # the hold after lowering: the load's pressure, (m g + A_r p_t)/A_p with m near 2160 kg
    hold = band[(band.t > 12.0)]
    assert np.all(hold["p_p_q05"] <= hold["p_p_mean"]) and np.all(hold["p_p_mean"] <= hold["p_p_q95"])
    a_p, a_r = np.pi / 4 * 0.063**2, np.pi / 4 * (0.063**2 - 0.036**2)
    expected = (2159.66 * 9.81 + a_r * 2e5) / a_p
    assert abs(hold["p_p_mean"].mean() / expected - 1) < 2e-3
    # the band's width there is set by the load's stderr, 0.41 kg: 2·1.645·0.41·g/A_p ≈ 4.2 kPa
    assert 1e3 < hold["p_p_width"].mean() < 1e4
