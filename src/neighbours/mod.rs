//! Neighbour search (paper Section 3.3) with Verlet lists.
//!
//! Particles are binned into cubic cells of edge `h >= 2 R_max + skin` (a hashed grid, so
//! memory does not grow with the spread of the particles), and every pair closer than
//! `R_i + R_j + skin` is listed once (i < j) in a compressed list. The list stays valid
//! until some particle has moved more than `skin / 2`, so it is rebuilt only every few
//! steps; contacts are still decided exactly (δ > 0) at every step, so results are the same
//! as with a fresh linked-cell search each step.
//!
//! Faces of the static mesh are binned once into a grid of the same kind; each particle
//! lists the faces within `R_i + R_j + skin`.
//!
//! Each listed pair carries the friction springs of its contact (Table 3), which are kept
//! across rebuilds and zeroed while the pair is not touching.

use glam::{DVec3, IVec3};
use rayon::prelude::*;

use crate::geometry::mesh::Face;
use crate::model::contact_state::{ActiveState, ContactState, States};
use crate::model::particles::{Id, Particles};

mod build;
mod grid;
mod history;
mod lists;
mod periodic;
pub use grid::*;
pub use history::*;
pub use lists::*;
pub use periodic::*;

/// Below this many items a parallel loop runs on one thread (spawn overhead dominates).
pub const MIN_PARALLEL_LEN: usize = 64;

/// How particles are binned for the lists: cells of edge `h`, and whether they are sized
/// for the largest radius (`uniform`: then every pair is within neighbouring cells).
#[derive(Clone, Copy, Debug)]
struct Layout {
    h: f64,
    uniform: bool,
}

impl Layout {
    /// Cells sized for the largest radius, or for the 90th percentile of the radii when the
    /// largest is more than twice that, so that a few large particles do not make every
    /// cell hold many small ones.
    fn of(radius: &[f64], skin: f64) -> Layout {
        let n = radius.len();
        let max_r = radius.iter().copied().fold(0.0, f64::max);
        let typical_r = if n > 0 {
            let mut r = radius.to_vec();
            let k = (9 * n / 10).min(n - 1);
            *r.select_nth_unstable_by(k, f64::total_cmp).1
        } else {
            0.0
        };
        let cell_r = if max_r <= 2.0 * typical_r {
            max_r
        } else {
            typical_r
        };
        let h = 2.0 * cell_r + skin;
        Layout {
            h: if h > 0.0 { h } else { 1.0 },
            uniform: cell_r == max_r,
        }
    }
}

impl Layout {
    /// Each particle's (cell key, id) for particles at `x` of ids `id`: the order the
    /// lists keep them in.
    fn keys(&self, x: &[DVec3], id: &[Id]) -> Vec<(u64, Id)> {
        let inv_h = 1.0 / self.h;
        x.par_iter()
            .zip(id.par_iter())
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|(&x, &id)| (key(cell_of(x, inv_h)), id))
            .collect()
    }
}

/// Verlet lists of particle pairs and particle-face pairs.
#[derive(Clone, Debug, Default)]
pub struct Neighbours {
    /// Extra distance listed beyond contact.
    pub skin: f64,
    /// Particle pairs i < j (storage indices).
    pub pairs: ContactList,
    /// Particle-face pairs.
    pub faces: ContactList,
    /// Particle pairs that touch across a periodic boundary: the particle of the higher id
    /// seen at its image, `x + shift[slot]`.
    pub wrapped: ContactList,
    pub shift: Vec<DVec3>,
    /// For each slot of `wrapped`, how often the partner's image crosses the gradient axis
    /// of a sheared domain (its shift then grows by that times V (t - t_build)).
    pub crossings: Vec<i8>,
    /// The shear offset V t at the last rebuild.
    pub offset_at_build: f64,
    /// The periodic axes of the domain, if any.
    pub periodic: Option<Periodic>,
    /// Positions at the last rebuild (the anchors of the Verlet criterion).
    x_at_build: Vec<DVec3>,
    /// Particles with nothing within reach at the last rebuild, each with how far it may
    /// move before the lists can miss a contact (half its clearance, at least skin / 2).
    lonely: Vec<(u32, f64)>,
    /// Whether the allowances put off a rebuild since the last one (a particle past skin / 2
    /// that did not make the lists stale).
    lonely_paid: bool,
    /// Whether the last rebuild came when it would have come without allowances: the next
    /// rebuild then finds no lonely particles (their clearances, by brute force, cost more
    /// than they save where grains in contact set the pace, as in the paper's hourglass).
    lonely_idle: bool,
    /// Number of rebuilds so far.
    pub rebuilds: u64,
    /// The optional members of a contact's state the stores hold.
    pub state: ActiveState,
}

