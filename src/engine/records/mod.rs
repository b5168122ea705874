//! The records of a run that the engine makes and the output writes: the snapshot a
//! checkpoint holds, the contacts of a contact network, the particles removed and the loads
//! on the walls. They live below both, so that neither imports the other.

use glam::DVec3;

pub mod bytes;
mod join;
pub use bytes::{decode, encode, encode_into};
pub use join::{join, shared_part};

use crate::engine::spawn::SpawnerState;
use crate::model::particles::{Id, Particles};
use crate::neighbours::Entry;

/// Everything needed to continue a run bit for bit: particles (in storage order, with their
/// ids), step count, the spawner's place in its random stream, the contact history (the
/// friction springs of every touching pair, Table 3, by particle id), and what rebuilds the
/// neighbour lists of the last rebuild exactly: its step, the positions it anchored the
/// particles at and its lonely particles.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub steps: u64,
    pub built_at: u64,
    pub particles: Particles,
    pub spawner: SpawnerState,
    pub anchors: Vec<DVec3>,
    pub lonely: Vec<(u32, f64)>,
    /// Particle pairs by (lower id, higher id) and particle-face contacts by (id, face).
    pub pair_history: Vec<Entry>,
    pub face_history: Vec<Entry>,
    /// The particles removed so far.
    pub removed: Removed,
    /// The loads on the mesh files summed since the last frame (`[output] wall_forces`).
    pub wall_sums: Vec<Wrench>,
    /// The heat into each mesh file since the last frame, in quanta of the run's heat
    /// model (with heat transfer; format 9).
    pub wall_heat: Vec<i128>,
    /// The resolved scenario of the run (`Scenario::to_toml`), to tell what a staged run
    /// changes.
    pub scenario: String,
    /// Face count and a hash of the faces of each mesh file, to find them in the mesh of a
    /// staged run.
    pub mesh_files: Vec<(u64, u64)>,
    /// The state of each servo, with its mesh file (format 4).
    pub servos: Vec<(u32, crate::model::servo::State)>,
    /// The optional members of a contact's state the histories hold (format 8).
    pub contact_state: crate::model::contact_state::ActiveState,
    /// The energy ledger, if the run keeps it (format 10).
    pub ledger: Option<crate::model::ledger::Kept>,
}

/// The partner of a particle in a contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Partner {
    Particle(Id),
    Face(usize),
}

/// Particles removed, and their mass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Outflow {
    pub count: u64,
    /// \[M\]
    pub mass: f64,
}

/// The particles removed so far: by each `[[outlets]]` box, and for leaving the `[domain]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Removed {
    pub outlets: Vec<Outflow>,
    pub domain: Outflow,
}

impl Removed {
    /// All particles removed so far.
    pub fn count(&self) -> u64 {
        self.domain.count + self.outlets.iter().map(|o| o.count).sum::<u64>()
    }
}

/// The force and torque that particles exert on a body (a mesh file).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Wrench {
    /// [ML/T²]
    pub f: DVec3,
    /// [ML²/T²], about the body's reference point.
    pub tau: DVec3,
}

impl std::ops::AddAssign for Wrench {
    fn add_assign(&mut self, o: Wrench) {
        self.f += o.f;
        self.tau += o.tau;
    }
}

/// A contact of the network (`Simulation::contact_network`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactRecord {
    /// The particle (its id; the lower one of a pair).
    pub id: Id,
    /// The other particle (its id) or the face (its index in the mesh).
    pub with: Partner,
    /// Where the two touch: x_i - r_i n (Eq. 29).
    pub point: DVec3,
    /// The force on particle `id`: its normal and tangential parts \[N\].
    pub f_n: DVec3,
    pub f_t: DVec3,
    /// δ \[L\]
    pub overlap: f64,
    /// The torque on particle `id` and on the other particle (0 for a face), about their
    /// centres: sliding, rolling and twisting (Eqs. 58-60) \[N m\].
    pub tau_i: DVec3,
    pub tau_j: DVec3,
}

/// The contact force and torque on each particle (torque about its centre) by its id, or,
/// with `whole`, on each row of a frame: a clump's (by its first sphere's id) summed over its
/// spheres, the torque about its centre of mass; from the contacts of `contacts` of the
/// particles `p` (partners not among them left out). Gravity and drag are not counted.
pub fn contact_loads(p: &Particles, contacts: &[ContactRecord], whole: bool) -> Loads {
    let at: rustc_hash::FxHashMap<Id, usize> =
        p.id.iter().enumerate().map(|(k, &id)| (id, k)).collect();
    let mut loads = Loads::default();
    // The row of the particle stored at `k`, and the lever of a force on it about the row's
    // centre (a clump's centre of mass: from the body's frame, which holds whatever images
    // of a periodic domain its centre and spheres were put at).
    let row = |k: usize| match p.body[k].filter(|_| whole) {
        Some(b) => {
            let index = p.bodies.index_of(b).expect("a listed body");
            let body = &p.bodies.list[index];
            let m = (p.bodies.members(index).iter())
                .position(|&s| s as usize == k)
                .expect("a sphere of its body");
            (b.first(), body.q * body.offsets[m])
        }
        None => (p.id[k], DVec3::ZERO),
    };
    let mut add = |k: usize, f: DVec3, tau: DVec3| {
        let (id, lever) = row(k);
        let load = loads.entry(id).or_default();
        load.0 += f;
        load.1 += tau + lever.cross(f);
    };
    for c in contacts {
        let f = c.f_n + c.f_t;
        if let Some(&i) = at.get(&c.id) {
            add(i, f, c.tau_i);
        }
        if let Partner::Particle(j) = c.with
            && let Some(&j) = at.get(&j)
        {
            add(j, -f, c.tau_j);
        }
    }
    loads
}

/// Force and torque by id (of a particle, or a clump's row).
pub type Loads = rustc_hash::FxHashMap<Id, (DVec3, DVec3)>;

impl ContactRecord {
    /// Where it stands in a network: pairs by (lower id, higher id), then contacts with
    /// faces by (id, face).
    pub fn network_order(&self) -> (u8, Id, Id) {
        match self.with {
            Partner::Particle(j) => (0, self.id, j),
            Partner::Face(f) => (1, self.id, f as Id),
        }
    }
}

/// FNV-1a, 64 bit, of `text`: how records name what they were made from (the mesh files'
/// faces, a checkpoint's scenario).
pub fn hash(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
    })
}
