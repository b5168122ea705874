//! Faults: unstable runs stop loudly, interrupted runs resume bit for bit, killed runs
//! leave only complete files.

use crate::common;

use crate::common::tinydem;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use tinydem::io::checkpoint;
use tinydem::io::csv::load_particles;

const HEADER: &str = "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n";

/// Writes `particles` (CSV rows after the header) and a scenario of them without gravity
/// (with extra `[simulation]` and `[material]` lines) into `dir`.
fn two_body(dir: &Path, particles: &str, simulation: &str, material: &str) {
    std::fs::write(dir.join("p.csv"), format!("{HEADER}{particles}")).unwrap();
    std::fs::write(
        dir.join("s.toml"),
        format!(
            "[geometry]\nradius_min = 0.002\nradius_max = 0.01\n[material]\n{material}\n\
             [kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
             [simulation]\nframes = 10\nsteps_per_frame = 10\nmax_particles = 0\n{simulation}\n\
             [input]\nparticles = \"p.csv\"\n"
        ),
    )
    .unwrap();
}

fn assert_contains(text: &str, expected: &[&str]) {
    for e in expected {
        assert!(text.contains(e), "message\n  {text}\nlacks\n  {e}");
    }
}

/// Resumes `checkpoint` with `scenario` in `dir`, into `out`, and asserts that it is refused
/// with a message holding each of `expected`, and no panic.
fn assert_resume_refused(
    dir: &Path,
    scenario: &str,
    checkpoint: &str,
    out: &str,
    expected: &[&str],
) {
    let o = tinydem(
        &["run", scenario, "-q", "-o", out, "--resume", checkpoint],
        dir,
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{checkpoint} resumed");
    assert!(!err.contains("panicked"), "{err}");
    assert_contains(&err, expected);
}

#[test]
fn too_large_timestep_is_warned_of_once_with_advice() {
    // Two equal spheres at 20 x Eq. 50's step pass halfway through each other in one step:
    // past the smaller radius, a warning (once for the pair) with the cause, not a stop.
    let t = tempfile::tempdir().unwrap();
    two_body(
        t.path(),
        "-0.0052,0,0,0.005,2,0,0,1,0,0,0,0,0,0\n0.0052,0,0,0.005,-2,0,0,1,0,0,0,0,0,0\n",
        "timestep = 3e-3",
        "",
    );
    std::fs::write(
        t.path().join("s.toml"),
        std::fs::read_to_string(t.path().join("s.toml"))
            .unwrap()
            .replace("radius_min = 0.002", "radius_min = 0.005"),
    )
    .unwrap();
    let o = tinydem(&["run", "s.toml", "--force"], t.path());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert_contains(
        &err,
        &[
            "warning: step 2: particles 0 and 1 overlap by 8.400e-3 m, more than the smaller radius 5.000e-3 m",
            "deep overlaps 1",
            "warning: 1 pair overlapped by more than the smaller radius",
            "timestep 3.000e-3 s exceeds Eq. 50's 1.508e-4 s",
            "try timestep <= 1.508e-4 s",
        ],
    );
    assert_eq!(err.matches("warning: step").count(), 1, "{err}");
    // Quiet runs still say it at the end.
    let o = tinydem(&["run", "s.toml", "-q", "--force", "-o", "quiet"], t.path());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success());
    assert_contains(
        &err,
        &["warning: 1 pair overlapped by more than the smaller radius"],
    );
}

#[test]
fn an_overlap_past_the_smaller_diameter_stops_the_run() {
    // A 2 mm grain shot at a 10 mm one gets wholly inside it within one step.
    let t = tempfile::tempdir().unwrap();
    two_body(
        t.path(),
        "-0.0125,0,0,0.002,5,0,0,1,0,0,0,0,0,0\n0,0,0,0.01,0,0,0,1,0,0,0,0,0,0\n",
        "timestep = 1e-3",
        "",
    );
    let o = tinydem(&["run", "s.toml", "-q", "--force"], t.path());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(!err.contains("panicked"), "{err}");
    assert_contains(
        &err,
        &[
            // Step 1 moves it 5 mm; step 2 finds the overlap.
            "became unstable at step 2",
            "particles 0 and 1 overlap by 4.500e-3 m, more than the smaller diameter 4.000e-3 m",
            "timestep 1.000e-3 s exceeds Eq. 50's",
            "last complete frame",
            "unstable.csv",
        ],
    );
    let state = load_particles(&t.path().join("output/unstable.csv")).unwrap();
    assert_eq!(state.len(), 2);
}

