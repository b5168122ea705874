//! The friction springs' update order (`[simulation] friction_springs`): advanced before
//! their force is taken, they create no energy; in the paper's order (Eqs. 53-55 as
//! printed, the original program's) they do. Elastic impacts, the tangential restitution's
//! independence of Δt, a bed that comes to rest and a column whose wall carries load.

use crate::common;

use glam::DVec3;
use tinydem::engine::Simulation;
use tinydem::geometry::mesh::Mesh;
use tinydem::model::integrate::Inertia;
use tinydem::model::particles::{Particle, Particles};
use tinydem::scenario::Scenario;

const R: f64 = 0.005;
const RHO: f64 = 1000.0;

/// A square floor rectangle at z = 0.
const FLOOR: &str = "OFF\n4 1 0\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n4 0 1 2 3\n";

#[derive(Clone, Copy, Debug, PartialEq)]
enum Order {
    AdvanceFirst,
    Paper,
}

impl Order {
    fn key(self) -> &'static str {
        match self {
            Order::AdvanceFirst => "advance_first",
            Order::Paper => "paper",
        }
    }
}

/// Friction of one mode only: `[material]` lines for sticking in mode `mode` (μ = 10).
#[derive(Clone, Copy, Debug)]
enum Mode {
    Sliding,
    Rolling,
    Twisting,
}

fn particle(x: DVec3, v: DVec3, w: DVec3) -> Particle {
    common::sphere(R, x, v, w)
}

/// A simulation of `particles` with the `[material]` lines `material`, the time step
/// `dt_factor` x Eq. (50), the floor if `floor` and gravity `g` downwards.
fn sim(
    material: &str,
    order: Order,
    dt_factor: f64,
    (floor, g): (bool, f64),
    particles: Vec<Particle>,
) -> Simulation {
    let text = |dt: String| {
        format!(
            "[geometry]\nradius_min = {R}\nradius_max = {R}\nmesh_radii = [0.0]\n\
             [material]\ndensity = {RHO}\n{material}\n\
             [kinetics]\ngravity = [0.0, 0.0, {}]\n\
             [simulation]\nmax_particles = 0\nspawn_attempts = 0\nfriction_springs = \"{}\"\n{dt}",
            -g,
            order.key()
        )
    };
    let eq50 = common::scenario(&text(String::new())).simulation.timestep;
    let s = common::scenario(&text(format!("timestep = {:e}\n", eq50 * dt_factor)));
    let mesh = if floor {
        Mesh::parse_off(FLOOR, "floor", &s.geometry.mesh_radii).unwrap()
    } else {
        Mesh::default()
    };
    Simulation::from_parts(s, mesh, particles.into_iter().collect::<Particles>()).unwrap()
}

/// Kinetic and rotational energy of all particles.
fn energy(s: &Simulation) -> f64 {
    let p = &s.particles;
    (0..p.len())
        .map(|i| {
            let b = Inertia::new(p.radius[i], RHO, 0.0);
            0.5 * b.m * p.v[i].length_squared() + 0.5 * b.i * p.w[i].length_squared()
        })
        .sum()
}

/// Steps until the bodies have touched and parted again (or a bound is reached).
fn through_the_impact(s: &mut Simulation) {
    let mut touched = false;
    for _ in 0..200_000 {
        s.step().unwrap();
        let touching = s.contact_count() > 0;
        if touched && !touching {
            return;
        }
        touched |= touching;
    }
    panic!("the impact did not end");
}

