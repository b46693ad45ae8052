#!/usr/bin/env bash
# Print the size tables of docs/performance.md (issue 22): the 20 m pipe with N segments
# (scripts/pipe-model.sh) and N cylinder drives on one supply (examples/n_cylinders), each
# with Radau's dense and sparse linear algebra: steps, wall time of the integration (median
# of 3), µs per step and peak memory (GNU time's maximum resident set).
# Usage: scripts/scaling-tables.sh ["10 25 50 100 200 400 800 2000"] ["1 2 4 8 16 32 64"]
set -euo pipefail
cd "$(dirname "$0")/.."
segments=${1:-"10 25 50 100 200 400 800 2000"}
drives=${2:-"1 2 4 8 16 32 64"}
[ -n "${NO_BUILD:-}" ] || cargo build --release -q -p bg-sim --bins --examples
bin=target/release/bg-sim
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# "steps|median wall (s)|peak KB" of 3 runs of a model file with the given linear algebra
runs() {
  local file=$1 la=$2 walls=() steps="" kb=""
  for _ in 1 2 3; do
    out=$(/usr/bin/time -f "peak %M" "$bin" run "$file" --set "simulation.linear_algebra=$la" \
      -o "$tmp/out.csv" 2>&1 || true)
    steps=$(echo "$out" | sed -nE 's/^solver: steps ([0-9]+),.*/\1/p')
    walls+=("$(echo "$out" | sed -nE 's/^solver:.*wall time ([0-9.]+) s.*/\1/p')")
    kb=$(echo "$out" | sed -nE 's/^peak ([0-9]+)$/\1/p')
  done
  local med
  med=$(printf '%s\n' "${walls[@]}" | sort -g | awk '{a[NR]=$1} END {print a[2]}')
  echo "$steps|$med|$kb"
}

row() {
  local label=$1 file=$2 n
  n=$("$bin" bench "$file" --rhs | sed -E 's/.*: ([0-9]+) states.*/\1/')
  for la in dense sparse; do
    IFS='|' read -r s w kb <<<"$(runs "$file" "$la")"
    us=$(awk -v w="$w" -v s="$s" 'BEGIN {printf "%.0f", 1e6*w/s}')
    echo "| $label | $n | $la | $s | $w | $us | $((kb / 1024)) |"
  done
}

echo "| segments | states | linear algebra | steps | wall (s) | µs per step | peak MB |"
echo "|---|---|---|---|---|---|---|"
for n in $segments; do
  scripts/pipe-model.sh "$n" > "$tmp/pipe.toml"
  row "$n" "$tmp/pipe.toml"
done
echo
echo "| drives | states | linear algebra | steps | wall (s) | µs per step | peak MB |"
echo "|---|---|---|---|---|---|---|"
for c in $drives; do
  target/release/examples/n_cylinders "$c" > "$tmp/c.toml"
  row "$c" "$tmp/c.toml"
done
