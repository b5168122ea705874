#!/usr/bin/env python3
"""Remakes the guide's pictures (docs/book/src/pictures): runs the default simulation and every example (about an hour
on 2 cores, most of it D's 20,000-grain pile and F at the paper's size), then draws them with
the renderer. Needs the Python package
(`python3 -m pip install ./python`), the built binary (`cargo build --release`, for
`analyze --plot`) and, for the pictures of two panels, ffmpeg (its hstack filter).

    python3 docs/pictures.py [--reuse] [NAME ...]   # all, or some of: hourglass b c d e f g h j k

(--reuse: draw from the runs already in /tmp/tinydem-pictures.)

Runs go to /tmp/tinydem-pictures/NAME; pictures to docs/book/src/pictures/.
"""

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

import tinydem

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs" / "book" / "src" / "pictures"
EXAMPLES = ROOT / "examples"
WORK = Path("/tmp/tinydem-pictures")
BINARY = ROOT / "target" / "release" / "tinydem"


REUSE = "--reuse" in sys.argv


def run(name, scenario, **kw):
    out = WORK / name
    if REUSE and (out / "checkpoint.bin").is_file():
        return out
    print(f"running {scenario} into {out}", flush=True)
    return Path(tinydem.run(scenario, output=out, overwrite=True, **kw))


def frame_at(out, t):
    """The number of the frame of `out` nearest the time t [s]."""
    o = tinydem.read_output(out)
    return int(o.numbers[int(np.argmin(np.abs(o.times - t)))])


def frame(out, k):
    return out / f"particles{k:06d}.csv"


def select(out, k, into, keep):
    """The particles of frame k of `out` for which keep(column -> value) holds, as frame k of
    the directory `into` (so that it keeps its frame number and so its time)."""
    into.mkdir(parents=True, exist_ok=True)
    src = frame(out, k)
    dst = into / src.name
    with open(src) as f, open(dst, "w") as g:
        header = f.readline()
        g.write(header)
        names = header.strip().split(",")
        for line in f:
            if keep(dict(zip(names, map(float, line.split(","))))):
                g.write(line)
    return dst


def cut(out, k, half, into):
    """The slab |y| < half of frame k of `out`."""
    return select(out, k, into, lambda p: abs(p["y"]) < half)


def side_by_side(left, right, target):
    subprocess.run(
        ["ffmpeg", "-y", "-loglevel", "error", "-i", str(left), "-i", str(right),
         "-filter_complex", "hstack", str(target)],
        check=True,
    )


def picture(src, target, **kw):
    tinydem.render(src, output=target, **kw)
    print(f"  {target}")


def hourglass():
    out = run("hourglass", EXAMPLES / "a_hourglass" / "scenario.toml")
    picture(frame(out, 100), DOCS / "hourglass.png", color="height", scale_bar=True)
    target = DOCS / "hourglass_energy.svg"
    subprocess.run(
        [str(BINARY), "plot", str(out / "log.csv"), "-y", "kinetic_energy,rotational_energy",
         "--log-y", "-o", str(target)],
        check=True,
    )


def off_bounds(path):
    """The box around the vertices of an OFF mesh: the view of a picture that shows all of
    it (render fits the view to the particles unless given bounds)."""
    lines = [l for l in Path(path).read_text().splitlines() if l.strip() and not l.startswith("#")]
    n = int(lines[1].split()[0])
    v = np.array([[float(t) for t in l.split()[:3]] for l in lines[2:2 + n]])
    return tuple(v.min(axis=0)), tuple(v.max(axis=0))


def b():
    out = run("b", EXAMPLES / "b_mixture" / "scenario.toml")
    picture(frame(out, 30), DOCS / "b_mixture.png", color="tag", view="front",
            width=400, height=600, scale_bar=True,
            bounds=off_bounds(EXAMPLES / "b_mixture" / "separator.off"))


def c():
    out = run("c", EXAMPLES / "c_marble_run" / "scenario.toml")
    picture(frame(out, frame_at(out, 7.6)), DOCS / "c_marble_run.png", width=640,
            height=540, scale_bar=True,
            bounds=off_bounds(EXAMPLES / "c_marble_run" / "course.off"))


def d():
    out = run("d", EXAMPLES / "d_pile" / "pile_20000.toml")
    picture(frame(out, int(tinydem.read_output(out).numbers[-1])), DOCS / "d_pile.png",
            color="height", view="front", width=720, height=420, scale_bar=True)


def e():
    out = run("e", EXAMPLES / "e_jamming" / "scenario.toml")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        style = dict(view="front", width=400, height=720, range=(0.0, 1.0), scale_bar=True)
        picture(frame(out, frame_at(out, 0.6)), tmp / "l.png", **style)
        picture(frame(out, int(tinydem.read_output(out).numbers[-1])), tmp / "r.png", **style)
        side_by_side(tmp / "l.png", tmp / "r.png", DOCS / "e_jamming.png")


