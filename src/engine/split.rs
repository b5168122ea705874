//! The split run's side of the simulation (`parallel/decomposition.rs` holds the decomposition
//! itself): splitting a simulation over processes, its collectives (`any`, `agree`), the
//! redistribution of particles and their contact history at rebuilds, ghosts, spawning and
//! removal over all processes, and the gathers of particles, contacts and snapshots.

use super::*;
use crate::engine::regions::Gone;
use crate::model::bodies::Body as RigidBody;
use crate::neighbours::{Entries, Periodic};
use crate::parallel::comm::{Comm, Reach, Reader, Writer};
use crate::parallel::decomposition::{
    Placement, REBALANCE, Share, Tree, agree, gather_by_id, get_body, get_entry, get_particle,
    put_body, put_entry, put_particle,
};
use rustc_hash::{FxHashMap, FxHashSet};

mod moves;
pub(super) use moves::{centre_in_box, owner_places};
use moves::{exchange_ghosts, migrate};

/// Every process's contacts (collective), in the order of `Simulation::contact_network`.
/// on the processes `reach` names (the others get none).
pub(crate) fn gather_contacts(
    (comm, reach): (&dyn Comm, Reach),
    mine: Vec<ContactRecord>,
) -> Vec<ContactRecord> {
    let mut w = Writer::default();
    for c in &mine {
        w.u64(c.id);
        match c.with {
            Partner::Particle(j) => {
                w.u8(0);
                w.u64(j);
            }
            Partner::Face(f) => {
                w.u8(1);
                w.u64(f as u64);
            }
        }
        w.vec3(c.point);
        w.vec3(c.f_n);
        w.vec3(c.f_t);
        w.f64(c.overlap);
        w.vec3(c.tau_i);
        w.vec3(c.tau_j);
    }
    let mut all = Vec::new();
    for m in comm.gather_to(reach, w.0) {
        let mut r = Reader::new(&m);
        while !r.done() {
            let id = r.u64();
            let with = match (r.u8(), r.u64()) {
                (0, j) => Partner::Particle(j),
                (_, f) => Partner::Face(f as usize),
            };
            all.push(ContactRecord {
                id,
                with,
                point: r.vec3(),
                f_n: r.vec3(),
                f_t: r.vec3(),
                overlap: r.f64(),
                tau_i: r.vec3(),
                tau_j: r.vec3(),
            });
        }
    }
    all.sort_by_key(ContactRecord::network_order);
    all
}

impl Simulation {
    /// Whether this process writes the output: the first of a split run.
    pub fn is_writer(&self) -> bool {
        self.share.as_ref().is_none_or(|d| d.comm.rank() == 0)
    }

    /// Whether each of `flags` is set on any process (one collective in a split run).
    pub fn any_each<const N: usize>(&self, flags: [bool; N]) -> [bool; N] {
        match &self.share {
            Some(d) => {
                let counts = d.comm.sum_i64(&flags.map(|f| f as i64));
                std::array::from_fn(|k| counts[k] > 0)
            }
            None => flags,
        }
    }

    /// This process's place among the processes of a split run: (rank, count).
    pub fn process(&self) -> Option<(usize, usize)> {
        self.share.as_ref().map(|d| d.rank())
    }

    /// [`agree`] over the processes of a split run; `r` in one process.
    pub fn agree<T>(&self, r: Result<T>) -> Result<T> {
        match &self.share {
            Some(d) => agree(&*d.comm, r),
            None => r,
        }
    }

    /// Whether `flag` is set on any process (collective in a split run).
    pub fn any(&self, flag: bool) -> bool {
        self.share.as_ref().map_or(flag, |d| d.comm.any(flag))
    }

    /// The number of particles (of all processes: collective in a split run).
    pub fn particle_count(&self) -> usize {
        match &self.share {
            Some(d) => d.comm.sum_i64(&[d.own_count() as i64])[0] as usize,
            None => self.particles.len(),
        }
    }

    /// Splits this simulation over the processes of `comm`: each process calls it with the
    /// same simulation (all its particles, as made or restored), keeps its share and the
    /// ghosts it needs, and from then on steps together with the others.
    pub fn split(self, comm: Box<dyn Comm>) -> Result<Simulation> {
        let (rank, size) = (comm.rank(), comm.size());
        let p = &self.particles;
        // Dealt out by id for a start (a rigid body whole, by its first sphere's).
        let owned = (0..p.len())
            .map(|i| p.body[i].map_or(p.id[i], |b| b.first()) as usize % size == rank)
            .collect();
        self.split_owning(comm, owned, Entries::default())
    }

    /// Splits a simulation of which each process of `comm` holds a share (of the initial
    /// particles, read by `io::inputs::read_share`), none twice: each starts as the owner
    /// of what it holds, and from then on they step together.
    pub fn split_shares(self, comm: Box<dyn Comm>) -> Result<Simulation> {
        self.split_shares_with(comm, Entries::default())
    }

