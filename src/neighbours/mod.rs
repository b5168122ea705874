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
mod tests {
    use super::*;

    /// The face lists rely on it: every cell lists its boxes in ascending order, however
    /// they were added.
    #[test]
    fn a_cell_lists_its_boxes_in_ascending_order() {
        let boxes: Vec<(DVec3, DVec3)> = (0..50)
            .map(|k| {
                let lo = DVec3::new((k * 37 % 11) as f64, (k * 13 % 7) as f64, 0.0) * 0.1;
                (lo, lo + DVec3::splat(0.05 + (k % 5) as f64 * 0.2))
            })
            .rev()
            .collect();
        let grid = CellGrid::of_boxes(&boxes, 0.1);
        let mut seen = 0;
        for x in 0..20 {
            for y in 0..20 {
                let items = grid.at(DVec3::new(
                    x as f64 * 0.1 + 0.05,
                    y as f64 * 0.1 + 0.05,
                    0.01,
                ));
                assert!(items.windows(2).all(|w| w[0] < w[1]), "{items:?}");
                seen += items.len();
            }
        }
        assert!(seen > 100, "{seen}");
    }

    /// Particles at `x` with radii `radius` (ids in that order).
    fn particles(x: &[DVec3], radius: &[f64]) -> Particles {
        x.iter()
            .zip(radius)
            .map(|(&x, &radius)| crate::model::particles::Particle {
                x,
                radius,
                ..Default::default()
            })
            .collect()
    }

    /// The listed particle pairs by id, (lower, higher), sorted; and a check that every
    /// owner's partners follow it, in order, within the next slab.
    fn listed(nb: &Neighbours, p: &Particles) -> Vec<(Id, Id)> {
        let list = &nb.pairs;
        let mut pairs = Vec::new();
        let slabs = &nb.pairs.blocks;
        for s in 0..slabs.len() - 1 {
            let limit = slabs.get(s + 2).copied().unwrap_or(slabs[slabs.len() - 1]);
            for i in slabs[s] as usize..slabs[s + 1] as usize {
                let run = &list.partner[list.run(i)];
                assert!(run.windows(2).all(|w| w[0] < w[1]), "{run:?}");
                for &j in run {
                    assert!(j as usize > i && j < limit, "{i} {j} slabs {slabs:?}");
                    let (a, b) = (p.id[i], p.id[j as usize]);
                    pairs.push((a.min(b), a.max(b)));
                }
            }
        }
        pairs.sort_unstable();
        pairs
    }

    /// Brute-force pairs within reach, as (i, j) with i < j.
    fn brute(x: &[DVec3], radius: &[f64], skin: f64) -> Vec<(Id, Id)> {
        let mut v = Vec::new();
        for i in 0..x.len() {
            for j in i + 1..x.len() {
                if x[i].distance(x[j]) < radius[i] + radius[j] + skin {
                    v.push((i as Id, j as Id));
                }
            }
        }
        v
    }

    #[test]
    fn polydisperse_lists_match_brute_force() {
        // 600 small particles and 6 ten times larger among them.
        let mut s = 11u64;
        let mut rnd = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let x: Vec<DVec3> = (0..606)
            .map(|_| DVec3::new(rnd(), rnd(), rnd()) * 0.15)
            .collect();
        let radius: Vec<f64> = (0..606)
            .map(|i| if i % 101 == 0 { 0.02 } else { 0.002 })
            .collect();
        let mut nb = Neighbours::new(0.001);
        let mut p = particles(&x, &radius);
        nb.rebuild(&mut p, &[], &FaceGrid::default());
        assert_eq!(listed(&nb, &p), brute(&x, &radius, 0.001));
    }

