//! Stage 4b of the step: heat transfer (`model/heat.rs`): conduction through the contacts of
//! touching particles and of particles with walls held at a temperature, sources and
//! exchange with the surroundings, then each particle's content and temperature advanced
//! (explicit Euler, by the thermal step f Δt).

use super::*;
use crate::model::heat::{HeatModel, conductance};

/// What stage 4b reads of the walls: each mesh file's temperature (`None`: adiabatic) and
/// conductivity.
pub(crate) struct WallHeat {
    pub(crate) temperature: Vec<Option<f64>>,
    pub(crate) conductivity: Vec<f64>,
}

impl WallHeat {
    /// Whether some wall is held at a temperature and conducts.
    fn any(&self) -> bool {
        (self.temperature.iter().zip(&self.conductivity)).any(|(t, &k)| t.is_some() && k > 0.0)
    }
}

/// Stage 4b: the heat of one thermal step into every particle of `p` (its content and
/// temperature updated), from its touching partners in `lists`, from the walls (faces of
/// `walls` held at a temperature), made in it and exchanged with the surroundings. Returns
/// the heat into each mesh file in quanta (from the `owned` particles of a split run), and
/// whether a temperature left the physical range (below 0 K, or not finite: the thermal
/// step overshoots).
///
/// A temperature set from outside (a file, a spawn region, Python) is taken as new: the
/// content of a particle whose temperature is not that of its content is made from its
/// temperature first. Each contact moves a whole number of quanta, computed once from its
/// lower-id side, so the sum of the contents changes only by the walls, the sources and
/// the surroundings, exactly.
pub(super) fn run(
    heat: &HeatModel,
    (walls, wall_heat): (&Walls, &WallHeat),
    lists: &Neighbours,
    owned: Option<&[bool]>,
    p: &mut Particles,
) -> (Vec<i128>, bool) {
    take_new_temperatures(heat, p);
    let p_ = &*p;
    let mut gain: Vec<i128> = match heat.own_gains() {
        true => (0..p_.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|i| heat.own_gain(p_.material[i], p_.radius[i], p_.temperature[i]))
            .collect(),
        false => vec![0; p_.len()],
    };
    between_pairs(heat, p_, lists, &mut gain);
    let into_walls = match wall_heat.any() {
        true => from_walls(heat, (walls, wall_heat), &lists.faces, owned, p_, &mut gain),
        false => vec![0; walls.files.len()],
    };
    let bad = advance(heat, p, &gain);
    (into_walls, bad)
}

/// The content of each particle whose temperature is not that of its content, from its
/// temperature.
fn take_new_temperatures(heat: &HeatModel, p: &mut Particles) {
    let Particles {
        radius,
        material,
        temperature,
        heat: content,
        ..
    } = p;
    (content, &*temperature, &*radius, &*material)
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .for_each(|(e, &t, &r, &m)| {
            let mc = heat.capacity(m, r);
            if mc > 0.0 && heat.temperature(mc, *e) != t {
                *e = heat.content(mc, t);
            }
        });
}

/// Each content advanced by its `gain`, and its temperature with it; whether a temperature
/// left the physical range.
fn advance(heat: &HeatModel, p: &mut Particles, gain: &[i128]) -> bool {
    let Particles {
        radius,
        material,
        temperature,
        heat: content,
        ..
    } = p;
    (content, temperature, &*radius, &*material, gain)
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|(e, t, &r, &m, &q)| {
            // (A particle that gains nothing keeps its temperature to the bit, as set.)
            let mc = heat.capacity(m, r);
            if mc > 0.0 && q != 0 {
                *e = e.saturating_add(q);
                *t = heat.temperature(mc, *e);
            }
            !(*t >= 0.0 && t.is_finite())
        })
        .reduce(|| false, |a, b| a | b)
}

/// The heat through a contact of partners `i` (the lower id) and `j` seen at its image
/// `x_j` overlapping, into `i`, in quanta.
#[inline]
fn through(heat: &HeatModel, p: &Particles, i: usize, j: usize, x_j: DVec3) -> i128 {
    let (r_i, r_j) = (p.radius[i], p.radius[j]);
    let delta = r_i + r_j - (p.x[i] - x_j).length();
    if delta <= 0.0 {
        return 0;
    }
    let k = |m: u16| heat.materials[m as usize].conductivity;
    let a = heat.conduction.contact_radius(r_i, r_j, delta);
    let h = conductance(k(p.material[i]), k(p.material[j]), a);
    heat.flow(h, p.temperature[j], p.temperature[i])
}

/// A slab (its index), its particles' gains and the next slab's.
type SlabGains<'a> = (usize, &'a mut [i128], Option<&'a mut [i128]>);

