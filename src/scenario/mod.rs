//! Scenario files: every parameter of the paper's Table 2, parsed and validated in one
//! place. Physics code receives a [`Scenario`] and never parses.
//!
//! ```toml
//! [geometry]   radius_min, radius_max, mesh, mesh_radii, mesh_contacts, spawn_min,
//!              spawn_max
//! [material]   density, youngs_modulus, poisson_ratio, restitution, friction_sliding,
//!              friction_rolling, friction_twisting, cohesion, viscosity, normal_model,
//!              adhesion_model, rolling_model, tangential_coulomb, thermal_conductivity,
//!              heat_capacity, initial_temperature, heat_source, surface_heat_transfer
//! [kinetics]   initial_velocity, initial_angular_velocity, gravity, ambient_temperature
//! [simulation] timestep, max_particles, frames, steps_per_frame, spawn_attempts, seed, skin,
//!              friction_springs = "advance_first" | "paper", until = { kinetic_energy_below,
//!              time, removed_at_least, servo_within }, thermal_time_scale,
//!              conduction_model = "batchelor_obrien" | "liggghts"
//! [[meshes]]   file | shape = { type = "box", min, max, open } | { type = "cylinder", center,
//!              axis, radius, height, open, orifice, resolution } | { type = "drum", center,
//!              axis, radius, length, resolution } | { type = "plane", point, normal, size } |
//!              { type = "hopper", center, axis, top_radius, outlet_radius, height,
//!              resolution }, radii, contacts, material, motion = { type = "harmonic",
//!              amplitude, frequency, direction, phase } | { type = "velocity", velocity } |
//!              { type = "rotation", center, axis, angular_velocity } | { type = "servo",
//!              direction, force | stress, max_speed, gain }, temperature   (any number)
//! [[tags]]     min, max, tag   (a box that labels particles entering it; any number)
//! [domain]     min, max, periodic = [bool, bool, bool]   (particles whose centre leaves
//!              it through a side that is not periodic are removed)
//! [[outlets]]  min, max   (particles whose centre enters one are removed; any number)
//! [[fixed]]    min, max   (the particles whose centre lies in one when the run or stage
//!              starts are held in place and at rest; any number)
//! [[spawn]]    min, max, material, velocity, temperature, count, rate, start, stop, radius = {
//!              distribution = "uniform" | "normal" | "lognormal" | "table", ... }
//! [[clumps]]  name, spheres = [[x, y, z, r], ...] | file, material, mass, inertia
//!              (rigid clumps of spheres; spawned by [[spawn]] clump, scale)
//! [[materials]] name, density, youngs_modulus, poisson_ratio, restitution, friction_*
//! [[interactions]] materials = [a, b], restitution, friction_*
//! [input]      particles
//! [output]     dir, checkpoint_every, checkpoint_minutes, formats, wall_forces, energy_ledger,
//!              contacts, forces,
//!              gather = "auto" | "always" | "never"
//! ```
//! Paths are relative to the scenario file. Unknown keys and values outside Table 2's
//! "Requirements" column are errors naming the key and the allowed range.

use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::geometry::mesh::Contacts;
pub use crate::geometry::shapes::Shape;
pub use crate::model::heat::{Conduction, Thermal};
pub use crate::model::materials::{FrictionSprings, Material, PairCoefficients};
use crate::model::motion::Motion;
use crate::model::registry::{AdhesionModel, NormalModel};
pub use crate::model::servo::{Servo, Target};

mod clumps;
mod heat;
mod meshes;
mod models;
mod output;
mod raw;
mod resolved;
mod spawn;
mod text;
mod until;
mod validate;
pub use clumps::{ClumpTemplate, MassSource};
pub use models::{GivenLiquid, GivenModels, beyond_defaults};
pub use output::{Formats, Gather};
pub use resolved::changes;
pub use text::MOST_SCENARIO_BYTES;
pub use until::{FrameState, Met, Until};

/// The geometry of the paper's default hourglass (Fig. 5A), embedded so that `tinydem`
/// runs with no files.
pub const HOURGLASS_OFF: &str = include_str!("../../assets/hourglass.off");

/// The value of `[geometry] mesh` that names the built-in hourglass (as `run.toml` of a
/// default run does).
pub const BUILTIN_HOURGLASS: &str = "builtin:hourglass";

/// The built-in hourglass as a mesh source.
fn builtin_hourglass() -> MeshSource {
    MeshSource::Embedded {
        name: "hourglass.off (built in)",
        text: HOURGLASS_OFF,
    }
}

