//! The regions of a scenario that act on particles: stage 5b, which tags those in a
//! `[[tags]]` box, and stage 7, which removes those in an outlet or outside the domain.

use super::*;

/// A grain removed: a particle, or a rigid body by its first sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Gone {
    pub first: Id,
    /// The outlet (an index of `[[outlets]]`), or the domain (past them).
    pub fate: u32,
    /// \[M\]
    pub mass: f64,
    /// The ids it had: `first..first + ids`.
    pub ids: u64,
}

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
        let (mine, gone) = self.leaving(fate);
        if gone.is_empty() {
            return;
        }
        self.book_kinetic(mine.iter().map(|&k| k as usize), false);
        // Counted in id order (over all processes), so the masses sum in an order of their
        // own.
        for g in &gone {
            let out = match self.removed.outlets.get_mut(g.fate as usize) {
                Some(o) => o,
                None => &mut self.removed.domain,
            };
            out.count += 1;
            out.mass += g.mass;
        }
        match &self.share {
            None => self.drop_stored(&mine),
            Some(_) => {
                let ids = gone.iter().flat_map(|g| g.first..g.first + g.ids);
                self.redistribute(
                    &ids.collect(),
                    crate::parallel::decomposition::Placement::Now,
                );
            }
        }
    }

    /// What leaves through `fate` (an outlet's index, or that of the domain past them):
    /// the storage indices of the own particles that go (a rigid body whole, where its
    /// centre of mass goes); and, over all processes (collective) in id order, each grain
    /// gone (a sphere, or a body by its first sphere).
    fn leaving(&self, fate: impl Fn(DVec3) -> Option<u32> + Sync) -> (Vec<u32>, Vec<Gone>) {
        let p = &self.particles;
        let own = |i: usize| self.share.as_ref().is_none_or(|d| d.owned[i]);
        let centre = |i: usize| match p.body[i] {
            Some(b) => p.bodies.list[p.bodies.index_of(b).expect("a listed body")].x,
            None => p.x[i],
        };
        let mine: Vec<u32> = (0..p.len())
            .into_par_iter()
            .with_min_len(4 * MIN_PARALLEL_LEN)
            .filter(|&i| own(i) && fate(centre(i)).is_some())
            .map(|i| i as u32)
            .collect();
        let densities = &self.model.densities;
        let mut gone: Vec<Gone> = Vec::new();
        for &i in &mine {
            let i = i as usize;
            let grain = match p.body[i] {
                // A body counts once, by its first sphere, with its mass.
                Some(b) if p.id[i] != b.first() => continue,
                Some(b) => {
                    let body = &p.bodies.list[p.bodies.index_of(b).expect("a listed body")];
                    (body.mass, body.offsets.len() as u64)
                }
                None => {
                    let density = densities[p.material[i] as usize];
                    (Inertia::mass_with(p.radius[i], density.mass_per_r3), 1)
                }
            };
            let (mass, ids) = grain;
            let fate = fate(centre(i)).expect("it leaves");
            gone.push(Gone {
                first: p.id[i],
                fate,
                mass,
                ids,
            });
        }
        if let Some(d) = &self.share {
            gone = split::all_gone(d, &gone);
        }
        gone.sort_unstable_by_key(|g| g.first);
        (mine, gone)
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
        let tagged = self.share.as_ref().map_or(tagged, |d| d.comm.any(tagged));
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