    #[test]
    fn lists_every_pair_within_reach_once_in_spatial_order() {
        // A small lattice with jitter; compare with brute force.
        let mut x = Vec::new();
        let mut s = 7u64;
        let mut rnd = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..400 {
            x.push(DVec3::new(rnd(), rnd(), rnd()) * 0.2 - 0.1);
        }
        let radius: Vec<f64> = (0..x.len())
            .map(|i| 0.005 + 0.001 * (i % 3) as f64)
            .collect();
        let mut nb = Neighbours::new(0.002);
        let mut p = particles(&x, &radius);
        nb.rebuild(&mut p, &[], &FaceGrid::default());
        assert_eq!(listed(&nb, &p), brute(&x, &radius, 0.002));
        // The particles are stored in the order of their cells, each one unchanged.
        let h = 2.0 * 0.007 + 0.002;
        let keys: Vec<u64> = p.x.iter().map(|&x| key(cell_of(x, 1.0 / h))).collect();
        assert!(keys.is_sorted());
        for k in 0..p.len() {
            assert_eq!(p.x[k], x[p.id[k] as usize]);
        }
        assert!(nb.pairs.blocks.len() > 3, "{:?}", nb.pairs.blocks);
    }

    /// A checkpoint's springs naming a particle it lacks are refused with the id; a split
    /// run's history leaves out the springs of particles another process holds.
    #[test]
    fn histories_by_id_name_or_skip_the_particles_absent() {
        let x = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
        let p = particles(&x, &[0.1; 3]);
        let s = |u_t: f64| {
            let springs = crate::model::springs::Springs {
                u_t,
                ..Default::default()
            };
            ContactState {
                springs,
                ..ContactState::default()
            }
        };
        let entries = [(0, 2, s(1.0)), (1, 7, s(2.0)), (2, 1, s(3.0))];
        let err = History::in_storage(&p, &entries, true).unwrap_err();
        assert!(err.contains("id 7"), "{err}");
        let index = IdIndex::of(&p);
        let h = History::of_present(&index, p.len(), &entries, true);
        assert_eq!(
            h.entries(),
            vec![(0, 2, s(1.0)), (1, 2, s(3.0))],
            "the pair with 7 left out, the others keyed low to high"
        );
    }

    #[test]
    fn an_index_of_few_of_many_ids_is_a_sorted_list_that_finds_what_a_table_finds() {
        let x = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let mut p = particles(&x, &[0.1; 4]);
        (p.id, p.next_id) = (vec![900_000, 5, 12_345, 17], 1_000_000);
        let sorted = IdIndex::of(&p);
        assert!(
            matches!(sorted, IdIndex::Sorted(_)),
            "4 of 10^6 ids: no table"
        );
        p.next_id = 900_001;
        let index = IdIndex::of(&p);
        let table = match &index {
            IdIndex::Sorted(list) => {
                let mut t = vec![NONE; 900_001];
                list.iter().for_each(|&(id, k)| t[id as usize] = k);
                IdIndex::Table(t)
            }
            IdIndex::Table(_) => unreachable!("4 of 900,001 ids"),
        };
        for id in [0, 5, 17, 18, 12_345, 899_999, 900_000, 900_001, u64::MAX] {
            assert_eq!(sorted.get(id), table.get(id), "id {id}");
        }
        assert_eq!(sorted.get(12_345), Some(2));
        (p.id, p.next_id) = (vec![0, 1, 2, 3], 4);
        assert!(
            matches!(IdIndex::of(&p), IdIndex::Table(_)),
            "all ids: a table"
        );
    }

