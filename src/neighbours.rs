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
use rustc_hash::FxHashMap;

use crate::contact::Springs;
use crate::mesh::Face;

/// Below this many items a parallel loop runs on one thread (spawn overhead dominates).
pub const MIN_PARALLEL_LEN: usize = 64;

const CELL_BIAS: i32 = 1 << 20;

/// The 13 neighbours of a cell that come after it (z, then y, then x): with the cell itself,
/// every pair of neighbouring cells once.
const FORWARD: [IVec3; 13] = {
    let mut d = [IVec3::ZERO; 13];
    let mut k = 0;
    let mut dz = -1;
    while dz <= 1 {
        let mut dy = -1;
        while dy <= 1 {
            let mut dx = -1;
            while dx <= 1 {
                if dz > 0 || (dz == 0 && (dy > 0 || (dy == 0 && dx > 0))) {
                    d[k] = IVec3::new(dx, dy, dz);
                    k += 1;
                }
                dx += 1;
            }
            dy += 1;
        }
        dz += 1;
    }
    d
};

/// Integer cell of a position; clamped so that far-flung particles share the outermost
/// cells (still correct, as pairs are always tested by distance).
#[inline]
pub fn cell_of(x: DVec3, inv_h: f64) -> IVec3 {
    let c = (x * inv_h).floor();
    let lim = (CELL_BIAS - 2) as f64;
    IVec3::new(
        c.x.clamp(-lim, lim) as i32,
        c.y.clamp(-lim, lim) as i32,
        c.z.clamp(-lim, lim) as i32,
    )
}

#[inline]
pub fn key(c: IVec3) -> u64 {
    let b = |v: i32| (v + CELL_BIAS) as u64;
    (b(c.x) << 42) | (b(c.y) << 21) | b(c.z)
}

/// A hashed grid of cubic cells: for each occupied cell, the items in it.
#[derive(Clone, Debug, Default)]
pub struct CellGrid {
    inv_h: f64,
    /// Item indices grouped by cell.
    items: Vec<u32>,
    /// Cell key -> range in `items`.
    cells: FxHashMap<u64, (u32, u32)>,
    /// Occupied cells in key order: cell coordinates and range in `items`.
    occupied: Vec<(IVec3, u32, u32)>,
}

impl CellGrid {
    /// Bins points into cells of edge `h`.
    pub fn of_points(x: &[DVec3], h: f64) -> CellGrid {
        let inv_h = 1.0 / h;
        let mut keyed: Vec<(u64, u32)> = x
            .par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .enumerate()
            .map(|(i, &x)| (key(cell_of(x, inv_h)), i as u32))
            .collect();
        keyed.par_sort_unstable();
        CellGrid::from_sorted(keyed, inv_h, |i| Some(cell_of(x[i as usize], inv_h)))
    }

    /// The grid of `(cell key, item)` pairs sorted by key; `cell` gives an item's cell
    /// coordinates where the list of occupied cells is wanted.
    fn from_sorted(
        keyed: Vec<(u64, u32)>,
        inv_h: f64,
        cell: impl Fn(u32) -> Option<IVec3>,
    ) -> CellGrid {
        let mut cells = FxHashMap::default();
        let mut occupied = Vec::new();
        let mut start = 0;
        for k in 1..=keyed.len() {
            if k == keyed.len() || keyed[k].0 != keyed[start].0 {
                cells.insert(keyed[start].0, (start as u32, k as u32));
                if let Some(c) = cell(keyed[start].1) {
                    occupied.push((c, start as u32, k as u32));
                }
                start = k;
            }
        }
        CellGrid {
            inv_h,
            items: keyed.into_iter().map(|(_, i)| i).collect(),
            cells,
            occupied,
        }
    }

