"""The Python package against the engine: stepping from Python gives bitwise the frames of
`tinydem run`, the arrays are numpy in id order, the readers read what runs write."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import warnings

import numpy as np
import pytest

import tinydem

ROOT = Path(__file__).resolve().parents[2]
MESH = ROOT / "assets" / "hourglass.off"
STEPS_PER_FRAME = 150
FRAMES = 4


def scenario(directory: Path, extra: str = "") -> Path:
    """A short hourglass run: 300 grains spawned and falling on the funnel."""
    path = directory / "s.toml"
    path.write_text(
        f'[geometry]\nmesh = "{MESH}"\n'
        f"[simulation]\nmax_particles = 300\nframes = {FRAMES}\n"
        f"steps_per_frame = {STEPS_PER_FRAME}\n{extra}"
    )
    return path


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """A scenario and the output directory tinydem.run wrote for it."""
    d = tmp_path_factory.mktemp("study")
    s = scenario(d)
    out = tinydem.run(s, output=d / "out")
    return s, Path(out)


def test_stepping_gives_the_frames_of_a_run(study, tmp_path):
    s, out = study
    sim = tinydem.Simulation(s, threads=2)
    for k in range(1, FRAMES + 1):
        sim.step(STEPS_PER_FRAME)
        sim.write_frame(tmp_path / f"f{k}.csv")
        assert (tmp_path / f"f{k}.csv").read_bytes() == (
            out / f"particles{k:06d}.csv"
        ).read_bytes(), f"frame {k}"
    assert sim.steps == FRAMES * STEPS_PER_FRAME
    assert sim.time == pytest.approx(sim.steps * sim.timestep, rel=1e-15)


def test_the_command_line_writes_the_same_frames(study, tmp_path):
    """Against the tinydem binary, where CI names it (TINYDEM_BIN) or it is built."""
    binary = os.environ.get("TINYDEM_BIN") or shutil.which("tinydem")
    built = ROOT / "target" / "release" / "tinydem"
    if not binary and built.exists():
        binary = str(built)
    if not binary:
        pytest.skip("no tinydem binary (set TINYDEM_BIN)")
    s, out = study
    subprocess.run(
        [binary, "run", str(s), "-q", "--output", str(tmp_path / "cli")], check=True
    )
    for k in range(FRAMES + 1):
        name = f"particles{k:06d}.csv"
        assert (tmp_path / "cli" / name).read_bytes() == (out / name).read_bytes()


def test_arrays_are_numpy_in_id_order(study):
    s, _ = study
    sim = tinydem.Simulation(s)
    sim.step(300)
    n = len(sim)
    assert n > 0
    for name, shape in [
        ("positions", (n, 3)),
        ("velocities", (n, 3)),
        ("angular_velocities", (n, 3)),
        ("orientations", (n, 4)),
        ("radii", (n,)),
    ]:
        a = getattr(sim, name)
        assert isinstance(a, np.ndarray) and a.dtype == np.float64, name
        assert a.shape == shape, name
    assert sim.ids.dtype == np.int64
    assert np.all(np.diff(sim.ids) > 0)
    assert np.allclose(np.linalg.norm(sim.orientations, axis=1), 1.0)
    assert np.all((sim.radii >= 0.002) & (sim.radii <= 0.01))


def test_optional_fields_are_named_and_a_missing_one_is_a_key_error(study):
    s, _ = study
    sim = tinydem.Simulation(s)
    assert sim.fields == []
    with pytest.raises(KeyError, match="no field 'temperature'.*hold: none"):
        sim.field("temperature")
    with pytest.raises(KeyError):
        sim.set_field("temperature", np.zeros(len(sim)))


def test_temperatures_are_read_and_set_by_name(tmp_path):
    path = scenario(
        tmp_path,
        "[material]\nthermal_conductivity = 1.0\nheat_capacity = 800.0\n"
        "initial_temperature = 300.0\n",
    )
    sim = tinydem.Simulation(path)
    sim.step(200)
    assert sim.fields == ["T"]
    t = sim.field("T")
    assert t.shape == (len(sim),) and np.all(t == 300.0)
    hot = np.full(len(sim), 300.0)
    hot[0] = 500.0
    sim.set_field("T", hot)
    sim.step(1)
    t = sim.field("T")
    # The set temperature is taken as new (its content made from it), then conducts.
    assert 499.0 < t[0] <= 500.0 and np.all(t[1:] >= 300.0)


def test_velocities_can_be_set(study):
    s, _ = study
    sim = tinydem.Simulation(s)
    sim.step(100)
    v = np.zeros_like(sim.velocities)
    v[:, 0] = 1.5
    sim.velocities = v
    assert np.array_equal(sim.velocities, v)
    sim.angular_velocities = np.ones_like(v)
    assert np.array_equal(sim.angular_velocities, np.ones_like(v))
    x0 = sim.positions
    sim.step(1)
    # Semi-implicit Euler: the new velocity (1.5 m/s plus gravity and contacts) moves x.
    assert np.median(sim.positions[:, 0] - x0[:, 0]) == pytest.approx(
        1.5 * sim.timestep, rel=1e-2
    )
    with pytest.raises(ValueError, match="shape"):
        sim.velocities = np.zeros((len(sim) + 1, 3))
    with pytest.raises(ValueError, match="finite"):
        sim.velocities = np.full_like(v, np.nan)


def test_threads_do_not_change_the_result(study):
    s, _ = study
    one, two = tinydem.Simulation(s, threads=1), tinydem.Simulation(s, threads=2)
    one.step(400)
    two.step(400)
    assert np.array_equal(one.positions, two.positions)
    assert np.array_equal(one.angular_velocities, two.angular_velocities)
    with pytest.raises(ValueError):
        tinydem.Simulation(s, threads=0)


def test_a_checkpoint_resumes_exactly(study, tmp_path):
    s, _ = study
    straight = tinydem.Simulation(s)
    straight.step(500)
    half = tinydem.Simulation(s)
    half.step(250)
    half.checkpoint(tmp_path / "c.bin")
    resumed = tinydem.Simulation(s, resume=tmp_path / "c.bin")
    assert resumed.steps == 250
    resumed.step(250)
    assert np.array_equal(resumed.positions, straight.positions)
    assert np.array_equal(resumed.velocities, straight.velocities)


def test_read_output_knows_times_frames_and_log(study):
    _, out = study
    o = tinydem.read_output(out)
    assert len(o) == FRAMES + 1
    assert list(o.steps) == [k * STEPS_PER_FRAME for k in range(FRAMES + 1)]
    dt = tinydem.Simulation(o.scenario).timestep
    assert np.allclose(o.times, o.steps * dt, rtol=1e-15)
    last = o[-1]
    assert set("x y z R vx vy vz q0 q1 q2 q3 wx wy wz".split()) <= set(last)
    assert len(o.frames[1:3]) == 2
    # log.csv: the kinetic energy of each frame, from its velocities and radii.
    log = o.log
    assert list(log["frame"]) == list(o.numbers)
    f = o[FRAMES]
    m = 4.0 / 3.0 * np.pi * 1000.0 * f["R"] ** 3
    v2 = f["vx"] ** 2 + f["vy"] ** 2 + f["vz"] ** 2
    w2 = f["wx"] ** 2 + f["wy"] ** 2 + f["wz"] ** 2
    energy = np.sum(0.5 * m * v2 + 0.5 * 0.4 * m * f["R"] ** 2 * w2)
    assert log["kinetic_energy"][-1] == pytest.approx(energy, rel=1e-12)
    assert log["particles"].dtype == np.int64
    assert o.checkpoint.is_file()


def test_read_frame_reads_tags_and_ids(tmp_path):
    frame = tmp_path / "f.csv"
    frame.write_text(
        "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,tag,id,material\n"
        "0,0,0,0.01,1,0,0,1,0,0,0,0,0,0,3,7,1\n"
    )
    f = tinydem.read_frame(frame)
    assert f["tag"].dtype == np.int64 and f["id"][0] == 7 and f["R"][0] == 0.01
    frame.write_text("x,y\n1,oops\n")
    with pytest.raises(ValueError, match="not a number"):
        tinydem.read_frame(frame)
    with pytest.raises(FileNotFoundError):
        tinydem.read_output(tmp_path)


def test_errors_are_python_exceptions(tmp_path):
    with pytest.raises(FileNotFoundError, match="cannot read scenario"):
        tinydem.Simulation(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[simulation]\nframes = -1\n")
    with pytest.raises(ValueError, match=r"bad.toml:2: \[simulation\] frames"):
        tinydem.Simulation(bad)
    unknown = tmp_path / "unknown.toml"
    unknown.write_text("[simulation]\nframez = 3\n")
    with pytest.raises(ValueError, match="unknown field `framez`"):
        tinydem.run(unknown)
    no_mesh = tmp_path / "no_mesh.toml"
    no_mesh.write_text('[geometry]\nmesh = "box.stl"\n')
    with pytest.raises(FileNotFoundError, match=r"\[geometry\] mesh: cannot read .*box.stl"):
        tinydem.Simulation(no_mesh)
    with pytest.raises(FileNotFoundError):
        tinydem.run(no_mesh)


def test_an_unstable_run_raises(tmp_path):
    (tmp_path / "p.csv").write_text(
        "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n"
        "-0.0125,0,0,0.002,5,0,0,1,0,0,0,0,0,0\n0,0,0,0.01,0,0,0,1,0,0,0,0,0,0\n"
    )
    s = tmp_path / "s.toml"
    s.write_text(
        "[geometry]\nradius_min = 0.002\nradius_max = 0.01\n"
        "[kinetics]\ngravity = [0.0, 0.0, 0.0]\n"
        "[simulation]\ntimestep = 1e-3\nmax_particles = 0\n"
        '[input]\nparticles = "p.csv"\n'
    )
    # As run() does, the constructor refuses that time step unless forced.
    with pytest.raises(ValueError, match="pass force=True"):
        tinydem.Simulation(s)
    with pytest.raises(ValueError, match=r"pass force=True to run it anyway\)"):
        tinydem.run(s, output=tmp_path / "out")
    sim = tinydem.Simulation(s, force=True)
    with pytest.raises(RuntimeError, match="unstable") as first:
        sim.step(10)
    # The simulation is poisoned: a later step raises that diagnosis and does nothing...
    steps = sim.steps
    with pytest.raises(RuntimeError, match="became unstable then") as again:
        sim.step(1)
    assert str(first.value) in str(again.value) and sim.steps == steps
    # ...unless forced, when it steps on.
    try:
        sim.step(1, force=True)
    except RuntimeError:
        pass
    assert sim.steps == steps + 1


def test_setters_take_array_likes_and_positions_can_be_set(study):
    s, _ = study
    sim, twin = tinydem.Simulation(s), tinydem.Simulation(s)
    sim.step(100)
    twin.step(100)
    n = len(sim)
    sim.velocities = [[0.0, 0.0, -1.0]] * n
    assert np.array_equal(sim.velocities[:, 2], -np.ones(n))
    sim.angular_velocities = np.ones((n, 3), dtype=np.float32)
    sim.angular_velocities = np.ones((n, 3), dtype=np.int64)
    assert sim.angular_velocities.dtype == np.float64
    # Positions set to where they are: the same run, to the bit (the lists are made anew).
    twin.positions = twin.positions.tolist()
    sim.velocities, sim.angular_velocities = twin.velocities, twin.angular_velocities
    sim.step(100)
    twin.step(100)
    assert np.array_equal(sim.positions, twin.positions)
    # A particle moved: it is where it was put.
    x = twin.positions
    x[0] = [0.0, 0.0, 0.35]
    twin.positions = x
    assert np.array_equal(twin.positions[0], [0.0, 0.0, 0.35])
    with pytest.raises(ValueError, match=r"positions\[1\] = .* must be finite"):
        twin.positions = np.where(np.arange(n)[:, None] == 1, np.nan, x)
    with pytest.raises(ValueError, match="shape"):
        twin.positions = x[:-1]


def test_add_and_remove_give_the_run_that_had_them_from_the_start(study, tmp_path):
    """Particles added (or removed) from Python before stepping: the bits of a run that
    read (or never had) them."""
    _, out = study
    rows = (out / "particles000004.csv").read_text().splitlines()
    header, body = rows[0], rows[1:]
    frame = tinydem.read_frame(out / "particles000004.csv")

    def sim_of(name, lines):
        (tmp_path / f"{name}.csv").write_text("\n".join([header] + lines) + "\n")
        scenario(tmp_path, f'spawn_attempts = 0\n[input]\nparticles = "{name}.csv"\n').rename(
            tmp_path / f"{name}.toml"
        )
        return tinydem.Simulation(tmp_path / f"{name}.toml")

    whole = sim_of("whole", body)
    added = sim_of("part", body[:-5])
    ids = added.add(
        np.c_[frame["x"], frame["y"], frame["z"]][-5:],
        frame["R"][-5:].tolist(),
        velocities=np.c_[frame["vx"], frame["vy"], frame["vz"]][-5:],
        angular_velocities=np.c_[frame["wx"], frame["wy"], frame["wz"]][-5:],
    )
    assert list(ids) == list(range(len(body) - 5, len(body)))
    extra = [line.replace(line.split(",")[2], "0.3", 1) for line in body[:3]]
    removed = sim_of("more", body + extra)
    removed.remove([len(body), len(body) + 1, len(body) + 2])
    assert len(removed) == len(whole) == len(added)
    for sim in (whole, added, removed):
        sim.step(200)
    for sim in (added, removed):
        assert np.array_equal(sim.positions, whole.positions)
        assert np.array_equal(sim.velocities, whole.velocities)
    with pytest.raises(ValueError, match="radii\\[0\\] = -1"):
        added.add([[0.0, 0.0, 0.3]], [-1.0])
    with pytest.raises(ValueError, match="ids: there is no particle 99999"):
        added.remove([99999])


def test_freeze_gives_the_run_of_a_fixed_box(study, tmp_path):
    """Particles frozen from Python before stepping: the bits of the CLI's run of the same
    particles with a [[fixed]] box around them; they stay put, and unfreeze lets go."""
    _, out = study
    (tmp_path / "start.csv").write_bytes((out / "particles000004.csv").read_bytes())
    frame = tinydem.read_frame(out / "particles000004.csv")
    low = float(np.median(frame["z"]))
    start = f'spawn_attempts = 0\n[input]\nparticles = "start.csv"\n'
    box = f"[[fixed]]\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, {low!r}]\n"
    scenario(tmp_path, start + box).rename(tmp_path / "boxed.toml")
    boxed = Path(tinydem.run(tmp_path / "boxed.toml", output=tmp_path / "boxed"))
    scenario(tmp_path, start).rename(tmp_path / "free.toml")
    sim = tinydem.Simulation(tmp_path / "free.toml")
    held = sim.ids[sim.positions[:, 2] <= low]
    assert 0 < len(held) < len(sim)
    sim.freeze(held.tolist())
    assert list(sim.ids[sim.fixed]) == list(held)
    before = sim.positions[sim.fixed]
    sim.step(FRAMES * STEPS_PER_FRAME)
    sim.write_frame(tmp_path / "frozen.csv")
    last = boxed / f"particles{FRAMES:06d}.csv"
    assert (tmp_path / "frozen.csv").read_bytes() == last.read_bytes()
    assert np.array_equal(sim.positions[sim.fixed], before)
    assert not sim.velocities[sim.fixed].any()
    sim.unfreeze(held)
    assert not sim.fixed.any()
    with pytest.raises(ValueError, match="ids: there is no particle 99999"):
        sim.freeze([99999])


def test_clumps_added_from_python_move_as_rigid_bodies(tmp_path):
    """A dimer added by name falls onto the funnel as one body: its spheres keep their
    distance and share one orientation; `bodies` names the body of each sphere; a frame
    written from Python reads back as the run's input would."""
    dimer = '[[clumps]]\nname = "dimer"\nspheres = [[0.0, 0.0, 0.0, 0.003], [0.004, 0.0, 0.0, 0.003]]\n'
    s = scenario(tmp_path, "spawn_attempts = 0\n" + dimer)
    sim = tinydem.Simulation(s)
    turn = [np.cos(0.4), 0.0, np.sin(0.4), 0.0]
    body = sim.add_clump("dimer", [0.0, 0.0, 0.02], orientation=turn, angular_velocity=[0.0, 0.0, 5.0])
    assert body == 0 and len(sim) == 2
    assert list(sim.bodies) == [0, 0]
    with pytest.raises(ValueError, match="no \\[\\[clumps\\]\\] template is named .rod."):
        sim.add_clump("rod", [0.0, 0.0, 0.0])
    sim.step(STEPS_PER_FRAME * FRAMES)
    x = sim.positions
    assert abs(np.linalg.norm(x[1] - x[0]) - 0.004) < 1e-12
    assert np.array_equal(sim.orientations[0], sim.orientations[1])
    assert sim.positions[:, 2].max() < 0.02
    sim.positions = sim.positions  # unchanged: allowed
    with pytest.raises(ValueError, match="is a sphere of the clump 0"):
        sim.positions = sim.positions + 0.001
    sim.write_frame(tmp_path / "dimer.csv")
    frame = tinydem.read_frame(tmp_path / "dimer.csv")
    assert list(frame["clump"]) == [0]
    # Freezing one of its spheres holds the clump whole.
    sim.freeze([1])
    held = sim.positions.copy()
    sim.step(50)
    assert np.array_equal(sim.positions, held)
    sim.unfreeze([0])
    sim.step(50)
    assert not np.array_equal(sim.positions, held)


