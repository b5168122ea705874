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

use crate::geometry::mesh::Face;
use crate::model::particles::Particles;
use crate::model::springs::Springs;

/// Below this many items a parallel loop runs on one thread (spawn overhead dominates).
pub const MIN_PARALLEL_LEN: usize = 64;

const CELL_BIAS: i32 = 1 << 20;

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

/// The cell of a key (the inverse of [`key`]).
fn unkey(k: u64) -> IVec3 {
    let c = |shift: u32| ((k >> shift) & ((1 << 21) - 1)) as i32 - CELL_BIAS;
    IVec3::new(c(42), c(21), c(0))
}

/// The 13 neighbours of a cell whose keys come after its own, in key order (x, then y, then
/// z): with the cell itself, every pair of neighbouring cells once.
const FORWARD: [IVec3; 13] = {
    let mut d = [IVec3::ZERO; 13];
    let mut k = 0;
    let mut dx = 0;
    while dx <= 1 {
        let mut dy = -1;
        while dy <= 1 {
            let mut dz = -1;
            while dz <= 1 {
                if dx > 0 || (dx == 0 && (dy > 0 || (dy == 0 && dz > 0))) {
                    d[k] = IVec3::new(dx, dy, dz);
                    k += 1;
                }
                dz += 1;
            }
            dy += 1;
        }
        dx += 1;
    }
    d
};

/// A hashed grid of cubic cells: for each occupied cell, the items in it.
#[derive(Clone, Debug, Default)]
pub struct CellGrid {
    inv_h: f64,
    /// Item indices grouped by cell.
    items: Vec<u32>,
    /// Cell key -> range in `items`.
    cells: FxHashMap<u64, (u32, u32)>,
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
        CellGrid::from_sorted(keyed, inv_h)
    }

    /// The grid of `(cell key, item)` pairs sorted by key.
    fn from_sorted(keyed: Vec<(u64, u32)>, inv_h: f64) -> CellGrid {
        let mut cells = FxHashMap::default();
        let mut start = 0;
        for k in 1..=keyed.len() {
            if k == keyed.len() || keyed[k].0 != keyed[start].0 {
                cells.insert(keyed[start].0, (start as u32, k as u32));
                start = k;
            }
        }
        CellGrid {
            inv_h,
            items: keyed.into_iter().map(|(_, i)| i).collect(),
            cells,
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
        CellGrid::from_sorted(keyed, inv_h)
    }

    /// The occupied cells with the range of items in each, in key order.
    fn occupied(&self) -> Vec<(IVec3, u32, u32)> {
        let mut cells: Vec<(u64, u32, u32)> =
            self.cells.iter().map(|(&k, &(a, b))| (k, a, b)).collect();
        cells.sort_unstable();
        cells
            .into_iter()
            .map(|(k, a, b)| (unkey(k), a, b))
            .collect()
    }

    /// The range of items in cell `c` (empty if none).
    #[inline]
    fn range(&self, c: IVec3) -> std::ops::Range<u32> {
        match self.cells.get(&key(c)) {
            Some(&(a, b)) => a..b,
            None => 0..0,
        }
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

/// A slot without a contact.
pub const NONE: u32 = u32::MAX;

/// Periodic axes of the domain: space repeats with period `length` along each `axes[a]`,
/// from `min`; with `shear`, the images across the gradient axis slide (Lees-Edwards).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Periodic {
    pub min: DVec3,
    pub length: DVec3,
    pub axes: [bool; 3],
    pub shear: Option<Shear>,
}

/// Lees-Edwards boundaries: the image of the box beyond the `gradient` axis's upper side is
/// shifted along the `axis` by `offset` = V t and moves with `velocity` V along it (the one
/// below by -V t, with -V), which imposes a simple shear of rate V / L_gradient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shear {
    pub velocity: f64,
    pub axis: usize,
    pub gradient: usize,
    /// The current offset V t (not reduced by the period).
    pub offset: f64,
}

impl Periodic {
    /// Puts `x` back into [min, min + length) along the periodic axes.
    #[inline]
    pub fn wrap(&self, x: DVec3) -> DVec3 {
        self.wrap_state(x, DVec3::ZERO).0
    }

    /// Puts a particle at `x` with velocity `v` back into the box: crossing the gradient axis
    /// of a sheared domain also shifts it along the shear axis by the offset and changes its
    /// velocity by the image's.
    #[inline]
    pub fn wrap_state(&self, x: DVec3, v: DVec3) -> (DVec3, DVec3) {
        let (mut x, mut v) = (x, v);
        if let Some(sh) = self.shear
            && x[sh.gradient].is_finite()
        {
            let (lo, l) = (self.min[sh.gradient], self.length[sh.gradient]);
            let crossings = ((x[sh.gradient] - lo) / l).floor();
            if crossings != 0.0 {
                x[sh.gradient] -= crossings * l;
                x[sh.axis] -= crossings * self.offset_in_period(sh);
                v[sh.axis] -= crossings * sh.velocity;
            }
        }
        let mut x = x.to_array();
        for (a, x) in x.iter_mut().enumerate() {
            if self.axes[a] && x.is_finite() {
                let (lo, l) = (self.min[a], self.length[a]);
                let mut w = lo + (*x - lo).rem_euclid(l);
                if w >= lo + l {
                    w = lo; // rem_euclid of a tiny negative number rounds up to l
                }
                *x = w;
            }
        }
        (DVec3::from_array(x), v)
    }

