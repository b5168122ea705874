//! The cases of heat transfer: two grains relaxing to their mean temperature, a chain of
//! grains between a hot and a cold wall at steady state, a grain cooling to its
//! surroundings and one warmed by its source.

use std::f64::consts::PI;

use anyhow::Result;
use glam::DVec3;

use super::*;

/// A simulation of fixed `grains` (material, radius, x along the axis, temperature) in the
/// scenario `text` (its keys; gravity off).
fn heated(setup: Setup, text: &str, grains: &[(u16, f64, f64, f64)]) -> Result<Simulation> {
    let s = Scenario::parse(text, std::path::Path::new("verify.toml"))?;
    let mut inputs = crate::io::inputs::read(&s)?;
    let mut p = Particles::default();
    p.activate("T");
    for &(material, radius, x, temperature) in grains {
        p.push(Particle {
            material,
            fixed: true,
            temperature,
            ..sphere_of(radius, DVec3::X * x, DVec3::ZERO)
        });
    }
    inputs.particles = p;
    let mut sim = Simulation::from_inputs(s, inputs)?;
    (setup.tamper)(&mut sim);
    Ok(sim)
}

/// m c of a grain of radius `r`, density `rho`, capacity `c`.
fn mc(r: f64, rho: f64, c: f64) -> f64 {
    4.0 / 3.0 * PI * r.powi(3) * rho * c
}

/// Batchelor & O'Brien's conductance 2 k_eff sqrt(R* δ).
fn conductance(k1: f64, k2: f64, r_star: f64, delta: f64) -> f64 {
    2.0 * (2.0 * k1 * k2 / (k1 + k2)) * (r_star * delta).sqrt()
}

/// The temperature of the particle of id `id`.
fn temperature(sim: &Simulation, id: usize) -> f64 {
    let p = &sim.particles;
    p.temperature[p.id_order()[id]]
}

/// Two grains (radii 5 and 4 mm, of different materials) held overlapping by 20 μm at 400
/// and 300 K: their difference decays as exp(-H (1/(m1 c1) + 1/(m2 c2)) t), their mean
/// weighted by m c stays, their heat content to the bit.
pub(super) fn heat_relaxation(setup: Setup) -> Result<Vec<Check>> {
    let (r1, r2, delta, steps, dt) = (0.005, 0.004, 2e-5, 4000, 0.1);
    let text = "[geometry]\nradius_min = 0.004\nradius_max = 0.005\n\
        [[materials]]\nname = \"glass\"\ndensity = 2500.0\nthermal_conductivity = 2.0\nheat_capacity = 800.0\n\
        [[materials]]\nname = \"resin\"\ndensity = 1500.0\nthermal_conductivity = 0.5\nheat_capacity = 1200.0\n\
        [kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
        [simulation]\ntimestep = 1e-5\nthermal_time_scale = 1e4\nmax_particles = 0\n";
    let grains = [(0, r1, 0.0, 400.0), (1, r2, r1 + r2 - delta, 300.0)];
    let mut sim = heated(setup, text, &grains)?;
    let (c1, c2) = (mc(r1, 2500.0, 800.0), mc(r2, 1500.0, 1200.0));
    let rate = conductance(2.0, 0.5, r1 * r2 / (r1 + r2), delta) * (1.0 / c1 + 1.0 / c2);
    let (_, content) = sim.heat_content();
    for _ in 0..steps {
        sim.step()?;
    }
    let (t1, t2) = (temperature(&sim, 0), temperature(&sim, 1));
    let measured = (100.0 / (t1 - t2)).ln() / (steps as f64 * dt);
    let case = "heat_relaxation";
    Ok(vec![
        Check::of(case, "relaxation rate", "1/s", (measured, rate, 1e-3)),
        Check::of(
            case,
            "mean temperature (m c weighted)",
            "K",
            (
                (c1 * t1 + c2 * t2) / (c1 + c2),
                (c1 * 400.0 + c2 * 300.0) / (c1 + c2),
                1e-12,
            ),
        ),
        Check::of(
            case,
            "heat content",
            "J",
            (sim.heat_content().1, content, 0.0),
        ),
    ])
}

