//! The hashed cell grid: particles and face boxes binned into cubic cells, and the grid of
//! the mesh faces.

use glam::{DVec3, IVec3};
use rayon::prelude::*;
use rustc_hash::FxHashMap;

use super::MIN_PARALLEL_LEN;
use crate::geometry::mesh::Face;

pub(crate) const CELL_BIAS: i32 = 1 << 20;

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
pub(crate) fn unkey(k: u64) -> IVec3 {
    let c = |shift: u32| ((k >> shift) & ((1 << 21) - 1)) as i32 - CELL_BIAS;
    IVec3::new(c(42), c(21), c(0))
}

/// The 13 neighbours of a cell whose keys come after its own, in key order (x, then y, then
/// z): with the cell itself, every pair of neighbouring cells once.
pub(crate) const FORWARD: [IVec3; 13] = {
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
    pub(crate) inv_h: f64,
    /// Item indices grouped by cell.
    pub(crate) items: Vec<u32>,
    /// Cell key -> range in `items`.
    pub(crate) cells: FxHashMap<u64, (u32, u32)>,
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
    pub(crate) fn from_sorted(keyed: Vec<(u64, u32)>, inv_h: f64) -> CellGrid {
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
    pub(crate) fn occupied(&self) -> Vec<(IVec3, u32, u32)> {
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
    pub(crate) fn range(&self, c: IVec3) -> std::ops::Range<u32> {
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
    pub(crate) fn in_cell(&self, c: IVec3) -> &[u32] {
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

/// The cells a face may span in its level of the [`FaceGrid`]: a face that would span more
/// goes to a level of cells 4 times as wide.
const MAX_CELLS_PER_FACE: f64 = 4096.0;

/// The grid of mesh faces: each face binned into every cell its bounding box, grown by the
/// reach of a particle, overlaps, so the cell of a particle's centre lists every face it can
/// reach before the next rebuild. Cells are 2 R_max + skin wide; a face that would span more
/// than `MAX_CELLS_PER_FACE` (4,096) of them (a floor of a kilometre under millimetre grains would
/// span 10^9) is binned in a level of cells 4, 16, ... times as wide, so that no face costs
/// more than that many entries. Usually every face is in the first level.
#[derive(Clone, Debug, Default)]
pub struct FaceGrid {
    /// The levels that hold faces, with their cell widths, finest first.
    levels: Vec<CellGrid>,
}

impl FaceGrid {
    /// The grid of `faces` for particles up to radius `max_radius` with `skin`.
    pub fn of(faces: &[Face], max_radius: f64, skin: f64) -> FaceGrid {
        let grow = DVec3::splat(max_radius + skin);
        let h = (2.0 * max_radius + skin).max(f64::MIN_POSITIVE);
        let mut by_level: Vec<Vec<(DVec3, DVec3)>> = Vec::new();
        let mut faces_of: Vec<Vec<u32>> = Vec::new();
        for (k, f) in faces.iter().enumerate() {
            let (lo, hi) = f.bounding_box();
            let (lo, hi) = (lo - grow, hi + grow);
            let cells = |h: f64| {
                let (a, b) = (cell_of(lo, 1.0 / h), cell_of(hi, 1.0 / h));
                let n = (b - a + IVec3::ONE).as_dvec3();
                n.x * n.y * n.z
            };
            let mut level = 0;
            while cells(h * 4f64.powi(level as i32)) > MAX_CELLS_PER_FACE {
                level += 1;
            }
            if by_level.len() <= level {
                by_level.resize(level + 1, Vec::new());
                faces_of.resize(level + 1, Vec::new());
            }
            by_level[level].push((lo, hi));
            faces_of[level].push(k as u32);
        }
        let levels = (by_level.iter().zip(&faces_of).enumerate())
            .filter(|(_, (boxes, _))| !boxes.is_empty())
            .map(|(level, (boxes, ids))| {
                let mut grid = CellGrid::of_boxes(boxes, h * 4f64.powi(level as i32));
                grid.items.iter_mut().for_each(|i| *i = ids[*i as usize]);
                grid
            })
            .collect();
        FaceGrid { levels }
    }

    /// The faces listed in the cells of `x`, ascending.
    #[inline]
    pub fn at(&self, x: DVec3) -> std::borrow::Cow<'_, [u32]> {
        match self.levels.as_slice() {
            [] => std::borrow::Cow::Borrowed(&[]),
            [one] => std::borrow::Cow::Borrowed(one.at(x)),
            all => {
                let mut faces: Vec<u32> = all.iter().flat_map(|g| g.at(x)).copied().collect();
                faces.sort_unstable();
                std::borrow::Cow::Owned(faces)
            }
        }
    }
}
