#!/usr/bin/env bash
# How fast a split run's stop checkpoint is complete: a settled bed of N grains (bench/bed.py)
# on 2 processes under mpirun, sent SIGNAL (TERM or USR1) 2 s into stepping; prints the seconds
# from the signal until both checkpoint parts are complete, until they are joined into
# checkpoint.bin, and until mpirun exits.
#
#   cargo build --release --features mpi
#   bench/stop.sh 1000000 TERM      # repeat, alternate, quote medians
set -euo pipefail
n=$1 sig=$2
here=$(cd "$(dirname "$0")" && pwd)
bin=${BIN:-$here/../target/release/tinydem}
work=${WORK:-/tmp/tinydem-stop}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
[ -e "$work/bed$n.toml" ] || python3 "$here/bed.py" "$n" "$work"
cd "$work"
rm -rf "out$n"
mpirun --oversubscribe -np 2 "$bin" run "bed$n.toml" -o "out$n" -q --force >"log$n.txt" 2>&1 &
pid=$!
while ! [ -s "out$n/frames.csv" ] || [ "$(wc -l <"out$n/frames.csv")" -lt 2 ]; do sleep 0.05; done
sleep 2
start=$(date +%s.%N)
kill "-$sig" $pid
parts="" joined=""
while kill -0 $pid 2>/dev/null; do
  now=$(date +%s.%N)
  [ -z "$parts" ] && [ "$(ls "out$n" | grep -c '\.part-[01]-of-2$')" = 2 ] && parts=$(echo "$now - $start" | bc)
  [ -z "$joined" ] && [ -e "out$n/checkpoint.bin" ] && joined=$(echo "$now - $start" | bc)
  sleep 0.005
done
rc=0
wait $pid || rc=$?
end=$(date +%s.%N)
echo "N=$n $sig: exit $rc, parts complete ${parts:-never} s, joined ${joined:-never} s, mpirun ended $(echo "$end - $start" | bc) s"