def test_errors_name_python_arguments(study, tmp_path):
    s, _ = study
    tinydem.run(s, output=tmp_path / "out")
    with pytest.raises(FileExistsError) as e:
        tinydem.run(s, output=tmp_path / "out")
    assert "overwrite=True" in str(e.value) and "--overwrite" not in str(e.value)


def test_render_draws_a_directory_and_an_animation(study, tmp_path):
    _, out = study
    done = tinydem.render(out, output=tmp_path / "pics", gif=True, width=320, height=240)
    assert len(done["pictures"]) == FRAMES + 1
    assert all(Path(p).is_file() for p in done["pictures"])
    assert Path(done["animation"]).read_bytes().startswith(b"GIF89a")
    one = tinydem.render(
        out / "particles000002.csv",
        output=tmp_path / "one.png",
        color="height",
        view="front",
        range=(0.0, 0.1),
        scale_bar=True,
    )
    assert [Path(p) for p in one["pictures"]] == [tmp_path / "one.png"]
    with pytest.raises(ValueError, match="color"):
        tinydem.render(out, color="colour")
    with pytest.raises(ValueError, match="range"):
        tinydem.render(out, range=(1.0, 0.0))


def test_fields_of_a_bed_hold_its_mass_and_press_down(tmp_path):
    """tinydem.fields: slices along z of grains resting on a floor, with their contacts."""
    s = tmp_path / "bed.toml"
    s.write_text(
        "[geometry]\nradius_min = 0.004\nradius_max = 0.005\n"
        "spawn_min = [-0.02, -0.02, 0.01]\nspawn_max = [0.02, 0.02, 0.06]\n"
        "[simulation]\nmax_particles = 60\nframes = 3\nsteps_per_frame = 2000\n"
        "[output]\ncontacts = true\n"
        "[[meshes]]\nshape = { type = \"box\", min = [-0.03, -0.03, 0.0], max = [0.03, 0.03, 0.1], "
        "open = [\"+z\"] }\n"
    )
    out = Path(tinydem.run(s, output=tmp_path / "out"))
    # The box reaches below the floor: the grains' kernels (3 mean radii) reach there too.
    box = ((-0.03, -0.03, -0.02), (0.03, 0.03, 0.1))
    [f] = tinydem.fields(out, slices="z", spacing=0.005, bounds=box)
    n = 24
    assert list(f["counts"]) == [1, 1, n] and f["frames"] == 1
    assert f["points"].shape == (n, 3) and f["stress"].shape == (n, 3, 3)
    assert all(Path(p).is_file() for p in f["files"])
    frame = tinydem.read_frame(out / "particles000003.csv")
    mass = (1000.0 * 4.0 / 3.0 * np.pi * frame["R"] ** 3).sum()
    # The slices hold the grains' mass (0.06 x 0.06 m across, 5 mm thick).
    assert f["density"].sum() * 0.06 * 0.06 * 0.005 == pytest.approx(mass, rel=1e-3)
    # Under the grains, at the floor, the stress is compressive.
    assert f["stress"][4, 2, 2] > 0.0
    assert f["stress"] == pytest.approx(f["contact_stress"] + f["kinetic_stress"])
    with pytest.raises(ValueError, match="kernel"):
        tinydem.fields(out, kernel="box")
    (out / "contacts000003.csv").unlink()
    with pytest.raises(FileNotFoundError, match="contacts = true"):
        tinydem.fields(out)


