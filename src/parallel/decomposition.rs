//! A run split over processes (domain decomposition), with the bits of the run in one.
//!
//! Each process owns the particles of a box of space, cut by recursive coordinate
//! bisection ([`Tree`], balanced by count), and holds copies (ghosts) of the other
//! processes' particles within reach of its box: `r_i + R_max + skin`, so every pair the
//! lists of one process would hold is listed on the process of each partner. A process
//! runs the stages of the step on all it holds; a pair of an own particle and a ghost is
//! evaluated on both sides, from the same bits, so both keep the same springs. Since the
//! loads are exact sums (`exact.rs`), an own particle's load is that of the run in one
//! process, bit for bit, and so is its motion. After integrating, each process sends the
//! new states of its particles to the processes that hold them as ghosts.
//!
//! When the lists must be rebuilt (on any process), every process rebuilds them: its
//! particles that left its box go to their new owners with their contact history (the
//! springs of their pairs, keyed by the pair of ids, and of their faces), the ghosts are
//! made afresh, and the boxes are cut anew when the counts are out of balance. Spawning
//! draws the same random stream on every process, against the particles of all processes
//! near the spawn regions; removals are counted in id order over all processes. Wall
//! loads are exact sums over all processes.
//!
//! In a periodic domain a process also holds, at their own places, the particles whose
//! images across the sides come within reach of its box; its lists pair them across the
//! sides as the lists of one process do, seen from the particle of the lower id with the
//! other at the image nearest it (a shift found from the two positions alone), so both
//! processes of such a pair see it with the same bits. Positions are wrapped into the box
//! at rebuilds, which rounds them: so the split run rebuilds at the steps the run in one
//! process does (see `Placement`).
//!
//! A rigid body (clump) is owned whole by the process whose box holds its centre of mass
//! (put back into a periodic box). Its spheres may lie outside that box, by at most the
//! largest distance of a sphere from its body's centre (measured at each rebuild over all
//! processes), so the reach of the ghosts grows by that much; and a body goes whole, with
//! its record, to every process one of its spheres is near. Only the owner moves a body
//! (stage 5a); the others take its spheres' states in stage 5c, so a ghost body's own
//! record (x, v, q, ω) is that of the last rebuild: nothing but its mass and offsets may be
//! read from it.

use anyhow::{Result, bail};
use glam::DVec3;

use crate::model::bodies::{Body, BodyId};
use crate::model::contact_state::{ActiveState, ContactState};
use crate::model::particles::{Active, Id, Particle, Particles};
use crate::neighbours::Entry;
use crate::parallel::comm::{Comm, Reach, Reader, Writer};

/// Past this ratio of the largest process's particle count to the mean, the boxes are cut
/// anew at the next rebuild.
pub(crate) const REBALANCE: f64 = 1.1;

/// Bisection steps for each cut: the cut lies within 2^-48 of the particles' extent of
/// the place that halves the count.
const BISECTIONS: usize = 48;

/// A node of the bisection: a process's box, or a cut across an axis.
#[derive(Clone, Copy, Debug)]
enum Cell {
    Leaf(usize),
    Cut {
        axis: usize,
        at: f64,
        below: u32,
        above: u32,
    },
}

/// The boxes of the processes: space cut recursively across an axis at a time (the
/// outermost boxes reach to infinity).
#[derive(Clone, Debug)]
pub struct Tree {
    cells: Vec<Cell>,
}

impl Tree {
    /// The process whose box holds `x` (below a cut: `x[axis] < at`).
    pub fn owner(&self, x: DVec3) -> usize {
        let mut c = 0;
        loop {
            match self.cells[c] {
                Cell::Leaf(rank) => return rank,
                Cell::Cut {
                    axis,
                    at,
                    below,
                    above,
                } => c = if x[axis] < at { below } else { above } as usize,
            }
        }
    }

    /// The processes whose boxes meet the cube of half-width `reach` around `x`.
    pub fn near(&self, x: DVec3, reach: f64, out: &mut Vec<usize>) {
        out.clear();
        let mut todo = vec![0u32];
        while let Some(c) = todo.pop() {
            match self.cells[c as usize] {
                Cell::Leaf(rank) => out.push(rank),
                Cell::Cut {
                    axis,
                    at,
                    below,
                    above,
                } => {
                    if x[axis] - reach < at {
                        todo.push(below);
                    }
                    if x[axis] + reach >= at {
                        todo.push(above);
                    }
                }
            }
        }
    }

