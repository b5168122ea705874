//! The split run's side of the simulation (`parallel/domain.rs` holds the decomposition
//! itself): splitting a simulation over processes, its collectives (`any`, `agree`), the
//! redistribution of particles and their contact history at rebuilds, ghosts, spawning and
//! removal over all processes, and the gathers of particles, contacts and snapshots.

use super::*;
use crate::model::bodies::Body as RigidBody;
use crate::neighbours::{Entries, Periodic};
use crate::parallel::comm::{Comm, Reader, Writer};
use crate::parallel::domain::{
    Domain, GHOST_STATE, Placement, REBALANCE, Tree, agree, gather_by_id, get_body, get_entry,
    get_particle, put_body, put_entry, put_particle,
};
use rustc_hash::{FxHashMap, FxHashSet};

/// Every process's contacts (collective), in the order of `Simulation::contact_network`.
pub(crate) fn gather_contacts(comm: &dyn Comm, mine: Vec<ContactRecord>) -> Vec<ContactRecord> {
    let mut w = Writer::default();
    for c in &mine {
        w.u32(c.id);
        match c.with {
            Partner::Particle(j) => {
                w.u8(0);
                w.u64(j as u64);
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
    }
    let mut all = Vec::new();
    for m in comm.all_gather(w.0) {
        let mut r = Reader::new(&m);
        while !r.done() {
            let id = r.u32();
            let with = match (r.u8(), r.u64() as usize) {
                (0, j) => Partner::Particle(j),
                (_, f) => Partner::Face(f),
            };
            all.push(ContactRecord {
                id,
                with,
                point: r.vec3(),
                f_n: r.vec3(),
                f_t: r.vec3(),
                overlap: r.f64(),
            });
        }
    }
    all.sort_by_key(|r| match r.with {
        Partner::Particle(j) => (0, r.id, j),
        Partner::Face(f) => (1, r.id, f),
    });
    all
}

impl Simulation {
    /// Whether this process writes the output: the first of a split run.
    pub fn is_writer(&self) -> bool {
        self.domain.as_ref().is_none_or(|d| d.comm.rank() == 0)
    }

    /// Whether each of `flags` is set on any process (one collective in a split run).
    pub fn any_each<const N: usize>(&self, flags: [bool; N]) -> [bool; N] {
        match &self.domain {
            Some(d) => {
                let counts = d.comm.sum_i64(&flags.map(|f| f as i64));
                std::array::from_fn(|k| counts[k] > 0)
            }
            None => flags,
        }
    }

    /// This process's place among the processes of a split run: (rank, count).
    pub fn process(&self) -> Option<(usize, usize)> {
        self.domain.as_ref().map(|d| d.rank())
    }

    /// [`agree`] over the processes of a split run; `r` in one process.
    pub fn agree<T>(&self, r: Result<T>) -> Result<T> {
        match &self.domain {
            Some(d) => agree(&*d.comm, r),
            None => r,
        }
    }

    /// Whether `flag` is set on any process (collective in a split run).
    pub fn any(&self, flag: bool) -> bool {
        self.domain.as_ref().map_or(flag, |d| d.comm.any(flag))
    }

    /// The number of particles (of all processes: collective in a split run).
    pub fn particle_count(&self) -> usize {
        match &self.domain {
            Some(d) => d.comm.sum_i64(&[d.own_count() as i64])[0] as usize,
            None => self.particles.len(),
        }
    }

    /// The snapshot of a split run (collective): the pieces of all processes, joined
    /// (`checkpoint::join`) as the parts of a stop checkpoint are, so that both give the
    /// same checkpoint. An error if some process's state is not one a checkpoint may hold.
    pub(crate) fn snapshot_split(&self) -> Result<Snapshot> {
        let d = self.domain.as_ref().expect("a split run");
        let mine = super::records::encode(&self.snapshot_piece(), 0);
        let pieces = d
            .comm
            .all_gather(mine)
            .iter()
            .map(|bytes| super::records::decode(bytes, Some(0)))
            .collect::<Result<Vec<_>>>()?;
        super::records::join(pieces)
    }

    /// This process's piece of the state of a split run: its own particles (with their
    /// anchors of the last rebuild), the springs of every contact one of them is in, and the
    /// state all processes share. `checkpoint::join` makes the snapshot of the pieces.
    pub fn snapshot_piece(&self) -> Snapshot {
        let d = self.domain.as_ref().expect("a split run");
        let p = &self.particles;
        let (mut pairs, mut faces) = self.neighbours.entries_by_id(&p.id);
        let (anchors, _) = self.neighbours.anchors();
        let own_ids: FxHashSet<u32> = (0..p.len())
            .filter(|&k| d.owned[k])
            .map(|k| p.id[k])
            .collect();
        let mut own = Particles {
            next_id: p.next_id,
            ..Particles::default()
        };
        let mut own_anchors = Vec::with_capacity(own_ids.len());
        for k in (0..p.len()).filter(|&k| d.owned[k]) {
            own.insert(p.id[k], p.get(k));
            own_anchors.push(anchors.get(k).copied().unwrap_or(p.x[k]));
        }
        for b in p.bodies_where(|k| d.owned[k]) {
            own.bodies.insert(p.bodies.list[b].clone());
        }
        own.locate_bodies();
        pairs.retain(|e| own_ids.contains(&e.0) || own_ids.contains(&e.1));
        faces.retain(|e| own_ids.contains(&e.0));
        Snapshot {
            steps: self.steps,
            built_at: self.built_at,
            particles: own,
            spawner: self.spawner.state(),
            anchors: own_anchors,
            lonely: Vec::new(),
            pair_history: pairs,
            face_history: faces,
            removed: self.removed.clone(),
            wall_sums: self.walls.sums.clone(),
            scenario: self.scenario.to_toml(),
            mesh_files: self.walls.signatures(),
            servos: self.walls.servos(),
        }
    }

    /// Splits this simulation over the processes of `comm`: each process calls it with the
    /// same simulation (all its particles, as made or restored), keeps its share and the
    /// ghosts it needs, and from then on steps together with the others.
    pub fn split(mut self, comm: Box<dyn Comm>) -> Result<Simulation> {
        let (rank, size) = (comm.rank(), comm.size());
        let p = &self.particles;
        // Dealt out by id for a start (a rigid body whole, by its first sphere's).
        let owned = (0..p.len())
            .map(|i| p.body[i].map_or(p.id[i], |b| b.first()) as usize % size == rank)
            .collect();
        self.domain = Some(Domain {
            comm,
            tree: None,
            owned,
            send: Vec::new(),
            recv: Vec::new(),
            cuts: 0,
        });
        self.redistribute(&FxHashSet::default(), Placement::Anchors);
        Ok(self)
    }

    /// This process's share of a split run, if it is one.
    pub fn domain(&self) -> Option<&Domain> {
        self.domain.as_ref()
    }

    /// Whether the particle of id `id` is this process's own (of a split run; in one
    /// process, whether it exists).
    pub fn owns(&self, id: u32) -> bool {
        let p = &self.particles;
        (0..p.len()).any(|i| p.id[i] == id && self.own(i))
    }

    /// Whether the particle stored at `i` is this process's own (always, in one process).
    #[inline]
    pub(crate) fn own(&self, i: usize) -> bool {
        self.domain.as_ref().is_none_or(|d| d.owned[i])
    }

    /// Rebuilds the lists of every process of a split run (collective): the own particles
    /// (but those of ids in `gone`) to the owners of the boxes they are in (the boxes cut
    /// anew when out of balance) with the springs of their contacts, then the ghosts each
    /// process needs, then the lists; all at the particles' places of `placement`.
    pub(crate) fn redistribute(&mut self, gone: &FxHashSet<u32>, placement: Placement) {
        // The anchors of the run in one process, if its lists were built: there the lists
        // are built again, with the mesh and sheared images where they were then, as a
        // checkpoint restores them.
        let anchors = match placement {
            Placement::Now => None,
            Placement::Anchors => {
                let (a, _) = self.neighbours.anchors();
                (a.len() == self.particles.len()).then(|| a.to_vec())
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
        let mut d = self.domain.take().expect("a split run");
        // The old lists and particles go as soon as what they hold is out.
        let springs = self.neighbours.entries_by_id(&self.particles.id);
        self.neighbours.clear_lists();
        let old = std::mem::take(&mut self.particles);
        let periodic = self.neighbours.periodic;
        let (mut held, mut held_at, (pairs, faces)) =
            migrate(&mut d, (old, periodic), anchors, gone, springs);
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
        let at: FxHashMap<u32, u32> = self
            .particles
            .id
            .iter()
            .enumerate()
            .map(|(i, &id)| (id, i as u32))
            .collect();
        let by_id = |mut ids: Vec<u32>| {
            ids.sort_unstable();
            ids.iter().map(|id| at[id]).collect::<Vec<u32>>()
        };
        d.send = ghosts_to.into_iter().map(by_id).collect();
        d.recv = ghosts_from.into_iter().map(by_id).collect();
        d.owned = owned;
        self.domain = Some(d);
        self.built();
        if let Some(now) = now {
            self.wind_on(now);
        }
    }

    /// Stage 1 of a split run (collective): every process draws the same candidates and
    /// tests them against the particles of all processes near the spawn regions; each keeps
    /// the new particles in its box.
    pub(crate) fn spawn_split(&mut self) {
        let s = &self.scenario;
        let p = &self.particles;
        if !self.spawner.active(s, p.next_id, self.time) {
            return;
        }
        let d = self.domain.as_ref().expect("a split run");
        let mut largest = s.geometry.radius_max;
        // How far a clump's spheres reach beyond its centre, which is in the region.
        let mut beyond: f64 = 0.0;
        for r in &s.spawn {
            largest = largest.max(r.radius.largest());
            if let Some(c) = &r.clump {
                beyond = beyond.max(s.clumps[c.template as usize].bounding_radius * c.scale.1);
            }
        }
        let own_max = (0..p.len())
            .filter(|&i| d.owned[i])
            .map(|i| p.radius[i])
            .fold(0.0, f64::max);
        let present = d.comm.max(own_max).max(0.0);
        // Twice the largest radius is the reach of a test; a little more keeps rounding
        // (of images across the sides) from leaving out a particle at that reach.
        let margin = DVec3::splat(2.5 * largest.max(present) + beyond);
        let regions = Spawner::regions(s);
        let in_reach = |x: DVec3| {
            regions
                .iter()
                .any(|r| x.cmpge(r.min - margin).all() && x.cmple(r.max + margin).all())
        };
        // In a periodic domain, also the particles whose images are near (the spawner sees
        // them through the sides).
        let periodic = self.spawner.periodic;
        let mut images = Vec::new();
        let mut near = |x: DVec3| match periodic {
            None => in_reach(x),
            Some(periodic) => {
                let x = periodic.wrap(x);
                periodic.image_shifts(x, margin.x, &mut images);
                in_reach(x) || images.iter().any(|&(s, _)| in_reach(x + s))
            }
        };
        let mut picked: Vec<bool> = (0..p.len()).map(|i| d.owned[i] && near(p.x[i])).collect();
        // A rigid body whole, if any of its spheres is near.
        for b in 0..p.bodies.len() {
            let members = p.bodies.members(b);
            if members.iter().any(|&k| picked[k as usize]) {
                members.iter().for_each(|&k| picked[k as usize] = true);
            }
        }
        let old_next = p.next_id;
        let mut around = gather_by_id(&*d.comm, p, |i| picked[i]);
        self.spawner.spawn(
            s,
            &mut around,
            &self.walls.mesh.faces,
            &self.face_grid,
            self.time,
            present,
        );
        if around.next_id == old_next {
            return;
        }
        let d = self.domain.as_mut().expect("a split run");
        let tree = d.tree.as_ref().expect("cut");
        let me = d.comm.rank();
        let periodic = self.neighbours.periodic;
        // The new particles in this process's box: a rigid body whole, by its centre.
        let at = owner_places(&around, &around.x, periodic);
        for i in (0..around.len()).filter(|&i| around.id[i] >= old_next) {
            if tree.owner(at[i]) == me {
                self.particles.insert(around.id[i], around.get(i));
                d.owned.push(true);
            }
        }
        for b in &around.bodies.list {
            if b.id.first() >= old_next && tree.owner(centre_in_box(b, periodic)) == me {
                self.particles.bodies.insert(b.clone());
            }
        }
        self.particles.locate_bodies();
        self.particles.next_id = around.next_id;
        self.redistribute(&FxHashSet::default(), Placement::Now);
    }

    /// Stage 7 of a split run (collective): the own particles that left, counted over all
    /// processes in id order; then every process rebuilds without them.
    pub(crate) fn remove_split(&mut self, fate: impl Fn(DVec3) -> Option<u32>) {
        let d = self.domain.as_ref().expect("a split run");
        let p = &self.particles;
        let mut w = Writer::default();
        for i in (0..p.len()).filter(|&i| d.owned[i] && p.body[i].is_none()) {
            if let Some(f) = fate(p.x[i]) {
                let density = self.model.densities[p.material[i] as usize];
                w.u32(p.id[i]);
                w.u32(f);
                w.f64(Inertia::mass_with(p.radius[i], density.mass_per_r3));
                w.u32(1);
            }
        }
        // A rigid body goes whole, where its centre of mass goes (as in one process).
        for b in p.bodies_where(|i| d.owned[i]) {
            let b = &p.bodies.list[b];
            if let Some(f) = fate(b.x) {
                w.u32(b.id.first());
                w.u32(f);
                w.f64(b.mass);
                w.u32(b.offsets.len() as u32);
            }
        }
        // (first id, fate, mass, count of ids)
        let mut gone: Vec<(u32, u32, f64, u32)> = Vec::new();
        for m in d.comm.all_gather(w.0) {
            let mut r = Reader::new(&m);
            while !r.done() {
                gone.push((r.u32(), r.u32(), r.f64(), r.u32()));
            }
        }
        if gone.is_empty() {
            return;
        }
        // Counted in id order, as in one process.
        gone.sort_unstable_by_key(|g| g.0);
        for &(_, f, mass, _) in &gone {
            let out: &mut Outflow = match self.removed.outlets.get_mut(f as usize) {
                Some(o) => o,
                None => &mut self.removed.domain,
            };
            out.count += 1;
            out.mass += mass;
        }
        let ids: FxHashSet<u32> = gone.iter().flat_map(|g| g.0..g.0 + g.3).collect();
        self.redistribute(&ids, Placement::Now);
    }

    /// The wall loads of this step over all processes (collective): exact sums, merged.
    pub(crate) fn reduce_walls(&self, step: &mut [Sum6]) {
        let Some(d) = &self.domain else { return };
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
        let p = &self.particles;
        match &self.domain {
            Some(d) => gather_by_id(&*d.comm, p, |i| d.owned[i]),
            None => gather_by_id(&crate::parallel::comm::Solo, p, |_| true),
        }
    }

    /// Bins the faces for particles up to radius `max_radius`.
    pub(crate) fn regrid_faces_for(&mut self, max_radius: f64) {
        self.face_grid = face_grid(&self.walls.mesh.faces, max_radius, self.neighbours.skin);
        self.face_grid_radius = max_radius;
    }
}

/// The boxes cut anew (collective) when the counts of own particles, at `own`, are out of
/// balance (or never cut).
fn recut(d: &mut Domain, own: &[DVec3]) {
    let k = d.comm.size();
    let counts: Vec<u64> = d
        .comm
        .all_gather((own.len() as u64).to_le_bytes().to_vec())
        .iter()
        .map(|c| Reader::new(c).u64())
        .collect();
    let mean = counts.iter().sum::<u64>() as f64 / k as f64;
    let largest = counts.iter().copied().max().unwrap_or(0) as f64;
    if d.tree.is_none() || largest > REBALANCE * mean.max(1.0) {
        d.tree = Some(Tree::bisect(&*d.comm, own));
        d.cuts += 1;
    }
}

/// Own particles of `p` (but those of ids in `gone`) to the owners of the boxes they are
/// in, placed at `anchors` if given (collective; the boxes cut anew first if need be), with
/// the springs of their contacts: the particles this process owns afterwards, their
/// anchors if given, and their springs. A pair's springs go to the owners of both
/// partners, each sent by its partner's old owner (both have the same springs), and are
/// kept once. A rigid body goes whole, with its record, to the owner of its centre.
fn migrate(
    d: &mut Domain,
    (p, periodic): (Particles, Option<Periodic>),
    anchors: Option<Vec<DVec3>>,
    gone: &FxHashSet<u32>,
    entries: Entries,
) -> (Particles, Option<Vec<DVec3>>, Entries) {
    let carry = anchors.is_some();
    // Where each particle is placed: at its anchor, or where it is now.
    let place: std::borrow::Cow<[DVec3]> = match anchors {
        Some(a) => a.into(),
        None => p.x.as_slice().into(),
    };
    let at = owner_places(&p, &place, periodic);
    let own: Vec<DVec3> = (0..p.len())
        .filter(|&i| d.owned[i] && !gone.contains(&p.id[i]))
        .map(|i| at[i])
        .collect();
    recut(d, &own);
    drop(own);
    let d = &*d;
    let to = Destinations::of(d, &p, &at, gone, &entries);
    drop(at);
    let me = d.comm.rank();
    let messages: Vec<Vec<u8>> = (0..d.comm.size())
        .map(|q| match q == me {
            true => Vec::new(), // what stays, stays
            false => to.message(q, &p, carry.then_some(&*place), &entries),
        })
        .collect();
    let mut held = Particles {
        next_id: p.next_id,
        ..Particles::default()
    };
    let mut held_at = carry.then(Vec::new);
    for &i in &to.particles[me] {
        held.insert(p.id[i as usize], p.get(i as usize));
        if let Some(at) = &mut held_at {
            at.push(place[i as usize]);
        }
    }
    for &b in &to.bodies[me] {
        held.bodies.insert(p.bodies.list[b as usize].clone());
    }
    let (pairs, faces) = &entries;
    let mut kept = (
        to.pairs[me].iter().map(|&e| pairs[e]).collect(),
        to.faces[me].iter().map(|&e| faces[e]).collect(),
    );
    drop((place, to, entries));
    drop(p);
    for (q, m) in d.comm.all_to_all(messages).iter().enumerate() {
        if q != me {
            receive(&mut Reader::new(m), &mut held, held_at.as_mut(), &mut kept);
        }
    }
    // A pair whose partners had two owners came from both.
    kept.0.sort_unstable_by_key(|e| (e.0, e.1));
    kept.0.dedup_by_key(|e| (e.0, e.1));
    held.locate_bodies();
    (held, held_at, kept)
}

/// Where each particle of `p` (at `place`) is placed to find its owner: its place, or for
/// a sphere of a rigid body its body's centre of mass ([`centre_in_box`]), so that a body
/// goes whole to the process of its centre.
fn owner_places<'a>(
    p: &Particles,
    place: &'a [DVec3],
    periodic: Option<Periodic>,
) -> std::borrow::Cow<'a, [DVec3]> {
    if p.bodies.is_empty() {
        return place.into();
    }
    let mut at = place.to_vec();
    for (b, body) in p.bodies.list.iter().enumerate() {
        let c = centre_in_box(body, periodic);
        p.bodies.members(b).iter().for_each(|&k| at[k as usize] = c);
    }
    at.into()
}

/// The centre of mass of `body`, put back into a periodic box (a body's centre is never
/// wrapped in the step, as its spheres are at rebuilds): the place that decides its owner.
fn centre_in_box(body: &RigidBody, periodic: Option<Periodic>) -> DVec3 {
    periodic.map_or(body.x, |periodic| periodic.wrap(body.x))
}

/// How far the spheres of this process's bodies of `held` (at `held_at`, or where they
/// are) are from their bodies' centres ([`centre_in_box`]; across periodic sides, the
/// nearest image): a body's owner's box holds its centre, so its spheres are within this
/// of the box, and their partners within this more than a sphere's reach.
fn body_spread(held: &Particles, held_at: Option<&[DVec3]>, periodic: Option<Periodic>) -> f64 {
    let mut spread: f64 = 0.0;
    for (b, body) in held.bodies.list.iter().enumerate() {
        let c = centre_in_box(body, periodic);
        for &k in held.bodies.members(b) {
            let a = held_at.map_or(held.x[k as usize], |at| at[k as usize]);
            let a = periodic.map_or(a, |periodic| a + periodic.image_towards(a, c).0);
            spread = spread.max(a.distance(c));
        }
    }
    spread
}

/// Where [`migrate`] sends each own particle (by index) and the springs of each contact
/// (by entry), per process.
struct Destinations {
    particles: Vec<Vec<u32>>,
    /// Rigid bodies (indices in `bodies.list`).
    bodies: Vec<Vec<u32>>,
    pairs: Vec<Vec<usize>>,
    faces: Vec<Vec<usize>>,
}

impl Destinations {
    /// To the owner of the box each kept own particle of `p` is placed in (at `place`):
    /// the particle, its contacts with faces, and its contacts with particles of higher id
    /// (to the owners of both partners); a rigid body's record to the owner of its spheres.
    fn of(
        d: &Domain,
        p: &Particles,
        place: &[DVec3],
        gone: &FxHashSet<u32>,
        (pairs, faces): &Entries,
    ) -> Destinations {
        let k = d.comm.size();
        let index: FxHashMap<u32, u32> =
            p.id.iter()
                .enumerate()
                .map(|(i, &id)| (id, i as u32))
                .collect();
        let tree = d.tree.as_ref().expect("cut");
        let owner = |id: u32| tree.owner(place[index[&id] as usize]);
        let mine = |id: u32| d.owned[index[&id] as usize];
        let mut to = Destinations {
            particles: vec![Vec::new(); k],
            bodies: vec![Vec::new(); k],
            pairs: vec![Vec::new(); k],
            faces: vec![Vec::new(); k],
        };
        for i in (0..p.len()).filter(|&i| d.owned[i] && !gone.contains(&p.id[i])) {
            to.particles[tree.owner(place[i])].push(i as u32);
        }
        for b in p.bodies_where(|i| d.owned[i] && !gone.contains(&p.id[i])) {
            let first = p.bodies.members(b)[0] as usize;
            to.bodies[tree.owner(place[first])].push(b as u32);
        }
        // A pair's springs go from the owner of each partner to where that partner goes
        // (only its owner knows: a ghost body's centre is that of the last rebuild); the
        // copies are the same bits, and [`migrate`] keeps one.
        for (e, &(a, b, _)) in pairs.iter().enumerate() {
            if gone.contains(&a) || gone.contains(&b) {
                continue;
            }
            let qa = mine(a).then(|| owner(a));
            let qb = mine(b).then(|| owner(b)).filter(|&qb| Some(qb) != qa);
            qa.into_iter().chain(qb).for_each(|q| to.pairs[q].push(e));
        }
        for (e, &(a, _, _)) in faces.iter().enumerate() {
            if !gone.contains(&a) && mine(a) {
                to.faces[owner(a)].push(e);
            }
        }
        to
    }

    /// What goes to process `q`: its particles (with their places if `place`), its rigid
    /// bodies, then its springs of pairs and of contacts with faces, each list after its
    /// length.
    fn message(
        &self,
        q: usize,
        p: &Particles,
        place: Option<&[DVec3]>,
        (pairs, faces): &Entries,
    ) -> Vec<u8> {
        let mut w = Writer::default();
        w.u64(self.particles[q].len() as u64);
        for &i in &self.particles[q] {
            put_particle(&mut w, p.id[i as usize], &p.get(i as usize));
            if let Some(place) = place {
                w.vec3(place[i as usize]);
            }
        }
        w.u64(self.bodies[q].len() as u64);
        for &b in &self.bodies[q] {
            put_body(&mut w, &p.bodies.list[b as usize]);
        }
        w.u64(self.pairs[q].len() as u64);
        self.pairs[q]
            .iter()
            .for_each(|&e| put_entry(&mut w, &pairs[e]));
        w.u64(self.faces[q].len() as u64);
        self.faces[q]
            .iter()
            .for_each(|&e| put_entry(&mut w, &faces[e]));
        w.0
    }
}

/// Adds what a [`Destinations::message`] holds to the particles `held` (and their places to
/// `held_at`, if carried) and the springs `kept`.
fn receive(
    r: &mut Reader,
    held: &mut Particles,
    mut held_at: Option<&mut Vec<DVec3>>,
    (pairs, faces): &mut Entries,
) {
    for _ in 0..r.u64() {
        let (id, particle) = get_particle(r);
        held.insert(id, particle);
        if let Some(at) = held_at.as_mut() {
            at.push(r.vec3());
        }
    }
    for _ in 0..r.u64() {
        held.bodies.insert(get_body(r));
    }
    for _ in 0..r.u64() {
        pairs.push(get_entry(r));
    }
    for _ in 0..r.u64() {
        faces.push(get_entry(r));
    }
}

/// Ghosts: copies of own particles (all `held` holds) for the processes whose boxes are
/// within reach of them or, across periodic sides, of their images (collective); `reach`
/// is the largest radius of all processes, the skin and the periodic sides. A rigid body
/// goes whole, with its record, to every process one of its spheres is within reach of.
/// Returns the ids sent to and received from each process.
fn exchange_ghosts(
    d: &Domain,
    held: &mut Particles,
    held_at: &mut Option<Vec<DVec3>>,
    reach: (f64, f64, Option<Periodic>),
) -> (Vec<Vec<u32>>, Vec<Vec<u32>>) {
    let k = d.comm.size();
    let (ghosts_to, bodies_to) = ghost_destinations(d, held, held_at.as_deref(), reach);
    let messages: Vec<Vec<u8>> = (0..k)
        .map(|q| {
            let mut w = Writer::default();
            w.u64(ghosts_to[q].len() as u64);
            for &i in &ghosts_to[q] {
                put_particle(&mut w, held.id[i as usize], &held.get(i as usize));
                if let Some(at) = held_at.as_ref() {
                    w.vec3(at[i as usize]);
                }
            }
            w.u64(bodies_to[q].len() as u64);
            for &b in &bodies_to[q] {
                put_body(&mut w, &held.bodies.list[b as usize]);
            }
            w.0
        })
        .collect();
    let ghosts_to: Vec<Vec<u32>> = ghosts_to
        .into_iter()
        .map(|list| list.into_iter().map(|i| held.id[i as usize]).collect())
        .collect();
    let mut ghosts_from: Vec<Vec<u32>> = vec![Vec::new(); k];
    for (q, m) in d.comm.all_to_all(messages).into_iter().enumerate() {
        let mut r = Reader::new(&m);
        for _ in 0..r.u64() {
            let (id, particle) = get_particle(&mut r);
            held.insert(id, particle);
            if let Some(at) = held_at.as_mut() {
                at.push(r.vec3());
            }
            ghosts_from[q].push(id);
        }
        for _ in 0..r.u64() {
            held.bodies.insert(get_body(&mut r));
        }
    }
    (ghosts_to, ghosts_from)
}

/// Which own particles of `held` (storage indices) go as ghosts to each process, and which
/// rigid bodies (indices in `bodies.list`): those within `r_i + r_max + skin` of its box,
/// or whose images are, and more by the spread of the bodies ([`body_spread`], the
/// largest of all processes): an own sphere may lie that far outside the box.
fn ghost_destinations(
    d: &Domain,
    held: &Particles,
    held_at: Option<&[DVec3]>,
    (r_max, skin, periodic): (f64, f64, Option<Periodic>),
) -> (Vec<Vec<u32>>, Vec<Vec<u32>>) {
    let (me, k) = (d.comm.rank(), d.comm.size());
    let tree = d.tree.as_ref().expect("cut");
    let spread = d.comm.max(body_spread(held, held_at, periodic)).max(0.0);
    let mut ghosts_to: Vec<Vec<u32>> = vec![Vec::new(); k];
    let mut bodies_to: Vec<Vec<u32>> = vec![Vec::new(); k];
    let (mut near, mut images, mut to) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..held.len() {
        let x = held_at.map_or(held.x[i], |at| at[i]);
        let reach = held.radius[i] + r_max + skin + spread;
        to.clear();
        tree.near(x, reach, &mut near);
        to.extend_from_slice(&near);
        if let Some(periodic) = periodic {
            periodic.image_shifts(x, reach, &mut images);
            for &(s, _) in &images {
                tree.near(x + s, reach, &mut near);
                to.extend_from_slice(&near);
            }
        }
        to.sort_unstable();
        to.dedup();
        for &q in to.iter().filter(|&&q| q != me) {
            match held.body[i] {
                None => ghosts_to[q].push(i as u32),
                Some(b) => bodies_to[q].push(held.bodies.index_of(b).expect("held") as u32),
            }
        }
    }
    // A body whole, once.
    for (q, bodies) in bodies_to.iter_mut().enumerate() {
        bodies.sort_unstable();
        bodies.dedup();
        for &b in bodies.iter() {
            ghosts_to[q].extend_from_slice(held.bodies.members(b as usize));
        }
    }
    (ghosts_to, bodies_to)
}

/// Stage 5c of a split run (collective): sends the new states of own particles of `p` to
/// the processes of `d` that hold them as ghosts, and takes theirs.
pub(super) fn refresh_ghosts(d: &Domain, p: &mut Particles) {
    let messages: Vec<(usize, Vec<u8>)> = d
        .send
        .iter()
        .enumerate()
        .filter(|(_, list)| !list.is_empty())
        .map(|(q, list)| {
            let mut w = Writer(Vec::with_capacity(list.len() * GHOST_STATE));
            for &i in list {
                let i = i as usize;
                w.vec3(p.x[i]);
                w.vec3(p.v[i]);
                w.quat(p.q[i]);
                w.vec3(p.w[i]);
                w.u32(p.tag[i]);
            }
            (q, w.0)
        })
        .collect();
    // Only the processes that hold ghosts of ours, or ours of theirs, hear from us.
    let from: Vec<(usize, usize)> = (0..d.recv.len())
        .filter(|&q| !d.recv[q].is_empty())
        .map(|q| (q, d.recv[q].len() * GHOST_STATE))
        .collect();
    for (m, &(q, _)) in d.comm.exchange(messages, &from).iter().zip(&from) {
        let mut r = Reader::new(m);
        for &i in &d.recv[q] {
            let i = i as usize;
            p.x[i] = r.vec3();
            p.v[i] = r.vec3();
            p.q[i] = r.quat();
            p.w[i] = r.vec3();
            p.tag[i] = r.u32();
        }
    }
}
