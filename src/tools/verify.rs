//! `tinydem verify`: single-contact cases with analytic references, run with the program
//! itself, so that a user sees on their own build whether it reproduces the known answers.
//! Each case runs a small simulation and measures what the theory predicts; a check passes
//! when the relative error is within its tolerance.
//!
//! The cases so far (the analytic limits; the published test series of Chung & Ooi 2011 and
//! of MFIX-DEM are to join them):
//! - `hertz_impact`: an elastic head-on impact of two equal spheres: peak overlap, peak force
//!   (from the change of momentum per step) and contact time against Hertz's solution.
//! - `restitution`: the same impact damped, at two speeds: the coefficient of restitution
//!   against the `restitution` asked for (Eqs. 18, 21).
//! - `free_fall`: a sphere dropped onto a floor: fall time, impact speed, rebound height.
//! - `wall_impact`: an elastic impact on a rigid floor against Hertz, and an oblique one in
//!   gross sliding: the tangential speed and spin after it.
//! - `chung_ooi_2`: Chung & Ooi's (2011) test 2, an elastic normal impact on a rigid plane
//!   (two alloys): peak overlap, peak force, contact time against Hertz.
//! - `slip_to_rolling`: a sphere launched sliding on a floor ends rolling at 5/7 of its speed.
//! - `stacked_spheres`: two spheres at rest on a floor under gravity: the overlaps with the
//!   floor (load 2 m g) and between them (m g) against Hertz's static overlap.

use anyhow::{Result, bail};
use glam::{DQuat, DVec3};

use crate::engine::Simulation;
use crate::geometry::mesh::Mesh;
use crate::model::integrate::Inertia;
use crate::model::particles::{Particle, Particles};
use crate::scenario::Scenario;

/// One quantity of a case: what tinydem measured, the reference, and the tolerance on the
/// relative error.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    pub case: &'static str,
    pub quantity: String,
    pub unit: &'static str,
    pub tinydem: f64,
    pub reference: f64,
    /// The largest relative error that passes.
    pub tolerance: f64,
    /// Whether the case gave the same bits on 1 and on 2 threads (it passes only then).
    pub same_bits: bool,
}

impl Check {
    /// A check of `case`: `quantity` [`unit`] measured as `tinydem`, expected as `reference`
    /// within the relative `tolerance`.
    fn of(
        case: &'static str,
        quantity: impl Into<String>,
        unit: &'static str,
        (tinydem, reference, tolerance): (f64, f64, f64),
    ) -> Check {
        Check {
            case,
            quantity: quantity.into(),
            unit,
            tinydem,
            reference,
            tolerance,
            same_bits: true,
        }
    }

    /// |tinydem - reference| / |reference|.
    pub fn error(&self) -> f64 {
        (self.tinydem - self.reference).abs() / self.reference.abs()
    }

    pub fn passes(&self) -> bool {
        self.error() <= self.tolerance && self.same_bits
    }
}

/// A case: its name, what it checks and against what, and how to run it.
pub struct Case {
    pub name: &'static str,
    pub what: &'static str,
    /// Whether `--quick` runs it.
    pub quick: bool,
    run: fn(Setup) -> Result<Vec<Check>>,
}

/// How a case makes its simulations: `tamper` changes each after its setup (a test makes
/// the model wrong with it, to see the suite fail).
#[derive(Clone, Copy)]
pub struct Setup {
    tamper: fn(&mut Simulation),
}

impl Default for Setup {
    fn default() -> Setup {
        Setup { tamper: |_| {} }
    }
}

