#!/usr/bin/env python3
"""The default hourglass run over many spawning seeds (issue 10's measurement; not a test).

For each seed it runs the paper's default simulation (Table 2, the built-in hourglass) with
`[simulation] seed = N`, the mesh-contact mode and the friction springs' order asked for, and reports whether the run
completed, how many pairs overlapped past the smaller radius (warnings), and the share of
grains below the throat (z < 0.15 m) at frame 20 (t = 0.6 s) and at the last frame.

    python3 bench/seeds.py --seeds 1-100 --mode merged --jobs 2
    python3 bench/seeds.py --seeds 1-20 --mode per_face --binary /tmp/old/tinydem
    python3 bench/seeds.py --seeds 1-20 --springs paper

Standard library only. Each run uses one thread; --jobs runs that many at once.
"""

import argparse
import concurrent.futures
import csv
import os
import re
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
THROAT = 0.15


def seeds(text):
    out = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out.extend(range(int(a), int(b or a) + 1))
    return out


def share_below(path):
    with open(path, newline="") as f:
        z = [float(row["z"]) for row in csv.DictReader(f)]
    return sum(1 for v in z if v < THROAT) / len(z) if z else float("nan")


def run(binary, mode, springs, seed, frames):
    with tempfile.TemporaryDirectory() as tmp:
        scenario = os.path.join(tmp, "s.toml")
        with open(scenario, "w") as f:
            f.write(
                f'[geometry]\nmesh = "{os.path.join(ROOT, "assets", "hourglass.off")}"\n'
                f"mesh_radii = [0.002, 0.02, 0.01]\n"
                + (f'mesh_contacts = "{mode}"\n' if mode else "")
                + f"[simulation]\nseed = {seed}\nframes = {frames}\n"
                + (f'friction_springs = "{springs}"\n' if springs else "")
            )
        out = os.path.join(tmp, "out")
        p = subprocess.run(
            [binary, "--threads", "1", "run", scenario, "-o", out, "-q"],
            capture_output=True,
            text=True,
        )
        warned = re.search(r"warning: (\d+) pairs? overlapped", p.stderr)
        frame = lambda k: os.path.join(out, f"particles{k:06d}.csv")
        return {
            "seed": seed,
            "completed": p.returncode == 0,
            "warnings": int(warned.group(1)) if warned else 0,
            "frame20": share_below(frame(20)) if os.path.exists(frame(20)) else float("nan"),
            "final": share_below(frame(frames)) if p.returncode == 0 else float("nan"),
            "error": p.stderr.strip().splitlines()[0] if p.returncode else "",
        }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", default="1-20", help="e.g. 1-100 or 1,5,58")
    ap.add_argument("--mode", choices=["merged", "per_face", ""], default="merged",
                    help="mesh_contacts ('' writes no key, for builds that predate it)")
    ap.add_argument("--springs", choices=["advance_first", "paper", ""], default="",
                    help="friction_springs ('' writes no key: the build's default)")
    ap.add_argument("--binary", default=os.path.join(ROOT, "target", "release", "tinydem"))
    ap.add_argument("--frames", type=int, default=100)
    ap.add_argument("--jobs", type=int, default=2)
    a = ap.parse_args()
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
        rows = list(pool.map(lambda s: run(a.binary, a.mode, a.springs, s, a.frames), seeds(a.seeds)))
    print("seed completed warnings frame20_below final_below")
    for r in rows:
        print(f"{r['seed']:4d} {str(r['completed']):9s} {r['warnings']:8d} {r['frame20']:14.3f} "
              f"{r['final']:11.3f} {r['error']}")
    done = [r for r in rows if r["completed"]]
    stat = lambda k: (statistics.mean(r[k] for r in done), statistics.stdev(r[k] for r in done)
                      if len(done) > 1 else 0.0)
    print(f"mode {a.mode or '(none)'}, springs {a.springs or '(default)'}: {len(done)} of {len(rows)} runs completed; "
          f"{sum(r['warnings'] for r in rows)} pairs warned of in "
          f"{sum(1 for r in rows if r['warnings'])} runs")
    if done:
        print("share below the throat at frame 20: {:.3f} +- {:.3f}; at the end: {:.3f} +- {:.3f}"
              .format(*stat("frame20"), *stat("final")))
    return 0 if len(done) == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main())