/// Where the static mesh comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshSource {
    None,
    File(PathBuf),
    /// Text compiled into the binary, with a name for messages.
    Embedded {
        name: &'static str,
        text: &'static str,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Geometry {
    /// R_min \[L\]
    pub radius_min: f64,
    /// R_max \[L\]
    pub radius_max: f64,
    pub mesh: MeshSource,
    /// R_mesh \[L\], selected per face by the OFF colour index.
    pub mesh_radii: Vec<f64>,
    /// Contacts with the main mesh: merged per surface, or one per face.
    pub mesh_contacts: Contacts,
    /// The material of the main mesh's faces.
    pub mesh_material: u16,
    /// s_min, s_max \[L\]: the spawn box.
    pub spawn_min: DVec3,
    pub spawn_max: DVec3,
    /// Whether the scenario names the spawn box (a stage spawns in it only then).
    pub spawn_box_named: bool,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Kinetics {
    /// v_0 [L/T]
    pub initial_velocity: DVec3,
    /// ω_0 [1/T]
    pub initial_angular_velocity: DVec3,
    /// g [L/T²]
    pub gravity: DVec3,
    /// T_∞ \[K\] of the surroundings grains exchange heat with (`surface_heat_transfer`).
    pub ambient_temperature: Option<f64>,
}

/// The `[simulation]` table: the time step, the run's length, the spawner's attempts and
/// seed, the skin and the friction springs' update.
#[derive(Clone, Debug, PartialEq)]
pub struct SimulationTable {
    /// Δt \[T\]
    pub timestep: f64,
    /// N_max
    pub max_particles: u64,
    /// N_frames
    pub frames: u64,
    /// N_steps
    pub steps_per_frame: u64,
    /// N_spawn
    pub spawn_attempts: u64,
    /// Seed of the random stream used for spawning.
    pub seed: u64,
    /// Verlet skin as a fraction of R_max: the lists hold the pairs within R_i + R_j +
    /// skin and are rebuilt when a particle has moved half of it. It sets how often the
    /// lists are rebuilt, and so the speed, not the result.
    pub skin: f64,
    /// The order of the friction springs' update, Sec. 2.3.
    pub friction_springs: FrictionSprings,
    /// f: heat is advanced by f Δt per step (1: in step with the mechanics).
    pub thermal_time_scale: f64,
    /// How a contact's conductance follows from its overlap.
    pub conduction_model: Conduction,
    /// Conditions that end the run before its last frame.
    pub until: Until,
}

impl SimulationTable {
    /// The shortest period of a periodic domain, in largest radii: twice the reach of the
    /// widest pair (2 R_max and the skin), with R_max to spare, so that a pair sees one
    /// image of the other.
    pub fn shortest_period(&self) -> f64 {
        5.0 + 2.0 * self.skin
    }
}

/// A material of `[[materials]]` (or the one `[material]`).
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialSpec {
    pub name: String,
    pub properties: Material,
}

/// Coefficients of the contact between two materials that override the means of theirs
/// (`[[interactions]]`).
#[derive(Clone, Debug, PartialEq)]
pub struct Interaction {
    /// The two materials (indices, the lower first).
    pub materials: (u16, u16),
    pub restitution: Option<f64>,
    pub friction_sliding: Option<f64>,
    pub friction_rolling: Option<f64>,
    pub friction_twisting: Option<f64>,
    pub cohesion: Option<f64>,
    /// DMT's or JKR's γ for the pair.
    pub surface_energy: Option<f64>,
    /// The liquid of the pair's bridges, key by key.
    pub liquid: GivenLiquid,
    /// Hooke's k_n and k_s / k_n for the pair.
    pub hooke_stiffness: Option<f64>,
    pub hooke_stiffness_ratio: Option<f64>,
    /// The sub-models it names.
    pub models: GivenModels,
}

impl Interaction {
    /// Each coefficient with its key and symbol (given or not), in the order of the file.
    pub fn coefficients(&self) -> [(&'static str, &'static str, Option<f64>); 11] {
        [
            ("restitution", "e_n", self.restitution),
            ("friction_sliding", "mu_s", self.friction_sliding),
            ("friction_rolling", "mu_r", self.friction_rolling),
            ("friction_twisting", "mu_t", self.friction_twisting),
            ("cohesion", "k_c", self.cohesion),
            ("surface_energy", "gamma", self.surface_energy),
            ("liquid_volume", "V", self.liquid.volume),
            ("surface_tension", "gamma_l", self.liquid.surface_tension),
            ("contact_angle", "theta", self.liquid.contact_angle),
            ("hooke_stiffness", "k_n", self.hooke_stiffness),
            (
                "hooke_stiffness_ratio",
                "k_s/k_n",
                self.hooke_stiffness_ratio,
            ),
        ]
    }
}

/// Where the faces of a `[[meshes]]` entry come from.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshInput {
    /// A mesh file, OFF or STL (`file`).
    File(PathBuf),
    /// A built-in shape (`shape`).
    Shape(Shape),
}

