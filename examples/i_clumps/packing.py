"""Example I: random packings of dimers against the published curve.

Pours 2,000 dimers (two spheres of radius r, centres d apart: aspect ratio
alpha = (2r + d) / 2r) into a box, without friction and with (mu = 0.5), for alpha from
1.0 (spheres) to 2.0 (touching spheres), and measures the packing fraction of the bulk:
the dimers whose centre lies 3 diameters from the walls, 2 above the floor and 3 below the
surface, each with the volume of its union (two spheres less their lens). Writes
packing.csv (alpha and the packing fraction without and with friction) and
docs/book/src/pictures/i_packing.svg (with `tinydem plot`; TINYDEM_BIN, else target/release/tinydem).

    python3 -m pip install ./python     # once
    python3 examples/i_clumps/packing.py

Published, frictionless: spheres near random close packing, 0.64; dimers denser, with a
maximum near alpha = 1.4-1.5 of about 0.70 (Donev et al. 2004 for ellipsoids; Faure,
Lefebvre-Lepot & Semin 2009 and Baule et al. 2013 for dimers: mean field 0.707 at its
maximum), falling back towards 0.64-0.66 at touching dimers.
"""

import math
import os
import subprocess
from pathlib import Path

import numpy as np

import tinydem

HERE = Path(__file__).resolve().parent
R = 0.004


def scenario(alpha: float, mu: float) -> str:
    """packing.toml with the dimer of aspect ratio alpha and friction mu."""
    text = (HERE / "packing.toml").read_text()
    d = 2 * R * (alpha - 1)
    text = text.replace(
        "spheres = [[0.0, 0.0, 0.0, 0.004], [0.004, 0.0, 0.0, 0.004]]",
        f"spheres = [[0.0, 0.0, 0.0, {R}], [{d!r}, 0.0, 0.0, {R}]]",
    )
    text = text.replace("friction_sliding = 0.0", f"friction_sliding = {mu}")
    return text.replace('dir = "output_packing"', f'dir = "packing/a{alpha:.1f}_mu{mu}"')


def volume(alpha: float) -> float:
    """The union of two spheres of radius R, centres d apart."""
    d = 2 * R * (alpha - 1)
    lens = math.pi / 12 * (4 * R + d) * (2 * R - d) ** 2
    return 2 * 4 / 3 * math.pi * R**3 - lens


def bulk_fraction(frame: dict, alpha: float) -> tuple:
    """Packing fraction of the dimers whose centre is in the bulk, and their count."""
    x, y, z = frame["x"], frame["y"], frame["z"]
    margin = 3 * 2 * R
    top = np.percentile(z, 98) - margin
    inside = (abs(x) < 0.05 - margin) & (abs(y) < 0.05 - margin) & (z > 4 * R) & (z < top)
    box = (0.1 - 2 * margin) ** 2 * (top - 4 * R)
    n = int(inside.sum())
    return n * volume(alpha) / box, n


def main() -> None:
    rows = []
    for mu in (0.0, 0.5):
        for alpha in (1.0, 1.2, 1.4, 1.5, 1.6, 1.8, 2.0):
            path = HERE / "packing" / f"a{alpha:.1f}_mu{mu}.toml"
            path.parent.mkdir(exist_ok=True)
            path.write_text(scenario(alpha, mu).replace('dir = "packing/', 'dir = "'))
            out = tinydem.run(path, overwrite=True)
            frames = sorted(Path(out).glob("particles*.csv"))
            phi, n = bulk_fraction(tinydem.read_frame(frames[-1]), alpha)
            rows.append((alpha, mu, phi, n))
            print(f"alpha {alpha:.1f}  mu {mu}  phi {phi:.4f}  ({n} dimers in the bulk)")
    table = HERE / "packing.csv"
    alphas = sorted({a for a, _, _, _ in rows})
    phi = {(a, m): p for a, m, p, _ in rows}
    table.write_text(
        "alpha,phi_frictionless,phi_friction_0.5\n"
        + "".join(f"{a},{phi[(a, 0.0)]:.5f},{phi[(a, 0.5)]:.5f}\n" for a in alphas)
    )
    binary = os.environ.get("TINYDEM_BIN", str(HERE.parents[1] / "target" / "release" / "tinydem"))
    subprocess.run(
        [binary, "plot", str(table), "-x", "alpha", "-y", "phi_frictionless,phi_friction_0.5"]
        + ["-o", str(HERE.parents[1] / "docs" / "book" / "src" / "pictures" / "i_packing.svg")],
        check=True,
    )

if __name__ == "__main__":
    main()
