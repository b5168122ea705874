//! The energy ledger's case (`energy-ledger.md`): where the energy of an impact and of a
//! sliding sphere goes, against theory, and the ledger's residual.

use anyhow::Result;
use glam::DVec3;

use super::{Check, E, NU, R, RHO, Setup, simulation, sphere_of};
use crate::engine::Simulation;
use crate::geometry::mesh::Mesh;
use crate::model::ledger::Balance;

/// `sim` made again keeping the energy ledger (and changed by `setup` as before).
fn keeping_books(setup: Setup, sim: Simulation) -> Result<Simulation> {
    let mut scenario = sim.scenario.clone();
    scenario.energy_ledger = true;
    let mesh = Mesh {
        faces: sim.walls.mesh.faces.clone(),
        ..Mesh::default()
    };
    let mut sim = Simulation::from_parts(scenario, mesh, sim.particles)?;
    (setup.tamper)(&mut sim);
    Ok(sim)
}

fn balance(sim: &Simulation) -> Balance {
    sim.thermo().energy.unwrap_or_default()
}

/// Two spheres meeting head on at 0.5 m/s each with restitution 0.5: what the impact took
/// is dissipated in the normal mode, and nothing in the others; a sphere set sliding on a
/// floor without spin (μ_s 0.3, no rolling or twisting friction) rolls at 5/7 of its speed,
/// sliding having taken 2/7 of its kinetic energy; the residual of both at the rounding.
pub(super) fn energy_ledger(setup: Setup) -> Result<Vec<Check>> {
    let case = "energy_ledger";
    let v = 0.5;
    let pair = vec![
        sphere_of(R, DVec3::new(-1.01 * R, 0.0, 0.0), DVec3::X * v),
        sphere_of(R, DVec3::new(1.01 * R, 0.0, 0.0), -DVec3::X * v),
    ];
    let material = "restitution = 0.5\nfriction_sliding = 0.5";
    let mut s = keeping_books(setup, simulation(setup, material, 0.0, None, false, pair)?)?;
    let before = s.thermo().kinetic_energy;
    for _ in 0..4000 {
        s.step()?;
    }
    let (after, b) = (s.thermo().kinetic_energy, balance(&s));
    let others: f64 = b.dissipated[1..].iter().map(|d| d.abs()).sum();
    let mut checks = vec![
        Check::of(
            case,
            "impact: normal mode's dissipation, of the loss",
            "J",
            (b.dissipated[0], before - after, 1e-9),
        ),
        Check::of(
            case,
            "impact: 1 + the other modes' dissipation, of the loss",
            "-",
            (1.0 + others / (before - after), 1.0, 1e-12),
        ),
        Check::of(
            case,
            "impact: 1 + the residual, of the energy",
            "-",
            (1.0 + b.residual / before, 1.0, 1e-12),
        ),
    ];
    let v0 = 0.5;
    let material = "restitution = 0.5\nfriction_sliding = 0.3\nfriction_rolling = 0.0\nfriction_twisting = 0.0";
    // Resting on the floor at Hertz's overlap under its weight (E* of a rigid wall).
    let (m, g) = (RHO * 4.0 / 3.0 * std::f64::consts::PI * R.powi(3), 9.81);
    let overlap = (3.0 * m * g / (4.0 * E / (1.0 - NU * NU) * R.sqrt())).powf(2.0 / 3.0);
    let grain = sphere_of(R, DVec3::new(0.0, 0.0, R - overlap), DVec3::X * v0);
    let s = simulation(setup, material, -g, None, true, vec![grain])?;
    let mut s = keeping_books(setup, s)?;
    let start = s.thermo().kinetic_energy;
    for _ in 0..40_000 {
        s.step()?;
    }
    let b = balance(&s);
    checks.extend([
        Check::of(
            case,
            "sliding sphere: sliding's dissipation, 2/7 of its energy",
            "J",
            // As slip_to_rolling's: rolling, the tangential spring's damper takes a little
            // more.
            (b.dissipated[1], 2.0 / 7.0 * start, 2e-3),
        ),
        Check::of(
            case,
            "sliding sphere: 1 + the residual, of the energy",
            "-",
            (1.0 + b.residual / start, 1.0, 1e-8),
        ),
    ]);
    Ok(checks)
}
