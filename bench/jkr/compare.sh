#!/bin/sh
# JKR's energy loss against LAMMPS (apt-get install lammps): two elastic spheres meet at 1.2
# times tinydem's sticking speed v_s (contact held to the separation delta_c, Thornton's); the
# energy balance of each criterion (parting at delta_c, or at the pull-off force as LAMMPS
# parts) against LAMMPS's relative speed after the impact.
set -e
cd "$(dirname "$0")"
python3 - > balance <<'PY'
import math
R, E, nu, w, rho = 0.005, 1e7, 0.3, 0.5, 2500.0
m = rho * 4 / 3 * math.pi * R**3
e_star, r_star, m_star = E / (2 * (1 - nu * nu)), R / 2, m / 2
c = math.sqrt(2 * math.pi * w / e_star)
A = lambda x: 8 / 15 * x**10 - 4 / 3 * x**7 + 0.5 * x**4
work = lambda x: -2 * math.pi * w * (c * r_star) ** (4 / 3) * (A(1) - A(x))
v_s = math.sqrt(2 * work(0.25 ** (1 / 3)) / m_star)
v0 = 1.2 * v_s
print(v0)
print(f"v_s {v_s:.7e}; after, parting at delta_c: {math.sqrt(v0**2 - v_s**2):.7e}, "
      f"at the pull-off force: {math.sqrt(v0**2 - 2 * work(0.75 ** (1 / 3)) / m_star):.7e}")
PY
tail -1 balance
lmp -in in.lammps -var v0 "$(head -1 balance)" -log none 2>/dev/null | awk '$1 == 200000 { print "LAMMPS, relative speed after: " $2 }' || true
rm balance