/// Every case, in the order of the table.
pub const CASES: &[Case] = &[
    Case {
        name: "hertz_impact",
        what: "elastic head-on impact of two equal spheres against Hertz's solution",
        quick: true,
        run: hertz_impact,
    },
    Case {
        name: "restitution",
        what: "damped head-on impacts: the restitution asked for (Eqs. 18, 21)",
        quick: true,
        run: restitution,
    },
    Case {
        name: "free_fall",
        what: "a sphere dropped onto a floor: fall time, impact speed, rebound height",
        quick: true,
        run: free_fall,
    },
    Case {
        name: "wall_impact",
        what: "elastic and oblique impacts on a rigid floor: Hertz, and the gross-sliding limit",
        quick: true,
        run: wall_impact,
    },
    Case {
        name: "chung_ooi_2",
        what: "Chung & Ooi (2011) test 2: elastic normal impact of a sphere on a rigid plane",
        quick: true,
        run: chung_ooi_2,
    },
    Case {
        name: "slip_to_rolling",
        what: "a sphere sliding on a floor ends rolling at 5/7 of its speed",
        quick: true,
        run: slip_to_rolling,
    },
    Case {
        name: "stacked_spheres",
        what: "two spheres at rest on a floor: Hertz's static overlaps",
        quick: true,
        run: stacked_spheres,
    },
];

/// The checks of the cases `only` names (all without), or of the quick ones if `quick`.
pub fn run(only: &[String], quick: bool) -> Result<Vec<Check>> {
    run_with(only, quick, Setup::default())
}

/// [`run`] with the simulations made by `setup`: each case on 1 and on 2 threads, its
/// checks those of 1 thread, marked with whether 2 gave the same bits.
fn run_with(only: &[String], quick: bool, setup: Setup) -> Result<Vec<Check>> {
    for name in only {
        if !CASES.iter().any(|c| c.name == name) {
            let known: Vec<&str> = CASES.iter().map(|c| c.name).collect();
            bail!("no case \"{name}\": the cases are {}", known.join(", "));
        }
    }
    let mut checks = Vec::new();
    for case in CASES {
        let chosen = if only.is_empty() {
            case.quick || !quick
        } else {
            only.iter().any(|n| n == case.name)
        };
        if chosen {
            let on = |threads: usize| -> Result<Vec<Check>> {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()?;
                pool.install(|| (case.run)(setup))
            };
            let (one, two) = (on(1)?, on(2)?);
            for (mut check, other) in one.into_iter().zip(two) {
                check.same_bits &= check.tinydem.to_bits() == other.tinydem.to_bits();
                checks.push(check);
            }
        }
    }
    Ok(checks)
}

/// The table of `checks`, one line each.
pub fn table(checks: &[Check]) -> String {
    let mut out = format!(
        "{:<18}{:<40}{:>14}{:>14}{:>11}{:>11}  1=2 threads  pass\n",
        "case", "quantity", "tinydem", "reference", "error", "tolerance"
    );
    for c in checks {
        out += &format!(
            "{:<18}{:<40}{:>14.6e}{:>14.6e}{:>11.2e}{:>11.1e}  {:<11}  {}\n",
            c.case,
            format!("{} [{}]", c.quantity, c.unit),
            c.tinydem,
            c.reference,
            c.error(),
            c.tolerance,
            if c.same_bits { "same bits" } else { "DIFFER" },
            if c.passes() { "yes" } else { "NO" }
        );
    }
    out
}

/// The report of `checks` as Markdown: what each case is, and the table.
pub fn report(checks: &[Check]) -> String {
    let mut out = String::from("# tinydem verify\n\n| case | what |\n|---|---|\n");
    for case in CASES
        .iter()
        .filter(|c| checks.iter().any(|k| k.case == c.name))
    {
        out += &format!("| `{}` | {} |\n", case.name, case.what);
    }
    out +=
        "\n| case | quantity | tinydem | reference | error | tolerance | 1 = 2 threads | pass |\n";
    out += "|---|---|---|---|---|---|---|---|\n";
    for c in checks {
        out += &format!(
            "| `{}` | {} [{}] | {:.6e} | {:.6e} | {:.2e} | {:.1e} | {} | {} |\n",
            c.case,
            c.quantity,
            c.unit,
            c.tinydem,
            c.reference,
            c.error(),
            c.tolerance,
            if c.same_bits {
                "same bits"
            } else {
                "**differ**"
            },
            if c.passes() { "yes" } else { "**no**" }
        );
    }
    out
}

