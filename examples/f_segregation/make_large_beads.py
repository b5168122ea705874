#!/usr/bin/env python3
"""Writes large_beads.csv: the seven large beads (R = 10 R_min = 20 mm) of example F at random
places on the floor of the cylinder (inner radius 39 R_min = 78 mm), 0.5 mm above the base,
not touching each other or the wall. Random sequential placement, seeded, so the file is the
same on every machine; a draw that leaves no room for all seven starts again.

    python3 make_large_beads.py [SEED=7]
"""
import math, random, sys

R, CYLINDER, COUNT, GAP = 0.02, 0.078, 7, 0.0005
rng = random.Random(int(sys.argv[1]) if len(sys.argv) > 1 else 7)
reach = CYLINDER - R - GAP  # the largest distance of a centre from the axis
while True:
    beads = []
    for _ in range(10000):
        r, phi = reach * math.sqrt(rng.random()), 2 * math.pi * rng.random()
        x, y = r * math.cos(phi), r * math.sin(phi)
        if all(math.hypot(x - a, y - b) >= 2 * R + GAP for a, b in beads):
            beads.append((x, y))
            if len(beads) == COUNT:
                break
    if len(beads) == COUNT:
        break
with open("large_beads.csv", "w") as f:
    f.write("x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n")
    for x, y in beads:
        f.write(f"{x:.6f},{y:.6f},{R + GAP},{R},0,0,0,1,0,0,0,0,0,0\n")
print(f"{len(beads)} beads: " + ", ".join(f"({x:+.4f}, {y:+.4f})" for x, y in beads))
