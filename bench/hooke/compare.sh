#!/usr/bin/env bash
# Hooke's linear spring-dashpot side by side with LIGGGHTS 3.8's `hooke/stiffness` (Debian):
# a head-on impact at 1 m/s of two grains and of a grain on a wall, at restitution 0.5 and 0.9;
# each code's restitution and contact time (steps with overlap x dt), and the analytic
# values of the damped linear oscillator.
#
#   bench/hooke/compare.sh [K_N] [STEPS_PER_CONTACT]    defaults: 2000 4000
#
# Installs LIGGGHTS from Debian when missing (apt-get install liggghts).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$(dirname "$here")")
kn=${1:-2000} per=${2:-4000}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if ! command -v liggghts >/dev/null; then
  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq liggghts) >/dev/null
fi
cargo build --release --quiet --manifest-path "$root/Cargo.toml"
printf 'OFF\n4 1 0\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n4 0 1 2 3\n' > "$tmp/floor.off"
printf "%8s %4s %10s %10s %10s %9s %12s %12s %12s %9s\n" case e "e LIGGGHTS" "e tinydem" "e theory" "e diff" \
  "t_c LIGGGHTS" "t_c tinydem" "t_c theory" "t_c diff"
for wall in 0 1; do
  for e in 0.5 0.9; do
    read -r dt steps gn gt ec tc < <(python3 - "$kn" "$e" "$wall" "$per" <<'PY'
import math, sys
k, e, wall, per = float(sys.argv[1]), float(sys.argv[2]), sys.argv[3] == "1", float(sys.argv[4])
m = 2500 * 4 / 3 * math.pi * 0.005 ** 3
ms = m if wall else m / 2
beta = 1 / math.sqrt(1 + (math.pi / math.log(e)) ** 2)
tc = math.pi / math.sqrt(k / ms * (1 - beta * beta))
dt = tc / per
print(dt, int(2.5 * per), 2 * beta * math.sqrt(ms * k), 2 * beta * math.sqrt(ms * k * 2 / 7),
      math.exp(-math.pi * beta / math.sqrt(1 - beta * beta)), tc)
PY
)
    (cd "$tmp" && liggghts -in "$here/in.liggghts" -var wall "$wall" -var kn "$kn" \
      -var kt "$(python3 -c "print($kn * 2 / 7)")" -var gn "$gn" -var gt "$gt" -var dt "$dt" \
      -var nsteps "$steps" -log "$tmp/liggghts.log" > /dev/null)
    if [ "$wall" = 1 ]; then
      printf 'x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n0,0,0.005000001,0.005,0,0,-1,1,0,0,0,0,0,0\n' > "$tmp/input.csv"
      mesh="mesh = \"floor.off\""
    else
      printf 'x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n0,0,0.010000001,0.005,0,0,-1,1,0,0,0,0,0,0\n0,0,0,0.005,0,0,0,1,0,0,0,0,0,0\n' > "$tmp/input.csv"
      mesh=""
    fi
    cat > "$tmp/s.toml" <<TOML
[geometry]
radius_min = 0.005
radius_max = 0.005
mesh_radii = [0.0]
$mesh
[material]
density = 2500.0
hooke_stiffness = $kn
restitution = $e
friction_sliding = 0.0
friction_rolling = 0.0
[kinetics]
gravity = [0.0, 0.0, 0.0]
[simulation]
timestep = $dt
frames = $steps
steps_per_frame = 1
max_particles = 0
spawn_attempts = 0
[input]
particles = "input.csv"
[domain]
min = [-0.05, -0.05, -0.05]
max = [0.05, 0.05, 0.05]
TOML
    rm -rf "$tmp/out"
    (cd "$tmp" && "$root/target/release/tinydem" run s.toml --output out --quiet --force)
    python3 - "$tmp/liggghts.log" "$tmp/out" "$wall" "$e" "$dt" "$ec" "$tc" <<'PY'
import csv, glob, os, sys
log, out, wall, e, dt, ec, tc = sys.argv[1], sys.argv[2], sys.argv[3] == "1", *map(float, sys.argv[4:])
R = 0.005
def measure(rows):
    touched, steps = False, 0
    for z1, z2, v1, v2 in rows:
        gap = z1 - R if wall else z1 - z2 - 2 * R
        if gap < 0:
            touched, steps = True, steps + 1
        elif touched:
            return (v1 if wall else v1 - v2), steps * dt
    raise SystemExit("the grains did not part")
rows, on = [], False
for line in open(log):
    p = line.split()
    if p[:1] == ["Step"]:
        on = True
        continue
    if on and len(p) == 5 and p[0].isdigit():
        rows.append(tuple(map(float, p[1:])))
    elif on and p[:1] == ["Loop"]:
        on = False
lig = measure(rows)
ours = []
for f in sorted(glob.glob(os.path.join(out, "particles*.csv"))):
    r = list(csv.DictReader(open(f)))
    r.sort(key=lambda row: -float(row["z"]))
    if wall:
        ours.append((float(r[0]["z"]), -0.005, float(r[0]["vz"]), 0.0))
    else:
        ours.append((float(r[0]["z"]), float(r[1]["z"]), float(r[0]["vz"]), float(r[1]["vz"])))
mine = measure(ours)
print("%8s %4s %10.6f %10.6f %10.6f %8.4f%% %12.6e %12.6e %12.6e %8.4f%%" % (
    "wall" if wall else "pair", e, lig[0], mine[0], ec, 100 * (mine[0] - lig[0]) / lig[0],
    lig[1], mine[1], tc, 100 * (mine[1] - lig[1]) / lig[1]))
PY
  done
done
