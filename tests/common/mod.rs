//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use glam::{DQuat, DVec3};
use tinydem::engine::Simulation;
use tinydem::model::particles::Particle;
use tinydem::scenario::Scenario;

pub fn data(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(path)
}

/// A scenario from TOML text; relative paths resolve against `tests/data`.
pub fn scenario(text: &str) -> Scenario {
    Scenario::parse(text, &data("inline.toml")).expect("valid test scenario")
}

/// A scenario from TOML text read as if from `path` (relative paths resolve against its
/// directory).
pub fn scenario_at(text: &str, path: &Path) -> Scenario {
    Scenario::parse(text, path).expect("valid test scenario")
}

/// A simulation of `particles`, all of radius `radius`, with the `[material]` lines
/// `material`, gravity `g` along -z, the mesh `off` (OFF text; none if empty) and the time
/// step `dt`; no spawning.
pub fn single_grains(
    radius: f64,
    material: &str,
    (g, off): (f64, &str),
    dt: f64,
    particles: Vec<Particle>,
) -> Simulation {
    let s = scenario(&format!(
        "[geometry]\nradius_min = {radius}\nradius_max = {radius}\nmesh_radii = [0.0]\n\
         [material]\n{material}\n\
         [kinetics]\ngravity = [0.0, 0.0, {}]\n\
         [simulation]\ntimestep = {dt:e}\nmax_particles = 0\nspawn_attempts = 0\n",
        -g
    ));
    let mesh = if off.is_empty() {
        tinydem::geometry::mesh::Mesh::default()
    } else {
        tinydem::geometry::mesh::Mesh::parse_off(off, "mesh", &s.geometry.mesh_radii).unwrap()
    };
    let particles = particles.into_iter().collect();
    Simulation::from_parts(s, mesh, particles).unwrap()
}

/// 200 grains poured into the silo for 3000 steps with the `[material]` lines `models`
/// (restitution 0.3, μ_s 0.5 before them) on `threads` threads with the skin `skin`: the
/// grains in id order and the number of contacts at the end.
pub fn silo_pour(models: &str, threads: usize, skin: f64) -> (Vec<Particle>, usize) {
    let text = format!(
        "[geometry]\nradius_min = 0.002\nradius_max = 0.003\nmesh = \"stages/silo.off\"\nmesh_radii = [0.0]\n\
         spawn_min = [-0.03, -0.03, 0.02]\nspawn_max = [0.03, 0.03, 0.1]\n\
         [material]\nrestitution = 0.3\nfriction_sliding = 0.5\n{models}\n\
         [simulation]\nmax_particles = 200\nskin = {skin}\n"
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(move || {
        let s = simulate(&text, 3000);
        let by_id = s.particles.iter_by_id().map(|e| e.1).collect();
        (by_id, s.held_contacts().len())
    })
}

/// A sphere of radius `radius` at `x` with velocity `v` and spin `w`, unrotated, tag and
/// material 0.
pub fn sphere(radius: f64, x: DVec3, v: DVec3, w: DVec3) -> Particle {
    Particle {
        x,
        radius,
        v,
        q: DQuat::IDENTITY,
        w,
        tag: 0,
        material: 0,
        fixed: false,
        body: None,
        ..Particle::default()
    }
}

/// Runs `steps` steps of a scenario given as TOML text.
pub fn simulate(text: &str, steps: u64) -> Simulation {
    let mut sim = Simulation::new(scenario(text)).expect("simulation starts");
    for _ in 0..steps {
        sim.step().unwrap();
    }
    sim
}

/// Runs the `tinydem` binary with `args` in `dir`.
pub fn tinydem(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tinydem"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("binary runs")
}

/// Runs the `tinydem` binary with `args` in `dir`, with the environment variables `env` set.
pub fn tinydem_with_env(args: &[&str], dir: &Path, env: &[(&str, &str)]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tinydem"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(dir)
        .output()
        .expect("binary runs")
}

/// A closed drum (radius 0.05 m, 0.03 m long along y) as an OFF text: `n` rectangles around,
/// and two end caps of triangles.
pub fn drum_off(n: usize) -> String {
    let (r, y) = (0.05, 0.015);
    let mut v = Vec::new();
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        v.push(format!("{} {} {}", r * a.cos(), -y, r * a.sin()));
        v.push(format!("{} {} {}", r * a.cos(), y, r * a.sin()));
    }
    v.push(format!("0 {} 0", -y));
    v.push(format!("0 {y} 0"));
    let mut f = Vec::new();
    for k in 0..n {
        let (a, b) = (2 * k, 2 * ((k + 1) % n));
        f.push(format!("4 {a} {b} {} {}", b + 1, a + 1));
        f.push(format!("3 {} {a} {b}", 2 * n));
        f.push(format!("3 {} {} {}", 2 * n + 1, b + 1, a + 1));
    }
    format!(
        "OFF\n{} {} 0\n{}\n{}\n",
        v.len(),
        f.len(),
        v.join("\n"),
        f.join("\n")
    )
}

/// Whether python3 with meshio (a real VTK reader) is here; without it a test that needs it
/// says it was skipped, except under CI, where `.ci/run` installs meshio: there it fails.
pub fn has_meshio() -> bool {
    let found = Command::new("python3")
        .args(["-c", "import meshio, numpy"])
        .status()
        .is_ok_and(|s| s.success());
    if !found {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI must have meshio (pip install meshio)"
        );
        eprintln!(
            "SKIPPED (the part with a real VTK reader): python3 with meshio not found (pip install meshio)"
        );
    }
    found
}
