"""Draw docs/performance/scaling.png from the table of scripts/scaling-figure.sh: per-step
cost and peak memory against the number of states, log-log, for the pipe family and the
cylinder drives, each binary (before/after) as its own line, with a slope-1 guide (cost
linear in the size of the machine). Also prints the Markdown tables of docs/performance.md.

Usage: python scripts/scaling-figure.py scaling.tsv scaling.png
"""

import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    for r in rows:
        for k in ("size", "states", "steps"):
            r[k] = int(r[k])
        for k in ("wall_s", "us_per_step", "peak_mb"):
            r[k] = float(r[k])
    return rows


def tables(rows):
    labels = sorted({r["binary"] for r in rows}, key=lambda b: b != "before")
    for family, size_name in (("pipe", "segments"), ("drives", "drives")):
        sub = [r for r in rows if r["family"] == family]
        if not sub:
            continue
        head = f"| {size_name} | states |"
        rule = "|---|---|"
        for b in labels:
            head += f" steps ({b}) | wall s ({b}) | µs/step ({b}) | peak MB ({b}) |"
            rule += "---|---|---|---|"
        print(head)
        print(rule)
        for size in sorted({r["size"] for r in sub}):
            at = {r["binary"]: r for r in sub if r["size"] == size}
            states = next(iter(at.values()))["states"]
            line = f"| {size} | {states} |"
            for b in labels:
                r = at.get(b)
                if r is None:
                    line += " — | — | — | — |"
                else:
                    line += (
                        f" {r['steps']} | {r['wall_s']:.3f} | {r['us_per_step']:.1f}"
                        f" | {r['peak_mb']:.0f} |"
                    )
            print(line)
        print()


def figure(rows, png):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6))
    styles = {
        ("pipe", "before"): dict(color="tab:blue", ls="--", marker="o", mfc="none"),
        ("pipe", "after"): dict(color="tab:blue", ls="-", marker="o"),
        ("drives", "before"): dict(color="tab:orange", ls="--", marker="s", mfc="none"),
        ("drives", "after"): dict(color="tab:orange", ls="-", marker="s"),
    }
    names = {"pipe": "pipe, N segments", "drives": "N cylinder drives"}
    for ax, key, title, unit in (
        (axes[0], "us_per_step", "cost per accepted step", "µs per step"),
        (axes[1], "peak_mb", "peak memory (whole process)", "MB (max. resident set)"),
    ):
        for (family, binary), style in styles.items():
            sub = sorted(
                (r for r in rows if r["family"] == family and r["binary"] == binary),
                key=lambda r: r["states"],
            )
            if not sub:
                continue
            ax.plot(
                [r["states"] for r in sub],
                [r[key] for r in sub],
                label=f"{names[family]} ({binary})",
                **style,
            )
        if key == "us_per_step":
            # a slope-1 guide through the smallest pipe point of the newest binary
            ref = [r for r in rows if r["family"] == "pipe"]
            if ref:
                r0 = min(ref, key=lambda r: (r["binary"] != "after", r["states"]))
                xs = [r0["states"], max(r["states"] for r in rows)]
                ax.plot(
                    xs,
                    [r0[key] * x / xs[0] for x in xs],
                    color="grey",
                    ls=":",
                    label="linear in states (slope 1)",
                )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("states")
        ax.set_ylabel(unit)
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(
        "Radau IIA, linear algebra `auto` (dense below 120 states, sparse above); release build"
    )
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print(f"wrote {png}", file=sys.stderr)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    rows = read(sys.argv[1])
    tables(rows)
    figure(rows, sys.argv[2])


if __name__ == "__main__":
    main()