/// Five grains in a row between a plane at 400 K and one at 300 K, overlapping each other by
/// 20 μm and the planes by 10 μm: at steady state the flux is ΔT over the resistances 1/H in
/// series, and each grain's temperature falls linearly in the resistance met from the hot
/// wall.
pub(super) fn heat_chain(setup: Setup) -> Result<Vec<Check>> {
    let (n, r, delta, delta_w) = (5, 0.005, 2e-5, 1e-5);
    let (h_pair, h_wall) = (
        conductance(1.0, 1.0, r / 2.0, delta),
        conductance(1.0, 400.0, r, delta_w),
    );
    let flux = 100.0 / (2.0 / h_wall + (n - 1) as f64 / h_pair);
    let dt = 0.1 * mc(r, 2500.0, 800.0) / (h_wall + h_pair);
    let pitch = 2.0 * r - delta;
    let x: Vec<f64> = (0..n).map(|k| r - delta_w + k as f64 * pitch).collect();
    let plane = |at: f64, nx: f64, t: f64| {
        format!(
            "[[meshes]]\nshape = {{ type = \"plane\", point = [{at}, 0.0, 0.0], normal = [{nx}, 0.0, 0.0], size = 0.05 }}\nmaterial = \"copper\"\ntemperature = {t}\n"
        )
    };
    let text = format!(
        "[geometry]\nradius_min = {r}\nradius_max = {r}\n\
         [[materials]]\nname = \"grain\"\ndensity = 2500.0\nthermal_conductivity = 1.0\nheat_capacity = 800.0\n\
         [[materials]]\nname = \"copper\"\nthermal_conductivity = 400.0\n{}{}\
         [kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
         [simulation]\ntimestep = 1e-6\nthermal_time_scale = {}\nmax_particles = 0\n",
        plane(0.0, 1.0, 400.0),
        plane(x[n - 1] + r - delta_w, -1.0, 300.0),
        dt / 1e-6
    );
    let grains: Vec<_> = x.iter().map(|&x| (0, r, x, 300.0)).collect();
    let mut sim = heated(setup, &text, &grains)?;
    let settle = (40.0 * (n * n) as f64 * mc(r, 2500.0, 800.0) / h_pair / dt) as usize;
    for _ in 0..settle {
        sim.step()?;
    }
    sim.take_wall_heat();
    let steps = 100;
    for _ in 0..steps {
        sim.step()?;
    }
    let into = sim.take_wall_heat();
    let per_second = |q: f64| q / (steps as f64 * dt);
    let middle = 400.0 - flux * (1.0 / h_wall + (n / 2) as f64 / h_pair);
    let case = "heat_chain";
    Ok(vec![
        Check::of(
            case,
            "flux out of the hot wall",
            "W",
            (-per_second(into[1]), flux, 1e-6),
        ),
        Check::of(
            case,
            "flux into the cold wall",
            "W",
            (per_second(into[2]), flux, 1e-6),
        ),
        Check::of(
            case,
            "temperature of the middle grain",
            "K",
            (temperature(&sim, n / 2), middle, 1e-9),
        ),
    ])
}

/// A free grain (3 mm, glass-like) at 400 K: cooling with h = 20 W/(m² K) to surroundings at
/// 300 K, T - T_∞ falls as exp(-h A t / (m c)); with a source of 10⁴ W/m³ instead, it warms by
/// q_V V t / (m c).
pub(super) fn heat_sources(setup: Setup) -> Result<Vec<Check>> {
    let (r, steps, dt) = (0.003, 2000, 0.1);
    let alone = |material: &str, kinetics: &str| {
        let text = format!(
            "[geometry]\nradius_min = {r}\nradius_max = {r}\n\
             [material]\ndensity = 2500.0\nheat_capacity = 800.0\n{material}\n\
             [kinetics]\ngravity = [0.0, 0.0, 0.0]\n{kinetics}\n\
             [simulation]\ntimestep = 1e-5\nthermal_time_scale = 1e4\nmax_particles = 0\n"
        );
        let mut sim = heated(setup, &text, &[(0, r, 0.0, 400.0)])?;
        for _ in 0..steps {
            sim.step()?;
        }
        anyhow::Ok(temperature(&sim, 0))
    };
    let c = mc(r, 2500.0, 800.0);
    let time = steps as f64 * dt;
    let cooled = alone(
        "surface_heat_transfer = 20.0",
        "ambient_temperature = 300.0",
    )?;
    let newton = 300.0 + 100.0 * (-20.0 * 4.0 * PI * r * r / c * time).exp();
    let warmed = alone("heat_source = 1e4", "")?;
    let source = 400.0 + 1e4 * 4.0 / 3.0 * PI * r.powi(3) * time / c;
    let case = "heat_sources";
    Ok(vec![
        Check::of(
            case,
            "excess temperature after cooling",
            "K",
            (cooled - 300.0, newton - 300.0, 2e-3),
        ),
        Check::of(
            case,
            "temperature warmed by its source",
            "K",
            (warmed, source, 1e-12),
        ),
    ])
}