    /// The shear offset reduced to [0, L) of the shear axis.
    fn offset_in_period(&self, sh: Shear) -> f64 {
        sh.offset.rem_euclid(self.length[sh.axis])
    }

    /// The image of a point at `x` nearest to a point at `to` (both in the box): its shift
    /// and how often it crosses the gradient axis of a sheared box (-1, 0, 1). The shift
    /// depends on the two points alone (not on how the image was found), so the pair of a
    /// particle and the other's image is seen with the same bits wherever it is listed.
    pub(crate) fn image_towards(&self, x: DVec3, to: DVec3) -> (DVec3, i8) {
        let periods = |a: usize, d: f64| (d / self.length[a]).round();
        let mut e = DVec3::ZERO;
        let mut n = 0.0;
        let gradient = self.shear.map(|sh| sh.gradient);
        if let Some(sh) = self.shear {
            n = periods(sh.gradient, to[sh.gradient] - x[sh.gradient]);
            e[sh.gradient] = n * self.length[sh.gradient];
            e[sh.axis] = n * self.offset_in_period(sh);
        }
        for a in (0..3).filter(|&a| self.axes[a] && Some(a) != gradient) {
            e[a] += periods(a, to[a] - x[a] - e[a]) * self.length[a];
        }
        (e, n as i8)
    }

    /// The images of a point at `x` (in the box) that come within `reach` of the box: their
    /// shifts and how many times each crosses the gradient axis (-1, 0, 1; 0 without
    /// shear). For each periodic axis where the point (or an image of it) is within `reach`
    /// of a side, the period towards the other side, and their combinations (edges,
    /// corners); across the gradient axis of a sheared box, with the offset along the shear
    /// axis, brought back into the period.
    pub(crate) fn image_shifts(&self, x: DVec3, reach: f64, out: &mut Vec<(DVec3, i8)>) {
        out.clear();
        out.push((DVec3::ZERO, 0));
        let near = |p: DVec3, a: usize| -> f64 {
            if p[a] - self.min[a] < reach {
                self.length[a]
            } else if self.min[a] + self.length[a] - p[a] < reach {
                -self.length[a]
            } else {
                0.0
            }
        };
        if let Some(sh) = self.shear {
            let (g, s) = (sh.gradient, sh.axis);
            let step = near(x, g);
            if step != 0.0 {
                let n = step.signum();
                let mut e = DVec3::ZERO;
                e[g] = step;
                e[s] = n * self.offset_in_period(sh);
                let (lo, l) = (self.min[s], self.length[s]);
                if x[s] + e[s] >= lo + l {
                    e[s] -= l;
                } else if x[s] + e[s] < lo {
                    e[s] += l;
                }
                out.push((e, n as i8));
            }
        }
        for a in 0..3 {
            if !self.axes[a] || self.shear.is_some_and(|sh| sh.gradient == a) {
                continue;
            }
            for k in 0..out.len() {
                let (e0, n) = out[k];
                let step = near(x + e0, a);
                if step != 0.0 {
                    let mut e = e0;
                    e[a] += step;
                    out.push((e, n));
                }
            }
        }
        out.remove(0);
    }
}

/// The friction springs of the touching contacts of one piece of a list, and its free
/// entries. A contact stage runs a piece in one task, which opens and closes entries in the
/// piece's own store.
#[derive(Clone, Debug, Default)]
pub struct Store {
    pub springs: Vec<Springs>,
    free: Vec<u32>,
}

impl Store {
    /// A new entry, with zero springs.
    #[inline]
    pub fn open(&mut self) -> u32 {
        match self.free.pop() {
            Some(k) => {
                self.springs[k as usize] = Springs::default();
                k
            }
            None => {
                if self.springs.len() == self.springs.capacity() {
                    // A little room at a time: contacts come and go, the count changes slowly.
                    self.springs.reserve_exact(self.springs.len() / 8 + 8);
                }
                self.springs.push(Springs::default());
                (self.springs.len() - 1) as u32
            }
        }
    }

    /// Frees entry `k` (its springs are forgotten).
    #[inline]
    pub fn close(&mut self, k: u32) {
        self.free.push(k);
    }

