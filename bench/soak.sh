#!/usr/bin/env bash
# A soak of the stops and resumes of split runs: for MINUTES minutes, runs a filling and
# draining silo (spawning, an outlet, wall loads, contact networks, CSV and VTK frames,
# a checkpoint every 3 s of wall time) under mpirun on a random number of processes, and
# at a random moment kills it: kill -9 or SIGTERM of a random process, SIGTERM, SIGINT,
# SIGUSR1 or kill -9 of mpirun. Each time it resumes from what is left (the checkpoint,
# or its parts) on another random process count, or starts afresh if nothing was left;
# each run that completes is compared, file by file and byte for byte, with an
# uninterrupted run in one process, and the soak starts the next.
#
#   cargo build --release --features mpi
#   bench/soak.sh 30          # minutes; prints a line per launch and a summary
set -uo pipefail
minutes=${1:-30}
here=$(cd "$(dirname "$0")" && pwd)
bin=${BIN:-$here/../target/release/tinydem}
work=${WORK:-/tmp/tinydem-soak}
frames=${FRAMES:-600}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
cat >silo.toml <<TOML
[geometry]
radius_min = 0.003
radius_max = 0.004
mesh = "$here/../tests/data/stages/silo.off"
mesh_radii = [0.0]
spawn_min = [-0.05, -0.05, 0.06]
spawn_max = [0.05, 0.05, 0.14]
[material]
restitution = 0.3
friction_sliding = 0.5
friction_rolling = 0.1
friction_twisting = 0.1
[simulation]
max_particles = 1500
frames = $frames
steps_per_frame = 250
[domain]
min = [-0.1, -0.1, -0.2]
max = [0.1, 0.1, 0.2]
[[outlets]]
min = [-0.1, -0.1, -0.2]
max = [0.1, 0.1, -0.05]
[output]
wall_forces = true
contacts = true
formats = ["csv", "vtk"]
checkpoint_minutes = 0.05
TOML

# The step of the newest checkpoint in out/ (the file, or a complete set of parts), or none.
newest() {
  python3 - "$1" <<'PY'
import os, re, sys
d = sys.argv[1]
steps = []
p = os.path.join(d, "checkpoint.bin")
if os.path.exists(p):
    with open(p, "rb") as f:
        steps.append(int.from_bytes(f.read(32)[24:32], "little"))
sets = {}
for name in os.listdir(d) if os.path.isdir(d) else []:
    m = re.fullmatch(r"checkpoint\.bin\.(\d+)\.part-(\d+)-of-(\d+)", name)
    if m:
        sets.setdefault((int(m[1]), int(m[3])), set()).add(int(m[2]))
steps += [s for (s, n), ks in sets.items() if len(ks) == n]
print(max(steps) if steps else "none")
PY
}

# The files a run writes the same on any process count (all but the checkpoint and run.toml).
compare() {
  local a=$1 b=$2 n=0 bad=0
  for f in "$a"/*; do
    name=$(basename "$f")
    case $name in checkpoint.bin* | run.toml | interrupted.csv) continue ;; esac
    n=$((n + 1))
    cmp -s "$f" "$b/$name" || { bad=$((bad + 1)); echo "  differs: $name"; }
  done
  [ "$(ls "$b" | grep -vc -e '^checkpoint.bin' -e '^run.toml$' -e '^interrupted.csv$')" = "$n" ] || {
    bad=$((bad + 1)); echo "  the file counts differ"; }
  compared=$((compared + n))
  return $bad
}

start=$(date +%s)
echo "reference: an uninterrupted run in one process"
"$bin" run silo.toml -o ref -q --force || exit 1
launches=0 completed=0 matched=0 compared=0 orphans=0 fresh=0 lost=0
declare -A actions=() counts=() exits=()
deadline=$((start + minutes * 60))
while [ "$(date +%s)" -lt $deadline ]; do
  np=$((RANDOM % 3 + 1))
  step=$(newest out)
  if [ "$step" = none ]; then
    args=(run silo.toml -o out -q --force --overwrite); fresh=$((fresh + 1))
  else
    args=(run silo.toml -o out -q --force --resume out/checkpoint.bin)
  fi
  mpirun --oversubscribe -np $np "$bin" "${args[@]}" >>launches.log 2>&1 &
  pid=$!
  launches=$((launches + 1)) counts[$np]=$((${counts[$np]:-0} + 1))
  sleep $((RANDOM % 10 + 2)).$((RANDOM % 10))
  ranks=($(pgrep -P $pid))
  action=none
  if kill -0 $pid 2>/dev/null && [ ${#ranks[@]} -gt 0 ]; then
    rank=${ranks[$((RANDOM % ${#ranks[@]}))]}
    case $((RANDOM % 7)) in
      0) action=kill9-rank; kill -9 "$rank" ;;
      1) action=term-rank; kill -TERM "$rank" ;;
      2 | 3) action=term-mpirun; kill -TERM $pid ;;
      4) action=int-mpirun; kill -INT $pid ;;
      5) action=usr1-mpirun; kill -USR1 $pid ;;
      6) action=kill9-mpirun; kill -9 $pid ;;
    esac
  fi
  rc=0
  wait $pid || rc=$?
  # Processes left by a killed mpirun: ended (they cannot finish without it).
  sleep 0.5
  left=$(pgrep -f "$bin run silo.toml -o out" | wc -l)
  if [ "$left" -gt 0 ]; then
    orphans=$((orphans + left)); pkill -9 -f "$bin run silo.toml -o out"; sleep 0.5
  fi
  actions[$action]=$((${actions[$action]:-0} + 1))
  exits["$action:$rc"]=$((${exits["$action:$rc"]:-0} + 1))
  now=$(newest out)
  echo "launch $launches: $np processes from step $step, $action, exit $rc, checkpoint now at step $now"
  if [ "$step" != none ] && [ "$now" != none ] && [ "$now" -lt "$step" ]; then
    echo "  LOST: the checkpoint went back from step $step to $now"; lost=$((lost + 1))
  fi
  if [ "$step" != none ] && [ "$now" = none ]; then
    echo "  LOST: no checkpoint after step $step"; lost=$((lost + 1))
  fi
  if [ $rc = 0 ] && [ "$(tail -1 out/frames.csv | cut -d, -f1)" = "$frames" ]; then
    completed=$((completed + 1))
    if compare ref out; then matched=$((matched + 1)); echo "  complete, the same bytes as the reference"; fi
    rm -rf out
  fi
done
elapsed=$(($(date +%s) - start))
echo
echo "soak: $((elapsed / 60)) min $((elapsed % 60)) s, $launches launches (processes: 1 x ${counts[1]:-0}, 2 x ${counts[2]:-0}, 3 x ${counts[3]:-0}), $fresh fresh starts"
for a in "${!actions[@]}"; do echo "  $a: ${actions[$a]}"; done | sort
echo "  exit codes by action: $(for k in "${!exits[@]}"; do echo -n "$k x${exits[$k]} "; done)"
echo "  orphaned processes ended: $orphans; checkpoints lost: $lost"
echo "  runs completed: $completed, identical to the reference: $matched ($compared files compared)"
[ $lost = 0 ] && [ $matched = $completed ]
