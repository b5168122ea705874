//! Moving meshes: friction with a moving wall uses the wall's velocity at the contact point.

use std::path::Path;

use tinydem::engine::Simulation;
use tinydem::scenario::Scenario;

const R: f64 = 0.005;

/// A simulation of the scenario text with the mesh files written into a temporary folder.
fn sim(dir: &Path, files: &[(&str, String)], text: &str) -> Simulation {
    for (name, content) in files {
        std::fs::write(dir.join(name), content).unwrap();
    }
    let s = Scenario::parse(text, &dir.join("s.toml")).unwrap();
    Simulation::new(s).unwrap()
}

const PLATE: &str = "OFF\n4 1 0\n-0.5 -0.5 0\n0.5 -0.5 0\n0.5 0.5 0\n-0.5 0.5 0\n4 0 1 2 3\n";

/// Overlap of a sphere resting on a rigid plane under gravity (Hertz, E* = E / (1 - ν²)).
fn resting_overlap() -> f64 {
    let m = 4.0 / 3.0 * std::f64::consts::PI * 1000.0 * R.powi(3);
    let e_star = 1e6 / (1.0 - 0.09);
    (m * 9.81 / (4.0 / 3.0 * e_star * R.sqrt())).powf(2.0 / 3.0)
}

fn particle_file(dir: &Path, z: f64) {
    std::fs::write(
        dir.join("p.csv"),
        format!("x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n0,0,{z},{R},0,0,0,1,0,0,0,0,0,0\n"),
    )
    .unwrap();
}

#[test]
fn plate_moving_sideways_carries_a_resting_sphere_by_static_friction() {
    let t = tempfile::tempdir().unwrap();
    particle_file(t.path(), R - resting_overlap());
    let v_plate = 0.1;
    let mut s = sim(
        t.path(),
        &[("plate.off", PLATE.to_string())],
        &format!(
            "[geometry]\nradius_min = {R}\nradius_max = {R}\n[simulation]\nmax_particles = 0\n\
             [[meshes]]\nfile = \"plate.off\"\nmotion = {{ type = \"velocity\", velocity = [{v_plate}, 0.0, 0.0] }}\n\
             [input]\nparticles = \"p.csv\"\n"
        ),
    );
    let dt = s.scenario.simulation.timestep;
    let steps = (0.3 / dt) as usize;
    for _ in 0..steps {
        s.step().unwrap();
    }
    // Carried along: moving with the plate, and staying on the same spot of it.
    let x0 = s.particles.x[0].x - s.time * v_plate;
    for _ in 0..steps {
        s.step().unwrap();
        assert!(s.contact_count() == 1, "lost contact");
    }
    let v = s.particles.v[0];
    assert!((v.x - v_plate).abs() < 1e-4 * v_plate, "v = {v}");
    let slip = s.particles.x[0].x - s.time * v_plate - x0;
    assert!(slip.abs() < 1e-7, "slipped by {slip} m on the plate");
    assert!(
        s.particles.w[0].length() < 1e-3,
        "rolls: {}",
        s.particles.w[0]
    );
}

/// Steps without contact of a sphere on a plate vibrating vertically with amplitude 1 mm
/// and peak acceleration `peak` (in g), after two periods of settling.
fn flights(peak: f64) -> usize {
    let t = tempfile::tempdir().unwrap();
    let a = 0.001;
    let omega = (peak * 9.81 / a).sqrt();
    let f = omega / (2.0 * std::f64::consts::PI);
    // Phase π/2: the plate starts at its top (z = A) at rest.
    particle_file(t.path(), a + R - resting_overlap());
    let mut s = sim(
        t.path(),
        &[("plate.off", PLATE.to_string())],
        &format!(
            "[geometry]\nradius_min = {R}\nradius_max = {R}\n[simulation]\nmax_particles = 0\n\
             [[meshes]]\nfile = \"plate.off\"\n\
             motion = {{ type = \"harmonic\", amplitude = {a}, frequency = {f}, direction = [0.0, 0.0, 1.0], phase = {} }}\n\
             [input]\nparticles = \"p.csv\"\n",
            std::f64::consts::FRAC_PI_2
        ),
    );
    let dt = s.scenario.simulation.timestep;
    let period = (1.0 / f / dt) as usize;
    let mut free = 0;
    for k in 0..12 * period {
        s.step().unwrap();
        if k > 2 * period && s.contact_count() == 0 {
            free += 1;
        }
    }
    free
}

