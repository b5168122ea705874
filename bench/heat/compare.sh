#!/usr/bin/env bash
# Heat conducted into a settled bed from a hot bottom plate, side by side with LIGGGHTS 3.8's
# `fix heat/gran/conduction` (Debian): the bed's mean temperature every 1000 steps from both,
# and their largest relative difference in the temperature rise.
#
#   bench/heat/compare.sh [N] [STEPS] [K] [C]    defaults: 10000 10000 1.0 1.0
#
# Installs LIGGGHTS from Debian when missing (apt-get install liggghts).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$(dirname "$here")")
n=${1:-10000} steps=${2:-10000} k=${3:-1.0} c=${4:-1.0}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if ! command -v liggghts >/dev/null; then
  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq liggghts) >/dev/null
fi
cargo build --release --quiet --manifest-path "$root/Cargo.toml"
edge=$(cat "$root/bench/data/n$n/edge.txt")
zcat "$root/bench/data/n$n/settled.csv.gz" > "$tmp/settled.csv"
python3 "$root/bench/csv2lammps.py" "$tmp/settled.csv" "$edge" "$tmp/bed.data" --liggghts
sed -i 's/^1 atom types/2 atom types/' "$tmp/bed.data"   # type 2: the rigid walls
(cd "$tmp" && liggghts -in "$here/in.liggghts" -var data "$tmp/bed.data" -var L "$edge" \
  -var nsteps "$steps" -var k "$k" -var c "$c" -log "$tmp/liggghts.log" > /dev/null)
half=$(python3 -c "print($edge / 2)")
sed -e "s|EDGE|$edge|g; s|HALF|$half|g; s|PARTICLES|$tmp/settled.csv|; s|FRAMES|$((steps / 1000))|" \
  -e "s|= K$|= $k|; s|= C$|= $c|" "$here/bed.toml" > "$tmp/bed.toml"
"$root/target/release/tinydem" run "$tmp/bed.toml" --output "$tmp/out" --quiet
python3 - "$tmp/liggghts.log" "$tmp/out/log.csv" <<'PY'
import csv, sys
rows, on = {}, False
for line in open(sys.argv[1]):
    p = line.split()
    if p[:1] == ["Step"]:
        on = True
        continue
    if on and len(p) == 4 and p[0].isdigit():
        rows[int(p[0])] = float(p[3])
    elif on and p[:1] == ["Loop"]:
        on = False
ours = {int(r["step"]): float(r["T_mean"]) for r in csv.DictReader(open(sys.argv[2]))}
print("%8s %12s %12s %9s" % ("step", "LIGGGHTS", "tinydem", "rise diff"))
worst = 0.0
for step in sorted(rows):
    if step in ours and step > 0:
        a, b = rows[step] - 300.0, ours[step] - 300.0
        d = (b - a) / a if a else 0.0
        worst = max(worst, abs(d))
        print("%8d %12.5f %12.5f %8.2f%%" % (step, rows[step], ours[step], 100 * d))
print("largest difference of the mean temperature rise: %.2f %%" % (100 * worst))
PY
