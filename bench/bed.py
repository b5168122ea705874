#!/usr/bin/env python3
"""A settled bed of N = 100000 or 1000000 grains (the benchmark's 10^5 packing, tiled 5 x 2 for
10^6) in an open box, as a scenario that runs for long: for the stop and soak measurements.

    python3 bench/bed.py 1000000 /tmp/bed     # writes /tmp/bed/bed1000000.{toml,csv,off}
"""
import gzip
import os
import sys

n, out = int(sys.argv[1]), sys.argv[2]
tiles = {100000: (1, 1), 1000000: (5, 2)}[n]
here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "n100000")
edge = float(open(os.path.join(here, "edge.txt")).read())
lines = gzip.open(os.path.join(here, "settled.csv.gz"), "rt").read().splitlines()
os.makedirs(out, exist_ok=True)
with open(os.path.join(out, f"bed{n}.csv"), "w") as f:
    f.write(lines[0] + "\n")
    for ix in range(tiles[0]):
        for iy in range(tiles[1]):
            for line in lines[1:]:
                c = line.split(",")
                c[0] = repr(float(c[0]) + ix * edge)
                c[1] = repr(float(c[1]) + iy * edge)
                f.write(",".join(c) + "\n")
lx, ly, lz = tiles[0] * edge, tiles[1] * edge, edge
with open(os.path.join(out, f"bed{n}.off"), "w") as f:
    f.write(
        f"OFF\n8 5 0\n0 0 0\n{lx} 0 0\n{lx} {ly} 0\n0 {ly} 0\n0 0 {lz}\n{lx} 0 {lz}\n{lx} {ly} {lz}\n"
        f"0 {ly} {lz}\n4 0 1 2 3\n4 0 3 7 4\n4 1 2 6 5\n4 0 1 5 4\n4 3 2 6 7\n"
    )
frames = int(os.environ.get("FRAMES", "100000"))
steps = int(os.environ.get("STEPS_PER_FRAME", "100"))
with open(os.path.join(out, f"bed{n}.toml"), "w") as f:
    f.write(
        f"""[geometry]
radius_min = 0.004
radius_max = 0.005
mesh = "bed{n}.off"
mesh_radii = [0.0]
[material]
youngs_modulus = 1e6
restitution = 0.5
friction_sliding = 0.3
friction_rolling = 0.3
[simulation]
max_particles = 0
spawn_attempts = 0
frames = {frames}
steps_per_frame = {steps}
[input]
particles = "bed{n}.csv"
"""
    )
