#!/usr/bin/env python3
"""Finds the arches that block the funnels of example E at the end of a run and measures their
aspect ratio, height to semi-width, as the paper reports it (about one on average, Fig. 5E):

    python3 arches.py OUTPUT_DIR [OUTPUT_DIR ...]   # the last frame of each; several runs pooled

A funnel is blocked when grains rest (speed below 1 cm/s) on both its walls and at least 50 rest
in it or on it (between its walls, up to 10 cm above its rim). Its arch is the lower edge of
that packing: the feet are the lowest grains touching the left and the right wall, the crown
the highest point of the lower envelope between them (the lowest grain centre in each one-diameter column). Height = crown above the mean height
of the feet, semi-width = half the distance of the feet, both between grain centres.

Over all frames it also counts, per funnel, the most grains it held at once below its rim (a
full funnel holds about 170-220) and the grains that fell through its throat: a funnel whose
stream passes straight through never fills, and a funnel that never fills does not arch."""
import csv, glob, math, os, statistics, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_funnels import D, PITCH, throats  # noqa: E402

REST = 0.01  # m/s
R = D / 2


def read_frame(path):
    """The grains of a frame, in id order: x, z and speed."""
    grains = []
    for r in csv.DictReader(open(path)):
        v = math.sqrt(sum(float(r[c]) ** 2 for c in ("vx", "vy", "vz")))
        grains.append((float(r["x"]), float(r["z"]), v))
    return grains


def history(frames):
    """Per funnel, over the frames: the most grains below its rim at once, and how many
    grains were seen just below its throat."""
    funnels = list(throats())
    most = [0] * len(funnels)
    through = [set() for _ in funnels]
    for path in frames:
        held = [0] * len(funnels)
        for i, (x, z, _) in enumerate(read_frame(path)):
            for k, (_, xc, zt, w) in enumerate(funnels):
                if abs(x - xc) < PITCH / 2 and zt < z < zt + (PITCH - w) / 2:
                    held[k] += 1
                if abs(x - xc) < w / 2 and zt - 10 * D < z < zt:
                    through[k].add(i)
        most = [max(a, b) for a, b in zip(most, held)]
    return most, [len(t) for t in through]


def distance_to_wall(x, z, a, b):
    """Distance of (x, z) from the segment a-b."""
    (ax, az), (bx, bz) = a, b
    t = max(0.0, min(1.0, ((x - ax) * (bx - ax) + (z - az) * (bz - az)) / ((bx - ax) ** 2 + (bz - az) ** 2)))
    return math.hypot(x - ax - t * (bx - ax), z - az - t * (bz - az))


def arches(grains, most, through):
    """Prints a row per funnel; the aspect ratio of each arch by layer."""
    print("layer  throat x [m]  width [d]  most in it  through  at rest on it  blocked  span [d]  height [d]  aspect")
    aspects = {}
    for (layer, xc, zt, w), m, t in zip(throats(), most, through):
        rim = zt + (PITCH - w) / 2
        left = ((xc - PITCH / 2, rim), (xc - w / 2, zt))
        right = ((xc + w / 2, zt), (xc + PITCH / 2, rim))
        # Resting grains in the funnel (between its walls) and on it (up to 10 cm above its rim).
        inside = [(x, z) for x, z, v in grains
                  if v < REST and zt - R < z < rim + 0.1 and abs(x - xc) < min(w / 2 + (z - zt), PITCH / 2) + R]
        on_left = [(x, z) for x, z in inside if distance_to_wall(x, z, *left) < 1.05 * R]
        on_right = [(x, z) for x, z in inside if distance_to_wall(x, z, *right) < 1.05 * R]
        blocked = len(inside) >= 50 and on_left and on_right
        row = (f"{layer:5d}  {xc:+12.3f}  {w / D:9.0f}  {m:10d}  {t:7d}  {len(inside):13d}"
               f"  {'yes' if blocked else 'no':>7}")
        if not blocked:
            print(row)
            continue
        lf, rf = min(on_left, key=lambda g: g[1]), min(on_right, key=lambda g: g[1])
        envelope = {}
        for x, z in inside:
            if lf[0] <= x <= rf[0]:
                k = int((x - lf[0]) / D)
                envelope[k] = min(envelope.get(k, math.inf), z)
        semi = (rf[0] - lf[0]) / 2
        height = max(envelope.values()) - (lf[1] + rf[1]) / 2
        aspects.setdefault(layer, []).append(height / semi)
        print(row + f"  {2 * semi / D:8.1f}  {height / D:10.1f}  {height / semi:6.2f}")
    return aspects


if len(sys.argv) < 2:
    sys.exit(__doc__)
aspects = {}
for out in sys.argv[1:]:
    frames = sorted(glob.glob(os.path.join(out, "particles*.csv")))
    if not frames:
        sys.exit(f"{out}: no frames particlesNNNNNN.csv")
    grains = read_frame(frames[-1])
    print(f"{frames[-1]}: {len(grains)} grains, {sum(v < REST for *_, v in grains)} at rest")
    for layer, a in arches(grains, *history(frames)).items():
        aspects.setdefault(layer, []).extend(a)
every = [a for layer in aspects.values() for a in layer]


def summary(name, a):
    error = f" +- {statistics.stdev(a) / math.sqrt(len(a)):.2f} (standard error)" if len(a) > 1 else ""
    print(f"{name}: {len(a)} arches, aspect ratio {statistics.mean(a):.2f}{error}")


for layer, a in sorted(aspects.items()):
    summary(f"layer {layer}", a)
if every:
    summary("all", every)