    /// Bins boxes into every cell they overlap.
    pub fn of_boxes(boxes: &[(DVec3, DVec3)], h: f64) -> CellGrid {
        let inv_h = 1.0 / h;
        let mut keyed: Vec<(u64, u32)> = Vec::new();
        for (i, &(lo, hi)) in boxes.iter().enumerate() {
            let (a, b) = (cell_of(lo, inv_h), cell_of(hi, inv_h));
            for z in a.z..=b.z {
                for y in a.y..=b.y {
                    for x in a.x..=b.x {
                        keyed.push((key(IVec3::new(x, y, z)), i as u32));
                    }
                }
            }
        }
        keyed.sort_unstable();
        CellGrid::from_sorted(keyed, inv_h, |_| None)
    }

    /// Items in the cell containing `x`.
    #[inline]
    pub fn at(&self, x: DVec3) -> &[u32] {
        self.in_cell(cell_of(x, self.inv_h))
    }

    #[inline]
    fn in_cell(&self, c: IVec3) -> &[u32] {
        match self.cells.get(&key(c)) {
            Some(&(a, b)) => &self.items[a as usize..b as usize],
            None => &[],
        }
    }

    /// Calls `f` for every item in the 27 cells around `x`.
    #[inline]
    pub fn for_each_near(&self, x: DVec3, mut f: impl FnMut(u32)) {
        let c = cell_of(x, self.inv_h);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    for &j in self.in_cell(c + IVec3::new(dx, dy, dz)) {
                        f(j);
                    }
                }
            }
        }
    }
}

/// A compressed list: for each owner `i`, a sorted run of partners, each with springs.
#[derive(Clone, Debug, Default)]
pub struct ContactList {
    /// Run of owner `i` is `start[i]..start[i+1]`.
    pub start: Vec<u32>,
    /// Owner of each slot.
    pub owner: Vec<u32>,
    /// Partner of each slot (particle `j > i`, or face index).
    pub partner: Vec<u32>,
    /// Friction springs of each slot.
    pub springs: Vec<Springs>,
    /// Whether the slot's springs (and its force, kept by the simulation) may be non-zero:
    /// its pair touched at the last force evaluation, or had springs when listed. A pair
    /// apart has both zeroed once, and is not looked at again while it stays apart.
    pub touched: Vec<bool>,
}

impl ContactList {
    pub fn slots(&self) -> usize {
        self.partner.len()
    }

    /// Every slot with non-zero springs: the contact history.
    pub fn history(&self) -> Vec<(u32, u32, Springs)> {
        (0..self.slots())
            .filter(|&k| self.springs[k] != Springs::default())
            .map(|k| (self.owner[k], self.partner[k], self.springs[k]))
            .collect()
    }

    /// Puts back a contact history saved by [`ContactList::history`]; every pair in it must
    /// be listed (it was touching when saved).
    pub fn restore(&mut self, history: &[(u32, u32, Springs)]) -> Result<(), String> {
        for &(i, j, springs) in history {
            let run = self.run(i as usize);
            match run.binary_search(&j) {
                Ok(k) => {
                    let slot = self.start[i as usize] as usize + k;
                    self.springs[slot] = springs;
                    self.touched[slot] = true;
                }
                Err(_) => return Err(format!("contact ({i}, {j}) is not within reach")),
            }
        }
        Ok(())
    }