/// The spheres of the single-contact cases: radius, density, Young's modulus, Poisson's
/// ratio (a soft glass-like grain, Table 2's scale).
const R: f64 = 0.005;
const RHO: f64 = 1000.0;
const E: f64 = 1e6;
const NU: f64 = 0.3;

/// A floor at z = 0.
const FLOOR: &str = "OFF\n4 1 0\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n4 0 1 2 3\n";

fn sphere(x: DVec3, v: DVec3) -> Particle {
    sphere_of(R, x, v)
}

fn sphere_of(radius: f64, x: DVec3, v: DVec3) -> Particle {
    Particle {
        x,
        radius,
        v,
        q: DQuat::IDENTITY,
        ..Particle::default()
    }
}

/// A simulation of `particles` (their radius the first one's) with the material keys
/// `material` (TOML lines; density, Young's modulus and Poisson's ratio `RHO`, `E`, `NU`
/// unless it gives them), gravity `g`, time step `dt` (Eq. 50's without) and the floor if
/// `floor`.
fn simulation(
    setup: Setup,
    material: &str,
    g: f64,
    dt: Option<f64>,
    floor: bool,
    particles: Vec<Particle>,
) -> Result<Simulation> {
    let dt = dt.map_or(String::new(), |dt| format!("timestep = {dt:e}\n"));
    let mut keys = String::new();
    for (key, value) in [
        ("density", RHO),
        ("youngs_modulus", E),
        ("poisson_ratio", NU),
    ] {
        if !material.contains(key) {
            keys += &format!("{key} = {value:e}\n");
        }
    }
    let r = particles.first().map_or(R, |p| p.radius);
    let text = format!(
        "[geometry]\nradius_min = {r:e}\nradius_max = {r:e}\nmesh_radii = [0.0]\n\
         [material]\n{keys}{material}\n\
         [kinetics]\ngravity = [0.0, 0.0, {g}]\n\
         [simulation]\nmax_particles = 0\nspawn_attempts = 0\n{dt}"
    );
    let s = Scenario::parse(&text, std::path::Path::new("verify.toml"))?;
    let mesh = if floor {
        Mesh::parse_off(FLOOR, "floor", &s.geometry.mesh_radii)?
    } else {
        Mesh::default()
    };
    let mut sim = Simulation::from_parts(s, mesh, particles.into_iter().collect::<Particles>())?;
    (setup.tamper)(&mut sim);
    Ok(sim)
}

/// What a head-on impact of two spheres at relative speed `v0` shows: restitution, contact
/// time, peak overlap and peak force (from sphere 1's change of momentum per step).
struct Impact {
    restitution: f64,
    contact_time: f64,
    peak_overlap: f64,
    peak_force: f64,
}

fn impact(setup: Setup, e_n: f64, v0: f64) -> Result<Impact> {
    let gap = 1e-5;
    let mut s = simulation(
        setup,
        &format!("restitution = {e_n}\nfriction_sliding = 0.3"),
        0.0,
        Some(1e-7),
        false,
        vec![
            sphere(DVec3::new(-R - gap, 0.0, 0.0), DVec3::X * v0 / 2.0),
            sphere(DVec3::new(R + gap, 0.0, 0.0), -DVec3::X * v0 / 2.0),
        ],
    )?;
    let dt = s.scenario.simulation.timestep;
    let m = Inertia::mass(R, RHO);
    let overlap = |s: &Simulation| 2.0 * R - (s.particles.x[1] - s.particles.x[0]).length();
    let (mut steps_in_contact, mut peak_overlap, mut peak_force) = (0u64, 0.0f64, 0.0f64);
    let mut touched = false;
    for _ in 0..10_000_000 {
        let v_before = s.particles.v[1].x;
        s.step()?;
        let delta = overlap(&s);
        if delta > 0.0 {
            touched = true;
            steps_in_contact += 1;
            peak_overlap = peak_overlap.max(delta);
            peak_force = peak_force.max(m * (s.particles.v[1].x - v_before) / dt);
        } else if touched {
            break;
        }
    }
    Ok(Impact {
        restitution: (s.particles.v[1].x - s.particles.v[0].x) / v0,
        contact_time: steps_in_contact as f64 * dt,
        peak_overlap,
        peak_force,
    })
}

