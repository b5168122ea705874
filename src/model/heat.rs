//! Heat transfer between grains: a temperature per particle, conduction through the contact
//! areas of touching particles and walls, a volumetric source, exchange with the
//! surroundings, advanced explicitly (the guide's heat page derives each line).
//!
//! Heat content is kept exactly: each particle holds its content as a whole number of
//! quanta ([`HeatModel::quantum`], a power of two far below a grain's content at 1 K), each
//! contact moves a whole number of quanta from one partner to the other, and the temperature
//! is the content over m c. So conduction conserves the total content to the bit, and the
//! content of a particle does not depend on the order its contacts are summed in (threads,
//! processes).

/// The thermal properties of a material.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Thermal {
    /// k \[W/(m K)\]: conducts heat where > 0.
    pub conductivity: f64,
    /// c \[J/(kg K)\].
    pub capacity: f64,
    /// T_0 \[K\]: the temperature of its particles that no file or region sets.
    pub initial_temperature: f64,
    /// q_V \[W/m³\]: heat made in its volume.
    pub source: f64,
    /// h \[W/(m² K)\]: exchange with the surroundings over a grain's surface (with `[kinetics]
    /// ambient_temperature`).
    pub surface_transfer: f64,
}

/// How the conductance of a contact follows from its overlap (`[simulation]
/// conduction_model`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Conduction {
    /// H = 2 k_eff a, a = sqrt(R* δ) the Hertz contact radius (Batchelor & O'Brien 1977).
    #[default]
    BatchelorOBrien,
    /// H = 2 k_eff sqrt(A), A = π a_o² with a_o the radius of the circle where the spheres'
    /// surfaces cross (LIGGGHTS's `heat/gran/conduction`, without its area correction).
    Liggghts,
}

impl Conduction {
    /// The value of the scenario key.
    pub fn key(self) -> &'static str {
        match self {
            Conduction::BatchelorOBrien => "batchelor_obrien",
            Conduction::Liggghts => "liggghts",
        }
    }

    /// The radius whose disc conducts, for spheres of radii `r_i`, `r_j` (`r_j` infinite:
    /// a wall) overlapping by `delta`.
    pub fn contact_radius(self, r_i: f64, r_j: f64, delta: f64) -> f64 {
        match self {
            Conduction::BatchelorOBrien => {
                let r_star = if r_j.is_finite() {
                    r_i * r_j / (r_i + r_j)
                } else {
                    r_i
                };
                (r_star * delta).sqrt()
            }
            Conduction::Liggghts => {
                let a_o = if r_j.is_finite() {
                    // The circle where the two surfaces cross, at distance d of the centres.
                    let d = r_i + r_j - delta;
                    let x = (d * d + r_i * r_i - r_j * r_j) / (2.0 * d);
                    (r_i * r_i - x * x).max(0.0).sqrt()
                } else {
                    (delta * (2.0 * r_i - delta)).max(0.0).sqrt()
                };
                std::f64::consts::PI.sqrt() * a_o
            }
        }
    }
}

/// k_eff = 2 k_i k_j / (k_i + k_j), the series conductivity of the two sides (0 if either
/// conducts nothing).
pub fn effective_conductivity(k_i: f64, k_j: f64) -> f64 {
    if k_i > 0.0 && k_j > 0.0 {
        2.0 * k_i * k_j / (k_i + k_j)
    } else {
        0.0
    }
}

/// H \[W/K\] = 2 k_eff a: the conductance of a contact of radius `a` between sides of
/// conductivities `k_i`, `k_j` (Batchelor & O'Brien 1977, Eq. 4.9).
pub fn conductance(k_i: f64, k_j: f64, a: f64) -> f64 {
    2.0 * effective_conductivity(k_i, k_j) * a
}

/// The constants of heat transfer in a run.
#[derive(Clone, Debug, PartialEq)]
pub struct HeatModel {
    /// Per material.
    pub materials: Vec<Thermal>,
    /// Per material: ρ 4/3 π, a particle's mass over R³.
    pub mass_per_r3: Vec<f64>,
    /// The thermal step Δt_th = f Δt (`thermal_time_scale` f) \[s\].
    pub dt: f64,
    /// T_∞ \[K\] of the surroundings, if grains exchange heat with them.
    pub ambient: Option<f64>,
    /// The heat content of one quantum \[J\]: a power of two.
    pub quantum: f64,
    pub conduction: Conduction,
}

