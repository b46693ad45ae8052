"""Stepping (``model.start``) past its input data follows the rule of ``run``: refused with
the input's name, the data's end and the hint ``extrapolate="hold"``; held only when asked.
``set_inputs`` with a series follows the same rule; a number on an input that the start's
data drive is refused (issue 37, items 3 and 8)."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import bgsim

MODELS = Path(__file__).resolve().parents[3] / "models"
MSD = MODELS / "msd_force.toml"  # m = 1 kg, k = 100 N/m, c = 2 N·s/m, input F


def step_df(t_end=2.0):
    return pd.DataFrame({"t": [0.0, 1.0, t_end], "F": [10.0, 10.0, 10.0]})


def test_advancing_past_the_start_data_is_refused_naming_input_end_and_hint():
    sim = bgsim.load(MSD).start(inputs=step_df(2.0))
    sim.advance_to(2.0)  # up to the data's end: fine
    with pytest.raises(bgsim.BgSimError) as e:
        sim.advance_to(2.5)
    msg = str(e.value)
    assert "`F`" in msg and "t = 2 s" in msg and 'extrapolate="hold"' in msg, msg
    assert sim.t == pytest.approx(2.0, abs=1e-12)  # nothing was integrated
    with pytest.raises(bgsim.BgSimError):
        sim.advance(0.1)


def test_hold_when_asked_equals_a_run_with_hold():
    model = bgsim.load(MSD)
    sim = model.start(inputs=step_df(2.0), extrapolate="hold")
    sim.advance_to(4.0)
    run = model.run(t_end=4.0, inputs=step_df(2.0), extrapolate="hold", solver="radau5")
    assert sim.get("x") == pytest.approx(float(run["x"].iloc[-1]), abs=1e-7)
    # a held 10 N on k = 100 N/m, ζ = 0.1: at t = 4 s within e^(-4) ≈ 2 % of 0.1 m
    assert sim.get("spring.q") == pytest.approx(0.1, abs=0.003)


def test_start_data_beginning_after_t0_is_refused():
    df = pd.DataFrame({"t": [0.5, 2.0], "F": [1.0, 1.0]})
    with pytest.raises(bgsim.BgSimError, match="extrapolate"):
        bgsim.load(MSD).start(inputs=df)
    bgsim.load(MSD).start(inputs=df, extrapolate="hold")


def test_set_inputs_series_outside_its_span_is_refused():
    sim = bgsim.load(MSD).start()
    sim.advance_to(1.0)
    with pytest.raises(bgsim.BgSimError, match="start at t = 1.5"):
        sim.set_inputs(F=([1.5, 3.0], [1.0, 1.0]))
    sim.set_inputs(F=([1.0, 2.0], [5.0, 5.0]))
    sim.advance_to(2.0)
    with pytest.raises(bgsim.BgSimError) as e:
        sim.advance_to(2.01)
    assert "`F`" in str(e.value) and "t = 2 s" in str(e.value)
    # a number replaces the series: advancing is free again
    sim.set_inputs(F=5.0)
    sim.advance_to(3.0)
    # hold when asked
    sim.set_inputs(F=([3.0, 3.5], [0.0, 0.0]), extrapolate="hold")
    sim.advance_to(4.0)
    assert sim.get("F") == 0.0


def test_set_inputs_number_on_an_input_the_start_data_drive_is_refused():
    sim = bgsim.load(MSD).start(inputs=step_df(2.0))
    sim.advance_to(0.5)
    with pytest.raises(bgsim.BgSimError, match="follows the data given to `start`"):
        sim.set_inputs(F=0.0)
    assert sim.get("F") == pytest.approx(10.0)
    # new data for it replace the old
    sim.set_inputs(F=([0.5, 3.0], [0.0, 0.0]))
    sim.advance_to(3.0)
    assert sim.get("F") == 0.0


def test_a_simulation_used_from_another_thread_raises_bgsimerror():
    import threading

    sim = bgsim.load(MSD).start()
    caught = []

    def use():
        try:
            sim.advance_to(0.1)
        except BaseException as e:  # a PanicException is a BaseException
            caught.append(e)

    th = threading.Thread(target=use)
    th.start()
    th.join()
    assert len(caught) == 1 and isinstance(caught[0], bgsim.BgSimError), caught
    assert "another thread" in str(caught[0])
    sim.advance_to(0.1)  # still usable on its own thread
    assert sim.t == pytest.approx(0.1, abs=1e-14)
