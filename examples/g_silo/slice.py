#!/usr/bin/env python3
"""Cuts the slab |y| < HALF of a frame, to look inside the silo:

    python3 slice.py discharge/particles000010.csv cut.csv [HALF=0.006]
"""
import sys

src, dst = sys.argv[1], sys.argv[2]
half = float(sys.argv[3]) if len(sys.argv) > 3 else 0.006
with open(src) as f, open(dst, "w") as out:
    header = f.readline()
    out.write(header)
    y = header.strip().split(",").index("y")
    for line in f:
        if abs(float(line.split(",")[y])) < half:
            out.write(line)
