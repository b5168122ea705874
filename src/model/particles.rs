//! Particle storage (paper Table 3), struct-of-arrays.
//!
//! A particle's identity is its id, given at creation (0, 1, 2, ... in creation order) and
//! never reused; frames, checkpoints and messages speak in ids and list particles in id
//! order. The storage index of a particle is where its state lives now, which the
//! simulation may change (it keeps particles in spatial order).

use glam::{DQuat, DVec3};

use crate::model::bodies::{Bodies, Body, BodyId};

pub use crate::model::id::{Id, MAX_ID};

/// The state of every particle.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Particles {
    /// The id of the particle stored at each index.
    pub id: Vec<Id>,
    /// The id the next particle created gets.
    pub next_id: Id,
    /// R \[L\]
    pub radius: Vec<f64>,
    /// x \[L\]
    pub x: Vec<DVec3>,
    /// v [L/T]
    pub v: Vec<DVec3>,
    /// Orientation q̂, mapping body to world coordinates.
    pub q: Vec<DQuat>,
    /// ω [1/T], world frame.
    pub w: Vec<DVec3>,
    /// A label per particle (0 by default), set by `[[tags]]` regions, e.g. to dye grains by
    /// the path they took.
    pub tag: Vec<u32>,
    /// The index of each particle's material in `[[materials]]` (0: the first, or the one
    /// `[material]`).
    pub material: Vec<u16>,
    /// Whether each particle is fixed: held in place and at rest, whatever acts on it
    /// (`[[fixed]]` boxes, the `fixed` column, Python's `freeze`).
    pub fixed: Vec<bool>,
    /// The rigid body (clump) each particle is a sphere of, if any: its state is the
    /// body's, which `bodies` holds.
    pub body: Vec<Option<BodyId>>,
    /// The rigid bodies (clumps) of several particles.
    pub bodies: Bodies,
}

/// One particle's state, as read from and written to CSV.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Particle {
    pub x: DVec3,
    pub radius: f64,
    pub v: DVec3,
    pub q: DQuat,
    pub w: DVec3,
    pub tag: u32,
    pub material: u16,
    pub fixed: bool,
    pub body: Option<BodyId>,
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

    /// Adds a particle that has its id already (one made elsewhere: by another process of a
    /// split run); `next_id` stays.
    pub fn insert(&mut self, id: Id, p: Particle) {
        self.id.push(id);
        self.radius.push(p.radius);
        self.x.push(p.x);
        self.v.push(p.v);
        self.q.push(p.q);
        self.w.push(p.w);
        self.tag.push(p.tag);
        self.material.push(p.material);
        self.fixed.push(p.fixed);
        self.body.push(p.body);
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

    pub fn get(&self, i: usize) -> Particle {
        Particle {
            x: self.x[i],
            radius: self.radius[i],
            v: self.v[i],
            q: self.q[i],
            w: self.w[i],
            tag: self.tag[i],
            material: self.material[i],
            fixed: self.fixed[i],
            body: self.body[i],
        }
    }

    /// The particles in storage order.
    pub fn iter(&self) -> impl Iterator<Item = Particle> + '_ {
        (0..self.len()).map(|i| self.get(i))
    }

    /// Puts the particle stored at `order[k]` at index `k`, for every `k`.
    pub fn permute(&mut self, order: &[u32]) {
        use rayon::prelude::*;
        fn gather<T: Copy + Send + Sync>(v: &mut Vec<T>, order: &[u32]) {
            *v = order
                .par_iter()
                .with_min_len(1024)
                .map(|&i| v[i as usize])
                .collect();
        }
        gather(&mut self.id, order);
        gather(&mut self.radius, order);
        gather(&mut self.x, order);
        gather(&mut self.v, order);
        gather(&mut self.q, order);
        gather(&mut self.w, order);
        gather(&mut self.tag, order);
        gather(&mut self.material, order);
        gather(&mut self.fixed, order);
        gather(&mut self.body, order);
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
