//! The regions of a scenario that act on particles: stage 5b, which tags those in a
//! `[[tags]]` box, and stage 7, which removes those in an outlet or outside the domain.

use super::*;

impl Simulation {
    /// Stage 7: particles whose centre has entered an outlet or left the domain are
    /// removed (counted, with their mass, by the outlet or the domain: the first outlet
    /// that holds a particle takes it). The lists are rebuilt without them; the ids of the
    /// others stay.
    #[inline(never)] // a stage of its own in profiles
    pub(super) fn remove(&mut self) {
        let s = &self.scenario;
        if !s.removes() {
            return;
        }
        let (domain, outlets, periodic) = (s.domain, s.outlets.clone(), s.periodic);
        // Outside the domain through a side that is not periodic.
        let outside = move |x: DVec3| {
            domain.is_some_and(|d| {
                (0..3).any(|a| !periodic[a] && (x[a] < d.min[a] || x[a] > d.max[a]))
            })
        };
        // Where each removed particle goes: an outlet, or `outlets.len()` for the domain.
        let fate = move |x: DVec3| -> Option<u32> {
            if let Some(k) = outlets.iter().position(|o| o.contains(x)) {
                return Some(k as u32);
            }
            outside(x).then_some(outlets.len() as u32)
        };
        if self.domain.is_some() {
            return self.remove_split(fate);
        }
        let p = &self.particles;
        // A rigid body goes whole, where its centre of mass goes.
        let centre = |i: usize| match p.body[i] {
            Some(b) => p.bodies.list[p.bodies.index_of(b).expect("a listed body")].x,
            None => p.x[i],
        };
        let gone: Vec<(u32, u32)> = (0..p.len())
            .into_par_iter()
            .with_min_len(4 * MIN_PARALLEL_LEN)
            .filter_map(|i| fate(centre(i)).map(|f| (i as u32, f)))
            .collect();
        if gone.is_empty() {
            return;
        }
        // Counted in id order, so the masses sum in an order of their own.
        let mut by_id: Vec<(Id, u32, u32)> = gone
            .iter()
            .map(|&(i, f)| (p.id[i as usize], i, f))
            .collect();
        by_id.sort_unstable();
        let densities = &self.model.densities;
        for &(id, i, f) in &by_id {
            let out = match self.removed.outlets.get_mut(f as usize) {
                Some(o) => o,
                None => &mut self.removed.domain,
            };
            let mass = match p.body[i as usize] {
                // A body counts once, by its first sphere, with its mass.
                Some(b) if id != b.first() => continue,
                Some(b) => p.bodies.mass_of(b),
                None => {
                    let material = densities[p.material[i as usize] as usize];
                    Inertia::mass_with(p.radius[i as usize], material.mass_per_r3)
                }
            };
            out.count += 1;
            out.mass += mass;
        }
        let gone: Vec<u32> = gone.into_iter().map(|(i, _)| i).collect();
        self.drop_stored(&gone);
    }

    /// Whether frames name each particle's id and material: particles can be removed (or
    /// were, in an earlier stage), so the line of a particle is not its id, or there are
    /// several materials.
    pub fn frames_carry_ids(&self) -> bool {
        let p = &self.particles;
        self.scenario.removes()
            || self.scenario.materials.len() > 1
            || !self.scenario.clumps.is_empty()
            || p.next_id as usize != self.particle_count()
    }

    /// Whether frames carry a `fixed` column: the scenario fixes particles, or some are.
    pub fn has_fixed(&self) -> bool {
        !self.scenario.fixed.is_empty() || self.particles.fixed.contains(&true)
    }

    /// Whether frames carry a tag column: the scenario tags particles, or they came tagged.
    pub fn has_tags(&self) -> bool {
        let tagged = self.particles.tagged();
        let tagged = self.domain.as_ref().map_or(tagged, |d| d.comm.any(tagged));
        !self.scenario.tags.is_empty() || tagged
    }
}

/// Stage 5b: particles of `p` whose centre is inside one of the boxes `regions` (`[[tags]]`)
/// take its tag (the last box that holds it).
#[inline(never)] // a stage of its own in profiles
pub(super) fn tag(regions: &[TagRegion], p: &mut Particles) {
    if regions.is_empty() {
        return;
    }
    p.tag
        .par_iter_mut()
        .zip(p.x.par_iter())
        .with_min_len(4 * MIN_PARALLEL_LEN)
        .for_each(|(tag, x)| {
            for r in regions {
                if x.cmpge(r.min).all() && x.cmple(r.max).all() {
                    *tag = r.tag;
                }
            }
        });
}