impl HeatModel {
    /// The quantum for particles of heat capacity m c at most `largest` \[J/K\]: 2^-64 of it
    /// (rounded up to a power of two), so a content of 2^63 K times the largest grain's
    /// still fits the 128 bits, and the smallest grain's temperature is resolved far
    /// below a float's last bit.
    pub fn quantum_for(largest: f64) -> f64 {
        assert!(
            largest.is_finite() && largest > 0.0,
            "heat capacity {largest}"
        );
        2f64.powi(largest.log2().ceil() as i32 - 64)
    }

    /// m c \[J/K\] of a particle of material `material` and radius `radius`.
    #[inline]
    pub fn capacity(&self, material: u16, radius: f64) -> f64 {
        let m = material as usize;
        self.mass_per_r3[m] * radius * radius * radius * self.materials[m].capacity
    }

    /// The content (in quanta) of heat capacity `mc` at temperature `t`.
    #[inline]
    pub fn content(&self, mc: f64, t: f64) -> i128 {
        (mc * t * (1.0 / self.quantum)).round_ties_even() as i128
    }

    /// The temperature of content `e` (in quanta) at heat capacity `mc`.
    #[inline]
    pub fn temperature(&self, mc: f64, e: i128) -> f64 {
        e as f64 * self.quantum / mc
    }

    /// The quanta of heat `joules`, rounded to the nearest (ties to even: the quanta of
    /// `-joules` are minus those of `joules`, so a contact moves as much out of one partner
    /// as into the other).
    #[inline]
    pub fn quanta(&self, joules: f64) -> i128 {
        // Exact: the quantum is a power of two. Below 2^62 the hardware's conversion to 64
        // bits; a contact's heat of a step nearly always is.
        let x = (joules * (1.0 / self.quantum)).round_ties_even();
        if x.abs() < 4.6e18 {
            x as i64 as i128
        } else {
            x as i128
        }
    }

    /// Whether any material makes heat or exchanges it with the surroundings (else a
    /// particle gains heat through its contacts only).
    pub fn own_gains(&self) -> bool {
        let exchange = self.ambient.is_some();
        (self.materials.iter()).any(|t| t.source != 0.0 || (exchange && t.surface_transfer > 0.0))
    }

    /// The heat of one thermal step through conductance `h` from temperature `from` to
    /// `to` (negative: the other way), in quanta.
    #[inline]
    pub fn flow(&self, h: f64, from: f64, to: f64) -> i128 {
        self.quanta(h * (from - to) * self.dt)
    }

    /// The heat made in one thermal step in (and exchanged with the surroundings over the
    /// surface of) a particle of material `material`, radius `radius`, at temperature `t`,
    /// in quanta.
    #[inline]
    pub fn own_gain(&self, material: u16, radius: f64, t: f64) -> i128 {
        let th = &self.materials[material as usize];
        let volume = 4.0 / 3.0 * std::f64::consts::PI * radius * radius * radius;
        let mut watts = th.source * volume;
        if let Some(t_inf) = self.ambient {
            let area = 4.0 * std::f64::consts::PI * radius * radius;
            watts += th.surface_transfer * area * (t_inf - t);
        }
        self.quanta(watts * self.dt)
    }