    /// Entries in use.
    pub fn len(&self) -> usize {
        self.springs.len() - self.free.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A compressed list: for each owner `i` (a storage index), a run of partners; each slot
/// whose pair touches holds its contact, an entry of the store of the slot's piece (the
/// pieces are runs of owners). Springs are kept only for touching pairs, those of a
/// particle pair as seen from the particle of the lower id (body i of the contact law),
/// whatever the storage order.
#[derive(Clone, Debug, Default)]
pub struct ContactList {
    /// Run of owner `i` is `start[i]..start[i+1]`.
    pub start: Vec<u32>,
    /// Partner of each slot: a particle `j > i` (storage index), or a face index.
    pub partner: Vec<u32>,
    /// The contact of each slot: its entry in its piece's store, or [`NONE`]. A pair that
    /// parts closes its contact and is not looked at again while it stays apart.
    pub contact: Vec<u32>,
    /// Owner bounds of the pieces: piece `p` is owners `pieces[p]..pieces[p+1]`.
    pub pieces: Vec<u32>,
    /// One store per piece.
    pub stores: Vec<Store>,
}

impl ContactList {
    pub fn slots(&self) -> usize {
        self.partner.len()
    }

    /// The slots of owner `i`.
    #[inline]
    pub fn run(&self, i: usize) -> std::ops::Range<usize> {
        self.start[i] as usize..self.start[i + 1] as usize
    }

    /// Number of owners.
    pub fn owners(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    /// Number of contacts (touching pairs).
    pub fn contacts(&self) -> usize {
        self.stores.iter().map(Store::len).sum()
    }

    /// Calls `f` with owner, slot and springs of every slot with non-zero springs, in slot
    /// order.
    fn for_each_live(&self, mut f: impl FnMut(usize, usize, Springs)) {
        for p in 0..self.pieces.len().saturating_sub(1) {
            let store = &self.stores[p];
            for i in self.pieces[p] as usize..self.pieces[p + 1] as usize {
                for k in self.run(i) {
                    let c = self.contact[k];
                    if c != NONE {
                        let s = store.springs[c as usize];
                        if s != Springs::default() {
                            f(i, k, s);
                        }
                    }
                }
            }
        }
    }

    /// The contact history of the list: for each slot with springs, the key that
    /// `key(owner, partner)` gives it (first keys below `keys`; none: the contact is
    /// dropped) and its springs.
    fn history(
        &self,
        keys: usize,
        key: impl Fn(usize, u32) -> Option<(u32, u32)> + Sync,
    ) -> History {
        Self::history_of(&[self], keys, key)
    }

    /// The contact history of several lists of the same kind (particle pairs, within the
    /// box and across periodic sides), as [`ContactList::history`].
    fn history_of(
        lists: &[&ContactList],
        keys: usize,
        key: impl Fn(usize, u32) -> Option<(u32, u32)> + Sync,
    ) -> History {
        History::from_visits(keys, |f| {
            for list in lists {
                list.for_each_live(|i, k, s| {
                    if let Some((a, other)) = key(i, list.partner[k]) {
                        f(a, other, s);
                    }
                });
            }
        })
    }

    /// A list from runs in compressed form cut into pieces at `pieces` (owner bounds), each
    /// slot with the springs `history` holds for (owner, partner), found by merging each
    /// run with the owner's history run (both ascending).
    fn with_springs(
        start: Vec<u32>,
        partner: Vec<u32>,
        pieces: Vec<u32>,
        history: &History,
    ) -> ContactList {
        let mut contact = vec![NONE; partner.len()];
        let slots: Vec<usize> = pieces.iter().map(|&o| start[o as usize] as usize).collect();
        let stores: Vec<Store> = (0..pieces.len().saturating_sub(1))
            .zip(cut(&mut contact, &slots))
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(|(p, contact)| {
                let first = slots[p];
                let mut store = Store::default();
                for i in pieces[p] as usize..pieces[p + 1] as usize {
                    let run = start[i] as usize..start[i + 1] as usize;
                    let (other, carried) = history.run(i);
                    let mut h = 0;
                    for k in run {
                        let j = partner[k];
                        while h < other.len() && other[h] < j {
                            h += 1;
                        }
                        if other.get(h) == Some(&j) && carried[h] != Springs::default() {
                            contact[k - first] = store.springs.len() as u32;
                            store.springs.push(carried[h]);
                        }
                    }
                }
                store.springs.shrink_to_fit();
                store
            })
            .collect();
        ContactList {
            start,
            partner,
            contact,
            pieces,
            stores,
        }
    }
}

/// Owner bounds of pieces of at least `size` slots of a list with run starts `start` (the
/// last piece may be shorter).
fn pieces_of(start: &[u32], size: usize) -> Vec<u32> {
    let mut bounds = vec![0u32];
    let owners = start.len().saturating_sub(1);
    for i in 1..owners {
        if (start[i] - start[bounds[bounds.len() - 1] as usize]) as usize >= size {
            bounds.push(i as u32);
        }
    }
    if owners > 0 {
        bounds.push(owners as u32);
    }
    bounds
}

/// Slots per piece of the particle-face list (a task of the mesh stage).
pub const FACE_PIECE: usize = 256;

/// A contact history: the springs of particle pairs keyed by (lower, higher) and of
/// particle-face contacts by (particle, face), where particles are named by id (in
/// checkpoints) or by their storage index after a rebuild's re-sort (to carry the springs
/// into the new lists). Compressed by the first key, each run ordered by the second.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct History {
    /// The entries of `a` are `start[a]..start[a+1]`, ordered by the other key.
    start: Vec<u32>,
    other: Vec<u32>,
    springs: Vec<Springs>,
}

impl History {
    /// The history of `(a, other, springs)` entries, `a` below `keys`: a counting sort by
    /// `a`, then each run by `other`. `visit` hands every entry to its argument, the same
    /// entries in the same order each time it is called (twice: to count, then to place).
    fn from_visits(keys: usize, visit: impl Fn(&mut dyn FnMut(u32, u32, Springs))) -> History {
        let mut start = vec![0u32; keys + 1];
        visit(&mut |a, _, _| start[a as usize + 1] += 1);
        for k in 0..keys {
            start[k + 1] += start[k];
        }
        let total = start[keys] as usize;
        let mut fill = start.clone();
        let mut other = vec![0u32; total];
        let mut springs = vec![Springs::default(); total];
        visit(&mut |a, o, s| {
            let k = fill[a as usize] as usize;
            (other[k], springs[k]) = (o, s);
            fill[a as usize] += 1;
        });
        drop(fill);
        // Runs are short: insertion sort, in place.
        for a in 0..keys {
            let run = start[a] as usize..start[a + 1] as usize;
            for k in run.start + 1..run.end {
                let mut m = k;
                while m > run.start && other[m - 1] > other[m] {
                    other.swap(m - 1, m);
                    springs.swap(m - 1, m);
                    m -= 1;
                }
            }
        }
        History {
            start,
            other,
            springs,
        }
    }

    /// The history of saved `(id, other, springs)` entries (a checkpoint's) for `particles`
    /// (in storage order): keyed by storage index, `pairs` or not. An entry naming a
    /// particle that `particles` lacks is an error.
    pub fn in_storage(
        particles: &Particles,
        entries: &[(u32, u32, Springs)],
        pairs: bool,
    ) -> Result<History, String> {
        Self::keyed(
            &storage_index(particles),
            particles.len(),
            entries,
            pairs,
            false,
        )
    }

    /// [`History::in_storage`] for `n` particles, whose storage indices by id are `index`
    /// ([`storage_index`]), of the entries that name only them; the others are left out.
    fn of_present(
        index: &[u32],
        n: usize,
        entries: &[(u32, u32, Springs)],
        pairs: bool,
    ) -> History {
        Self::keyed(index, n, entries, pairs, true).expect("entries of absent particles left out")
    }

    fn keyed(
        index: &[u32],
        n: usize,
        entries: &[(u32, u32, Springs)],
        pairs: bool,
        skip_absent: bool,
    ) -> Result<History, String> {
        let at = |id: u32| index.get(id as usize).copied().filter(|&k| k != NONE);
        if !skip_absent {
            let named = |e: &(u32, u32, Springs)| [Some(e.0), pairs.then_some(e.1)];
            if let Some(id) = entries
                .iter()
                .flat_map(named)
                .flatten()
                .find(|&id| at(id).is_none())
            {
                return Err(format!(
                    "contact of particle id {id}, which the checkpoint lacks"
                ));
            }
        }
        Ok(History::from_visits(n, |f| {
            for &(a, b, s) in entries {
                let Some(a) = at(a) else { continue };
                if pairs {
                    let Some(b) = at(b) else { continue };
                    f(a.min(b), a.max(b), s);
                } else {
                    f(a, b, s);
                }
            }
        }))
    }

    /// Every entry, ordered by the first key and then by the other.
    pub fn entries(&self) -> Vec<(u32, u32, Springs)> {
        (0..self.start.len().saturating_sub(1))
            .flat_map(|a| {
                (self.start[a] as usize..self.start[a + 1] as usize)
                    .map(move |k| (a as u32, self.other[k], self.springs[k]))
            })
            .collect()
    }

    pub fn len(&self) -> usize {
        self.other.len()
    }

    pub fn is_empty(&self) -> bool {
        self.other.is_empty()
    }

    /// The entries of `a`: the other keys (ascending) and their springs.
    #[inline]
    fn run(&self, a: usize) -> (&[u32], &[Springs]) {
        if a + 1 >= self.start.len() {
            return (&[], &[]);
        }
        let run = self.start[a] as usize..self.start[a + 1] as usize;
        (&self.other[run.clone()], &self.springs[run])
    }
}

/// Contact histories as lists of entries: particle pairs and particle-face contacts.
pub type Entries = (Vec<(u32, u32, Springs)>, Vec<(u32, u32, Springs)>);

/// The contact histories of both lists.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Histories {
    pub pairs: History,
    pub faces: History,
}

/// The storage index of each id of `particles` (by id; [`NONE`] for ids it lacks).
fn storage_index(particles: &Particles) -> Vec<u32> {
    let mut index = vec![NONE; particles.next_id as usize];
    for (k, &id) in particles.id.iter().enumerate() {
        index[id as usize] = k as u32;
    }
    index
}

/// The history of particle pairs of a list, by (lower id, higher id).
fn pair_key(ids: &[u32]) -> impl Fn(usize, u32) -> Option<(u32, u32)> + Sync + '_ {
    move |i, j| {
        let (a, b) = (ids[i], ids[j as usize]);
        Some((a.min(b), a.max(b)))
    }
}

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
    fn keys(&self, x: &[DVec3], id: &[u32]) -> Vec<(u64, u32)> {
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
    /// Number of rebuilds so far.
    pub rebuilds: u64,
}

