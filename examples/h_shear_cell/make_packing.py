#!/usr/bin/env python3
"""Writes initial.csv for the shear cell: 12 x 12 x 12 grains of radius 2 mm on a jittered
cubic lattice filling the periodic box of 0.05 m (solid fraction 0.46), glass and rubber
alternating like a 3D checkerboard, moving with the imposed shear profile v_x = V z / L.

    python3 make_packing.py
"""
import random

L, n, R, V = 0.05, 12, 0.002, 0.25
a = L / n
random.seed(1)
with open("initial.csv", "w") as f:
    f.write("x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,material\n")
    for i in range(n):
        for j in range(n):
            for k in range(n):
                x = [-L / 2 + a * (c + 0.5) + random.uniform(-0.05, 0.05) * a for c in (i, j, k)]
                f.write(f"{x[0]:.9g},{x[1]:.9g},{x[2]:.9g},{R},{V * x[2] / L:.9g},0,0,1,0,0,0,0,0,0,{(i + j + k) % 2}\n")
