#!/usr/bin/env python3
"""The oedometer study: fill (1_fill.toml), settle until still (2_settle.toml), then press with
the servo lid of 3_press.toml at 1, 2, 4, 8, 16 and 32 kPa and back to 4 kPa, each stage --from
the checkpoint of the one before (the lid carried where it was). For each load: the bed's height
(the lid's bottom), its strain from the height at 1 kPa, the oedometric modulus between
consecutive loads M = d(sigma) / d(strain), and the loads the floor and the ring carry. Writes
study.csv and, with --svg FILE, a plot of stress against strain.

    python3 examples/j_oedometer/study.py [--out DIR] [--svg FILE]

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
LOADS = [1000.0, 2000.0, 4000.0, 8000.0, 16000.0, 32000.0, 4000.0]
LID_START = 0.13  # the lid's bottom at rest, 3_press.toml's shape.center


def arg(name, default):
    return sys.argv[sys.argv.index(name) + 1] if name in sys.argv else default


def run(scenario, out, before=None):
    cmd = [str(BINARY), "run", str(scenario), "-o", str(out), "--overwrite", "--quiet"]
    if before is not None:
        cmd += ["--from", str(before / "checkpoint.bin")]
    subprocess.run(cmd, check=True)
    return out


def last_row(path):
    with open(path) as f:
        return list(csv.DictReader(f))[-1]


def main():
    work = Path(arg("--out", "/tmp/tinydem-oedometer"))
    work.mkdir(parents=True, exist_ok=True)
    fill = run(HERE / "1_fill.toml", work / "1_fill")
    settled = run(HERE / "2_settle.toml", work / "2_settle", fill)
    template = (HERE / "3_press.toml").read_text()
    before, rows = settled, []
    for k, stress in enumerate(LOADS):
        scenario = work / f"3_press_{k}.toml"
        scenario.write_text(template.replace("stress = 1000.0", f"stress = {stress}"))
        out = run(scenario, work / f"3_press_{k}", before)
        log, walls = last_row(out / "log.csv"), None
        with open(out / "walls.csv") as f:
            walls = [r for r in csv.DictReader(f) if r["frame"] == log["frame"]]
        # Mesh 1 the ring, 2 the floor, 3 the lid.
        ring, floor = -float(walls[1]["fz"]), -float(walls[2]["fz"])
        height = LID_START - float(log["mesh3_position"])
        rows.append(
            {
                "stress": stress,
                "load": float(log["mesh3_load"]),
                "height": height,
                "floor": floor,
                "ring": ring,
                "time": float(log["time"]),
                "ended": log.get("until", ""),
            }
        )
        before = out
    h1 = rows[0]["height"]
    for k, r in enumerate(rows):
        r["strain"] = (h1 - r["height"]) / h1
        if k > 0:
            p = rows[k - 1]
            r["modulus"] = (r["stress"] - p["stress"]) / (r["strain"] - p["strain"])
        else:
            r["modulus"] = float("nan")
    keys = ["stress", "load", "height", "strain", "modulus", "floor", "ring", "time", "ended"]
    with open(work / "study.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    print(f"{'stress [Pa]':>12} {'lid [N]':>9} {'height [mm]':>12} {'strain':>9} {'M [MPa]':>9} {'floor [N]':>10} {'ring [N]':>9}")
    for r in rows:
        print(
            f"{r['stress']:12.0f} {r['load']:9.4f} {1e3 * r['height']:12.4f} {r['strain']:9.5f}"
            f" {r['modulus'] / 1e6:9.3f} {r['floor']:10.4f} {r['ring']:9.4f}"
        )
    svg = arg("--svg", None)
    if svg:
        Path(svg).write_text(plot(rows))
    print(f"table in {work / 'study.csv'}")


def nice(step):
    """The round step (1, 2 or 5 times a power of ten) at least `step`."""
    power = 10 ** math.floor(math.log10(step))
    return next(m * power for m in (1, 2, 5, 10) if m * power >= step)


def plot(rows):
    """Stress against strain as an SVG: loading in one colour, the unloading step in another."""
    w, h, left, bottom = 640, 420, 80, 60
    xs = [100 * r["strain"] for r in rows]
    ys = [r["stress"] / 1000 for r in rows]
    xstep, ystep = nice(max(xs) / 5), nice(max(ys) / 5)
    xmax = xstep * (int(max(xs) / xstep) + 1)
    ymax = ystep * (int(max(ys) / ystep) + 1)
    px = lambda x: left + (w - left - 20) * x / xmax
    py = lambda y: h - bottom - (h - bottom - 20) * y / ymax
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="14">']
    out.append(f'<rect width="{w}" height="{h}" fill="white"/>')
    out.append(f'<line x1="{left}" y1="{h - bottom}" x2="{w - 20}" y2="{h - bottom}" stroke="black"/>')
    out.append(f'<line x1="{left}" y1="{h - bottom}" x2="{left}" y2="20" stroke="black"/>')
    for k in range(int(round(xmax / xstep)) + 1):
        x = xstep * k
        out.append(f'<text x="{px(x):.1f}" y="{h - bottom + 20}" text-anchor="middle">{x:g}</text>')
    for k in range(int(round(ymax / ystep)) + 1):
        y = ystep * k
        out.append(f'<text x="{left - 8}" y="{py(y) + 5:.1f}" text-anchor="end">{y:g}</text>')
    out.append(f'<text x="{(w + left) / 2}" y="{h - 15}" text-anchor="middle">strain from the bed at 1 kPa [%]</text>')
    out.append(f'<text x="20" y="{(h - bottom) / 2}" text-anchor="middle" transform="rotate(-90 20 {(h - bottom) / 2})">stress [kPa]</text>')
    load = " ".join(f"{px(x):.1f},{py(y):.1f}" for x, y in zip(xs[:-1], ys[:-1]))
    out.append(f'<polyline points="{load}" fill="none" stroke="#1f5fa8" stroke-width="2"/>')
    un = " ".join(f"{px(x):.1f},{py(y):.1f}" for x, y in zip(xs[-2:], ys[-2:]))
    out.append(f'<polyline points="{un}" fill="none" stroke="#c0392b" stroke-width="2" stroke-dasharray="6 4"/>')
    for x, y in zip(xs, ys):
        out.append(f'<circle cx="{px(x):.1f}" cy="{py(y):.1f}" r="4" fill="#1f5fa8"/>')
    out.append(f'<text x="{left + 20}" y="40" fill="#1f5fa8">loading 1 to 32 kPa</text>')
    out.append(f'<text x="{left + 20}" y="60" fill="#c0392b">unloading to 4 kPa</text>')
    out.append("</svg>")
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    main()
