//! The simulation: state and the time step as named stages.
//!
//! ```text
//! step:  move meshes -> spawn -> update neighbours -> particle contacts -> mesh contacts
//!        -> integrate -> check stability
//! ```

use std::sync::Mutex;
use std::time::Instant;

use anyhow::{Result, bail};
use glam::DVec3;
use rayon::prelude::*;

use crate::contact::{Body, ContactForce, ContactLaw, Kinematics, Other, Springs};
use crate::integrate::{Inertia, Response, State, advance};
use crate::lanes::{Gather, Lanes};
use crate::mesh::{Contacts, Face, Mesh};
use crate::motion::{Motion, Pose, RigidVelocity};
use crate::neighbours::{CellGrid, ContactList, MIN_PARALLEL_LEN, Neighbours, face_grid};
use crate::particles::Particles;
use crate::scenario::{MeshSource, Scenario, default_timestep};
use crate::spawn::{Spawner, SpawnerState};
use crate::surface::{self, Candidate, Fate};

/// List slots per piece of the contact stages: small enough for stack buffers, large
/// enough to fill lanes.
const PIECE: usize = 256;
/// Contacts per group evaluated together: 8 doubles fill an AVX-512 register, two AVX ones.
const WIDTH: usize = 8;
type Group = wide::f64x8;

/// A piece of a contact list (`PIECE` slots): the forces, springs, touched flags, owners
/// and partners of its slots.
type Piece<'a> = (
    &'a mut [ContactForce],
    &'a mut [Springs],
    &'a mut [bool],
    &'a [u32],
    &'a [u32],
);

/// The pieces of `list` and its slots' `forces`, for the contact stages to run in parallel.
fn pieces<'a>(
    forces: &'a mut [ContactForce],
    list: &'a mut ContactList,
) -> impl IndexedParallelIterator<Item = Piece<'a>> {
    forces
        .par_chunks_mut(PIECE)
        .zip(list.springs.par_chunks_mut(PIECE))
        .zip(list.touched.par_chunks_mut(PIECE))
        .zip(
            list.owner
                .par_chunks(PIECE)
                .zip(list.partner.par_chunks(PIECE)),
        )
        .map(|(((forces, springs), touched), (owner, partner))| {
            (forces, springs, touched, owner, partner)
        })
        .with_min_len(MIN_PARALLEL_LEN.div_ceil(PIECE))
}

/// Boundaries of pieces of at least `PIECE` slots (the last may be shorter) that keep each
/// owner's run of slots whole; `start` is a compressed list's run starts.
fn owner_aligned_bounds(start: &[u32]) -> Vec<usize> {
    let mut bounds = vec![0];
    for &k in start {
        let k = k as usize;
        if k - bounds[bounds.len() - 1] >= PIECE {
            bounds.push(k);
        }
    }
    let end = start.last().map_or(0, |&k| k as usize);
    if end > bounds[bounds.len() - 1] {
        bounds.push(end);
    }
    bounds
}

/// `slice` cut at `bounds` (ascending, from 0 to its length).
fn cut<'a, T>(mut slice: &'a mut [T], bounds: &[usize]) -> Vec<&'a mut [T]> {
    bounds
        .windows(2)
        .map(|w| {
            let (piece, rest) = std::mem::take(&mut slice).split_at_mut(w[1] - w[0]);
            slice = rest;
            piece
        })
        .collect()
}

/// The pieces of `list` cut at `bounds` (see [`owner_aligned_bounds`]), with its slots'
/// `forces`: every owner's slots lie in one piece.
fn owner_pieces<'a>(
    forces: &'a mut [ContactForce],
    list: &'a mut ContactList,
    bounds: &[usize],
) -> impl IndexedParallelIterator<Item = Piece<'a>> {
    let mut owner: &[u32] = &list.owner;
    let mut partner: &[u32] = &list.partner;
    let fixed: Vec<(&[u32], &[u32])> = bounds
        .windows(2)
        .map(|w| {
            let n = w[1] - w[0];
            let (o, rest_o) = owner.split_at(n);
            let (p, rest_p) = partner.split_at(n);
            (owner, partner) = (rest_o, rest_p);
            (o, p)
        })
        .collect();
    cut(forces, bounds)
        .into_par_iter()
        .zip(cut(&mut list.springs, bounds))
        .zip(cut(&mut list.touched, bounds))
        .zip(fixed)
        .map(|(((forces, springs), touched), (owner, partner))| {
            (forces, springs, touched, owner, partner)
        })
        .with_min_len(MIN_PARALLEL_LEN.div_ceil(PIECE))
}