    #[test]
    fn springs_follow_their_pairs_through_a_re_sort() {
        let x = vec![
            DVec3::new(0.5, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.009, 0.0, 0.0),
            DVec3::new(0.509, 0.0, 0.0),
        ];
        let radius = vec![0.005; 4];
        let mut p = particles(&x, &radius);
        let mut nb = Neighbours::new(0.002);
        nb.rebuild(&mut p, &[], &FaceGrid::default());
        assert_eq!(listed(&nb, &p), vec![(0, 3), (1, 2)]);
        // Give each pair springs that name it, then move the pairs past each other.
        let list = &mut nb.pairs;
        for i in 0..p.len() {
            let block = list.blocks.partition_point(|&b| b as usize <= i) - 1;
            for k in list.start[i] as usize..list.start[i + 1] as usize {
                let id = p.id[i].min(p.id[list.partner[k] as usize]);
                let e = list.stores[block].open();
                list.stores[block].state.springs[e as usize].u_t = id as f64 + 1.0;
                list.contact[k] = e;
            }
        }
        for x in &mut p.x {
            x.x = 1.0 - x.x;
        }
        nb.rebuild(&mut p, &[], &FaceGrid::default());
        assert_eq!(p.id, vec![3, 0, 2, 1]);
        let (mut pairs, _) = nb.entries_by_id(&p.id);
        pairs.sort_unstable_by_key(|e| (e.0, e.1));
        assert_eq!(
            pairs
                .iter()
                .map(|e| (e.0, e.1, e.2.springs.u_t))
                .collect::<Vec<_>>(),
            vec![(0, 3, 1.0), (1, 2, 2.0)]
        );
    }

    /// The storage index of the particle with id `id`.
    fn at(p: &Particles, id: Id) -> usize {
        p.id.iter().position(|&i| i == id).expect("present")
    }

