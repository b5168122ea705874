#!/usr/bin/env python3
"""The tangential restitution of a soft oblique impact as the time step shrinks, for both
Coulomb tests (`tangential_coulomb` "total", the paper's Eq. 55, and "spring", LIGGGHTS's):
a grain (R 5 mm, rho 2500, E 1 MPa, nu 0.3, e 0.5, mu 0.4) meets a rigid floor at v_n = 1 m/s,
v_t = 4 m/s, without spin or gravity; e_t = (v_x - R w_y) after / before, at dt = Eq. 50 x f.

    python3 bench/coulomb/convergence.py [TINYDEM]    (default target/release/tinydem)
"""
import csv, glob, math, os, subprocess, sys, tempfile
R=0.005; E=1e6; rho=2500; nu=0.3
eq50 = R*math.sqrt(rho*(1-nu*nu)/E)
binary = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else "target/release/tinydem")
os.chdir(tempfile.mkdtemp())
open("floor.off","w").write("OFF\n4 1 0\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n4 0 1 2 3\n")
open("input.csv","w").write("x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n0,0,0.005000001,0.005,4,0,-1,1,0,0,0,0,0,0\n")
print("dt / Eq. 50: " + " ".join("%7s" % f for f in [1.0,0.3,0.1,0.03,0.01,0.003,0.001,0.0003]))
for coulomb in ["total","spring"]:
  for order in ["advance_first"]:
    row=[]
    for f in [1.0,0.3,0.1,0.03,0.01,0.003,0.001,0.0003]:
        dt=eq50*f
        steps=int(0.01/dt)
        open("s.toml","w").write(f"""[geometry]
radius_min = {R}
radius_max = {R}
mesh = "floor.off"
mesh_radii = [0.0]
[material]
density = {rho}
youngs_modulus = {E}
poisson_ratio = {nu}
restitution = 0.5
friction_sliding = 0.4
friction_rolling = 0.0
friction_twisting = 0.0
tangential_coulomb = "{coulomb}"
[kinetics]
gravity = [0.0, 0.0, 0.0]
[simulation]
timestep = {dt}
frames = 1
steps_per_frame = {steps}
max_particles = 0
spawn_attempts = 0
friction_springs = "{order}"
[input]
particles = "input.csv"
[domain]
min = [-1, -1, -1]
max = [1, 1, 1]
""")
        subprocess.run([binary,"run","s.toml","--output","out","--quiet","--force","--overwrite"],check=True)
        last=sorted(glob.glob("out/particles*.csv"))[-1]
        r=next(csv.DictReader(open(last)))
        vc=float(r["vx"])-R*float(r["wy"])
        row.append(vc/4.0)
    print("%-12s" % coulomb + " ".join("%7.4f" % x for x in row))
