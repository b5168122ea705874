//! Particle storage (paper Table 3), struct-of-arrays.
//!
//! A particle's identity is its id, given at creation (0, 1, 2, ... in creation order) and
//! never reused; frames, checkpoints and messages speak in ids and list particles in id
//! order. The storage index of a particle is where its state lives now, which the
//! simulation may change (it keeps particles in spatial order).

use glam::{DQuat, DVec3};

use crate::model::bodies::{Bodies, Body, BodyId};
use crate::model::value::Value;

pub use crate::model::id::{Id, MAX_ID};

/// The per-particle fields, declared once: from this table follow the storage
/// ([`Particles`], a vector per field), the one-particle record ([`Particle`]), `insert`,
/// `get` and `permute`, the records of the split run's messages (every field), the state
/// sent to ghosts each step (the fields marked `ghost`) and the checkpoint record (the
/// fields with a `checkpoint` format, from that format on, in the table's order).
///
/// A row: its doc (meaning and unit), `name: type`, then `ghost: bool` and
/// `checkpoint: Option<format>`. The type is a [`Value`] (its bytes); its `Default` is the
/// value of a particle that does not say (and of a checkpoint older than the field).
macro_rules! particle_fields {
    ($(
        $(#[doc = $doc:literal])*
        $name:ident: $ty:ty, ghost: $ghost:literal, checkpoint: $since:expr;
    )*) => {
        /// The state of every particle.
        #[derive(Clone, Debug, Default, PartialEq)]
        pub struct Particles {
            /// The id of the particle stored at each index.
            pub id: Vec<Id>,
            /// The id the next particle created gets.
            pub next_id: Id,
            $($(#[doc = $doc])* pub $name: Vec<$ty>,)*
            /// The rigid bodies (clumps) of several particles.
            pub bodies: Bodies,
        }

        /// One particle's state: a row of [`Particles`].
        #[derive(Clone, Copy, Debug, Default, PartialEq)]
        pub struct Particle {
            $($(#[doc = $doc])* pub $name: $ty,)*
        }

        impl Particles {
            /// Adds a particle that has its id already (one made elsewhere: by another
            /// process of a split run); `next_id` stays.
            pub fn insert(&mut self, id: Id, p: Particle) {
                self.id.push(id);
                $(self.$name.push(p.$name);)*
            }

            /// The particle stored at `i`.
            pub fn get(&self, i: usize) -> Particle {
                Particle { $($name: self.$name[i],)* }
            }

            /// Puts the fields of the particle stored at `order[k]` at index `k`.
            fn gather_fields(&mut self, order: &[u32]) {
                gather(&mut self.id, order);
                $(gather(&mut self.$name, order);)*
            }

            /// The bytes of the state sent to a particle's ghosts each step.
            pub const GHOST_STATE: usize = 0 $(+ if $ghost { <$ty as Value>::SIZE } else { 0 })*;

            /// Appends the state sent to the ghosts of the particle stored at `i`.
            pub fn put_ghost_state(&self, i: usize, out: &mut Vec<u8>) {
                $(if $ghost { self.$name[i].put(out); })*
            }

            /// Sets the ghost stored at `i` to the state `bytes` begin with.
            pub fn take_ghost_state(&mut self, i: usize, bytes: &mut &[u8]) {
                $(if $ghost { self.$name[i] = Value::take(bytes); })*
            }
        }

        impl Particle {
            /// The bytes of a particle in a message.
            pub const SIZE: usize = 0 $(+ <$ty as Value>::SIZE)*;

            /// Appends the particle's bytes in a message: every field.
            pub fn put(&self, out: &mut Vec<u8>) {
                $(self.$name.put(out);)*
            }

            /// The particle whose message `bytes` begin with.
            pub fn take(bytes: &mut &[u8]) -> Particle {
                Particle { $($name: Value::take(bytes),)* }
            }

            /// The bytes of a particle's record in a checkpoint of format `version`.
            pub fn checkpoint_size(version: u32) -> usize {
                0 $(+ match $since { Some(since) if version >= since => <$ty as Value>::SIZE, _ => 0 })*
            }

            /// Appends the particle's record in a checkpoint of the newest format.
            pub fn put_checkpoint(&self, out: &mut Vec<u8>) {
                $(if $since.is_some() { self.$name.put(out); })*
            }

            /// The particle whose record in a checkpoint of format `version` `bytes` begin
            /// with (fields newer than the format at their defaults).
            pub fn take_checkpoint(bytes: &mut &[u8], version: u32) -> Particle {
                let mut p = Particle::default();
                $(if matches!($since, Some(since) if version >= since) {
                    p.$name = Value::take(bytes);
                })*
                p
            }
        }
    };
}

particle_fields! {
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