/// Hertz's elastic impact: with F = 4/3 E* sqrt(R*) δ^(3/2), the peak overlap
/// δ_m = (15 m* v0² / (16 E* sqrt(R*)))^(2/5) and the contact time
/// t_c = 2 δ_m / v0 ∫₀¹ dx / sqrt(1 - x^(5/2)) = 2.94328 δ_m / v0 (Johnson 1985, Sec. 11.4).
fn hertz_impact(setup: Setup) -> Result<Vec<Check>> {
    let v0 = 0.5;
    let got = impact(setup, 1.0, v0)?;
    let m_star = Inertia::mass(R, RHO) / 2.0;
    let (r_star, e_star) = (R / 2.0, E / (2.0 * (1.0 - NU * NU)));
    let delta_m = (15.0 * m_star * v0 * v0 / (16.0 * e_star * r_star.sqrt())).powf(0.4);
    let check = |quantity: &str, unit, tinydem, reference, tolerance| {
        Check::of(
            "hertz_impact",
            quantity,
            unit,
            (tinydem, reference, tolerance),
        )
    };
    Ok(vec![
        check("peak overlap", "m", got.peak_overlap, delta_m, 1e-4),
        check(
            "peak force",
            "N",
            got.peak_force,
            4.0 / 3.0 * e_star * r_star.sqrt() * delta_m.powf(1.5),
            1e-4,
        ),
        check(
            "contact time",
            "s",
            got.contact_time,
            2.0 * 1.471_637_6 * delta_m / v0,
            5e-4, // the time step is 5e-5 of it
        ),
        check("restitution (elastic)", "-", got.restitution, 1.0, 1e-4),
    ])
}

/// The damping of Eq. (18) with β of Eq. (21) gives e_n independent of the impact speed
/// (the damped Hertz oscillator's restitution depends on β alone).
fn restitution(setup: Setup) -> Result<Vec<Check>> {
    let mut checks = Vec::new();
    for e_n in [0.2, 0.5, 0.8] {
        for v0 in [0.1, 1.0] {
            let e = impact(setup, e_n, v0)?.restitution;
            let quantity = format!("e at e_n = {e_n}, v0 = {v0} m/s");
            checks.push(Check::of("restitution", quantity, "-", (e, e_n, 1e-3)));
        }
    }
    Ok(checks)
}

/// A sphere dropped from rest with its lowest point h = 50 mm above a floor (MFIX-DEM's first
/// case, Garg et al. 2012): it touches after sqrt(2 h / g) at sqrt(2 g h), and with
/// restitution e rises again to e² h: e is that of a free impact, and gravity acting
/// through the 2 ms contact takes a little from the rebound (3.6e-3 of the height here).
fn free_fall(setup: Setup) -> Result<Vec<Check>> {
    let (g, h, e_n, dt) = (9.81, 0.05, 0.8, 1e-6);
    let mut s = simulation(
        setup,
        &format!("restitution = {e_n}\nfriction_sliding = 0.3"),
        -g,
        Some(dt),
        true,
        vec![sphere(DVec3::new(0.0, 0.0, R + h), DVec3::ZERO)],
    )?;
    let mut steps = 0u64;
    while s.particles.x[0].z >= R {
        s.step()?;
        steps += 1;
    }
    // The moment the lowest point crossed z = 0, between the last two steps.
    let (z, v) = (s.particles.x[0].z, s.particles.v[0].z);
    let touch = steps as f64 * dt - (R - z) / -v;
    let speed = -v;
    while s.particles.v[0].z <= 0.0 || s.particles.x[0].z < R {
        s.step()?;
    }
    let mut apex = s.particles.x[0].z;
    while s.particles.v[0].z > 0.0 {
        s.step()?;
        apex = apex.max(s.particles.x[0].z);
    }
    let check = |quantity: &str, unit, tinydem, reference, tolerance| {
        Check::of("free_fall", quantity, unit, (tinydem, reference, tolerance))
    };
    Ok(vec![
        check("time to touch", "s", touch, (2.0 * h / g).sqrt(), 1e-4),
        check("impact speed", "m/s", speed, (2.0 * g * h).sqrt(), 1e-4),
        check("rebound height", "m", apex - R, e_n * e_n * h, 5e-3),
    ])
}