/// The fewest owners in a slab (a task of the pair stage).
const MIN_SLAB: usize = 64;

/// The blocks of the pair list, slabs: owner bounds such that the partners of slab `s` lie
/// in slabs `s` and `s + 1` (slab `s + 2` starts beyond the last partner of slab `s`). So
/// the pair stage can run the even slabs at the same time, each adding forces to its own
/// particles and the next slab's, then the odd ones.
fn slabs_of(start: &[u32], partner: &[u32]) -> Vec<u32> {
    let n = start.len().saturating_sub(1);
    let reach = |i: usize| {
        let (a, b) = (start[i] as usize, start[i + 1] as usize);
        if a == b { i } else { partner[b - 1] as usize }
    };
    let mut bounds = vec![0u32];
    if n == 0 {
        return bounds;
    }
    // `need`: where the slab after next must start at the earliest.
    let (mut start, mut need) = (0usize, 0usize);
    let mut furthest = 0usize;
    for i in 0..n {
        furthest = furthest.max(reach(i));
        if i + 1 - start >= MIN_SLAB && i + 1 >= need && i + 1 < n {
            bounds.push((i + 1) as u32);
            need = furthest + 1;
            start = i + 1;
            furthest = 0;
        }
    }
    bounds.push(n as u32);
    bounds
}

impl Neighbours {
    pub fn new(skin: f64) -> Self {
        Neighbours {
            skin,
            ..Default::default()
        }
    }

    /// Where the particle of the higher id of slot `k` of `wrapped` is seen, relative to
    /// where it is: the shift of its image now, and the velocity the image adds.
    #[inline]
    pub fn image(&self, k: usize) -> (DVec3, DVec3) {
        let n = self.crossings[k] as f64;
        match self.periodic.and_then(|p| p.shear) {
            Some(sh) if n != 0.0 => {
                let mut drift = DVec3::ZERO;
                drift[sh.axis] = n * (sh.offset - self.offset_at_build);
                let mut dv = DVec3::ZERO;
                dv[sh.axis] = n * sh.velocity;
                (self.shift[k] + drift, dv)
            }
            _ => (self.shift[k], DVec3::ZERO),
        }
    }

    /// The pair of slot `k` of `wrapped`, listed under `a` with partner `b` (storage
    /// indices), as the law sees it: body i the particle of the lower id, body j the other,
    /// and where j's image is relative to j (shift, added velocity).
    #[inline]
    pub fn across(&self, ids: &[Id], a: usize, b: usize, k: usize) -> (usize, usize, DVec3, DVec3) {
        let (shift, dv) = self.image(k);
        if ids[a] < ids[b] {
            (a, b, shift, dv)
        } else {
            (b, a, shift, dv)
        }
    }

    /// How far the images across a sheared side have slid since the last rebuild.
    pub fn shear_drift(&self) -> f64 {
        self.periodic
            .and_then(|p| p.shear)
            .map_or(0.0, |sh| (sh.offset - self.offset_at_build).abs())
    }

    /// Lists for a domain with the periodic axes `periodic`.
    pub fn with_periodic(skin: f64, periodic: Option<Periodic>) -> Self {
        Neighbours {
            skin,
            periodic,
            ..Default::default()
        }
    }