/// The conduction between touching particles: the pair list's slabs (even ones at once,
/// then odd ones, as stage 3: a slab's partners lie in it or the next), then the pairs
/// across periodic sides.
fn between_pairs(heat: &HeatModel, p: &Particles, lists: &Neighbours, gain: &mut [i128]) {
    let ContactList {
        start,
        partner,
        contact,
        blocks: slabs,
        ..
    } = &lists.pairs;
    let owners: Vec<usize> = slabs.iter().map(|&o| o as usize).collect();
    for phase in 0..2 {
        let mut all: Vec<Option<&mut [i128]>> = cut(gain, &owners).into_iter().map(Some).collect();
        let tasks: Vec<SlabGains> = (phase..all.len())
            .step_by(2)
            .map(|s| {
                let own = all[s].take().expect("each slab once");
                (s, own, all.get_mut(s + 1).and_then(Option::take))
            })
            .collect();
        tasks.into_par_iter().for_each(|(s, own, mut next)| {
            let (base, end) = (owners[s], owners[s + 1]);
            for a in base..end {
                for k in start[a] as usize..start[a + 1] as usize {
                    if contact[k] == NONE {
                        continue;
                    }
                    let b = partner[k] as usize;
                    let (i, j) = if p.id[a] < p.id[b] { (a, b) } else { (b, a) };
                    let q = through(heat, p, i, j, p.x[j]);
                    for (at, q) in [(i, q), (j, -q)] {
                        match at < end {
                            true => own[at - base] += q,
                            false => {
                                next.as_mut().expect("partners reach the next slab")[at - end] += q
                            }
                        }
                    }
                }
            }
        });
    }
    let w = &lists.wrapped;
    for a in 0..w.start.len().saturating_sub(1) {
        for k in w.start[a] as usize..w.start[a + 1] as usize {
            if w.contact[k] == NONE {
                continue;
            }
            let b = w.partner[k] as usize;
            // As stage 3: the lower id at its place, the other at its image.
            let (shift, _) = lists.image(k);
            let (i, j) = if p.id[a] < p.id[b] { (a, b) } else { (b, a) };
            let q = through(heat, p, i, j, p.x[j] + shift);
            gain[i] += q;
            gain[j] -= q;
        }
    }
}

/// The conduction between particles and the faces they touch of the mesh files held at a
/// temperature (the contacts of stage 4, one per touch of a surface), into `gain`; the
/// heat into each file, of the `owned` particles.
fn from_walls(
    heat: &HeatModel,
    (walls, wall_heat): (&Walls, &WallHeat),
    list: &ContactList,
    owned: Option<&[bool]>,
    p: &Particles,
    gain: &mut [i128],
) -> Vec<i128> {
    let files = walls.files.len();
    gain.par_iter_mut()
        .enumerate()
        .with_min_len(MIN_PARALLEL_LEN)
        .fold(
            || vec![0i128; files],
            |mut into, (i, g)| {
                for k in list.start[i] as usize..list.start[i + 1] as usize {
                    if list.contact[k] == NONE {
                        continue;
                    }
                    let f = list.partner[k] as usize;
                    let file = walls.face_file[f] as usize;
                    let Some(t_w) = wall_heat.temperature[file] else {
                        continue;
                    };
                    let face = &walls.mesh.faces[f];
                    let (d, feature) = face.separation_and_feature(p.x[i]);
                    let (d, _) = surface::snap(face, p.x[i], p.radius[i], d, feature);
                    let delta = p.radius[i] + face.radius - d.length();
                    if delta <= 0.0 {
                        continue;
                    }
                    let a = heat
                        .conduction
                        .contact_radius(p.radius[i], f64::INFINITY, delta);
                    let k_i = heat.materials[p.material[i] as usize].conductivity;
                    let h = conductance(k_i, wall_heat.conductivity[file], a);
                    let q = heat.flow(h, t_w, p.temperature[i]);
                    *g += q;
                    if owned.is_none_or(|o| o[i]) {
                        into[file] -= q;
                    }
                }
                into
            },
        )
        .reduce(
            || vec![0i128; files],
            |mut a, b| {
                a.iter_mut().zip(b).for_each(|(a, b)| *a += b);
                a
            },
        )
}

/// An i128 as three words of 42 bits (the highest signed), which add as i64 over up to
/// 2^21 processes without overflow.
fn words(v: i128) -> [i64; 3] {
    const MASK: i128 = (1 << 42) - 1;
    [
        (v >> 84) as i64,
        ((v >> 42) & MASK) as i64,
        (v & MASK) as i64,
    ]
}

fn from_words(w: &[i64]) -> i128 {
    ((w[0] as i128) << 84) + ((w[1] as i128) << 42) + w[2] as i128
}