    /// [`Simulation::split_shares`] of a share of a checkpoint's parts
    /// (`Simulation::restore_share`), with the springs of its particles' contacts with
    /// particles of other shares (`pending`), which go to the owners with the particles.
    pub fn split_shares_with(self, comm: Box<dyn Comm>, pending: Entries) -> Result<Simulation> {
        let owned = vec![true; self.particles.len()];
        self.split_owning(comm, owned, pending)
    }

    /// Splits this simulation, this process owning the particles `owned` says at first.
    fn split_owning(
        mut self,
        comm: Box<dyn Comm>,
        owned: Vec<bool>,
        pending: Entries,
    ) -> Result<Simulation> {
        self.share = Some(Share {
            comm,
            tree: None,
            owned,
            send: Vec::new(),
            recv: Vec::new(),
            cuts: 0,
        });
        self.redistribute_with(&FxHashSet::default(), Placement::Anchors, pending);
        Ok(self)
    }

    /// This process's share of a split run, if it is one.
    pub fn share(&self) -> Option<&Share> {
        self.share.as_ref()
    }

    /// Whether the particle of id `id` is this process's own (of a split run; in one
    /// process, whether it exists).
    pub fn owns(&self, id: Id) -> bool {
        let p = &self.particles;
        (0..p.len()).any(|i| p.id[i] == id && self.own(i))
    }

    /// The ids of this process's own particles, in a split run.
    pub(crate) fn own_ids(&self) -> Option<FxHashSet<Id>> {
        let d = self.share.as_ref()?;
        let p = &self.particles;
        Some(
            (0..p.len())
                .filter(|&k| d.owned[k])
                .map(|k| p.id[k])
                .collect(),
        )
    }

    /// Whether the particle stored at `i` is this process's own (always, in one process).
    #[inline]
    pub(crate) fn own(&self, i: usize) -> bool {
        self.share.as_ref().is_none_or(|d| d.owned[i])
    }

    /// Rebuilds the lists of every process of a split run (collective): the own particles
    /// (but those of ids in `gone`) to the owners of the boxes they are in (the boxes cut
    /// anew when out of balance) with the springs of their contacts, then the ghosts each
    /// process needs, then the lists; all at the particles' places of `placement`.
    pub(crate) fn redistribute(&mut self, gone: &FxHashSet<Id>, placement: Placement) {
        self.redistribute_with(gone, placement, Entries::default());
    }

    /// [`Simulation::redistribute`], with springs beside the lists' (`pending`: of contacts
    /// with particles this process does not hold) carried to their owners too.
    fn redistribute_with(&mut self, gone: &FxHashSet<Id>, placement: Placement, pending: Entries) {
        // The anchors of the run in one process, if its lists were built: there the lists
        // are built again, with the mesh and sheared images where they were then, as a
        // checkpoint restores them.
        let anchors = match placement {
            Placement::Now => None,
            Placement::Anchors => {
                // (Decided together: a process that holds nothing has all its anchors.)
                let (a, _) = self.neighbours.anchors();
                let anchored = a.len() == self.particles.len();
                (!self.any(!anchored)).then(|| a.to_vec())
            }
        };
        // Carried along with the particles, if any.
        let carry = anchors.is_some();
        let now = carry.then(|| self.rewind_to(self.built_at));
        if let (Placement::Now, Some(periodic)) = (placement, self.neighbours.periodic) {
            // As at a rebuild in one process: the particles put back into the box (the
            // ghosts too, as their owners do, so that every process places them alike).
            let p = &mut self.particles;
            for (x, v) in p.x.iter_mut().zip(p.v.iter_mut()) {
                (*x, *v) = periodic.wrap_state(*x, *v);
            }
        }
        let mut d = self.share.take().expect("a split run");
        // The old lists and particles go as soon as what they hold is out; the loads too.
        self.loads = Vec::new();
        let mut springs = self.neighbours.entries_by_id(&self.particles.id);
        springs.0.extend(pending.0);
        springs.1.extend(pending.1);
        self.neighbours.clear_lists();
        let old = std::mem::take(&mut self.particles);
        let periodic = self.neighbours.periodic;
        let (mut held, mut held_at, (pairs, faces)) = migrate(
            &mut d,
            (old, periodic),
            anchors,
            gone,
            (springs, self.neighbours.state),
        );
        let n_own = held.len();
        let r_max = d.comm.max(held.max_radius()).max(0.0);
        let reach = (r_max, self.neighbours.skin, self.neighbours.periodic);
        let (ghosts_to, ghosts_from) = exchange_ghosts(&d, &mut held, &mut held_at, reach);
        held.locate_bodies();
        let mut owned: Vec<bool> = (0..held.len()).map(|i| i < n_own).collect();
        // The lists, with the faces binned for the largest particle of all processes.
        self.particles = held;
        let max_radius = self.scenario.geometry.radius_max.max(r_max);
        if self.walls.move_at_all() || max_radius > self.face_grid_radius {
            self.regrid_faces_for(max_radius);
        }
        let order = self.neighbours.rebuild_from(
            &mut self.particles,
            held_at,
            &pairs,
            &faces,
            &self.walls.mesh.faces,
            &self.face_grid,
        );
        if placement == Placement::Anchors && !carry {
            // Never built in one process: stale at the first step, as there.
            self.neighbours.forget_anchors();
        }
        owned = order.iter().map(|&o| owned[o as usize]).collect();
        let at: FxHashMap<Id, u32> = self
            .particles
            .id
            .iter()
            .enumerate()
            .map(|(i, &id)| (id, i as u32))
            .collect();
        let by_id = |mut ids: Vec<Id>| {
            ids.sort_unstable();
            ids.iter().map(|id| at[id]).collect::<Vec<u32>>()
        };
        d.send = ghosts_to.into_iter().map(by_id).collect();
        d.recv = ghosts_from.into_iter().map(by_id).collect();
        d.owned = owned;
        self.share = Some(d);
        self.built();
        if let Some(now) = now {
            self.wind_on(now);
        }
    }