    /// Whether the lists must be rebuilt: the particle count changed, or some particle moved
    /// more than half the skin, less `mesh_drift` (how far a moving face has moved), since
    /// the last rebuild.
    ///
    /// A lonely particle past its allowance that is still lonely is re-anchored where it
    /// is instead (see `Neighbours::reanchor`), which costs one pass over the particles
    /// rather than a rebuild.
    pub fn stale(&mut self, x: &[DVec3], radius: &[f64], faces: &[Face], mesh_drift: f64) -> bool {
        if x.len() != self.x_at_build.len() || mesh_drift >= 0.5 * self.skin {
            return true;
        }
        let limit = (0.5 * self.skin - mesh_drift).powi(2);
        let moved = |a: DVec3, b: DVec3| (a - b).length_squared();
        let any_far = x
            .par_iter()
            .zip(self.x_at_build.par_iter())
            .with_min_len(4 * MIN_PARALLEL_LEN)
            .any(|(a, b)| moved(*a, *b) > limit || !a.is_finite());
        if !any_far {
            return false;
        }
        if self.lonely.is_empty() {
            // Skipped: allowances would have put this rebuild off only if every particle
            // past skin / 2 has nothing listed. (None found otherwise: the next rebuild
            // looks again; a split run's lists never have them.)
            if self.lonely_idle {
                self.lonely_idle = !self.only_unlisted_beyond(x, limit);
            }
            return true;
        }
        let stale = self.stale_with_lonely(x, (radius, faces), (limit, mesh_drift));
        self.lonely_paid |= !stale;
        if stale {
            self.lonely_idle = !self.lonely_paid;
        }
        stale
    }

    /// [`Neighbours::stale`] once some particle moved more than skin / 2 (its square `limit`).
    fn stale_with_lonely(
        &mut self,
        x: &[DVec3],
        (radius, faces): (&[f64], &[Face]),
        (limit, mesh_drift): (f64, f64),
    ) -> bool {
        let moved = |a: DVec3, b: DVec3| (a - b).length_squared();
        // Some particle moved more than skin / 2: stale unless every such particle is a
        // lonely one within its own allowance, or one that can be re-anchored.
        let mut k = 0;
        for i in 0..x.len() {
            while k < self.lonely.len() && (self.lonely[k].0 as usize) < i {
                k += 1;
            }
            let d2 = moved(x[i], self.x_at_build[i]);
            if !x[i].is_finite() {
                return true;
            }
            match self.lonely.get(k).copied() {
                Some((j, allowance))
                    if j as usize == i
                        && d2 > (allowance - mesh_drift).powi(2)
                        && !self.reanchor(k, x, radius, faces, mesh_drift) =>
                {
                    return true;
                }
                Some((j, _)) if j as usize == i => {}
                _ if d2 > limit => return true,
                _ => {}
            }
        }
        false
    }

    /// Whether every particle that moved more than skin / 2 (its square `limit`) since the
    /// last rebuild has nothing listed: neither partners nor faces.
    fn only_unlisted_beyond(&self, x: &[DVec3], limit: f64) -> bool {
        let listed = self.listed(x.len());
        (0..x.len())
            .filter(|&i| (x[i] - self.x_at_build[i]).length_squared() > limit)
            .all(|i| !listed[i])
    }

    /// Whether each of `n` particles has something in the lists: a partner or a face.
    fn listed(&self, n: usize) -> Vec<bool> {
        let mut listed = vec![false; n];
        for &j in &self.pairs.partner {
            listed[j as usize] = true;
        }
        for (i, l) in listed.iter_mut().enumerate() {
            *l |= !self.pairs.run(i).is_empty() || !self.faces.run(i).is_empty();
        }
        listed
    }

    /// Re-anchors lonely particle `self.lonely[k]` at its current position if it is still
    /// at least a skin from where any other body can be before the next rebuild: particle
    /// j anywhere within its allowance a_j of its anchor, faces anywhere within skin / 2 of
    /// where they are. With c the smallest such gap, the particle may then move c / 2; no
    /// other particle's allowance relied on where it was. Returns false (a rebuild is
    /// needed) if it is not, or if the brute-force search would be too costly.
    fn reanchor(
        &mut self,
        k: usize,
        x: &[DVec3],
        radius: &[f64],
        faces: &[Face],
        mesh_drift: f64,
    ) -> bool {
        const BUDGET: usize = 200_000;
        if x.len() + faces.len() > BUDGET {
            return false;
        }
        let i = self.lonely[k].0 as usize;
        let (xi, ri) = (x[i], radius[i]);
        let half_skin = 0.5 * self.skin;
        let mut lonely = self.lonely.iter().peekable();
        let mut clearance = f64::INFINITY;
        for (j, (&anchor, &rj)) in self.x_at_build.iter().zip(radius).enumerate() {
            let allowance = match lonely.next_if(|&&(l, _)| l as usize == j) {
                Some(&(_, a)) => a,
                None => half_skin,
            };
            if j != i {
                clearance = clearance.min(xi.distance(anchor) - ri - rj - allowance);
            }
        }
        let clearance = clearance.min(clearance_to_faces(xi, ri, faces) - half_skin);
        if clearance < self.skin || mesh_drift > 0.0 {
            return false;
        }
        self.x_at_build[i] = xi;
        self.lonely[k].1 = 0.5 * clearance;
        true
    }