/// A sphere falling onto a rigid floor, without gravity. Normal at 0.5 m/s, elastic: Hertz
/// with m* = m, R* = R and the wall's E* = E / (1 - ν²). Oblique (v_n = 0.2 m/s, v_t = 1
/// m/s, μ = 0.3, elastic, a grain 1000 times stiffer so that the overlap stays below 0.5 %
/// of R), in gross sliding (2 μ v_n < 2/7 v_t: the contact point slides throughout): the
/// friction impulse is μ times the normal one, 2 m v_n, so v_t' = v_t - 2 μ v_n and
/// ω' R = 5 μ v_n (Maw, Barber & Fawcett 1976, their regime of large incidence). The lever
/// of the friction force is the distance to the contact point, R - δ: the spin falls short
/// of the rigid limit by about the mean δ / R, hence its tolerance.
fn wall_impact(setup: Setup) -> Result<Vec<Check>> {
    let bounce = |material: &str, v: DVec3| -> Result<(Simulation, u64)> {
        let at = DVec3::new(0.0, 0.0, R + 1e-6);
        let mut s = simulation(setup, material, 0.0, Some(1e-7), true, vec![sphere(at, v)])?;
        let mut steps_in_contact = 0;
        let mut touched = false;
        for _ in 0..10_000_000 {
            s.step()?;
            if s.particles.x[0].z < R {
                touched = true;
                steps_in_contact += 1;
            } else if touched {
                break;
            }
        }
        Ok((s, steps_in_contact))
    };
    let v0 = 0.5;
    let (s, steps) = bounce("restitution = 1.0", -DVec3::Z * v0)?;
    let m = Inertia::mass(R, RHO);
    let e_wall = E / (1.0 - NU * NU);
    let delta_m = (15.0 * m * v0 * v0 / (16.0 * e_wall * R.sqrt())).powf(0.4);
    let t_c = steps as f64 * s.scenario.simulation.timestep;
    let (v_n, v_t, mu) = (0.2, 1.0, 0.3);
    let material = format!(
        "youngs_modulus = {:e}\nrestitution = 1.0\nfriction_sliding = {mu}\nfriction_rolling = 0.0",
        1000.0 * E
    );
    let (oblique, _) = bounce(&material, DVec3::new(v_t, 0.0, -v_n))?;
    let check = |quantity: &str, unit, tinydem, reference, tolerance| {
        Check::of(
            "wall_impact",
            quantity,
            unit,
            (tinydem, reference, tolerance),
        )
    };
    let impulse = 2.0 * mu * v_n;
    Ok(vec![
        check(
            "contact time",
            "s",
            t_c,
            2.0 * 1.471_637_6 * delta_m / v0,
            5e-4,
        ),
        check(
            "rebound speed (elastic)",
            "m/s",
            s.particles.v[0].z,
            v0,
            1e-4,
        ),
        check(
            "oblique: tangential speed after",
            "m/s",
            oblique.particles.v[0].x,
            v_t - impulse,
            1e-3,
        ),
        check(
            "oblique: spin times R after",
            "m/s",
            oblique.particles.w[0].y * R,
            2.5 * impulse,
            2e-3,
        ),
    ])
}

