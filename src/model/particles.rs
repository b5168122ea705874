//! Particle storage (paper Table 3), struct-of-arrays.
//!
//! A particle's identity is its id, given at creation (0, 1, 2, ... in creation order) and
//! never reused; frames, checkpoints and messages speak in ids and list particles in id
//! order. The storage index of a particle is where its state lives now, which the
//! simulation may change (it keeps particles in spatial order).

use glam::{DQuat, DVec3};

use crate::model::bodies::{Bodies, Body, BodyId};
use crate::model::fields::{Value, particle_fields};

pub use crate::model::id::{Id, MAX_ID};

// The per-particle fields, declared once (the machinery: `model/fields.rs`). A row: its doc
// (meaning and unit) and `name: type`; a core field then says whether ghosts receive it each
// step and from which checkpoint format on the record holds it; an optional field (held
// only when a run asks for it) whether ghosts receive it and its unit.
particle_fields! {
    core {
        /// x \[L\]
        x: DVec3, ghost: true, checkpoint: Some(2);
        /// R \[L\]
        radius: f64, ghost: false, checkpoint: Some(2);
        /// v [L/T]
        v: DVec3, ghost: true, checkpoint: Some(2);
        /// Orientation q̂, mapping body to world coordinates.
        q: DQuat, ghost: true, checkpoint: Some(2);
        /// ω [1/T], world frame.
        w: DVec3, ghost: true, checkpoint: Some(2);
        /// A label per particle (0 by default), set by `[[tags]]` regions, e.g. to dye grains by
        /// the path they took.
        tag: u32, ghost: true, checkpoint: Some(2);
        /// The index of each particle's material in `[[materials]]` (0: the first, or the one
        /// `[material]`).
        material: u16, ghost: false, checkpoint: Some(3);
        /// Whether each particle is fixed: held in place and at rest, whatever acts on it
        /// (`[[fixed]]` boxes, the `fixed` column, Python's `freeze`).
        fixed: bool, ghost: false, checkpoint: Some(5);
        /// The rigid body (clump) each particle is a sphere of, if any: its state is the
        /// body's, which `bodies` holds (and checkpoints hold apart).
        body: Option<BodyId>, ghost: false, checkpoint: None::<u32>;
    }
    optional {
        /// T \[K\], the temperature (held when heat is transferred: a material conducts,
        /// makes or exchanges heat).
        temperature: f64, ghost: true, unit: "K", name: "T";
        /// The heat content m c T in quanta of the run's heat model (`model/heat.rs`):
        /// what heat transfer keeps exactly; the temperature follows from it.
        heat: i128, ghost: false, unit: "J";
        #[cfg(test)]
        /// A number the tests carry through messages, checkpoints and frames.
        probe: f64, ghost: true, unit: "-";
    }
}

fn gather<T: Copy + Send + Sync>(v: &mut Vec<T>, order: &[u32]) {
    use rayon::prelude::*;
    *v = order
        .par_iter()
        .with_min_len(1024)
        .map(|&i| v[i as usize])
        .collect();
}

impl Particles {
    pub fn len(&self) -> usize {
        self.x.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Adds a particle with the next id.
    pub fn push(&mut self, p: Particle) {
        self.insert(self.next_id, p);
        self.next_id += 1;
    }

    /// Adds a rigid body with its spheres (of `radii`, in the order of its offsets; the
    /// rest of their state from `sphere`), which take the next ids (the first of them the
    /// body's id) and the body's motion.
    pub fn push_body(&mut self, mut body: Body, radii: &[f64], sphere: Particle) {
        body.id = BodyId::new(self.next_id);
        let first = self.len();
        for (k, &radius) in radii.iter().enumerate() {
            let (x, v) = body.sphere_state(k);
            self.push(Particle {
                x,
                radius,
                v,
                q: body.q,
                w: body.w,
                body: Some(body.id),
                ..sphere
            });
        }
        self.bodies.push(body, first);
    }

    /// Finds every body's spheres in storage again ([`Bodies::locate`]).
    pub fn locate_bodies(&mut self) {
        self.bodies.locate(&self.id, &self.body);
    }

    /// The indices in `bodies.list` of the bodies whose first sphere `pick` takes (by its
    /// storage index): e.g. the bodies a process of a split run owns.
    pub fn bodies_where<'a>(
        &'a self,
        pick: impl Fn(usize) -> bool + 'a,
    ) -> impl Iterator<Item = usize> + 'a {
        let bodies = &self.bodies;
        (0..bodies.len()).filter(move |&b| pick(bodies.members(b)[0] as usize))
    }

    /// The particles in storage order.
    pub fn iter(&self) -> impl Iterator<Item = Particle> + '_ {
        (0..self.len()).map(|i| self.get(i))
    }

    /// Puts the particle stored at `order[k]` at index `k`, for every `k`.
    pub fn permute(&mut self, order: &[u32]) {
        self.gather_fields(order);
        if !self.bodies.is_empty() {
            self.bodies.locate(&self.id, &self.body);
        }
    }

    /// The storage indices in id order.
    pub fn id_order(&self) -> Vec<usize> {
        let mut order: Vec<usize> = (0..self.len()).collect();
        if !self.id.is_sorted() {
            order.sort_unstable_by_key(|&i| self.id[i]);
        }
        order
    }

    /// The particles in id order, with their ids.
    pub fn iter_by_id(&self) -> impl Iterator<Item = (Id, Particle)> + '_ {
        self.id_order()
            .into_iter()
            .map(|i| (self.id[i], self.get(i)))
    }

    /// Whether any particle carries a tag.
    pub fn tagged(&self) -> bool {
        self.tag.iter().any(|&t| t != 0)
    }

    /// Largest radius present, or 0.
    pub fn max_radius(&self) -> f64 {
        self.radius.iter().copied().fold(0.0, f64::max)
    }
}

impl FromIterator<Particle> for Particles {
    fn from_iter<I: IntoIterator<Item = Particle>>(iter: I) -> Self {
        let mut p = Particles::default();
        for x in iter {
            p.push(x);
        }
        p
    }
}