impl Simulation {
    /// Heat transfer set up, if the scenario transfers heat: its model, the walls'
    /// temperatures, and the particles holding a temperature (their material's initial
    /// one, unless they hold one already, e.g. from a `T` column) and a content.
    pub(super) fn start_heat(&mut self) -> Result<()> {
        let s = &self.scenario;
        if !s.heat() {
            self.model.heat = None;
            return Ok(());
        }
        let mut used = s.spawned_materials();
        used.extend(self.particles.material.iter().copied());
        used.sort_unstable();
        used.dedup();
        s.heat_capacity_missing(used)?;
        let r_max = LoadScales::largest_radius(s).max(self.particles.max_radius());
        let model = s.heat_model(r_max).expect("heat is transferred");
        let mut temperature = vec![None; self.walls.files.len()];
        for (t, m) in temperature[1..].iter_mut().zip(&s.meshes) {
            *t = m.temperature;
        }
        let conductivity = (self.walls.files.iter())
            .map(|f| {
                s.materials[f.material as usize]
                    .properties
                    .thermal
                    .conductivity
            })
            .collect();
        let walls = WallHeat {
            temperature,
            conductivity,
        };
        let p = &mut self.particles;
        if !p.active.temperature {
            p.activate("T");
            for (t, &m) in p.temperature.iter_mut().zip(&p.material) {
                *t = s.materials[m as usize]
                    .properties
                    .thermal
                    .initial_temperature;
            }
        }
        p.activate("heat");
        take_new_temperatures(&model, p);
        self.walls.heat = vec![0; self.walls.files.len()];
        self.model.heat = Some((model, walls));
        Ok(())
    }

    /// A step's heat into each mesh file (of this process's own particles), added to the
    /// files' sums (over all processes of a split run).
    pub(super) fn add_wall_heat(&mut self, step: Vec<i128>) {
        let step = match &self.share {
            Some(d) => {
                let w: Vec<i64> = step.iter().flat_map(|&v| words(v)).collect();
                d.comm.sum_i64(&w).chunks(3).map(from_words).collect()
            }
            None => step,
        };
        for (sum, q) in self.walls.heat.iter_mut().zip(step) {
            *sum += q;
        }
    }

    /// The heat into each mesh file since the last call \[J\] (0 without heat transfer),
    /// and the sums set back to zero.
    pub fn take_wall_heat(&mut self) -> Vec<f64> {
        let heat = self.walls.take_heat();
        match &self.model.heat {
            Some((model, _)) => heat.iter().map(|&q| q as f64 * model.quantum).collect(),
            None => vec![0.0; heat.len()],
        }
    }

    /// The temperatures of the particles (over all processes of a split run: the mean an
    /// exact sum, so the same bits on any number), if heat is transferred (collective).
    pub(super) fn temperatures(&self) -> Option<Temperatures> {
        self.model.heat.as_ref()?;
        let p = &self.particles;
        let own: Vec<usize> = (0..p.len()).filter(|&i| self.own(i)).collect();
        // Σ T in units of 2^-64 K, exactly.
        let kelvin = 2f64.powi(64);
        let sum: i128 = own
            .iter()
            .map(|&i| (p.temperature[i] * kelvin) as i128)
            .sum();
        let (content, _) = self.heat_content();
        let min = own
            .iter()
            .map(|&i| p.temperature[i])
            .fold(f64::INFINITY, f64::min);
        let max = own
            .iter()
            .map(|&i| p.temperature[i])
            .fold(f64::NEG_INFINITY, f64::max);
        let (n, sum, content, min, max) = match &self.share {
            Some(d) => {
                let w: Vec<i64> = [own.len() as i128, sum, content]
                    .iter()
                    .flat_map(|&v| words(v))
                    .collect();
                let total: Vec<i128> = d.comm.sum_i64(&w).chunks(3).map(from_words).collect();
                (
                    total[0],
                    total[1],
                    total[2],
                    -d.comm.max(-min),
                    d.comm.max(max),
                )
            }
            None => (own.len() as i128, sum, content, min, max),
        };
        let quantum = self.model.heat.as_ref().map_or(0.0, |h| h.0.quantum);
        Some(match n {
            0 => Temperatures::default(),
            n => Temperatures {
                mean: sum as f64 / kelvin / n as f64,
                min,
                max,
                content: content as f64 * quantum,
            },
        })
    }

    /// The heat content of the particles Σ m c T \[J\] (this process's own, in a split run),
    /// exactly summed: 0 without heat transfer.
    pub fn heat_content(&self) -> (i128, f64) {
        let Some((model, _)) = &self.model.heat else {
            return (0, 0.0);
        };
        let p = &self.particles;
        let total: i128 = (0..p.len())
            .filter(|&i| self.own(i))
            .map(|i| p.heat[i])
            .sum();
        (total, total as f64 * model.quantum)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn words_of_an_i128_add_up_to_its_sum() {
        let values = [
            0i128,
            1,
            -1,
            (1 << 100) + 12345,
            -(1 << 110) - 7,
            i64::MAX as i128 * 3,
        ];
        let mut total = [0i64; 3];
        for v in values {
            let w = super::words(v);
            assert_eq!(super::from_words(&w), v);
            (0..3).for_each(|k| total[k] += w[k]);
        }
        assert_eq!(super::from_words(&total), values.iter().sum::<i128>());
    }
}
