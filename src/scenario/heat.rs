//! Validation of the heat-transfer keys: each material's thermal properties, the
//! surroundings, the thermal step and the conduction model, and what `tinydem check` and
//! `run` warn of.

use anyhow::{Result, bail};

use super::raw::RawMaterial;
use super::validate::{Range, check};
use super::*;
use crate::model::heat::HeatModel;

/// A material's thermal properties (`table` names it in messages). (Whether its grains
/// have the heat capacity they need: [`Scenario::heat_capacity_missing`], once the
/// materials of the grains are known.)
pub(super) fn thermal(table: &str, m: &RawMaterial) -> Result<Thermal> {
    let key = |name: &str| format!("{table} {name}");
    let opt = |name: &str, x: Option<f64>| check(&key(name), x.unwrap_or(0.0), Range::NonNegative);
    let t = Thermal {
        conductivity: opt("thermal_conductivity", m.thermal_conductivity)?,
        capacity: opt("heat_capacity", m.heat_capacity)?,
        initial_temperature: temperature(&key("initial_temperature"), m.initial_temperature)?
            .unwrap_or(0.0),
        source: check(
            &key("heat_source"),
            m.heat_source.unwrap_or(0.0),
            Range::Finite,
        )?,
        surface_transfer: opt("surface_heat_transfer", m.surface_heat_transfer)?,
    };
    Ok(t)
}

/// A temperature \[K\] under `key`, if given: finite and >= 0.
pub(super) fn temperature(key: &str, t: Option<f64>) -> Result<Option<f64>> {
    t.map(|t| {
        if !(t.is_finite() && t >= 0.0) {
            bail!("{key} = {t} K is not allowed: a temperature is a finite number >= 0 (kelvin)");
        }
        Ok(t)
    })
    .transpose()
}

/// The value of `[simulation] conduction_model` (default "batchelor_obrien").
pub(super) fn conduction_model(value: Option<String>) -> Result<Conduction> {
    match value.as_deref() {
        None | Some("batchelor_obrien") => Ok(Conduction::BatchelorOBrien),
        Some("liggghts") => Ok(Conduction::Liggghts),
        Some(other) => bail!(
            "[simulation] conduction_model = \"{other}\" is not allowed: it must be \"batchelor_obrien\" (H = 2 k a, a the Hertz contact radius) or \"liggghts\" (H = 2 k sqrt(A), A the area of the circle where the surfaces cross, as LIGGGHTS's heat/gran/conduction)"
        ),
    }
}

/// `[simulation] thermal_time_scale` (default 1).
pub(super) fn thermal_time_scale(f: Option<f64>) -> Result<f64> {
    check(
        "[simulation] thermal_time_scale",
        f.unwrap_or(1.0),
        Range::Positive,
    )
}

impl Scenario {
    /// The constants of heat transfer, if heat is transferred, for grains of radius at
    /// most `r_max` (which sets the quantum of heat).
    pub fn heat_model(&self, r_max: f64) -> Option<HeatModel> {
        if !self.heat() {
            return None;
        }
        let densest = (self.materials.iter())
            .map(|m| m.properties.density * m.properties.thermal.capacity)
            .fold(0.0, f64::max);
        let largest = densest * 4.0 / 3.0 * std::f64::consts::PI * r_max.powi(3);
        let s = &self.simulation;
        Some(HeatModel {
            materials: self
                .materials
                .iter()
                .map(|m| m.properties.thermal)
                .collect(),
            mass_per_r3: (self.materials.iter())
                .map(|m| 4.0 / 3.0 * std::f64::consts::PI * m.properties.density)
                .collect(),
            dt: s.timestep * s.thermal_time_scale,
            ambient: self.kinetics.ambient_temperature,
            quantum: HeatModel::quantum_for(largest.max(f64::MIN_POSITIVE)),
            conduction: s.conduction_model,
        })
    }

    /// The thermal step f Δt and the grains' shortest thermal time scale (m c over the
    /// conductance of 12 contacts of a tenth of R_min, `HeatModel::time_scale`), if heat
    /// is transferred.
    pub fn thermal_steps(&self) -> Option<(f64, f64)> {
        let g = &self.geometry;
        let model = self.heat_model(g.radius_max)?;
        Some((model.dt, model.time_scale(g.radius_min, 12.0)))
    }