/// Chung & Ooi (2011), test 2: a sphere of radius 0.1 m meets a rigid plane at 0.2 m/s,
/// elastic and frictionless, of aluminium alloy (E = 70 GPa, ν = 0.30, ρ = 2699 kg/m³) and
/// of magnesium alloy (40 GPa, 0.35, 1800 kg/m³). Their figure is the force-overlap curve of
/// Hertz's solution; checked here: its peak overlap and force (force as m dv/dt) and the
/// contact time, with m* = m, R* = R, E* = E / (1 - ν²).
fn chung_ooi_2(setup: Setup) -> Result<Vec<Check>> {
    let (r, v0, dt) = (0.1, 0.2, 1e-7);
    let mut checks = Vec::new();
    for (name, e, nu, rho) in [
        ("aluminium alloy", 7.0e10, 0.30, 2699.0),
        ("magnesium alloy", 4.0e10, 0.35, 1800.0),
    ] {
        let material = format!(
            "density = {rho:e}\nyoungs_modulus = {e:e}\npoisson_ratio = {nu}\n\
             restitution = 1.0\nfriction_sliding = 0.0\nfriction_rolling = 0.0"
        );
        let at = DVec3::new(0.0, 0.0, r + 1e-7);
        let ball = sphere_of(r, at, -DVec3::Z * v0);
        let mut s = simulation(setup, &material, 0.0, Some(dt), true, vec![ball])?;
        let m = Inertia::mass(r, rho);
        let (mut steps, mut peak_overlap, mut peak_force, mut touched) =
            (0u64, 0.0f64, 0.0f64, false);
        for _ in 0..10_000_000 {
            let v_before = s.particles.v[0].z;
            s.step()?;
            let delta = r - s.particles.x[0].z;
            if delta > 0.0 {
                touched = true;
                steps += 1;
                peak_overlap = peak_overlap.max(delta);
                peak_force = peak_force.max(m * (s.particles.v[0].z - v_before) / dt);
            } else if touched {
                break;
            }
        }
        let e_star = e / (1.0 - nu * nu);
        let delta_m = (15.0 * m * v0 * v0 / (16.0 * e_star * r.sqrt())).powf(0.4);
        let check = |quantity: &str, unit, tinydem, reference, tolerance| {
            let quantity = format!("{name}: {quantity}");
            Check::of(
                "chung_ooi_2",
                quantity,
                unit,
                (tinydem, reference, tolerance),
            )
        };
        checks.extend([
            check("peak overlap", "m", peak_overlap, delta_m, 1e-4),
            check(
                "peak force",
                "N",
                peak_force,
                4.0 / 3.0 * e_star * r.sqrt() * delta_m.powf(1.5),
                1e-4,
            ),
            check(
                "contact time",
                "s",
                steps as f64 * dt,
                2.0 * 1.471_637_6 * delta_m / v0,
                5e-4,
            ),
        ]);
    }
    Ok(checks)
}

/// A sphere launched sliding without spin on a floor: Coulomb friction slows it and spins it
/// up until v = ω R, at v = 5/7 v0 for a solid sphere (I = 2/5 m R²), whatever μ.
fn slip_to_rolling(setup: Setup) -> Result<Vec<Check>> {
    let v0 = 0.5;
    let mut s = simulation(
        setup,
        "restitution = 0.5\nfriction_sliding = 0.3\nfriction_rolling = 0.0\nfriction_twisting = 0.0",
        -9.81,
        None,
        true,
        vec![sphere(DVec3::new(0.0, 0.0, R * 0.9995), DVec3::X * v0)],
    )?;
    for _ in 0..40_000 {
        s.step()?;
    }
    let (v, w) = (s.particles.v[0], s.particles.w[0]);
    // The tolerance: the sphere bounces a little at the start.
    let check = |quantity: &str, tinydem, reference| {
        Check::of(
            "slip_to_rolling",
            quantity,
            "m/s",
            (tinydem, reference, 2e-3),
        )
    };
    Ok(vec![
        check("final speed", v.x, 5.0 / 7.0 * v0),
        check("final spin times R", w.y * R, 5.0 / 7.0 * v0),
    ])
}

