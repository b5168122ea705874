#!/usr/bin/env python3
"""Reads tinydem's VTK output with meshio (a real VTK reader) and compares it with the CSV
frame of the same step. Usage: vtk_check.py OUTPUT_DIR FRAME. Exit 0 when all values match."""
import csv, sys, xml.etree.ElementTree as ET
import meshio, numpy as np

out, k = sys.argv[1], int(sys.argv[2])
m = meshio.read(f"{out}/particles{k:06d}.vtu")
rows = list(csv.DictReader(open(f"{out}/particles{k:06d}.csv")))
col = lambda *names: np.array([[float(r[c]) for c in names] for r in rows])
checks = {
    "points": (m.points, col("x", "y", "z")),
    "radius": (m.point_data["radius"].reshape(-1), col("R").reshape(-1)),
    "velocity": (m.point_data["velocity"], col("vx", "vy", "vz")),
    "angular_velocity": (m.point_data["angular_velocity"], col("wx", "wy", "wz")),
    "orientation": (m.point_data["orientation"], col("q0", "q1", "q2", "q3")),
}
tags = col("tag").reshape(-1) if "tag" in rows[0] else np.zeros(len(rows))
checks["tag"] = (m.point_data["tag"].reshape(-1).astype(float), tags)
assert len(rows) > 0, "empty frame"
for name, (vtk, ref) in checks.items():
    assert vtk.shape == ref.shape, (name, vtk.shape, ref.shape)
    assert np.array_equal(vtk, ref), f"{name} differs: max {np.abs(vtk - ref).max()}"
assert sum(len(c.data) for c in m.cells) == len(rows), "one vertex cell per particle"

mesh = meshio.read(f"{out}/mesh.vtu")
kinds = sorted((c.type, len(c.data)) for c in mesh.cells)
print("mesh cells", kinds)
assert ("quad", 5) in kinds, kinds
assert np.all(mesh.cell_data["radius"][0] >= 0)

times = [float(d.get("timestep")) for d in ET.parse(f"{out}/particles.pvd").getroot().iter("DataSet")]
assert len(times) == k + 1 and times[0] == 0.0 and all(b > a for a, b in zip(times, times[1:])), times
print(f"ok: {len(rows)} particles, {len(checks)} arrays identical to the CSV, {len(times)} frames in the pvd")