    /// The thermal step against the grains' thermal time scale, with heat transfer.
    pub fn thermal_line(&self) -> String {
        let s = self;
        match s.thermal_steps() {
            Some((dt, tau)) => format!(
                "thermal step           {dt:.6e} s (f = {}; {:.3} x the grains' thermal time scale {tau:.6e} s)\n",
                s.simulation.thermal_time_scale,
                dt / tau
            ),
            None => String::new(),
        }
    }

    /// Why heat transfer is refused: a thermal step f Δt past the grains' thermal time scale
    /// (the explicit update of a grain with that many contacts overshoots, and its temperature
    /// oscillates and grows).
    pub fn thermal_refusal(&self) -> Option<String> {
        let s = self;
        let (dt, tau) = s.thermal_steps()?;
        (dt > tau).then(|| {
            format!(
                "the thermal step f dt = {dt:.3e} s ([simulation] thermal_time_scale = {} x timestep) \
                 exceeds the grains' thermal time scale {tau:.3e} s (m c over the conductance of 12 \
                 contacts of radius R_min/10): temperatures would overshoot and blow up (set \
                 thermal_time_scale at most {:.3e})",
                s.simulation.thermal_time_scale,
                tau / s.simulation.timestep
            )
        })
    }

    /// Whether heat is transferred: some material conducts, makes heat or exchanges it
    /// with the surroundings. Only then do particles hold a temperature.
    pub fn heat(&self) -> bool {
        self.materials.iter().any(|m| {
            let t = &m.properties.thermal;
            t.conductivity > 0.0 || t.source != 0.0 || t.surface_transfer > 0.0
        })
    }

    /// The error for grains of the materials `used` (indices) that conduct, make heat or
    /// exchange it but have no heat capacity (a material of walls alone needs none).
    pub fn heat_capacity_missing(&self, used: impl IntoIterator<Item = u16>) -> Result<()> {
        for m in used {
            let spec = &self.materials[m as usize];
            let t = &spec.properties.thermal;
            let heated = t.conductivity > 0.0 || t.source != 0.0 || t.surface_transfer > 0.0;
            if heated && t.capacity == 0.0 {
                bail!(
                    "material \"{}\" has no heat_capacity: its grains conduct, make or exchange heat, so they need c [J/(kg K)] > 0",
                    spec.name
                );
            }
        }
        Ok(())
    }

    /// The materials grains are spawned of (a clump's spheres: its template's).
    pub fn spawned_materials(&self) -> Vec<u16> {
        let mut used: Vec<u16> = (self.spawn.iter())
            .map(|r| match r.clump {
                Some(c) => self.clumps[c.template as usize].material,
                None => r.material,
            })
            .collect();
        if self.spawn.is_empty() {
            used.push(0);
        }
        used
    }

    /// Heat keys that do nothing, for warnings: temperatures given while no material
    /// conducts, makes or exchanges heat.
    pub fn idle_heat_keys(&self) -> Vec<String> {
        if self.heat() {
            let exchanges =
                (self.materials.iter()).any(|m| m.properties.thermal.surface_transfer > 0.0);
            return match (self.kinetics.ambient_temperature, exchanges) {
                (Some(_), false) => vec![
                    "[kinetics] ambient_temperature is set, but no material has a surface_heat_transfer > 0: the surroundings exchange no heat".into(),
                ],
                (None, true) => vec![
                    "a material has a surface_heat_transfer, but [kinetics] ambient_temperature is not set: the surroundings exchange no heat".into(),
                ],
                _ => vec![],
            };
        }
        let mut keys = Vec::new();
        for m in &self.materials {
            if m.properties.thermal.initial_temperature != 0.0 {
                keys.push(format!("material \"{}\" initial_temperature", m.name));
            }
        }
        keys.extend(
            (self.spawn.iter().enumerate())
                .filter(|(_, r)| r.temperature.is_some())
                .map(|(k, _)| format!("[[spawn]] #{} temperature", k + 1)),
        );
        keys.extend(
            (self.meshes.iter().enumerate())
                .filter(|(_, m)| m.temperature.is_some())
                .map(|(k, _)| format!("[[meshes]] #{} temperature", k + 1)),
        );
        if self.kinetics.ambient_temperature.is_some() {
            keys.push("[kinetics] ambient_temperature".into());
        }
        if self.simulation.thermal_time_scale != 1.0 {
            keys.push("[simulation] thermal_time_scale".into());
        }
        match keys.is_empty() {
            true => vec![],
            false => vec![format!(
                "{} set, but no material conducts heat (thermal_conductivity), makes it (heat_source) or exchanges it (surface_heat_transfer): temperatures stay as they are",
                keys.join(", ")
            )],
        }
    }
}
