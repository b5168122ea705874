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
materials = col("material").reshape(-1) if "material" in rows[0] else np.zeros(len(rows))
checks["material"] = (m.point_data["material"].reshape(-1).astype(float), materials)
if "id" in rows[0]:
    checks["id"] = (m.point_data["id"].reshape(-1).astype(float), col("id").reshape(-1))
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

# The contact network: a line per contact, with the CSV's overlaps and force magnitudes.
# meshio does not read .vtp: the file's raw appended arrays are read here (the same writer
# as the .vtu frames above, which meshio checks).
def read_vtp(path):
    data = open(path, "rb").read()
    head, _, rest = data.partition(b"<AppendedData encoding=\"raw\">")
    blob = rest[rest.index(b"_") + 1:]
    root = ET.fromstring(head.decode() + "</VTKFile>")
    assert root.get("type") == "PolyData", root.get("type")
    piece = root.find("PolyData/Piece")
    types = {"Float64": "<f8", "Int64": "<i8", "UInt32": "<u4", "UInt8": "u1"}
    arrays = {}
    for a in piece.iter("DataArray"):
        at = int(a.get("offset"))
        size = int.from_bytes(blob[at:at + 8], "little")
        arrays[a.get("Name")] = np.frombuffer(blob[at + 8:at + 8 + size], dtype=types[a.get("type")])
    return int(piece.get("NumberOfLines")), arrays

n_lines, net = read_vtp(f"{out}/contacts{k:06d}.vtp")
crows = list(csv.DictReader(open(f"{out}/contacts{k:06d}.csv")))
assert len(crows) > 0, "no contacts"
assert n_lines == len(crows) and len(net["offsets"]) == len(crows), (n_lines, len(crows))
assert np.array_equal(net["offsets"], 2 * np.arange(1, len(crows) + 1))
ccol = lambda *names: np.array([[float(r[c]) for c in names] for r in crows])
assert np.array_equal(net["overlap"], ccol("overlap").reshape(-1))
fn = np.linalg.norm(ccol("fn_x", "fn_y", "fn_z"), axis=1)
assert np.allclose(net["normal_force"], fn, rtol=1e-12, atol=0)
points = net["points"].reshape(-1, 3)
faces = net["face"]
walls = faces >= 0
assert np.array_equal(points[1::2][walls], ccol("x", "y", "z")[walls]), "contact points"
assert np.array_equal(faces, ccol("face").reshape(-1)), "face index per line"
print(f"contacts: {len(crows)} lines, {int((faces >= 0).sum())} with faces")

times = [float(d.get("timestep")) for d in ET.parse(f"{out}/particles.pvd").getroot().iter("DataSet")]
assert len(times) == k + 1 and times[0] == 0.0 and all(b > a for a, b in zip(times, times[1:])), times
print(f"ok: {len(rows)} particles, {len(checks)} arrays identical to the CSV, {len(times)} frames in the pvd")