    /// The shortest thermal time scale of a grain: m c over the conductance of `contacts`
    /// contacts of radius one tenth of its own (a dense packing under load), for the
    /// materials that conduct, over the radii `r_min` to `r_max` (m c / H grows as R²,
    /// so the smallest grains set it), with the fastest exchange with the surroundings.
    pub fn time_scale(&self, r_min: f64, contacts: f64) -> f64 {
        let mut tau = f64::INFINITY;
        for (m, th) in self.materials.iter().enumerate() {
            // (A material of walls alone has no capacity.)
            if th.capacity <= 0.0 || (th.conductivity <= 0.0 && th.surface_transfer <= 0.0) {
                continue;
            }
            let mc = self.capacity(m as u16, r_min);
            let k_max = self
                .materials
                .iter()
                .map(|t| t.conductivity)
                .fold(0.0, f64::max);
            let h = contacts * conductance(th.conductivity, k_max, 0.1 * r_min)
                + match self.ambient {
                    Some(_) => th.surface_transfer * 4.0 * std::f64::consts::PI * r_min * r_min,
                    None => 0.0,
                };
            if h > 0.0 {
                tau = tau.min(mc / h);
            }
        }
        tau
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> HeatModel {
        HeatModel {
            materials: vec![Thermal {
                conductivity: 1.0,
                capacity: 800.0,
                initial_temperature: 300.0,
                source: 0.0,
                surface_transfer: 0.0,
            }],
            mass_per_r3: vec![2500.0 * 4.0 / 3.0 * std::f64::consts::PI],
            dt: 1e-5,
            ambient: None,
            quantum: HeatModel::quantum_for(1.0),
            conduction: Conduction::BatchelorOBrien,
        }
    }

    #[test]
    fn contents_and_temperatures_convert_back_within_a_quantum() {
        let h = model();
        let mc = h.capacity(0, 1e-3);
        for t in [0.0, 1e-3, 293.15, 2000.0] {
            let e = h.content(mc, t);
            assert!((h.temperature(mc, e) - t).abs() <= h.quantum / mc);
        }
        assert_eq!(HeatModel::quantum_for(1.0), 2f64.powi(-64));
        assert_eq!(HeatModel::quantum_for(3.0), 2f64.powi(-62));
    }

    #[test]
    fn the_contact_radii_of_the_two_models() {
        let (r, delta) = (1e-3, 1e-6);
        // Hertz: a² = R* δ, R* = R/2 for equal spheres and R for a wall.
        let b = Conduction::BatchelorOBrien;
        assert!((b.contact_radius(r, r, delta) - (r / 2.0 * delta).sqrt()).abs() < 1e-15);
        assert!((b.contact_radius(r, f64::INFINITY, delta) - (r * delta).sqrt()).abs() < 1e-15);
        // The crossing circle of equal spheres: a_o² = R δ - δ²/4, times sqrt(π).
        let l = Conduction::Liggghts;
        let a_o = (r * delta - delta * delta / 4.0).sqrt();
        let pi = std::f64::consts::PI;
        assert!((l.contact_radius(r, r, delta) - pi.sqrt() * a_o).abs() < 1e-12 * a_o);
        let wall = (2.0 * r * delta - delta * delta).sqrt();
        assert!((l.contact_radius(r, f64::INFINITY, delta) - pi.sqrt() * wall).abs() < 1e-12);
    }

    #[test]
    fn conductance_in_series_and_none_through_an_insulator() {
        assert_eq!(effective_conductivity(2.0, 2.0), 2.0);
        assert!((effective_conductivity(1.0, 3.0) - 1.5).abs() < 1e-15);
        assert_eq!(conductance(1.0, 0.0, 1e-4), 0.0);
        assert_eq!(conductance(4.0, 4.0, 1e-4), 8e-4);
    }

    #[test]
    fn a_flow_moves_whole_quanta_and_sources_add_heat() {
        let mut h = model();
        let q = h.flow(1e-3, 400.0, 300.0);
        assert_eq!(q, h.quanta(1e-3 * 100.0 * 1e-5));
        assert_eq!(h.flow(1e-3, 300.0, 400.0), -q);
        assert_eq!(h.own_gain(0, 1e-3, 300.0), 0);
        h.materials[0].source = 1e6;
        let v = 4.0 / 3.0 * std::f64::consts::PI * 1e-9;
        assert_eq!(h.own_gain(0, 1e-3, 300.0), h.quanta(1e6 * v * 1e-5));
        h.materials[0].source = 0.0;
        h.materials[0].surface_transfer = 10.0;
        h.ambient = Some(290.0);
        assert!(h.own_gain(0, 1e-3, 300.0) < 0);
    }
}
