#!/usr/bin/env bash
# Runs LIGGGHTS (and LAMMPS, if installed) and tinydem alternately on the same settled packings
# and prints the ratio of Cundall numbers (particle-steps per second) per N and worker count.
# Ratios measured in one run are what count on a noisy machine.
#
#   bench/peers.sh [SIZES] [WORKERS] [ROUNDS] [SPLIT]   defaults: "1000 10000 100000" "1 2" 3 threads
#
# The peers run WORKERS MPI processes; tinydem runs WORKERS threads in one process, or, with
# SPLIT = ranks, WORKERS processes of one thread under mpirun (built with --features mpi).
#
# Installs the peers from Debian when missing (apt-get install liggghts lammps).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
sizes=${1:-"1000 10000 100000"}
workers=${2:-"1 2"}
rounds=${3:-3}
split=${4:-threads}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

if ! command -v liggghts >/dev/null; then
  echo "installing LIGGGHTS and LAMMPS from Debian..." >&2
  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq liggghts lammps) >/dev/null
fi
features=()
[ "$split" = ranks ] && features=(--features mpi)
cargo build --release --quiet "${features[@]}" --manifest-path "$root/Cargo.toml"
tinydem="$root/target/release/tinydem"

# Peer steps: about 2e7 particle-steps per run for small N, at least 100.
steps_for() { local n=$1; local s=$((20000000 / n)); [ "$s" -lt 100 ] && s=100; [ "$s" -gt 20000 ] && s=20000; echo "$s"; }

# Seconds per step of a peer from its log: the loop time includes only the timed run.
peer() { # code n workers
  local code=$1 n=$2 w=$3 L data log steps
  L=$(cat "$here/data/n$n/edge.txt")
  steps=$(steps_for "$n")
  data="$tmp/$code.$n.data"
  [ -f "$data" ] || python3 "$here/csv2lammps.py" "$here/data/n$n/settled.csv.gz" "$L" "$data" \
      $([ "$code" = liggghts ] && echo --liggghts)
  log="$tmp/$code.$n.$w.log"
  local deck=$here/in.liggghts exe=liggghts
  [ "$code" = lammps ] && { deck=$here/in.lammps; exe=lmp; }
  local cmd=("$exe" -in "$deck" -var data "$data" -var L "$L" -var nsteps "$steps" -log "$log" -screen none)
  if [ "$w" -gt 1 ]; then mpirun --allow-run-as-root --oversubscribe -np "$w" "${cmd[@]}" >/dev/null 2>&1
  else "${cmd[@]}" >/dev/null 2>&1; fi
  awk -v s="$steps" '/^Loop time of/ {print $4 / s}' "$log"
}

ours() { # n workers -> seconds per step (column 4 of the bench row: ms per step)
  if [ "$split" = ranks ] && [ "$2" -gt 1 ]; then
    mpirun --allow-run-as-root --oversubscribe -np "$2" "$tinydem" bench --single --sizes "$1" --threads 1 --repeats 1
  else
    "$tinydem" bench --single --sizes "$1" --threads "$2" --repeats 1
  fi | awk '{print $4 / 1000}'
}

median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }

peers=(liggghts)
command -v lmp >/dev/null && peers+=(lammps)
printf '%8s %7s %-9s %12s %12s %8s\n' N workers peer "peer Cundall" "ours Cundall" ratio
for n in $sizes; do
  for w in $workers; do
    for code in "${peers[@]}"; do
      : >"$tmp/p"; : >"$tmp/o"
      for _ in $(seq "$rounds"); do
        peer "$code" "$n" "$w" >>"$tmp/p"
        ours "$n" "$w" >>"$tmp/o"
      done
      p=$(median <"$tmp/p"); o=$(median <"$tmp/o")
      awk -v n="$n" -v w="$w" -v c="$code" -v p="$p" -v o="$o" \
        'BEGIN {printf "%8d %7d %-9s %12.3e %12.3e %8.2f\n", n, w, c, n / p, n / o, p / o}'
    done
  done
done
