#!/usr/bin/env bash
# Print the cost tables of docs/performance.md: the crane's cost against the number of modes
# per link, and a generated model's cost against the number of cylinder drives.
# Usage: scripts/performance-tables.sh   (builds the release binary first; takes ~1 min)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q -p bg-sim --bins --examples
bin=target/release/bg-sim
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# median wall time (ms) and the solver line of 5 runs
runs() {
  local walls=() line=""
  for _ in 1 2 3 4 5; do
    line=$("$bin" run "$@" -o "$tmp/out.csv" 2>/dev/null | grep '^solver:' || true)
    walls+=("$(echo "$line" | sed -E 's/.*wall time ([0-9.]+) s.*/\1/')")
  done
  local med
  med=$(printf '%s\n' "${walls[@]}" | sort -g | awk '{a[NR]=$1} END {printf "%.1f", a[3]*1000}')
  echo "$med|$(echo "$line" | sed -E 's/.*steps ([0-9]+), rhs evals ([0-9]+), Jacobian evals ([0-9]+).*LU factorisations ([0-9]+).*/\1|\2|\3|\4/')"
}
rhs() { "$bin" bench "$@" --rhs | sed -E 's/.*: ([0-9]+) states; rhs ([0-9.]+) µs per call, Jacobian ([0-9.]+) µs per call \(([0-9.]+) rhs.*/\1|\2|\3|\4/'; }

echo "| modes per link | states | µs per rhs | µs per Jacobian (rhs-equiv.) | wall (ms) | steps | rhs | Jacobians | LU |"
echo "|---|---|---|---|---|---|---|---|---|"
for m in 0 1 2 3 4 5 6 7 8 9 10; do
  set_modes=(--set "parameters.modes1=$m" --set "parameters.modes2=$m")
  IFS='|' read -r n r j je <<<"$(rhs models/knuckle_boom.toml "${set_modes[@]}")"
  IFS='|' read -r w s e jj lu <<<"$(runs models/knuckle_boom.toml "${set_modes[@]}")"
  echo "| $m | $n | $r | $j ($je) | $w | $s | $e | $jj | $lu |"
done
echo
echo "| cylinder drives | states | µs per rhs | µs per Jacobian (rhs-equiv.) | wall (ms) | steps | rhs | Jacobians | LU |"
echo "|---|---|---|---|---|---|---|---|---|"
for c in 1 2 4 8 16 32; do
  target/release/examples/n_cylinders "$c" > "$tmp/c$c.toml"
  IFS='|' read -r n r j je <<<"$(rhs "$tmp/c$c.toml")"
  IFS='|' read -r w s e jj lu <<<"$(runs "$tmp/c$c.toml")"
  echo "| $c | $n | $r | $j ($je) | $w | $s | $e | $jj | $lu |"
done