/// The fewest owners in a slab (a task of the pair stage).
const MIN_SLAB: usize = 64;

/// The pieces of the pair list, slabs: owner bounds such that the partners of slab `s` lie
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
    pub fn across(
        &self,
        ids: &[u32],
        a: usize,
        b: usize,
        k: usize,
    ) -> (usize, usize, DVec3, DVec3) {
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
        let mut partnered = vec![false; n];
        for &j in &self.pairs.partner {
            partnered[j as usize] = true;
        }
        let listed = |i: usize| {
            !self.pairs.run(i).is_empty() || partnered[i] || !self.faces.run(i).is_empty()
        };
        let candidates: Vec<usize> = (0..n).filter(|&i| !listed(i)).collect();
        const BUDGET: usize = 4_000_000;
        // Clearances by brute force do not see periodic images: no lonely particles then.
        if candidates.is_empty()
            || candidates.len() * (n + faces.len()) > BUDGET
            || self.periodic.is_some()
        {
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

    /// The contact histories of the current lists by id.
    pub fn history(&self, ids: &[u32], id_count: usize) -> Histories {
        Histories {
            pairs: ContactList::history_of(&[&self.pairs, &self.wrapped], id_count, pair_key(ids)),
            faces: self.faces.history(id_count, |i, f| Some((ids[i], f))),
        }
    }

    /// Drops the lists (their memory), until the next rebuild.
    pub fn clear_lists(&mut self) {
        self.pairs = ContactList::default();
        self.faces = ContactList::default();
        self.wrapped = ContactList::default();
    }

    /// The contact histories of the current lists by id, unsorted: particle pairs as
    /// (lower id, higher id, springs), particle-face contacts as (id, face, springs).
    pub fn entries_by_id(&self, ids: &[u32]) -> Entries {
        let mut pairs = Vec::with_capacity(self.pairs.contacts() + self.wrapped.contacts());
        for list in [&self.pairs, &self.wrapped] {
            list.for_each_live(|i, k, s| {
                let (a, b) = (ids[i], ids[list.partner[k] as usize]);
                pairs.push((a.min(b), a.max(b), s));
            });
        }
        let mut faces = Vec::with_capacity(self.faces.contacts());
        self.faces
            .for_each_live(|i, k, s| faces.push((ids[i], self.faces.partner[k], s)));
        (pairs, faces)
    }

    /// The positions the lists were built at and the lonely particles' allowances: with
    /// the storage order, all a checkpoint needs to restore the very same lists.
    pub fn anchors(&self) -> (&[DVec3], &[(u32, f64)]) {
        (&self.x_at_build, &self.lonely)
    }

    /// Rebuilds both lists for `particles`, re-sorting them into spatial order first.
    ///
    /// Particles are stored in the order of their cells (cell key, then id), so that
    /// neighbours in space are neighbours in memory; the springs of touching pairs are
    /// carried to their slots in the new lists (keyed by the particles' new storage
    /// indices, so that carrying them runs in spatial order too), and the lists are built
    /// from the positions (see `Neighbours::build`).
    pub fn rebuild(&mut self, particles: &mut Particles, faces: &[Face], face_grid: &CellGrid) {
        self.rebuild_without(particles, &[], faces, face_grid);
    }

    /// Rebuilds the lists as [`Neighbours::rebuild`] does, removing first the particles
    /// (storage indices, ascending) in `gone` and the history of their contacts.
    pub fn rebuild_without(
        &mut self,
        particles: &mut Particles,
        gone: &[u32],
        faces: &[Face],
        face_grid: &CellGrid,
    ) {
        if let Some(periodic) = self.periodic {
            // Between rebuilds particles move freely across periodic sides; here they are
            // put back into the box.
            particles
                .x
                .par_iter_mut()
                .zip(particles.v.par_iter_mut())
                .with_min_len(4 * MIN_PARALLEL_LEN)
                .for_each(|(x, v)| (*x, *v) = periodic.wrap_state(*x, *v));
        }
        let layout = Layout::of(&particles.radius, self.skin);
        let keys = layout.keys(&particles.x, &particles.id);
        let order: Option<Vec<u32>> = (!gone.is_empty() || !keys.is_sorted()).then(|| {
            let mut gone = gone.iter().peekable();
            let mut order: Vec<u32> = (0..particles.len() as u32)
                .filter(|&i| gone.next_if_eq(&&i).is_none())
                .collect();
            order.par_sort_unstable_by_key(|&i| keys[i as usize]);
            order
        });
        drop(keys);
        let n = order.as_ref().map_or(particles.len(), Vec::len);
        // Where each particle goes (NONE: removed), and the springs by the new places.
        let mut new = vec![NONE; self.pairs.owners()];
        match &order {
            Some(order) => {
                for (k, &old) in order.iter().enumerate() {
                    if (old as usize) < new.len() {
                        new[old as usize] = k as u32;
                    }
                }
            }
            None => new.iter_mut().enumerate().for_each(|(k, v)| *v = k as u32),
        }
        let kept = |a: u32| (a != NONE).then_some(a);
        let history = Histories {
            pairs: ContactList::history_of(&[&self.pairs, &self.wrapped], n, |i, j| {
                let (a, b) = (kept(new[i])?, kept(new[j as usize])?);
                Some((a.min(b), a.max(b)))
            }),
            faces: self.faces.history(n, |i, f| kept(new[i]).map(|a| (a, f))),
        };
        drop(new);
        // The old lists and anchors go before the new ones are made.
        self.pairs = ContactList::default();
        self.faces = ContactList::default();
        self.wrapped = ContactList::default();
        self.x_at_build = Vec::new();
        if let Some(order) = order {
            particles.permute(&order);
        }
        let x = particles.x.clone();
        self.build(&x, particles, faces, face_grid, layout, &history);
        self.find_lonely(&x, &particles.radius, faces);
        self.x_at_build = x;
        self.rebuilds += 1;
    }

    /// Rebuilds the lists for `particles` (re-sorted into spatial order first) where they
    /// are, or at the positions `at` (one per particle: the anchors of an earlier rebuild,
    /// which become the anchors again), with the springs of `pairs` and `faces`,
    /// entries by id ((lower id, higher id) and (id, face); those naming a particle that
    /// `particles` lacks are left out). For a process of a split run (`domain.rs`), which
    /// gathers its history from other processes: it finds no lonely particles, whose
    /// clearances would need the particles it does not hold. Returns the permutation
    /// applied (`Particles::permute`).
    pub fn rebuild_from(
        &mut self,
        particles: &mut Particles,
        at: Option<Vec<DVec3>>,
        pairs: &[(u32, u32, Springs)],
        faces_history: &[(u32, u32, Springs)],
        faces: &[Face],
        face_grid: &CellGrid,
    ) -> Vec<u32> {
        let layout = Layout::of(&particles.radius, self.skin);
        let keys = layout.keys(at.as_deref().unwrap_or(&particles.x), &particles.id);
        let mut order: Vec<u32> = (0..particles.len() as u32).collect();
        order.par_sort_unstable_by_key(|&i| keys[i as usize]);
        drop(keys);
        self.pairs = ContactList::default();
        self.faces = ContactList::default();
        self.wrapped = ContactList::default();
        particles.permute(&order);
        let at = at.map(|at| {
            order
                .iter()
                .map(|&o| at[o as usize])
                .collect::<Vec<DVec3>>()
        });
        let index = storage_index(particles);
        let history = Histories {
            pairs: History::of_present(&index, particles.len(), pairs, true),
            faces: History::of_present(&index, particles.len(), faces_history, false),
        };
        drop(index);
        let x = at.unwrap_or_else(|| particles.x.clone());
        self.build(&x, particles, faces, face_grid, layout, &history);
        self.lonely = Vec::new();
        self.x_at_build = x;
        self.rebuilds += 1;
        order
    }

    /// Forgets the anchors of the last rebuild, so that the lists count as stale at the
    /// next step (as those of a simulation never stepped).
    pub fn forget_anchors(&mut self) {
        self.x_at_build = Vec::new();
        self.lonely = Vec::new();
    }

    /// Builds again the lists of a checkpoint: the particles in their saved storage order,
    /// the positions of the last rebuild (`anchors`) and its lonely particles, and the
    /// contact histories (keyed by storage index, [`History::in_storage`]). The lists are
    /// those the run had, slot for slot.
    pub fn restore(
        &mut self,
        particles: &Particles,
        anchors: Vec<DVec3>,
        lonely: Vec<(u32, f64)>,
        faces: &[Face],
        face_grid: &CellGrid,
        history: &Histories,
    ) {
        let layout = Layout::of(&particles.radius, self.skin);
        self.build(&anchors, particles, faces, face_grid, layout, history);
        self.x_at_build = anchors;
        self.lonely = lonely;
        self.rebuilds += 1;
    }

    /// Both lists for particles at `x` (radii and ids from `particles`, in storage order),
    /// with the springs of `history`, and the slabs.
    ///
    /// Each pair is listed once, under its lower storage index, with its partners in
    /// ascending order. Cells sized for every radius (`uniform`): each particle looks for
    /// its partners of higher index in the 27 cells around its own. Otherwise each pair is
    /// found by its larger particle (ties: the lower index), which searches as many cells
    /// as its own reach needs, and the pairs are sorted afterwards.
    fn build(
        &mut self,
        x: &[DVec3],
        particles: &Particles,
        faces: &[Face],
        face_grid: &CellGrid,
        layout: Layout,
        history: &Histories,
    ) {
        let radius = &particles.radius;
        let n = x.len();
        let skin = self.skin;
        let grid = CellGrid::of_points(x, layout.h);
        let close = |i: u32, j: u32| {
            let reach = radius[i as usize] + radius[j as usize] + skin;
            (x[i as usize] - x[j as usize]).length_squared() < reach * reach
        };
        let in_cell_order = layout.uniform && {
            let inv_h = 1.0 / layout.h;
            x.windows(2)
                .all(|w| key(cell_of(w[0], inv_h)) <= key(cell_of(w[1], inv_h)))
        };
        let (start, partner) = if in_cell_order {
            // Storage in cell order: per cell, each particle's partners are the later ones
            // of its cell and those of the 13 cells after it in key order, whose indices
            // all come after its own; so each run comes out sorted.
            let cells = grid.occupied();
            let runs: Vec<Vec<u32>> = cells
                .par_iter()
                .with_min_len(MIN_PARALLEL_LEN / 4)
                .fold(Vec::new, |mut out: Vec<u32>, &(c, a, b)| {
                    let forward = FORWARD.map(|d| grid.range(c + d));
                    for i in a..b {
                        let at = out.len();
                        out.push(0); // the run's length, filled below
                        for j in (i + 1..b).chain(forward.iter().flat_map(|r| r.clone())) {
                            if close(i, j) {
                                out.push(j);
                            }
                        }
                        out[at] = (out.len() - at - 1) as u32;
                    }
                    out
                })
                .collect();
            runs_to_csr(n, runs)
        } else if layout.uniform {
            // Any storage order (a restored checkpoint may hold a re-anchored particle out
            // of its cell): per owner, its partners of higher index from the 27 cells
            // around its cell, sorted.
            let runs: Vec<Vec<u32>> = (0..n as u32)
                .into_par_iter()
                .with_min_len(4 * MIN_PARALLEL_LEN)
                .fold(Vec::new, |mut out: Vec<u32>, i| {
                    let at = out.len();
                    out.push(0); // the run's length, filled below
                    grid.for_each_near(x[i as usize], |j| {
                        if j > i && close(i, j) {
                            out.push(j);
                        }
                    });
                    out[at + 1..].sort_unstable();
                    out[at] = (out.len() - at - 1) as u32;
                    out
                })
                .collect();
            runs_to_csr(n, runs)
        } else {
            let finds = |i: u32, j: u32| {
                let (ri, rj) = (radius[i as usize], radius[j as usize]);
                rj < ri || (rj == ri && j > i)
            };
            let cells_needed = |i: u32| {
                ((2.0 * radius[i as usize] + skin) / layout.h)
                    .ceil()
                    .max(1.0) as i32
            };
            let mut pairs: Vec<u64> = (0..n as u32)
                .into_par_iter()
                .with_min_len(4 * MIN_PARALLEL_LEN)
                .fold(Vec::new, |mut out: Vec<u64>, i| {
                    let c = cell_of(x[i as usize], 1.0 / layout.h);
                    let m = cells_needed(i);
                    for dz in -m..=m {
                        for dy in -m..=m {
                            for dx in -m..=m {
                                for &j in grid.in_cell(c + IVec3::new(dx, dy, dz)) {
                                    if finds(i, j) && close(i, j) {
                                        out.push(((i.min(j) as u64) << 32) | i.max(j) as u64);
                                    }
                                }
                            }
                        }
                    }
                    out
                })
                .flatten()
                .collect();
            pairs.par_sort_unstable();
            compress(n, pairs.iter().map(|&k| ((k >> 32) as u32, k as u32)))
        };
        let slabs = slabs_of(&start, &partner);
        self.pairs = ContactList::with_springs(start, partner, slabs, &history.pairs);
        if let Some(periodic) = self.periodic {
            // Pairs across periodic sides: each image x_j + s of a particle near a side
            // against the particles i < j near it; one shift per pair, since a period is
            // longer than twice any reach (checked by the scenario).
            let max_radius = radius.iter().copied().fold(0.0, f64::max);
            let reach_max = 2.0 * max_radius + skin;
            let m = (reach_max / layout.h).ceil().max(1.0) as i32;
            type Found = (u32, u32, DVec3, i8);
            let mut found: Vec<Found> = (0..n as u32)
                .into_par_iter()
                .with_min_len(4 * MIN_PARALLEL_LEN)
                .fold(
                    || (Vec::new(), Vec::new()),
                    |(mut out, mut shifts): (Vec<Found>, Vec<(DVec3, i8)>), j| {
                        periodic.image_shifts(x[j as usize], reach_max, &mut shifts);
                        for &(s, crossing) in &shifts {
                            let image = x[j as usize] + s;
                            let c = cell_of(image, 1.0 / layout.h);
                            for dz in -m..=m {
                                for dy in -m..=m {
                                    for dx in -m..=m {
                                        for &i in grid.in_cell(c + IVec3::new(dx, dy, dz)) {
                                            let reach =
                                                radius[i as usize] + radius[j as usize] + skin;
                                            if i < j
                                                && (x[i as usize] - image).length_squared()
                                                    < reach * reach
                                            {
                                                out.push((i, j, s, crossing));
                                            }
                                        }
                                    }
                                }
                            }
                        }
                        (out, shifts)
                    },
                )
                .map(|(out, _)| out)
                .flatten()
                .collect();
            found.sort_unstable_by_key(|&(i, j, _, _)| (i, j));
            // Each pair as the law sees it: the particle of the higher id at its image
            // nearest the other.
            let ids = &particles.id;
            for f in &mut found {
                let (lo, hi) = if ids[f.0 as usize] < ids[f.1 as usize] {
                    (f.0, f.1)
                } else {
                    (f.1, f.0)
                };
                (f.2, f.3) = periodic.image_towards(x[hi as usize], x[lo as usize]);
            }
            let (start, partner) = compress(n, found.iter().map(|&(i, j, _, _)| (i, j)));
            self.shift = found.iter().map(|f| f.2).collect();
            self.crossings = found.iter().map(|f| f.3).collect();
            self.offset_at_build = periodic.shear.map_or(0.0, |sh| sh.offset);
            let pieces = pieces_of(&start, FACE_PIECE);
            self.wrapped = ContactList::with_springs(start, partner, pieces, &history.pairs);
        }
        drop(grid);

        // The items of a grid cell come in ascending order, so each particle's run of faces
        // is sorted.
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
        drop(face_pairs);
        let pieces = pieces_of(&start, FACE_PIECE);
        self.faces = ContactList::with_springs(start, partner, pieces, &history.faces);
    }
}

/// `slice` cut at `bounds` (ascending, from 0 to its length).
pub(crate) fn cut<'a, T>(mut slice: &'a mut [T], bounds: &[usize]) -> Vec<&'a mut [T]> {
    bounds
        .windows(2)
        .map(|w| {
            let (piece, rest) = std::mem::take(&mut slice).split_at_mut(w[1] - w[0]);
            slice = rest;
            piece
        })
        .collect()
}

