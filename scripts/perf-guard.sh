#!/usr/bin/env bash
# The performance regression guard: count the instructions (callgrind) of four whole `bg-sim run`
# processes for two commits, built side by side in release, and print the ratios.
#
#   scripts/perf-guard.sh BASE [HEAD]     (HEAD defaults to the work tree as it is, uncommitted
#                                          changes included; BASE and HEAD are any git revisions)
#
# The four runs: the knuckle boom crane, the load-sensing crane, the 200-segment pipe of
# scripts/pipe-model.sh and the lift circuit. Instruction counts do not depend on the machine's
# load, so the ratio is what to read; a ratio above 1.02 on any run deserves a look.
# Each revision is built in its own worktree and target directory under target/perf-guard/
# (the first build of a revision takes several minutes; later runs reuse it).
set -euo pipefail
cd "$(dirname "$0")/.."
base=${1:?usage: scripts/perf-guard.sh BASE [HEAD]}
head=${2:-}
command -v valgrind >/dev/null || { echo "perf-guard: valgrind is needed (apt-get install valgrind)" >&2; exit 2; }

root=$PWD
work=$root/target/perf-guard
mkdir -p "$work"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# build REV → prints the path of its bg-sim binary
build() {
  local rev=$1 dir sha
  if [ -z "$rev" ]; then
    cargo build --release -q --locked -p bg-sim --bin bg-sim >&2
    echo "$root/target/release/bg-sim"
    return
  fi
  sha=$(git rev-parse --short=10 "$rev^{commit}")
  dir=$work/$sha
  if [ ! -d "$dir/src" ]; then
    git worktree add -q --detach "$dir/src" "$sha" >&2
  fi
  (cd "$dir/src" && CARGO_TARGET_DIR="$dir/target" cargo build --release -q --locked -p bg-sim --bin bg-sim) >&2
  echo "$dir/target/release/bg-sim"
}

# instructions BIN MODEL [ARGS…] → the total instruction count of the whole process
instructions() {
  local bin=$1 model=$2
  shift 2
  valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" "$bin" run "$model" \
    -o "$tmp/out.csv" --quiet "$@" >/dev/null 2>"$tmp/vg.log" || {
    echo "perf-guard: the run of $model failed under $bin (see below)" >&2
    tail -5 "$tmp/vg.log" >&2
    exit 1
  }
  awk '/^summary:/ {print $2}' "$tmp/cg.out"
}

bin_base=$(build "$base")
bin_head=$(build "$head")
scripts/pipe-model.sh 200 > "$tmp/pipe200.toml"

echo "| run | ${base} | ${head:-work tree} | ratio |"
echo "|---|---|---|---|"
for spec in "crane:models/knuckle_boom.toml" "ls-crane:models/knuckle_boom_ls.toml" \
  "pipe-200:$tmp/pipe200.toml" "lift:models/lift_circuit.toml"; do
  name=${spec%%:*}
  model=${spec#*:}
  a=$(instructions "$bin_base" "$model")
  b=$(instructions "$bin_head" "$model")
  awk -v n="$name" -v a="$a" -v b="$b" \
    'BEGIN { printf "| %s | %.1f M | %.1f M | %.3f |\n", n, a / 1e6, b / 1e6, b / a }'
done
