# Pieces shared by bench/compare.sh and bench/exact.sh (sourced).

# ms/step of each size, from the table `tinydem bench` prints (by the column's name; builds
# before the process-per-size bench took --single --threads): BIN SIZES WORKERS.
bench_ms() {
  { "$1" bench --sizes "$2" --workers "$3" --repeats 1 2>/dev/null ||
    "$1" bench --single --sizes "$2" --threads "$3" --repeats 1 2>/dev/null; } |
    awk 'NR == 1 { for (k = 1; k <= NF; k++) if ($k == "ms/step") c = k; next }
         c && $1 ~ /^[0-9]+$/ { printf "%s ", $c }'
}

# Wall seconds of `BIN run s.toml` in DIR (made afresh, s.toml holding TEXT; an empty file is
# the default run): BIN DIR TEXT. A build that refuses TEXT (`check`) runs the empty file.
timed_run() {
  local start end
  rm -rf "$2" && mkdir -p "$2"
  printf '%b' "$3" >"$2/s.toml"
  "$1" check "$2/s.toml" >/dev/null 2>&1 || : >"$2/s.toml"
  start=$(date +%s.%N)
  (cd "$2" && "$1" run s.toml -o out -q --force >/dev/null 2>&1)
  end=$(date +%s.%N)
  python3 -c "print(f'{$end - $start:.2f}')"
}

# The medians of two builds' rounds ("a b c;a b c;...", one number per size, then the default
# run) and their ratio: NAME_A NAME_B ROWS_A ROWS_B SIZES.
summary() {
  python3 - "$@" <<'PY'
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
}