impl MeshInput {
    /// How `tinydem check` and messages name it: the file, or the shape's type.
    pub fn name(&self) -> String {
        match self {
            MeshInput::File(p) => p.display().to_string(),
            MeshInput::Shape(s) => format!("a built-in {}", s.kind()),
        }
    }
}

/// One mesh file or built-in shape with its radii and, optionally, a prescribed motion
/// (`[[meshes]]`).
#[derive(Clone, Debug, PartialEq)]
pub struct MeshSpec {
    pub input: MeshInput,
    /// R_mesh of this file's faces, picked by the OFF colour index (STL and shapes: the
    /// first).
    pub radii: Vec<f64>,
    pub contacts: Contacts,
    pub motion: Option<Motion>,
    /// A servo that drives it instead (`motion = { type = "servo", ... }`).
    pub servo: Option<Servo>,
    /// The material of its faces (an index of `Scenario::materials`).
    pub material: u16,
    /// T_w \[K\]: its faces held at this temperature (heat flows between them and the grains
    /// that touch them); `None`: adiabatic.
    pub temperature: Option<f64>,
}

/// How the radii of spawned particles are drawn (`[[spawn]] radius`).
#[derive(Clone, Debug, PartialEq)]
pub enum RadiusDistribution {
    /// Uniform in [min, max] (the paper's, with R_min and R_max).
    Uniform { min: f64, max: f64 },
    /// Normal with `mean` and `std`, truncated to [min, max] (drawn again outside).
    Normal {
        mean: f64,
        std: f64,
        min: f64,
        max: f64,
    },
    /// Log-normal with the `mean` and `std` of the radius, truncated to [min, max].
    LogNormal {
        mean: f64,
        std: f64,
        min: f64,
        max: f64,
    },
    /// One of `radii`, each with its share of the number of particles (`weights`, relative).
    Table { radii: Vec<f64>, weights: Vec<f64> },
}

/// The parameters mu and sigma² of ln R ~ N(mu, sigma²) for the mean and standard deviation
/// of R itself.
pub fn log_normal(mean: f64, std: f64) -> (f64, f64) {
    let sigma2 = (1.0 + (std / mean).powi(2)).ln();
    (mean.ln() - 0.5 * sigma2, sigma2)
}

impl RadiusDistribution {
    /// The mean of the cube of the radii it draws, E\[R³\] \[L³\] (by the midpoint rule for
    /// the truncated normal and log-normal: 4,000 intervals of [min, max]).
    pub fn mean_cube(&self) -> f64 {
        let truncated = |min: f64, max: f64, density: &dyn Fn(f64) -> f64| {
            if max <= min {
                return min.powi(3);
            }
            let n = 4000;
            let h = (max - min) / n as f64;
            let (mut weight, mut cubes) = (0.0, 0.0);
            for k in 0..n {
                let r = min + (k as f64 + 0.5) * h;
                let w = density(r);
                (weight, cubes) = (weight + w, cubes + w * r.powi(3));
            }
            cubes / weight
        };
        match self {
            RadiusDistribution::Uniform { min, max } if max > min => {
                (max.powi(4) - min.powi(4)) / (4.0 * (max - min))
            }
            RadiusDistribution::Uniform { min, .. } => min.powi(3),
            RadiusDistribution::Normal {
                mean,
                std,
                min,
                max,
            } => truncated(*min, *max, &|r| (-0.5 * ((r - mean) / std).powi(2)).exp()),
            RadiusDistribution::LogNormal {
                mean,
                std,
                min,
                max,
            } => {
                let (mu, sigma2) = log_normal(*mean, *std);
                let density = |r: f64| (-(r.ln() - mu).powi(2) / (2.0 * sigma2)).exp() / r;
                truncated(*min, *max, &density)
            }
            RadiusDistribution::Table { radii, weights } => {
                let total: f64 = weights.iter().sum();
                radii
                    .iter()
                    .zip(weights)
                    .map(|(r, w)| w * r.powi(3))
                    .sum::<f64>()
                    / total
            }
        }
    }