/// Two spheres stacked on a floor, settled under gravity: the floor carries 2 m g at
/// overlap (3 F / (4 E*_w sqrt(R)))^(2/3) with E*_w = E / (1 - ν²) (a rigid wall); the
/// spheres' contact m g with E* = E / (2 (1 - ν²)), R* = R / 2.
fn stacked_spheres(setup: Setup) -> Result<Vec<Check>> {
    let g = 9.81;
    let mut s = simulation(
        setup,
        "restitution = 0.1\nfriction_sliding = 0.3",
        -g,
        None,
        true,
        vec![
            sphere(DVec3::new(0.0, 0.0, R), DVec3::ZERO),
            sphere(DVec3::new(0.0, 0.0, 3.0 * R), DVec3::ZERO),
        ],
    )?;
    let dt = s.scenario.simulation.timestep;
    // Settled: many periods of the contact's oscillation, damped.
    let steps = (0.5 / dt) as usize;
    for _ in 0..steps {
        s.step()?;
    }
    let p = &s.particles;
    let (low, high) = if p.x[0].z < p.x[1].z { (0, 1) } else { (1, 0) };
    let m = Inertia::mass(R, RHO);
    let static_overlap = |f: f64, e_star: f64, r_star: f64| {
        (3.0 * f / (4.0 * e_star * r_star.sqrt())).powf(2.0 / 3.0)
    };
    let e_wall = E / (1.0 - NU * NU);
    let e_pair = E / (2.0 * (1.0 - NU * NU));
    let check = |quantity: &str, tinydem, reference| {
        Check::of("stacked_spheres", quantity, "m", (tinydem, reference, 1e-6))
    };
    Ok(vec![
        check(
            "overlap with the floor",
            R - p.x[low].z,
            static_overlap(2.0 * m * g, e_wall, R),
        ),
        check(
            "overlap between the spheres",
            2.0 * R - (p.x[high] - p.x[low]).length(),
            static_overlap(m * g, e_pair, R / 2.0),
        ),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unknown_case_is_refused_with_the_known_ones() {
        let e = run(&["nope".into()], false).unwrap_err().to_string();
        assert!(e.contains("hertz_impact") && e.contains("nope"), "{e}");
    }

    /// The suite can fail: with the normal stiffness doubled (a wrong model), the Hertz
    /// cases do.
    #[test]
    fn a_wrong_model_fails_the_hertz_cases() {
        let stiffer = Setup {
            tamper: |sim| sim.model.law.stiffer(2.0),
        };
        let only = ["hertz_impact".to_string(), "stacked_spheres".to_string()];
        let checks = run_with(&only, false, stiffer).unwrap();
        let failed: Vec<&str> = (checks.iter().filter(|c| !c.passes()))
            .map(|c| c.quantity.as_str())
            .collect();
        assert_eq!(
            failed,
            [
                "peak overlap",
                "peak force",
                "contact time",
                "overlap with the floor",
                "overlap between the spheres"
            ]
        );
        assert!(run(&only, false).unwrap().iter().all(Check::passes));
    }

    #[test]
    fn a_check_fails_beyond_its_tolerance() {
        let c = Check {
            case: "x",
            quantity: "q".into(),
            unit: "-",
            tinydem: 1.02,
            reference: 1.0,
            tolerance: 0.01,
            same_bits: true,
        };
        assert!(!c.passes());
        assert!(table(std::slice::from_ref(&c)).contains("NO"));
        assert!(report(&[c]).contains("**no**"));
    }

    /// Johnson's constant of the contact time: ∫₀¹ dx / sqrt(1 - x^(5/2)) = sqrt(π) Γ(7/5) / Γ(9/10).
    #[test]
    fn the_contact_time_constant_is_the_integral() {
        // x = 1 - u²: the integrand's singularity at 1 becomes smooth.
        let n = 200_000;
        let integral: f64 = (0..n)
            .map(|k| {
                let u = (k as f64 + 0.5) / n as f64;
                let x: f64 = 1.0 - u * u;
                2.0 * u / (1.0 - x.powf(2.5)).sqrt() / n as f64
            })
            .sum();
        assert!((integral - 1.471_637_6).abs() < 1e-5, "{integral}");
    }
}
