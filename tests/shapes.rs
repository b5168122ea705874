//! Built-in shapes (`[[meshes]] shape = ...`) hold grains: one sphere dropped into each comes to
//! rest where the shape's geometry puts it, and the shape carries its weight.
//! (Areas and volumes against the analytic ones: `src/geometry/shapes/tests.rs`.)

use crate::common;

use std::f64::consts::PI;

use glam::DVec3;
use tinydem::driver::check;
use tinydem::engine::Simulation;
use tinydem::engine::setup::Inputs;
use tinydem::io::inputs;
use tinydem::model::contact::damping_factor;
use tinydem::model::integrate::Inertia;
use tinydem::model::particles::Particles;
use tinydem::scenario::Scenario;

const R: f64 = 0.005;
const RHO: f64 = 1000.0;
const E: f64 = 1e6;
const NU: f64 = 0.3;
const G: f64 = 9.81;

/// The scenario of one sphere of radius `R` in the shape `shape`, its wall loads summed,
/// with `[simulation]` lines `extra`.
fn scenario(shape: &str, extra: &str) -> Scenario {
    let text = format!(
        "[geometry]\nradius_min = {R}\nradius_max = {R}\n\
         [material]\ndensity = {RHO}\nyoungs_modulus = {E}\npoisson_ratio = {NU}\n\
         restitution = 0.3\n\
         [kinetics]\ngravity = [0.0, 0.0, -{G}]\n\
         [simulation]\nmax_particles = 0\nspawn_attempts = 0\n{extra}\n\
         [output]\nwall_forces = true\n\
         [[meshes]]\nshape = {shape}\n"
    );
    common::scenario(&text)
}

/// One sphere dropped from `x` (at rest) into `scenario`'s shape; after `seconds`, its state
/// and the mean load on the shape over the last 1,000 steps.
fn drop_into_with(scenario: Scenario, x: DVec3, seconds: f64) -> (DVec3, DVec3, DVec3) {
    let inputs = Inputs {
        meshes: inputs::meshes(&scenario).unwrap(),
        particles: std::iter::once(common::sphere(R, x, DVec3::ZERO, DVec3::ZERO))
            .collect::<Particles>(),
    };
    let mut sim = Simulation::from_inputs(scenario, inputs).unwrap();
    let steps = (seconds / sim.scenario.simulation.timestep).round() as u64;
    for _ in 0..steps - 1000 {
        sim.step().unwrap();
    }
    sim.take_wall_loads();
    for _ in 0..1000 {
        sim.step().unwrap();
    }
    let loads = sim.take_wall_loads();
    // Mesh 0 is `[geometry] mesh` (none here), mesh 1 the shape.
    let load = loads[1].f / 1000.0;
    (sim.particles.x[0], sim.particles.v[0], load)
}

/// [`drop_into_with`] at the time step of Eq. 50.
fn drop_into(shape: &str, x: DVec3, seconds: f64) -> (DVec3, DVec3, DVec3) {
    drop_into_with(scenario(shape, ""), x, seconds)
}

/// The overlap of a sphere of radius `R` pressed onto a flat rigid wall by its weight (Hertz).
fn sag() -> f64 {
    let e_star = E / (1.0 - NU * NU);
    (3.0 * weight() / (4.0 * e_star * R.sqrt())).powf(2.0 / 3.0)
}

fn weight() -> f64 {
    Inertia::mass(R, RHO) * G
}

/// At rest, where expected to `within` [m], and its weight on the shape to 0.1 %.
fn rests(what: &str, (x, v, load): (DVec3, DVec3, DVec3), expected: DVec3, within: f64) {
    assert!(v.length() < 1e-5, "{what}: still moving at {v}");
    assert!(
        (x - expected).length() < within,
        "{what}: rests at {x}, expected {expected} (within {within})"
    );
    let w = DVec3::new(0.0, 0.0, -weight());
    assert!(
        (load - w).length() < 1e-3 * weight(),
        "{what}: the shape carries {load}, the grain weighs {w}"
    );
}

#[test]
fn a_grain_rests_on_a_plane_a_kilometre_wide_in_little_memory() {
    // Binned in cells of 2 R_max + skin, the plane would fill 10^9 cells (it took 24 GB and
    // was killed): it goes to a coarser level of the face grid instead.
    let plane =
        "{ type = \"plane\", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 1000.0 }";
    let at = DVec3::new(0.01, -0.02, R - sag());
    rests(
        "kilometre plane",
        drop_into(plane, DVec3::new(0.01, -0.02, 0.02), 0.6),
        at,
        0.02 * sag(),
    );
}

#[test]
fn a_grain_rests_on_a_plane_and_on_the_floor_of_a_box() {
    let plane =
        "{ type = \"plane\", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 0.1 }";
    let at = DVec3::new(0.01, -0.02, R - sag());
    rests(
        "plane",
        drop_into(plane, DVec3::new(0.01, -0.02, 0.02), 0.6),
        at,
        0.02 * sag(),
    );
    let cup =
        "{ type = \"box\", min = [-0.05, -0.05, -0.01], max = [0.05, 0.05, 0.1], open = [\"+z\"] }";
    rests(
        "box",
        drop_into(cup, DVec3::new(0.01, -0.02, 0.02), 0.6),
        DVec3::new(0.01, -0.02, -0.01 + R - sag()),
        0.02 * sag(),
    );
}