def test_the_example_study_runs():
    """examples/python/study.py, the notebook-style example, runs start to end."""
    script = ROOT / "examples" / "python" / "study.py"
    done = subprocess.run(
        [sys.executable, str(script)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    assert "animation in" in done.stdout
    out = ROOT / "examples" / "python" / "output"
    assert (out / "log.csv").is_file() and (out / "kicked.bin").is_file()


def test_ctrl_c_stops_a_run_with_a_checkpoint_that_resumes(tmp_path):
    import signal
    import threading
    import time

    # A run far longer than the test, interrupted once it has written a frame (not after a
    # fixed time, which a fast machine could outrun).
    s = scenario(tmp_path).read_text().replace(f"frames = {FRAMES}", "frames = 10000")
    (tmp_path / "long.toml").write_text(s)
    out = tmp_path / "out"

    def interrupt():
        deadline = time.monotonic() + 60
        while not (out / "particles000001.csv").is_file() and time.monotonic() < deadline:
            time.sleep(0.01)
        os.kill(os.getpid(), signal.SIGINT)

    # Python turns SIGINT into KeyboardInterrupt only if it was not ignored when it started
    # (a job started in the background by a non-interactive shell ignores it): install the
    # handler here, as an interactive session has it.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Thread(target=interrupt)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            tinydem.run(tmp_path / "long.toml", output=out)
    finally:
        timer.join()
        signal.signal(signal.SIGINT, previous)
    assert (out / "checkpoint.bin").is_file() and (out / "interrupted.csv").is_file()
    steps = tinydem.Simulation(tmp_path / "long.toml", resume=out / "checkpoint.bin").steps
    assert STEPS_PER_FRAME <= steps < 10000 * STEPS_PER_FRAME


def test_a_panic_of_the_engine_is_a_runtime_error():
    # PyO3's PanicException derives from BaseException: `except Exception` would miss it.
    with pytest.raises(RuntimeError, match="internal error of tinydem"):
        tinydem._tinydem._internal_panic()


def test_a_frame_in_pieces_reads_as_one(tmp_path):
    """A frame a split run wrote in pieces (``[output] gather = "never"``) reads as the
    gathered frame: rows joined in id order; a gap in the pieces is an error naming it."""
    header = "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,id,material"
    row = lambda i: ",".join([str(0.1 * i), "0", "0", "0.01"] + ["0"] * 3 + ["1", "0", "0", "0"] + ["0"] * 3 + [str(i), "0"])
    pieces = {0: [3, 0, 5], 1: [1, 4], 2: [2]}
    for k, ids in pieces.items():
        (tmp_path / f"particles000007_{k}.csv").write_text("\n".join([header] + [row(i) for i in ids]) + "\n")
    frame = tinydem.read_frame(tmp_path / "particles000007.csv")
    assert list(frame["id"]) == [0, 1, 2, 3, 4, 5]
    assert np.allclose(frame["x"], 0.1 * np.arange(6))
    (tmp_path / "particles000007_1.csv").unlink()
    with pytest.raises(FileNotFoundError, match="particles000007_1.csv is missing"):
        tinydem.read_frame(tmp_path / "particles000007.csv")


def test_a_forced_blow_up_warns_as_the_command_line_does(tmp_path):
    """Two grains at 20 x Eq. 50's time step, forced: they pass halfway through each other in
    a step. The command line warns of the overlap past the smaller radius; Python says it as
    a RuntimeWarning (and the forced refusal itself)."""
    (tmp_path / "p.csv").write_text(
        "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n"
        "-0.0052,0,0,0.005,2,0,0,1,0,0,0,0,0,0\n0.0052,0,0,0.005,-2,0,0,1,0,0,0,0,0,0\n"
    )
    s = tmp_path / "s.toml"
    s.write_text(
        "[geometry]\nradius_min = 0.005\nradius_max = 0.01\n"
        "[kinetics]\ngravity = [0.0, 0.0, 0.0]\n"
        "[simulation]\ntimestep = 3e-3\nmax_particles = 0\n"
        '[input]\nparticles = "p.csv"\n'
    )
    with pytest.raises(ValueError, match="Eq. 50"):
        tinydem.Simulation(s)
    with pytest.warns(RuntimeWarning, match=r"x Eq. 50.*\(forced\)"):
        sim = tinydem.Simulation(s, force=True)
    with pytest.warns(RuntimeWarning, match="overlap .* more than the smaller radius") as said:
        sim.step(100)
    assert any("Likely cause: timestep" in str(w.message) for w in said)
    # Once per pair, as on the command line.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim.step(100)


def test_add_refuses_deep_overlaps_and_radii_the_lists_are_not_made_for(study):
    s, _ = study
    sim = tinydem.Simulation(s)
    r = 0.005
    with pytest.raises(ValueError, match="new particle 0 would overlap new particle 1 by 196 % of the smaller radius"):
        sim.add([[0.0, 0.0, 0.3], [0.0002, 0.0, 0.3]], [r, r])
    with pytest.raises(ValueError, match=r"radius 0.07 .* outside \[geometry\] radius_min"):
        sim.add([[0.0, 0.0, 0.3]], [0.07])
    n = len(sim)
    assert sim.add([[0.0, 0.0, 0.3], [0.0002, 0.0, 0.3]], [r, r], allow_overlap=True).shape == (2,)
    assert len(sim) == n + 2
    with pytest.raises(ValueError, match="would overlap particle"):
        sim.add([[0.0, 0.0, 0.3]], [r])
    with pytest.raises(ValueError, match=r"step\(-5\): the number of steps must be >= 0"):
        sim.step(-5)