    /// Cuts space among the processes of `comm` so that each holds about as many of the
    /// points as the others (`x`: this process's share of them). Level by level: each group
    /// of processes cuts its box across the longest extent of its points, at the place
    /// that leaves below as many points as the first half of its processes should hold,
    /// found by bisection with the counts summed over all processes. Every process gets
    /// the same tree.
    pub fn bisect(comm: &dyn Comm, x: &[DVec3]) -> Tree {
        let mut cells = vec![Cell::Leaf(0)];
        let mut groups = vec![Group {
            cell: 0,
            ranks: 0..comm.size(),
            members: (0..x.len() as u32).collect(),
        }];
        loop {
            let (split, done): (Vec<Group>, Vec<Group>) =
                groups.into_iter().partition(|g| g.ranks.len() > 1);
            for g in done {
                cells[g.cell] = Cell::Leaf(g.ranks.start);
            }
            if split.is_empty() {
                break;
            }
            let (lo, hi, count) = extents(comm, x, &split);
            let axis: Vec<usize> = (0..split.len())
                .map(|g| longest_axis(hi[g] - lo[g]))
                .collect();
            let target: Vec<i64> = (0..split.len())
                .map(|g| {
                    let (n, left) = (split[g].ranks.len() as u64, split[g].ranks.len() as u64 / 2);
                    ((count[g] * left + n / 2) / n) as i64
                })
                .collect();
            let at = cut_places(comm, x, &split, &axis, &target, (&lo, &hi));
            groups = Vec::new();
            for (g, grp) in split.into_iter().enumerate() {
                groups.extend(halve(&mut cells, grp, x, (axis[g], at[g])));
            }
        }
        Tree { cells }
    }
}

/// Processes that share a box of the bisection: its cell of the tree, their ranks, and
/// this process's points in it.
struct Group {
    cell: usize,
    ranks: std::ops::Range<usize>,
    members: Vec<u32>,
}

/// The extent and count of each group's points over all processes (collective).
fn extents(comm: &dyn Comm, x: &[DVec3], split: &[Group]) -> (Vec<DVec3>, Vec<DVec3>, Vec<u64>) {
    let mut w = Writer::default();
    for g in split {
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for &i in &g.members {
            (lo, hi) = (lo.min(x[i as usize]), hi.max(x[i as usize]));
        }
        w.vec3(lo);
        w.vec3(hi);
        w.u64(g.members.len() as u64);
    }
    let mut lo = vec![DVec3::INFINITY; split.len()];
    let mut hi = vec![DVec3::NEG_INFINITY; split.len()];
    let mut count = vec![0u64; split.len()];
    for d in comm.all_gather(w.0) {
        let mut r = Reader::new(&d);
        for g in 0..split.len() {
            lo[g] = lo[g].min(r.vec3());
            hi[g] = hi[g].max(r.vec3());
            count[g] += r.u64();
        }
    }
    (lo, hi, count)
}

/// The axis of the longest extent `e` (x if it is not finite).
fn longest_axis(e: DVec3) -> usize {
    if !e.is_finite() || (e.x >= e.y && e.x >= e.z) {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    }
}

/// The place of each group's cut across its `axis` that leaves `target` points below it
/// (collective): `BISECTIONS` bisections of the extent `lo`..`hi` with the counts summed
/// over all processes.
fn cut_places(
    comm: &dyn Comm,
    x: &[DVec3],
    split: &[Group],
    axis: &[usize],
    target: &[i64],
    (lo, hi): (&[DVec3], &[DVec3]),
) -> Vec<f64> {
    let mut a: Vec<f64> = (0..split.len()).map(|g| lo[g][axis[g]]).collect();
    let mut b: Vec<f64> = (0..split.len()).map(|g| hi[g][axis[g]]).collect();
    for g in 0..split.len() {
        if !(a[g].is_finite() && b[g].is_finite()) {
            (a[g], b[g]) = (0.0, 0.0);
        }
    }
    for _ in 0..BISECTIONS {
        let mid: Vec<f64> = (0..split.len())
            .map(|g| a[g] + 0.5 * (b[g] - a[g]))
            .collect();
        let below: Vec<i64> = split
            .iter()
            .enumerate()
            .map(|(g, grp)| {
                grp.members
                    .iter()
                    .filter(|&&i| x[i as usize][axis[g]] < mid[g])
                    .count() as i64
            })
            .collect();
        let below = comm.sum_i64(&below);
        for g in 0..split.len() {
            if below[g] < target[g] {
                a[g] = mid[g];
            } else {
                b[g] = mid[g];
            }
        }
    }
    b
}