    /// The largest radius it draws.
    pub fn largest(&self) -> f64 {
        match self {
            RadiusDistribution::Uniform { max, .. }
            | RadiusDistribution::Normal { max, .. }
            | RadiusDistribution::LogNormal { max, .. } => *max,
            RadiusDistribution::Table { radii, .. } => radii.iter().copied().fold(0.0, f64::max),
        }
    }
}

/// A region that inserts particles (`[[spawn]]`).
#[derive(Clone, Debug, PartialEq)]
pub struct SpawnRegion {
    /// Where the centres are drawn (uniformly).
    pub region: Region,
    pub material: u16,
    /// Initial velocity of its particles (default `[kinetics] initial_velocity`).
    pub velocity: DVec3,
    /// Initial temperature \[K\] of its particles (default: their material's).
    pub temperature: Option<f64>,
    /// How many particles it inserts in all (None: no limit but the rate's and
    /// `max_particles`).
    pub count: Option<u64>,
    /// Particles per second (None: as fast as `spawn_attempts` per step allow).
    pub rate: Option<f64>,
    /// When it is active \[s\], from `start` until `stop`.
    pub start: f64,
    pub stop: f64,
    pub radius: RadiusDistribution,
    /// What it inserts: spheres of `radius` and `material`, or clumps of a template.
    pub clump: Option<SpawnClump>,
}

/// The clumps a `[[spawn]]` region inserts (`clump = "name"`): the template's index in
/// `[[clumps]]` and the range of the factor its lengths are scaled by (uniform; 1 by
/// default). The orientation is uniform over rotations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpawnClump {
    pub template: u16,
    pub scale: (f64, f64),
}

/// A box that labels the particles whose centre enters it (`[[tags]]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TagRegion {
    pub min: DVec3,
    pub max: DVec3,
    pub tag: u32,
}

/// An axis-aligned box of space, `min` to `max` (inclusive).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    pub min: DVec3,
    pub max: DVec3,
}

impl Region {
    /// Whether `x` lies in the box (its faces included).
    #[inline]
    pub fn contains(&self, x: DVec3) -> bool {
        x.cmpge(self.min).all() && x.cmple(self.max).all()
    }
}

/// A complete, validated scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    pub geometry: Geometry,
    /// Material 0 (the one `[material]`, or the first of `[[materials]]`).
    pub material: Material,
    /// Every material: `[[materials]]` in order, or the one `[material]` (named "default").
    pub materials: Vec<MaterialSpec>,
    /// Pair coefficients that override the means (`[[interactions]]`).
    pub interactions: Vec<Interaction>,
    pub kinetics: Kinetics,
    pub simulation: SimulationTable,
    /// Further meshes, each with its own radii and motion (`[[meshes]]`).
    pub meshes: Vec<MeshSpec>,
    /// Regions that tag particles passing through them (`[[tags]]`), later ones winning.
    pub tags: Vec<TagRegion>,
    /// The bounds of the simulated space (`[domain]`): particles whose centre leaves it are
    /// removed. None: unbounded.
    pub domain: Option<Region>,
    /// The axes along which the domain is periodic (`[domain] periodic`).
    pub periodic: [bool; 3],
    /// Lees-Edwards boundaries: the velocity V of the images across the gradient axis, and
    /// the shear and gradient axes (`[domain] lees_edwards`).
    pub lees_edwards: Option<(f64, usize, usize)>,
    /// Boxes that remove the particles whose centre enters them (`[[outlets]]`).
    pub outlets: Vec<Region>,
    /// Boxes whose particles are fixed when the run or stage starts (`[[fixed]]`).
    pub fixed: Vec<Region>,
    /// Templates of rigid clumps of spheres (`[[clumps]]`), with their mass properties.
    pub clumps: Vec<ClumpTemplate>,
    /// Insertion regions (`[[spawn]]`); when there are any, the `[geometry]` spawn box is not
    /// used.
    pub spawn: Vec<SpawnRegion>,
    /// Initial particles (CSV), if any.
    pub particles: Option<PathBuf>,
    /// Output directory.
    pub output_dir: PathBuf,
    /// Write a checkpoint every this many frames (0: only when interrupted).
    pub checkpoint_every: u64,
    /// Also write one when this many minutes of wall time have passed since the last (0:
    /// never; default [`DEFAULT_CHECKPOINT_MINUTES`]), so that a job killed without warning
    /// loses at most that.
    pub checkpoint_minutes: f64,
    /// Frame formats to write.
    pub formats: Formats,
    /// Write `walls.csv`: the force and torque the particles exert on each mesh file.
    pub wall_forces: bool,
    /// Keep the energy ledger (`model/ledger.rs`): `log.csv` says where the energy went.
    pub energy_ledger: bool,
    /// Write the contact network with every frame (`contactsNNNNNN.csv`, and `.vtp` with VTK).
    pub contact_network: bool,
    /// Write each row's contact force and torque in the frames (`fx,fy,fz,tx,ty,tz`; VTK's
    /// `force` and `torque` of each sphere).
    pub forces: bool,
    /// Whether a split run gathers each frame into one file or writes a piece per process.
    pub gather: Gather,
}

