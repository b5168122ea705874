//! Rigid bodies made of several particles (clumps, issue 28).
//!
//! A clump's spheres are particles like any other for the neighbour lists and the contact
//! law; what makes them one body is the table here: each body's state (x, v, q̂, ω of its
//! centre of mass), mass, principal moments and the places of its spheres in its frame.
//! A body's spheres have consecutive ids, the first of which is the body's id: sphere k
//! of body b is particle b + k. Each particle names its body (`Particles::body`).

use std::num::NonZeroU64;

use glam::{DQuat, DVec3};

use crate::model::id::Id;

/// The body a particle is a sphere of: the id of the body's first sphere.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BodyId(NonZeroU64);

impl BodyId {
    /// The body whose first sphere is particle `first`.
    pub fn new(first: Id) -> BodyId {
        BodyId(NonZeroU64::new(first.wrapping_add(1)).expect("ids below u64::MAX"))
    }

    /// The id of its first sphere (the body's id in frames).
    pub fn first(self) -> Id {
        self.0.get() - 1
    }
}

/// One rigid body: a clump of spheres.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    pub id: BodyId,
    /// Its template's index in `[[clumps]]`.
    pub template: u16,
    /// The factor its template's lengths were scaled by.
    pub scale: f64,
    /// Centre of mass \[L\], its velocity [L/T], orientation (body to world), angular
    /// velocity (world frame) [1/T].
    pub x: DVec3,
    pub v: DVec3,
    pub q: DQuat,
    pub w: DVec3,
    /// Mass \[M\] and principal moments of inertia \[M L²\].
    pub mass: f64,
    pub inertia: DVec3,
    /// The centres of its spheres in its frame, in id order \[L\].
    pub offsets: Vec<DVec3>,
    /// The radius about the centre of mass of the sphere that holds every sphere \[L\].
    pub bounding_radius: f64,
}

impl Body {
    /// Where sphere `k` is, and its velocity, for the body's state.
    pub fn sphere_state(&self, k: usize) -> (DVec3, DVec3) {
        let r = self.q * self.offsets[k];
        (self.x + r, self.v + self.w.cross(r))
    }

    /// The kinetic energy of translation and of rotation \[J\].
    pub fn kinetic_energy(&self) -> (f64, f64) {
        let l = self.inertia * (self.q.inverse() * self.w);
        (
            0.5 * self.mass * self.v.length_squared(),
            crate::model::rigid::energy(l, self.inertia),
        )
    }
}

/// The bodies of a simulation, ascending by id, with the storage index of each sphere.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bodies {
    pub list: Vec<Body>,
    /// Where body b's spheres are stored: `members[start[b]..start[b + 1]]`, in id order.
    start: Vec<u32>,
    members: Vec<u32>,
    /// The mass of the body of the sphere stored at each index (for the contact law,
    /// without a search), 0 for a plain sphere; up to the last sphere of a body.
    mass_at: Vec<f64>,
}

impl Bodies {
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// The index in `list` of body `id`.
    pub fn index_of(&self, id: BodyId) -> Option<usize> {
        self.list.binary_search_by_key(&id, |b| b.id).ok()
    }

    /// The mass of the body whose sphere is stored at `k` (which must be a body's sphere).
    #[inline(always)]
    pub fn mass_at(&self, k: usize) -> f64 {
        self.mass_at[k]
    }

    /// The mass of body `id` (which must exist).
    pub fn mass_of(&self, id: BodyId) -> f64 {
        self.list[self.index_of(id).expect("a listed body")].mass
    }

    /// The storage indices of body b's spheres (b an index in `list`), in id order.
    pub fn members(&self, b: usize) -> &[u32] {
        Members {
            start: &self.start,
            members: &self.members,
        }
        .of(b)
    }

    /// The bodies to change, and where each one's spheres are stored.
    pub fn parts_mut(&mut self) -> (&mut [Body], Members<'_>) {
        let members = Members {
            start: &self.start,
            members: &self.members,
        };
        (&mut self.list, members)
    }