#[test]
fn a_grain_rests_on_the_bottom_of_a_cylinder_beside_its_orifice() {
    // Off the axis, on the annulus between the orifice (r = 0.01) and the wall (0.04).
    let silo = "{ type = \"cylinder\", center = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 1.0], radius = 0.04, height = 0.1, open = [\"top\"], orifice = 0.01 }";
    let x = DVec3::new(0.02, 0.005, 0.03);
    rests(
        "cylinder",
        drop_into(silo, x, 0.6),
        DVec3::new(0.02, 0.005, R - sag()),
        0.02 * sag(),
    );
}

#[test]
fn a_grain_rests_in_the_lowest_groove_of_a_drum() {
    // Axis along y: vertex k of the 48-gon at angle 2 pi k / 48 from x, towards -z; the
    // lowest vertex (k = 12) is a groove between two rectangles inclined by pi / 48, each at
    // the apothem r cos(pi / 48) from the axis. A sphere touching both lies below the axis
    // at the depth d with (r - d) cos(pi / 48) = R (less the sag along each normal).
    let (r, n) = (0.04, 48.0);
    let drum = format!(
        "{{ type = \"drum\", center = [0.0, 0.0, 0.05], axis = [0.0, 1.0, 0.0], radius = {r}, length = 0.03, resolution = {n} }}"
    );
    let c = (PI / n).cos();
    let d = r - R / c;
    rests(
        "drum",
        drop_into(&drum, DVec3::new(0.0, 0.0, 0.05), 0.6),
        DVec3::new(0.0, 0.0, 0.05 - d),
        0.05 * R,
    );
}

#[test]
fn a_grain_larger_than_the_outlet_rests_in_a_hopper_at_the_step_check_asks_for() {
    // A cone frustum about the z axis; a sphere on the axis touches the 48 faces of the
    // inscribed polygonal cone (apothems r cos(pi / 48)) where its centre is R from them.
    let (ro, rt, h, n) = (0.003, 0.04, 0.05, 48.0);
    let hopper = format!(
        "{{ type = \"hopper\", center = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 1.0], top_radius = {rt}, outlet_radius = {ro}, height = {h}, resolution = {n} }}"
    );
    let x = DVec3::new(0.0, 0.0, 0.04);
    // At Eq. 50's step the 48 contacts in parallel are too stiff: the grain gains energy
    // and leaves the hopper upwards. `check` and `run` say so, with the step to take.
    let eq50 = scenario(&hopper, "");
    let warned = check::cautions(&eq50);
    assert_eq!(warned.len(), 1, "{warned:?}");
    assert!(
        warned[0]
            .contains("seated in its outlet of [[meshes]] #1 (a built-in hopper) touches 48 faces")
    );
    let (x_end, v_end, _) = drop_into_with(eq50.clone(), x, 0.8);
    assert!(
        x_end.z > h || v_end.length() > 0.1,
        "the grain rests at Eq. 50's step ({x_end}, {v_end}): is the warning still needed?"
    );
    let beta = damping_factor(0.3);
    let dt = eq50.eq50_timestep() * check::seat_timestep(n as u32, beta);
    let smaller = scenario(&hopper, &format!("timestep = {dt}"));
    assert!(check::cautions(&smaller).is_empty());
    // Where it rests: the faces' plane in the (apothem, z) half-plane is
    // a(z) = c (ro + (rt - ro) z / h); the distance from (0, z) to it is R.
    let c = (PI / n).cos();
    let slope = c * (rt - ro) / h;
    let z = (R * (1.0 + slope * slope).sqrt() - c * ro) / slope;
    let got = drop_into_with(smaller, x, 0.8);
    // On the axis to 1 um (48 faces press it from all around); z to 5 % of R.
    assert!(got.0.truncate().length() < 1e-6, "off the axis: {}", got.0);
    rests("hopper", got, DVec3::new(0.0, 0.0, z), 0.05 * R);
}

#[test]
fn check_warns_of_seats_only_where_a_grain_fits_a_ring_of_faces() {
    let warns = |shape: &str| !check::cautions(&scenario(shape, "")).is_empty();
    let cone = |outlet: f64, res: u32| {
        format!(
            "{{ type = \"hopper\", center = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 1.0], top_radius = 0.04, outlet_radius = {outlet}, height = 0.05, resolution = {res} }}"
        )
    };
    // A closed cone's apex, an outlet narrower than the grain: 48 faces at once.
    assert!(warns(&cone(0.0, 48)) && warns(&cone(0.004, 48)));
    // An outlet the grain falls through; 6 faces, which Eq. 50's step resolves at e = 0.3.
    assert!(!warns(&cone(0.006, 48)) && !warns(&cone(0.0, 6)));
    let silo = |orifice: f64| {
        format!(
            "{{ type = \"cylinder\", center = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 1.0], radius = 0.04, height = 0.1, open = [\"top\"], orifice = {orifice} }}"
        )
    };
    assert!(warns(&silo(0.003)) && !warns(&silo(0.0)) && !warns(&silo(0.01)));
}
