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
//! - `chung_ooi_1`, `chung_ooi_3`, `chung_ooi_4` (`chung_ooi.rs`): Chung & Ooi's (2011) test 1
//!   (two glass and two limestone spheres at 10 m/s each, Hertz), test 3 (restitution of
//!   alumina and cast iron on a plane at 3.9 m/s) and test 4 (oblique impacts of an alumina
//!   sphere on a rigid plane at 3.9 m/s, in gross sliding: tangential restitution and spin).
//! - `chung_ooi_2`: Chung & Ooi's (2011) test 2, an elastic normal impact on a rigid plane
//!   (two alloys): peak overlap, peak force, contact time against Hertz.
//! - `slip_to_rolling`: a sphere launched sliding on a floor ends rolling at 5/7 of its speed.
//! - `stacked_spheres`: two spheres at rest on a floor under gravity: the overlaps with the
//!   floor (load 2 m g) and between them (m g) against Hertz's static overlap.
//! - `hooke_impact`, `rolling_resistance`, `dmt_contact` (`models.rs`): the contact models
//!   beyond the paper's: Hooke's impacts against the damped linear oscillator and LIGGGHTS's
//!   figures, CDT's and EPSD2's stopping distance, DMT's resting overlap.
//! - `jkr_contact`, `liquid_bridge` (`beyond.rs`): contacts beyond touch: JKR's pull-off
//!   force and separation and its sticking speed; a bridge's force and rupture.
//! - `heat_relaxation`, `heat_chain`, `heat_sources` (`heat.rs`): heat transfer against
//!   its analytic limits: two grains relaxing, a chain at steady state between a hot and a
//!   cold wall, cooling to the surroundings and a source.
//!
//! The cases of single contacts are in `contacts.rs`.

use anyhow::{Result, bail};
use glam::{DQuat, DVec3};

mod beyond;
mod chung_ooi;
mod contacts;
mod heat;
mod ledger;
mod models;

