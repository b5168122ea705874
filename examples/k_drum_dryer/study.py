#!/usr/bin/env python3
"""Example K's study: the drum dryer of scenario.toml at three speeds (1.5, 3 and 6 rad/s). For
each: the bed's mean temperature against time (from log.csv) and the wall-to-bed heat-transfer
coefficient h = Q / (A (T_w - T_bed)), Q the heat the wall gives the bed, A the drum's inner
area and T_bed its mean temperature, averaged over the second half of the run. Writes
heating.csv (time and T_mean at each speed), study.csv (speed, h) and, with --plots DIR, the
plots heating.svg and coefficient.svg (drawn by `tinydem plot`).

    python3 examples/k_drum_dryer/study.py [--out DIR] [--plots DIR]

Needs the built binary (cargo build --release), or TINYDEM_BIN; only the standard library.
"""

import csv
import math
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
BINARY = Path(os.environ.get("TINYDEM_BIN", HERE.parents[1] / "target" / "release" / "tinydem"))
SPEEDS = [1.5, 3.0, 6.0]  # rad/s
RADIUS, LENGTH, T_WALL = 0.06, 0.04, 400.0
AREA = 2.0 * math.pi * RADIUS * LENGTH + 2.0 * math.pi * RADIUS**2


def arg(name, default):
    return sys.argv[sys.argv.index(name) + 1] if name in sys.argv else default


def main():
    work = Path(arg("--out", "/tmp/tinydem-drum-dryer"))
    work.mkdir(parents=True, exist_ok=True)
    template = (HERE / "scenario.toml").read_text()
    curves, rows = {}, []
    for speed in SPEEDS:
        scenario = work / f"drum_{speed}.toml"
        scenario.write_text(template.replace("angular_velocity = 3.0", f"angular_velocity = {speed}"))
        out = work / f"drum_{speed}"
        subprocess.run([str(BINARY), "run", str(scenario), "-o", str(out), "--overwrite", "--quiet"],
                       check=True)
        with open(out / "log.csv") as f:
            log = list(csv.DictReader(f))
        curves[speed] = [(float(r["time"]), float(r["T_mean"])) for r in log[1:]]
        late = log[len(log) // 2:]
        h = sum(-float(r["mesh1_heat"]) / (AREA * (T_WALL - float(r["T_mean"]))) for r in late) / len(late)
        rows.append((speed, h, float(log[-1]["T_mean"])))
        print(f"{speed} rad/s: h = {h:.2f} W/(m^2 K), T_bed at the end {rows[-1][2]:.2f} K")
    with open(work / "heating.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time"] + [f"T_mean_{s}_rad_s" for s in SPEEDS])
        for k in range(len(curves[SPEEDS[0]])):
            w.writerow([curves[SPEEDS[0]][k][0]] + [curves[s][k][1] for s in SPEEDS])
    with open(work / "study.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["speed", "h", "T_end"])
        w.writerows(rows)
    plots = arg("--plots", None)
    if plots:
        y = ",".join(f"T_mean_{s}_rad_s" for s in SPEEDS)
        subprocess.run([str(BINARY), "plot", str(work / "heating.csv"), "-y", y, "-o",
                        str(Path(plots) / "k_heating.svg"), "--plot-size", "900x600"], check=True)
        subprocess.run([str(BINARY), "plot", str(work / "study.csv"), "-x", "speed", "-y", "h", "-o",
                        str(Path(plots) / "k_coefficient.svg"), "--plot-size", "900x600"], check=True)


if __name__ == "__main__":
    main()
