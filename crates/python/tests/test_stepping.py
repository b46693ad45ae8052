"""Stepping (``model.start``) and linearising (``model.linearize``) from Python: many short
advances equal one run, no solver restart per call, names and errors; the linear model of
the mass-spring-damper against its closed form."""

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


def test_many_short_advances_equal_one_run_without_restarts():
    model = bgsim.load(MSD)
    # Radau, as the stepping uses it, at the file's tolerances
    run = model.run(t_end=2.0, dt_out=0.01, solver="radau5")
    sim = model.start()
    assert sim.t == 0.0
    xs = []
    for k in range(1, 201):
        sim.advance_to(k * 0.01)
        xs.append(sim.get("x"))
    assert sim.t == pytest.approx(2.0, abs=1e-14)
    xs = np.array(xs)
    assert np.abs(xs - run["x"].to_numpy()[1:]).max() < 1e-9
    assert np.abs(xs - closed_form(np.arange(1, 201) * 0.01)).max() < 1e-8
    st = sim.stats()
    # a restart per call would cost a Jacobian per call: 200
    assert st["jac_evals"] < 20, st
    assert st["lu_factorisations"] <= 2 * 200 + run.attrs["stats"]["steps"], st
    # advance(dt) is advance_to(t + dt)
    sim.advance(0.5)
    assert sim.t == pytest.approx(2.5)
    assert sim.get("x") == pytest.approx(closed_form(2.5), abs=1e-8)


def test_state_is_named_and_values_are_read_by_any_name():
    sim = bgsim.load(MSD).start()
    sim.advance_to(0.3)
    s = sim.state()
    assert list(s.index) == ["mass.p", "spring.q"]
    assert s["spring.q"] == sim.get("x") == sim.get("spring.q")
    # an output of the model, a bond variable, a derivative
    assert sim.get("F_spring") == pytest.approx(10.0 * sim.get("x"))
    assert sim.get("spring.q.dot") == pytest.approx(sim.get("v"))
    many = sim.get_many(["x", "v"])
    assert many == {"x": sim.get("x"), "v": sim.get("v")}
    assert sim.outputs == ["x", "v", "F_spring"] and sim.inputs == []


def test_stepping_errors():
    sim = bgsim.load(MSD).start()
    sim.advance_to(0.5)
    with pytest.raises(bgsim.BgSimError, match="only goes forward"):
        sim.advance_to(0.25)
    with pytest.raises(bgsim.BgSimError, match="did you mean `x`"):
        sim.get("xx")
    with pytest.raises(bgsim.BgSimError, match="no input"):
        sim.set_inputs(F=1.0)


def test_linearize_returns_named_numpy_matrices():
    model = bgsim.load(MSD, set={"k": 100.0, "c": 2.0})
    A, B, C, D = model.linearize(t=0.0, outputs=["x", "v"])
    lin = model.linearize(outputs=["x", "v"])
    assert lin.states == ["mass.p", "spring.q"]
    assert lin.outputs == ["x", "v"] and lin.inputs == []
    assert isinstance(A, np.ndarray) and A.shape == (2, 2) and B.shape == (2, 0)
    np.testing.assert_allclose(A, [[-2.0, -100.0], [1.0, 0.0]], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(C, [[0.0, 1.0], [1.0, 0.0]])
    assert D.shape == (2, 0)
    poles = np.sort_complex(lin.poles())
    np.testing.assert_allclose(poles, [-1 - math.sqrt(99) * 1j, -1 + math.sqrt(99) * 1j], atol=1e-12)
    # at a later time of a run: the same (a linear model)
    later = model.linearize(t=1.0, outputs=["x"])
    assert later.t == pytest.approx(1.0)
    np.testing.assert_allclose(later.A, A, atol=1e-12)
    # at the current point of a simulation
    sim = model.start()
    sim.advance_to(0.2)
    np.testing.assert_allclose(sim.linearize(outputs=["x"]).A, A, atol=1e-12)
    with pytest.raises(bgsim.BgSimError, match="did you mean"):
        model.linearize(outputs=["xx"])


MSD_F = MODELS / "msd_force.toml"


def test_set_inputs_drives_the_force_input():
    sim = bgsim.load(MSD_F).start()
    assert sim.inputs == ["F"]
    sim.advance_to(1.0)
    assert sim.get("x") == 0.0
    sim.set_inputs(F=10.0)
    sim.set_inputs({"F": 10.0})  # the same value again: nothing happens
    jac_before = sim.stats()["jac_evals"]
    for k in range(1, 1901):
        sim.advance_to(1.0 + k * 0.01)
    assert sim.get("F") == 10.0
    assert abs(sim.get("x") - 0.1) < 1e-6
    # no restart per call: far fewer Jacobians than calls
    assert sim.stats()["jac_evals"] - jac_before < 50, sim.stats()


def test_run_with_a_dataframe_or_numpy_input_equals_the_step_in_the_model():
    import pandas as pd

    model = bgsim.load(MSD_F)
    ref = bgsim.load(MSD_F, set={"F_step": 10.0}).run(t_end=5.0)
    data = pd.DataFrame({"t": [0.0, 1.0, 5.0], "F": [0.0, 10.0, 10.0]})
    df = model.run(t_end=5.0, inputs=data, inputs_interp="hold")
    assert np.abs(df["x"].to_numpy() - ref["x"].to_numpy()).max() < 1e-9
    arrays = model.run(
        t_end=5.0, inputs={"F": (np.array([0.0, 1.0, 5.0]), np.array([0.0, 10.0, 10.0]))}, inputs_interp="hold"
    )
    assert np.abs(arrays["x"].to_numpy() - ref["x"].to_numpy()).max() < 1e-9
    with pytest.raises(bgsim.BgSimError, match="end at t = 2"):
        model.run(t_end=5.0, inputs={"F": ([0.0, 2.0], [0.0, 1.0])})
    held = model.run(t_end=5.0, inputs={"F": ([0.0, 2.0], [0.0, 1.0])}, extrapolate="hold")
    assert held["F"].iloc[-1] == 1.0
    with pytest.raises(bgsim.BgSimError, match="did you mean `F`"):
        model.run(t_end=5.0, inputs={"f": ([0.0, 5.0], [0.0, 1.0])})


def test_linearize_the_force_input():
    model = bgsim.load(MSD_F)
    A, B, C, D = model.linearize(t=0.0, inputs=["F"], outputs=["x"])
    lin = model.linearize(t=0.0, inputs=["F"], outputs=["x"])
    np.testing.assert_array_equal(B, [[1.0], [0.0]])
    np.testing.assert_array_equal(D, [[0.0]])
    assert lin.inputs == ["F"] and lin.outputs == ["x"]
    assert lin.dc_gain("F", "x") == pytest.approx(0.01, abs=1e-15)
    poles = np.sort_complex(lin.poles())
    np.testing.assert_allclose(poles, [-1 - math.sqrt(99) * 1j, -1 + math.sqrt(99) * 1j], atol=1e-12)
    w = 2 * np.pi * np.array([0.1, 1.0, 10.0])
    g = lin.response("F", "x", w / (2 * np.pi))
    np.testing.assert_allclose(g, 1 / (100 - w**2 + 2j * w), rtol=1e-12)