#[test]
fn vibrated_plate_keeps_contact_below_one_g_and_loses_it_above() {
    assert_eq!(flights(0.5), 0, "lost contact at 0.5 g");
    assert_eq!(flights(0.9), 0, "lost contact at 0.9 g");
    let f2 = flights(2.0);
    eprintln!("steps in flight at 2 g: {f2}");
    assert!(f2 > 100, "never took off at 2 g");
}

/// A drum of radius 5 cm and width 4 cm about the y axis, as 24 rectangles and two caps.
fn drum() -> String {
    let (r, w, n) = (0.05f64, 0.02f64, 24);
    let mut v = Vec::new();
    for k in 0..n {
        let th = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
        v.push(format!("{} {} {}", r * th.cos(), -w, r * th.sin()));
        v.push(format!("{} {} {}", r * th.cos(), w, r * th.sin()));
    }
    let c = 1.1 * r;
    for y in [-w, w] {
        for (x, z) in [(-c, -c), (c, -c), (c, c), (-c, c)] {
            v.push(format!("{x} {y} {z}"));
        }
    }
    let mut f = Vec::new();
    for k in 0..n {
        let (a, b) = (2 * k, 2 * ((k + 1) % n));
        f.push(format!("4 {a} {b} {} {}", b + 1, a + 1));
    }
    f.push(format!(
        "4 {} {} {} {}",
        2 * n,
        2 * n + 1,
        2 * n + 2,
        2 * n + 3
    ));
    f.push(format!(
        "4 {} {} {} {}",
        2 * n + 4,
        2 * n + 5,
        2 * n + 6,
        2 * n + 7
    ));
    format!(
        "OFF\n{} {} 0\n{}\n{}\n",
        v.len(),
        f.len(),
        v.join("\n"),
        f.join("\n")
    )
}

/// Mean x of the particles in a drum turning at `omega` about +y, after filling and turning.
fn drum_mean_x(omega: f64) -> f64 {
    let t = tempfile::tempdir().unwrap();
    let mut s = sim(
        t.path(),
        &[("drum.off", drum())],
        &format!(
            "[geometry]\nradius_min = 0.003\nradius_max = 0.004\n\
             spawn_min = [-0.03, -0.015, -0.04]\nspawn_max = [0.03, 0.015, 0.0]\n\
             [kinetics]\ninitial_velocity = [0.0, 0.0, 0.0]\n\
             [simulation]\nmax_particles = 120\nspawn_attempts = 20\n\
             [[meshes]]\nfile = \"drum.off\"\n\
             motion = {{ type = \"rotation\", center = [0.0, 0.0, 0.0], axis = [0.0, 1.0, 0.0], angular_velocity = {omega} }}\n"
        ),
    );
    let dt = s.scenario.simulation.timestep;
    for _ in 0..(1.0 / dt) as usize {
        s.step().unwrap();
    }
    assert_eq!(s.particles.len(), 120);
    // All inside the drum.
    for x in &s.particles.x {
        assert!(
            (x.x * x.x + x.z * x.z).sqrt() < 0.05 && x.y.abs() < 0.02,
            "escaped: {x}"
        );
    }
    s.particles.x.iter().map(|x| x.x).sum::<f64>() / s.particles.len() as f64
}

#[test]
fn rotating_drum_carries_particles_up_its_wall() {
    // Turning about +y, the drum's bottom moves toward -x: the bed is dragged up the -x side.
    let still = drum_mean_x(0.0);
    let turning = drum_mean_x(3.0);
    assert!(
        still.abs() < 0.003,
        "a still drum's bed is centred: {still}"
    );
    assert!(
        turning < -0.008,
        "a turning drum's bed leans toward -x: {turning}"
    );
    eprintln!("drum mean x: still {still}, turning {turning}");
    let reverse = drum_mean_x(-3.0);
    assert!(
        reverse > 0.008,
        "and toward +x when turning the other way: {reverse}"
    );
}
