//! The simulation: state and the time step as named stages.
//!
//! ```text
//! step:  move meshes -> spawn -> update neighbours -> particle contacts -> mesh contacts
//!        -> integrate -> tag -> exchange (split runs) -> check stability -> remove
//! ```

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Result, bail};
use glam::DVec3;
use rayon::prelude::*;

pub use crate::engine::records::{ContactRecord, Outflow, Partner, Removed, Snapshot, Wrench};
use crate::geometry::mesh::{Contacts, Face, Mesh};
use crate::model::contact::{
    Body, Coefficients, ContactLaw, ContactParts, Kinematics, Models, Other, with_models,
};
use crate::model::exact::{Scale, Scales8, Sum6, pack};
use crate::model::heat::HeatModel;
use crate::model::integrate::{Density, Inertia, Response, State, advance};
use crate::model::lanes::{Gather, Lanes};
use crate::model::ledger::{Entry as LedgerEntry, WALL};
use crate::model::motion::{Motion, Pose, RigidVelocity};
use crate::model::particles::{Id, Particles};
use crate::model::servo;
use crate::neighbours::{
    ContactList, Entries, Entry, FACE_BLOCK, FaceGrid, Histories, History, IdIndex,
    MIN_PARALLEL_LEN, NONE, Neighbours, Store, cut,
};
use crate::parallel::decomposition::Share;

mod advance;
mod bodies;
mod checks;
mod edit;
pub use edit::{DEEPEST_ADDED, Overlap};
mod faces;
mod heat;
mod ledger;
mod loads;
#[cfg(test)]
mod open_core_tests;
mod pairs;
pub mod records;
mod regions;
mod report;
pub mod setup;
mod snapshot;
pub mod spawn;
mod spawning;
mod split;
mod walls;
use crate::engine::spawn::{Spawner, SpawnerState};
use crate::geometry::surface::{self, Candidate, Fate};
use crate::model::springs::Springs;
use crate::scenario::{Scenario, TagRegion};
use loads::Load;
pub use loads::LoadScales;
use walls::Drive;
pub use walls::{MeshFile, Walls};

/// Contacts per group evaluated together: 8 doubles fill an AVX-512 register, two AVX ones.
const WIDTH: usize = 8;
type Group = wide::f64x8;

/// The clock and servos of a simulation rewound to its last rebuild.
pub(crate) struct Rewound {
    steps: u64,
    time: f64,
    servos: Vec<(u32, servo::State)>,
}

/// The constants the stages compute with: the contact law of the scenario's materials,
/// each material's density quotients and the resolutions of the loads' sums.
pub(crate) struct Model {
    pub(crate) law: ContactLaw,
    pub(crate) densities: Vec<Density>,
    pub(crate) scales: LoadScales,
    /// Heat transfer, if the scenario's materials conduct, make or exchange heat; with
    /// the walls' temperatures and conductivities.
    pub(crate) heat: Option<(HeatModel, heat::WallHeat)>,
}

impl Model {
    /// The mass of particle `k` of `p` (of its body, for a sphere of a rigid body).
    fn mass(&self, p: &Particles, k: usize) -> f64 {
        if p.body[k].is_some() {
            return p.bodies.mass_at(k);
        }
        Inertia::mass_with(
            p.radius[k],
            self.densities[p.material[k] as usize].mass_per_r3,
        )
    }
}

/// The masses `m` of the particles `idx` of `p` in lanes, with those of the spheres of
/// rigid bodies replaced by their body's: a clump's sphere enters the contact law with the
/// clump's mass.
#[inline(always)]
fn body_masses(p: &Particles, idx: &[usize; WIDTH], m: Group) -> Group {
    if p.bodies.is_empty() {
        return m;
    }
    let mut m = m.scatter();
    for (l, &k) in idx.iter().enumerate() {
        if p.body[k].is_some() {
            m[l] = p.bodies.mass_at(k);
        }
    }
    Group::gather(m)
}