/// Kinetic energy after / before an elastic impact (e_n = 1) that sticks in mode `mode`,
/// on the floor or between two spheres.
///
/// Rolling and twisting take a spin of 1 m/s at the surface (about a horizontal axis, and
/// about the normal), so that their energy is much of the whole; μ = 10 keeps the springs
/// sticking until the load vanishes. Energy is lost even so: the spring's stiffness falls
/// with the overlap while it holds its stretch (the model's, whatever the order).
fn impact_energy_ratio(mode: Mode, floor: bool, order: Order, dt_factor: f64) -> f64 {
    let spin = 1.0;
    let mu = |m: bool| if m { 10.0 } else { 0.0 };
    let material = format!(
        "restitution = 1.0\nfriction_sliding = {}\nfriction_rolling = {}\nfriction_twisting = {}",
        mu(matches!(mode, Mode::Sliding)),
        mu(matches!(mode, Mode::Rolling)),
        mu(matches!(mode, Mode::Twisting)),
    );
    let gap = 1e-4;
    let particles = if floor {
        // v_n 0.5 m/s; v_t 0.25 m/s (sliding), or a spin.
        let (v, w) = match mode {
            Mode::Sliding => (DVec3::new(0.25, 0.0, -0.5), DVec3::ZERO),
            Mode::Rolling => (DVec3::new(0.0, 0.0, -0.5), DVec3::Y * (spin / R)),
            Mode::Twisting => (DVec3::new(0.0, 0.0, -0.5), DVec3::Z * (spin / R)),
        };
        vec![particle(DVec3::Z * (R + gap), v, w)]
    } else {
        // Along x at 0.5 m/s relative; sliding 0.25 m/s along y, rolling or twisting by
        // opposite spins (which cancel at the contact point, so do not slide).
        let (v, w) = match mode {
            Mode::Sliding => (DVec3::new(0.25, 0.125, 0.0), DVec3::ZERO),
            Mode::Rolling => (DVec3::X * 0.25, DVec3::Z * (spin / R)),
            Mode::Twisting => (DVec3::X * 0.25, DVec3::X * (spin / R)),
        };
        let x = DVec3::X * (R + gap);
        vec![particle(-x, v, w), particle(x, -v, -w)]
    };
    let mut s = sim(&material, order, dt_factor, (floor, 0.0), particles);
    let before = energy(&s);
    through_the_impact(&mut s);
    energy(&s) / before
}

#[test]
fn elastic_sticking_impacts_create_no_energy_when_springs_advance_first() {
    for floor in [true, false] {
        for mode in [Mode::Sliding, Mode::Rolling, Mode::Twisting] {
            let ratio = |order, dt| impact_energy_ratio(mode, floor, order, dt);
            let (at_eq50, at_tenth) = (
                ratio(Order::AdvanceFirst, 1.0),
                ratio(Order::AdvanceFirst, 0.1),
            );
            let what = format!("{mode:?} on {}", if floor { "a plane" } else { "a sphere" });
            assert!(at_eq50 <= 1.02, "{what}: energy x {at_eq50} at Eq. 50");
            assert!(
                at_tenth <= 1.002,
                "{what}: energy x {at_tenth} at Eq. 50 / 10"
            );
            // The paper's order gains energy: the option reproduces it.
            let paper = ratio(Order::Paper, 1.0);
            assert!(
                paper > 1.03 * at_eq50,
                "{what}: the paper's order gave x {paper}, advancing first x {at_eq50}"
            );
        }
    }
}

/// The tangential restitution of the contact point, after / before, of a sphere hitting
/// the floor obliquely with a friction that sticks for part of the impact.
/// Elastic (e_n = 1), μ_s = 0.5, v_t = v_n = 0.5 m/s: it sticks, then slides.
fn tangential_restitution(order: Order, dt_factor: f64) -> f64 {
    let material = "restitution = 1.0\nfriction_sliding = 0.5\nfriction_rolling = 0.0\nfriction_twisting = 0.0";
    let v = DVec3::new(0.5, 0.0, -0.5);
    let mut s = sim(
        material,
        order,
        dt_factor,
        (true, 0.0),
        vec![particle(DVec3::Z * (R + 1e-4), v, DVec3::ZERO)],
    );
    let contact_point =
        |s: &Simulation| (s.particles.v[0] + s.particles.w[0].cross(-DVec3::Z * R)).x;
    let before = contact_point(&s);
    through_the_impact(&mut s);
    contact_point(&s) / before
}