/// Runs collected as `[length, partners...]` blocks, `n` of them in owner order, in
/// compressed form.
fn runs_to_csr(n: usize, runs: Vec<Vec<u32>>) -> (Vec<u32>, Vec<u32>) {
    let total = runs.iter().map(Vec::len).sum::<usize>() - n;
    let mut start = Vec::with_capacity(n + 1);
    let mut partner = Vec::with_capacity(total);
    start.push(0u32);
    for block in runs {
        let mut k = 0;
        while k < block.len() {
            let len = block[k] as usize;
            partner.extend_from_slice(&block[k + 1..k + 1 + len]);
            start.push(partner.len() as u32);
            k += 1 + len;
        }
    }
    debug_assert_eq!(start.len(), n + 1);
    (start, partner)
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

    /// Particles at `x` with radii `radius` (ids in that order).
    fn particles(x: &[DVec3], radius: &[f64]) -> Particles {
        x.iter()
            .zip(radius)
            .map(|(&x, &radius)| crate::model::particles::Particle {
                x,
                radius,
                v: DVec3::ZERO,
                q: glam::DQuat::IDENTITY,
                w: DVec3::ZERO,
                tag: 0,
                material: 0,
            })
            .collect()
    }

    /// The listed particle pairs by id, (lower, higher), sorted; and a check that every
    /// owner's partners follow it, in order, within the next slab.
    fn listed(nb: &Neighbours, p: &Particles) -> Vec<(u32, u32)> {
        let list = &nb.pairs;
        let mut pairs = Vec::new();
        let slabs = &nb.pairs.pieces;
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
        let mut p = particles(&x, &radius);
        nb.rebuild(&mut p, &[], &CellGrid::default());
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
        nb.rebuild(&mut p, &[], &CellGrid::default());
        assert_eq!(listed(&nb, &p), brute(&x, &radius, 0.002));
        // The particles are stored in the order of their cells, each one unchanged.
        let h = 2.0 * 0.007 + 0.002;
        let keys: Vec<u64> = p.x.iter().map(|&x| key(cell_of(x, 1.0 / h))).collect();
        assert!(keys.is_sorted());
        for k in 0..p.len() {
            assert_eq!(p.x[k], x[p.id[k] as usize]);
        }
        assert!(nb.pairs.pieces.len() > 3, "{:?}", nb.pairs.pieces);
    }

    /// A checkpoint's springs naming a particle it lacks are refused with the id; a split
    /// run's history leaves out the springs of particles another process holds.
    #[test]
    fn histories_by_id_name_or_skip_the_particles_absent() {
        let x = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
        let p = particles(&x, &[0.1; 3]);
        let s = |u_t: f64| Springs {
            u_t,
            ..Springs::default()
        };
        let entries = [(0, 2, s(1.0)), (1, 7, s(2.0)), (2, 1, s(3.0))];
        let err = History::in_storage(&p, &entries, true).unwrap_err();
        assert!(err.contains("id 7"), "{err}");
        let index = storage_index(&p);
        let h = History::of_present(&index, p.len(), &entries, true);
        assert_eq!(
            h.entries(),
            vec![(0, 2, s(1.0)), (1, 2, s(3.0))],
            "the pair with 7 left out, the others keyed low to high"
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
        nb.rebuild(&mut p, &[], &CellGrid::default());
        assert_eq!(listed(&nb, &p), vec![(0, 3), (1, 2)]);
        // Give each pair springs that name it, then move the pairs past each other.
        let list = &mut nb.pairs;
        for i in 0..p.len() {
            let piece = list.pieces.partition_point(|&b| b as usize <= i) - 1;
            for k in list.start[i] as usize..list.start[i + 1] as usize {
                let id = p.id[i].min(p.id[list.partner[k] as usize]);
                let e = list.stores[piece].open();
                list.stores[piece].springs[e as usize].u_t = id as f64 + 1.0;
                list.contact[k] = e;
            }
        }
        for x in &mut p.x {
            x.x = 1.0 - x.x;
        }
        nb.rebuild(&mut p, &[], &CellGrid::default());
        assert_eq!(p.id, vec![3, 0, 2, 1]);
        let pairs = nb.history(&p.id, 4).pairs;
        assert_eq!(
            pairs
                .entries()
                .iter()
                .map(|e| (e.0, e.1, e.2.u_t))
                .collect::<Vec<_>>(),
            vec![(0, 3, 1.0), (1, 2, 2.0)]
        );
    }

    /// The storage index of the particle with id `id`.
    fn at(p: &Particles, id: u32) -> usize {
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
        nb.rebuild(&mut p, &[], &CellGrid::default());
        assert_eq!(nb.lonely.len(), 1, "{:?}", nb.lonely);
        let mut rebuilds = 0;
        while p.x[at(&p, 0)].z > 0.015 {
            let k = at(&p, 0);
            p.x[k].z -= 0.001;
            if nb.stale(&p.x, &p.radius, &[], 0.0) {
                nb.rebuild(&mut p, &[], &CellGrid::default());
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
        nb.rebuild(&mut p, &[], &CellGrid::default());
        let k = at(&p, 2);
        p.x[k].x += 0.6 * skin;
        assert!(nb.stale(&p.x, &p.radius, &[], 0.0));
    }

    #[test]
    fn two_lonely_particles_meeting_head_on_are_listed_before_they_touch() {
        let radius = vec![0.01; 2];
        let x = vec![DVec3::new(-0.5, 0.0, 0.0), DVec3::new(0.5, 0.0, 0.0)];
        let mut nb = Neighbours::new(0.005);
        let mut p = particles(&x, &radius);
        nb.rebuild(&mut p, &[], &CellGrid::default());
        assert_eq!(nb.lonely.len(), 2);
        let mut rebuilds = 0;
        for _ in 0..600 {
            let (a, b) = (at(&p, 0), at(&p, 1));
            p.x[a].x += 0.001;
            p.x[b].x -= 0.0013;
            if nb.stale(&p.x, &p.radius, &[], 0.0) {
                nb.rebuild(&mut p, &[], &CellGrid::default());
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
