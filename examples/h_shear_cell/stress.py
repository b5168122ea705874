#!/usr/bin/env python3
"""Velocity profile and stress of the sheared packing, averaged over the last frames:

    python3 stress.py OUTPUT_DIR [FRAMES=20]

The stress (compression positive) is sigma_ab = -(1/V) sum over contacts of l_a f_b, with l
the branch vector from grain i to grain j (twice the lever to the contact point, so the
minimum image across the periodic and sheared sides is implied) and f the force on grain i,
plus the kinetic part (1/V) sum m u_a u_b with u the velocity relative to the imposed profile.
Pressure p = tr(sigma)/3, effective friction mu = -sigma_xz / sigma_zz, inertial number
I = gamma_dot d / sqrt(p / rho_grains)."""
import csv, glob, math, sys

out = sys.argv[1]
last = int(sys.argv[2]) if len(sys.argv) > 2 else 20
L, V = 0.05, 0.25
rho = [2500.0, 1100.0]
frames = sorted(glob.glob(f"{out}/particles*.csv"))[-last:]
sig = [[0.0] * 3 for _ in range(3)]
layers = [[0.0, 0] for _ in range(5)]
pairs = {}
for f in frames:
    k = int(f[-10:-4])
    p = {int(r["id"]): r for r in csv.DictReader(open(f))}
    x = {i: [float(r[c]) for c in "xyz"] for i, r in p.items()}
    for i, r in p.items():
        z = x[i][2]
        u = [float(r["vx"]) - V * z / L, float(r["vy"]), float(r["vz"])]
        m = 4 / 3 * math.pi * rho[int(r["material"])] * float(r["R"]) ** 3
        for a in range(3):
            for b in range(3):
                sig[a][b] += m * u[a] * u[b] / L**3 / len(frames)
        layer = min(4, int((z + L / 2) / (L / 5)))
        layers[layer][0] += float(r["vx"])
        layers[layer][1] += 1
    for c in csv.DictReader(open(f"{out}/contacts{k:06d}.csv")):
        i, j = int(c["id_i"]), int(c["id_j"])
        if j < 0:
            continue
        ci = [float(c[a]) for a in "xyz"]
        # branch vector: twice the lever from i to the contact point
        l = [2 * (ci[a] - x[i][a]) for a in range(3)]
        fo = [float(c["fn_" + a]) + float(c["ft_" + a]) for a in "xyz"]
        for a in range(3):
            for b in range(3):
                sig[a][b] -= l[a] * fo[b] / L**3 / len(frames)
        key = tuple(sorted((int(p[i]["material"]), int(p[j]["material"]))))
        pairs[key] = pairs.get(key, 0) + 1
pressure = (sig[0][0] + sig[1][1] + sig[2][2]) / 3
inertial = (V / L) * 0.004 / math.sqrt(pressure / (0.5 * (rho[0] + rho[1])))
print(f"frames {len(frames)}; velocity by layer (imposed profile V z / L):")
for n, (s, c) in enumerate(layers):
    z = -L / 2 + (n + 0.5) * L / 5
    print(f"  z = {z * 1000:6.1f} mm: vx = {s / c:7.4f} m/s (imposed {V * z / L:7.4f})")
print(f"pressure {pressure:.3f} Pa, shear stress sigma_xz {sig[0][2]:.3f} Pa, "
      f"effective friction {-sig[0][2] / sig[2][2]:.3f}, inertial number {inertial:.2f}")
names = ["glass", "rubber"]
total = sum(pairs.values())
for (a, b), n in sorted(pairs.items()):
    print(f"  {names[a]}-{names[b]} contacts: {n / len(frames):.0f} per frame ({100 * n / total:.0f} %)")
