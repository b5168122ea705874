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

use crate::contact::{Body, Coefficients, ContactLaw, Kinematics, Other};
use crate::domain::Domain;
use crate::exact::{Scale, Scales8, Sum6, pack};
use crate::integrate::{Density, Inertia, Response, State, advance};
use crate::lanes::{Gather, Lanes};
use crate::mesh::{Contacts, Face, Mesh};
use crate::motion::{Motion, Pose, RigidVelocity};
use crate::neighbours::{
    CellGrid, ContactList, FACE_PIECE, Histories, History, MIN_PARALLEL_LEN, NONE, Neighbours,
    Store, cut, face_grid,
};
use crate::particles::Particles;
pub use crate::records::{ContactRecord, Outflow, Partner, Removed, Snapshot, Wrench};
use crate::scenario::{MeshSource, Scenario};
use crate::spawn::{Spawner, SpawnerState};
use crate::springs::Springs;
use crate::surface::{self, Candidate, Fate};

/// Contacts per group evaluated together: 8 doubles fill an AVX-512 register, two AVX ones.
const WIDTH: usize = 8;
type Group = wide::f64x8;

/// Force (components 0-2) and torque (3-5) on one particle, summed over its contacts during
/// a step (Eqs. 1-2), exactly (`exact.rs`): the same bits in whatever order the contacts add
/// to it.
type Load = Sum6;

/// The resolutions of the force and torque sums, from the largest force and torque the
/// scenario's materials and radii can produce (see [`LoadScales::of`]).
#[derive(Clone, Copy, Debug)]
pub struct LoadScales {
    pub force: Scale,
    pub torque: Scale,
    /// Of a load's components.
    lanes: Scales8,
}

impl LoadScales {
    /// The largest radius the scenario's particles can have.
    fn largest_radius(s: &Scenario) -> f64 {
        let mut r_max = s.geometry.radius_max;
        for region in &s.spawn {
            r_max = r_max.max(region.radius.largest());
        }
        r_max
    }

    /// Room above the largest total load of one step on a wall: 2^20 contacts of the
    /// largest force (far more than the grains' weight); torques with the lever `lever`.
    const WALL_ROOM: f64 = 1048576.0;

    /// The scales of a step's loads on the walls, for torques about points at most `lever`
    /// from the particles.
    fn walls(&self, lever: f64) -> Scales8 {
        let largest = LoadScales::WALL_ROOM * self.force.largest();
        let (force, torque) = (
            Scale::for_largest(largest),
            Scale::for_largest((largest * lever).max(f64::MIN_POSITIVE)),
        );
        Scales8::new([force, force, force, torque, torque, torque, force, force])
    }

    /// Room above the largest force of a contact, E* R_max^2 (Hertz at an overlap of R_max,
    /// or the cohesion k_c pi R_max^2): 2^12, which also holds particles up to 64 R_max.
    const ROOM: f64 = 4096.0;

    /// The scales of a scenario: from its parameters only (not from the particles of the
    /// moment), so that a resumed run and every process of a run use the same ones.
    pub fn of(s: &Scenario) -> LoadScales {
        let r_max = LoadScales::largest_radius(s);
        let mut stiffest: f64 = 0.0;
        for m in &s.materials {
            let m = &m.properties;
            let e_star = m.youngs_modulus / (1.0 - m.poisson_ratio * m.poisson_ratio);
            stiffest = stiffest.max(e_star).max(std::f64::consts::PI * m.cohesion);
        }
        for i in &s.interactions {
            stiffest = stiffest.max(std::f64::consts::PI * i.cohesion.unwrap_or(0.0));
        }
        let largest = (LoadScales::ROOM * stiffest * r_max * r_max).max(f64::MIN_POSITIVE);
        let (force, torque) = (
            Scale::for_largest(largest),
            Scale::for_largest((largest * r_max).max(f64::MIN_POSITIVE)),
        );
        LoadScales {
            force,
            torque,
            lanes: Scales8::new([force, force, force, torque, torque, torque, force, force]),
        }
    }
}

/// A piece of owners `owners` of a contact list: their loads, and the contacts of their
/// slots (which start at slot `first`) with the piece's store.
struct Piece<'a> {
    owners: std::ops::Range<usize>,
    first: usize,
    loads: &'a mut [Load],
    contact: &'a mut [u32],
    store: &'a mut Store,
}

/// The pieces of a contact list (its run starts `start`, owner bounds `bounds` of its pieces,
/// its slots' `contact` and its `stores`), each with the `loads` of its owners.
fn pieces<'a>(
    bounds: &[u32],
    loads: &'a mut [Load],
    start: &[u32],
    contact: &'a mut [u32],
    stores: &'a mut [Store],
) -> Vec<Piece<'a>> {
    let owners: Vec<usize> = bounds.iter().map(|&o| o as usize).collect();
    let slots: Vec<usize> = owners.iter().map(|&o| start[o] as usize).collect();
    cut(loads, &owners)
        .into_iter()
        .zip(cut(contact, &slots))
        .zip(stores.iter_mut())
        .enumerate()
        .map(|(k, ((loads, contact), store))| Piece {
            owners: owners[k]..owners[k + 1],
            first: slots[k],
            loads,
            contact,
            store,
        })
        .collect()
}

/// Two distinct elements of a slice, mutably.
fn pair_mut<T>(v: &mut [T], a: usize, b: usize) -> (&mut T, &mut T) {
    assert_ne!(a, b);
    if a < b {
        let (lo, hi) = v.split_at_mut(b);
        (&mut lo[a], &mut hi[0])
    } else {
        let (lo, hi) = v.split_at_mut(a);
        (&mut hi[0], &mut lo[b])
    }
}

/// The springs of store entries `c` in the lanes of a group.
#[inline(always)]
fn gather_springs(store: &Store, c: [u32; WIDTH]) -> Springs<Group> {
    let (mut u_s, mut u_r, mut u_t) = ([DVec3::ZERO; WIDTH], [DVec3::ZERO; WIDTH], [0.0; WIDTH]);
    for l in 0..WIDTH {
        let s = &store.springs[c[l] as usize];
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
    let (u_s, u_r, u_t) = (
        Group::scatter_vec(lanes.u_s),
        Group::scatter_vec(lanes.u_r),
        lanes.u_t.scatter(),
    );
    for (l, &c) in c.iter().enumerate() {
        store.springs[c as usize] = Springs {
            u_s: u_s[l],
            u_r: u_r[l],
            u_t: u_t[l],
        };
    }
}

/// A face within reach of a particle, in stage 4.
struct Near {
    /// The particle, and the face's slot in the piece of the particle-face list.
    owner: u32,
    slot: usize,
    kin: Kinematics,
    /// Separation x - p_F and whether p_F counts as inside the face (see `surface::snap`).
    d: DVec3,
    interior: bool,
}

/// Buffers of one piece of the mesh-contact stage.
#[derive(Default)]
struct MeshScratch {
    /// The piece's faces within reach.
    near: Vec<Near>,
    /// Which of `near` are contacts of their own, for the law.
    contacts: Vec<u32>,
    /// One particle's faces within reach as candidates, and what becomes of them.
    candidates: Vec<Candidate>,
    order: Vec<usize>,
    fates: Vec<Fate>,
}

/// The stages of a step, for the timing breakdown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    MoveMeshes,
    Spawn,
    Neighbours,
    ParticleContacts,
    MeshContacts,
    Integrate,
    Tag,
    Exchange,
    Stability,
    Remove,
}

