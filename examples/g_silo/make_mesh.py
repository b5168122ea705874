#!/usr/bin/env python3
"""Writes the meshes of the silo example (OFF): a cylindrical wall, a flat floor with a
central orifice, and the plug that closes the orifice while the silo fills.

    python3 make_mesh.py      # writes silo_wall.off, silo_floor.off, plug.off here
"""
import math

D, H, D0, N = 0.10, 0.20, 0.03, 48  # silo diameter, height, orifice diameter, segments


def ring(r, z):
    return [(r * math.cos(2 * math.pi * k / N), r * math.sin(2 * math.pi * k / N), z) for k in range(N)]


def write(name, vertices, faces, comment):
    with open(name, "w") as f:
        f.write(f"OFF\n# {comment}\n{len(vertices)} {len(faces)} 0\n")
        for v in vertices:
            f.write("%.9g %.9g %.9g\n" % v)
        for face in faces:
            f.write(f"{len(face)} " + " ".join(map(str, face)) + "\n")


bottom, top = ring(D / 2, 0.0), ring(D / 2, H)
write("silo_wall.off", bottom + top,
      [(k, (k + 1) % N, N + (k + 1) % N, N + k) for k in range(N)],
      f"cylindrical silo wall, diameter {D} m, height {H} m, {N} rectangles")
outer, inner = ring(D / 2, 0.0), ring(D0 / 2, 0.0)
write("silo_floor.off", outer + inner,
      [t for k in range(N) for t in ((k, (k + 1) % N, N + (k + 1) % N), (k, N + (k + 1) % N, N + k))],
      f"flat floor with a central orifice of diameter {D0} m, {2 * N} triangles")
write("plug.off", [(0.0, 0.0, 0.0)] + ring(D0 / 2 * 1.02, 0.0),
      [(0, 1 + k, 1 + (k + 1) % N) for k in range(N)],
      f"disk closing the orifice (diameter {D0 * 1.02:.4g} m), {N} triangles")