#[test]
fn tangential_restitution_does_not_depend_on_the_time_step() {
    let e_t = |order| -> (Vec<f64>, f64) {
        let e: Vec<f64> = [1.0, 0.5, 0.1]
            .iter()
            .map(|&dt| tangential_restitution(order, dt))
            .collect();
        let spread =
            e.iter().cloned().fold(f64::MIN, f64::max) - e.iter().cloned().fold(f64::MAX, f64::min);
        (e, spread)
    };
    let (first, spread) = e_t(Order::AdvanceFirst);
    assert!(spread < 0.08, "e_t at Eq. 50, / 2, / 10: {first:?}");
    assert!(first.iter().all(|&e| e < 0.0 && e > -0.5), "{first:?}");
    // The paper's order reverses the contact point faster than it came at Eq. 50.
    let (paper, spread) = e_t(Order::Paper);
    assert!(spread > 0.5 && paper[0] < -1.0, "{paper:?}");
}

/// The largest spin left, over the last 0.1 s of 2 s, of a sphere set spinning at 50 rad/s
/// about the normal of the floor it rests on (e_n 0.5, μ_s 0.3, μ_t 0.2), at Eq. (50).
fn twist_left(order: Order) -> f64 {
    let material = "restitution = 0.5\nfriction_sliding = 0.3\nfriction_rolling = 0.3";
    let p = particle(DVec3::Z * (R * 0.9996), DVec3::ZERO, DVec3::Z * 50.0);
    let mut s = sim(material, order, 1.0, (true, 9.81), vec![p]);
    let steps = |t: f64| (t / s.scenario.simulation.timestep) as u64;
    let (settle, last) = (steps(1.9), steps(0.1));
    for _ in 0..settle {
        s.step().unwrap();
    }
    let mut most: f64 = 0.0;
    for _ in 0..last {
        s.step().unwrap();
        most = most.max(s.particles.w[0].length());
    }
    most
}

#[test]
fn a_twisted_sphere_comes_to_rest_at_the_default_time_step() {
    let first = twist_left(Order::AdvanceFirst);
    assert!(first < 1e-6, "still spinning at {first} rad/s");
    // The paper's order keeps a stick-slip limit cycle of the twisting spring.
    let paper = twist_left(Order::Paper);
    assert!(paper > 0.1, "the paper's order left {paper} rad/s");
}

/// An open box 0.06 m square, 0.1 m high: a floor of two triangles and four walls.
const BOX: &str = "OFF\n8 6 0\n\
    -0.03 -0.03 0\n0.03 -0.03 0\n0.03 0.03 0\n-0.03 0.03 0\n\
    -0.03 -0.03 0.1\n0.03 -0.03 0.1\n0.03 0.03 0.1\n-0.03 0.03 0.1\n\
    3 0 1 2\n3 0 2 3\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";

/// 300 grains (R 3-4 mm, the default material) poured into the box; after `seconds`, the
/// kinetic and rotational energy per grain over m g d of a mean grain, and the rms spin.
fn poured_bed(order: Order, seconds: f64) -> (f64, f64) {
    let s = common::scenario(&format!(
        "[geometry]\nradius_min = 0.003\nradius_max = 0.004\nmesh_radii = [0.0]\n\
         spawn_min = [-0.025, -0.025, 0.01]\nspawn_max = [0.025, 0.025, 0.09]\n\
         [kinetics]\ninitial_velocity = [0.0, 0.0, 0.0]\n\
         [simulation]\nmax_particles = 300\nfriction_springs = \"{}\"\n",
        order.key()
    ));
    let mesh = Mesh::parse_off(BOX, "box", &s.geometry.mesh_radii).unwrap();
    let steps = (seconds / s.simulation.timestep).ceil() as u64;
    let mut sim = Simulation::from_parts(s, mesh, Particles::default()).unwrap();
    for _ in 0..steps {
        sim.step().unwrap();
    }
    let p = &sim.particles;
    let n = p.len() as f64;
    let (r, d) = (0.0035, 0.007);
    let mgd = Inertia::mass(r, sim.scenario.material.density) * 9.81 * d;
    let spin = (p.w.iter().map(|w| w.length_squared()).sum::<f64>() / n).sqrt();
    let t = sim.thermo();
    ((t.kinetic_energy + t.rotational_energy) / n / mgd, spin)
}