/// What the contact stages of a step find beside the loads, for the stability check: the
/// overlaps deeper than the smaller radius, and whether a load left the range of its
/// exact sum (or was not finite).
#[derive(Default)]
pub(super) struct Findings {
    deep: Vec<Deep>,
    beyond_range: bool,
}

impl Findings {
    fn merge(&mut self, other: Findings) {
        self.deep.extend(other.deep);
        self.beyond_range |= other.beyond_range;
    }
}

/// [`Findings`] as the parallel tasks of a contact stage collect them.
#[derive(Default)]
struct Found {
    deep: Mutex<Vec<Deep>>,
    beyond: AtomicBool,
    /// The ledger's entries, if it is kept.
    entries: Option<Mutex<Vec<LedgerEntry>>>,
}

impl Found {
    /// Findings to collect, with the ledger's entries after those of `ledger` if it is
    /// kept (taken, to be given back by [`Found::into_inner`]: its room stays).
    fn new(ledger: Option<&mut Vec<LedgerEntry>>) -> Found {
        Found {
            entries: ledger.map(|e| Mutex::new(std::mem::take(e))),
            ..Found::default()
        }
    }

    /// Keeps the ledger's entries `e` (if it is kept).
    fn enter(&self, e: impl FnOnce() -> ([LedgerEntry; WIDTH], usize)) {
        if let Some(entries) = &self.entries {
            let (e, n) = e();
            entries
                .lock()
                .expect("not poisoned")
                .extend_from_slice(&e[..n]);
        }
    }

    /// What was found, and the ledger's entries back into `ledger`.
    fn into_inner(self, ledger: Option<&mut Vec<LedgerEntry>>) -> Findings {
        if let (Some(entries), Some(ledger)) = (self.entries, ledger) {
            *ledger = entries.into_inner().expect("not poisoned");
        }
        Findings {
            deep: self.deep.into_inner().expect("not poisoned"),
            beyond_range: self.beyond.into_inner(),
        }
    }
}

/// A block of owners `owners` of a contact list: their loads, and the contacts of their
/// slots (which start at slot `first`) with the block's store.
struct Block<'a> {
    owners: std::ops::Range<usize>,
    first: usize,
    loads: &'a mut [Load],
    contact: &'a mut [u32],
    store: &'a mut Store,
}

/// The blocks of a contact list (its run starts `start`, owner bounds `bounds` of its blocks,
/// its slots' `contact` and its `stores`), each with the `loads` of its owners.
fn blocks<'a>(
    bounds: &[u32],
    loads: &'a mut [Load],
    start: &[u32],
    contact: &'a mut [u32],
    stores: &'a mut [Store],
) -> Vec<Block<'a>> {
    let owners: Vec<usize> = bounds.iter().map(|&o| o as usize).collect();
    let slots: Vec<usize> = owners.iter().map(|&o| start[o] as usize).collect();
    cut(loads, &owners)
        .into_iter()
        .zip(cut(contact, &slots))
        .zip(stores.iter_mut())
        .enumerate()
        .map(|(k, ((loads, contact), store))| Block {
            owners: owners[k]..owners[k + 1],
            first: slots[k],
            loads,
            contact,
            store,
        })
        .collect()
}

/// The springs of store entries `c` in the lanes of a group.
#[inline(always)]
fn gather_springs(store: &Store, c: [u32; WIDTH]) -> Springs<Group> {
    let (mut u_s, mut u_r, mut u_t) = ([DVec3::ZERO; WIDTH], [DVec3::ZERO; WIDTH], [0.0; WIDTH]);
    for l in 0..WIDTH {
        let s = &store.state.springs[c[l] as usize];
        (u_s[l], u_r[l], u_t[l]) = (s.u_s, s.u_r, s.u_t);
    }
    Springs {
        u_s: Group::gather_vec(u_s),
        u_r: Group::gather_vec(u_r),
        u_t: Group::gather(u_t),
    }
}

