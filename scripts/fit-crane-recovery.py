"""The crane recovery experiment of issue 32 (docs/fit.md, "The crane"): data made with the
knuckle-boom crane at hidden values of beta, R_l, r_p and m3, with 1 % Gaussian noise (of
each column's RMS) on p_p1, p_r1, l1, l2 and q3; `bg-sim fit` from starts 30 % off, then the
same by Nelder–Mead, and the product pair C_d·w. Prints each fit's report and a summary.

    python3 scripts/fit-crane-recovery.py [BG_SIM] [T_END] [METHODS]

BG_SIM defaults to target/release/bg-sim if built, else target/debug/bg-sim; T_END (s) to
the model's 20 s; METHODS to "lm,lm-fd,nelder-mead" (comma-separated; lm uses the exact
sensitivities, lm-fd central differences). Only the standard library is used.
"""

import csv
import json
import math
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "models" / "knuckle_boom.toml"
HIDDEN = {"beta": 1.2e9, "R_l": 2.0e13, "r_p": 8000.0, "m3": 6000.0}
BOUNDS = {"beta": (5e8, 5e9), "R_l": (1e12, 1e14), "r_p": (1e3, 5e4), "m3": (2e3, 2e4)}
COLUMNS = ["p_p1", "p_r1", "l1", "l2", "q3"]
RTOL = 1e-7


def bg_sim_path():
    if len(sys.argv) > 1:
        return Path(sys.argv[1])
    rel = ROOT / "target" / "release" / "bg-sim"
    return rel if rel.exists() else ROOT / "target" / "debug" / "bg-sim"


def fit(bg_sim, data, params, extra):
    args = [str(bg_sim), "fit", str(MODEL), "--data", str(data), "--format", "json",
            "--rtol", repr(RTOL), "-q", *extra]
    for p in params:
        args += ["--param", p]
    t = time.perf_counter()
    out = subprocess.run(args, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if out.returncode != 0:
        sys.exit(out.stderr)
    return json.loads(out.stdout), wall


def main():
    bg_sim = bg_sim_path()
    t_end = float(sys.argv[2]) if len(sys.argv) > 2 else None
    extra = ["--t-end", repr(t_end)] if t_end else []
    with tempfile.TemporaryDirectory() as d:
        clean, data = Path(d) / "clean.csv", Path(d) / "measured.csv"
        sets = [a for k, v in HIDDEN.items() for a in ("--set", f"parameters.{k}={v!r}")]
        subprocess.run([str(bg_sim), "run", str(MODEL), "-q", "-o", str(clean), "--rtol",
                        repr(RTOL), *extra, *sets], stderr=subprocess.DEVNULL)
        with clean.open() as f:
            rows = list(csv.DictReader(f))
        rng = random.Random(32)
        sigma = {c: 0.01 * math.sqrt(sum(float(r[c]) ** 2 for r in rows) / len(rows)) for c in COLUMNS}
        with data.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["t", *COLUMNS])
            for r in rows:
                w.writerow([r["t"], *(repr(float(r[c]) + rng.gauss(0, sigma[c])) for c in COLUMNS)])
        params = [f"{k}={BOUNDS[k][0]!r}..{BOUNDS[k][1]!r}@{0.7 * v!r}" for k, v in HIDDEN.items()]
        methods = sys.argv[3].split(",") if len(sys.argv) > 3 else ["lm", "lm-fd", "nelder-mead"]
        for method in methods:
            how = ["--method", "lm", "--jacobian", "fd"] if method == "lm-fd" else ["--method", method]
            rep, wall = fit(bg_sim, data, params, [*extra, *how])
            print(f"== {method}: {rep['iterations']} iterations, {rep['runs']} runs, {wall:.1f} s, "
                  f"converged {rep['converged']}, cost {rep['cost']:.6e}")
            for k, v in HIDDEN.items():
                e = rep["estimates"][k]
                lo, hi = e["ci95"]
                inside = lo is not None and lo <= v <= hi
                print(f"  {k:5} true {v:.4e}  estimate {e['value']:.5e} ± {e['stderr'] or float('nan'):.2e}"
                      f"  [{lo}, {hi}]  {'inside' if inside else 'OUTSIDE'}")
            for wn in rep["warnings"]:
                print("  warning:", wn)
        rep, wall = fit(bg_sim, data, ["C_d=0.1..2@0.5", "w=1e-4..5e-3@8e-4"], extra)
        print(f"== product pair C_d, w: {rep['runs']} runs, {wall:.1f} s")
        for wn in rep["warnings"]:
            print("  warning:", wn)


if __name__ == "__main__":
    main()