use crate::engine::Simulation;
use crate::geometry::mesh::Mesh;
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
        run: contacts::hertz_impact,
    },
    Case {
        name: "restitution",
        what: "damped head-on impacts: the restitution asked for (Eqs. 18, 21)",
        quick: true,
        run: contacts::restitution,
    },
    Case {
        name: "free_fall",
        what: "a sphere dropped onto a floor: fall time, impact speed, rebound height",
        quick: true,
        run: contacts::free_fall,
    },
    Case {
        name: "wall_impact",
        what: "elastic and oblique impacts on a rigid floor: Hertz, and the gross-sliding limit",
        quick: true,
        run: contacts::wall_impact,
    },
    Case {
        name: "chung_ooi_1",
        what: "Chung & Ooi (2011) test 1: elastic normal impact of two identical spheres",
        quick: true,
        run: chung_ooi::chung_ooi_1,
    },
    Case {
        name: "chung_ooi_2",
        what: "Chung & Ooi (2011) test 2: elastic normal impact of a sphere on a rigid plane",
        quick: true,
        run: contacts::chung_ooi_2,
    },
    Case {
        name: "chung_ooi_3",
        what: "Chung & Ooi (2011) test 3: normal impacts on a rigid plane at five restitutions",
        quick: true,
        run: chung_ooi::chung_ooi_3,
    },
    Case {
        name: "chung_ooi_4",
        what: "Chung & Ooi (2011) test 4: oblique impacts on a rigid plane in gross sliding",
        quick: true,
        run: chung_ooi::chung_ooi_4,
    },
    Case {
        name: "slip_to_rolling",
        what: "a sphere sliding on a floor ends rolling at 5/7 of its speed",
        quick: true,
        run: contacts::slip_to_rolling,
    },
    Case {
        name: "stacked_spheres",
        what: "two spheres at rest on a floor: Hertz's static overlaps",
        quick: true,
        run: contacts::stacked_spheres,
    },
    Case {
        name: "hooke_impact",
        what: "Hooke's impacts (pair and wall, e 0.5 and 0.9): the damped linear oscillator, and LIGGGHTS",
        quick: true,
        run: models::hooke_impact,
    },
    Case {
        name: "rolling_resistance",
        what: "a sphere rolling on a floor, braked by the CDT and EPSD2 torques: the stopping distance",
        quick: true,
        run: models::rolling_resistance,
    },
    Case {
        name: "dmt_contact",
        what: "two grains held by DMT's pull settle where Hertz balances it",
        quick: true,
        run: models::dmt_contact,
    },
    Case {
        name: "jkr_contact",
        what: "an elastic grain on a JKR floor: pull-off force and separation, the speed it leaves with past the sticking speed",
        quick: true,
        run: beyond::jkr_contact,
    },
    Case {
        name: "liquid_bridge",
        what: "a liquid bridge's force against Willett's closed form, and its rupture distance",
        quick: true,
        run: beyond::liquid_bridge,
    },
    Case {
        name: "energy_ledger",
        what: "where the energy goes: an impact's loss in the normal mode alone, a sliding sphere's 2/7 in sliding",
        quick: true,
        run: ledger::energy_ledger,
    },
    Case {
        name: "heat_relaxation",
        what: "two grains held in contact relax to their mean temperature at the rate of their conductance",
        quick: true,
        run: heat::heat_relaxation,
    },
    Case {
        name: "heat_chain",
        what: "a chain of grains between a hot and a cold wall: the steady flux of resistances in series",
        quick: true,
        run: heat::heat_chain,
    },
    Case {
        name: "heat_sources",
        what: "a grain cooling to its surroundings (Newton) and one warmed by its source",
        quick: true,
        run: heat::heat_sources,
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
        "{:<20}{:<48}{:>14}{:>14}{:>11}{:>11}  1=2 threads  pass\n",
        "case", "quantity", "tinydem", "reference", "error", "tolerance"
    );
    for c in checks {
        out += &format!(
            "{:<20}{:<48}{:>14.6e}{:>14.6e}{:>11.2e}{:>11.1e}  {:<11}  {}\n",
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

/// The checks of an elastic Hertz impact of `case` (on `name`): the `measured` peak overlap,
/// peak force and contact time against Hertz's solution for E*, R*, m* and the approach speed
/// v0: δ_m = (15 m* v0² / (16 E* sqrt(R*)))^(2/5), F_m = 4/3 E* sqrt(R*) δ_m^(3/2),
/// t_c = 2.943 δ_m / v0.
fn hertz_checks(
    (case, name): (&'static str, &str),
    (peak_overlap, peak_force, time): (f64, f64, f64),
    (e_star, r_star, m_star, v0): (f64, f64, f64, f64),
) -> [Check; 3] {
    let delta_m = (15.0 * m_star * v0 * v0 / (16.0 * e_star * r_star.sqrt())).powf(0.4);
    let force = 4.0 / 3.0 * e_star * r_star.sqrt() * delta_m.powf(1.5);
    let check = |quantity: &str, unit, measured, reference, tolerance| {
        Check::of(
            case,
            format!("{name}: {quantity}"),
            unit,
            (measured, reference, tolerance),
        )
    };
    [
        check("peak overlap", "m", peak_overlap, delta_m, 1e-4),
        check("peak force", "N", peak_force, force, 1e-4),
        check(
            "contact time",
            "s",
            time,
            2.0 * 1.471_637_6 * delta_m / v0,
            5e-4,
        ),
    ]
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
        // Hooke's: twice k_n shortens every contact by sqrt(2); its damping ratio, and so
        // its restitution, stays, but not to LIGGGHTS's digits at the step of the right k_n.
        let hooke = run_with(&["hooke_impact".to_string()], false, stiffer).unwrap();
        let failed: Vec<&str> = (hooke.iter().filter(|c| !c.passes()))
            .map(|c| c.quantity.as_str())
            .collect();
        assert_eq!(failed.len(), 12, "{failed:?}");
        assert!(
            (failed.iter()).all(|q| q.contains("contact time") || q.contains("LIGGGHTS")),
            "{failed:?}"
        );
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