#[test]
fn a_poured_bed_comes_to_rest() {
    let (energy, spin) = poured_bed(Order::AdvanceFirst, 1.0);
    assert!(energy < 1e-8, "energy per grain {energy} m g d after 1 s");
    assert!(spin < 1e-2, "rms spin {spin} rad/s after 1 s");
    // In the paper's order the springs keep the bed spinning.
    let (energy, spin) = poured_bed(Order::Paper, 1.0);
    assert!(energy > 1e-6 && spin > 0.5, "{energy} m g d, {spin} rad/s");
}

/// A vertical cylinder (radius 0.02 m, 0.15 m high) of `n` rectangles, open at both ends.
fn cylinder_off(n: usize) -> String {
    let (r, h) = (0.02, 0.15);
    let mut v = Vec::new();
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        v.push(format!("{} {} 0", r * a.cos(), r * a.sin()));
        v.push(format!("{} {} {h}", r * a.cos(), r * a.sin()));
    }
    let f: Vec<String> = (0..n)
        .map(|k| {
            let (a, b) = (2 * k, 2 * ((k + 1) % n));
            format!("4 {a} {b} {} {}", b + 1, a + 1)
        })
        .collect();
    format!(
        "OFF\n{} {n} 0\n{}\n{}\n",
        v.len(),
        v.join("\n"),
        f.join("\n")
    )
}

/// 400 grains poured into the cylinder on a floor and settled for 1 s: the share of their
/// weight that the cylinder's wall carries, over the next 0.1 s.
fn wall_share(order: Order) -> f64 {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("wall.off"), cylinder_off(24)).unwrap();
    std::fs::write(
        dir.path().join("floor.off"),
        "OFF\n4 1 0\n-0.03 -0.03 0\n0.03 -0.03 0\n0.03 0.03 0\n-0.03 0.03 0\n4 0 1 2 3\n",
    )
    .unwrap();
    let text = format!(
        "[geometry]\nradius_min = 0.003\nradius_max = 0.004\n\
         spawn_min = [-0.013, -0.013, 0.01]\nspawn_max = [0.013, 0.013, 0.14]\n\
         [kinetics]\ninitial_velocity = [0.0, 0.0, 0.0]\n\
         [simulation]\nmax_particles = 400\nfriction_springs = \"{}\"\n\
         [[meshes]]\nfile = \"wall.off\"\n[[meshes]]\nfile = \"floor.off\"\n\
         [output]\nwall_forces = true\n",
        order.key()
    );
    let path = dir.path().join("column.toml");
    let s = Scenario::parse(&text, &path).unwrap();
    let steps = |t: f64| (t / s.simulation.timestep).ceil() as u64;
    let (settle, measure) = (steps(1.0), steps(0.1));
    let mut sim = Simulation::new(s).unwrap();
    for _ in 0..settle {
        sim.step().unwrap();
    }
    sim.take_wall_loads();
    for _ in 0..measure {
        sim.step().unwrap();
    }
    let loads = sim.take_wall_loads();
    let p = &sim.particles;
    assert_eq!(p.len(), 400);
    let density = sim.scenario.material.density;
    let weight: f64 = p
        .radius
        .iter()
        .map(|&r| Inertia::mass(r, density) * 9.81)
        .sum();
    let [.., wall, floor] = loads[..] else {
        panic!("{} mesh files", loads.len())
    };
    let (wall, floor) = (-wall.f.z / measure as f64, -floor.f.z / measure as f64);
    assert!(
        ((wall + floor) / weight - 1.0).abs() < 0.02,
        "wall {wall} N + floor {floor} N vs weight {weight} N"
    );
    wall / weight
}

#[test]
fn a_column_in_a_cylinder_hangs_part_of_its_weight_on_the_wall() {
    // Measured 0.023 of 0.72 N: poured, the bed slides down the wall while it compacts
    // and keeps part of that friction at rest. (In the paper's order the share creeps up
    // for as long as the grains jiggle, to 0.3 after 1 s: not asserted.)
    let share = wall_share(Order::AdvanceFirst);
    assert!(share > 0.01, "the wall carries {share} of the weight");
}
