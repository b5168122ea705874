#!/usr/bin/env python3
"""Writes funnels.off: a 2D container (the grains move in the plane y = 0) 0.48 m wide holding
three layers of four lined-up funnels each, with walls at 45 degrees and throats of 10, 8 and 6
grain diameters (d = 4 mm), the layout of the paper's Fig. 5E. The funnels of a layer meet at
ridges; the layers' throats are at z = 0.56, 0.38 and 0.20 m, the floor at z = 0.

    python3 make_funnels.py    # prints the throats (layer, centre x, z, width) it wrote
"""
D = 0.004  # grain diameter
WIDTH, PITCH = 0.48, 0.12  # container and funnel width
LAYERS = [(0.56, 10 * D), (0.38, 8 * D), (0.20, 6 * D)]  # throat height and width
HEIGHT, Y = 1.0, 0.01  # container height; the faces span -Y..Y across the plane


def quad(a, b):
    """A rectangle spanning y = -Y..Y over the segment from a to b in the x-z plane."""
    (x0, z0), (x1, z1) = a, b
    return [(x0, -Y, z0), (x1, -Y, z1), (x1, Y, z1), (x0, Y, z0)]


def throats():
    n = round(WIDTH / PITCH)
    for layer, (z, w) in enumerate(LAYERS, start=1):
        for k in range(n):
            yield layer, -WIDTH / 2 + (k + 0.5) * PITCH, z, w


faces = [
    quad((-WIDTH / 2, 0), (WIDTH / 2, 0)),  # floor
    quad((-WIDTH / 2, 0), (-WIDTH / 2, HEIGHT)),  # side walls
    quad((WIDTH / 2, 0), (WIDTH / 2, HEIGHT)),
]
for _, xc, z, w in throats():
    rim = z + (PITCH - w) / 2  # 45-degree walls up to the ridges
    faces.append(quad((xc - PITCH / 2, rim), (xc - w / 2, z)))
    faces.append(quad((xc + w / 2, z), (xc + PITCH / 2, rim)))

if __name__ == "__main__":
    with open("funnels.off", "w") as f:
        f.write("OFF\n# 2D jamming: three layers of four funnels, throats of 10, 8 and 6 diameters"
                " (make_funnels.py)\n")
        f.write(f"{4 * len(faces)} {len(faces)} 0\n")
        for face in faces:
            for v in face:
                f.write("%.6g %.6g %.6g\n" % v)
        for k in range(len(faces)):
            f.write("4 %d %d %d %d\n" % tuple(range(4 * k, 4 * k + 4)))
    for t in throats():
        print("layer %d  x = %+.2f  z = %.2f  width %.3f" % t)