    fn run(&self, i: usize) -> &[u32] {
        if i + 1 >= self.start.len() {
            return &[];
        }
        &self.partner[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Only the slots with non-zero springs (the touching pairs), in a compact list; the rest
    /// of the memory is freed. Used to carry the contact history across a rebuild.
    fn touching(self) -> ContactList {
        let n = self.start.len().saturating_sub(1);
        let mut start = Vec::with_capacity(n + 1);
        let mut partner = Vec::new();
        let mut springs = Vec::new();
        start.push(0u32);
        for i in 0..n {
            for k in self.start[i] as usize..self.start[i + 1] as usize {
                if self.springs[k] != Springs::default() {
                    partner.push(self.partner[k]);
                    springs.push(self.springs[k]);
                }
            }
            start.push(partner.len() as u32);
        }
        ContactList {
            start,
            owner: Vec::new(),
            partner,
            springs,
            touched: Vec::new(),
        }
    }

    /// A new list from per-owner partner runs (`start`, `partner` in compressed form, each
    /// run sorted), carrying over the springs of pairs that were listed before.
    fn rebuild(&self, start: Vec<u32>, partner: Vec<u32>) -> ContactList {
        let mut owner = Vec::with_capacity(partner.len());
        for (i, w) in start.windows(2).enumerate() {
            owner.extend(std::iter::repeat_n(i as u32, (w[1] - w[0]) as usize));
        }
        let springs: Vec<Springs> = owner
            .par_iter()
            .zip(partner.par_iter())
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|(&i, &j)| {
                let old = self.run(i as usize);
                match old.binary_search(&j) {
                    Ok(k) => self.springs[self.start[i as usize] as usize + k],
                    Err(_) => Springs::default(),
                }
            })
            .collect();
        let touched = springs
            .par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|s| *s != Springs::default())
            .collect();
        ContactList {
            start,
            owner,
            partner,
            springs,
            touched,
        }
    }
}

/// Compressed form of `(owner, partner)` pairs: a counting sort by owner that keeps the
/// order of each owner's partners.
fn compress(n: usize, pairs: impl Iterator<Item = (u32, u32)> + Clone) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; n + 1];
    for (i, _) in pairs.clone() {
        start[i as usize + 1] += 1;
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let mut fill = start.clone();
    let mut partner = vec![0u32; start[n] as usize];
    for (i, j) in pairs {
        partner[fill[i as usize] as usize] = j;
        fill[i as usize] += 1;
    }
    (start, partner)
}

/// Verlet lists of particle pairs and particle-face pairs.
#[derive(Clone, Debug, Default)]
pub struct Neighbours {
    /// Extra distance listed beyond contact.
    pub skin: f64,
    /// Particle pairs i < j.
    pub pairs: ContactList,
    /// For each particle j, the pair slots in which it is the partner (sorted).
    pub reverse_start: Vec<u32>,
    pub reverse_slot: Vec<u32>,
    /// Particle-face pairs.
    pub faces: ContactList,
    /// Positions at the last rebuild.
    x_at_build: Vec<DVec3>,
    /// Particles with nothing within reach at the last rebuild, each with how far it may
    /// move before the lists can miss a contact (half its clearance, at least skin / 2).
    lonely: Vec<(u32, f64)>,
    /// Number of rebuilds so far.
    pub rebuilds: u64,
}

impl Neighbours {
    pub fn new(skin: f64) -> Self {
        Neighbours {
            skin,
            ..Default::default()
        }
    }