/// The springs of slots `k` in the lanes of a group.
#[inline(always)]
fn gather_springs(springs: &[Springs], k: [usize; WIDTH]) -> Springs<Group> {
    Springs {
        u_s: Group::gather_vec(k.map(|k| springs[k].u_s)),
        u_r: Group::gather_vec(k.map(|k| springs[k].u_r)),
        u_t: Group::gather(k.map(|k| springs[k].u_t)),
    }
}

/// Puts the springs of a group's lanes back into slots `k` (the first `k.len()` lanes).
#[inline(always)]
fn scatter_springs(lanes: Springs<Group>, springs: &mut [Springs], k: &[usize]) {
    let (u_s, u_r, u_t) = (
        Group::scatter_vec(lanes.u_s),
        Group::scatter_vec(lanes.u_r),
        lanes.u_t.scatter(),
    );
    for (l, &k) in k.iter().enumerate() {
        springs[k] = Springs {
            u_s: u_s[l],
            u_r: u_r[l],
            u_t: u_t[l],
        };
    }
}

/// Puts the forces of a group's lanes into slots `k` (the first `k.len()` lanes).
#[inline(always)]
fn scatter_forces(lanes: ContactForce<Group>, forces: &mut [ContactForce], k: &[usize]) {
    let (f, tau_i, tau_j) = (
        Group::scatter_vec(lanes.f),
        Group::scatter_vec(lanes.tau_i),
        Group::scatter_vec(lanes.tau_j),
    );
    for (l, &k) in k.iter().enumerate() {
        forces[k] = ContactForce {
            f: f[l],
            tau_i: tau_i[l],
            tau_j: tau_j[l],
        };
    }
}

/// A face within reach of a particle, in stage 4.
struct Near {
    /// Its slot in the particle-face list.
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
    Stability,
}

impl Stage {
    pub const ALL: [Stage; 8] = [
        Stage::MoveMeshes,
        Stage::Spawn,
        Stage::Neighbours,
        Stage::ParticleContacts,
        Stage::MeshContacts,
        Stage::Integrate,
        Stage::Tag,
        Stage::Stability,
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
            Stage::Stability => "stability check",
        }
    }
}

/// Wall time spent in each stage of the step so far [s].
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

/// Verlet skin as a fraction of R_max.
const SKIN_PER_RADIUS: f64 = 0.5;

/// Everything needed to continue a run bit for bit: particles, step count, the spawner's
/// place in its random stream, and the contact history (the friction springs of every
/// touching pair, Table 3).
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub steps: u64,
    pub particles: Particles,
    pub spawner: SpawnerState,
    pub pair_history: Vec<(u32, u32, Springs)>,
    pub face_history: Vec<(u32, u32, Springs)>,
}

/// The partner of a particle in a contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Partner {
    Particle(usize),
    Face(usize),
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

    /// "particles 1 and 2 overlap by ..., more than the smaller radius ..." (or diameter).
    fn describe(&self) -> String {
        let (bound, size) = if self.through() {
            ("diameter", 2.0 * self.limit)
        } else {
            ("radius", self.limit)
        };
        match self.other {
            Partner::Particle(j) => format!(
                "particles {} and {j} overlap by {:.3e} m, more than the smaller {bound} {size:.3e} m",
                self.i, self.delta
            ),
            Partner::Face(f) => format!(
                "particle {} overlaps mesh face {f} by {:.3e} m, more than its {bound} {size:.3e} m",
                self.i, self.delta
            ),
        }
    }
}

/// Overlaps deeper than the smaller radius that did not stop the run, each pair counted
/// once.
#[derive(Clone, Debug, Default)]
pub struct Warnings {
    seen: rustc_hash::FxHashSet<(usize, Partner)>,
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
}

