#!/usr/bin/env bash
# The same bits before and after a change that should not change them (a move of code):
# builds two revisions and runs, with each, the reference cases, the default simulation (with
# no scenario) and every example (each cut to its first FRAMES frames, default 3), then compares the output
# directories file by file, byte for byte (all but run.toml, which names the command).
#
#   bench/same_bits.sh 4668975 HEAD          # FRAMES=3; prints one line per case
set -euo pipefail
a=$1 b=$2
frames=${FRAMES:-3}
repo=$(cd "$(dirname "$0")/.." && pwd)
work=${WORK:-/tmp/tinydem-same-bits}
rm -rf "$work" && mkdir -p "$work"
for rev in "$a" "$b"; do
  tree="$work/tree-$rev"
  git -C "$repo" worktree add --detach -f "$tree" "$rev" >/dev/null
  (cd "$tree" && CARGO_TARGET_DIR="$work/target-$rev" cargo build --release --quiet)
done
cases=()
for d in "$repo"/tests/data/reference/*/; do cases+=("reference/$(basename "$d")"); done
cases+=(default)
for d in "$repo"/examples/*/; do [ -e "$d/scenario.toml" ] && cases+=("examples/$(basename "$d")"); done
same=0 differ=0
for c in "${cases[@]}"; do
  for rev in "$a" "$b"; do
    bin="$work/target-$rev/release/tinydem"
    run="$work/run-$rev/$c"
    mkdir -p "$run"
    case $c in
      default) # the default scenario (no keys but the frames):
        printf '[simulation]\nframes = %s\n' "$frames" >"$run/scenario.toml"
        (cd "$run" && "$bin" run scenario.toml -o out -q --force >/dev/null) ;;
      reference/*) src="$repo/tests/data/$c"; cp -r "$src/." "$run/"
        (cd "$run" && "$bin" run scenario.toml -o out -q --force >/dev/null) ;;
      examples/*) src="$repo/$c"; cp -r "$src/." "$run/"
        sed -i -E "s/^frames = [0-9]+/frames = $frames/" "$run/scenario.toml"
        (cd "$run" && "$bin" run scenario.toml -o out -q --force >/dev/null) ;;
    esac
  done
  out_a="$work/run-$a/$c" out_b="$work/run-$b/$c"
  if diff -rq -x run.toml -x '*.lock' "$out_a" "$out_b" >/dev/null; then
    n=$(find "$out_a" -type f ! -name run.toml | wc -l)
    echo "same   $c ($n files)"; same=$((same + 1))
  else
    echo "DIFFER $c"; { diff -rq -x run.toml -x '*.lock' "$out_a" "$out_b" || true; } | head -5
    differ=$((differ + 1))
  fi
done
for rev in "$a" "$b"; do git -C "$repo" worktree remove --force "$work/tree-$rev"; done
echo "$same cases the same, $differ differ"
[ $differ = 0 ]