/// Puts the springs of a group's lanes back into store entries `c` (the first `c.len()`
/// lanes).
#[inline(always)]
fn scatter_springs(lanes: Springs<Group>, store: &mut Store, c: &[u32]) {
    #[cfg(test)]
    open_core_tests::touch(store, c);
    let (u_s, u_r, u_t) = (
        Group::scatter_vec(lanes.u_s),
        Group::scatter_vec(lanes.u_r),
        lanes.u_t.scatter(),
    );
    for (l, &c) in c.iter().enumerate() {
        store.state.springs[c as usize] = Springs {
            u_s: u_s[l],
            u_r: u_r[l],
            u_t: u_t[l],
        };
    }
}

/// The stages of a step, for the timing breakdown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    MoveMeshes,
    Spawn,
    Neighbours,
    ParticleContacts,
    MeshContacts,
    Heat,
    Bodies,
    Integrate,
    Tag,
    Exchange,
    Ledger,
    Stability,
    Remove,
}

impl Stage {
    pub const ALL: [Stage; 13] = [
        Stage::MoveMeshes,
        Stage::Spawn,
        Stage::Neighbours,
        Stage::ParticleContacts,
        Stage::MeshContacts,
        Stage::Heat,
        Stage::Bodies,
        Stage::Integrate,
        Stage::Tag,
        Stage::Exchange,
        Stage::Ledger,
        Stage::Stability,
        Stage::Remove,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Stage::MoveMeshes => "move meshes",
            Stage::Spawn => "spawn",
            Stage::Neighbours => "neighbour lists",
            Stage::ParticleContacts => "particle contacts",
            Stage::MeshContacts => "mesh contacts",
            Stage::Heat => "heat",
            Stage::Bodies => "rigid bodies",
            Stage::Integrate => "integrate",
            Stage::Tag => "tag",
            Stage::Exchange => "exchange",
            Stage::Ledger => "energy ledger",
            Stage::Stability => "stability check",
            Stage::Remove => "remove",
        }
    }
}

/// Wall time spent in each stage of the step so far \[s\].
#[derive(Clone, Debug, Default)]
pub struct StageTimes {
    seconds: [f64; Stage::ALL.len()],
}

impl StageTimes {
    fn add(&mut self, stage: Stage, since: Instant) -> Instant {
        let now = Instant::now();
        self.seconds[stage as usize] += (now - since).as_secs_f64();
        now
    }

    /// Seconds spent in `stage`.
    pub fn of(&self, stage: Stage) -> f64 {
        self.seconds[stage as usize]
    }

    /// Seconds spent in all stages.
    pub fn total(&self) -> f64 {
        self.seconds.iter().sum()
    }
}

/// What a particle overlaps too deeply: another particle (its storage index) or a face.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Against {
    Particle(usize),
    Face(usize),
}

/// An overlap deeper than `limit`, the smaller radius (the particle's, against a face):
/// a warning; deeper than twice that, a sign of instability.
#[derive(Clone, Copy, Debug)]
pub struct Deep {
    /// The particle's storage index.
    i: usize,
    other: Against,
    delta: f64,
    limit: f64,
}

impl Deep {
    /// Whether the overlap passes the smaller diameter: the smaller body is wholly inside
    /// the other, which no transient of a stable run does.
    fn through(&self) -> bool {
        self.delta > 2.0 * self.limit
    }

    /// "particles 1 and 2 overlap by ..., more than the smaller radius ..." (or diameter),
    /// naming the particles by their `ids`.
    fn describe(&self, ids: &[Id]) -> String {
        let (bound, size) = if self.through() {
            ("diameter", 2.0 * self.limit)
        } else {
            ("radius", self.limit)
        };
        let i = ids[self.i];
        match self.other {
            Against::Particle(j) => {
                let j = ids[j];
                let (a, b) = (i.min(j), i.max(j));
                format!(
                    "particles {a} and {b} overlap by {:.3e} m, more than the smaller {bound} {size:.3e} m",
                    self.delta
                )
            }
            Against::Face(f) => format!(
                "particle {i} overlaps mesh face {f} by {:.3e} m, more than its {bound} {size:.3e} m",
                self.delta
            ),
        }
    }