impl Stage {
    pub const ALL: [Stage; 10] = [
        Stage::MoveMeshes,
        Stage::Spawn,
        Stage::Neighbours,
        Stage::ParticleContacts,
        Stage::MeshContacts,
        Stage::Integrate,
        Stage::Tag,
        Stage::Exchange,
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
            Stage::Integrate => "integrate",
            Stage::Tag => "tag",
            Stage::Exchange => "exchange",
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

/// An overlap deeper than `limit`, the smaller radius (the particle's, against a face):
/// a warning; deeper than twice that, a sign of instability.
#[derive(Clone, Copy, Debug)]
pub struct Deep {
    i: usize,
    other: Partner,
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
    fn describe(&self, ids: &[u32]) -> String {
        let (bound, size) = if self.through() {
            ("diameter", 2.0 * self.limit)
        } else {
            ("radius", self.limit)
        };
        let i = ids[self.i];
        match self.other {
            Partner::Particle(j) => {
                let (a, b) = (i.min(ids[j]), i.max(ids[j]));
                format!(
                    "particles {a} and {b} overlap by {:.3e} m, more than the smaller {bound} {size:.3e} m",
                    self.delta
                )
            }
            Partner::Face(f) => format!(
                "particle {i} overlaps mesh face {f} by {:.3e} m, more than its {bound} {size:.3e} m",
                self.delta
            ),
        }
    }

    /// The pair in ids, the same whatever the storage order.
    fn key(&self, ids: &[u32]) -> (u32, Partner) {
        let i = ids[self.i];
        match self.other {
            Partner::Particle(j) => (i.min(ids[j]), Partner::Particle(i.max(ids[j]) as usize)),
            face => (i, face),
        }
    }
}

/// Overlaps deeper than the smaller radius that did not stop the run, each pair counted
/// once.
#[derive(Clone, Debug, Default)]
pub struct Warnings {
    /// Pairs by id: the particle (the lower id of a particle pair) and its partner.
    seen: rustc_hash::FxHashSet<(u32, Partner)>,
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

/// The reports of every process of a split run, in the order they are told.
fn gather_told(
    comm: &dyn crate::comm::Comm,
    told: Vec<(u8, u64, u64, String)>,
) -> Vec<(u8, u64, u64, String)> {
    use crate::comm::{Reader, Writer};
    let mut w = Writer::default();
    for (kind, a, b, text) in &told {
        w.u8(*kind);
        w.u64(*a);
        w.u64(*b);
        w.bytes(text.as_bytes());
    }
    let mut all = Vec::new();
    for m in comm.all_gather(w.0) {
        let mut r = Reader::new(&m);
        while !r.done() {
            let (kind, a, b) = (r.u8(), r.u64(), r.u64());
            all.push((kind, a, b, String::from_utf8_lossy(r.bytes()).into_owned()));
        }
    }
    all.sort_by_key(|x| (x.0, x.1, x.2));
    all
}

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

/// `face_part` of a face that does not move.
const STATIC: u32 = u32::MAX;

/// A mesh file whose faces follow a prescribed motion.
#[derive(Clone, Debug)]
struct MovingPart {
    faces: std::ops::Range<usize>,
    motion: Motion,
    /// Velocity field at the current time.
    velocity: RigidVelocity,
    /// Corners of its faces at rest, to measure how far they moved.
    corners: Vec<DVec3>,
    /// Pose at the last neighbour-list rebuild.
    pose_at_build: Pose,
}

/// Where a mesh file's faces are in [`Simulation::mesh`]: `[geometry] mesh` first, then the
/// `[[meshes]]` in order.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshFile {
    pub name: String,
    pub faces: std::ops::Range<usize>,
    pub contacts: Contacts,
    /// The point torques on it are taken about: the origin, or the centre of its rotation.
    pub torque_about: DVec3,
    /// The material of its faces.
    pub material: u16,
}

/// A running simulation.
pub struct Simulation {
    pub scenario: Scenario,
    pub particles: Particles,
    pub mesh: Mesh,
    /// The mesh files `mesh` was put together from.
    pub mesh_files: Vec<MeshFile>,
    law: ContactLaw,
    pub(crate) neighbours: Neighbours,
    pub(crate) face_grid: CellGrid,
    pub(crate) spawner: Spawner,
    /// Force and torque on each particle (storage order), summed by stages 3 and 4 and used
    /// up by stage 5.
    loads: Vec<Load>,
    /// The resolutions of the loads' sums.
    scales: LoadScales,
    /// Some force or torque of the last step was beyond the range of the sums, or not
    /// finite (the run is unstable).
    beyond_range: bool,
    /// The mesh as read (at t = 0).
    rest_faces: Vec<Face>,
    /// Parts of the mesh that follow a prescribed motion.
    moving: Vec<MovingPart>,
    /// For each face, its moving part, or `STATIC`.
    face_part: Vec<u32>,
    /// Largest displacement of a moving face since the last neighbour-list rebuild.
    mesh_drift: f64,
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
    /// For each face, its mesh file (an index of `mesh_files`), if wall loads are summed.
    face_file: Vec<u32>,
    /// For each face, its material.
    face_material: Vec<u16>,
    /// For each material, the quotients of its density.
    pub(crate) densities: Vec<Density>,
    /// The loads on each mesh file summed over the steps since the last call of
    /// [`Simulation::take_wall_loads`] (`[output] wall_forces`): each step's exactly (over
    /// all contacts, and all processes), then the steps in order.
    pub(crate) wall_sums: Vec<Wrench>,
    /// The resolutions of the wall loads' sums of a step.
    wall_scales: Scales8,
    /// The largest radius the faces are binned for.
    pub(crate) face_grid_radius: f64,
    /// This process's share of a run split over several (`domain.rs`).
    pub(crate) domain: Option<Domain>,
}

impl Simulation {
    /// Sets up a simulation: reads the mesh and the initial particles.
    pub fn new(scenario: Scenario) -> Result<Simulation> {
        let g = &scenario.geometry;
        let (mut mesh, name) = match &g.mesh {
            MeshSource::None => (Mesh::default(), String::new()),
            MeshSource::File(path) => {
                (Mesh::load(path, &g.mesh_radii)?, path.display().to_string())
            }
            MeshSource::Embedded { name, text } => (
                Mesh::parse_off(text, name, &g.mesh_radii)?,
                name.to_string(),
            ),
        };
        mesh = mesh.with_contacts(g.mesh_contacts);
        let mut files = vec![MeshFile {
            name,
            faces: 0..mesh.faces.len(),
            contacts: g.mesh_contacts,
            torque_about: DVec3::ZERO,
            material: g.mesh_material,
        }];
        let mut moving = Vec::new();
        for spec in &scenario.meshes {
            let part = Mesh::load(&spec.file, &spec.radii)?.with_contacts(spec.contacts);
            let faces = mesh.faces.len()..mesh.faces.len() + part.faces.len();
            if let Some(motion) = spec.motion {
                moving.push((faces.clone(), motion));
            }
            files.push(MeshFile {
                name: spec.file.display().to_string(),
                faces,
                contacts: spec.contacts,
                torque_about: match spec.motion {
                    Some(Motion::Rotation { center, .. }) => center,
                    _ => DVec3::ZERO,
                },
                material: spec.material,
            });
            mesh.append(part);
        }
        let particles = match &scenario.particles {
            Some(path) => crate::csv::load_particles(path)?,
            None => Particles::default(),
        };
        let mut sim = Simulation::from_parts(scenario, mesh, particles)?;
        sim.mesh_files = files;
        for file in &sim.mesh_files {
            sim.face_material[file.faces.clone()].fill(file.material);
        }
        sim.sum_wall_loads();
        for (faces, motion) in moving {
            for f in faces.clone() {
                sim.face_part[f] = sim.moving.len() as u32;
            }
            let corners = sim.rest_faces[faces.clone()]
                .iter()
                .flat_map(Face::corners)
                .collect();
            sim.moving.push(MovingPart {
                faces,
                motion,
                velocity: RigidVelocity::default(),
                corners,
                pose_at_build: Pose::REST,
            });
        }
        sim.move_meshes();
        Ok(sim)
    }

    /// Continues a run from a snapshot taken by [`Simulation::snapshot`] with the same
    /// scenario: the result is bitwise the same as if the run had not stopped.
    pub fn restore(scenario: Scenario, snapshot: Snapshot) -> Result<Simulation> {
        let input = scenario.particles.clone();
        let mut sim = Simulation::new(Scenario {
            particles: None,
            ..scenario
        })?;
        // The particles come from the snapshot; the scenario keeps its input file, so that
        // its `run.toml` reruns the run.
        sim.scenario.particles = input;
        let misfit = |what: String| anyhow::anyhow!("the checkpoint does not fit: {what}");
        let built = !snapshot.anchors.is_empty();
        if built && snapshot.anchors.len() != snapshot.particles.len() {
            return Err(misfit("one anchor per particle".into()));
        }
        check_materials(&snapshot.particles, &sim.scenario)
            .map_err(|e| misfit(format!("{e:#}")))?;
        sim.particles = snapshot.particles;
        let (regions, spawn) = (snapshot.spawner.regions.len(), sim.scenario.spawn.len());
        if regions > spawn {
            return Err(misfit(format!(
                "it counts the insertions of {regions} [[spawn]] regions, the scenario has {spawn}"
            )));
        }
        let (sums, files) = (snapshot.wall_sums.len(), sim.mesh_files.len());
        if sums != 0 && sums != files {
            return Err(misfit(format!(
                "it sums the loads on {sums} mesh files, the scenario has {files}"
            )));
        }
        sim.spawner = Spawner::resume(sim.scenario.simulation.seed, snapshot.spawner);
        if snapshot.removed.outlets.len() > sim.removed.outlets.len() {
            return Err(misfit(format!(
                "it counts {} outlets, the scenario has {}",
                snapshot.removed.outlets.len(),
                sim.removed.outlets.len()
            )));
        }
        sim.removed.domain = snapshot.removed.domain;
        sim.removed.outlets[..snapshot.removed.outlets.len()]
            .copy_from_slice(&snapshot.removed.outlets);
        if !sim.wall_sums.is_empty() && snapshot.wall_sums.len() == sim.wall_sums.len() {
            sim.wall_sums = snapshot.wall_sums;
        }
        let history = Histories {
            pairs: History::in_storage(&sim.particles, &snapshot.pair_history, true)
                .map_err(misfit)?,
            faces: History::in_storage(&sim.particles, &snapshot.face_history, false)
                .map_err(misfit)?,
        };
        if let Some(&(_, f, _)) = snapshot
            .face_history
            .iter()
            .find(|e| e.1 as usize >= sim.mesh.faces.len())
        {
            return Err(misfit(format!(
                "contact with face {f}, which the mesh lacks"
            )));
        }
        let dt = sim.scenario.simulation.timestep;
        if !built {
            // Taken before the first step: the lists are made as that step would make them.
            sim.steps = snapshot.steps;
            sim.time = sim.steps as f64 * dt;
            sim.move_meshes();
            sim.neighbours =
                Neighbours::with_periodic(sim.neighbours.skin, sim.neighbours.periodic);
            return Ok(sim);
        }
        // The lists of the last rebuild, built again with the mesh (and sheared images)
        // where they were then.
        sim.steps = snapshot.built_at;
        sim.time = sim.steps as f64 * dt;
        sim.slide_images();
        sim.move_meshes();
        sim.regrid_faces();
        sim.neighbours.restore(
            &sim.particles,
            snapshot.anchors,
            snapshot.lonely,
            &sim.mesh.faces,
            &sim.face_grid,
            &history,
        );
        sim.built();
        sim.steps = snapshot.steps;
        sim.time = sim.steps as f64 * dt;
        sim.move_meshes();
        Ok(sim)
    }

    /// Starts a new stage of a study from the snapshot of another run (`tinydem run NEXT
    /// --from CHECKPOINT`): the particles (ids, materials, tags) and all their contact
    /// history are the snapshot's, everything else is `scenario`'s, whose clock starts at 0
    /// (its meshes start their motions at rest, its frames count from 0). Contacts with a
    /// mesh file are carried when `scenario` has the same file (the same faces), wherever
    /// it stands in the list; the spawner continues its random stream if the seed is the
    /// same. When the mesh is the same too, the lists are rebuilt as the run had them, so a
    /// stage that only adds frames gives the bits of one uninterrupted run. Returns what was
    /// carried and dropped, for the user.
    pub fn stage(scenario: Scenario, snapshot: Snapshot) -> Result<(Simulation, Vec<String>)> {
        if scenario.particles.is_some() {
            bail!(
                "[input] particles cannot be combined with --from: the particles are those of the checkpoint"
            );
        }
        let mut sim = Simulation::new(scenario)?;
        let misfit = |what: String| anyhow::anyhow!("the checkpoint does not fit: {what}");
        let mut notes = Vec::new();
        let p = snapshot.particles;
        check_materials(&p, &sim.scenario).map_err(|e| misfit(format!("{e:#}")))?;
        let old_seed = if snapshot.scenario.is_empty() {
            None
        } else {
            let old = Scenario::parse(&snapshot.scenario, std::path::Path::new("checkpoint"))
                .map_err(|e| misfit(format!("its scenario does not parse: {e:#}")))?;
            if old.lees_edwards.is_some() {
                bail!(
                    "a run with Lees-Edwards boundaries cannot start a stage yet (its images would jump back to offset 0): continue it with --resume"
                );
            }
            Some(old.simulation.seed)
        };
        if old_seed == Some(sim.scenario.simulation.seed) {
            // The stage's [[spawn]] regions are its own: their counts start at 0 with its
            // clock.
            let state = SpawnerState {
                regions: Vec::new(),
                ..snapshot.spawner
            };
            sim.spawner = Spawner::resume(sim.scenario.simulation.seed, state);
            notes.push("spawning continues the random stream of the checkpoint".into());
        } else {
            notes.push(format!(
                "spawning draws from a new random stream (seed {})",
                sim.scenario.simulation.seed
            ));
        }
        // Each mesh file of the checkpoint's run, found among this scenario's by its faces.
        let new_files = sim.mesh_signatures();
        let mut taken = vec![false; new_files.len()];
        let mut face_map: Vec<Option<u32>> = Vec::new();
        for old in &snapshot.mesh_files {
            let found = (0..new_files.len()).find(|&j| !taken[j] && new_files[j] == *old);
            if let Some(j) = found {
                taken[j] = true;
            }
            let start = found.map(|j| sim.mesh_files[j].faces.start as u32);
            face_map.extend((0..old.0 as u32).map(|f| start.map(|s| s + f)));
        }
        let face_history: Vec<_> = snapshot
            .face_history
            .iter()
            .filter_map(|&(id, f, springs)| {
                face_map
                    .get(f as usize)
                    .copied()
                    .flatten()
                    .map(|f| (id, f, springs))
            })
            .collect();
        let dropped = snapshot.face_history.len() - face_history.len();
        let same_mesh = snapshot.mesh_files == new_files;
        notes.push(format!(
            "carried {} particles, {} particle contacts and {} contacts with meshes{}",
            p.len(),
            snapshot.pair_history.len(),
            face_history.len(),
            if dropped > 0 {
                format!(" ({dropped} with mesh files this scenario lacks were dropped)")
            } else {
                String::new()
            }
        ));
        let history = Histories {
            pairs: History::in_storage(&p, &snapshot.pair_history, true).map_err(misfit)?,
            faces: History::in_storage(&p, &face_history, false).map_err(misfit)?,
        };
        let built = !snapshot.anchors.is_empty();
        if built && snapshot.anchors.len() != p.len() {
            return Err(misfit("one anchor per particle".into()));
        }
        sim.particles = p;
        if built {
            // The lists at the positions of the run's last rebuild; the allowances of its
            // lonely particles hold only for the same mesh.
            let lonely = if same_mesh {
                snapshot.lonely
            } else {
                Vec::new()
            };
            sim.regrid_faces();
            sim.neighbours.restore(
                &sim.particles,
                snapshot.anchors,
                lonely,
                &sim.mesh.faces,
                &sim.face_grid,
                &history,
            );
            sim.built();
        }
        Ok((sim, notes))
    }

    /// The complete state of the run (collective in a split run, where it fails if the
    /// state of some process is not one a checkpoint may hold).
    pub fn snapshot(&self) -> Result<Snapshot> {
        if self.domain.is_some() {
            return self.snapshot_split();
        }
        let p = &self.particles;
        let history = self.neighbours.history(&p.id, p.next_id as usize);
        let (anchors, lonely) = self.neighbours.anchors();
        Ok(Snapshot {
            steps: self.steps,
            built_at: self.built_at,
            particles: p.clone(),
            spawner: self.spawner.state(),
            anchors: anchors.to_vec(),
            lonely: lonely.to_vec(),
            pair_history: history.pairs.entries(),
            face_history: history.faces.entries(),
            removed: self.removed.clone(),
            wall_sums: self.wall_sums.clone(),
            scenario: self.scenario.to_toml(),
            mesh_files: self.mesh_signatures(),
        })
    }

    /// Sets up a simulation from a mesh and particles already in memory.
    pub fn from_parts(scenario: Scenario, mesh: Mesh, particles: Particles) -> Result<Simulation> {
        let g = &scenario.geometry;
        let max_radius = g.radius_max.max(particles.max_radius());
        if particles.len() as u64 > u32::MAX as u64 / 2 {
            bail!("too many particles: {}", particles.len());
        }
        check_materials(&particles, &scenario)?;
        if let Some(periodic) = scenario.periodicity() {
            let periods = scenario.simulation.shortest_period();
            let shortest = periods * max_radius;
            for a in 0..3 {
                if periodic.axes[a] && periodic.length[a] < shortest {
                    bail!(
                        "the period {} of the domain along axis {a} is shorter than {periods} times the largest radius ({shortest})",
                        periodic.length[a]
                    );
                }
            }
        }
        let skin = scenario.simulation.skin * g.radius_max;
        let face_grid = face_grid(&mesh.faces, max_radius, skin);
        let mut sim = Simulation {
            law: ContactLaw::of(&scenario),
            neighbours: Neighbours::with_periodic(skin, scenario.periodicity()),
            face_grid,
            spawner: Spawner::new(scenario.simulation.seed),
            loads: Vec::new(),
            scales: LoadScales::of(&scenario),
            beyond_range: false,
            rest_faces: mesh.faces.clone(),
            moving: Vec::new(),
            face_part: vec![STATIC; mesh.faces.len()],
            mesh_drift: 0.0,
            built_at: 0,
            time: 0.0,
            steps: 0,
            stage_times: StageTimes::default(),
            warnings: Warnings::default(),
            mesh_files: vec![MeshFile {
                name: "mesh".into(),
                faces: 0..mesh.faces.len(),
                contacts: mesh
                    .faces
                    .first()
                    .map_or_else(Contacts::default, |f| f.contacts),
                torque_about: DVec3::ZERO,
                material: scenario.geometry.mesh_material,
            }],
            face_material: vec![scenario.geometry.mesh_material; mesh.faces.len()],
            densities: scenario
                .materials
                .iter()
                .map(|m| Density::new(m.properties.density, m.properties.viscosity))
                .collect(),
            removed: Removed {
                outlets: vec![Outflow::default(); scenario.outlets.len()],
                domain: Outflow::default(),
            },
            face_file: Vec::new(),
            wall_sums: Vec::new(),
            wall_scales: Scales8::new([Scale::for_largest(1.0); 8]),
            face_grid_radius: max_radius,
            domain: None,
            scenario,
            particles,
            mesh,
        };
        sim.sum_wall_loads();
        Ok(sim)
    }

    /// Face count and a hash of the rest geometry of each mesh file (shape, radius and
    /// contact mode of its faces, in order).
    pub fn mesh_signatures(&self) -> Vec<(u64, u64)> {
        self.mesh_files
            .iter()
            .map(|file| {
                let faces = &self.rest_faces[file.faces.clone()];
                let text: String = faces
                    .iter()
                    .map(|f| format!("{:?}{:?}{:?};", f.shape, f.radius, f.contacts))
                    .collect();
                (faces.len() as u64, crate::records::hash(&text))
            })
            .collect()
    }

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
    pub fn particles_in_domain(&self) -> std::borrow::Cow<'_, Particles> {
        // Of a split run, all processes' (collective), in id order.
        let mut p = match (&self.domain, self.neighbours.periodic) {
            (None, None) => return std::borrow::Cow::Borrowed(&self.particles),
            (None, Some(_)) => self.particles.clone(),
            (Some(_), _) => self.gather_particles(),
        };
        if let Some(periodic) = self.neighbours.periodic {
            for (x, v) in p.x.iter_mut().zip(p.v.iter_mut()) {
                (*x, *v) = periodic.wrap_state(*x, *v);
            }
        }
        std::borrow::Cow::Owned(p)
    }

    /// Advances the simulation by one time step Δt.
    ///
    /// Fails, leaving the state as computed, when the run has become unstable: an overlap
    /// deeper than the smaller radius, or a non-finite position or velocity.
    pub fn step(&mut self) -> Result<(), Unstable> {
        let t = Instant::now();
        self.slide_images();
        self.move_meshes();
        let t = self.stage_times.add(Stage::MoveMeshes, t);
        self.spawn();
        let t = self.stage_times.add(Stage::Spawn, t);
        self.update_neighbours();
        let t = self.stage_times.add(Stage::Neighbours, t);
        let mut deep = self.particle_contacts();
        let t = self.stage_times.add(Stage::ParticleContacts, t);
        deep.extend(self.mesh_contacts());
        let t = self.stage_times.add(Stage::MeshContacts, t);
        let non_finite = self.integrate();
        let t = self.stage_times.add(Stage::Integrate, t);
        self.tag();
        let t = self.stage_times.add(Stage::Tag, t);
        self.refresh_ghosts();
        let t = self.stage_times.add(Stage::Exchange, t);
        self.steps += 1;
        self.time = self.steps as f64 * self.scenario.simulation.timestep;
        self.check_stability(deep, non_finite || self.beyond_range)?;
        let t = self.stage_times.add(Stage::Stability, t);
        self.remove();
        self.stage_times.add(Stage::Remove, t);
        Ok(())
    }

    /// Stage 7: particles whose centre has entered an outlet or left the domain are
    /// removed (counted, with their mass, by the outlet or the domain: the first outlet
    /// that holds a particle takes it). The lists are rebuilt without them; the ids of the
    /// others stay.
    #[inline(never)] // a stage of its own in profiles
    fn remove(&mut self) {
        let s = &self.scenario;
        if !s.removes() {
            return;
        }
        let (domain, outlets, periodic) = (s.domain, s.outlets.clone(), s.periodic);
        // Outside the domain through a side that is not periodic.
        let outside = move |x: DVec3| {
            domain.is_some_and(|d| {
                (0..3).any(|a| !periodic[a] && (x[a] < d.min[a] || x[a] > d.max[a]))
            })
        };
        // Where each removed particle goes: an outlet, or `outlets.len()` for the domain.
        let fate = move |x: DVec3| -> Option<u32> {
            if let Some(k) = outlets.iter().position(|o| o.contains(x)) {
                return Some(k as u32);
            }
            outside(x).then_some(outlets.len() as u32)
        };
        if self.domain.is_some() {
            return self.remove_split(fate);
        }
        let p = &self.particles;
        let gone: Vec<(u32, u32)> =
            p.x.par_iter()
                .enumerate()
                .with_min_len(4 * MIN_PARALLEL_LEN)
                .filter_map(|(i, x)| fate(*x).map(|f| (i as u32, f)))
                .collect();
        if gone.is_empty() {
            return;
        }
        // Counted in id order, so the masses sum in an order of their own.
        let mut by_id: Vec<(u32, u32, u32)> = gone
            .iter()
            .map(|&(i, f)| (p.id[i as usize], i, f))
            .collect();
        by_id.sort_unstable();
        let densities = &self.densities;
        for &(_, i, f) in &by_id {
            let out = match self.removed.outlets.get_mut(f as usize) {
                Some(o) => o,
                None => &mut self.removed.domain,
            };
            out.count += 1;
            let material = densities[p.material[i as usize] as usize];
            out.mass += Inertia::mass_with(p.radius[i as usize], material.mass_per_r3);
        }
        let gone: Vec<u32> = gone.into_iter().map(|(i, _)| i).collect();
        self.neighbours.rebuild_without(
            &mut self.particles,
            &gone,
            &self.mesh.faces,
            &self.face_grid,
        );
        self.built();
    }

    /// Whether frames name each particle's id and material: particles can be removed (or
    /// were, in an earlier stage), so the line of a particle is not its id, or there are
    /// several materials.
    pub fn frames_carry_ids(&self) -> bool {
        let p = &self.particles;
        self.scenario.removes()
            || self.scenario.materials.len() > 1
            || p.next_id as usize != self.particle_count()
    }

    /// The contact network at the current state: every touching particle pair and
    /// particle-face contact (as the last step resolved them) with the force the law gives
    /// it now, from its current springs (left unchanged): the forces the next step applies.
    /// Pairs by (lower id, higher id), then contacts with faces by (id, face).
    pub fn contact_network(&self) -> Vec<ContactRecord> {
        let mut network = self.held_contact_network();
        if let Some(d) = &self.domain {
            // Each contact from the process that owns its particle (of a pair, the lower id).
            let p = &self.particles;
            let own: rustc_hash::FxHashSet<u32> = (0..p.len())
                .filter(|&k| d.owned[k])
                .map(|k| p.id[k])
                .collect();
            network.retain(|c| own.contains(&c.id));
            network = crate::domain::gather_contacts(&*d.comm, network);
        }
        network
    }

    /// The contact network of the particles this process holds (own and ghosts).
    fn held_contact_network(&self) -> Vec<ContactRecord> {
        let p = &self.particles;
        let law = &self.law;
        let mass = |k: usize| {
            Inertia::mass_with(
                p.radius[k],
                self.densities[p.material[k] as usize].mass_per_r3,
            )
        };
        let body = |k: usize| Body {
            x: p.x[k],
            radius: p.radius[k],
            v: p.v[k],
            w: p.w[k],
        };
        let record = |i: usize, other: Other, kin: &Kinematics, coef, springs: Springs, with| {
            let mut springs = springs;
            let force = law.evaluate(coef, p.radius[i], mass(i), other, kin, &mut springs);
            let f_n = kin.n * kin.n.dot(force.f);
            ContactRecord {
                id: p.id[i],
                with,
                point: p.x[i] - kin.n * kin.r_i,
                f_n,
                f_t: force.f - f_n,
                overlap: kin.delta,
            }
        };
        let mut out = Vec::new();
        // Each open contact of `list`: owner, partner, springs and slot.
        let open = |list: &ContactList| {
            let mut v = Vec::new();
            for piece in 0..list.pieces.len().saturating_sub(1) {
                let store = &list.stores[piece];
                for i in list.pieces[piece] as usize..list.pieces[piece + 1] as usize {
                    for k in list.run(i) {
                        if list.contact[k] != NONE {
                            let springs = store.springs[list.contact[k] as usize];
                            v.push((i, list.partner[k] as usize, springs, k));
                        }
                    }
                }
            }
            v
        };
        // Pairs within the box, and across periodic sides with the partner at its image.
        let nb = &self.neighbours;
        let within = open(&nb.pairs).into_iter().map(|(a, b, s, _)| {
            let (i, j) = if p.id[a] < p.id[b] { (a, b) } else { (b, a) };
            (i, j, s, DVec3::ZERO, DVec3::ZERO)
        });
        let across = open(&nb.wrapped).into_iter().map(|(a, b, s, k)| {
            let (i, j, shift, dv) = nb.across(&p.id, a, b, k);
            (i, j, s, shift, dv)
        });
        for (i, j, springs, shift, dv) in within.chain(across) {
            let bj = Body {
                x: p.x[j] + shift,
                v: p.v[j] + dv,
                ..body(j)
            };
            let Some(kin) = Kinematics::between_particles(&body(i), &bj) else {
                continue;
            };
            let other = Other::Particle {
                r: p.radius[j],
                m: mass(j),
            };
            let coef = law.pair(p.material[i], p.material[j]);
            out.push(record(
                i,
                other,
                &kin,
                coef,
                springs,
                Partner::Particle(p.id[j] as usize),
            ));
        }
        for (i, f, springs, _) in open(&self.neighbours.faces) {
            let face = &self.mesh.faces[f];
            let wall = match self.face_part[f] {
                STATIC => RigidVelocity::default(),
                part => self.moving[part as usize].velocity,
            };
            let b = body(i);
            let (d, feature) = face.separation_and_feature(b.x);
            let (d, _) = surface::snap(face, b.x, b.radius, d, feature);
            let Some(kin) = Kinematics::with_wall(&b, d, face.radius, &wall) else {
                continue;
            };
            let coef = law.with_wall(p.material[i], self.face_material[f]);
            out.push(record(
                i,
                Other::Wall,
                &kin,
                coef,
                springs,
                Partner::Face(f),
            ));
        }
        out.sort_by_key(|r| match r.with {
            Partner::Particle(j) => (0, r.id, j),
            Partner::Face(f) => (1, r.id, f),
        });
        out
    }

    /// What the status line and `log.csv` report of the current state, as LAMMPS's thermo
    /// output does: the energies (summed in id order, so the same for any storage order),
    /// the contacts of the last step and the deepest of them relative to the smaller radius.
    pub fn thermo(&self) -> Thermo {
        let p = &self.particles;
        let mut energies: Vec<(u32, f64, f64)> = (0..p.len())
            .filter(|&k| self.own(k))
            .map(|k| {
                let m = Inertia::mass_with(
                    p.radius[k],
                    self.densities[p.material[k] as usize].mass_per_r3,
                );
                let i = 0.4 * m * p.radius[k] * p.radius[k];
                (
                    p.id[k],
                    0.5 * m * p.v[k].length_squared(),
                    0.5 * i * p.w[k].length_squared(),
                )
            })
            .collect();
        if let Some(d) = &self.domain {
            // Over all processes, still in id order.
            use crate::comm::{Reader, Writer};
            let mut w = Writer::default();
            for &(id, t, r) in &energies {
                w.u32(id);
                w.f64(t);
                w.f64(r);
            }
            energies.clear();
            for m in d.comm.all_gather(w.0) {
                let mut r = Reader::new(&m);
                while !r.done() {
                    energies.push((r.u32(), r.f64(), r.f64()));
                }
            }
        }
        energies.sort_unstable_by_key(|e| e.0);
        let (translational, rotational) = energies
            .iter()
            .fold((0.0, 0.0), |(t, r), e| (t + e.1, r + e.2));
        let radius_of: rustc_hash::FxHashMap<u32, f64> =
            p.id.iter().copied().zip(p.radius.iter().copied()).collect();
        let own: Option<rustc_hash::FxHashSet<u32>> = self.domain.as_ref().map(|d| {
            (0..p.len())
                .filter(|&k| d.owned[k])
                .map(|k| p.id[k])
                .collect()
        });
        let mut thermo = Thermo {
            particles: energies.len(),
            kinetic_energy: translational + rotational,
            rotational_energy: rotational,
            removed: self.removed.count(),
            ..Thermo::default()
        };
        for c in self.held_contact_network() {
            if own.as_ref().is_some_and(|own| !own.contains(&c.id)) {
                continue; // told by the process that owns it
            }
            let r = radius_of[&c.id];
            let smaller = match c.with {
                Partner::Particle(j) => {
                    thermo.pair_contacts += 1;
                    r.min(radius_of[&(j as u32)])
                }
                Partner::Face(_) => {
                    thermo.wall_contacts += 1;
                    r
                }
            };
            thermo.max_overlap = thermo.max_overlap.max(c.overlap / smaller);
        }
        if let Some(d) = &self.domain {
            let counts = d
                .comm
                .sum_i64(&[thermo.pair_contacts as i64, thermo.wall_contacts as i64]);
            (thermo.pair_contacts, thermo.wall_contacts) = (counts[0] as usize, counts[1] as usize);
            thermo.max_overlap = d.comm.max(thermo.max_overlap);
        }
        thermo
    }

    /// Starts summing the loads on each mesh file (`take_wall_loads`).
    fn sum_wall_loads(&mut self) {
        if !self.scenario.wall_forces {
            return;
        }
        self.face_file = vec![0; self.mesh.faces.len()];
        for (k, file) in self.mesh_files.iter().enumerate() {
            self.face_file[file.faces.clone()].fill(k as u32);
        }
        self.wall_sums = vec![Wrench::default(); self.mesh_files.len()];
        // The lever of a torque about a file's point: to its farthest corner, or across the
        // domain, and a particle's radius; 16 times that, for meshes that move.
        let mut lever: f64 = 0.0;
        for file in &self.mesh_files {
            for face in &self.rest_faces[file.faces.clone()] {
                for c in face.corners() {
                    lever = lever.max(c.distance(file.torque_about) + face.radius);
                }
            }
        }
        if let Some(d) = self.scenario.domain {
            lever = lever.max((d.max - d.min).length());
        }
        lever = 16.0 * (lever + LoadScales::largest_radius(&self.scenario));
        self.wall_scales = self.scales.walls(lever);
    }

    /// The loads on each mesh file summed over the steps since the last call, and the
    /// sums set back to zero (empty unless `[output] wall_forces`).
    pub fn take_wall_loads(&mut self) -> Vec<Wrench> {
        let zero = vec![Wrench::default(); self.wall_sums.len()];
        std::mem::replace(&mut self.wall_sums, zero)
    }

    /// Stage 5b: particles whose centre is inside a `[[tags]]` box take its tag.
    #[inline(never)] // a stage of its own in profiles
    fn tag(&mut self) {
        let regions = &self.scenario.tags;
        if regions.is_empty() {
            return;
        }
        let p = &mut self.particles;
        p.tag
            .par_iter_mut()
            .zip(p.x.par_iter())
            .with_min_len(4 * MIN_PARALLEL_LEN)
            .for_each(|(tag, x)| {
                for r in regions {
                    if x.cmpge(r.min).all() && x.cmple(r.max).all() {
                        *tag = r.tag;
                    }
                }
            });
    }

    /// Whether frames carry a tag column: the scenario tags particles, or they came tagged.
    pub fn has_tags(&self) -> bool {
        let tagged = self.particles.tagged();
        let tagged = self.domain.as_ref().map_or(tagged, |d| d.comm.any(tagged));
        !self.scenario.tags.is_empty() || tagged
    }

    /// Stage 6: stop loudly rather than continue a run that has blown up: a non-finite
    /// state (`bad`, from the integration) or an overlap past the smaller diameter. `deep`
    /// lists the overlaps deeper than the smaller radius found in this step's contact
    /// stages; those within the diameter are a legitimate transient of a crowded packing
    /// (a small grain squeezed by a large one) and only warned of, once per pair.
    #[inline(never)] // a stage of its own in profiles
    fn check_stability(&mut self, mut deep: Vec<Deep>, bad: bool) -> Result<(), Unstable> {
        let p = &self.particles;
        let non_finite =
            |k: usize| !(p.x[k].is_finite() && p.v[k].is_finite() && p.w[k].is_finite());
        // Split over processes: each reports on its own particles (a pair: the one of the
        // lower id), and all stop if one must.
        let bad = match &self.domain {
            Some(d) => {
                deep.retain(|x| d.owned[x.i]);
                let own_bad = (0..p.len()).any(|k| d.owned[k] && non_finite(k));
                let bad = self.beyond_range || own_bad || deep.iter().any(Deep::through);
                d.comm.any(bad)
            }
            None => bad || deep.iter().any(Deep::through),
        };
        if !bad {
            for d in deep {
                if self.warnings.seen.insert(d.key(&p.id)) {
                    self.warnings
                        .fresh
                        .push(format!("step {}: {}", self.steps, d.describe(&p.id)));
                }
            }
            return Ok(());
        }
        // What went wrong, each with the order it is told in: the range of the sums, then
        // up to five particles in id order, then the deepest overlaps by pair.
        let mut told: Vec<(u8, u64, u64, String)> = Vec::new();
        if self.beyond_range {
            told.push((0, 0, 0, format!(
                "a contact force or torque was not finite or beyond the range of the sums ({:.3e} N, {:.3e} N m: 4096 times the largest a contact of these materials and radii should give)",
                self.scales.force.largest(),
                self.scales.torque.largest()
            )));
        }
        for k in p
            .id_order()
            .into_iter()
            .filter(|&k| self.own(k) && non_finite(k))
            .take(5)
        {
            told.push((
                1,
                p.id[k] as u64,
                0,
                format!(
                    "particle {} has a non-finite state (x = {}, v = {}, w = {})",
                    p.id[k], p.x[k], p.v[k], p.w[k]
                ),
            ));
        }
        deep.retain(Deep::through);
        deep.sort_by_key(|d| d.key(&p.id));
        for d in deep.iter().take(5) {
            let (a, other) = d.key(&p.id);
            let b = match other {
                Partner::Particle(j) => j as u64,
                Partner::Face(f) => (1 << 40) | f as u64,
            };
            told.push((2, a as u64, b, d.describe(&p.id)));
        }
        if let Some(d) = &self.domain {
            told = gather_told(&*d.comm, told);
        }
        let mut what: Vec<String> = Vec::new();
        let kind = |k: u8| told.iter().filter(move |t| t.0 == k).map(|t| t.3.clone());
        what.extend(kind(0).take(1));
        what.extend(kind(1).take(5));
        let room = 5 - what.len().min(5);
        what.extend(kind(2).take(room));
        Err(Unstable {
            step: self.steps,
            time: self.time,
            what,
            advice: self.advice(),
        })
    }

    /// Overlaps past the smaller radius so far (each pair once).
    pub fn warnings(&self) -> &Warnings {
        &self.warnings
    }

    /// Descriptions of the pairs that overlapped past the smaller radius for the first time
    /// since the last call.
    pub fn take_new_warnings(&mut self) -> Vec<String> {
        let fresh = std::mem::take(&mut self.warnings.fresh);
        match &self.domain {
            // Every process's (collective).
            Some(d) => crate::domain::gather_lines(&*d.comm, fresh),
            None => fresh,
        }
    }

    /// The likely cause of an instability, from the time step and the material.
    pub fn advice(&self) -> String {
        let s = &self.scenario;
        let dt = s.simulation.timestep;
        let eq50 = s.eq50_timestep();
        if dt > eq50 {
            format!(
                "timestep {dt:.3e} s exceeds Eq. 50's {eq50:.3e} s for this stiffness and density \
                 ({:.1} x): try timestep <= {eq50:.3e} s (or leave it unset)",
                dt / eq50
            )
        } else {
            format!(
                "timestep {dt:.3e} s is within Eq. 50's {eq50:.3e} s: check for particles \
                 created overlapping each other or the mesh, radii below radius_min, very \
                 high impact speeds or strong friction (try a smaller timestep, e.g. {:.3e} s)",
                dt / 5.0
            )
        }
    }

    /// Stage 0: moving mesh parts to their pose at the current time, with their velocity.
    pub(crate) fn move_meshes(&mut self) {
        let t = self.time;
        let mut drift: f64 = 0.0;
        for part in &mut self.moving {
            let pose = part.motion.pose(t);
            for f in part.faces.clone() {
                self.mesh.faces[f] = self.rest_faces[f].moved(&pose);
            }
            part.velocity = part.motion.velocity(t);
            for &c in &part.corners {
                drift = drift.max(pose.point(c).distance(part.pose_at_build.point(c)));
            }
        }
        self.mesh_drift = drift;
    }

    /// Records the mesh pose at a neighbour-list rebuild, and re-bins moved faces.
    fn mark_mesh_built(&mut self) {
        let t = self.time;
        for part in &mut self.moving {
            part.pose_at_build = part.motion.pose(t);
        }
        self.mesh_drift = 0.0;
    }

    /// The rest geometry of the mesh (for checkpoint fingerprints).
    pub fn rest_mesh(&self) -> Mesh {
        Mesh {
            faces: self.rest_faces.clone(),
            vertices: self.mesh.vertices.clone(),
        }
    }

    /// The mesh as it is at time `t` (for pictures of frames).
    pub fn mesh_at(&mut self, t: f64) -> &Mesh {
        let now = self.time;
        self.time = t;
        self.move_meshes();
        self.time = now;
        &self.mesh
    }

    /// Whether some part of the mesh moves.
    pub fn mesh_moves(&self) -> bool {
        !self.moving.is_empty()
    }

    /// Particles inserted by each `[[spawn]]` region so far.
    pub fn spawned(&self) -> Vec<u64> {
        let mut n = self.spawner.inserted();
        n.resize(self.scenario.spawn.len(), 0);
        n
    }

    /// Stage 1 (Section 3.1): new particles in the spawn box or the `[[spawn]]` regions.
    #[inline(never)] // a stage of its own in profiles
    fn spawn(&mut self) {
        if self.domain.is_some() {
            return self.spawn_split();
        }
        let s = &self.scenario;
        if (self.particles.next_id as u64) < s.simulation.max_particles {
            self.spawner.spawn(
                s,
                &mut self.particles,
                &self.mesh.faces,
                &self.face_grid,
                self.time,
                0.0,
            );
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
            &self.mesh.faces,
            self.mesh_drift.max(self.neighbours.shear_drift()),
        );
        match &self.domain {
            // Split over processes: all rebuild when one must.
            Some(d) if d.comm.any(stale) => {
                self.redistribute(&Default::default(), crate::domain::Placement::Now)
            }
            Some(_) => {}
            None if stale => self.rebuild_lists(!self.moving.is_empty()),
            None => {}
        }
    }

    /// Rebuilds the Verlet lists (re-sorting the particles into spatial order), re-binning
    /// the faces first if `regrid_faces` (they moved, or larger particles appeared).
    fn rebuild_lists(&mut self, regrid_faces: bool) {
        if regrid_faces || self.particles.max_radius() > self.face_grid_radius {
            self.regrid_faces();
        }
        self.neighbours
            .rebuild(&mut self.particles, &self.mesh.faces, &self.face_grid);
        self.built();
    }

    /// Bins the faces as they are now for particles up to the largest radius.
    fn regrid_faces(&mut self) {
        let g = &self.scenario.geometry;
        self.regrid_faces_for(g.radius_max.max(self.particles.max_radius()));
    }

    /// After a rebuild: loads for the particles, pieces of the face list, and the mesh pose
    /// the lists were built with.
    pub(crate) fn built(&mut self) {
        self.loads.clear();
        self.loads.resize(self.particles.len(), Load::default());
        self.built_at = self.steps;
        self.mark_mesh_built();
    }

    /// Stage 3 (Section 2.2): the force of every touching particle pair, once per pair,
    /// added to the loads of both particles (with the reactions of Eqs. 56-60). Returns the
    /// overlaps deeper than the smaller radius.
    ///
    /// The owners are cut into slabs whose partners lie at most in the next slab
    /// (`Neighbours::slabs`): the even slabs run at the same time, then the odd ones, so a
    /// load is added to by one slab at a time, in an order that does not depend on the
    /// number of threads. Each slab first sorts out its touching pairs (a pair that has just
    /// parted forgets its springs), then evaluates them `WIDTH` at a time in SIMD lanes; a
    /// lane gives the bits the pair would give alone. Body i of a pair is the particle of
    /// the lower id, so a pair's force and springs do not depend on the storage order.
    #[inline(never)] // a stage of its own in profiles
    fn particle_contacts(&mut self) -> Vec<Deep> {
        let deep = Mutex::new(Vec::new());
        let beyond = AtomicBool::new(false);
        let scales = &self.scales;
        let p = &self.particles;
        let law = &self.law;
        let densities = &self.densities;
        // One material: the same coefficients and density in every lane, set up once.
        let uniform = law.uniform();
        let one_pair: Coefficients<Group> = law.pair(0, 0).splat();
        let mass_per_r3 = |idx: &[usize; WIDTH]| {
            if uniform {
                Group::splat(densities[0].mass_per_r3)
            } else {
                Group::gather(idx.map(|k| densities[p.material[k] as usize].mass_per_r3))
            }
        };
        let ContactList {
            start,
            partner,
            contact,
            pieces: slabs,
            stores,
        } = &mut self.neighbours.pairs;
        let (start, partner, slabs) = (&*start, &*partner, &*slabs);
        thread_local! {
            static TOUCHING: std::cell::RefCell<Vec<[u32; 3]>> = Default::default();
        }
        for phase in 0..2 {
            let mut all: Vec<Option<Piece>> =
                pieces(slabs, &mut self.loads, start, contact, stores)
                    .into_iter()
                    .map(Some)
                    .collect();
            // A slab, with the loads of the next one.
            let tasks: Vec<(Piece, Option<Piece>)> = (phase..all.len())
                .step_by(2)
                .map(|s| {
                    let own = all[s].take().expect("each slab once");
                    (own, all.get_mut(s + 1).and_then(Option::take))
                })
                .collect();
            tasks.into_par_iter().for_each(|(slab, next)| {
                TOUCHING.with_borrow_mut(|touching| {
                    let Piece {
                        owners,
                        first,
                        loads,
                        contact,
                        store,
                    } = slab;
                    let mut next_loads = next.map(|n| (n.owners.start, n.loads));
                    // The touching pairs: the particle of the lower id (body i of the law,
                    // whatever the storage order), the other, and the contact's entry in the
                    // slab's store (opened at first touch, closed when the pair parts).
                    touching.clear();
                    for i in owners.clone() {
                        let (xi, ri) = (p.x[i], p.radius[i]);
                        let run = start[i] as usize - first..start[i + 1] as usize - first;
                        for kl in run {
                            let j = partner[first + kl] as usize;
                            let reach = ri + p.radius[j];
                            if (xi - p.x[j]).length_squared() < reach * reach {
                                let (a, b) = if p.id[i] < p.id[j] { (i, j) } else { (j, i) };
                                if contact[kl] == NONE {
                                    contact[kl] = store.open();
                                }
                                touching.push([a as u32, b as u32, contact[kl]]);
                            } else if contact[kl] != NONE {
                                // The contact ended: forget its history.
                                store.close(contact[kl]);
                                contact[kl] = NONE;
                            }
                        }
                    }
                    let (base, owned) = (owners.start, owners.end);
                    // The load of a particle of this slab or of the next one.
                    fn load<'l>(
                        idx: usize,
                        (base, owned): (usize, usize),
                        loads: &'l mut [Load],
                        next: &'l mut Option<(usize, &mut [Load])>,
                    ) -> &'l mut Load {
                        if idx < owned {
                            &mut loads[idx - base]
                        } else {
                            let (start, next) =
                                next.as_mut().expect("partners reach the next slab only");
                            &mut next[idx - *start]
                        }
                    }
                    for group in touching.chunks(WIDTH) {
                        // A short last group repeats its last pair in the spare lanes.
                        let (mut i, mut j, mut c) = ([0; WIDTH], [0; WIDTH], [0; WIDTH]);
                        for l in 0..WIDTH {
                            let [a, b, e] = group[l.min(group.len() - 1)];
                            (i[l], j[l], c[l]) = (a as usize, b as usize, e);
                        }
                        let body = |idx: [usize; WIDTH]| Body::<Group> {
                            x: Group::gather_vec_at(&p.x, &idx),
                            radius: Group::gather_at(&p.radius, &idx),
                            v: Group::gather_vec_at(&p.v, &idx),
                            w: Group::gather_vec_at(&p.w, &idx),
                        };
                        let (body_i, body_j) = (body(i), body(j));
                        let d = body_i.x - body_j.x; // Eq. (8)
                        let kin = Kinematics::of_touching_particles(
                            &body_i,
                            &body_j,
                            d,
                            Group::dot(d, d),
                        );
                        let mut lanes = gather_springs(store, c);
                        let other = Other::Particle {
                            r: body_j.radius,
                            m: Inertia::mass_with(body_j.radius, mass_per_r3(&j)),
                        };
                        let m_i = Inertia::mass_with(body_i.radius, mass_per_r3(&i));
                        let coef = if uniform {
                            one_pair
                        } else {
                            Coefficients::gather(std::array::from_fn(|l| {
                                law.pair(p.material[i[l]], p.material[j[l]])
                            }))
                        };
                        let force =
                            law.evaluate(&coef, body_i.radius, m_i, other, &kin, &mut lanes);
                        scatter_springs(lanes, store, &c[..group.len()]);
                        let (f, tau_i, tau_j) = (
                            Group::scatter_vec(force.f),
                            Group::scatter_vec(force.tau_i),
                            Group::scatter_vec(force.tau_j),
                        );
                        let (at, lanes, mut fine) = ((base, owned), &scales.lanes, true);
                        for l in 0..group.len() {
                            let load_i = load(i[l], at, loads, &mut next_loads);
                            fine &= load_i.add(pack(f[l], tau_i[l]), lanes);
                            let load_j = load(j[l], at, loads, &mut next_loads);
                            fine &= load_j.add(pack(-f[l], tau_j[l]), lanes); // Eqs. (56)-(60)
                        }
                        if !fine {
                            beyond.store(true, Ordering::Relaxed);
                        }
                        if kin.delta.simd_gt(body_i.radius.min(body_j.radius)).any() {
                            let delta = kin.delta.scatter();
                            for l in 0..group.len() {
                                let limit = p.radius[i[l]].min(p.radius[j[l]]);
                                if delta[l] > limit {
                                    deep.lock().expect("not poisoned").push(Deep {
                                        i: i[l],
                                        other: Partner::Particle(j[l]),
                                        delta: delta[l],
                                        limit,
                                    });
                                }
                            }
                        }
                    }
                });
            });
        }
        let mut deep = deep.into_inner().expect("not poisoned");
        self.beyond_range |= beyond.into_inner();
        self.wrapped_contacts(&mut deep);
        deep
    }

    /// Stage 3, across periodic sides: the pairs of `Neighbours::wrapped`, partner j seen at
    /// its image x_j + shift, one by one in slot order (they are few: those at the sides),
    /// after the slabs; the law as for any pair, body i the lower id.
    fn wrapped_contacts(&mut self, deep: &mut Vec<Deep>) {
        let p = &self.particles;
        let law = &self.law;
        let nb = &mut self.neighbours;
        let images: Vec<(DVec3, DVec3)> = (0..nb.shift.len()).map(|k| nb.image(k)).collect();
        let ContactList {
            start,
            partner,
            contact,
            pieces,
            stores,
        } = &mut nb.wrapped;
        let mass = |k: usize| {
            Inertia::mass_with(
                p.radius[k],
                self.densities[p.material[k] as usize].mass_per_r3,
            )
        };
        for piece in 0..pieces.len().saturating_sub(1) {
            let store = &mut stores[piece];
            for a in pieces[piece] as usize..pieces[piece + 1] as usize {
                for k in start[a] as usize..start[a + 1] as usize {
                    let b = partner[k] as usize;
                    // Seen from the lower id: the other at its image (and its velocity), as
                    // `Neighbours::across`.
                    let (shift, dv) = images[k];
                    let (i, j) = if p.id[a] < p.id[b] { (a, b) } else { (b, a) };
                    let body = |k: usize, x: DVec3, dv: DVec3| Body {
                        x,
                        radius: p.radius[k],
                        v: p.v[k] + dv,
                        w: p.w[k],
                    };
                    let (bi, bj) = (body(i, p.x[i], DVec3::ZERO), body(j, p.x[j] + shift, dv));
                    let Some(kin) = Kinematics::between_particles(&bi, &bj) else {
                        if contact[k] != NONE {
                            store.close(contact[k]);
                            contact[k] = NONE;
                        }
                        continue;
                    };
                    if contact[k] == NONE {
                        contact[k] = store.open();
                    }
                    let springs = &mut store.springs[contact[k] as usize];
                    let other = Other::Particle {
                        r: p.radius[j],
                        m: mass(j),
                    };
                    let coef = law.pair(p.material[i], p.material[j]);
                    let force = law.evaluate(coef, p.radius[i], mass(i), other, &kin, springs);
                    let scales = &self.scales;
                    let (load_i, load_j) = pair_mut(&mut self.loads, i, j);
                    let fine = load_i.add(pack(force.f, force.tau_i), &scales.lanes)
                        & load_j.add(pack(-force.f, force.tau_j), &scales.lanes); // Eqs. (56)-(60)
                    self.beyond_range |= !fine;
                    let limit = p.radius[i].min(p.radius[j]);
                    if kin.delta > limit {
                        deep.push(Deep {
                            i,
                            other: Partner::Particle(j),
                            delta: kin.delta,
                            limit,
                        });
                    }
                }
            }
        }
    }

    /// Stage 4 (Sections 2.2, 3.3): the force of every particle-face contact. Returns the
    /// overlaps deeper than the particle's radius.
    ///
    /// Each piece of the list holds whole runs of owners. For each particle it finds the
    /// faces within reach (closest point, kinematics), decides which of them are contacts
    /// of their own (one per touch of a connected surface, `surface.rs`; with `per_face`
    /// every face is a surface of its own), hands the springs of the others to the contact
    /// that absorbs them, then evaluates the law for `WIDTH` contacts at a time in SIMD
    /// lanes (bit for bit as alone).
    #[inline(never)] // a stage of its own in profiles
    fn mesh_contacts(&mut self) -> Vec<Deep> {
        let deep = Mutex::new(Vec::new());
        let beyond = AtomicBool::new(false);
        let scales = &self.scales;
        let p = &self.particles;
        let law = &self.law;
        let faces = &self.mesh.faces;
        let (face_part, moving) = (&self.face_part, &self.moving);
        let (densities, face_material) = (&self.densities, &self.face_material);
        let uniform = law.uniform();
        let one_wall: Coefficients<Group> = law.with_wall(0, 0).splat();
        let ContactList {
            start,
            partner,
            contact,
            pieces: bounds,
            stores,
        } = &mut self.neighbours.faces;
        let (start, partner) = (&*start, &*partner);
        thread_local! {
            static SCRATCH: std::cell::RefCell<MeshScratch> = Default::default();
        }
        let (face_file, files, about) = (&self.face_file, self.wall_sums.len(), &self.mesh_files);
        let wall_scales = &self.wall_scales;
        let owned = self.domain.as_ref().map(|d| &d.owned[..]);
        let all = pieces(bounds, &mut self.loads, start, contact, stores);
        let walls: Vec<(Vec<Sum6>, bool)> = all
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN.div_ceil(FACE_PIECE))
            .map(|piece| {
                SCRATCH.with_borrow_mut(|scratch| {
                    let Piece {
                        owners,
                        first,
                        loads,
                        contact,
                        store,
                    } = piece;
                    let MeshScratch {
                        near,
                        candidates,
                        contacts,
                        order,
                        fates,
                    } = scratch;
                    // The faces within reach, each with its closest point and kinematics; the
                    // slots of a particle are consecutive, so are its candidates.
                    near.clear();
                    for i in owners.clone() {
                        let run = start[i] as usize..start[i + 1] as usize;
                        if run.is_empty() {
                            continue;
                        }
                        let body = Body {
                            x: p.x[i],
                            radius: p.radius[i],
                            v: p.v[i],
                            w: p.w[i],
                        };
                        for (k, &f) in run.clone().zip(&partner[run]) {
                            let kl = k - first;
                            let face = &faces[f as usize];
                            let touch = if face.certainly_beyond(body.x, body.radius + face.radius)
                            {
                                None
                            } else {
                                let wall = match face_part[f as usize] {
                                    STATIC => RigidVelocity::default(),
                                    part => moving[part as usize].velocity,
                                };
                                let (d, feature) = face.separation_and_feature(body.x);
                                let (d, interior) =
                                    surface::snap(face, body.x, body.radius, d, feature);
                                Kinematics::with_wall(&body, d, face.radius, &wall)
                                    .map(|kin| (kin, d, interior))
                            };
                            match touch {
                                Some((kin, d, interior)) => near.push(Near {
                                    owner: i as u32,
                                    slot: kl,
                                    kin,
                                    d,
                                    interior,
                                }),
                                None if contact[kl] != NONE => {
                                    // The contact ended: forget its history.
                                    store.close(contact[kl]);
                                    contact[kl] = NONE;
                                }
                                None => {}
                            }
                        }
                    }
                    // One contact per touch, particle by particle; the absorbed hand over
                    // their springs and are treated as apart.
                    contacts.clear();
                    let mut a = 0;
                    while a < near.len() {
                        let i = near[a].owner as usize;
                        let mut b = a + 1;
                        while b < near.len() && near[b].owner as usize == i {
                            b += 1;
                        }
                        let (x, radius) = (p.x[i], p.radius[i]);
                        let several = b - a > 1;
                        if several {
                            candidates.clear();
                            candidates.extend(near[a..b].iter().map(|c| Candidate {
                                face: partner[first + c.slot],
                                point: x - c.d,
                                dist2: c.d.length_squared(),
                                interior: c.interior,
                            }));
                            let tol = surface::tolerance(x, radius);
                            surface::resolve(candidates, faces, tol, order, fates);
                            for (c, fate) in near[a..b].iter().zip(fates.iter()) {
                                let Fate::Absorbed(s) = *fate else { continue };
                                let (k, s) = (c.slot, near[a + s].slot);
                                let none = |e: u32| {
                                    e == NONE || store.springs[e as usize] == Springs::default()
                                };
                                if none(contact[s]) && contact[k] != NONE {
                                    if contact[s] == NONE {
                                        // The absorbing contact takes over the entry.
                                        (contact[s], contact[k]) = (contact[k], NONE);
                                    } else {
                                        let e = contact[k] as usize;
                                        store.springs[contact[s] as usize] = store.springs[e];
                                    }
                                }
                            }
                        }
                        for (c, near) in near[a..b].iter().enumerate() {
                            let k = near.slot;
                            if !several || fates[c] == Fate::Contact {
                                if near.kin.delta > radius {
                                    deep.lock().expect("not poisoned").push(Deep {
                                        i,
                                        other: Partner::Face(partner[first + k] as usize),
                                        delta: near.kin.delta,
                                        limit: radius,
                                    });
                                }
                                if contact[k] == NONE {
                                    contact[k] = store.open();
                                }
                                contacts.push((a + c) as u32);
                            } else if contact[k] != NONE {
                                store.close(contact[k]);
                                contact[k] = NONE;
                            }
                        }
                        a = b;
                    }
                    // The law, `WIDTH` contacts at a time (as for particle pairs), added to
                    // the particles' loads, and their reactions (of own particles, in a split
                    // run) to the piece's exact sum for each mesh file.
                    let (mut wall, mut wall_fine) = (vec![Sum6::default(); files], true);
                    for group in contacts.chunks(WIDTH) {
                        let c: [&Near; WIDTH] =
                            std::array::from_fn(|l| &near[group[l.min(group.len() - 1)] as usize]);
                        let e = c.map(|c| contact[c.slot]);
                        let i = c.map(|c| c.owner as usize);
                        let scalar =
                            |get: fn(&Kinematics) -> f64| Group::gather(c.map(|c| get(&c.kin)));
                        let vector = |get: fn(&Kinematics) -> DVec3| {
                            Group::gather_vec(c.map(|c| get(&c.kin)))
                        };
                        let kin = Kinematics::<Group> {
                            n: vector(|k| k.n),
                            delta: scalar(|k| k.delta),
                            r_i: scalar(|k| k.r_i),
                            r_j: scalar(|k| k.r_j),
                            v: vector(|k| k.v),
                            omega: vector(|k| k.omega),
                        };
                        let radius = Group::gather(i.map(|i| p.radius[i]));
                        let (mass, coef) = if uniform {
                            (
                                Inertia::mass_with(radius, Group::splat(densities[0].mass_per_r3)),
                                one_wall,
                            )
                        } else {
                            let m = i.map(|i| p.material[i]);
                            let f = c.map(|c| face_material[partner[first + c.slot] as usize]);
                            (
                                Inertia::mass_with(
                                    radius,
                                    Group::gather(m.map(|m| densities[m as usize].mass_per_r3)),
                                ),
                                Coefficients::gather(std::array::from_fn(|l| {
                                    law.with_wall(m[l], f[l])
                                })),
                            )
                        };
                        let mut lanes = gather_springs(store, e);
                        let force =
                            law.evaluate(&coef, radius, mass, Other::Wall, &kin, &mut lanes);
                        scatter_springs(lanes, store, &e[..group.len()]);
                        let (f, tau) =
                            (Group::scatter_vec(force.f), Group::scatter_vec(force.tau_i));
                        let mut fine = true;
                        for l in 0..group.len() {
                            let load = &mut loads[i[l] - owners.start];
                            fine &= load.add(pack(f[l], tau[l]), &scales.lanes);
                        }
                        if !fine {
                            beyond.store(true, Ordering::Relaxed);
                        }
                        if files > 0 {
                            // The reaction on the mesh file (Newton's third law for the
                            // force and for the torque about the file's reference point).
                            for l in (0..group.len()).filter(|&l| owned.is_none_or(|o| o[i[l]])) {
                                let k = face_file[partner[first + c[l].slot] as usize] as usize;
                                let arm = p.x[i[l]] - about[k].torque_about;
                                let reaction = pack(-f[l], -(arm.cross(f[l]) + tau[l]));
                                wall_fine &= wall[k].add(reaction, wall_scales);
                            }
                        }
                    }
                    (wall, wall_fine)
                })
            })
            .collect();
        if !self.wall_sums.is_empty() {
            let mut step = vec![Sum6::default(); self.wall_sums.len()];
            for (piece, fine) in walls {
                self.beyond_range |= !fine;
                for (sum, w) in step.iter_mut().zip(&piece) {
                    sum.merge(w);
                }
            }
            self.reduce_walls(&mut step);
            for (sum, w) in self.wall_sums.iter_mut().zip(&step) {
                let [fx, fy, fz, tx, ty, tz] = w.value(&self.wall_scales);
                *sum += Wrench {
                    f: DVec3::new(fx, fy, fz),
                    tau: DVec3::new(tx, ty, tz),
                };
            }
        }
        self.beyond_range |= beyond.into_inner();
        deep.into_inner().expect("not poisoned")
    }

    /// Stage 5 (Section 2.3): advance each particle by Δt under the force and torque its
    /// contacts added to its load (Eqs. 1-2).
    /// Returns whether some particle's new state is not finite (for stage 6, so that it
    /// needs no pass of its own).
    #[inline(never)] // a stage of its own in profiles
    fn integrate(&mut self) -> bool {
        let s = &self.scenario;
        let scales = &self.scales;
        let (dt, g) = (s.simulation.timestep, s.kinetics.gravity);
        let densities = &self.densities;
        let uniform = densities.len() == 1;
        let p = &mut self.particles;
        let material = &p.material;
        (
            p.x.par_chunks_mut(WIDTH),
            p.v.par_chunks_mut(WIDTH),
            p.q.par_chunks_mut(WIDTH),
            p.w.par_chunks_mut(WIDTH),
            p.radius.par_chunks(WIDTH),
            material.par_chunks(WIDTH),
            self.loads.par_chunks_mut(WIDTH),
        )
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN.div_ceil(WIDTH))
            .map(|(x, v, q, w, radius, material, load)| {
                // `WIDTH` particles at a time in lanes; a short last group repeats its last
                // particle in the spare lanes. The loads are used up (zeroed for the next
                // step).
                let n = x.len();
                let lane: [usize; WIDTH] = std::array::from_fn(|l| l.min(n - 1));
                let (mut f, mut tau) = ([DVec3::ZERO; WIDTH], [DVec3::ZERO; WIDTH]);
                for l in 0..WIDTH {
                    let v = load[lane[l]].value(&scales.lanes);
                    (f[l], tau[l]) = (DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5]));
                }
                load.fill(Load::default());
                let state = State::<Group> {
                    x: Group::gather_vec_at(x, &lane),
                    v: Group::gather_vec_at(v, &lane),
                    q: Group::gather_quat_at(q, &lane),
                    w: Group::gather_vec_at(w, &lane),
                };
                let (inv_mass_r3, drag) = if uniform {
                    let d = densities[0];
                    (Group::splat(d.inv_mass_r3), Group::splat(d.drag))
                } else {
                    let d = lane.map(|l| densities[material[l] as usize]);
                    (
                        Group::gather(d.map(|d| d.inv_mass_r3)),
                        Group::gather(d.map(|d| d.drag)),
                    )
                };
                let body = Response::with(Group::gather_at(radius, &lane), inv_mass_r3, drag);
                let new = advance(
                    state,
                    &body,
                    Group::gather_vec(f),
                    Group::gather_vec(tau),
                    Group::splat_vec(g),
                    Group::splat(dt),
                );
                let (new_x, new_v, new_q, new_w) = (
                    Group::scatter_vec(new.x),
                    Group::scatter_vec(new.v),
                    Group::scatter_quat(new.q),
                    Group::scatter_vec(new.w),
                );
                x.copy_from_slice(&new_x[..n]);
                v.copy_from_slice(&new_v[..n]);
                q.copy_from_slice(&new_q[..n]);
                w.copy_from_slice(&new_w[..n]);
                (0..n).any(|l| !(x[l].is_finite() && v[l].is_finite() && w[l].is_finite()))
            })
            .reduce(|| false, |a, b| a || b)
    }
}