    /// The wall loads of this step over all processes (collective): exact sums, merged.
    pub(crate) fn reduce_walls(&self, step: &mut [Sum6]) {
        let Some(d) = &self.share else { return };
        let words: Vec<i64> = step.iter().flat_map(|s| s.words()).collect();
        let total = d.comm.sum_i64(&words);
        for (s, w) in step.iter_mut().zip(total.chunks(12)) {
            *s = Sum6::from_words(w.try_into().expect("12 words"));
            s.carry();
        }
    }

    /// All particles of a split run, in id order, on every process (collective); this
    /// process's particles in one.
    pub fn gather_particles(&self) -> Particles {
        self.gather_particles_to(Reach::Everyone)
    }

    /// [`Simulation::gather_particles`] on the processes `reach` names (collective); the
    /// others get none.
    pub(crate) fn gather_particles_to(&self, reach: Reach) -> Particles {
        let p = &self.particles;
        match &self.share {
            Some(d) => gather_by_id((&*d.comm, reach), p, |i| d.owned[i]),
            None => gather_by_id((&crate::parallel::comm::Solo, reach), p, |_| true),
        }
    }

    /// Bins the faces for particles up to radius `max_radius`.
    pub(crate) fn regrid_faces_for(&mut self, max_radius: f64) {
        self.face_grid = FaceGrid::of(&self.walls.mesh.faces, max_radius, self.neighbours.skin);
        self.face_grid_radius = max_radius;
    }
}

/// Stage 5c of a split run (collective): sends the new states of own particles of `p` to
/// the processes of `d` that hold them as ghosts, and takes theirs.
pub(super) fn refresh_ghosts(d: &Share, p: &mut Particles) {
    let messages: Vec<(usize, Vec<u8>)> = d
        .send
        .iter()
        .enumerate()
        .filter(|(_, list)| !list.is_empty())
        .map(|(q, list)| {
            let mut out = Vec::with_capacity(list.len() * p.ghost_state_size());
            list.iter()
                .for_each(|&i| p.put_ghost_state(i as usize, &mut out));
            (q, out)
        })
        .collect();
    // Only the processes that hold ghosts of ours, or ours of theirs, hear from us.
    let from: Vec<(usize, usize)> = (0..d.recv.len())
        .filter(|&q| !d.recv[q].is_empty())
        .map(|q| (q, d.recv[q].len() * p.ghost_state_size()))
        .collect();
    for (m, &(q, _)) in d.comm.exchange(messages, &from).iter().zip(&from) {
        let mut bytes = &m[..];
        d.recv[q]
            .iter()
            .for_each(|&i| p.take_ghost_state(i as usize, &mut bytes));
    }
}

/// The grains `gone` of every process (collective), in the order of the ranks.
pub(super) fn all_gone(d: &Share, gone: &[Gone]) -> Vec<Gone> {
    let mut w = Writer::default();
    for g in gone {
        w.u64(g.first);
        w.u32(g.fate);
        w.f64(g.mass);
        w.u64(g.ids);
    }
    let mut all = Vec::new();
    for m in d.comm.all_gather(w.0) {
        let mut r = Reader::new(&m);
        while !r.done() {
            let (first, fate, mass, ids) = (r.u64(), r.u32(), r.f64(), r.u64());
            all.push(Gone {
                first,
                fate,
                mass,
                ids,
            });
        }
    }
    all
}
