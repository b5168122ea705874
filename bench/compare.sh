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

# ms/step of each size, from the table `tinydem bench` prints (by the column's name; builds
# before the process-per-size bench took --single --threads).
bench() {
  { "$1" bench --sizes "$sizes" --workers "$workers" --repeats 1 2>/dev/null ||
    "$1" bench --single --sizes "$sizes" --threads "$workers" --repeats 1 2>/dev/null; } |
    awk 'NR == 1 { for (k = 1; k <= NF; k++) if ($k == "ms/step") c = k; next }
         c && $1 ~ /^[0-9]+$/ { printf "%s ", $c }'
}

# Wall seconds of the default run (the paper's hourglass, 1000 grains, 3 s).
default_run() {
  local dir="$work/default-$2" scenario
  rm -rf "$dir" && mkdir -p "$dir"
  printf '[simulation]\nfriction_springs = "%s"\n' "$springs" >"$dir/s.toml"
  scenario="$dir/s.toml"
  "$1" check "$scenario" >/dev/null 2>&1 || { : >"$dir/s.toml"; }   # an old build without the key
  local start end
  start=$(date +%s.%N)
  (cd "$dir" && "$1" run s.toml -o out -q --force >/dev/null 2>&1)
  end=$(date +%s.%N)
  python3 -c "print(f'{$end - $start:.2f}')"
}

declare -A rows
for ((r = 1; r <= rounds; r++)); do
  if ((r % 2)); then order=("$old" "$new"); else order=("$new" "$old"); fi
  for rev in "${order[@]}"; do
    line="$(bench "${bin[$rev]}")$(default_run "${bin[$rev]}" "$rev")"
    rows[$rev]+="$line;"
    echo "round $r $rev: ms/step at $sizes, then the default run [s]: $line"
  done
done

python3 - "$old" "$new" "${rows[$old]}" "${rows[$new]}" "$sizes" <<'PY'
import statistics, sys
old, new, a, b, sizes = sys.argv[1:]
parse = lambda s: [list(map(float, r.split())) for r in s.strip(";").split(";")]
a, b = parse(a), parse(b)
names = [f"{n} ms/step" for n in sizes.split(",")] + ["default run s"]
print(f"{'':>16} {old:>10} {new:>10}  {new}/{old}")
for k, name in enumerate(names):
    ma, mb = statistics.median(r[k] for r in a), statistics.median(r[k] for r in b)
    print(f"{name:>16} {ma:>10.3f} {mb:>10.3f}  {mb / ma:.3f}")
PY