/// Cuts group `grp`'s box across `axis` at `at`: its cell becomes the cut, and the two
/// halves, each with half its processes, are the groups returned.
fn halve(cells: &mut Vec<Cell>, grp: Group, x: &[DVec3], (axis, at): (usize, f64)) -> [Group; 2] {
    let (below, above) = (cells.len(), cells.len() + 1);
    cells.push(Cell::Leaf(0));
    cells.push(Cell::Leaf(0));
    cells[grp.cell] = Cell::Cut {
        axis,
        at,
        below: below as u32,
        above: above as u32,
    };
    let middle = grp.ranks.start + grp.ranks.len() / 2;
    let (under, over): (Vec<u32>, Vec<u32>) =
        grp.members.iter().partition(|&&i| x[i as usize][axis] < at);
    [
        Group {
            cell: below,
            ranks: grp.ranks.start..middle,
            members: under,
        },
        Group {
            cell: above,
            ranks: middle..grp.ranks.end,
            members: over,
        },
    ]
}

/// Where a redistribution places the particles (for their owners, ghosts and lists).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Placement {
    /// Where they are now (put back into a periodic box first): a rebuild of the lists.
    Now,
    /// Where the lists of the run in one process were last built, its anchors: on
    /// splitting a simulation made or restored in one process, so that the split run
    /// rebuilds its lists (and puts particles back into a periodic box) at the steps that
    /// run would.
    Anchors,
}

/// The share of one process in a split run.
pub struct Share {
    pub(crate) comm: Box<dyn Comm>,
    pub(crate) tree: Option<Tree>,
    /// Whether each particle held (storage order) is this process's own; the others are
    /// ghosts, copies of other processes' particles.
    pub(crate) owned: Vec<bool>,
    /// For each process, the own particles (storage indices, in id order) it holds as
    /// ghosts; and the ghosts it sends the states of (storage indices, in id order).
    pub(crate) send: Vec<Vec<u32>>,
    pub(crate) recv: Vec<Vec<u32>>,
    /// Times the boxes were cut.
    pub cuts: u64,
}

impl Share {
    /// This process and the number of processes.
    pub fn rank(&self) -> (usize, usize) {
        (self.comm.rank(), self.comm.size())
    }

    /// Own particles held.
    pub fn own_count(&self) -> usize {
        self.owned.iter().filter(|&&o| o).count()
    }
}

/// A particle's record in a message between processes that hold the optional fields
/// `active`: its id, then its fields ([`Particle::put`]).
pub(crate) fn put_particle(w: &mut Writer, active: &Active, id: Id, p: &Particle) {
    w.u64(id);
    p.put(active, &mut w.0);
}

/// A rigid body's record in a message (beside its spheres, which name it).
pub(crate) fn put_body(w: &mut Writer, b: &Body) {
    w.u64(b.id.first());
    w.u16(b.template);
    w.f64(b.scale);
    w.vec3(b.x);
    w.vec3(b.v);
    w.quat(b.q);
    w.vec3(b.w);
    w.f64(b.mass);
    w.vec3(b.inertia);
    w.u32(b.offsets.len() as u32);
    b.offsets.iter().for_each(|&o| w.vec3(o));
    w.f64(b.bounding_radius);
}

pub(crate) fn get_body(r: &mut Reader) -> Body {
    Body {
        id: BodyId::new(r.u64()),
        template: r.u16(),
        scale: r.f64(),
        x: r.vec3(),
        v: r.vec3(),
        q: r.quat(),
        w: r.vec3(),
        mass: r.f64(),
        inertia: r.vec3(),
        offsets: (0..r.u32()).map(|_| r.vec3()).collect(),
        bounding_radius: r.f64(),
    }
}

pub(crate) fn get_particle(r: &mut Reader, active: &Active) -> (Id, Particle) {
    let id = r.u64();
    (
        id,
        Particle::take(active, &mut r.record(Particle::size(active))),
    )
}

/// A contact's record in a message between processes whose stores hold the optional
/// members `active`: its particle ids (or id and face), then its state.
pub(crate) fn put_entry(w: &mut Writer, active: &ActiveState, (a, b, s): &Entry) {
    w.u64(*a);
    w.u64(*b);
    s.put(active, &mut w.0);
}

pub(crate) fn get_entry(r: &mut Reader, active: &ActiveState) -> Entry {
    let (a, b) = (r.u64(), r.u64());
    (
        a,
        b,
        ContactState::take(active, &mut r.record(ContactState::size(active))),
    )
}

