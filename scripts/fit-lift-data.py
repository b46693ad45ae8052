"""Synthetic "measured" data for the calibration walk-through of docs/fit.md: the lift
circuit run at hidden parameter values, four of its outputs kept, and Gaussian noise of
1 % of each column's RMS added (seeded, so the data are the same on every machine).

    python3 scripts/fit-lift-data.py [BG_SIM] [OUT.csv]

BG_SIM defaults to target/debug/bg-sim, OUT.csv to docs/fit/lift-measured.csv. Only the
standard library is used.
"""

import csv
import math
import random
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "models" / "lift_circuit.toml"
# the "true" machine: 8 % heavier load, 25 % more guide friction, a 20 % stiffer oil than
# the model file says
HIDDEN = {"m": 2160.0, "c_load": 3.75e4, "beta": 1.8e9}
COLUMNS = ["s", "p_p", "p_b", "p_pump"]
NOISE = 0.01  # of each column's RMS
SEED = 32


def main():
    bg_sim = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "target" / "debug" / "bg-sim"
    out = Path(sys.argv[2]) if len(sys.argv) > 2 else ROOT / "docs" / "fit" / "lift-measured.csv"
    with tempfile.TemporaryDirectory() as d:
        clean = Path(d) / "clean.csv"
        sets = [a for k, v in HIDDEN.items() for a in ("--set", f"parameters.{k}={v!r}")]
        # the model's [[check]]s hold the file's hand figures, not these values: a failed
        # check (exit 1) still writes the complete results
        subprocess.run(
            [str(bg_sim), "run", str(MODEL), "-q", "-o", str(clean), *sets],
            stderr=subprocess.DEVNULL,
        )
        if not clean.exists():
            sys.exit("the run did not finish")
        with clean.open() as f:
            rows = list(csv.DictReader(f))
    rng = random.Random(SEED)
    sigma = {
        c: NOISE * math.sqrt(sum(float(r[c]) ** 2 for r in rows) / len(rows)) for c in COLUMNS
    }
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t", *COLUMNS])
        for r in rows:
            w.writerow([r["t"], *(repr(float(r[c]) + rng.gauss(0.0, sigma[c])) for c in COLUMNS)])
    print(f"wrote {len(rows)} rows to {out}; noise σ: " + ", ".join(f"{c} {s:.4g}" for c, s in sigma.items()))


if __name__ == "__main__":
    main()