    /// The lonely particles of the new lists and their allowances: a particle with no
    /// listed partner is at least `skin` from every other body (its clearance c). Allowing
    /// it to move c / 2 keeps every unlisted pair apart: two lonely particles move at most
    /// (c_i + c_j) / 2 <= max(c_i, c_j), a lonely and an ordinary one c_i / 2 + skin / 2
    /// <= c_i. Clearances are found by brute force, so only while that stays cheap.
    fn find_lonely(&mut self, x: &[DVec3], radius: &[f64], faces: &[Face]) {
        let n = x.len();
        let listed = self.listed(n);
        let candidates: Vec<usize> = (0..n).filter(|&i| !listed[i]).collect();
        let r_max = radius.iter().copied().fold(0.0, f64::max);
        const BUDGET: usize = 4_000_000;
        self.lonely_paid = false;
        // Clearances by brute force do not see periodic images: no lonely particles then.
        if candidates.is_empty()
            || candidates.len() * (n + faces.len()) > BUDGET
            || self.periodic.is_some()
            || self.lonely_idle
        {
            self.lonely = Vec::new();
            return;
        }
        self.lonely = candidates
            .par_iter()
            .map(|&i| {
                let (xi, ri) = (x[i], radius[i]);
                // The nearest centre, without a root per pair; with the largest radius its
                // gap is a lower bound of the clearance, which is all the allowance needs.
                let nearest = nearest_squared(xi, &x[..i]).min(nearest_squared(xi, &x[i + 1..]));
                let clearance = nearest.sqrt() - ri - r_max;
                let clearance = clearance.min(clearance_to_faces(xi, ri, faces));
                (i as u32, (0.5 * clearance).max(0.5 * self.skin))
            })
            .collect();
    }

    /// Drops the lists (their memory), until the next rebuild.
    pub fn clear_lists(&mut self) {
        self.pairs = ContactList::default();
        self.faces = ContactList::default();
        self.wrapped = ContactList::default();
    }

    /// The contact histories of the current lists by id, unsorted: particle pairs as
    /// (lower id, higher id, springs), particle-face contacts as (id, face, springs).
    pub fn entries_by_id(&self, ids: &[Id]) -> Entries {
        let mut pairs = Vec::with_capacity(self.pairs.contacts() + self.wrapped.contacts());
        for list in [&self.pairs, &self.wrapped] {
            list.for_each_live(|i, k, s| {
                let (a, b) = (ids[i], ids[list.partner[k] as usize]);
                pairs.push((a.min(b), a.max(b), s));
            });
        }
        let mut faces = Vec::with_capacity(self.faces.contacts());
        self.faces
            .for_each_live(|i, k, s| faces.push((ids[i], self.faces.partner[k] as Id, s)));
        (pairs, faces)
    }

    /// The positions the lists were built at and the lonely particles' allowances: with
    /// the storage order, all a checkpoint needs to restore the very same lists.
    pub fn anchors(&self) -> (&[DVec3], &[(u32, f64)]) {
        (&self.x_at_build, &self.lonely)
    }
}

/// The smallest gap between a particle at `x` of radius `r` and the faces (brute force).
/// The smallest squared distance from `a` to the points `x` (∞ for none), in four
/// independent lanes so that the loop vectorises.
fn nearest_squared(a: DVec3, x: &[DVec3]) -> f64 {
    let mut m = [f64::INFINITY; 4];
    let chunks = x.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        for l in 0..4 {
            m[l] = m[l].min(a.distance_squared(c[l]));
        }
    }
    for p in rest {
        m[0] = m[0].min(a.distance_squared(*p));
    }
    m[0].min(m[1]).min(m[2].min(m[3]))
}

fn clearance_to_faces(x: DVec3, r: f64, faces: &[Face]) -> f64 {
    faces
        .iter()
        .map(|face| face.separation(x).length() - r - face.radius)
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests;
