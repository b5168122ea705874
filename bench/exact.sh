#!/usr/bin/env bash
# What the exact sums cost: this tree built as it is and with `--features plain-sums` (float
# sums in place of the exact ones; a build for this measurement only), run ROUNDS times in
# alternating order on the benchmark (`tinydem bench --sizes SIZES --workers WORKERS`, ms per
# step) and on the default hourglass run (wall seconds); prints every round, the medians and
# exact/plain. The share of the step the exact sums take is 1 - plain/exact.
#
#   bench/exact.sh                          # ROUNDS=3 SIZES=10000,100000 WORKERS=1
#   ROUNDS=5 SIZES=10000 WORKERS=2 bench/exact.sh
set -euo pipefail
rounds=${ROUNDS:-3} sizes=${SIZES:-10000,100000} workers=${WORKERS:-1}
repo=$(cd "$(dirname "$0")/.." && pwd)
work=${WORK:-/tmp/tinydem-exact}
export TINYDEM_BENCH_DATA=${TINYDEM_BENCH_DATA:-$repo/bench/data}
mkdir -p "$work"
(cd "$repo" && cargo build --release --quiet)
(cd "$repo" && CARGO_TARGET_DIR="$work/target-plain" cargo build --release --quiet --features plain-sums)
declare -A bin=([exact]="$repo/target/release/tinydem" [plain]="$work/target-plain/release/tinydem")

# ms/step of each size, from the table `tinydem bench` prints (by the column's name).
bench() {
  "$1" bench --sizes "$sizes" --workers "$workers" --repeats 1 2>/dev/null |
    awk 'NR == 1 { for (k = 1; k <= NF; k++) if ($k == "ms/step") c = k; next }
         c && $1 ~ /^[0-9]+$/ { printf "%s ", $c }'
}

# Wall seconds of the default run (the paper's hourglass, 1000 grains, 3 s).
default_run() {
  local dir="$work/default-$2" start end
  rm -rf "$dir" && mkdir -p "$dir" && : >"$dir/s.toml"
  start=$(date +%s.%N)
  (cd "$dir" && "$1" run s.toml -o out -q --force >/dev/null 2>&1)
  end=$(date +%s.%N)
  python3 -c "print(f'{$end - $start:.2f}')"
}

declare -A rows
for ((r = 1; r <= rounds; r++)); do
  if ((r % 2)); then order=(exact plain); else order=(plain exact); fi
  for kind in "${order[@]}"; do
    line="$(bench "${bin[$kind]}")$(default_run "${bin[$kind]}" "$kind")"
    rows[$kind]+="$line;"
    echo "round $r $kind: ms/step at $sizes, then the default run [s]: $line"
  done
done

python3 - "${rows[exact]}" "${rows[plain]}" "$sizes" <<'PY'
import statistics, sys
a, b, sizes = sys.argv[1:]
parse = lambda s: [list(map(float, r.split())) for r in s.strip(";").split(";")]
a, b = parse(a), parse(b)
names = [f"{n} ms/step" for n in sizes.split(",")] + ["default run s"]
print(f"{'':>16} {'exact':>10} {'plain':>10}  exact/plain  share of the step")
for k, name in enumerate(names):
    ma, mb = statistics.median(r[k] for r in a), statistics.median(r[k] for r in b)
    print(f"{name:>16} {ma:>10.3f} {mb:>10.3f}  {ma / mb:11.3f}  {100 * (1 - mb / ma):5.1f} %")
PY
