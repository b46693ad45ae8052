#!/usr/bin/env python3
"""Write data/knuckle_boom_joystick.csv: a joystick profile for the two valve commands of
models/knuckle_boom.toml (inputs joy1, joy2), sampled at 50 Hz over 20 s.

Synthetic, shaped like an operator's recording: each lever is pushed over 1 s, held, and
released over 1 s, with a small hand tremor (±0.01, seeded) while it is held; both
levers overlap for a while. Run: python3 scripts/joystick_profile.py
"""
import math
import random

RATE = 50.0
T_END = 20.0
random.seed(20)


def lever(t, moves):
    """Sum of trapezoidal pushes (start, end, level), 1 s ramps."""
    v = 0.0
    for start, end, level in moves:
        ramp = 1.0
        if start <= t < start + ramp:
            v += level * (t - start) / ramp
        elif start + ramp <= t < end:
            v += level
        elif end <= t < end + ramp:
            v += level * (1.0 - (t - end) / ramp)
    return v


U1 = [(0.5, 3.0, 0.5), (11.0, 12.5, -0.2)]
U2 = [(2.0, 5.0, 0.4), (14.0, 15.0, -0.25)]

rows = ["t,joy1,joy2"]
n = int(T_END * RATE)
for k in range(n + 1):
    t = k / RATE
    u = []
    for moves in (U1, U2):
        v = lever(t, moves)
        if v != 0.0:
            v += 0.01 * (2.0 * random.random() - 1.0)
        u.append(max(-1.0, min(1.0, v)))
    rows.append(f"{t:.2f},{u[0]:.4f},{u[1]:.4f}")
with open("data/knuckle_boom_joystick.csv", "w") as f:
    f.write("\n".join(rows) + "\n")