    /// Whether the lists must be rebuilt: the particle count changed, or some particle moved
    /// more than half the skin, less `mesh_drift` (how far a moving face has moved), since
    /// the last rebuild.
    ///
    /// A lonely particle past its allowance that is still lonely is re-anchored where it
    /// is instead (see [`Neighbours::reanchor`]), which costs one pass over the particles
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
            return true;
        }
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
        let listed = |i: usize| {
            self.pairs.start[i] != self.pairs.start[i + 1]
                || self.reverse_start[i] != self.reverse_start[i + 1]
                || self.faces.start[i] != self.faces.start[i + 1]
        };
        let candidates: Vec<usize> = (0..n).filter(|&i| !listed(i)).collect();
        const BUDGET: usize = 4_000_000;
        if candidates.is_empty() || candidates.len() * (n + faces.len()) > BUDGET {
            self.lonely = Vec::new();
            return;
        }
        self.lonely = candidates
            .par_iter()
            .map(|&i| {
                let (xi, ri) = (x[i], radius[i]);
                let mut clearance = f64::INFINITY;
                for j in (0..n).filter(|&j| j != i) {
                    clearance = clearance.min(xi.distance(x[j]) - ri - radius[j]);
                }
                let clearance = clearance.min(clearance_to_faces(xi, ri, faces));
                (i as u32, (0.5 * clearance).max(0.5 * self.skin))
            })
            .collect();
    }

    /// Rebuilds both lists for particles at `x` with radii `radius`.
    ///
    /// Cells are sized for the largest radius, or for the 90th percentile of the radii when
    /// the largest is more than twice that, so that a few large particles do not make every
    /// cell hold many small ones. Each pair is found by its larger particle (ties: the lower
    /// index), which searches as many cells as its own reach needs.
    pub fn rebuild(&mut self, x: &[DVec3], radius: &[f64], faces: &[Face], face_grid: &CellGrid) {
        let n = x.len();
        // Keep only the history of touching pairs while the new lists are built.
        let old_pairs = std::mem::take(&mut self.pairs).touching();
        let old_faces = std::mem::take(&mut self.faces).touching();
        let skin = self.skin;
        let max_r = radius.iter().copied().fold(0.0, f64::max);
        let typical_r = if n > 0 {
            let mut r = radius.to_vec();
            let k = (9 * n / 10).min(n - 1);
            *r.select_nth_unstable_by(k, f64::total_cmp).1
        } else {
            0.0
        };
        // Sized for the largest particle unless it is far larger than most (then every
        // cell would hold many small particles).
        let cell_r = if max_r <= 2.0 * typical_r {
            max_r
        } else {
            typical_r
        };
        let h = 2.0 * cell_r + skin;
        let h = if h > 0.0 { h } else { 1.0 };
        let grid = CellGrid::of_points(x, h);
        let uniform = cell_r == max_r;
        // With cells for ordinary sizes (not `uniform`): whether i finds its pair with j (the
        // larger radius, ties: the lower index), and how many cells around its own it must
        // search (its partners are no larger, so within 2 R_i + skin).
        let finds = |i: u32, j: u32| {
            let (ri, rj) = (radius[i as usize], radius[j as usize]);
            rj < ri || (rj == ri && j > i)
        };
        let cells_needed = |i: u32| ((2.0 * radius[i as usize] + skin) / h).ceil().max(1.0) as i32;
        let close = |i: u32, j: u32| {
            let reach = radius[i as usize] + radius[j as usize] + skin;
            (x[i as usize] - x[j as usize]).length_squared() < reach * reach
        };
        let key = |i: u32, j: u32| ((i.min(j) as u64) << 32) | i.max(j) as u64;

        // The pairs found, in one list per piece of the parallel loop over occupied cells.
        let per_cell: Vec<Vec<u64>> = if uniform {
            // Cells sized for every pair: each pair of cells is visited once (a cell and
            // the 13 of its neighbours that come after it), so each pair of particles is
            // tested once; the pairs are sorted afterwards.
            grid.occupied
                .par_iter()
                .with_min_len(MIN_PARALLEL_LEN / 16)
                .fold(Vec::new, |mut pairs, &(c, a, b)| {
                    let own = &grid.items[a as usize..b as usize];
                    for (k, &i) in own.iter().enumerate() {
                        for &j in &own[k + 1..] {
                            if close(i, j) {
                                pairs.push(key(i, j));
                            }
                        }
                    }
                    for d in FORWARD {
                        let other = grid.in_cell(c + d);
                        for &i in own {
                            for &j in other {
                                if close(i, j) {
                                    pairs.push(key(i, j));
                                }
                            }
                        }
                    }
                    pairs
                })
                .collect()
        } else {
            // Cells for ordinary sizes: the 27 neighbour ranges are looked up once for the
            // cell's particles of ordinary size; larger particles search their own wider
            // block, and find only partners no larger than themselves.
            grid.occupied
                .par_iter()
                .with_min_len(MIN_PARALLEL_LEN / 16)
                .fold(Vec::new, |mut pairs, &(c, a, b)| {
                    let mut near: [&[u32]; 27] = [&[]; 27];
                    let mut k = 0;
                    for dz in -1..=1 {
                        for dy in -1..=1 {
                            for dx in -1..=1 {
                                near[k] = grid.in_cell(c + IVec3::new(dx, dy, dz));
                                k += 1;
                            }
                        }
                    }
                    for &i in &grid.items[a as usize..b as usize] {
                        let m = cells_needed(i);
                        if m == 1 {
                            for &j in near.iter().flat_map(|r| r.iter()) {
                                if finds(i, j) & close(i, j) {
                                    pairs.push(key(i, j));
                                }
                            }
                        } else {
                            for dz in -m..=m {
                                for dy in -m..=m {
                                    for dx in -m..=m {
                                        for &j in grid.in_cell(c + IVec3::new(dx, dy, dz)) {
                                            if finds(i, j) & close(i, j) {
                                                pairs.push(key(i, j));
                                            }
                                        }
                                    }
                                }
                            }
                        }
                    }
                    pairs
                })
                .collect()
        };
        let mut pairs: Vec<u64> = per_cell.into_iter().flatten().collect();
        // Pairs of one owner came from several cells: bring them together in order.
        pairs.par_sort_unstable();
        let (start, partner) = compress(n, pairs.iter().map(|&k| ((k >> 32) as u32, k as u32)));
        self.pairs = old_pairs.rebuild(start, partner);

        // Reverse index by counting sort over partners (keeps slots in ascending order).
        let mut count = vec![0u32; n + 1];
        for &j in &self.pairs.partner {
            count[j as usize + 1] += 1;
        }
        for k in 0..n {
            count[k + 1] += count[k];
        }
        let mut fill = count.clone();
        let mut slots = vec![0u32; self.pairs.slots()];
        for (slot, &j) in self.pairs.partner.iter().enumerate() {
            slots[fill[j as usize] as usize] = slot as u32;
            fill[j as usize] += 1;
        }
        self.reverse_start = count;
        self.reverse_slot = slots;

        // The items of a grid cell come in ascending order, so each particle's run of faces
        // is sorted (as `ContactList` needs).
        let face_pairs: Vec<(u32, u32)> = (0..n)
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN / 8)
            .flat_map_iter(|i| {
                let (xi, ri) = (x[i], radius[i]);
                face_grid.at(xi).iter().copied().filter_map(move |f| {
                    let face = &faces[f as usize];
                    let reach = ri + face.radius + skin;
                    let near = face.separation(xi).length_squared() < reach * reach;
                    near.then_some((i as u32, f))
                })
            })
            .collect();
        let (start, partner) = compress(n, face_pairs.iter().copied());
        self.faces = old_faces.rebuild(start, partner);

        self.find_lonely(x, radius, faces);
        self.x_at_build = x.to_vec();
        self.rebuilds += 1;
    }
}

