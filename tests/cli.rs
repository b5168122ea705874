//! The command line: error paths exit non-zero with a clear message and never panic;
//! results do not depend on the number of threads.

use crate::common;

use crate::common::tinydem;
use std::path::{Path, PathBuf};
use std::process::Output;

use tinydem::scenario::Scenario;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Asserts a failed run whose message contains every one of `expected`.
fn fails_with(o: &Output, expected: &[&str]) {
    let err = stderr(o);
    assert!(!o.status.success(), "should fail: {err}");
    assert!(!err.contains("panicked"), "panicked: {err}");
    for e in expected {
        assert!(err.contains(e), "message\n  {err}\nlacks\n  {e}");
    }
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const HEADER: &str = "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n";

#[test]
fn missing_scenario_file() {
    let t = tempfile::tempdir().unwrap();
    fails_with(
        &tinydem(&["run", "nope.toml"], t.path()),
        &["cannot read scenario file nope.toml"],
    );
    fails_with(&tinydem(&["check", "nope.toml"], t.path()), &["nope.toml"]);
}

#[test]
fn missing_mesh_and_particle_files() {
    let t = tempfile::tempdir().unwrap();
    let dir = std::path::absolute(t.path()).unwrap();
    let tried = |name: &str| dir.join(name).display().to_string();
    // The scenario, the key and the path tried, before anything runs.
    write(t.path(), "m.toml", "[geometry]\nmesh = \"absent.off\"\n");
    fails_with(
        &tinydem(&["run", "m.toml"], t.path()),
        &["m.toml: [geometry] mesh: cannot read", &tried("absent.off")],
    );
    let shapes = "[[meshes]]\nshape = { type = \"plane\", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 1.0 }\n";
    write(
        t.path(),
        "k.toml",
        &format!("{shapes}[[meshes]]\nfile = \"sub/box.stl\"\n"),
    );
    fails_with(
        &tinydem(&["check", "k.toml"], t.path()),
        &[
            "k.toml: [[meshes]] #2 file: cannot read",
            &tried("sub/box.stl"),
        ],
    );
    write(t.path(), "p.toml", "[input]\nparticles = \"absent.csv\"\n");
    fails_with(
        &tinydem(&["run", "p.toml"], t.path()),
        &[
            "p.toml: [input] particles: cannot read",
            &tried("absent.csv"),
        ],
    );
}

#[test]
fn the_default_run_takes_the_run_options_and_misplaced_ones_are_explained() {
    let t = tempfile::tempdir().unwrap();
    // The hint of a refused second run works as written.
    let o = tinydem(&["--output", "first", "--quiet"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(t.path().join("first/particles000001.csv").exists());
    fails_with(
        &tinydem(&["-o", "first", "-q"], t.path()),
        &["or --output another directory"],
    );
    fails_with(
        &tinydem(&["--output", "x", "render", "first"], t.path()),
        &["go after the command: tinydem render ... --output DIR"],
    );
    // A run killed before its first checkpoint: --resume says why there is none.
    std::fs::remove_file(t.path().join("first/checkpoint.bin")).unwrap();
    fails_with(
        &tinydem(
            &["-o", "first", "--resume", "first/checkpoint.bin"],
            t.path(),
        ),
        &[
            "holds frames up to particles000100.csv but no checkpoint",
            "checkpoint_minutes",
            "--overwrite",
        ],
    );
}

#[test]
fn malformed_off_files() {
    let t = tempfile::tempdir().unwrap();
    write(
        t.path(),
        "s.toml",
        "[geometry]\nmesh = \"m.off\"\nmesh_radii = [0.0]\n",
    );
    let cases: &[(&str, &[&str])] = &[
        (
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n5 0 1 2 0 1\n",
            &["m.off:6", "1 to 4 vertices"],
        ),
        (
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
            &["m.off:6", "vertex index 7 is out of range"],
        ),
        (
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 3\n",
            &["m.off:6", "radius index 3"],
        ),
        (
            "OFF\n3 1 0\n0 0 0\n1 zero 0\n",
            &["m.off:4", "found 'zero'"],
        ),
        (
            "OFF\n3 1 0\n0 0 0\n1 0\n",
            &["m.off:4", "three finite numbers"],
        ),
        (
            "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
            &["ends after 1 of 2 faces"],
        ),
        (
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n0\n",
            &["m.off:6", "1 to 4 vertices"],
        ),
        ("PLY\n", &["m.off:1", "expected the keyword 'OFF'"]),
        ("OFF\n999999999999 1 0\n", &["more than the file can hold"]),
    ];
    for (off, expected) in cases {
        write(t.path(), "m.off", off);
        fails_with(&tinydem(&["run", "s.toml"], t.path()), expected);
    }
    std::fs::write(t.path().join("m.off"), [0xffu8, 0xfe, 0x00, 0x12]).unwrap();
    fails_with(&tinydem(&["run", "s.toml"], t.path()), &["not a text file"]);
}

#[test]
fn malformed_csv_files() {
    let t = tempfile::tempdir().unwrap();
    write(t.path(), "s.toml", "[input]\nparticles = \"p.csv\"\n");
    let row = "0,0,0.1,0.005,0,0,0,1,0,0,0,0,0,0\n";
    let cases: Vec<(String, &[&str])> = vec![
        (
            format!("{HEADER}0,0,0.1,-0.005,0,0,0,1,0,0,0,0,0,0\n"),
            &["p.csv:2", "radius R = -0.005 must be > 0"],
        ),
        // Radii far from the scenario's [R_min, R_max] = [0.002, 0.01] (Table 2).
        (
            format!("{HEADER}{row}0,0,0.1,5.0,0,0,0,1,0,0,0,0,0,0\n"),
            &[
                "p.csv:3",
                "radius R = 5 is more than 64 times [geometry] radius_max = 0.01",
            ],
        ),
        (
            format!("{HEADER}0,0,0.1,0.0005,0,0,0,1,0,0,0,0,0,0\n"),
            &[
                "p.csv:2",
                "radius R = 0.0005 is below half [geometry] radius_min = 0.002",
            ],
        ),
        (
            "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,material\n\
             0,0,0.1,0.005,0,0,0,1,0,0,0,0,0,0,0\n0,0,0.2,0.005,0,0,0,1,0,0,0,0,0,0,3\n"
                .to_string(),
            &[
                "p.csv:3",
                "material 3, but the scenario has 1 material (0 to 0)",
            ],
        ),
        (
            format!("{HEADER}{row}0,0,nan,0.005,0,0,0,1,0,0,0,0,0,0\n"),
            &["p.csv:3", "finite"],
        ),
        (
            format!("{HEADER}0,0,0.1,0.005\n"),
            &["p.csv:2", "expected 14 values, found 4"],
        ),
        (
            format!("{HEADER}0,0,0.1,0.005,0,0,0,1,0,0,0,0,0,x\n"),
            &["p.csv:2", "column 14 ('wz')", "found 'x'"],
        ),
        (
            "x,y,z,R\n".to_string(),
            &["p.csv:1", "column 'vx' is missing"],
        ),
        (String::new(), &["p.csv", "empty file"]),
        (
            format!("{HEADER}0,0,0.1,0.005,0,0,0,0,0,0,0,0,0,0\n"),
            &["p.csv:2", "quaternion"],
        ),
    ];
    for (csv, expected) in cases {
        write(t.path(), "p.csv", &csv);
        fails_with(&tinydem(&["run", "s.toml"], t.path()), expected);
    }
}

#[test]
fn bad_scenario_values_and_arguments() {
    let t = tempfile::tempdir().unwrap();
    write(t.path(), "s.toml", "[material]\nrestitution = 2.0\n");
    fails_with(
        &tinydem(&["run", "s.toml"], t.path()),
        &["s.toml", "restitution = 2", "[0, 1]"],
    );
    fails_with(&tinydem(&["run"], t.path()), &["SCENARIO"]);
    fails_with(&tinydem(&["frobnicate"], t.path()), &["frobnicate"]);
    write(t.path(), "ok.toml", "[simulation]\nframes = 0\n");
    fails_with(
        &tinydem(&["run", "ok.toml", "--threads", "0"], t.path()),
        &["--threads must be at least 1"],
    );
}

#[test]
fn unwritable_output_directory_is_reported_before_simulating() {
    let t = tempfile::tempdir().unwrap();
    write(t.path(), "s.toml", "[simulation]\nframes = 1\n");
    write(t.path(), "file", "not a directory");
    fails_with(
        &tinydem(&["run", "s.toml", "--output", "file/sub"], t.path()),
        &["cannot create output directory", "file/sub"],
    );
}

#[test]
fn check_prints_derived_quantities() {
    let t = tempfile::tempdir().unwrap();
    write(t.path(), "s.toml", "[simulation]\nframes = 10\n");
    let o = tinydem(&["check", "s.toml"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    for key in [
        "time step",
        "6.033241e-5",
        "particle mass",
        "stiffness",
        "total simulated time",
        "output",
        "friction springs       advance_first",
    ] {
        assert!(out.contains(key), "missing {key} in\n{out}");
    }
}

/// The pair table says where each pair's coefficients and sub-models come from, for a pair
/// of one material too.
#[test]
fn check_says_where_each_pairs_coefficients_come_from() {
    let t = tempfile::tempdir().unwrap();
    write(
        t.path(),
        "s.toml",
        "[[materials]]\nname = \"a\"\ncohesion = 200.0\n[[materials]]\nname = \"b\"\ncohesion = 100.0\n\
         [[interactions]]\nmaterials = [\"b\", \"a\"]\nfriction_sliding = 0.5\nadhesion_model = \"none\"\n\
         [[interactions]]\nmaterials = [\"b\", \"b\"]\nrestitution = 0.9\n\
         [simulation]\nframes = 1\n",
    );
    let o = tinydem(&["check", "s.toml"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    for line in [
        "a - a: e_n 0.5, mu_s 0.3, mu_r 0.3, mu_t 0.2, k_c 200 (its own)",
        "a - b: e_n 0.5, mu_s 0.5, mu_r 0.3, mu_t 0.2, k_c 0 (mu_s, adhesion_model from [[interactions]], the rest means)",
        "b - b: e_n 0.9, mu_s 0.3, mu_r 0.3, mu_t 0.2, k_c 100 (e_n from [[interactions]], the rest its own)",
    ] {
        assert!(out.contains(line), "missing {line} in\n{out}");
    }
}

/// `verify` runs its cases, prints the table, writes the report, and refuses an unknown
/// case naming the known ones.
#[test]
fn verify_runs_the_analytic_cases_and_writes_its_report() {
    let t = tempfile::tempdir().unwrap();
    let o = tinydem(&["verify", "--quick", "--report", "report"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    for case in [
        "hertz_impact",
        "restitution",
        "free_fall",
        "wall_impact",
        "chung_ooi_1",
        "chung_ooi_2",
        "chung_ooi_3",
        "chung_ooi_4",
        "slip_to_rolling",
        "stacked_spheres",
        "heat_relaxation",
        "heat_chain",
        "heat_sources",
        "hooke_impact",
        "rolling_resistance",
        "dmt_contact",
        "jkr_contact",
        "liquid_bridge",
        "energy_ledger",
    ] {
        assert!(out.contains(case), "missing {case} in\n{out}");
    }
    assert!(out.contains("checks pass") && !out.contains(" NO"), "{out}");
    let report = std::fs::read_to_string(t.path().join("report/verify.md")).unwrap();
    assert!(
        report.contains("| `hertz_impact` | contact time [s] |"),
        "{report}"
    );
    let o = tinydem(&["verify", "--only", "hertz_impact,nope"], t.path());
    fails_with(&o, &["no case \"nope\"", "stacked_spheres"]);
}

#[test]
fn check_says_the_order_of_the_friction_springs() {
    let t = tempfile::tempdir().unwrap();
    write(
        t.path(),
        "s.toml",
        "[simulation]\nframes = 1\nfriction_springs = \"paper\"\n",
    );
    let o = tinydem(&["check", "s.toml"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    let line = "friction springs       paper (the force of the previous step's spring";
    assert!(out.contains(line), "missing {line} in\n{out}");
}

#[test]
fn check_names_periodic_sides_shear_and_spawn_regions_and_warns_only_of_real_removals() {
    let t = tempfile::tempdir().unwrap();
    // Two grains just past a periodic side (put back in) and one below the floor (removed).
    let grains = format!(
        "{HEADER}0.0505,0,0.05,0.004,0,0,0,1,0,0,0,0,0,0\n0,-0.0502,0.05,0.004,0,0,0,1,0,0,0,0,0,0\n\
         0,0,-0.06,0.004,0,0,0,1,0,0,0,0,0,0\n"
    );
    write(t.path(), "p.csv", &grains);
    write(
        t.path(),
        "s.toml",
        "[geometry]\nradius_min = 0.004\nradius_max = 0.005\n\
         [simulation]\nframes = 1\nmax_particles = 50\n\
         [domain]\nmin = [-0.05, -0.05, -0.05]\nmax = [0.05, 0.05, 0.2]\nperiodic = [true, true, false]\n\
         [input]\nparticles = \"p.csv\"\n\
         [[spawn]]\nmin = [-0.04, -0.04, 0.1]\nmax = [0.04, 0.04, 0.15]\ncount = 40\n",
    );
    let o = tinydem(&["check", "s.toml"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    for line in [
        "(periodic along x and y: particles leaving it across another side are removed)",
        "warning: 1 initial particles lie outside it and are removed at the first step",
        "spawn region 1         [-0.04, -0.04, 0.1] .. [0.04, 0.04, 0.15]: 40 particles, R uniform in [0.004, 0.005]",
        "in all at most 50 particles (max_particles)",
    ] {
        assert!(out.contains(line), "missing {line} in\n{out}");
    }
    // And the shear of a Lees-Edwards box.
    write(
        t.path(),
        "le.toml",
        "[simulation]\nframes = 1\nmax_particles = 0\n\
         [domain]\nmin = [-0.05, -0.05, -0.05]\nmax = [0.05, 0.05, 0.05]\nperiodic = [true, true, true]\n\
         lees_edwards = { velocity = 0.2, shear_axis = \"x\", gradient_axis = \"z\" }\n",
    );
    let o = tinydem(&["check", "le.toml"], t.path());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    for line in [
        "(periodic along x, y and z: nothing leaves it)",
        "Lees-Edwards           the images across the z sides move at 0.2 m/s along x (shear rate 2.000000e0/s)",
        "spawning               none",
    ] {
        assert!(out.contains(line), "missing {line} in\n{out}");
    }
}

#[test]
fn a_run_that_would_spawn_in_the_default_box_outside_its_domain_says_how_to_fix_it() {
    let t = tempfile::tempdir().unwrap();
    write(
        t.path(),
        "s.toml",
        "[simulation]\nframes = 1\n[domain]\nmin = [-0.2, -0.2, -0.2]\nmax = [0.2, 0.2, 0.35]\n",
    );
    for command in ["check", "run"] {
        let o = tinydem(&[command, "s.toml"], t.path());
        let err = stderr(&o);
        assert!(!o.status.success(), "{command}");
        assert!(
            err.contains("spawn box [-0.1, -0.1, 0.3] .. [0.1, 0.1, 0.4] must lie inside [domain]")
                && err.contains("the paper's default, as the scenario names no spawn box: name one, add [[spawn]] regions, or set [simulation] max_particles = 0"),
            "{command}: {err}"
        );
    }
    // With nothing to spawn, the default box does not matter.
    write(
        t.path(),
        "s.toml",
        "[simulation]\nframes = 1\nmax_particles = 0\n[domain]\nmin = [-0.2, -0.2, -0.2]\nmax = [0.2, 0.2, 0.35]\n",
    );
    let o = tinydem(&["check", "s.toml"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn check_says_which_meshes_merge_their_contacts() {
    let t = tempfile::tempdir().unwrap();
    let square = "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
    write(t.path(), "a.off", square);
    write(t.path(), "b.off", square);
    write(
        t.path(),
        "s.toml",
        "[geometry]\nmesh = \"a.off\"\nmesh_radii = [0.0]\n\
         [[meshes]]\nfile = \"b.off\"\ncontacts = \"per_face\"\n",
    );
    let o = tinydem(&["check", "s.toml"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    for line in [
        "a.off: 2 faces, contacts merged (one per touch of a connected surface; 1 surface)",
        "mesh 1                 b.off: 2 faces, contacts per face (the original program's)",
    ] {
        assert!(out.contains(line), "missing {line} in\n{out}");
    }
}

/// The frames of a short hourglass run (spawning, mesh and particle contacts).
fn hourglass_frames(threads: &str, dir: &Path) -> Vec<Vec<u8>> {
    let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/hourglass.off");
    write(
        dir,
        "s.toml",
        &format!(
            "[geometry]\nmesh = \"{}\"\n[simulation]\nmax_particles = 1500\nframes = 4\nsteps_per_frame = 600\n",
            mesh.display()
        ),
    );
    let o = tinydem(
        &[
            "run",
            "s.toml",
            "-q",
            "--threads",
            threads,
            "--output",
            "out",
        ],
        dir,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    (0..=4)
        .map(|k| std::fs::read(dir.join(format!("out/particles{k:06}.csv"))).unwrap())
        .collect()
}

#[test]
fn output_is_identical_for_one_and_two_threads() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let one = hourglass_frames("1", a.path());
    let two = hourglass_frames("2", b.path());
    assert!(one[4].len() > 1000 * 100, "the run spawned particles");
    for (k, (x, y)) in one.iter().zip(&two).enumerate() {
        assert!(x == y, "frame {k} differs between 1 and 2 threads");
    }
}

#[test]
fn output_format_is_the_original_one() {
    let t = tempfile::tempdir().unwrap();
    let frames = hourglass_frames("2", t.path());
    let text = String::from_utf8(frames[1].clone()).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz"));
    let row: Vec<f64> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(row.len(), 14);
    // Frame 0 is the initial state: the hourglass run starts empty.
    assert_eq!(
        String::from_utf8(frames[0].clone())
            .unwrap()
            .lines()
            .count(),
        1
    );
}

#[test]
fn bench_runs_a_small_configuration() {
    let t = tempfile::tempdir().unwrap();
    let o = tinydem(
        &[
            "bench",
            "--sizes",
            "1000",
            "--workers",
            "1",
            "--steps",
            "5",
            "--repeats",
            "1",
        ],
        t.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    let row: Vec<&str> = out
        .lines()
        .nth(1)
        .expect("a result row")
        .split_whitespace()
        .collect();
    assert_eq!(row[0], "1000");
    let cundall: f64 = row[4].parse().unwrap();
    let contacts: f64 = row[8].parse().unwrap();
    assert!(cundall > 0.0);
    // The settled packing: about 3.7 contacts per particle counted per particle, i.e.
    // about half that counted once per pair, plus walls.
    assert!(
        contacts > 1.5 && contacts < 3.5,
        "contacts per particle {contacts}"
    );
    fails_with(
        &tinydem(&["bench", "--sizes", "1234", "--workers", "1"], t.path()),
        &["no packing for N = 1234"],
    );
}

#[test]
fn render_draws_frames_and_directories() {
    let t = tempfile::tempdir().unwrap();
    let frames = hourglass_frames("2", t.path());
    assert!(frames.len() == 5);
    renders_a_frame(t.path());
    renders_a_directory_in_one_view(t.path());
    renders_a_movie_in_a_fixed_box(t.path());
    fails_with(
        &tinydem(&["render", "nope.csv"], t.path()),
        &["cannot read particle file nope.csv"],
    );
    fails_with(
        &tinydem(
            &["render", "out/particles000004.csv", "--width", "0"],
            t.path(),
        ),
        &["picture size 0x1200"],
    );
    fails_with(
        &tinydem(
            &["render", "out/particles000004.csv", "--size", "800by600"],
            t.path(),
        ),
        &["\"800by600\" is no WIDTHxHEIGHT"],
    );
}

/// A frame of the run in `dir`, with the hourglass mesh.
fn renders_a_frame(dir: &Path) {
    let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/hourglass.off");
    let o = tinydem(
        &[
            "render",
            "out/particles000004.csv",
            "--mesh",
            mesh.to_str().unwrap(),
            "-o",
            "f.png",
            "--size",
            "320x200",
        ],
        dir,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(dir.join("f.png")).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (320, 200));
    let drawn = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
    assert!(drawn > 320 * 200 / 50, "only {drawn} pixels drawn");
}

/// A directory: one PNG per frame and an animation; the scenario supplies the mesh.
fn renders_a_directory_in_one_view(dir: &Path) {
    let o = tinydem(
        &[
            "render",
            "out",
            "--scenario",
            "s.toml",
            "--gif",
            "--width",
            "160",
            "--height",
            "120",
        ],
        dir,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    for k in 0..=4 {
        assert!(dir.join(format!("out/particles{k:06}.png")).exists());
    }
    let gif = std::fs::read(dir.join("out/animation.gif")).unwrap();
    assert!(gif.starts_with(b"GIF89a"));
    // One view for all frames: the static mesh's edges are the same pixels in each picture
    // (the run.toml of the directory supplies the mesh), and so is the colour bar.
    let pictures: Vec<image::RgbImage> = (0..=4)
        .map(|k| {
            image::open(dir.join(format!("out/particles{k:06}.png")))
                .unwrap()
                .to_rgb8()
        })
        .collect();
    let edge = |img: &image::RgbImage| {
        img.enumerate_pixels()
            .filter(|(_, _, p)| p.0 == [60, 60, 60])
            .map(|(x, y, _)| (x, y))
            .collect::<std::collections::BTreeSet<_>>()
    };
    let first = edge(&pictures[0]);
    assert!(first.len() > 100, "{}", first.len());
    let last = edge(&pictures[4]);
    assert!(last.is_subset(&first), "the view moved");
}

/// --range and --bounds, and a movie (an animated GIF where ffmpeg is missing).
fn renders_a_movie_in_a_fixed_box(dir: &Path) {
    let o = common::tinydem_with_env(
        &[
            "render",
            "out",
            "-o",
            "pics",
            "--movie",
            "--range",
            "0,5",
            "--bounds",
            "-0.2,-0.2,-0.3,0.2,0.2,0.3",
            "--scale-bar",
            "--width",
            "200",
            "--height",
            "150",
        ],
        dir,
        &[("PATH", "/nonexistent")],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("an animated GIF instead"),
        "{}",
        stderr(&o)
    );
    assert!(dir.join("pics/animation.gif").exists());
    fails_with(
        &tinydem(&["render", "out", "--range", "5,1"], dir),
        &["--range 5,1"],
    );
    // With the system's ffmpeg (CI installs it), an MP4.
    let ffmpeg = std::process::Command::new("ffmpeg")
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success());
    if ffmpeg {
        let o = tinydem(&["render", "out", "-o", "movie", "--movie"], dir);
        assert!(o.status.success(), "{}", stderr(&o));
        let mp4 = std::fs::read(dir.join("movie/animation.mp4")).unwrap();
        assert_eq!(&mp4[4..8], b"ftyp", "an MP4 file");
    } else {
        eprintln!("no ffmpeg: the MP4 path is not tested here");
    }
}

#[test]
fn tag_regions_label_particles_and_add_a_tag_column() {
    let t = tempfile::tempdir().unwrap();
    write(
        t.path(),
        "s.toml",
        "[geometry]\nspawn_min = [-0.05, -0.05, 0.3]\nspawn_max = [0.05, 0.05, 0.4]\n\
         [simulation]\nmax_particles = 100\nframes = 2\nsteps_per_frame = 2000\n\
         [[tags]]\nmin = [-1.0, -1.0, -10.0]\nmax = [0.0, 1.0, 0.25]\ntag = 3\n\
         [[tags]]\nmin = [0.0, -1.0, -10.0]\nmax = [1.0, 1.0, 0.25]\ntag = 4\n",
    );
    let o = tinydem(&["run", "s.toml", "-q"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(t.path().join("output/particles000002.csv")).unwrap();
    assert!(text.starts_with("x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,tag\n"));
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 100);
    // Every particle fell below z = 0.25 and took the tag of the side it fell on.
    for r in &rows {
        assert!(r[2] < 0.25);
        assert_eq!(r[14], if r[0] <= 0.0 { 3.0 } else { 4.0 }, "{r:?}");
    }
    // The tagged frame reads back, tags included.
    let p = tinydem::io::csv::load_particles(&t.path().join("output/particles000002.csv")).unwrap();
    assert!(p.tag.iter().all(|&t| t == 3 || t == 4));
}

#[test]
fn analyze_prints_a_table_and_writes_csv_and_plot() {
    let t = tempfile::tempdir().unwrap();
    hourglass_frames("2", t.path());
    let o = tinydem(
        &[
            "analyze",
            "out",
            "--scenario",
            "s.toml",
            "--large",
            "0.009",
            "--csv",
            "a.csv",
            "--plot",
            "a.png",
            "--column",
            "coordination,packing_fraction",
        ],
        t.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let table = String::from_utf8_lossy(&o.stdout);
    assert_eq!(table.lines().count(), 6, "{table}");
    let csv = std::fs::read_to_string(t.path().join("a.csv")).unwrap();
    let last: Vec<f64> = csv
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(last[0], 4.0);
    assert!(
        (last[1] - 4.0 * 600.0 * 6.0332412e-5).abs() < 1e-6,
        "time {}",
        last[1]
    );
    assert!(
        last[2] > 1000.0 && last[3] > 0.0 && last[4] > 0.0,
        "{last:?}"
    );
    assert!(image::open(t.path().join("a.png")).is_ok());
    fails_with(
        &tinydem(
            &["analyze", "out", "--plot", "b.png", "--column", "nope"],
            t.path(),
        ),
        &["no column \"nope\" (the columns: frame, time,"],
    );
    plots_the_log(t.path());
}

/// `tinydem plot` of the run's log: two columns on a log axis as SVG, wall loads of one
/// mesh as PNG; a missing column or a bad filter is refused.
fn plots_the_log(dir: &Path) {
    let o = tinydem(
        &[
            "plot",
            "out/log.csv",
            "-y",
            "kinetic_energy,rotational_energy",
            "--log-y",
            "-o",
            "e.svg",
        ],
        dir,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let svg = std::fs::read_to_string(dir.join("e.svg")).unwrap();
    assert!(svg.contains("kinetic_energy [J]") && svg.contains("rotational_energy [J]"));
    assert!(svg.contains("time [s]"));
    fails_with(
        &tinydem(&["plot", "out/log.csv", "-y", "energy"], dir),
        &["no column \"energy\" (the columns: frame, step, time,"],
    );
    fails_with(
        &tinydem(
            &["plot", "out/log.csv", "-y", "time", "--where", "frame"],
            dir,
        ),
        &["--where frame: expected COLUMN=NUMBER"],
    );
    let o = tinydem(
        &[
            "plot",
            "out/log.csv",
            "-x",
            "step",
            "-y",
            "particles",
            "--where",
            "frame=2",
            "-o",
            "p.png",
            "--plot-size",
            "400x300",
        ],
        dir,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(dir.join("p.png")).unwrap();
    assert_eq!((img.width(), img.height()), (400, 300));
}

/// `analyze --repose`: both flanks with their errors from the resting grains; frames without
/// a pile give nan and one note that says why; a window that cannot be is refused.
#[test]
fn analyze_repose_fits_resting_flanks_and_says_when_there_is_no_pile() {
    let t = tempfile::tempdir().unwrap();
    std::fs::create_dir(t.path().join("out")).unwrap();
    // Frame 0: grains in the air. Frame 1: a resting 45° heap 40 diameters tall.
    let (r, mut gas, mut heap) = (0.001, String::from(HEADER), String::from(HEADER));
    for k in 0..100 {
        gas += &format!("{},0,0.5,{r},0,0,-1,1,0,0,0,0,0,0\n", 0.003 * k as f64);
    }
    for c in -40i32..=40 {
        let x = 2.0 * r * c as f64;
        let mut z = r;
        while z + r <= 0.08 - x.abs() {
            heap += &format!("{x},0,{z},{r},0,0,0,1,0,0,0,0,0,0\n");
            z += 2.0 * r;
        }
    }
    write(t.path(), "out/particles000000.csv", &gas);
    write(t.path(), "out/particles000001.csv", &heap);
    let o = tinydem(&["analyze", "out", "--repose", "--csv", "a.csv"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("no pile in 1 of 2 frames (nan), e.g. frame 0: 0 grains at rest"),
        "{}",
        stderr(&o)
    );
    let csv = std::fs::read_to_string(t.path().join("a.csv")).unwrap();
    let mut lines = csv.lines();
    assert!(
        lines
            .next()
            .unwrap()
            .ends_with("repose_left_deg,repose_left_err_deg,repose_right_deg,repose_right_err_deg"),
        "{csv}"
    );
    assert!(lines.next().unwrap().ends_with("nan,nan,nan,nan"), "{csv}");
    let v: Vec<f64> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let n = v.len();
    assert!(
        (v[n - 4] - 45.0).abs() < 1.0 && (v[n - 2] - 45.0).abs() < 1.0,
        "{v:?}"
    );
    assert!(v[n - 3] < 0.5 && v[n - 1] < 0.5, "{v:?}");
    // A window reaching further down than the pile changes nothing; one that cannot be is
    // refused.
    let o = tinydem(
        &["analyze", "out", "--repose", "--window", "3,30"],
        t.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    fails_with(
        &tinydem(
            &["analyze", "out", "--repose", "--window", "30,3"],
            t.path(),
        ),
        &["--window FROM,TO needs 0 <= FROM < TO, got 30,3"],
    );
    fails_with(
        &tinydem(&["analyze", "out", "--repose", "--window", "3"], t.path()),
        &["--window FROM,TO takes two numbers, got 1"],
    );
    fails_with(
        &tinydem(
            &["analyze", "out", "--repose", "--rest-speed", "0"],
            t.path(),
        ),
        &["--rest-speed must be positive, got 0"],
    );
    fails_with(
        &tinydem(&["analyze", "out", "--window", "3,30"], t.path()),
        &["--repose"],
    );
}

#[test]
fn a_run_reports_where_its_time_went() {
    let dir = tempfile::tempdir().unwrap();
    // Enough particles that each stage takes more than the 0.05 % of the run the line shows
    // on a loaded machine too.
    write(
        dir.path(),
        "s.toml",
        "[geometry]\nspawn_min = [0, 0, 0]\nspawn_max = [0.2, 0.2, 0.2]\n\
         [simulation]\nmax_particles = 1000\nframes = 2\nsteps_per_frame = 100\n",
    );
    let o = tinydem(&["run", "s.toml", "--output", "out"], dir.path());
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    let line = err
        .lines()
        .find(|l| l.starts_with("time: "))
        .unwrap_or_else(|| panic!("no time line in\n{err}"));
    for stage in ["particle contacts", "integrate", "frames"] {
        assert!(line.contains(stage), "{stage} missing from {line}");
    }
    // Quiet runs stay quiet.
    let o = tinydem(&["run", "s.toml", "-q", "--output", "out2"], dir.path());
    assert!(o.status.success());
    assert!(stderr(&o).is_empty(), "{}", stderr(&o));
}

/// An output directory describes itself: `run.toml` is the resolved scenario (it loads back
/// to the same one, from anywhere), `frames.csv` lists frame, step and time, and `analyze`
/// finds the frame times and the density without `--scenario`.
#[test]
fn output_directories_describe_their_run() {
    let t = tempfile::tempdir().unwrap();
    let s = write(
        t.path(),
        "s.toml",
        "[geometry]\nspawn_min = [0, 0, 0]\nspawn_max = [0.1, 0.1, 0.1]\n\
         [material]\ndensity = 2000.0\n\
         [simulation]\ntimestep = 2e-5\nmax_particles = 30\nframes = 3\nsteps_per_frame = 40\n",
    );
    let o = tinydem(&["run", "s.toml", "-q"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = t.path().join("output");
    let again = Scenario::load(&out.join("run.toml")).unwrap();
    assert_eq!(again, Scenario::load(&s).unwrap().absolute());
    let frames = std::fs::read_to_string(out.join("frames.csv")).unwrap();
    let lines: Vec<&str> = frames.lines().collect();
    assert_eq!(lines[0], "frame,step,time");
    assert_eq!(lines.len(), 5, "{frames}");
    assert!(lines[2].starts_with("1,40,0.0008"), "{frames}");
    let a = tinydem(&["analyze", "output"], t.path());
    assert!(a.status.success(), "{}", stderr(&a));
    let table = String::from_utf8_lossy(&a.stdout).to_string();
    let row = table.lines().nth(2).unwrap();
    assert!(
        row.contains("8.000000e-4"),
        "frame 1 at t = 40 x 2e-5 s: {table}"
    );
}

/// A directory with the output of an earlier run is refused (frames of two runs would mix)
/// unless `--overwrite`, which removes that output first; a second run into a directory that
/// a live run holds is refused, a lock left by a killed run is taken over.
#[test]
fn output_of_another_run_is_not_mixed_in() {
    let t = tempfile::tempdir().unwrap();
    let scenario = |frames: u32| {
        format!(
            "[geometry]\nspawn_min = [0, 0, 0]\nspawn_max = [0.1, 0.1, 0.1]\n\
             [simulation]\nmax_particles = 20\nframes = {frames}\nsteps_per_frame = 20\n"
        )
    };
    write(t.path(), "long.toml", &scenario(3));
    write(t.path(), "short.toml", &scenario(1));
    let o = tinydem(&["run", "long.toml", "-q"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let o = tinydem(&["run", "short.toml", "-q"], t.path());
    fails_with(&o, &["holds the output of an earlier run", "--overwrite"]);
    std::fs::write(t.path().join("output/notes.txt"), "mine").unwrap();
    // What the tools made of the first run goes with it too (a stale animation.gif stayed).
    let o = tinydem(
        &[
            "render", "output", "--gif", "--width", "160", "--height", "120",
        ],
        t.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let made = [
        "animation.gif",
        "particles000003.png",
        "fields_mean.vti",
        "fields000003.csv",
    ];
    for name in &made[2..] {
        std::fs::write(t.path().join("output").join(name), "derived").unwrap();
    }
    let o = tinydem(&["run", "short.toml", "-q", "--overwrite"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = t.path().join("output");
    assert!(out.join("particles000001.csv").exists());
    assert!(
        !out.join("particles000003.csv").exists(),
        "frames of the first run are gone"
    );
    for name in made {
        assert!(!out.join(name).exists(), "{name} of the first run stayed");
    }
    assert!(out.join("notes.txt").exists(), "other files stay");
    assert!(
        !out.join(".tinydem.lock").exists(),
        "the lock goes with the run"
    );
    // A live process holds the directory (this test, with the lock), then nobody: the file
    // left by a killed run names a process that lives (this test's, a reused id) or not.
    let held = tinydem::io::lock::Lock::take(&out).unwrap();
    let o = tinydem(&["run", "short.toml", "-q", "--overwrite"], t.path());
    fails_with(&o, &["another tinydem run (process", "is writing into"]);
    drop(held);
    for pid in [std::process::id(), 999_999_999] {
        std::fs::write(out.join(".tinydem.lock"), format!("{pid}\n")).unwrap();
        let o = tinydem(&["run", "short.toml", "-q", "--overwrite"], t.path());
        assert!(o.status.success(), "{}", stderr(&o));
    }
}

/// A run of 300 grains for `frames` frames of 100 steps (about 0.1 s a frame).
fn busy_scenario(frames: u32) -> String {
    format!(
        "[geometry]\nspawn_min = [-0.05, -0.05, 0.0]\nspawn_max = [0.05, 0.05, 0.3]\n\
         [simulation]\nmax_particles = 300\nframes = {frames}\nsteps_per_frame = 100\n"
    )
}

/// Frame files of a directory and their bytes.
fn frames_of(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with("particles"))
        .map(|n| (n.clone(), std::fs::read(dir.join(&n)).unwrap()))
        .collect();
    files.sort();
    files
}

/// Runs refused by the lock, one after another beside a running run, harm it in nothing:
/// it completes with the frames of a run alone (they used to clear its temporary files).
#[test]
fn refused_runs_beside_a_running_one_leave_it_whole() {
    let t = tempfile::tempdir().unwrap();
    write(t.path(), "s.toml", &busy_scenario(30));
    let o = tinydem(&["run", "s.toml", "-q", "-o", "alone"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let mut first = std::process::Command::new(env!("CARGO_BIN_EXE_tinydem"))
        .args(["run", "s.toml", "-q", "-o", "same"])
        .current_dir(t.path())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while !t.path().join("same/.tinydem.lock").exists() {
        assert!(
            started.elapsed().as_secs() < 30,
            "the first run does not start"
        );
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let mut refused = 0;
    while first.try_wait().unwrap().is_none() {
        let o = tinydem(
            &["run", "s.toml", "-q", "-o", "same", "--overwrite"],
            t.path(),
        );
        if o.status.success() {
            break; // started after the first had ended
        }
        fails_with(&o, &["another tinydem run"]);
        refused += 1;
    }
    let status = first.wait().unwrap();
    assert!(
        status.success(),
        "the first run failed beside {refused} refused ones"
    );
    assert!(refused >= 5, "only {refused} runs were refused");
    assert!(
        frames_of(&t.path().join("same")) == frames_of(&t.path().join("alone")),
        "the frames differ from a run alone"
    );
}

/// Two runs started together into one fresh directory: one runs, the other is refused,
/// and the one that runs writes the frames of a run alone.
#[test]
fn of_two_runs_started_together_exactly_one_runs() {
    let t = tempfile::tempdir().unwrap();
    write(t.path(), "s.toml", &busy_scenario(3));
    let o = tinydem(&["run", "s.toml", "-q", "-o", "alone"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let alone = frames_of(&t.path().join("alone"));
    for k in 0..20 {
        let dir = format!("together{k}");
        let start = || {
            std::process::Command::new(env!("CARGO_BIN_EXE_tinydem"))
                .args(["run", "s.toml", "-q", "-o", &dir])
                .current_dir(t.path())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap()
        };
        let (a, b) = (start(), start());
        let outputs = [a.wait_with_output().unwrap(), b.wait_with_output().unwrap()];
        let ran = outputs.iter().filter(|o| o.status.success()).count();
        for o in outputs.iter().filter(|o| !o.status.success()) {
            let err = stderr(o);
            assert!(
                err.contains("another tinydem run")
                    || err.contains("holds the output of an earlier run"),
                "try {k}: {err}"
            );
        }
        assert_eq!(ran, 1, "try {k}");
        assert!(
            frames_of(&t.path().join(&dir)) == alone,
            "try {k}: frames differ"
        );
    }
}

/// `log.csv` carries what the status line shows, frame by frame: the kinetic energy agrees
/// with `analyze` of the frames, the contacts per particle with its coordination number
/// (pairs and face contacts of the last step against pairs that overlap in the frame).
#[test]
fn the_log_follows_the_state_frame_by_frame() {
    let t = tempfile::tempdir().unwrap();
    hourglass_frames("2", t.path());
    let log = std::fs::read_to_string(t.path().join("out/log.csv")).unwrap();
    let mut lines = log.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header,
        tinydem::driver::run::LOG_HEADER
            .split(',')
            .collect::<Vec<_>>()
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 5, "{log}");
    let a = tinydem(&["analyze", "out", "--csv", "a.csv"], t.path());
    assert!(a.status.success(), "{}", stderr(&a));
    let table = std::fs::read_to_string(t.path().join("a.csv")).unwrap();
    let columns: Vec<&str> = table.lines().next().unwrap().split(',').collect();
    let col = |name: &str| columns.iter().position(|c| *c == name).unwrap();
    let of = |name: &str| header.iter().position(|c| *c == name).unwrap();
    for (row, line) in rows.iter().zip(table.lines().skip(1)) {
        let a: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
        let e = row[of("kinetic_energy")];
        assert!(
            (e - a[col("kinetic_energy")]).abs() <= 1e-6 * e,
            "{row:?} {a:?}"
        );
        assert!(row[of("rotational_energy")] <= e);
        let pairs = row[of("pair_contacts")];
        let n = row[of("particles")];
        assert!(
            (2.0 * pairs / n.max(1.0) - a[col("coordination")]).abs() < 0.05,
            "{row:?} {a:?}"
        );
    }
    let last = rows.last().unwrap();
    assert!(last[of("pair_contacts")] > 100.0 && last[of("wall_contacts")] > 10.0);
    assert!(last[of("max_overlap")] > 0.0 && last[of("max_overlap")] < 1.0);
    // The status line shows the same.
    let o = tinydem(&["run", "s.toml", "--output", "again"], t.path());
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    let line = err.lines().find(|l| l.starts_with("frame      4")).unwrap();
    for part in ["E_k ", "contacts/particle ", "overlap/R "] {
        assert!(line.contains(part), "{part} missing from {line}");
    }
}

/// `check` warns of a time step far past Eq. 50 and of output larger than the free space,
/// and `run` refuses both unless `--force`; `check` estimates the wall time from a trial.
#[test]
fn check_warns_and_run_refuses_what_would_fail() {
    let t = tempfile::tempdir().unwrap();
    let base = "[geometry]\nspawn_min = [0, 0, 0]\nspawn_max = [0.1, 0.1, 0.1]\n\
                [simulation]\nmax_particles = 30\nsteps_per_frame = 20\n";
    // Eq. 50 for the defaults (R_min 2 mm, rho 1000, E 1e6, nu 0.3): 6.033e-5 s.
    write(
        t.path(),
        "fast.toml",
        &format!("{base}frames = 2\ntimestep = 3e-4\n"),
    );
    write(
        t.path(),
        "huge.toml",
        &format!("{base}frames = 1000000000\n"),
    );
    write(t.path(), "fine.toml", &format!("{base}frames = 2\n"));
    let check = |name: &str| {
        let o = tinydem(&["check", name], t.path());
        assert!(o.status.success(), "{}", stderr(&o));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let fine = check("fine.toml");
    assert!(!fine.contains("warning"), "{fine}");
    let wall = fine.lines().find(|l| l.starts_with("wall time")).unwrap();
    assert!(wall.contains("the whole run, timed"), "{wall}");
    assert!(fine.contains(" free in "), "{fine}");
    let fast = check("fast.toml");
    assert!(
        fast.contains("warning: time step 3.000e-4 s is 5.0 x Eq. 50"),
        "{fast}"
    );
    let huge = check("huge.toml");
    assert!(huge.contains("warning: the output may grow to"), "{huge}");
    let wall = huge.lines().find(|l| l.starts_with("wall time")).unwrap();
    assert!(wall.contains("a trial of"), "{wall}");
    for name in ["fast.toml", "huge.toml"] {
        let o = tinydem(&["run", name, "-q", "-o", "out"], t.path());
        fails_with(&o, &["run with --force"]);
        assert!(!t.path().join("out").exists(), "refused before writing");
    }
    let o = tinydem(
        &["run", "fast.toml", "-q", "--force", "-o", "out"],
        t.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

/// A FIFO named as a mesh (or as particles) is refused at once; it used to block the run
/// for good, deaf to SIGTERM and SIGINT.
#[test]
fn a_fifo_as_an_input_file_is_refused_without_blocking() {
    let t = tempfile::tempdir().unwrap();
    let made = std::process::Command::new("mkfifo")
        .arg(t.path().join("fifo"))
        .status()
        .unwrap();
    assert!(made.success());
    for (name, text) in [
        ("mesh.toml", "[geometry]\nmesh = \"fifo\"\n"),
        ("csv.toml", "[input]\nparticles = \"fifo\"\n"),
    ] {
        write(t.path(), name, text);
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_tinydem"))
            .args(["run", name, "-q", "-o", "out"])
            .current_dir(t.path())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let start = std::time::Instant::now();
        while child.try_wait().unwrap().is_none() {
            if start.elapsed().as_secs() > 20 {
                child.kill().unwrap();
                panic!("{name}: the run blocks on the FIFO");
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        fails_with(
            &child.wait_with_output().unwrap(),
            &["fifo", "not a regular file"],
        );
    }
}

/// `tinydem analyze --energy`: the ledger's breakdown at the last frame (the shares of the
/// energy put in add up to one) and its plot; a log without the ledger is refused.
#[test]
fn analyze_energy_tells_where_the_energy_went() {
    let t = tempfile::tempdir().unwrap();
    hourglass_frames("2", t.path());
    fails_with(
        &tinydem(&["analyze", "out", "--energy"], t.path()),
        &["log.csv has no energy ledger: run with [output] energy_ledger = true"],
    );
    let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/hourglass.off");
    write(
        t.path(),
        "e.toml",
        &format!(
            "[geometry]\nmesh = \"{}\"\n[simulation]\nmax_particles = 500\nframes = 3\nsteps_per_frame = 600\n\
             [output]\nenergy_ledger = true\n",
            mesh.display()
        ),
    );
    let o = tinydem(&["run", "e.toml", "-q", "--output", "ledger"], t.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let o = tinydem(
        &["analyze", "ledger", "--energy", "--plot", "e.png"],
        t.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    let share = |column: &str| -> f64 {
        let line = out.lines().find(|l| l.starts_with(column)).expect(column);
        let pct = line.split_whitespace().last().unwrap();
        pct.trim_end_matches('%').parse::<f64>().unwrap() / 100.0
    };
    // What holds the energy and what took it: all but the work, the energy spawned and the
    // residual.
    let taken = tinydem::model::ledger::COLUMNS
        .into_iter()
        .filter(|c| c.starts_with("dissipated_") || *c == "energy_removed");
    let columns: Vec<&str> = ["kinetic_energy", "stored_elastic"]
        .into_iter()
        .chain(taken)
        .collect();
    let total: f64 = columns.iter().map(|c| share(c)).sum();
    assert!((total - 1.0).abs() < 1e-4, "{total}\n{out}");
    assert!(share("dissipated_sliding") > 0.0, "{out}");
    assert!(image::open(t.path().join("e.png")).is_ok());
}