#[test]
fn a_non_finite_state_stops_the_run() {
    let t = tempfile::tempdir().unwrap();
    two_body(
        t.path(),
        "0,0,0,0.005,0,0,0,1,0,0,0,0,0,0\n",
        "timestep = 10.0",
        "",
    );
    std::fs::write(
        t.path().join("s.toml"),
        std::fs::read_to_string(t.path().join("s.toml"))
            .unwrap()
            .replace("gravity = [0.0, 0.0, 0.0]", "gravity = [0.0, 0.0, -1e308]"),
    )
    .unwrap();
    let o = tinydem(&["run", "s.toml", "-q", "--force"], t.path());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert_contains(
        &err,
        &[
            "became unstable at step 1",
            "particle 0 has a non-finite state",
        ],
    );
}

/// A pile that spawns particles and keeps them in contact: spring history matters.
fn pile(dir: &Path, frames: u64) {
    std::fs::write(
        dir.join("box.off"),
        "OFF\n8 5 0\n-0.03 -0.03 0\n0.03 -0.03 0\n0.03 0.03 0\n-0.03 0.03 0\n-0.03 -0.03 0.2\n0.03 -0.03 0.2\n\
         0.03 0.03 0.2\n-0.03 0.03 0.2\n4 0 1 2 3\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("s.toml"),
        format!(
            "[geometry]\nradius_min = 0.003\nradius_max = 0.005\nmesh = \"box.off\"\nmesh_radii = [0.0]\n\
             spawn_min = [-0.02, -0.02, 0.05]\nspawn_max = [0.02, 0.02, 0.15]\n\
             [simulation]\nmax_particles = 400\nspawn_attempts = 3\nframes = {frames}\nsteps_per_frame = 2000\n"
        ),
    )
    .unwrap();
}