/// A running simulation.
pub struct Simulation {
    pub scenario: Scenario,
    pub particles: Particles,
    pub mesh: Mesh,
    /// The mesh files `mesh` was put together from.
    pub mesh_files: Vec<MeshFile>,
    law: ContactLaw,
    neighbours: Neighbours,
    face_grid: CellGrid,
    spawner: Spawner,
    /// Force of each particle pair slot and each particle-face slot, this step.
    pair_forces: Vec<ContactForce>,
    face_forces: Vec<ContactForce>,
    /// Pieces of the particle-face list for stage 4, each holding whole runs of owners.
    face_pieces: Vec<usize>,
    /// The mesh as read (at t = 0).
    rest_faces: Vec<Face>,
    /// Parts of the mesh that follow a prescribed motion.
    moving: Vec<MovingPart>,
    /// For each face, its moving part, or `STATIC`.
    face_part: Vec<u32>,
    /// Largest displacement of a moving face since the last neighbour-list rebuild.
    mesh_drift: f64,
    /// Simulated time [T] and number of steps taken.
    pub time: f64,
    pub steps: u64,
    /// Wall time per stage.
    pub stage_times: StageTimes,
    /// Overlaps past the smaller radius that did not stop the run.
    warnings: Warnings,
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
            });
            mesh.append(part);
        }
        let particles = match &scenario.particles {
            Some(path) => crate::csv::load_particles(path)?,
            None => Particles::default(),
        };
        let mut sim = Simulation::from_parts(scenario, mesh, particles)?;
        sim.mesh_files = files;
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
        let mut sim = Simulation::new(Scenario {
            particles: None,
            ..scenario
        })?;
        sim.particles = snapshot.particles;
        sim.steps = snapshot.steps;
        sim.time = sim.steps as f64 * sim.scenario.simulation.timestep;
        sim.spawner = Spawner::resume(sim.scenario.simulation.seed, snapshot.spawner);
        sim.move_meshes();
        sim.rebuild_lists(true);
        sim.neighbours
            .pairs
            .restore(&snapshot.pair_history)
            .and_then(|()| sim.neighbours.faces.restore(&snapshot.face_history))
            .map_err(|e| anyhow::anyhow!("the checkpoint does not fit its particles: {e}"))?;
        Ok(sim)
    }

    /// The complete state of the run.
    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            steps: self.steps,
            particles: self.particles.clone(),
            spawner: self.spawner.state(),
            pair_history: self.neighbours.pairs.history(),
            face_history: self.neighbours.faces.history(),
        }
    }

    /// Sets up a simulation from a mesh and particles already in memory.
    pub fn from_parts(scenario: Scenario, mesh: Mesh, particles: Particles) -> Result<Simulation> {
        let g = &scenario.geometry;
        let max_radius = g.radius_max.max(particles.max_radius());
        if particles.len() as u64 > u32::MAX as u64 / 2 {
            bail!("too many particles: {}", particles.len());
        }
        let skin = SKIN_PER_RADIUS * g.radius_max;
        let face_grid = face_grid(&mesh.faces, max_radius, skin);
        Ok(Simulation {
            law: ContactLaw::new(&scenario.material, scenario.simulation.timestep),
            neighbours: Neighbours::new(skin),
            face_grid,
            spawner: Spawner::new(scenario.simulation.seed),
            pair_forces: Vec::new(),
            face_forces: Vec::new(),
            face_pieces: vec![0],
            rest_faces: mesh.faces.clone(),
            moving: Vec::new(),
            face_part: vec![STATIC; mesh.faces.len()],
            mesh_drift: 0.0,
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
            }],
            scenario,
            particles,
            mesh,
        })
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
        let touching = |f: &ContactForce| *f != ContactForce::default();
        self.pair_forces.iter().filter(|f| touching(f)).count()
            + self.face_forces.iter().filter(|f| touching(f)).count()
    }

    /// Advances the simulation by one time step Δt.
    ///
    /// Fails, leaving the state as computed, when the run has become unstable: an overlap
    /// deeper than the smaller radius, or a non-finite position or velocity.
    pub fn step(&mut self) -> Result<(), Unstable> {
        let t = Instant::now();
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
        self.steps += 1;
        self.time = self.steps as f64 * self.scenario.simulation.timestep;
        let result = self.check_stability(deep, non_finite);
        self.stage_times.add(Stage::Stability, t);
        result
    }

    /// Stage 5b: particles whose centre is inside a `[[tags]]` box take its tag.
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
        !self.scenario.tags.is_empty() || self.particles.tagged()
    }

    /// Stage 6: stop loudly rather than continue a run that has blown up: a non-finite
    /// state (`bad`, from the integration) or an overlap past the smaller diameter. `deep`
    /// lists the overlaps deeper than the smaller radius found in this step's contact
    /// stages; those within the diameter are a legitimate transient of a crowded packing
    /// (a small grain squeezed by a large one) and only warned of, once per pair.
    fn check_stability(&mut self, mut deep: Vec<Deep>, bad: bool) -> Result<(), Unstable> {
        let p = &self.particles;
        let non_finite =
            |k: usize| !(p.x[k].is_finite() && p.v[k].is_finite() && p.w[k].is_finite());
        if !bad && deep.iter().all(|d| !d.through()) {
            for d in deep {
                if self.warnings.seen.insert((d.i, d.other)) {
                    self.warnings
                        .fresh
                        .push(format!("step {}: {}", self.steps, d.describe()));
                }
            }
            return Ok(());
        }
        let mut what = Vec::new();
        for k in (0..p.len()).filter(|&k| non_finite(k)).take(5) {
            what.push(format!(
                "particle {k} has a non-finite state (x = {}, v = {}, w = {})",
                p.x[k], p.v[k], p.w[k]
            ));
        }
        deep.retain(Deep::through);
        deep.sort_by_key(|d| (d.i, d.other));
        for d in deep.iter().take(5 - what.len().min(5)) {
            what.push(d.describe());
        }
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
        std::mem::take(&mut self.warnings.fresh)
    }

    /// The likely cause of an instability, from the time step and the material.
    pub fn advice(&self) -> String {
        let s = &self.scenario;
        let dt = s.simulation.timestep;
        let eq50 = default_timestep(s.geometry.radius_min, &s.material);
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
    fn move_meshes(&mut self) {
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

    /// Stage 1 (Section 3.1): new particles in the spawn box.
    fn spawn(&mut self) {
        let s = &self.scenario;
        if self.particles.len() < s.simulation.max_particles as usize {
            self.spawner
                .spawn(s, &mut self.particles, &self.mesh.faces, &self.face_grid);
        }
    }

    /// Stage 2 (Section 3.3): rebuild the Verlet lists when they may miss a contact.
    fn update_neighbours(&mut self) {
        let p = &self.particles;
        if self
            .neighbours
            .stale(&p.x, &p.radius, &self.mesh.faces, self.mesh_drift)
        {
            self.rebuild_lists(!self.moving.is_empty());
        }
    }

    /// Rebuilds the Verlet lists, re-binning the faces first if `regrid_faces` (they moved,
    /// or larger particles appeared).
    fn rebuild_lists(&mut self, regrid_faces: bool) {
        if regrid_faces {
            let g = &self.scenario.geometry;
            let max_radius = g.radius_max.max(self.particles.max_radius());
            self.face_grid = face_grid(&self.mesh.faces, max_radius, self.neighbours.skin);
        }
        let p = &self.particles;
        self.neighbours
            .rebuild(&p.x, &p.radius, &self.mesh.faces, &self.face_grid);
        // The new slots' forces are zero until their pairs touch; stages 3 and 4 then write
        // a slot's force while it touches and zero it once when it stops.
        let zero = ContactForce::default();
        self.pair_forces.clear();
        self.pair_forces.resize(self.neighbours.pairs.slots(), zero);
        self.face_forces.clear();
        self.face_forces.resize(self.neighbours.faces.slots(), zero);
        self.face_pieces = owner_aligned_bounds(&self.neighbours.faces.start);
        self.mark_mesh_built();
    }

    /// Stage 3 (Section 2.2): the force of every touching particle pair, once per pair.
    /// Returns the overlaps deeper than the smaller radius (a sign of instability).
    ///
    /// Each piece of the list first sorts its pairs into touching and apart (a pair that
    /// has just parted forgets its springs and force), then evaluates the touching ones
    /// `WIDTH` at a time in SIMD lanes; a lane gives the bits the pair would give alone, so
    /// neither the pieces nor the grouping change a result.
    fn particle_contacts(&mut self) -> Vec<Deep> {
        let deep = Mutex::new(Vec::new());
        let p = &self.particles;
        let law = &self.law;
        let density = self.scenario.material.density;
        let list = &mut self.neighbours.pairs;
        pieces(&mut self.pair_forces, list).for_each(
            |(forces, springs, touched, owner, partner)| {
                let mut touching = [0u16; PIECE];
                let mut count = 0;
                for (k, (&i, &j)) in owner.iter().zip(partner).enumerate() {
                    let (i, j) = (i as usize, j as usize);
                    let reach = p.radius[i] + p.radius[j];
                    if (p.x[i] - p.x[j]).length_squared() < reach * reach {
                        touching[count] = k as u16;
                        count += 1;
                        touched[k] = true;
                    } else if touched[k] {
                        // The contact ended: forget its history and its force.
                        springs[k] = Springs::default();
                        forces[k] = ContactForce::default();
                        touched[k] = false;
                    }
                }
                for group in touching[..count].chunks(WIDTH) {
                    // A short last group repeats its last pair in the spare lanes.
                    let k: [usize; WIDTH] =
                        std::array::from_fn(|l| group[l.min(group.len() - 1)] as usize);
                    let i = k.map(|k| owner[k] as usize);
                    let j = k.map(|k| partner[k] as usize);
                    let body = |idx: [usize; WIDTH]| Body::<Group> {
                        x: Group::gather_vec(idx.map(|i| p.x[i])),
                        radius: Group::gather(idx.map(|i| p.radius[i])),
                        v: Group::gather_vec(idx.map(|i| p.v[i])),
                        w: Group::gather_vec(idx.map(|i| p.w[i])),
                    };
                    let (body_i, body_j) = (body(i), body(j));
                    let d = body_i.x - body_j.x; // Eq. (8)
                    let kin =
                        Kinematics::of_touching_particles(&body_i, &body_j, d, Group::dot(d, d));
                    let mass = |idx: [usize; WIDTH]| {
                        Group::gather(idx.map(|i| Inertia::mass(p.radius[i], density)))
                    };
                    let mut lanes = gather_springs(springs, k);
                    let other = Other::Particle {
                        r: body_j.radius,
                        m: mass(j),
                    };
                    let force = law.evaluate(body_i.radius, mass(i), other, &kin, &mut lanes);
                    scatter_springs(lanes, springs, &k[..group.len()]);
                    scatter_forces(force, forces, &k[..group.len()]);
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
            },
        );
        deep.into_inner().expect("not poisoned")
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
    fn mesh_contacts(&mut self) -> Vec<Deep> {
        let deep = Mutex::new(Vec::new());
        let p = &self.particles;
        let law = &self.law;
        let faces = &self.mesh.faces;
        let (face_part, moving) = (&self.face_part, &self.moving);
        let density = self.scenario.material.density;
        let list = &mut self.neighbours.faces;
        thread_local! {
            static SCRATCH: std::cell::RefCell<MeshScratch> = Default::default();
        }
        owner_pieces(&mut self.face_forces, list, &self.face_pieces).for_each(
            |(forces, springs, touched, owner, partner)| {
                SCRATCH.with_borrow_mut(|scratch| {
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
                    for (k, (&i, &f)) in owner.iter().zip(partner).enumerate() {
                        let (i, face) = (i as usize, &faces[f as usize]);
                        let body = Body {
                            x: p.x[i],
                            radius: p.radius[i],
                            v: p.v[i],
                            w: p.w[i],
                        };
                        let contact = if face.certainly_beyond(body.x, body.radius + face.radius) {
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
                        match contact {
                            Some((kin, d, interior)) => near.push(Near {
                                slot: k,
                                kin,
                                d,
                                interior,
                            }),
                            None if touched[k] => {
                                // The contact ended: forget its history and its force.
                                springs[k] = Springs::default();
                                forces[k] = ContactForce::default();
                                touched[k] = false;
                            }
                            None => {}
                        }
                    }
                    // One contact per touch, particle by particle (its slots, so its faces
                    // within reach, are consecutive); the absorbed hand over their springs
                    // and are treated as apart.
                    contacts.clear();
                    let mut a = 0;
                    while a < near.len() {
                        let i = owner[near[a].slot];
                        let mut b = a + 1;
                        while b < near.len() && owner[near[b].slot] == i {
                            b += 1;
                        }
                        let (x, radius) = (p.x[i as usize], p.radius[i as usize]);
                        let several = b - a > 1;
                        if several {
                            candidates.clear();
                            candidates.extend(near[a..b].iter().map(|c| Candidate {
                                face: partner[c.slot],
                                point: x - c.d,
                                dist2: c.d.length_squared(),
                                interior: c.interior,
                            }));
                            let tol = surface::tolerance(x, radius);
                            surface::resolve(candidates, faces, tol, order, fates);
                            for (c, fate) in near[a..b].iter().zip(fates.iter()) {
                                if let Fate::Absorbed(s) = *fate {
                                    let s = near[a + s].slot;
                                    if springs[s] == Springs::default() {
                                        springs[s] = springs[c.slot];
                                    }
                                }
                            }
                        }
                        for (c, near) in near[a..b].iter().enumerate() {
                            let k = near.slot;
                            if !several || fates[c] == Fate::Contact {
                                if near.kin.delta > radius {
                                    deep.lock().expect("not poisoned").push(Deep {
                                        i: i as usize,
                                        other: Partner::Face(partner[k] as usize),
                                        delta: near.kin.delta,
                                        limit: radius,
                                    });
                                }
                                contacts.push((a + c) as u32);
                                touched[k] = true;
                            } else if touched[k] {
                                springs[k] = Springs::default();
                                forces[k] = ContactForce::default();
                                touched[k] = false;
                            }
                        }
                        a = b;
                    }
                    // The law, `WIDTH` contacts at a time (as for particle pairs).
                    for group in contacts.chunks(WIDTH) {
                        let c: [&Near; WIDTH] =
                            std::array::from_fn(|l| &near[group[l.min(group.len() - 1)] as usize]);
                        let k = c.map(|c| c.slot);
                        let i = k.map(|k| owner[k] as usize);
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
                        let mass = Group::gather(i.map(|i| Inertia::mass(p.radius[i], density)));
                        let mut lanes = gather_springs(springs, k);
                        let force = law.evaluate(radius, mass, Other::Wall, &kin, &mut lanes);
                        scatter_springs(lanes, springs, &k[..group.len()]);
                        scatter_forces(force, forces, &k[..group.len()]);
                    }
                });
            },
        );
        deep.into_inner().expect("not poisoned")
    }

    /// Stage 5 (Section 2.3): sum each particle's contact forces and torques (Eqs. 1-2,
    /// with the reactions of Eqs. 56-60) and advance it by Δt.
    /// Returns whether some particle's new state is not finite (for stage 6, so that it
    /// needs no pass of its own).
    fn integrate(&mut self) -> bool {
        let s = &self.scenario;
        let (dt, g) = (s.simulation.timestep, s.kinetics.gravity);
        let (density, viscosity) = (s.material.density, s.material.viscosity);
        let nb = &self.neighbours;
        let (pair_forces, face_forces) = (&self.pair_forces, &self.face_forces);
        // Force and torque on particle i.
        let load = |i: usize| {
            let mut f = DVec3::ZERO;
            let mut tau = DVec3::ZERO;
            let own = nb.pairs.start[i] as usize..nb.pairs.start[i + 1] as usize;
            for c in &pair_forces[own] {
                f += c.f;
                tau += c.tau_i;
            }
            let reverse = nb.reverse_start[i] as usize..nb.reverse_start[i + 1] as usize;
            for &slot in &nb.reverse_slot[reverse] {
                let c = &pair_forces[slot as usize];
                f -= c.f; // Eqs. (56), (57)
                tau += c.tau_j; // Eqs. (58)-(60)
            }
            let faces = nb.faces.start[i] as usize..nb.faces.start[i + 1] as usize;
            for c in &face_forces[faces] {
                f += c.f;
                tau += c.tau_i;
            }
            (f, tau)
        };
        let p = &mut self.particles;
        (
            p.x.par_chunks_mut(WIDTH),
            p.v.par_chunks_mut(WIDTH),
            p.q.par_chunks_mut(WIDTH),
            p.w.par_chunks_mut(WIDTH),
            p.radius.par_chunks(WIDTH),
        )
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN.div_ceil(WIDTH))
            .enumerate()
            .map(|(group, (x, v, q, w, radius))| {
                // `WIDTH` particles at a time in lanes; a short last group repeats its last
                // particle in the spare lanes.
                let n = x.len();
                let lane: [usize; WIDTH] = std::array::from_fn(|l| l.min(n - 1));
                let loads = lane.map(|l| load(group * WIDTH + l));
                let state = State::<Group> {
                    x: Group::gather_vec(lane.map(|l| x[l])),
                    v: Group::gather_vec(lane.map(|l| v[l])),
                    q: Group::gather_quat(lane.map(|l| q[l])),
                    w: Group::gather_vec(lane.map(|l| w[l])),
                };
                let body =
                    Response::new(Group::gather(lane.map(|l| radius[l])), density, viscosity);
                let (f, tau) = (loads.map(|l| l.0), loads.map(|l| l.1));
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
