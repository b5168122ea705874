//! Stage 6 of the step: the stability verdict (deep overlaps, states out of range), the
//! warnings of overlaps past the smaller radius and the advice they give.

use super::*;

/// The reports of every process of a split run, in the order they are told.
pub(super) fn gather_told(
    comm: &dyn crate::parallel::comm::Comm,
    told: Vec<(u8, u64, u64, String)>,
) -> Vec<(u8, u64, u64, String)> {
    use crate::parallel::comm::{Reader, Writer};
    let mut w = Writer::default();
    for (kind, a, b, text) in &told {
        w.u8(*kind);
        w.u64(*a);
        w.u64(*b);
        w.bytes(text.as_bytes());
    }
    let mut all = Vec::new();
    for m in comm.all_gather(w.0) {
        let mut r = Reader::new(&m);
        while !r.done() {
            let (kind, a, b) = (r.u8(), r.u64(), r.u64());
            all.push((kind, a, b, String::from_utf8_lossy(r.bytes()).into_owned()));
        }
    }
    all.sort_by_key(|x| (x.0, x.1, x.2));
    all
}

impl Simulation {
    /// Stage 6: stop loudly rather than continue a run that has blown up: a non-finite
    /// state (`non_finite_state`, from the integration), a load out of the range of its sum
    /// or an overlap past the smaller diameter (`found` by this step's contact stages, with
    /// every overlap deeper than the smaller radius). Those within the diameter are a
    /// legitimate transient of a crowded packing (a small grain squeezed by a large one)
    /// and only warned of, once per pair.
    #[inline(never)] // a stage of its own in profiles
    pub(super) fn check_stability(
        &mut self,
        found: Findings,
        non_finite_state: bool,
    ) -> Result<(), Unstable> {
        let Findings {
            mut deep,
            beyond_range,
            ..
        } = found;
        let p = &self.particles;
        let non_finite = |k: usize| self.broken(k);
        // Split over processes: each reports on its own particles (a pair: the one of the
        // lower id), and all stop if one must.
        let bad = match &self.share {
            Some(d) => {
                deep.retain(|x| d.owned[x.i]);
                let own_bad = (0..p.len()).any(|k| d.owned[k] && non_finite(k));
                let bad = beyond_range || own_bad || deep.iter().any(Deep::through);
                d.comm.any(bad)
            }
            None => non_finite_state || beyond_range || deep.iter().any(Deep::through),
        };
        if !bad {
            for d in deep {
                if self.warnings.seen.insert(d.key(&p.id)) {
                    self.warnings
                        .fresh
                        .push(format!("step {}: {}", self.steps, d.describe(&p.id)));
                }
            }
            return Ok(());
        }
        let told = self.told(deep, beyond_range);
        let told = match &self.share {
            Some(d) => gather_told(&*d.comm, told),
            None => told,
        };
        let mut what: Vec<String> = Vec::new();
        let kind = |k: u8| told.iter().filter(move |t| t.0 == k).map(|t| t.3.clone());
        what.extend(kind(0).take(1));
        what.extend(kind(1).take(5));
        let room = 5 - what.len().min(5);
        what.extend(kind(2).take(room));
        let hot = (0..self.particles.len()).any(|k| self.own(k) && self.bad_temperature(k));
        Err(Unstable {
            step: self.steps,
            time: self.time,
            what,
            advice: match hot {
                true => "the explicit heat update overshoots: lower [simulation] thermal_time_scale (tinydem check prints the thermal time scale)".into(),
                false => self.advice(),
            },
        })
    }

    /// What went wrong in a step that stops the run, each with the order it is told in:
    /// the range of the sums, then up to five particles in id order (own ones, in a split
    /// run), then the deepest overlaps past the smaller diameter by pair.
    fn told(&self, mut deep: Vec<Deep>, beyond_range: bool) -> Vec<(u8, u64, u64, String)> {
        let p = &self.particles;
        let non_finite = |k: usize| self.broken(k);
        let mut told: Vec<(u8, u64, u64, String)> = Vec::new();
        if beyond_range {
            told.push((0, 0, 0, format!(
                "a contact force or torque was not finite or beyond the range of the sums ({:.3e} N, {:.3e} N m: 4096 times the largest a contact of these materials and radii should give)",
                self.model.scales.force.largest(),
                self.model.scales.torque.largest()
            )));
        }
        for k in p
            .id_order()
            .into_iter()
            .filter(|&k| self.own(k) && non_finite(k))
            .take(5)
        {
            let what = match self.model.heat.as_ref().filter(|_| self.bad_temperature(k)) {
                Some((h, _)) => format!(
                    "particle {} has a temperature of {} K (heat advanced by f dt = {:.3e} s per step)",
                    p.id[k], p.temperature[k], h.dt,
                ),
                None => format!(
                    "particle {} has a non-finite state (x = {}, v = {}, w = {})",
                    p.id[k], p.x[k], p.v[k], p.w[k]
                ),
            };
            told.push((1, p.id[k], 0, what));
        }
        deep.retain(Deep::through);
        deep.sort_by_key(|d| d.key(&p.id));
        for d in deep.iter().take(5) {
            let (a, other) = d.key(&p.id);
            let b = match other {
                Partner::Particle(j) => j,
                // (Faces after every particle: ids stay below 2^62.)
                Partner::Face(f) => (1 << 63) | f as u64,
            };
            told.push((2, a, b, d.describe(&p.id)));
        }
        told
    }

    /// Whether particle `k`'s state has blown up: not finite, or (with heat transfer) a
    /// temperature below 0 K or not finite.
    fn broken(&self, k: usize) -> bool {
        let p = &self.particles;
        !(p.x[k].is_finite() && p.v[k].is_finite() && p.w[k].is_finite()) || self.bad_temperature(k)
    }

    /// Whether particle `k`'s temperature (with heat transfer) has left the physical
    /// range: below 0 K, or not finite.
    fn bad_temperature(&self, k: usize) -> bool {
        let t = self.particles.temperature.get(k);
        self.model.heat.is_some() && t.is_some_and(|&t| !(t >= 0.0 && t.is_finite()))
    }

    /// Overlaps past the smaller radius so far (each pair once).
    pub fn warnings(&self) -> &Warnings {
        &self.warnings
    }

    /// Descriptions of the pairs that overlapped past the smaller radius for the first time
    /// since the last call.
    pub fn take_new_warnings(&mut self) -> Vec<String> {
        let fresh = std::mem::take(&mut self.warnings.fresh);
        match &self.share {
            // Every process's (collective).
            Some(d) => crate::parallel::decomposition::gather_lines(&*d.comm, fresh),
            None => fresh,
        }
    }

    /// The likely cause of an instability, from the time step and the material.
    pub fn advice(&self) -> String {
        let s = &self.scenario;
        let dt = s.simulation.timestep;
        let (eq50, rule) = (s.eq50_timestep(), s.timestep_rule());
        if dt > eq50 {
            format!(
                "timestep {dt:.3e} s exceeds {rule}'s {eq50:.3e} s for this stiffness and density \
                 ({:.1} x): try timestep <= {eq50:.3e} s (or leave it unset)",
                dt / eq50
            )
        } else {
            format!(
                "timestep {dt:.3e} s is within {rule}'s {eq50:.3e} s: check for particles \
                 created overlapping each other or the mesh, radii below radius_min, very \
                 high impact speeds or strong friction (try a smaller timestep, e.g. {:.3e} s)",
                dt / 5.0
            )
        }
    }
}