fn frames_of(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap())
        .filter(|e| e.file_name().to_string_lossy().starts_with("particles"))
        .map(|e| {
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

#[test]
fn interrupted_run_resumes_bit_for_bit() {
    let frames = 12;
    // Uninterrupted reference.
    let a = tempfile::tempdir().unwrap();
    pile(a.path(), frames);
    let o = tinydem(&["run", "s.toml", "-q", "--output", "out"], a.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let reference = frames_of(&a.path().join("out"));
    assert_eq!(reference.len() as u64, frames + 1);

    // Interrupted with SIGINT part-way, then resumed.
    let b = tempfile::tempdir().unwrap();
    pile(b.path(), frames);
    let child = Command::new(env!("CARGO_BIN_EXE_tinydem"))
        .args(["run", "s.toml", "-q", "--output", "out"])
        .current_dir(b.path())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until a few frames exist, so particles are piled up and in contact.
    let start = Instant::now();
    while !b.path().join("out/particles000004.csv").exists() {
        assert!(start.elapsed() < Duration::from_secs(60), "run too slow");
        std::thread::sleep(Duration::from_millis(5));
    }
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(
        err.contains("interrupted after step") && err.contains("--resume"),
        "{err}"
    );
    let ckpt = b.path().join("out/checkpoint.bin");
    assert!(b.path().join("out/interrupted.csv").exists());
    // Any fingerprint check is done by the CLI; here only the content matters.
    let snapshot = checkpoint::decode(&std::fs::read(&ckpt).unwrap(), None).unwrap();
    assert!(snapshot.steps < frames * 2000, "interrupted before the end");
    assert!(
        !snapshot.pair_history.is_empty(),
        "particles were in contact"
    );
    assert!(
        !snapshot.face_history.is_empty(),
        "particles touched the box"
    );

    let o = tinydem(
        &[
            "run",
            "s.toml",
            "-q",
            "--output",
            "out",
            "--resume",
            "out/checkpoint.bin",
        ],
        b.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!b.path().join("out/interrupted.csv").exists());
    let resumed = frames_of(&b.path().join("out"));
    assert_eq!(resumed.len(), reference.len());
    for ((name, x), (_, y)) in reference.iter().zip(&resumed) {
        assert!(x == y, "{name} differs after resume");
    }
}

#[test]
fn checkpoints_of_another_scenario_or_damaged_are_refused() {
    let t = tempfile::tempdir().unwrap();
    pile(t.path(), 2);
    std::fs::write(
        t.path().join("s.toml"),
        std::fs::read_to_string(t.path().join("s.toml")).unwrap()
            + "[output]\ncheckpoint_every = 1\n",
    )
    .unwrap();
    let o = tinydem(&["run", "s.toml", "-q"], t.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let ckpt = t.path().join("output/checkpoint.bin");
    assert!(ckpt.exists(), "periodic checkpoint written");

    // Another spawning, or the other order of the friction springs (checkpoints from before
    // the choice are in the paper's order and resume only in it): another scenario.
    let scenario = std::fs::read_to_string(t.path().join("s.toml")).unwrap();
    for (from, to) in [
        ("max_particles = 400", "max_particles = 401"),
        (
            "[simulation]\n",
            "[simulation]\nfriction_springs = \"paper\"\n",
        ),
    ] {
        std::fs::write(t.path().join("other.toml"), scenario.replace(from, to)).unwrap();
        assert_resume_refused(
            t.path(),
            "other.toml",
            "output/checkpoint.bin",
            "output",
            &["different scenario"],
        );
    }

    let mut bytes = std::fs::read(&ckpt).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0xff;
    std::fs::write(t.path().join("bad.bin"), &bytes).unwrap();
    assert_resume_refused(
        t.path(),
        "s.toml",
        "bad.bin",
        "output",
        &["checksum", "bad.bin"],
    );
}

/// Checkpoints forged with a valid checksum but impossible content are refused on
/// `--resume` with the field named, never a panic.
#[test]
fn forged_checkpoints_are_refused_by_their_content() {
    let t = tempfile::tempdir().unwrap();
    pile(t.path(), 1);
    let o = tinydem(&["run", "s.toml", "-q"], t.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bytes = std::fs::read(t.path().join("output/checkpoint.bin")).unwrap();
    // The fingerprint follows the magic (12 bytes) and the version (4).
    let fingerprint = u64::from_le_bytes(bytes[16..24].try_into().unwrap());
    let good = checkpoint::decode(&bytes, Some(fingerprint)).unwrap();
    assert!(good.particles.len() > 10);
    type Forge = fn(&mut tinydem::model::particles::Particles);
    let forgeries: [(Forge, &str); 5] = [
        (
            |p| p.material[0] = 7,
            "has material 7, but the scenario has 1 material",
        ),
        (
            |p| p.q[0] = glam::DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0),
            "not a unit quaternion",
        ),
        (|p| p.x[0].x = 1e300, "has the position"),
        (|p| p.v[0].y = f64::NAN, "has the velocity"),
        (|p| p.radius[0] = -0.004, "has the radius"),
    ];
    for (k, (forge, expected)) in forgeries.iter().enumerate() {
        let mut snapshot = good.clone();
        forge(&mut snapshot.particles);
        let name = format!("forged{k}.bin");
        std::fs::write(
            t.path().join(&name),
            checkpoint::encode(&snapshot, fingerprint),
        )
        .unwrap();
        assert_resume_refused(t.path(), "s.toml", &name, &format!("out{k}"), &[expected]);
    }
    let mut snapshot = good.clone();
    let history = if snapshot.pair_history.is_empty() {
        &mut snapshot.face_history
    } else {
        &mut snapshot.pair_history
    };
    history.first_mut().expect("a contact").2.springs.u_t = f64::INFINITY;
    std::fs::write(
        t.path().join("springs.bin"),
        checkpoint::encode(&snapshot, fingerprint),
    )
    .unwrap();
    assert_resume_refused(
        t.path(),
        "s.toml",
        "springs.bin",
        "out",
        &["the friction springs of contact"],
    );
    // Counts that do not fit the scenario: spawn regions, mesh files, outlets.
    type Recount = fn(&mut tinydem::engine::Snapshot);
    let recounts: [(Recount, &str); 3] = [
        (
            |s| s.spawner.regions = vec![Default::default(); 2],
            "the insertions of 2 [[spawn]] regions, the scenario has 0",
        ),
        (
            |s| s.wall_sums = vec![Default::default(); 3],
            "the loads on 3 mesh files, the scenario has 1",
        ),
        (
            |s| s.removed.outlets = vec![Default::default(); 1],
            "it counts 1 outlets, the scenario has 0",
        ),
    ];
    for (k, (recount, expected)) in recounts.iter().enumerate() {
        let mut snapshot = good.clone();
        recount(&mut snapshot);
        let name = format!("recounted{k}.bin");
        std::fs::write(
            t.path().join(&name),
            checkpoint::encode(&snapshot, fingerprint),
        )
        .unwrap();
        assert_resume_refused(t.path(), "s.toml", &name, &format!("count{k}"), &[expected]);
    }
}

/// The `run.toml` of a resumed run reruns its scenario: it keeps `[input] particles` (it
/// lost them, and a rerun had no particles).
#[test]
fn the_run_toml_of_a_resumed_run_reruns_it() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path();
    std::fs::write(
        d.join("two.csv"),
        "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n\
         0,0,0.01,0.004,0,0,0,1,0,0,0,0,0,0\n0.0085,0,0.01,0.004,-0.1,0,0,1,0,0,0,0,0,0\n",
    )
    .unwrap();
    std::fs::write(
        d.join("s.toml"),
        "[geometry]\nradius_min = 0.004\nradius_max = 0.004\n\
         [kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
         [simulation]\nmax_particles = 0\nspawn_attempts = 0\nframes = 3\nsteps_per_frame = 50\n\
         [input]\nparticles = \"two.csv\"\n[output]\ncheckpoint_every = 1\n",
    )
    .unwrap();
    let run = |args: &[&str]| {
        let o = tinydem(args, d);
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    };
    run(&["run", "s.toml", "-q", "-o", "first"]);
    std::fs::copy(d.join("first/checkpoint.bin"), d.join("at_end.bin")).unwrap();
    run(&[
        "run",
        "s.toml",
        "-q",
        "-o",
        "first",
        "--resume",
        "at_end.bin",
    ]);
    let text = std::fs::read_to_string(d.join("first/run.toml")).unwrap();
    assert!(text.contains("[input]\nparticles = "), "{text}");
    run(&["run", "first/run.toml", "-q", "-o", "again"]);
    let (first, again) = (frames_of(&d.join("first")), frames_of(&d.join("again")));
    assert_eq!(first.len(), 4);
    assert!(first == again, "the rerun differs");
}

#[test]
fn killed_run_leaves_only_complete_files() {
    let t = tempfile::tempdir().unwrap();
    pile(t.path(), 200);
    let mut child = Command::new(env!("CARGO_BIN_EXE_tinydem"))
        .args(["run", "s.toml", "-q"])
        .current_dir(t.path())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !t.path().join("output/particles000003.csv").exists() {
        assert!(start.elapsed() < Duration::from_secs(60), "run too slow");
        std::thread::sleep(Duration::from_millis(2));
    }
    std::thread::sleep(Duration::from_millis(37));
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let mut count = 0;
    for e in std::fs::read_dir(t.path().join("output")).unwrap() {
        let e = e.unwrap();
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue; // a temporary file, never read and removed by the next run
        }
        if name == "run.toml" {
            // Written whole (atomically) before the first frame.
            tinydem::scenario::Scenario::load(&e.path()).unwrap();
            continue;
        }
        if !name.starts_with("particles") {
            continue; // logs: a line at a time, a torn last line is dropped on resume
        }
        let p =
            load_particles(&e.path()).unwrap_or_else(|err| panic!("{name} incomplete: {err:#}"));
        let text = std::fs::read_to_string(e.path()).unwrap();
        assert!(text.ends_with('\n'), "{name} does not end with a newline");
        assert_eq!(text.lines().count(), p.len() + 1);
        count += 1;
    }
    assert!(count >= 4);
}

#[test]
fn finished_run_with_a_moving_mesh_extends_from_its_checkpoint_bit_for_bit() {
    let scenario = |frames: u64| {
        format!(
            "[geometry]\nradius_min = 0.003\nradius_max = 0.005\nmesh = \"box.off\"\nmesh_radii = [0.0]\n\
             spawn_min = [-0.02, -0.02, 0.05]\nspawn_max = [0.02, 0.02, 0.15]\n\
             [simulation]\nmax_particles = 200\nspawn_attempts = 3\nframes = {frames}\nsteps_per_frame = 1500\n\
             [[meshes]]\nfile = \"plate.off\"\n\
             motion = {{ type = \"harmonic\", amplitude = 0.002, frequency = 15.0, direction = [0.0, 0.0, 1.0] }}\n\
             [output]\ncheckpoint_every = 2\n"
        )
    };
    let plate = "OFF\n4 1 0\n-0.03 -0.03 0.01\n0.03 -0.03 0.01\n0.03 0.03 0.01\n-0.03 0.03 0.01\n4 0 1 2 3\n";
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    for dir in [a.path(), b.path()] {
        pile(dir, 1); // writes box.off
        std::fs::write(dir.join("plate.off"), plate).unwrap();
    }
    std::fs::write(a.path().join("s.toml"), scenario(8)).unwrap();
    let o = tinydem(&["run", "s.toml", "-q"], a.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    std::fs::write(b.path().join("s.toml"), scenario(4)).unwrap();
    let o = tinydem(&["run", "s.toml", "-q"], b.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::write(b.path().join("s.toml"), scenario(8)).unwrap();
    let o = tinydem(
        &["run", "s.toml", "-q", "--resume", "output/checkpoint.bin"],
        b.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let (x, y) = (
        frames_of(&a.path().join("output")),
        frames_of(&b.path().join("output")),
    );
    assert_eq!(x.len(), 9);
    assert_eq!(x.len(), y.len());
    for ((name, p), (_, q)) in x.iter().zip(&y) {
        assert!(p == q, "{name} differs after extending the run");
    }
}

#[test]
fn a_pair_squeezed_past_the_smaller_radius_goes_on_with_one_warning() {
    // Elastic Hertz impact of a 2 mm grain on a 10 mm one at 15 m/s: the largest overlap,
    // (15 m* v² / (16 E* sqrt(R*)))^(2/5) = 2.5 mm, lies between the small radius and its
    // diameter. The grain rebounds; the run goes on with one warning for the pair.
    use glam::{DQuat, DVec3};
    use tinydem::engine::Simulation;
    use tinydem::model::particles::{Particle, Particles};
    let s = common::scenario(
        "[geometry]\nradius_min = 0.002\nradius_max = 0.01\n\
         [material]\nrestitution = 1.0\nfriction_sliding = 0.0\nfriction_rolling = 0.0\n\
         [kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
         [simulation]\ntimestep = 1e-6\nmax_particles = 0\n",
    );
    let grain = |x: f64, radius: f64, v: f64| Particle {
        x: DVec3::X * x,
        radius,
        v: DVec3::X * v,
        q: DQuat::IDENTITY,
        w: DVec3::ZERO,
        tag: 0,
        material: 0,
        fixed: false,
        body: None,
        ..Particle::default()
    };
    let particles: Particles = [grain(-0.01201, 0.002, 15.0), grain(0.0, 0.01, 0.0)]
        .into_iter()
        .collect();
    let mut sim = Simulation::from_parts(s, Default::default(), particles).unwrap();
    let mut deepest: f64 = 0.0;
    for _ in 0..2000 {
        sim.step()
            .expect("a transient within the diameter does not stop the run");
        let p = &sim.particles;
        deepest = deepest.max(0.012 - p.x[0].distance(p.x[1]));
    }
    assert!(
        deepest > 0.002 && deepest < 0.004,
        "deepest overlap {deepest}"
    );
    assert_eq!(sim.warnings().count(), 1);
    let fresh = sim.take_new_warnings();
    assert_eq!(fresh.len(), 1, "{fresh:?}");
    assert!(
        fresh[0].contains("particles 0 and 1 overlap by"),
        "{fresh:?}"
    );
    assert!(sim.particles.v[0].x < 0.0, "the grain rebounds");
}

/// `[output] checkpoint_minutes`: a run killed without warning (SIGKILL) leaves a
/// checkpoint at most that old, which resumes to the frames of an uninterrupted run.
#[test]
fn a_run_killed_without_warning_resumes_from_its_timed_checkpoint() {
    let t = tempfile::tempdir().unwrap();
    pile(t.path(), 6);
    let scenario = std::fs::read_to_string(t.path().join("s.toml")).unwrap();
    std::fs::write(
        t.path().join("s.toml"),
        scenario + "[output]\ncheckpoint_minutes = 0.0005\n", // 30 ms
    )
    .unwrap();
    let o = tinydem(&["run", "s.toml", "-q", "-o", "whole"], t.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut child = Command::new(env!("CARGO_BIN_EXE_tinydem"))
        .args(["run", "s.toml", "-q", "-o", "out"])
        .current_dir(t.path())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !t.path().join("out/particles000002.csv").exists() {
        assert!(start.elapsed() < Duration::from_secs(60), "run too slow");
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap(); // SIGKILL: no stop checkpoint
    child.wait().unwrap();
    let ckpt = t.path().join("out/checkpoint.bin");
    let snapshot = checkpoint::decode(&std::fs::read(&ckpt).unwrap(), None).unwrap();
    assert!(
        snapshot.steps > 0 && snapshot.steps < 6 * 2000,
        "a timed checkpoint at step {}",
        snapshot.steps
    );
    let o = tinydem(
        &[
            "run",
            "s.toml",
            "-q",
            "-o",
            "out",
            "--resume",
            "out/checkpoint.bin",
        ],
        t.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (whole, resumed) = (
        frames_of(&t.path().join("whole")),
        frames_of(&t.path().join("out")),
    );
    assert_eq!(whole.len(), resumed.len());
    for ((name, x), (_, y)) in whole.iter().zip(&resumed) {
        assert!(x == y, "{name} differs after resuming");
    }
}

/// Starts `tinydem run s.toml -q -o out` in `dir`, its stderr piped, and waits for the
/// frame file `first`.
fn start_run(dir: &Path, first: &str) -> std::process::Child {
    let child = Command::new(env!("CARGO_BIN_EXE_tinydem"))
        .args(["run", "s.toml", "-q", "-o", "out"])
        .current_dir(dir)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !dir.join("out").join(first).exists() {
        assert!(start.elapsed() < Duration::from_secs(60), "run too slow");
        std::thread::sleep(Duration::from_millis(2));
    }
    child
}

/// Waits until a thread of `child` waits in the opening of a FIFO for a reader (the kernel
/// names that wait `wait_for_partner`, `fifo_open` in older kernels): not a guess of how
/// long the steps before it take, which a busy machine stretches.
fn wait_until_blocked_on_a_fifo(child: &std::process::Child) {
    let tasks = format!("/proc/{}/task", child.id());
    // Where the kernel hides wait channels (`0`), a thread asleep in openat (257) will do.
    let blocked = || {
        std::fs::read_dir(&tasks).into_iter().flatten().any(|t| {
            let t = t.unwrap().path();
            let read = |f: &str| std::fs::read_to_string(t.join(f)).unwrap_or_default();
            let wchan = read("wchan");
            wchan.contains("wait_for_partner")
                || wchan.contains("fifo_open")
                || (wchan == "0" && read("syscall").starts_with("257 "))
        })
    };
    let start = Instant::now();
    while !blocked() {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "the run never blocked on the FIFO"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn signal(child: &std::process::Child, signal: i32) {
    // SAFETY: kill sends a signal to the child's process id; nothing else.
    assert_eq!(unsafe { libc::kill(child.id() as i32, signal) }, 0);
}

/// SIGCONT (which launchers send a second before SIGTERM) writes a checkpoint and the run
/// goes on; SIGUSR1 (which mpirun passes on and waits for) stops it like SIGTERM, and, coming
/// within seconds of the SIGCONT, keeps that checkpoint rather than write another that a
/// launcher's SIGKILL might cut short.
#[test]
fn sigcont_checkpoints_and_goes_on_and_sigusr1_stops() {
    let t = tempfile::tempdir().unwrap();
    pile(t.path(), 60);
    let child = start_run(t.path(), "particles000001.csv");
    signal(&child, libc::SIGCONT);
    let ckpt = t.path().join("out/checkpoint.bin");
    let start = Instant::now();
    while !ckpt.exists() {
        assert!(start.elapsed() < Duration::from_secs(30), "no checkpoint");
        std::thread::sleep(Duration::from_millis(2));
    }
    let first = checkpoint::decode(&std::fs::read(&ckpt).unwrap(), None).unwrap();
    // Still running: more frames come.
    let next = format!("particles{:06}.csv", first.steps / 2000 + 2);
    while !t.path().join("out").join(&next).exists() {
        assert!(start.elapsed() < Duration::from_secs(60), "the run stopped");
        std::thread::sleep(Duration::from_millis(2));
    }
    signal(&child, libc::SIGUSR1);
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert_contains(
        &err,
        &[
            &format!("SIGCONT: checkpoint of step {} written", first.steps),
            "interrupted after step",
            &format!(
                "the checkpoint of step {}, written on SIGCONT, is",
                first.steps
            ),
        ],
    );
    let last = checkpoint::decode(&std::fs::read(&ckpt).unwrap(), None).unwrap();
    assert_eq!(last.steps, first.steps);
    assert!(t.path().join("out/interrupted.csv").exists());
}

/// A run blocked in a write (here: a FIFO where the next frame's temporary file goes, as a
/// hung network file system would) cannot see the stop it is asked for; a second signal
/// ends it at once.
#[test]
fn a_second_signal_ends_a_blocked_run_at_once() {
    let t = tempfile::tempdir().unwrap();
    pile(t.path(), 60);
    let child = start_run(t.path(), "particles000000.csv");
    let fifo = t.path().join("out/.particles000003.csv.tmp");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let frames = t.path().join("out/frames.csv");
    let start = Instant::now();
    while std::fs::read_to_string(&frames).map_or(0, |f| f.lines().count()) < 4 {
        assert!(start.elapsed() < Duration::from_secs(60), "run too slow");
        std::thread::sleep(Duration::from_millis(2));
    }
    // Frame 2 is out; frame 3 cannot be written: wait until the run is stuck in it (on a
    // loaded machine the steps up to frame 3 may take seconds).
    wait_until_blocked_on_a_fifo(&child);
    signal(&child, libc::SIGTERM);
    std::thread::sleep(Duration::from_millis(500));
    let mut child = child;
    assert!(
        child.try_wait().unwrap().is_none(),
        "blocked, it cannot stop"
    );
    let asked = Instant::now();
    signal(&child, libc::SIGTERM);
    let out = child.wait_with_output().unwrap();
    assert!(asked.elapsed() < Duration::from_secs(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert_contains(&err, &["a second signal: stopping now"]);
}
