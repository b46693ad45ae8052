#!/usr/bin/env bash
# Cost that grows with the work (docs/performance.md, issue 22): run the two scaling families —
# the 20 m pipe in N segments (scripts/pipe-model.sh) and N cylinder drives on one supply
# (examples/n_cylinders) — with the default linear algebra (`auto`), and record per size the
# states, steps, wall time of the integration, µs per step and peak memory (GNU time's maximum
# resident set); then print the tables and draw the log–log figure
# docs/performance/scaling.png (scripts/scaling-figure.py, matplotlib in a venv under target/).
#
# Usage: scripts/scaling-figure.sh [BEFORE_BINARY]
#   BEFORE_BINARY  a bg-sim built from an earlier commit (e.g. `git worktree add /tmp/b 50ec6c4 &&
#                  cargo build --release -p bg-sim` there); its rows are labelled `before`.
# Environment: SEGMENTS="10 25 …", DRIVES="1 2 …", REPEAT=3 (runs per point below 2 s, the
# median is kept; slower points run once), NO_BUILD=1 (use target/release as it is),
# OUT=docs/performance/scaling.tsv, BINARIES="before=PATH after=PATH" (instead of the
# arguments), KEEP=earlier.tsv (copy its rows of the labels not measured now: measure the
# `before` binary once, then only `after` after each change).
# Takes about 4 min on a quiet 2-core machine for both binaries (the 2 000-segment pipe is
# most of it), 10–15 min under heavy load.
set -euo pipefail
cd "$(dirname "$0")/.."
before=${1:-}
segments=${SEGMENTS:-"10 25 50 100 200 400 800 2000"}
drives=${DRIVES:-"1 2 4 8 16 32 64"}
repeat=${REPEAT:-3}
out=${OUT:-docs/performance/scaling.tsv}
[ -n "${NO_BUILD:-}" ] || cargo build --release -q -p bg-sim --bins --examples
after=target/release/bg-sim
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# "states steps wall_s peak_kb" of one run of a model file by a binary.
once() {
  local bin=$1 file=$2 log
  log=$(/usr/bin/time -f "peak %M" "$bin" run "$file" -o "$tmp/out.csv" 2>&1 || true)
  local states steps wall kb
  states=$(echo "$log" | sed -nE '1s/.*: ([0-9]+) states,.*/\1/p')
  steps=$(echo "$log" | sed -nE 's/^solver: steps ([0-9]+),.*/\1/p')
  wall=$(echo "$log" | sed -nE 's/^solver:.*wall time ([0-9.]+) s.*/\1/p')
  kb=$(echo "$log" | sed -nE 's/^peak ([0-9]+)$/\1/p')
  if [ -z "$steps" ] || [ -z "$wall" ]; then
    echo "run failed: $bin $file" >&2
    echo "$log" | tail -5 >&2
    exit 1
  fi
  echo "$states $steps $wall $kb"
}

# One point: the median wall of REPEAT runs (one run if the first takes 2 s or more).
point() {
  local family=$1 size=$2 label=$3 bin=$4 file=$5 walls=() r states steps kb
  read -r states steps w kb <<<"$(once "$bin" "$file")"
  walls+=("$w")
  if awk -v w="$w" 'BEGIN {exit !(w < 2)}'; then
    for _ in $(seq 2 "$repeat"); do
      read -r states steps w r <<<"$(once "$bin" "$file")"
      walls+=("$w")
      [ "$r" -gt "$kb" ] && kb=$r
    done
  fi
  local med
  med=$(printf '%s\n' "${walls[@]}" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
  awk -v f="$family" -v n="$size" -v l="$label" -v s="$states" -v st="$steps" -v w="$med" -v kb="$kb" \
    'BEGIN {printf "%s\t%s\t%s\t%s\t%s\t%s\t%.2f\t%.1f\n", f, n, l, s, st, w, 1e6*w/st, kb/1024}'
}

bins=()
if [ -n "${BINARIES:-}" ]; then
  read -r -a bins <<<"$BINARIES"
else
  [ -n "$before" ] && bins+=("before=$before")
  bins+=("after=$after")
fi
labels=$(printf '%s\n' "${bins[@]}" | sed 's/=.*//' | paste -sd'|')
mkdir -p "$(dirname "$out")"
start=$(date +%s)
{
  printf 'family\tsize\tbinary\tstates\tsteps\twall_s\tus_per_step\tpeak_mb\n'
  for n in $segments; do
    scripts/pipe-model.sh "$n" > "$tmp/pipe.toml"
    for b in "${bins[@]}"; do point pipe "$n" "${b%%=*}" "${b#*=}" "$tmp/pipe.toml"; done
  done
  for c in $drives; do
    target/release/examples/n_cylinders "$c" > "$tmp/drives.toml"
    for b in "${bins[@]}"; do point drives "$c" "${b%%=*}" "${b#*=}" "$tmp/drives.toml"; done
  done
  if [ -n "${KEEP:-}" ]; then
    awk -F'\t' -v re="^($labels)$" 'NR > 1 && $3 !~ re' "$KEEP"
  fi
} | tee "$out.partial"
mv "$out.partial" "$out"
echo "measured in $(( $(date +%s) - start )) s; load average: $(cut -d' ' -f1-3 /proc/loadavg)" >&2

# the figure: matplotlib in a venv of its own under target/ (made once)
venv=target/plot-venv
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c 'import matplotlib' 2>/dev/null; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install -q matplotlib
fi
"$venv/bin/python" scripts/scaling-figure.py "$out" docs/performance/scaling.png