/// `[output] checkpoint_minutes` unless the scenario says: a run killed without warning
/// (SIGKILL, a lost node) loses at most this much wall time.
pub const DEFAULT_CHECKPOINT_MINUTES: f64 = 10.0;

/// Default time step of a material: Eq. (50), Δt = R_min sqrt(ρ (1 - ν²) / E); with Hooke's
/// normal model t_c / [`HOOKE_STEPS`], t_c = π sqrt(m* / k_n) the undamped contact time of
/// two grains of R_min (m* = m / 2), which no impact speed shortens.
pub fn default_timestep(radius_min: f64, material: &Material) -> f64 {
    match material.models.normal {
        NormalModel::Hertz => {
            let nu = material.poisson_ratio;
            radius_min * (material.density * (1.0 - nu * nu) / material.youngs_modulus).sqrt()
        }
        NormalModel::Hooke => {
            let m = material.density * 4.0 / 3.0 * std::f64::consts::PI * radius_min.powi(3);
            hooke_contact_time(0.5 * m, material.hooke_stiffness) / HOOKE_STEPS
        }
    }
}

/// Steps per undamped Hooke contact of the default time step: at 20 a damped impact's
/// restitution is within 1 % (symplectic Euler), and twice the step (10 per contact, where
/// `run` refuses) is still far from the bound of stability (ω Δt = 2, 1.6 steps).
pub const HOOKE_STEPS: f64 = 20.0;

/// The undamped contact time of a Hooke contact of effective mass `m_star`, π sqrt(m* / k_n).
pub fn hooke_contact_time(m_star: f64, k_n: f64) -> f64 {
    std::f64::consts::PI * (m_star / k_n).sqrt()
}

impl Default for Scenario {
    /// The paper's default simulation (Table 2): 1000 particles falling through the
    /// hourglass of Fig. 5A.
    fn default() -> Self {
        let mut s = Scenario::from_raw(raw::RawScenario::default(), Path::new("."))
            .expect("Table 2 defaults are valid");
        s.geometry.mesh = builtin_hourglass();
        s
    }
}

impl Scenario {
    /// Whether the scenario names its materials (`[[materials]]`) rather than having the one
    /// `[material]`.
    pub fn uses_materials(&self) -> bool {
        self.materials.len() > 1 || self.materials[0].name != "default"
    }

    /// Why a run of this scenario that spawns in the spawn box cannot (see `box_outside`).
    pub fn spawn_box_outside(&self) -> Option<String> {
        if !self.spawn.is_empty() {
            return None;
        }
        spawn::box_outside(&self.geometry, &self.simulation, self.domain)
    }