    /// The pair in ids, the same whatever the storage order.
    fn key(&self, ids: &[Id]) -> (Id, Partner) {
        let i = ids[self.i];
        match self.other {
            Against::Particle(j) => {
                let j = ids[j];
                (i.min(j), Partner::Particle(i.max(j)))
            }
            Against::Face(f) => (i, Partner::Face(f)),
        }
    }
}

/// Overlaps deeper than the smaller radius that did not stop the run, each pair counted
/// once.
#[derive(Clone, Debug, Default)]
pub struct Warnings {
    /// Pairs by id: the particle (the lower id of a particle pair) and its partner.
    seen: rustc_hash::FxHashSet<(Id, Partner)>,
    /// Descriptions of the pairs seen for the first time since the last
    /// [`Simulation::take_new_warnings`], with their step.
    fresh: Vec<String>,
}

impl Warnings {
    /// Number of pairs that have overlapped by more than the smaller radius.
    pub fn count(&self) -> usize {
        self.seen.len()
    }
}

/// A run that has become numerically unstable.
#[derive(Clone, Debug)]
pub struct Unstable {
    pub step: u64,
    pub time: f64,
    /// The offending particles and contacts (at most five).
    pub what: Vec<String>,
    /// The likely cause and what to try.
    pub advice: String,
}

impl std::fmt::Display for Unstable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the run became unstable at step {} (t = {:.6e} s): ",
            self.step, self.time
        )?;
        write!(f, "{}", self.what.join("; "))?;
        write!(f, ". Likely cause: {}", self.advice)
    }
}

impl std::error::Error for Unstable {}

/// Fails unless every particle's material is one of the scenario's.
fn check_materials(p: &Particles, s: &Scenario) -> Result<()> {
    let n = s.materials.len();
    if let Some(k) = (0..p.len()).find(|&k| p.material[k] as usize >= n) {
        bail!(
            "particle {} has material {}, but the scenario has {n} material{} (0 to {})",
            p.id[k],
            p.material[k],
            if n == 1 { "" } else { "s" },
            n - 1
        );
    }
    Ok(())
}

/// Whether each clump of `p` (of a checkpoint a stage continues) is of its template in
/// the `[[clumps]]` of `s`: the same spheres, scaled by its factor. Frames name a clump by
/// its template's index, and `render` and `analyze` draw it from that template.
fn check_clumps(p: &Particles, s: &Scenario) -> Result<()> {
    for b in &p.bodies.list {
        let t = s.clumps.get(b.template as usize);
        let same = t.is_some_and(|t| {
            t.spheres.len() == b.offsets.len()
                && (t.spheres.iter().zip(&b.offsets))
                    .all(|(sp, &o)| (sp.centre * b.scale).distance(o) <= 1e-9 * b.bounding_radius)
        });
        if !same {
            let name = t.map_or("none".to_string(), |t| format!("'{}'", t.name));
            bail!(
                "clump {} is of template {} of the run it continues, but this scenario's \
                 [[clumps]] entry {} ({name}) is another shape: keep the templates of that run, \
                 in their order, and add new ones after them",
                b.id.first(),
                b.template,
                b.template
            );
        }
    }
    Ok(())
}

/// The state in numbers (`Simulation::thermo`), for the status line and `log.csv`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Thermo {
    pub particles: usize,
    /// Kinetic energy, translational and rotational \[J\], and its rotational part.
    pub kinetic_energy: f64,
    pub rotational_energy: f64,
    /// Touching particle pairs and particle-face contacts in the last step.
    pub pair_contacts: usize,
    pub wall_contacts: usize,
    /// The deepest overlap relative to the smaller radius (the particle's, against a face).
    pub max_overlap: f64,
    /// Particles removed so far by the outlets and the domain bounds.
    pub removed: u64,
    /// The temperatures, if heat is transferred.
    pub heat: Option<Temperatures>,
    /// The energy ledger's balance, if it is kept.
    pub energy: Option<crate::model::ledger::Balance>,
}