    #[test]
    fn a_lonely_particle_may_move_half_its_clearance() {
        // A particle 0.5 m from a small cluster falls towards it in 1 mm steps.
        let radius = vec![0.01; 4];
        let x = vec![
            DVec3::new(0.0, 0.0, 0.5),
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.02, 0.0, 0.0),
            DVec3::new(-0.02, 0.0, 0.0),
        ];
        let skin = 0.005;
        let mut nb = Neighbours::new(skin);
        let mut p = particles(&x, &radius);
        nb.rebuild(&mut p, &[], &FaceGrid::default());
        assert_eq!(nb.lonely.len(), 1, "{:?}", nb.lonely);
        let mut rebuilds = 0;
        while p.x[at(&p, 0)].z > 0.015 {
            let k = at(&p, 0);
            p.x[k].z -= 0.001;
            if nb.stale(&p.x, &p.radius, &[], 0.0) {
                nb.rebuild(&mut p, &[], &FaceGrid::default());
                rebuilds += 1;
            }
            // Whatever touches is listed.
            let (a, b) = (at(&p, 0), at(&p, 1));
            if p.x[a].distance(p.x[b]) < 0.02 {
                assert!(
                    listed(&nb, &p).contains(&(0, 1)),
                    "contact missed at z = {}",
                    p.x[a].z
                );
            }
        }
        // Skin / 2 alone would rebuild every 3 steps (160 times).
        assert!(rebuilds < 20, "{rebuilds} rebuilds");
        // An ordinary particle still triggers a rebuild after skin / 2.
        let mut nb = Neighbours::new(skin);
        nb.rebuild(&mut p, &[], &FaceGrid::default());
        let k = at(&p, 2);
        p.x[k].x += 0.6 * skin;
        assert!(nb.stale(&p.x, &p.radius, &[], 0.0));
    }

    #[test]
    fn lonely_clearances_are_skipped_while_listed_grains_set_the_pace() {
        let radius = vec![0.01; 3];
        let x = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0199, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 0.5),
        ];
        let skin = 0.005;
        let mut nb = Neighbours::new(skin);
        let mut p = particles(&x, &radius);
        nb.rebuild(&mut p, &[], &FaceGrid::default());
        assert_eq!(nb.lonely.len(), 1, "the grain far from the pair");
        // The touching pair moves on together past skin / 2: a rebuild no allowance puts off.
        for id in [0, 1] {
            let k = at(&p, id);
            p.x[k].y += 0.6 * skin;
        }
        assert!(nb.stale(&p.x, &p.radius, &[], 0.0));
        nb.rebuild(&mut p, &[], &FaceGrid::default());
        assert!(
            nb.lonely.is_empty(),
            "no clearances while listed grains set the pace"
        );
        // The lone grain alone moves past skin / 2: an allowance would have put that off.
        let k = at(&p, 2);
        p.x[k].z -= 0.6 * skin;
        assert!(nb.stale(&p.x, &p.radius, &[], 0.0));
        nb.rebuild(&mut p, &[], &FaceGrid::default());
        assert_eq!(nb.lonely.len(), 1, "found again");
        // And then it does: the grain moves on within its allowance, no rebuild.
        let k = at(&p, 2);
        p.x[k].z -= 0.6 * skin;
        assert!(!nb.stale(&p.x, &p.radius, &[], 0.0));
    }

    #[test]
    fn two_lonely_particles_meeting_head_on_are_listed_before_they_touch() {
        let radius = vec![0.01; 2];
        let x = vec![DVec3::new(-0.5, 0.0, 0.0), DVec3::new(0.5, 0.0, 0.0)];
        let mut nb = Neighbours::new(0.005);
        let mut p = particles(&x, &radius);
        nb.rebuild(&mut p, &[], &FaceGrid::default());
        assert_eq!(nb.lonely.len(), 2);
        let mut rebuilds = 0;
        for _ in 0..600 {
            let (a, b) = (at(&p, 0), at(&p, 1));
            p.x[a].x += 0.001;
            p.x[b].x -= 0.0013;
            if nb.stale(&p.x, &p.radius, &[], 0.0) {
                nb.rebuild(&mut p, &[], &FaceGrid::default());
                rebuilds += 1;
            }
            let (a, b) = (at(&p, 0), at(&p, 1));
            if p.x[a].distance(p.x[b]) < 0.02 {
                assert_eq!(listed(&nb, &p), vec![(0, 1)], "contact missed at {:?}", p.x);
            }
        }
        let (a, b) = (at(&p, 0), at(&p, 1));
        assert!(
            p.x[a].x > p.x[b].x,
            "they passed through each other's place"
        );
        assert!(rebuilds < 150, "{rebuilds} rebuilds");
    }

    /// The image a wrapped pair is seen with is the one `image_shifts` finds, and the same
    /// whichever particle is the one listed: its shift depends on the two points alone.
    #[test]
    fn the_image_towards_a_point_is_the_nearest_one_found() {
        let sheared = Periodic {
            min: DVec3::splat(-0.05),
            length: DVec3::new(0.1, 0.08, 0.1),
            axes: [true, true, true],
            shear: Some(Shear {
                velocity: 0.3,
                axis: 0,
                gradient: 2,
                offset: 0.1234,
            }),
        };
        let plain = Periodic {
            shear: None,
            ..sheared
        };
        let mut shifts = Vec::new();
        for periodic in [plain, sheared] {
            let mut checked = 0;
            for k in 0..4000u64 {
                let h = |m: u64| {
                    let z = (k * 8 + m).wrapping_mul(0x9E37_79B9_7F4A_7C15);
                    ((z ^ (z >> 29)).wrapping_mul(0xBF58_476D_1CE4_E5B9) >> 40) as f64
                        / (1u64 << 24) as f64
                };
                let x = periodic.min + DVec3::new(h(1), h(2), h(3)) * periodic.length;
                let to = periodic.min + DVec3::new(h(4), h(5), h(6)) * periodic.length;
                let reach = 0.02;
                periodic.image_shifts(x, reach, &mut shifts);
                for &(s, n) in &shifts {
                    if (x + s).distance(to) < reach {
                        let (e, m) = periodic.image_towards(x, to);
                        assert!((e - s).length() < 1e-12 && m == n, "{x} {to}: {e} {s}");
                        checked += 1;
                    }
                }
            }
            assert!(checked > 20, "{checked} pairs across the sides");
        }
    }
}