    /// The rule of the default time step: Eq. 50 (Hertz), Hooke's t_c / 20, or both.
    pub fn timestep_rule(&self) -> &'static str {
        let hooke = |m: &MaterialSpec| m.properties.models.normal == NormalModel::Hooke;
        match (
            self.materials.iter().any(hooke),
            self.materials.iter().all(hooke),
        ) {
            (false, _) => "Eq. 50",
            (true, true) => "Hooke's t_c/20",
            (true, false) => "Eq. 50 and Hooke's t_c/20",
        }
    }

    /// The default time step: Eq. (50)'s (or Hooke's t_c / 20) for the stiffest, lightest
    /// of the materials ([`default_timestep`]).
    pub fn eq50_timestep(&self) -> f64 {
        self.materials
            .iter()
            .map(|m| default_timestep(self.geometry.radius_min, &m.properties))
            .fold(f64::INFINITY, f64::min)
    }

    /// The coefficients of contacts between materials `a` and `b` (particle or mesh): those
    /// of `[[interactions]]` where given, otherwise the means of the two materials'.
    pub fn pair(&self, a: u16, b: u16) -> PairCoefficients {
        let (m, n) = (
            &self.materials[a as usize].properties,
            &self.materials[b as usize].properties,
        );
        let mean = |x: f64, y: f64| if a == b { x } else { 0.5 * (x + y) };
        let given = self
            .interactions
            .iter()
            .find(|i| i.materials == (a.min(b), a.max(b)));
        let pick = |over: Option<f64>, x: f64, y: f64| over.unwrap_or_else(|| mean(x, y));
        let cohesion = pick(given.and_then(|i| i.cohesion), m.cohesion, n.cohesion);
        let mut mixed = m.models.mix(n.models);
        if cohesion > 0.0 {
            // A cohesion given for the pair alone adheres as the materials' would.
            mixed.adhesion = AdhesionModel::Sjkr;
        }
        let models = (given.map(|i| i.models).unwrap_or_default()).over(mixed);
        PairCoefficients {
            restitution: pick(
                given.and_then(|i| i.restitution),
                m.restitution,
                n.restitution,
            ),
            friction_sliding: pick(
                given.and_then(|i| i.friction_sliding),
                m.friction_sliding,
                n.friction_sliding,
            ),
            friction_rolling: pick(
                given.and_then(|i| i.friction_rolling),
                m.friction_rolling,
                n.friction_rolling,
            ),
            friction_twisting: pick(
                given.and_then(|i| i.friction_twisting),
                m.friction_twisting,
                n.friction_twisting,
            ),
            // A pair without adhesion (named so in its [[interactions]]) pulls not.
            cohesion: match models.adhesion {
                AdhesionModel::Sjkr => cohesion,
                AdhesionModel::None
                | AdhesionModel::Dmt
                | AdhesionModel::Jkr
                | AdhesionModel::JkrForce => 0.0,
            },
            surface_energy: match models.adhesion {
                AdhesionModel::Dmt | AdhesionModel::Jkr | AdhesionModel::JkrForce => {
                    given.and_then(|i| i.surface_energy).unwrap_or_else(|| {
                        models::mean_of([m, n], models::has_surface_energy, |m| m.surface_energy)
                    })
                }
                AdhesionModel::None | AdhesionModel::Sjkr => 0.0,
            },
            liquid: given.map(|i| i.liquid).unwrap_or_default().over([m, n]),
            hooke_stiffness: given.and_then(|i| i.hooke_stiffness).unwrap_or_else(|| {
                models::mean_of([m, n], models::is_hooke, |m| m.hooke_stiffness)
            }),
            hooke_stiffness_ratio: (given.and_then(|i| i.hooke_stiffness_ratio)).unwrap_or_else(
                || models::mean_of([m, n], models::is_hooke, |m| m.hooke_stiffness_ratio),
            ),
            models,
            given: given.is_some(),
        }
    }

    /// The scenario with every file path absolute (for `run.toml`, which must resolve
    /// wherever it is read from).
    pub fn absolute(&self) -> Scenario {
        let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        let mut s = self.clone();
        if let MeshSource::File(p) = &s.geometry.mesh {
            s.geometry.mesh = MeshSource::File(abs(p));
        }
        for m in &mut s.meshes {
            if let MeshInput::File(p) = &m.input {
                m.input = MeshInput::File(abs(p));
            }
        }
        s.particles = s.particles.as_deref().map(abs);
        s.output_dir = abs(&s.output_dir);
        s
    }

    /// Whether particles can be removed during the run (a domain with a side that is not
    /// periodic, or outlets).
    pub fn removes(&self) -> bool {
        (self.domain.is_some() && self.periodic != [true; 3]) || !self.outlets.is_empty()
    }

    /// The periodic axes of the domain, if it has any.
    pub fn periodicity(&self) -> Option<crate::neighbours::Periodic> {
        let d = self.domain?;
        self.periodic
            .contains(&true)
            .then(|| crate::neighbours::Periodic {
                min: d.min,
                length: d.max - d.min,
                axes: self.periodic,
                shear: self.lees_edwards.map(|(velocity, axis, gradient)| {
                    crate::neighbours::Shear {
                        velocity,
                        axis,
                        gradient,
                        offset: 0.0,
                    }
                }),
            })
    }

    /// Total simulated time N_frames N_steps Δt.
    pub fn total_time(&self) -> f64 {
        self.simulation.frames as f64
            * self.simulation.steps_per_frame as f64
            * self.simulation.timestep
    }
}

#[cfg(test)]
mod tests;