/// The particles' temperatures in numbers, for `log.csv`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Temperatures {
    /// Mean, least and greatest temperature \[K\] (0 without particles).
    pub mean: f64,
    pub min: f64,
    pub max: f64,
    /// Σ m c T \[J\].
    pub content: f64,
}

impl Thermo {
    /// Contacts per particle: each pair counts for both, each face contact for its particle.
    pub fn contacts_per_particle(&self) -> f64 {
        match self.particles {
            0 => 0.0,
            n => (2 * self.pair_contacts + self.wall_contacts) as f64 / n as f64,
        }
    }
}

/// A running simulation.
pub struct Simulation {
    pub scenario: Scenario,
    pub particles: Particles,
    /// The mesh, its files and moving parts, and the loads on them.
    pub walls: Walls,
    /// The contact law, densities and load scales.
    pub(crate) model: Model,
    pub(crate) neighbours: Neighbours,
    pub(crate) face_grid: FaceGrid,
    pub(crate) spawner: Spawner,
    /// Force and torque on each particle (storage order), summed by stages 3 and 4 and used
    /// up by stage 5.
    loads: Vec<Load>,
    /// Step of the last neighbour-list rebuild.
    pub(crate) built_at: u64,
    /// Simulated time \[T\] and number of steps taken.
    pub time: f64,
    pub steps: u64,
    /// Wall time per stage.
    pub stage_times: StageTimes,
    /// Overlaps past the smaller radius that did not stop the run.
    warnings: Warnings,
    /// Particles removed so far by the outlets and the domain bounds.
    pub removed: Removed,
    /// The largest radius the faces are binned for.
    pub(crate) face_grid_radius: f64,
    /// The energy ledger, if the scenario keeps it.
    pub(crate) books: Option<ledger::Books>,
    /// This process's share of a run split over several (`decomposition.rs`).
    pub(crate) share: Option<Share>,
}

impl Simulation {
    /// Number of neighbour-list rebuilds so far.
    pub fn rebuilds(&self) -> u64 {
        self.neighbours.rebuilds
    }

    /// Number of listed particle pairs and particle-face pairs (Verlet list slots).
    pub fn list_slots(&self) -> (usize, usize) {
        (self.neighbours.pairs.slots(), self.neighbours.faces.slots())
    }

    /// Number of particle-particle and particle-face contacts in the last step.
    pub fn contact_count(&self) -> usize {
        let nb = &self.neighbours;
        nb.pairs.contacts() + nb.wrapped.contacts() + nb.faces.contacts()
    }