/// The particles of `p` that `pick` picks (storage indices), of every process
/// (collective), in id order, on the processes `reach` names (the others get none);
/// `next_id` that of `p`.
pub(crate) fn gather_by_id(
    (comm, reach): (&dyn Comm, Reach),
    p: &Particles,
    pick: impl Fn(usize) -> bool,
) -> Particles {
    let mut w = Writer::default();
    let picked: Vec<usize> = (0..p.len()).filter(|&i| pick(i)).collect();
    w.u64(picked.len() as u64);
    for &i in &picked {
        put_particle(&mut w, &p.active, p.id[i], &p.get(i));
    }
    // The bodies of the spheres picked (all of a body's spheres, if any).
    let bodies: Vec<usize> = p.bodies_where(&pick).collect();
    w.u64(bodies.len() as u64);
    bodies
        .iter()
        .for_each(|&b| put_body(&mut w, &p.bodies.list[b]));
    let mut all: Vec<(Id, Particle)> = Vec::new();
    let mut all_bodies = Vec::new();
    for m in comm.gather_to(reach, w.0) {
        let mut r = Reader::new(&m);
        for _ in 0..r.u64() {
            all.push(get_particle(&mut r, &p.active));
        }
        for _ in 0..r.u64() {
            all_bodies.push(get_body(&mut r));
        }
    }
    all.sort_unstable_by_key(|e| e.0);
    let mut out = p.empty_like();
    for (id, particle) in all {
        out.insert(id, particle);
    }
    if !all_bodies.is_empty() {
        all_bodies.into_iter().for_each(|b| out.bodies.insert(b));
        out.locate_bodies();
    }
    out
}

/// Every process's lines (collective), process by process.
pub(crate) fn gather_lines(comm: &dyn Comm, mine: Vec<String>) -> Vec<String> {
    let mut w = Writer::default();
    mine.iter().for_each(|l| w.bytes(l.as_bytes()));
    let mut all = Vec::new();
    for m in comm.all_gather(w.0) {
        let mut r = Reader::new(&m);
        while !r.done() {
            all.push(String::from_utf8_lossy(r.bytes()).into_owned());
        }
    }
    all
}

/// `r` if every process's `r` is fine (collective); otherwise the first failing
/// process's error, on every process: one error for the user, and no process left
/// waiting for the others.
pub fn agree<T>(comm: &dyn Comm, r: Result<T>) -> Result<T> {
    let mine = match &r {
        Ok(_) => Vec::new(),
        Err(e) => format!("{e:#}").into_bytes(),
    };
    let all = comm.all_gather(mine);
    match r {
        Err(e) => Err(e),
        Ok(v) => match all.iter().position(|m| !m.is_empty()) {
            None => Ok(v),
            Some(q) => bail!("process {q}: {}", String::from_utf8_lossy(&all[q])),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel::comm::Threads;

    #[test]
    fn bisection_shares_the_points_evenly_and_every_process_agrees() {
        for k in [2usize, 3, 5] {
            let handles: Vec<_> = Threads::group(k)
                .into_iter()
                .map(|c| {
                    std::thread::spawn(move || {
                        // Each process holds a different share of a line of points.
                        let x: Vec<DVec3> = (0..1000)
                            .filter(|i| i % k == c.rank())
                            .map(|i| DVec3::new((i as f64 * 0.37).sin(), i as f64 * 1e-3, 0.0))
                            .collect();
                        let tree = Tree::bisect(&c, &x);
                        let all: Vec<DVec3> = (0..1000)
                            .map(|i| DVec3::new((i as f64 * 0.37).sin(), i as f64 * 1e-3, 0.0))
                            .collect();
                        let mut counts = vec![0; k];
                        all.iter().for_each(|&x| counts[tree.owner(x)] += 1);
                        let mut near = Vec::new();
                        tree.near(all[0], 10.0, &mut near);
                        near.sort();
                        (counts, near)
                    })
                })
                .collect();
            let results: Vec<_> = handles
                .into_iter()
                .map(|h| h.join().expect("ran"))
                .collect();
            for r in &results {
                assert_eq!(r, &results[0], "the processes disagree");
            }
            let (counts, near) = &results[0];
            for &c in counts {
                assert!((c as f64 - 1000.0 / k as f64).abs() <= 2.0, "{counts:?}");
            }
            assert_eq!(near, &(0..k).collect::<Vec<_>>());
        }
    }
}
