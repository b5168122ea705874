#!/usr/bin/env bash
# The speed of two builds side by side, alternating so that a noisy machine treats both alike:
# builds OLD and NEW (revisions; NEW defaults to HEAD) in work trees, then ROUNDS times runs
# each, in alternating order, on the benchmark (`tinydem bench --sizes SIZES --workers
# WORKERS`, ms per step) and on the default hourglass run (whole, wall seconds; NEW with
# `friction_springs = "$SPRINGS"` when it knows the key, so that both integrate the same
# physics), and prints every round, the medians and NEW/OLD.
#
#   bench/compare.sh 83456f0              # ROUNDS=3 SIZES=10000,100000 WORKERS=1 SPRINGS=paper
#   ROUNDS=5 SIZES=10000 bench/compare.sh 4668975 HEAD
set -euo pipefail
old=$1 new=${2:-HEAD}
rounds=${ROUNDS:-3} sizes=${SIZES:-10000,100000} workers=${WORKERS:-1} springs=${SPRINGS:-paper}
repo=$(cd "$(dirname "$0")/.." && pwd)
source "$repo/bench/lib.sh"
work=${WORK:-/tmp/tinydem-compare}
export TINYDEM_BENCH_DATA=${TINYDEM_BENCH_DATA:-$repo/bench/data}
mkdir -p "$work"
declare -A bin
for rev in "$old" "$new"; do
  sha=$(git -C "$repo" rev-parse --short "$rev")
  tree="$work/tree-$sha"
  [ -d "$tree" ] || git -C "$repo" worktree add --detach -f "$tree" "$sha" >/dev/null
  (cd "$tree" && CARGO_TARGET_DIR="$work/target-$sha" cargo build --release --quiet)
  bin[$rev]="$work/target-$sha/release/tinydem"
done

declare -A rows
for ((r = 1; r <= rounds; r++)); do
  if ((r % 2)); then order=("$old" "$new"); else order=("$new" "$old"); fi
  for rev in "${order[@]}"; do
    line="$(bench_ms "${bin[$rev]}" "$sizes" "$workers")$(timed_run "${bin[$rev]}" "$work/default-$rev" "[simulation]\\nfriction_springs = \"$springs\"\\n")"
    rows[$rev]+="$line;"
    echo "round $r $rev: ms/step at $sizes, then the default run [s]: $line"
  done
done

summary "$old" "$new" "${rows[$old]}" "${rows[$new]}" "$sizes"