def cutaway(out, k, into):
    """Frame k of `out` with the large beads and only the small beads in the back half of
    the cylinder (y > 30 mm), so that the front view shows the large beads inside the bed."""
    return select(out, k, into, lambda p: p["R"] > 0.01 or p["y"] > 0.03)


def f():
    out = run("f", EXAMPLES / "f_segregation" / "scenario.toml")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        style = dict(color="radius", view="front", width=400, height=480, scale_bar=True,
                     bounds=((-0.08, -0.08, -0.005), (0.08, 0.08, 0.16)), scenario=out / "run.toml")
        last = int(tinydem.read_output(out).numbers[-1])
        picture(cutaway(out, 1, tmp / "l"), tmp / "l.png", **style)
        picture(cutaway(out, last, tmp / "r"), tmp / "r.png", **style)
        side_by_side(tmp / "l.png", tmp / "r.png", DOCS / "f_segregation.png")
    subprocess.run(
        [str(BINARY), "analyze", str(out), "--large", "0.02", "--plot",
         str(DOCS / "f_heights.png"), "--column", "large_mean_height"],
        check=True, stdout=subprocess.DEVNULL,
    )


def g():
    fill = run("g1", EXAMPLES / "g_silo" / "1_fill.toml")
    out = run("g2", EXAMPLES / "g_silo" / "2_discharge.toml",
              from_checkpoint=fill / "checkpoint.bin")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        style = dict(color="tag", view="front", width=420, height=600,
                     scenario=out / "run.toml", scale_bar=True)
        for side, t in (("l", 0.95), ("r", 2.4)):
            k = frame_at(out, t)
            picture(cut(out, k, 0.006, tmp / side), tmp / f"{side}.png", **style)
        side_by_side(tmp / "l.png", tmp / "r.png", DOCS / "g_silo.png")


def h():
    out = run("h", EXAMPLES / "h_shear_cell" / "scenario.toml")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        k = int(tinydem.read_output(out).numbers[-1])
        src = cut(out, k, 0.006, tmp / "cut")
        style = dict(view="front", width=480, height=420, scenario=out / "run.toml")
        picture(src, tmp / "l.png", color="material", **style)
        picture(src, tmp / "r.png", color="speed", **style)
        side_by_side(tmp / "l.png", tmp / "r.png", DOCS / "h_shear_cell.png")


def j():
    """The oedometer study: its script runs the stages; the bed at 32 kPa, and stress against
    strain (an SVG the script draws)."""
    out = WORK / "j"
    if not (REUSE and (out / "study.csv").is_file()):
        subprocess.run([sys.executable, str(EXAMPLES / "j_oedometer" / "study.py"), "--out", str(out),
                        "--svg", str(DOCS / "j_oedometer_stress.svg")], check=True)
    pressed = out / "3_press_5"
    k = int(tinydem.read_output(pressed).numbers[-1])
    picture(frame(pressed, k), DOCS / "j_oedometer.png", color="height", view="front",
            width=480, height=560, scenario=pressed / "run.toml", scale_bar=True)


def i():
    """Example I: the pile of tetrahedral clumps, and the packing fractions of dimers (its
    script runs the 14 packings and draws the plot)."""
    out = run("i", EXAMPLES / "i_clumps" / "pile_tetrahedra.toml")
    picture(frame(out, int(tinydem.read_output(out).numbers[-1])), DOCS / "i_pile_tetrahedra.png",
            color="height", view="front", width=720, height=420, scale_bar=True,
            scenario=out / "run.toml")
    subprocess.run([sys.executable, str(EXAMPLES / "i_clumps" / "packing.py")], check=True,
                   env={**os.environ, "TINYDEM_BIN": str(BINARY)})


def k():
    """The drum dryer: its study runs three speeds and draws the heating curves and the
    coefficient; the bed at 3 rad/s at the end, coloured by temperature."""
    out = WORK / "k"
    if not (REUSE and (out / "study.csv").is_file()):
        subprocess.run([sys.executable, str(EXAMPLES / "k_drum_dryer" / "study.py"), "--out", str(out),
                        "--plots", str(DOCS)], check=True, env={**os.environ, "TINYDEM_BIN": str(BINARY)})
    run3 = out / "drum_3.0"
    last = int(tinydem.read_output(run3).numbers[-1])
    picture(frame(run3, last), DOCS / "k_drum_dryer.png", color="temperature", view="front",
            width=480, height=480, scenario=run3 / "run.toml", scale_bar=True)


ALL = {"hourglass": hourglass, "b": b, "c": c, "d": d, "e": e, "f": f, "g": g, "h": h, "i": i,
       "j": j, "k": k}

if __name__ == "__main__":
    for name in [a for a in sys.argv[1:] if a != "--reuse"] or ALL:
        ALL[name]()
