#!/usr/bin/env bash
# What the exact sums cost: this tree built as it is and with `--features plain-sums` (float
# sums in place of the exact ones; a build for this measurement only), run ROUNDS times in
# alternating order on the benchmark (`tinydem bench --sizes SIZES --workers WORKERS`, ms per
# step) and on the default hourglass run (wall seconds); prints every round, the medians and
# plain/exact, which is 1 minus the share of the step the exact sums take.
#
#   bench/exact.sh                          # ROUNDS=3 SIZES=10000,100000 WORKERS=1
#   ROUNDS=5 SIZES=10000 WORKERS=2 bench/exact.sh
set -euo pipefail
rounds=${ROUNDS:-3} sizes=${SIZES:-10000,100000} workers=${WORKERS:-1}
repo=$(cd "$(dirname "$0")/.." && pwd)
source "$repo/bench/lib.sh"
work=${WORK:-/tmp/tinydem-exact}
export TINYDEM_BENCH_DATA=${TINYDEM_BENCH_DATA:-$repo/bench/data}
mkdir -p "$work"
(cd "$repo" && cargo build --release --quiet)
(cd "$repo" && CARGO_TARGET_DIR="$work/target-plain" cargo build --release --quiet --features plain-sums)
declare -A bin=([exact]="$repo/target/release/tinydem" [plain]="$work/target-plain/release/tinydem")

declare -A rows
for ((r = 1; r <= rounds; r++)); do
  if ((r % 2)); then order=(exact plain); else order=(plain exact); fi
  for kind in "${order[@]}"; do
    line="$(bench_ms "${bin[$kind]}" "$sizes" "$workers")$(timed_run "${bin[$kind]}" "$work/default-$kind" "")"
    rows[$kind]+="$line;"
    echo "round $r $kind: ms/step at $sizes, then the default run [s]: $line"
  done
done

summary exact plain "${rows[exact]}" "${rows[plain]}" "$sizes"