    /// Finds every body's spheres in storage (ids `id`, bodies `body`), after particles
    /// were added, removed or reordered; bodies none of whose spheres remain are dropped.
    /// Panics if a body lost only some of its spheres (a body is removed whole).
    pub fn locate(&mut self, id: &[Id], body: &[Option<BodyId>]) {
        let mut found: Vec<Vec<u32>> = self
            .list
            .iter()
            .map(|b| vec![u32::MAX; b.offsets.len()])
            .collect();
        for (k, (&id, b)) in id.iter().zip(body).enumerate() {
            if let Some(b) = *b {
                let at = self.index_of(b).expect("a particle's body is listed");
                found[at][(id - b.first()) as usize] = k as u32;
            }
        }
        let mut keep = found.iter().map(|f| f[0] != u32::MAX);
        self.list.retain(|_| keep.next().expect("one per body"));
        self.start = vec![0];
        self.members.clear();
        self.mass_at.clear();
        self.mass_at.resize(id.len(), 0.0);
        for (f, body) in found
            .into_iter()
            .filter(|f| f[0] != u32::MAX)
            .zip(&self.list)
        {
            assert!(
                f.iter().all(|&k| k != u32::MAX),
                "a body lost some of its spheres"
            );
            for &k in &f {
                self.mass_at[k as usize] = body.mass;
            }
            self.members.extend(f);
            self.start.push(self.members.len() as u32);
        }
        if self.list.is_empty() {
            // As a table that never held a body.
            self.start.clear();
            self.mass_at.clear();
        }
    }

    /// Adds `body` in id order (one that came from elsewhere: another process of a split
    /// run); its spheres are found by the next [`Bodies::locate`], which must come before
    /// anything else reads the table.
    pub fn insert(&mut self, body: Body) {
        let at = self.list.partition_point(|b| b.id < body.id);
        assert!(
            self.list.get(at).is_none_or(|b| b.id != body.id),
            "a body once"
        );
        self.list.insert(at, body);
    }

    /// Adds `body`, whose spheres are stored at `first..` in order, after every other.
    pub fn push(&mut self, body: Body, first: usize) {
        assert!(
            self.list.last().is_none_or(|b| b.id < body.id),
            "bodies in id order"
        );
        if self.start.is_empty() {
            self.start.push(0);
        }
        let n = body.offsets.len();
        self.members.extend((first..first + n).map(|k| k as u32));
        self.start.push(self.members.len() as u32);
        self.mass_at.resize(first, 0.0);
        self.mass_at.resize(first + n, body.mass);
        self.list.push(body);
    }
}

/// Where the spheres of each body are stored ([`Bodies::parts_mut`]).
#[derive(Clone, Copy)]
pub struct Members<'a> {
    start: &'a [u32],
    members: &'a [u32],
}

impl<'a> Members<'a> {
    /// The storage indices of body b's spheres, in id order.
    pub fn of(&self, b: usize) -> &'a [u32] {
        &self.members[self.start[b] as usize..self.start[b + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body(first: Id, n: usize) -> Body {
        Body {
            id: BodyId::new(first),
            template: 0,
            scale: 1.0,
            x: DVec3::ZERO,
            v: DVec3::ZERO,
            q: DQuat::IDENTITY,
            w: DVec3::ZERO,
            mass: 1.0,
            inertia: DVec3::ONE,
            offsets: vec![DVec3::ZERO; n],
            bounding_radius: 1.0,
        }
    }

    #[test]
    fn spheres_are_found_after_reordering_and_removal() {
        let mut bodies = Bodies::default();
        bodies.push(body(1, 2), 1);
        bodies.push(body(3, 3), 3);
        assert_eq!(bodies.members(1), &[3, 4, 5]);
        // Stored as ids 5, 3, 0, 2, 1, 4; then body 1 removed.
        let ids = [5, 3, 0, 2, 1, 4];
        let of = |id: Id| match id {
            1 | 2 => Some(BodyId::new(1)),
            3..=5 => Some(BodyId::new(3)),
            _ => None,
        };
        let body: Vec<_> = ids.iter().map(|&i| of(i)).collect();
        bodies.locate(&ids, &body);
        assert_eq!(bodies.members(0), &[4, 3]);
        assert_eq!(bodies.members(1), &[1, 5, 0]);
        let ids = [5, 3, 0, 4];
        let body: Vec<_> = ids.iter().map(|&i| of(i)).collect();
        bodies.locate(&ids, &body);
        assert_eq!(bodies.len(), 1);
        assert_eq!(bodies.list[0].id.first(), 3);
        assert_eq!(bodies.members(0), &[1, 3, 0]);
        assert_eq!(bodies.mass_of(BodyId::new(3)), 1.0);
    }
}
