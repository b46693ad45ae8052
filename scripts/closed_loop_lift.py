"""A PI position loop written in Python drives the lift circuit's 4/3 valve at 100 Hz
(docs/python.md), against the same loop written in the model (pi_loop = 1).

    python scripts/closed_loop_lift.py            # prints the comparison and the timing
"""

import sys
import time
from pathlib import Path

import numpy as np

import bgsim

MODEL = Path(__file__).resolve().parents[1] / "models" / "lift_circuit.toml"
KP, KI, S_REF = 20.0, 10.0, 0.3  # 1/m, 1/(m·s), m: the model's kp, ki, s_ref
DT, T_END = 0.01, 6.0  # 100 Hz, 6 s
# A controller test needs less than the file's rtol 1e-8 (its hand-calculation checks)
SETTINGS = {"simulation.rtol": 1e-6, "simulation.atol": 1e-6}


def python_loop():
    """The loop in Python: sample s, PI with the integral by the rectangle rule, hold the
    command for one sample (zero-order hold)."""
    sim = bgsim.load(MODEL, set={"schedule": 0.0, **SETTINGS}).start()
    integral, rows = 0.0, []
    wall = time.perf_counter()
    advance_s = 0.0
    for k in range(round(T_END / DT)):
        s = sim.get("s")
        e = S_REF - s
        u = min(max(KP * e + integral, -1.0), 1.0)
        integral += KI * e * DT
        sim.set_inputs(u_valve=u)
        rows.append((sim.t, s, u))
        a = time.perf_counter()
        sim.advance_to((k + 1) * DT)
        advance_s += time.perf_counter() - a
    wall = time.perf_counter() - wall
    rows.append((sim.t, sim.get("s"), u))
    return np.array(rows), wall, advance_s, sim.stats()


def model_loop():
    """The same loop written in the model: continuous PI (pi_loop = 1)."""
    model = bgsim.load(MODEL, set={"schedule": 0.0, "pi_loop": 1.0, **SETTINGS})
    return model.run(t_end=T_END, dt_out=DT)


def main():
    py, wall, advance_s, stats = python_loop()
    df = model_loop()
    s_model = np.interp(py[:, 0], df["t"], df["s"])
    n = len(py) - 1
    print(f"Python PI at 100 Hz: {n} advance calls, {wall:.3f} s wall for {T_END} s simulated "
          f"= {T_END / wall:.0f}× real time")
    print(f"  one advance call: {1e6 * advance_s / n:.0f} µs on average "
          f"(the loop's Python, get and set_inputs: {1e6 * (wall - advance_s) / n:.0f} µs per sample)")
    print(f"  solver: {stats['steps']} steps, {stats['jac_evals']} Jacobians, "
          f"{stats['lu_factorisations']} LUs, {stats['rhs_evals']} rhs")
    print(f"  final stroke {py[-1, 1]:.5f} m (set-point {S_REF} m); the model's loop {s_model[-1]:.5f} m")
    print(f"  largest difference in stroke, Python loop − model loop: {np.abs(py[:, 1] - s_model).max() * 1e3:.2f} mm")
    return 0


if __name__ == "__main__":
    sys.exit(main())