/// The smallest gap between a particle at `x` of radius `r` and the faces (brute force).
fn clearance_to_faces(x: DVec3, r: f64, faces: &[Face]) -> f64 {
    faces
        .iter()
        .map(|face| face.separation(x).length() - r - face.radius)
        .fold(f64::INFINITY, f64::min)
}

/// The grid of mesh faces for particles up to radius `max_radius`: each face is binned into
/// every cell its bounding box, grown by `max_radius + skin`, overlaps, so the cell of a
/// particle's centre lists every face it can reach before the next rebuild.
pub fn face_grid(faces: &[Face], max_radius: f64, skin: f64) -> CellGrid {
    let grow = DVec3::splat(max_radius + skin);
    let boxes: Vec<(DVec3, DVec3)> = faces
        .iter()
        .map(|f| {
            let (lo, hi) = f.bounding_box();
            (lo - grow, hi + grow)
        })
        .collect();
    let h = (2.0 * max_radius + skin).max(f64::MIN_POSITIVE);
    CellGrid::of_boxes(&boxes, h)
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

    /// The listed particle pairs, as (owner, partner).
    fn listed(nb: &Neighbours) -> Vec<(u32, u32)> {
        let p = &nb.pairs;
        p.owner
            .iter()
            .copied()
            .zip(p.partner.iter().copied())
            .collect()
    }

    /// Brute-force pairs within reach, as (i, j) with i < j.
    fn brute(x: &[DVec3], radius: &[f64], skin: f64) -> Vec<(u32, u32)> {
        let mut v = Vec::new();
        for i in 0..x.len() {
            for j in i + 1..x.len() {
                if x[i].distance(x[j]) < radius[i] + radius[j] + skin {
                    v.push((i as u32, j as u32));
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
        nb.rebuild(&x, &radius, &[], &CellGrid::default());
        assert_eq!(listed(&nb), brute(&x, &radius, 0.001));
    }

    #[test]
    fn lists_every_pair_within_reach_once() {
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
        nb.rebuild(&x, &radius, &[], &CellGrid::default());
        let brute = brute(&x, &radius, 0.002);
        assert_eq!(listed(&nb), brute);
        // The reverse index names every slot once, under its partner.
        for j in 0..x.len() {
            for &slot in
                &nb.reverse_slot[nb.reverse_start[j] as usize..nb.reverse_start[j + 1] as usize]
            {
                assert_eq!(nb.pairs.partner[slot as usize] as usize, j);
            }
        }
        assert_eq!(nb.reverse_slot.len(), brute.len());
    }

    #[test]
    fn a_lonely_particle_may_move_half_its_clearance() {
        // A particle 0.5 m from a small cluster falls towards it in 1 mm steps.
        let radius = vec![0.01; 4];
        let mut x = vec![
            DVec3::new(0.0, 0.0, 0.5),
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.02, 0.0, 0.0),
            DVec3::new(-0.02, 0.0, 0.0),
        ];
        let skin = 0.005;
        let mut nb = Neighbours::new(skin);
        nb.rebuild(&x, &radius, &[], &CellGrid::default());
        assert_eq!(nb.lonely.len(), 1, "{:?}", nb.lonely);
        let mut rebuilds = 0;
        while x[0].z > 0.015 {
            x[0].z -= 0.001;
            if nb.stale(&x, &radius, &[], 0.0) {
                nb.rebuild(&x, &radius, &[], &CellGrid::default());
                rebuilds += 1;
            }
            // Whatever touches is listed.
            if x[0].distance(x[1]) < 0.02 {
                assert_eq!(
                    &nb.pairs.partner[..1],
                    &[1],
                    "contact missed at z = {}",
                    x[0].z
                );
            }
        }
        // Skin / 2 alone would rebuild every 3 steps (160 times).
        assert!(rebuilds < 20, "{rebuilds} rebuilds");
        // An ordinary particle still triggers a rebuild after skin / 2.
        let mut nb = Neighbours::new(skin);
        nb.rebuild(&x, &radius, &[], &CellGrid::default());
        x[2].x += 0.6 * skin;
        assert!(nb.stale(&x, &radius, &[], 0.0));
    }

    #[test]
    fn two_lonely_particles_meeting_head_on_are_listed_before_they_touch() {
        let radius = vec![0.01; 2];
        let mut x = vec![DVec3::new(-0.5, 0.0, 0.0), DVec3::new(0.5, 0.0, 0.0)];
        let mut nb = Neighbours::new(0.005);
        nb.rebuild(&x, &radius, &[], &CellGrid::default());
        assert_eq!(nb.lonely.len(), 2);
        let mut rebuilds = 0;
        for _ in 0..600 {
            x[0].x += 0.001;
            x[1].x -= 0.0013;
            if nb.stale(&x, &radius, &[], 0.0) {
                nb.rebuild(&x, &radius, &[], &CellGrid::default());
                rebuilds += 1;
            }
            if x[0].distance(x[1]) < 0.02 {
                assert_eq!(nb.pairs.partner, vec![1], "contact missed at {:?}", x);
            }
        }
        assert!(x[0].x > x[1].x, "they passed through each other's place");
        assert!(rebuilds < 150, "{rebuilds} rebuilds");
    }
}