    /// The particles with their positions put back into the domain along its periodic
    /// axes (between neighbour-list rebuilds they may be up to half the skin beyond a side),
    /// for output; the particles themselves if it has none.
    /// Of a split run: all processes' particles in id order on the first (collective), and
    /// none on the others (they write nothing; [`Simulation::gather_particles`] gives all
    /// to all).
    pub fn particles_in_domain(&self) -> std::borrow::Cow<'_, Particles> {
        let p = match (&self.share, self.neighbours.periodic) {
            (None, None) => return std::borrow::Cow::Borrowed(&self.particles),
            (None, Some(_)) => self.particles.clone(),
            (Some(_), _) => self.gather_particles_to(crate::parallel::comm::Reach::Writer),
        };
        std::borrow::Cow::Owned(self.put_in_domain(p))
    }

    /// The pieces of a frame of a split run written by each process: its own particles (in
    /// id order, with their bodies) and, for the lines of its contacts, all it holds (own
    /// and ghosts), as [`Simulation::particles_in_domain`] puts them. Not collective.
    pub fn own_particles_in_domain(&self) -> (Particles, Particles) {
        let p = &self.particles;
        let solo = crate::parallel::comm::Solo;
        let reach = crate::parallel::comm::Reach::Everyone;
        let own = crate::parallel::decomposition::gather_by_id((&solo, reach), p, |i| self.own(i));
        (self.put_in_domain(own), self.put_in_domain(p.clone()))
    }

    /// `p` with its positions put back into the domain along its periodic axes.
    fn put_in_domain(&self, mut p: Particles) -> Particles {
        if let Some(periodic) = self.neighbours.periodic {
            for (x, v) in p.x.iter_mut().zip(p.v.iter_mut()) {
                (*x, *v) = periodic.wrap_state(*x, *v);
            }
            for b in &mut p.bodies.list {
                (b.x, b.v) = periodic.wrap_state(b.x, b.v);
            }
        }
        p
    }

    /// Advances the simulation by one time step Δt.
    ///
    /// Fails, leaving the state as computed, when the run has become unstable: an overlap
    /// deeper than the smaller radius, or a non-finite position or velocity.
    pub fn step(&mut self) -> Result<(), Unstable> {
        let t = Instant::now();
        self.slide_images();
        self.walls.move_to(self.time);
        let t = self.stage_times.add(Stage::MoveMeshes, t);
        self.open_books();
        let first_new = self.particles.next_id;
        self.spawn();
        if self.books.is_some() && self.particles.next_id > first_new {
            let p = &self.particles;
            let new: Vec<usize> = (0..p.len()).filter(|&k| p.id[k] >= first_new).collect();
            self.book_kinetic(new.into_iter(), true);
        }
        let t = self.stage_times.add(Stage::Spawn, t);
        self.update_neighbours();
        let t = self.stage_times.add(Stage::Neighbours, t);
        // The ledger's entries of this step, in the room of the last step's.
        let mut entries = self.books.as_mut().map(|b| b.take_entries());
        let p = &self.particles;
        let lists = &mut self.neighbours;
        let mut found = pairs::run(&self.model, p, lists, &mut self.loads, entries.as_mut());
        let t = self.stage_times.add(Stage::ParticleContacts, t);
        let owned = self.share.as_ref().map(|d| &d.owned[..]);
        let list = &mut self.neighbours.faces;
        let (on_faces, walls) = faces::run(
            &self.model,
            p,
            (&self.walls, owned),
            list,
            (&mut self.loads, entries.as_mut()),
        );
        found.merge(on_faces);
        self.add_wall_loads(walls);
        let t = self.stage_times.add(Stage::MeshContacts, t);
        let mut overheated = false;
        if let Some(model) = &self.model.heat {
            let owned = self.share.as_ref().map(|d| &d.owned[..]);
            let (p, lists) = (&mut self.particles, &self.neighbours);
            let walls;
            (walls, overheated) = heat::run(&model.0, (&self.walls, &model.1), lists, owned, p);
            self.add_wall_heat(walls);
        }
        let t = self.stage_times.add(Stage::Heat, t);
        self.remember_velocities();
        let (dt, g) = (
            self.scenario.simulation.timestep,
            self.scenario.kinetics.gravity,
        );
        let periodic = self.neighbours.periodic;
        let owned = self.share.as_ref().map(|d| &d.owned[..]);
        let bodies_non_finite = bodies::run(
            &self.model,
            (dt, g),
            (periodic, owned),
            &mut self.particles,
            &self.loads,
        );
        let t = self.stage_times.add(Stage::Bodies, t);
        let non_finite = advance::run(&self.model, (dt, g), &mut self.particles, &mut self.loads)
            | bodies_non_finite
            | overheated;
        #[cfg(test)]
        open_core_tests::walk(&mut self.particles, dt);
        let t = self.stage_times.add(Stage::Integrate, t);
        regions::tag(&self.scenario.tags, &mut self.particles);
        let t = self.stage_times.add(Stage::Tag, t);
        if let Some(d) = &self.share {
            split::refresh_ghosts(d, &mut self.particles);
        }
        let t = self.stage_times.add(Stage::Exchange, t);
        if let Some(entries) = entries {
            found.beyond_range |= !self.keep_books(entries);
        }
        let t = self.stage_times.add(Stage::Ledger, t);
        self.steps += 1;
        self.time = self.steps as f64 * self.scenario.simulation.timestep;
        self.check_stability(found, non_finite)?;
        let t = self.stage_times.add(Stage::Stability, t);
        self.remove();
        self.stage_times.add(Stage::Remove, t);
        Ok(())
    }

    /// The state `[simulation] until` is checked on at a frame (collective in a split run).
    pub fn frame_state(&self, th: &Thermo) -> crate::scenario::FrameState {
        let p = &self.particles;
        crate::scenario::FrameState {
            time: self.time,
            kinetic_energy: th.kinetic_energy,
            particles: th.particles,
            spawning: !self.spawner.finished(&self.scenario, p.next_id, self.time),
            removed: th.removed,
            servos: (self.walls.servo_controls().iter())
                .map(|&(k, c, s)| (k, s.load, c.force))
                .collect(),
        }
    }

    /// Lees-Edwards: the images across the gradient sides of a sheared domain to their
    /// offset V t now (for the lists and the spawner).
    pub(crate) fn slide_images(&mut self) {
        let time = self.time;
        if let Some(periodic) = &mut self.neighbours.periodic
            && let Some(shear) = &mut periodic.shear
        {
            shear.offset = shear.velocity * time;
        }
        self.spawner.periodic = self.neighbours.periodic;
    }

    /// Stage 2 (Section 3.3): rebuild the Verlet lists when they may miss a contact.
    #[inline(never)] // a stage of its own in profiles
    fn update_neighbours(&mut self) {
        let p = &self.particles;
        let stale = self.neighbours.stale(
            &p.x,
            &p.radius,
            &self.walls.mesh.faces,
            self.walls.drift.max(self.neighbours.shear_drift()),
        );
        match &self.share {
            // Split over processes: all rebuild when one must.
            Some(d) if d.comm.any(stale) => self.redistribute(
                &Default::default(),
                crate::parallel::decomposition::Placement::Now,
            ),
            Some(_) => {}
            None if stale => self.rebuild_lists(self.walls.move_at_all()),
            None => {}
        }
    }

    /// Rebuilds the Verlet lists (re-sorting the particles into spatial order), re-binning
    /// the faces first if `regrid_faces` (they moved, or larger particles appeared).
    fn rebuild_lists(&mut self, regrid_faces: bool) {
        if regrid_faces || self.particles.max_radius() > self.face_grid_radius {
            self.regrid_faces();
        }
        // The loads hold nothing between steps: their room is given back while the
        // rebuild needs its own (the history of the contacts), and taken again after.
        self.loads = Vec::new();
        self.neighbours
            .rebuild(&mut self.particles, &self.walls.mesh.faces, &self.face_grid);
        self.built();
    }

    /// Bins the faces as they are now for particles up to the largest radius.
    fn regrid_faces(&mut self) {
        let g = &self.scenario.geometry;
        self.regrid_faces_for(g.radius_max.max(self.particles.max_radius()));
    }

    /// The clock, the sheared images and the walls (servos too) back at step `built_at`, for
    /// the lists to be built again as they were then; what [`Simulation::wind_on`] takes to
    /// bring them back.
    pub(crate) fn rewind_to(&mut self, built_at: u64) -> Rewound {
        let now = Rewound {
            steps: self.steps,
            time: self.time,
            servos: self.walls.rewind_servos(),
        };
        self.steps = built_at;
        self.time = built_at as f64 * self.scenario.simulation.timestep;
        self.slide_images();
        self.walls.move_to(self.time);
        now
    }

    /// The clock and the walls back where [`Simulation::rewind_to`] took them from.
    pub(crate) fn wind_on(&mut self, now: Rewound) {
        (self.steps, self.time) = (now.steps, now.time);
        self.walls.set_servos(&now.servos);
        self.walls.move_to(self.time);
    }

    /// After a rebuild: loads for the particles, blocks of the face list, and the mesh pose
    /// the lists were built with.
    pub(crate) fn built(&mut self) {
        self.loads.clear();
        self.loads.resize(self.particles.len(), Load::default());
        self.built_at = self.steps;
        self.walls.mark_built(self.time);
    }
}
