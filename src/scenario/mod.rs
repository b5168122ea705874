//! Scenario files: every parameter of the paper's Table 2, parsed and validated in one
//! place. Physics code receives a [`Scenario`] and never parses.
//!
//! ```toml
//! [geometry]   radius_min, radius_max, mesh, mesh_radii, mesh_contacts, spawn_min,
//!              spawn_max
//! [material]   density, youngs_modulus, poisson_ratio, restitution, friction_sliding,
//!              friction_rolling, friction_twisting, cohesion, viscosity
//! [kinetics]   initial_velocity, initial_angular_velocity, gravity
//! [simulation] timestep, max_particles, frames, steps_per_frame, spawn_attempts, seed, skin,
//!              friction_springs = "advance_first" | "paper"
//! [[meshes]]   file, radii, contacts, motion = { type = "harmonic", amplitude, frequency, direction,
//!              phase } | { type = "velocity", velocity } | { type = "rotation", center, axis,
//!              angular_velocity }   (any number of these)
//! [[tags]]     min, max, tag   (a box that labels particles entering it; any number)
//! [domain]     min, max, periodic = [bool, bool, bool]   (particles whose centre leaves
//!              it through a side that is not periodic are removed)
//! [[outlets]]  min, max   (particles whose centre enters one are removed; any number)
//! [[spawn]]    min, max, material, velocity, count, rate, start, stop, radius = {
//!              distribution = "uniform" | "normal" | "lognormal" | "table", ... }
//! [[materials]] name, density, youngs_modulus, poisson_ratio, restitution, friction_*
//! [[interactions]] materials = [a, b], restitution, friction_*
//! [input]      particles
//! [output]     dir, checkpoint_every, checkpoint_minutes, formats, wall_forces, contacts
//! ```
//! Paths are relative to the scenario file. Unknown keys and values outside Table 2's
//! "Requirements" column are errors naming the key and the allowed range.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use glam::DVec3;
use serde::Deserialize;

use crate::geometry::mesh::Contacts;
pub use crate::model::materials::{FrictionSprings, Material, PairCoefficients};
use crate::model::motion::Motion;

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
}

#[derive(Clone, Debug, PartialEq)]
pub struct Kinetics {
    /// v_0 [L/T]
    pub initial_velocity: DVec3,
    /// ω_0 [1/T]
    pub initial_angular_velocity: DVec3,
    /// g [L/T²]
    pub gravity: DVec3,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Simulation {
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
}

impl Simulation {
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
}

impl Interaction {
    /// Each coefficient with its key and symbol (given or not), in the order of the file.
    pub fn coefficients(&self) -> [(&'static str, &'static str, Option<f64>); 5] {
        [
            ("restitution", "e_n", self.restitution),
            ("friction_sliding", "mu_s", self.friction_sliding),
            ("friction_rolling", "mu_r", self.friction_rolling),
            ("friction_twisting", "mu_t", self.friction_twisting),
            ("cohesion", "k_c", self.cohesion),
        ]
    }
}

/// One mesh file with its radii and, optionally, a prescribed motion (`[[meshes]]`).
#[derive(Clone, Debug, PartialEq)]
pub struct MeshSpec {
    pub file: PathBuf,
    /// R_mesh of this file's faces, picked by the OFF colour index (STL: the first).
    pub radii: Vec<f64>,
    pub contacts: Contacts,
    pub motion: Option<Motion>,
    /// The material of its faces (an index of `Scenario::materials`).
    pub material: u16,
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

impl RadiusDistribution {
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
    /// How many particles it inserts in all (None: no limit but the rate's and
    /// `max_particles`).
    pub count: Option<u64>,
    /// Particles per second (None: as fast as `spawn_attempts` per step allow).
    pub rate: Option<f64>,
    /// When it is active \[s\], from `start` until `stop`.
    pub start: f64,
    pub stop: f64,
    pub radius: RadiusDistribution,
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
    pub simulation: Simulation,
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
    /// never), so that a job killed without warning loses at most that.
    pub checkpoint_minutes: f64,
    /// Frame formats to write.
    pub formats: Formats,
    /// Write `walls.csv`: the force and torque the particles exert on each mesh file.
    pub wall_forces: bool,
    /// Write the contact network with every frame (`contactsNNNNNN.csv`, and `.vtp` with VTK).
    pub contact_network: bool,
}

/// The frame formats of `[output] formats`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Formats {
    /// `particlesNNNNNN.csv`, the original program's format.
    pub csv: bool,
    /// `particlesNNNNNN.vtu`, `mesh.vtu` and `particles.pvd` for ParaView.
    pub vtk: bool,
}

impl Formats {
    fn parse(names: Option<Vec<String>>) -> Result<Formats> {
        let Some(names) = names else {
            return Ok(Formats {
                csv: true,
                vtk: false,
            });
        };
        let mut f = Formats {
            csv: false,
            vtk: false,
        };
        for name in &names {
            match name.as_str() {
                "csv" => f.csv = true,
                "vtk" => f.vtk = true,
                other => bail!(
                    "[output] formats: unknown format \"{other}\": the formats are \"csv\" and \"vtk\""
                ),
            }
        }
        if !f.csv && !f.vtk {
            bail!("[output] formats must name at least one of \"csv\" and \"vtk\"");
        }
        Ok(f)
    }
}

/// What `new` changes with respect to `old` (both resolved scenarios, `Scenario::to_toml`),
/// one line per key: `[material] friction_sliding: 0.3 -> 0.5`, `[[meshes]] #2 file: added
/// "plug.off"`.
pub fn changes(old: &str, new: &str) -> Vec<String> {
    // `section key` -> value, in the order of the text.
    fn flat(text: &str) -> Vec<(String, String)> {
        let mut out = Vec::new();
        let mut section = String::new();
        let mut counts: std::collections::HashMap<String, usize> = Default::default();
        for line in text.lines().map(str::trim) {
            if line.starts_with("[[") {
                let n = counts.entry(line.to_string()).or_default();
                *n += 1;
                section = format!("{line} #{n}");
            } else if line.starts_with('[') {
                section = line.to_string();
            } else if let Some(mesh) = line.strip_prefix("# mesh: ") {
                out.push((format!("{section} mesh"), format!("{mesh:?}")));
            } else if let Some((k, v)) = line.split_once(" = ") {
                out.push((format!("{section} {k}"), v.to_string()));
            }
        }
        out
    }
    let (old, new) = (flat(old), flat(new));
    let find = |list: &[(String, String)], key: &str| {
        list.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone())
    };
    let mut lines = Vec::new();
    for (key, value) in &new {
        match find(&old, key) {
            Some(was) if was != *value => lines.push(format!("{key}: {was} -> {value}")),
            Some(_) => {}
            None => lines.push(format!("{key}: added {value}")),
        }
    }
    for (key, value) in &old {
        if find(&new, key).is_none() {
            lines.push(format!("{key}: removed (was {value})"));
        }
    }
    lines
}

/// Default time step, Eq. (50): Δt = R_min sqrt(ρ (1 - ν²) / E).
pub fn default_timestep(radius_min: f64, material: &Material) -> f64 {
    let nu = material.poisson_ratio;
    radius_min * (material.density * (1.0 - nu * nu) / material.youngs_modulus).sqrt()
}

// ---- The file format: every key optional, unknown keys rejected. -------------------

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMesh {
    file: PathBuf,
    radii: Option<Vec<f64>>,
    contacts: Option<String>,
    material: Option<String>,
    motion: Option<RawMotion>,
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum RawMotion {
    Harmonic {
        amplitude: f64,
        frequency: f64,
        direction: [f64; 3],
        phase: Option<f64>,
    },
    Velocity {
        velocity: [f64; 3],
    },
    Rotation {
        center: [f64; 3],
        axis: [f64; 3],
        angular_velocity: f64,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTag {
    min: [f64; 3],
    max: [f64; 3],
    tag: u32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSpawn {
    min: [f64; 3],
    max: [f64; 3],
    material: Option<String>,
    velocity: Option<[f64; 3]>,
    count: Option<u64>,
    rate: Option<f64>,
    start: Option<f64>,
    stop: Option<f64>,
    radius: Option<RawRadius>,
}

#[derive(Deserialize)]
#[serde(tag = "distribution", rename_all = "lowercase", deny_unknown_fields)]
enum RawRadius {
    Uniform {
        min: Option<f64>,
        max: Option<f64>,
    },
    Normal {
        mean: f64,
        std: f64,
        min: Option<f64>,
        max: Option<f64>,
    },
    Lognormal {
        mean: f64,
        std: f64,
        min: Option<f64>,
        max: Option<f64>,
    },
    Table {
        radii: Vec<f64>,
        weights: Option<Vec<f64>>,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDomain {
    min: [f64; 3],
    max: [f64; 3],
    periodic: Option<[bool; 3]>,
    lees_edwards: Option<RawShear>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawShear {
    velocity: f64,
    shear_axis: String,
    gradient_axis: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBox {
    min: [f64; 3],
    max: [f64; 3],
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawScenario {
    #[serde(default)]
    meshes: Vec<RawMesh>,
    #[serde(default)]
    materials: Vec<RawNamedMaterial>,
    #[serde(default)]
    interactions: Vec<RawInteraction>,
    #[serde(default)]
    tags: Vec<RawTag>,
    domain: Option<RawDomain>,
    #[serde(default)]
    outlets: Vec<RawBox>,
    #[serde(default)]
    spawn: Vec<RawSpawn>,
    #[serde(default)]
    geometry: RawGeometry,
    #[serde(default)]
    material: RawMaterial,
    #[serde(default)]
    kinetics: RawKinetics,
    #[serde(default)]
    simulation: RawSimulation,
    #[serde(default)]
    input: RawInput,
    #[serde(default)]
    output: RawOutput,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawGeometry {
    radius_min: Option<f64>,
    radius_max: Option<f64>,
    mesh: Option<PathBuf>,
    mesh_radii: Option<Vec<f64>>,
    mesh_contacts: Option<String>,
    mesh_material: Option<String>,
    spawn_min: Option<[f64; 3]>,
    spawn_max: Option<[f64; 3]>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawMaterial {
    cohesion: Option<f64>,
    density: Option<f64>,
    youngs_modulus: Option<f64>,
    poisson_ratio: Option<f64>,
    restitution: Option<f64>,
    friction_sliding: Option<f64>,
    friction_rolling: Option<f64>,
    friction_twisting: Option<f64>,
    viscosity: Option<f64>,
}

impl RawMaterial {
    /// Whether it sets a property of the particles (anything but the fluid's viscosity).
    fn has_particle_keys(&self) -> bool {
        self.density.is_some()
            || self.youngs_modulus.is_some()
            || self.poisson_ratio.is_some()
            || self.restitution.is_some()
            || self.friction_sliding.is_some()
            || self.friction_rolling.is_some()
            || self.friction_twisting.is_some()
            || self.cohesion.is_some()
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawNamedMaterial {
    name: String,
    cohesion: Option<f64>,
    density: Option<f64>,
    youngs_modulus: Option<f64>,
    poisson_ratio: Option<f64>,
    restitution: Option<f64>,
    friction_sliding: Option<f64>,
    friction_rolling: Option<f64>,
    friction_twisting: Option<f64>,
}

impl From<RawNamedMaterial> for RawMaterial {
    fn from(m: RawNamedMaterial) -> RawMaterial {
        RawMaterial {
            density: m.density,
            youngs_modulus: m.youngs_modulus,
            poisson_ratio: m.poisson_ratio,
            restitution: m.restitution,
            friction_sliding: m.friction_sliding,
            friction_rolling: m.friction_rolling,
            friction_twisting: m.friction_twisting,
            viscosity: None,
            cohesion: m.cohesion,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInteraction {
    materials: [String; 2],
    cohesion: Option<f64>,
    restitution: Option<f64>,
    friction_sliding: Option<f64>,
    friction_rolling: Option<f64>,
    friction_twisting: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawKinetics {
    initial_velocity: Option<[f64; 3]>,
    initial_angular_velocity: Option<[f64; 3]>,
    gravity: Option<[f64; 3]>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawSimulation {
    timestep: Option<f64>,
    max_particles: Option<u64>,
    frames: Option<u64>,
    steps_per_frame: Option<u64>,
    spawn_attempts: Option<u64>,
    seed: Option<u64>,
    skin: Option<f64>,
    friction_springs: Option<String>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawInput {
    particles: Option<PathBuf>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawOutput {
    dir: Option<PathBuf>,
    checkpoint_every: Option<u64>,
    checkpoint_minutes: Option<f64>,
    formats: Option<Vec<String>>,
    wall_forces: Option<bool>,
    contacts: Option<bool>,
}

/// A range check of Table 2's "Requirements" column.
#[derive(Clone, Copy)]
enum Range {
    Positive,
    NonNegative,
    /// Any finite value.
    Finite,
    /// (lo, hi]
    OpenClosed(f64, f64),
    /// [lo, hi]
    Closed(f64, f64),
}

impl Range {
    fn contains(self, x: f64) -> bool {
        x.is_finite()
            && match self {
                Range::Positive => x > 0.0,
                Range::NonNegative => x >= 0.0,
                Range::Finite => true,
                Range::OpenClosed(lo, hi) => x > lo && x <= hi,
                Range::Closed(lo, hi) => x >= lo && x <= hi,
            }
    }

    fn describe(self) -> String {
        match self {
            Range::Positive => "a finite number > 0".into(),
            Range::NonNegative => "a finite number >= 0".into(),
            Range::Finite => "a finite number".into(),
            Range::OpenClosed(lo, hi) => format!("in ({lo}, {hi}]"),
            Range::Closed(lo, hi) => format!("in [{lo}, {hi}]"),
        }
    }
}

fn check(key: &str, x: f64, range: Range) -> Result<f64> {
    if !range.contains(x) {
        bail!(
            "{key} = {x} is not allowed: it must be {}",
            range.describe()
        );
    }
    Ok(x)
}

fn check_vec(key: &str, v: [f64; 3]) -> Result<DVec3> {
    for (c, x) in ["x", "y", "z"].iter().zip(v) {
        check(&format!("{key}.{c}"), x, Range::Finite)?;
    }
    Ok(DVec3::from_array(v))
}

/// A box from `min` and `max` under `key`: `max >= min` in every component, or `max > min`
/// if `strict` (a box of space that must hold particles).
fn region(key: &str, b: RawBox, strict: bool) -> Result<Region> {
    let (min, max) = (
        check_vec(&format!("{key} min"), b.min)?,
        check_vec(&format!("{key} max"), b.max)?,
    );
    if strict && max.cmple(min).any() {
        bail!("{key} max = {max} must be > min = {min} in every component");
    }
    if max.cmplt(min).any() {
        bail!("{key} max = {max} must be >= min = {min} in every component");
    }
    Ok(Region { min, max })
}

/// Validates one `[[spawn]]` region: `index` finds a material by name, `velocity` is the
/// default initial velocity, radii must lie in [R_min, R_max] (`radii`).
fn spawn_region(
    key: &str,
    r: RawSpawn,
    index: &dyn Fn(&str, &str) -> Result<u16>,
    velocity: DVec3,
    radii: (f64, f64),
) -> Result<SpawnRegion> {
    let k = |name: &str| format!("{key} {name}");
    let region = region(
        key,
        RawBox {
            min: r.min,
            max: r.max,
        },
        false,
    )?;
    let material = match &r.material {
        Some(name) => index(&k("material"), name)?,
        None => 0,
    };
    let velocity = match r.velocity {
        Some(v) => check_vec(&k("velocity"), v)?,
        None => velocity,
    };
    let rate = r
        .rate
        .map(|x| check(&k("rate"), x, Range::Positive))
        .transpose()?;
    if r.count.is_none() && rate.is_none() {
        bail!("{key} needs a count (particles in all) or a rate (particles per second), or both");
    }
    let start = check(&k("start"), r.start.unwrap_or(0.0), Range::NonNegative)?;
    let stop = match r.stop {
        Some(t) => check(&k("stop"), t, Range::NonNegative)?,
        None => f64::INFINITY,
    };
    if stop <= start {
        bail!("{} = {stop} must be after start = {start}", k("stop"));
    }
    let (lo, hi) = radii;
    let within = |name: &str, x: f64| -> Result<f64> {
        let x = check(&k(&format!("radius.{name}")), x, Range::Positive)?;
        if x < lo || x > hi {
            bail!(
                "{} = {x} must lie within [geometry] radius_min = {lo} and radius_max = {hi}",
                k(&format!("radius.{name}"))
            );
        }
        Ok(x)
    };
    let bounds = |min: Option<f64>, max: Option<f64>| -> Result<(f64, f64)> {
        let (min, max) = (
            within("min", min.unwrap_or(lo))?,
            within("max", max.unwrap_or(hi))?,
        );
        if max < min {
            bail!("{} = {max} must be >= min = {min}", k("radius.max"));
        }
        Ok((min, max))
    };
    let spread = |mean: f64, std: f64, min: f64, max: f64| -> Result<(f64, f64)> {
        let mean = check(&k("radius.mean"), mean, Range::Positive)?;
        let std = check(&k("radius.std"), std, Range::NonNegative)?;
        if std == 0.0 && (mean < min || mean > max) {
            bail!(
                "{} = {mean} must lie within [{min}, {max}]",
                k("radius.mean")
            );
        }
        Ok((mean, std))
    };
    let radius = match r.radius {
        None => RadiusDistribution::Uniform { min: lo, max: hi },
        Some(RawRadius::Uniform { min, max }) => {
            let (min, max) = bounds(min, max)?;
            RadiusDistribution::Uniform { min, max }
        }
        Some(RawRadius::Normal {
            mean,
            std,
            min,
            max,
        }) => {
            let (min, max) = bounds(min, max)?;
            let (mean, std) = spread(mean, std, min, max)?;
            RadiusDistribution::Normal {
                mean,
                std,
                min,
                max,
            }
        }
        Some(RawRadius::Lognormal {
            mean,
            std,
            min,
            max,
        }) => {
            let (min, max) = bounds(min, max)?;
            let (mean, std) = spread(mean, std, min, max)?;
            RadiusDistribution::LogNormal {
                mean,
                std,
                min,
                max,
            }
        }
        Some(RawRadius::Table { radii, weights }) => {
            if radii.is_empty() {
                bail!("{} must hold at least one radius", k("radius.radii"));
            }
            for (i, &x) in radii.iter().enumerate() {
                within(&format!("radii[{i}]"), x)?;
            }
            let weights = weights.unwrap_or_else(|| vec![1.0; radii.len()]);
            if weights.len() != radii.len() {
                bail!(
                    "{} has {} entries, radii {}: one weight per radius",
                    k("radius.weights"),
                    weights.len(),
                    radii.len()
                );
            }
            for (i, &w) in weights.iter().enumerate() {
                check(&k(&format!("radius.weights[{i}]")), w, Range::NonNegative)?;
            }
            let total: f64 = weights.iter().sum();
            if total <= 0.0 {
                bail!("{} must not all be zero", k("radius.weights"));
            }
            RadiusDistribution::Table { radii, weights }
        }
    };
    Ok(SpawnRegion {
        region,
        material,
        velocity,
        count: r.count,
        rate,
        start,
        stop,
        radius,
    })
}

/// Validates the properties of one material (`key` names it in messages).
fn material(key: &str, m: RawMaterial, viscosity: f64) -> Result<Material> {
    let key = |name: &str| format!("{key} {name}");
    let friction_sliding = check(
        &key("friction_sliding"),
        m.friction_sliding.unwrap_or(0.3),
        Range::NonNegative,
    )?;
    Ok(Material {
        density: check(&key("density"), m.density.unwrap_or(1e3), Range::Positive)?,
        youngs_modulus: check(
            &key("youngs_modulus"),
            m.youngs_modulus.unwrap_or(1e6),
            Range::Positive,
        )?,
        poisson_ratio: check(
            &key("poisson_ratio"),
            m.poisson_ratio.unwrap_or(0.3),
            Range::OpenClosed(-1.0, 0.5),
        )?,
        restitution: check(
            &key("restitution"),
            m.restitution.unwrap_or(0.5),
            Range::Closed(0.0, 1.0),
        )?,
        friction_sliding,
        friction_rolling: check(
            &key("friction_rolling"),
            m.friction_rolling.unwrap_or(0.3),
            Range::NonNegative,
        )?,
        // Eq. (41)
        friction_twisting: check(
            &key("friction_twisting"),
            m.friction_twisting.unwrap_or(2.0 / 3.0 * friction_sliding),
            Range::NonNegative,
        )?,
        viscosity,
        cohesion: check(
            &key("cohesion"),
            m.cohesion.unwrap_or(0.0),
            Range::NonNegative,
        )?,
    })
}

/// The value of a `mesh_contacts` or `contacts` key (default "merged").
fn contacts(key: &str, value: Option<String>) -> Result<Contacts> {
    match value.as_deref() {
        None | Some("merged") => Ok(Contacts::Merged),
        Some("per_face") => Ok(Contacts::PerFace),
        Some(other) => bail!(
            "{key} = \"{other}\" is not allowed: it must be \"merged\" (one contact per touch of a connected surface) or \"per_face\" (a contact per face, as the original program)"
        ),
    }
}

/// The value of `[simulation] friction_springs` (default "advance_first").
fn friction_springs(value: Option<String>) -> Result<FrictionSprings> {
    match value.as_deref() {
        None | Some("advance_first") => Ok(FrictionSprings::AdvanceFirst),
        Some("paper") => Ok(FrictionSprings::Paper),
        Some(other) => bail!(
            "[simulation] friction_springs = \"{other}\" is not allowed: it must be \"advance_first\" (advance the spring, then take its force: no energy created) or \"paper\" (the paper's Eqs. 53-55 in their order, as the original program)"
        ),
    }
}

/// Validates one `[[meshes]]` entry.
fn mesh_spec(k: usize, m: RawMesh, base: &Path) -> Result<MeshSpec> {
    let key = |name: &str| format!("[[meshes]] #{} {name}", k + 1);
    let radii = m.radii.unwrap_or_else(|| vec![0.0]);
    if radii.is_empty() {
        bail!("{} must hold at least one radius", key("radii"));
    }
    for (i, &r) in radii.iter().enumerate() {
        check(&key(&format!("radii[{i}]")), r, Range::NonNegative)?;
    }
    let unit = |name: &str, v: [f64; 3]| -> Result<DVec3> {
        let v = check_vec(&key(name), v)?;
        if v.length_squared() == 0.0 {
            bail!("{} must not be the zero vector", key(name));
        }
        Ok(v.normalize())
    };
    let motion = match m.motion {
        None => None,
        Some(RawMotion::Harmonic {
            amplitude,
            frequency,
            direction,
            phase,
        }) => Some(Motion::Harmonic {
            amplitude: check(&key("motion.amplitude"), amplitude, Range::NonNegative)?,
            frequency: check(&key("motion.frequency"), frequency, Range::NonNegative)?,
            direction: unit("motion.direction", direction)?,
            phase: check(&key("motion.phase"), phase.unwrap_or(0.0), Range::Finite)?,
        }),
        Some(RawMotion::Velocity { velocity }) => Some(Motion::Velocity {
            velocity: check_vec(&key("motion.velocity"), velocity)?,
        }),
        Some(RawMotion::Rotation {
            center,
            axis,
            angular_velocity,
        }) => Some(Motion::Rotation {
            center: check_vec(&key("motion.center"), center)?,
            axis: unit("motion.axis", axis)?,
            angular_velocity: check(
                &key("motion.angular_velocity"),
                angular_velocity,
                Range::Finite,
            )?,
        }),
    };
    Ok(MeshSpec {
        file: base.join(m.file),
        radii,
        contacts: contacts(&key("contacts"), m.contacts)?,
        motion,
        material: 0,
    })
}

impl Default for Scenario {
    /// The paper's default simulation (Table 2): 1000 particles falling through the
    /// hourglass of Fig. 5A.
    fn default() -> Self {
        let mut s = Scenario::from_raw(RawScenario::default(), Path::new("."))
            .expect("Table 2 defaults are valid");
        s.geometry.mesh = builtin_hourglass();
        s
    }
}

impl Scenario {
    /// Parses and validates scenario text; `path` names the file in messages and anchors
    /// relative paths.
    pub fn parse(text: &str, path: &Path) -> Result<Scenario> {
        let raw: RawScenario = toml::from_str(text)
            .map_err(|e| anyhow::anyhow!("{}: {}", path.display(), e.to_string().trim_end()))?;
        let base = path.parent().unwrap_or(Path::new("."));
        Scenario::from_raw(raw, base)
            .with_context(|| format!("{}: invalid scenario", path.display()))
    }

    fn from_raw(raw: RawScenario, base: &Path) -> Result<Scenario> {
        let mut g = raw.geometry;
        let g_mesh_material = g.mesh_material.take();
        let radius_min = check(
            "[geometry] radius_min",
            g.radius_min.unwrap_or(0.002),
            Range::Positive,
        )?;
        let radius_max = check(
            "[geometry] radius_max",
            g.radius_max.unwrap_or(0.01),
            Range::Positive,
        )?;
        if radius_max < radius_min {
            bail!("[geometry] radius_max = {radius_max} must be >= radius_min = {radius_min}");
        }
        let mesh_radii = g.mesh_radii.unwrap_or_else(|| vec![0.002, 0.02, 0.01]);
        if mesh_radii.is_empty() {
            bail!("[geometry] mesh_radii must hold at least one radius");
        }
        for (k, &r) in mesh_radii.iter().enumerate() {
            check(
                &format!("[geometry] mesh_radii[{k}]"),
                r,
                Range::NonNegative,
            )?;
        }
        let spawn_min = check_vec(
            "[geometry] spawn_min",
            g.spawn_min.unwrap_or([-0.1, -0.1, 0.3]),
        )?;
        let spawn_max = check_vec(
            "[geometry] spawn_max",
            g.spawn_max.unwrap_or([0.1, 0.1, 0.4]),
        )?;
        if spawn_max.cmplt(spawn_min).any() {
            bail!(
                "[geometry] spawn_max = {spawn_max} must be >= spawn_min = {spawn_min} in every component"
            );
        }
        let geometry = Geometry {
            radius_min,
            radius_max,
            mesh: match g.mesh {
                None => MeshSource::None,
                Some(p) if p.as_os_str() == BUILTIN_HOURGLASS => builtin_hourglass(),
                Some(p) => MeshSource::File(base.join(p)),
            },
            mesh_radii,
            mesh_contacts: contacts("[geometry] mesh_contacts", g.mesh_contacts)?,
            mesh_material: 0,
            spawn_min,
            spawn_max,
        };

        let viscosity = check(
            "[material] viscosity",
            raw.material.viscosity.unwrap_or(0.0),
            Range::NonNegative,
        )?;
        let materials: Vec<MaterialSpec> = if raw.materials.is_empty() {
            vec![MaterialSpec {
                name: "default".into(),
                properties: material("[material]", raw.material, viscosity)?,
            }]
        } else {
            if raw.material.has_particle_keys() {
                bail!(
                    "[material] may only set viscosity (of the surrounding fluid) when [[materials]] are given: set the other properties in [[materials]]"
                );
            }
            let mut names = std::collections::BTreeSet::new();
            raw.materials
                .into_iter()
                .enumerate()
                .map(|(k, m)| {
                    let key = format!("[[materials]] #{}", k + 1);
                    let name = m.name.trim().to_string();
                    if name.is_empty() {
                        bail!("{key} name must not be empty");
                    }
                    if !names.insert(name.clone()) {
                        bail!("{key} name = \"{name}\" is used by another material");
                    }
                    let properties = material(&format!("{key} (\"{name}\")"), m.into(), viscosity)?;
                    Ok(MaterialSpec { name, properties })
                })
                .collect::<Result<_>>()?
        };
        if materials.len() > u16::MAX as usize {
            bail!("[[materials]]: at most {} materials", u16::MAX);
        }
        let index = |key: &str, name: &str| -> Result<u16> {
            materials
                .iter()
                .position(|m| m.name == name)
                .map(|k| k as u16)
                .ok_or_else(|| {
                    let known: Vec<String> = materials
                        .iter()
                        .map(|m| format!("\"{}\"", m.name))
                        .collect();
                    anyhow::anyhow!(
                        "{key} = \"{name}\" is not a material: the materials are {}",
                        known.join(", ")
                    )
                })
        };
        let mut interactions: Vec<Interaction> = Vec::new();
        for (k, i) in raw.interactions.into_iter().enumerate() {
            let key = |name: &str| format!("[[interactions]] #{} {name}", k + 1);
            let pair = (
                index(&key("materials[0]"), &i.materials[0])?,
                index(&key("materials[1]"), &i.materials[1])?,
            );
            let pair = (pair.0.min(pair.1), pair.0.max(pair.1));
            if interactions.iter().any(|o| o.materials == pair) {
                bail!(
                    "{} = [\"{}\", \"{}\"]: that pair is given twice",
                    key("materials"),
                    i.materials[0],
                    i.materials[1]
                );
            }
            let opt = |name: &str, x: Option<f64>, r: Range| -> Result<Option<f64>> {
                x.map(|x| check(&key(name), x, r)).transpose()
            };
            interactions.push(Interaction {
                materials: pair,
                restitution: opt("restitution", i.restitution, Range::Closed(0.0, 1.0))?,
                friction_sliding: opt("friction_sliding", i.friction_sliding, Range::NonNegative)?,
                friction_rolling: opt("friction_rolling", i.friction_rolling, Range::NonNegative)?,
                friction_twisting: opt(
                    "friction_twisting",
                    i.friction_twisting,
                    Range::NonNegative,
                )?,
                cohesion: opt("cohesion", i.cohesion, Range::NonNegative)?,
            });
        }
        let material = materials[0].properties.clone();

        let k = raw.kinetics;
        let kinetics = Kinetics {
            initial_velocity: check_vec(
                "[kinetics] initial_velocity",
                k.initial_velocity.unwrap_or([0.0, 0.0, -1.0]),
            )?,
            initial_angular_velocity: check_vec(
                "[kinetics] initial_angular_velocity",
                k.initial_angular_velocity.unwrap_or([0.0; 3]),
            )?,
            gravity: check_vec("[kinetics] gravity", k.gravity.unwrap_or([0.0, 0.0, -9.81]))?,
        };

        let s = raw.simulation;
        let timestep = match s.timestep {
            Some(dt) => check("[simulation] timestep", dt, Range::Positive)?,
            None => materials
                .iter()
                .map(|m| default_timestep(radius_min, &m.properties))
                .fold(f64::INFINITY, f64::min),
        };
        let simulation = Simulation {
            timestep,
            max_particles: s.max_particles.unwrap_or(1000),
            frames: s.frames.unwrap_or(100),
            steps_per_frame: s.steps_per_frame.unwrap_or(500),
            spawn_attempts: s.spawn_attempts.unwrap_or(100),
            seed: s.seed.unwrap_or(1),
            skin: check("[simulation] skin", s.skin.unwrap_or(0.5), Range::Positive)?,
            friction_springs: friction_springs(s.friction_springs)?,
        };
        if simulation.spawn_attempts > 1_000_000_000 {
            bail!(
                "[simulation] spawn_attempts = {} is too large: at most 1000000000 per time step",
                simulation.spawn_attempts
            );
        }
        if simulation
            .frames
            .checked_mul(simulation.steps_per_frame)
            .is_none_or(|n| n > 1 << 53)
        {
            bail!(
                "[simulation] frames x steps_per_frame = {} x {} is too many time steps (at most 2^53)",
                simulation.frames,
                simulation.steps_per_frame
            );
        }
        if simulation.max_particles > u32::MAX as u64 / 2 {
            bail!(
                "[simulation] max_particles = {} is too large: at most {}",
                simulation.max_particles,
                u32::MAX / 2
            );
        }

        let mut geometry = geometry;
        if let Some(name) = &g_mesh_material {
            geometry.mesh_material = index("[geometry] mesh_material", name)?;
        }
        let meshes = raw
            .meshes
            .into_iter()
            .enumerate()
            .map(|(k, mut m)| {
                let name = m.material.take();
                let mut spec = mesh_spec(k, m, base)?;
                if let Some(name) = name {
                    spec.material = index(&format!("[[meshes]] #{} material", k + 1), &name)?;
                }
                Ok(spec)
            })
            .collect::<Result<Vec<_>>>()?;

        let tags = raw
            .tags
            .into_iter()
            .enumerate()
            .map(|(k, t)| {
                let b = RawBox {
                    min: t.min,
                    max: t.max,
                };
                let Region { min, max } = region(&format!("[[tags]] #{}", k + 1), b, false)?;
                Ok(TagRegion {
                    min,
                    max,
                    tag: t.tag,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let periodic = raw
            .domain
            .as_ref()
            .and_then(|d| d.periodic)
            .unwrap_or([false; 3]);
        let lees_edwards = match raw.domain.as_ref().and_then(|d| d.lees_edwards.as_ref()) {
            None => None,
            Some(le) => {
                let key = "[domain] lees_edwards";
                let axis = |name: &str, value: &str| -> Result<usize> {
                    match value {
                        "x" => Ok(0),
                        "y" => Ok(1),
                        "z" => Ok(2),
                        other => bail!(
                            "{key} {name} = \"{other}\" is not allowed: it must be \"x\", \"y\" or \"z\""
                        ),
                    }
                };
                let (s, g) = (
                    axis("shear_axis", &le.shear_axis)?,
                    axis("gradient_axis", &le.gradient_axis)?,
                );
                if s == g {
                    bail!("{key}: shear_axis and gradient_axis must differ");
                }
                if !(periodic[s] && periodic[g]) {
                    bail!(
                        "{key}: the domain must be periodic along the shear axis {} and the gradient axis {}",
                        le.shear_axis,
                        le.gradient_axis
                    );
                }
                Some((
                    check(&format!("{key} velocity"), le.velocity, Range::Finite)?,
                    s,
                    g,
                ))
            }
        };
        let domain = raw
            .domain
            .map(|d| {
                region(
                    "[domain]",
                    RawBox {
                        min: d.min,
                        max: d.max,
                    },
                    true,
                )
            })
            .transpose()?;
        if let Some(d) = domain {
            let periods = simulation.shortest_period();
            let shortest = periods * radius_max;
            for (a, name) in ["x", "y", "z"].iter().enumerate() {
                let length = d.max[a] - d.min[a];
                if periodic[a] && length < shortest {
                    bail!(
                        "[domain] is periodic along {name} with a period of {length}: it must be at least {periods} radius_max = {shortest}"
                    );
                }
            }
        }
        let outlets = raw
            .outlets
            .into_iter()
            .enumerate()
            .map(|(k, b)| region(&format!("[[outlets]] #{}", k + 1), b, false))
            .collect::<Result<Vec<_>>>()?;
        let spawn = raw
            .spawn
            .into_iter()
            .enumerate()
            .map(|(k, r)| {
                spawn_region(
                    &format!("[[spawn]] #{}", k + 1),
                    r,
                    &index,
                    kinetics.initial_velocity,
                    (radius_min, radius_max),
                )
            })
            .collect::<Result<Vec<_>>>()?;
        for (k, r) in spawn.iter().enumerate() {
            if let Some(d) = domain
                && !(d.contains(r.region.min) && d.contains(r.region.max))
            {
                bail!(
                    "[[spawn]] #{} box {} .. {} must lie inside [domain] {} .. {}",
                    k + 1,
                    r.region.min,
                    r.region.max,
                    d.min,
                    d.max
                );
            }
        }
        if let Some(d) = domain
            && spawn.is_empty()
            && simulation.max_particles > 0
            && simulation.spawn_attempts > 0
            && !(d.contains(spawn_min) && d.contains(spawn_max))
        {
            bail!(
                "[geometry] spawn box {spawn_min} .. {spawn_max} must lie inside [domain] {} .. {} \
                 (particles spawned outside it would be removed at once)",
                d.min,
                d.max
            );
        }

        Ok(Scenario {
            geometry,
            material,
            materials,
            interactions,
            kinetics,
            simulation,
            meshes,
            tags,
            domain,
            periodic,
            lees_edwards,
            outlets,
            spawn,
            particles: raw.input.particles.map(|p| base.join(p)),
            output_dir: raw
                .output
                .dir
                .map_or_else(|| base.join("output"), |d| base.join(d)),
            checkpoint_every: raw.output.checkpoint_every.unwrap_or(0),
            checkpoint_minutes: check(
                "[output] checkpoint_minutes",
                raw.output.checkpoint_minutes.unwrap_or(0.0),
                Range::NonNegative,
            )?,
            formats: Formats::parse(raw.output.formats)?,
            wall_forces: raw.output.wall_forces.unwrap_or(false),
            contact_network: raw.output.contacts.unwrap_or(false),
        })
    }

    /// The scenario as TOML with every default filled in: parsed again (from a file in the
    /// current directory) it gives the same scenario. A built-in mesh is named in a comment.
    pub fn to_toml(&self) -> String {
        use std::fmt::Write;
        let f = |x: f64| format!("{x:?}");
        let v = |x: DVec3| format!("[{:?}, {:?}, {:?}]", x.x, x.y, x.z);
        let list = |xs: &[f64]| {
            let items: Vec<String> = xs.iter().map(|&x| f(x)).collect();
            format!("[{}]", items.join(", "))
        };
        let text = |t: &str| toml::Value::String(t.to_string()).to_string();
        let path = |p: &Path| text(&p.display().to_string());
        let contacts = |c: Contacts| match c {
            Contacts::Merged => "\"merged\"",
            Contacts::PerFace => "\"per_face\"",
        };
        let mut o = String::new();
        let g = &self.geometry;
        o += "[geometry]\n";
        let _ = writeln!(o, "radius_min = {}", f(g.radius_min));
        let _ = writeln!(o, "radius_max = {}", f(g.radius_max));
        match &g.mesh {
            MeshSource::None => {}
            MeshSource::File(p) => {
                let _ = writeln!(o, "mesh = {}", path(p));
            }
            MeshSource::Embedded { name, .. } => {
                let _ = writeln!(o, "mesh = {}  # {name}", text(BUILTIN_HOURGLASS));
            }
        }
        let _ = writeln!(o, "mesh_radii = {}", list(&g.mesh_radii));
        let _ = writeln!(o, "mesh_contacts = {}", contacts(g.mesh_contacts));
        let material = |k: u16| text(&self.materials[k as usize].name);
        if self.uses_materials() {
            let _ = writeln!(o, "mesh_material = {}", material(g.mesh_material));
        }
        let _ = writeln!(o, "spawn_min = {}", v(g.spawn_min));
        let _ = writeln!(o, "spawn_max = {}", v(g.spawn_max));
        let properties = |o: &mut String, m: &Material| {
            for (key, x) in [
                ("density", m.density),
                ("youngs_modulus", m.youngs_modulus),
                ("poisson_ratio", m.poisson_ratio),
                ("restitution", m.restitution),
                ("friction_sliding", m.friction_sliding),
                ("friction_rolling", m.friction_rolling),
                ("friction_twisting", m.friction_twisting),
                ("cohesion", m.cohesion),
            ] {
                let _ = writeln!(o, "{key} = {}", f(x));
            }
        };
        if self.uses_materials() {
            for m in &self.materials {
                let _ = writeln!(o, "\n[[materials]]\nname = {}", text(&m.name));
                properties(&mut o, &m.properties);
            }
            for i in &self.interactions {
                let name = |k: u16| text(&self.materials[k as usize].name);
                let _ = writeln!(
                    o,
                    "\n[[interactions]]\nmaterials = [{}, {}]",
                    name(i.materials.0),
                    name(i.materials.1)
                );
                for (key, _, x) in i.coefficients() {
                    if let Some(x) = x {
                        let _ = writeln!(o, "{key} = {}", f(x));
                    }
                }
            }
            o += "\n[material]\n";
        } else {
            o += "\n[material]\n";
            properties(&mut o, &self.material);
        }
        let _ = writeln!(o, "viscosity = {}", f(self.material.viscosity));
        let k = &self.kinetics;
        o += "\n[kinetics]\n";
        let _ = writeln!(o, "initial_velocity = {}", v(k.initial_velocity));
        let _ = writeln!(
            o,
            "initial_angular_velocity = {}",
            v(k.initial_angular_velocity)
        );
        let _ = writeln!(o, "gravity = {}", v(k.gravity));
        let s = &self.simulation;
        o += "\n[simulation]\n";
        let _ = writeln!(o, "timestep = {}", f(s.timestep));
        for (key, n) in [
            ("max_particles", s.max_particles),
            ("frames", s.frames),
            ("steps_per_frame", s.steps_per_frame),
            ("spawn_attempts", s.spawn_attempts),
            ("seed", s.seed),
        ] {
            let _ = writeln!(o, "{key} = {n}");
        }
        let _ = writeln!(o, "skin = {}", f(s.skin));
        let _ = writeln!(o, "friction_springs = {}", text(s.friction_springs.key()));
        for mesh in &self.meshes {
            o += "\n[[meshes]]\n";
            let _ = writeln!(o, "file = {}", path(&mesh.file));
            let _ = writeln!(o, "radii = {}", list(&mesh.radii));
            let _ = writeln!(o, "contacts = {}", contacts(mesh.contacts));
            if self.uses_materials() {
                let _ = writeln!(o, "material = {}", material(mesh.material));
            }
            match mesh.motion {
                None => {}
                Some(Motion::Harmonic {
                    amplitude,
                    frequency,
                    direction,
                    phase,
                }) => {
                    let _ = writeln!(
                        o,
                        "motion = {{ type = \"harmonic\", amplitude = {}, frequency = {}, direction = {}, phase = {} }}",
                        f(amplitude),
                        f(frequency),
                        v(direction),
                        f(phase)
                    );
                }
                Some(Motion::Velocity { velocity }) => {
                    let _ = writeln!(
                        o,
                        "motion = {{ type = \"velocity\", velocity = {} }}",
                        v(velocity)
                    );
                }
                Some(Motion::Rotation {
                    center,
                    axis,
                    angular_velocity,
                }) => {
                    let _ = writeln!(
                        o,
                        "motion = {{ type = \"rotation\", center = {}, axis = {}, angular_velocity = {} }}",
                        v(center),
                        v(axis),
                        f(angular_velocity)
                    );
                }
            }
        }
        for t in &self.tags {
            o += "\n[[tags]]\n";
            let _ = writeln!(o, "min = {}\nmax = {}\ntag = {}", v(t.min), v(t.max), t.tag);
        }
        if let Some(d) = self.domain {
            let _ = writeln!(o, "\n[domain]\nmin = {}\nmax = {}", v(d.min), v(d.max));
            let [x, y, z] = self.periodic;
            let _ = writeln!(o, "periodic = [{x}, {y}, {z}]");
            if let Some((velocity, s, g)) = self.lees_edwards {
                let name = |a: usize| ["x", "y", "z"][a];
                let _ = writeln!(
                    o,
                    "lees_edwards = {{ velocity = {}, shear_axis = \"{}\", gradient_axis = \"{}\" }}",
                    f(velocity),
                    name(s),
                    name(g)
                );
            }
        }
        for b in &self.outlets {
            let _ = writeln!(o, "\n[[outlets]]\nmin = {}\nmax = {}", v(b.min), v(b.max));
        }
        for r in &self.spawn {
            let _ = writeln!(
                o,
                "\n[[spawn]]\nmin = {}\nmax = {}\nvelocity = {}",
                v(r.region.min),
                v(r.region.max),
                v(r.velocity)
            );
            if self.uses_materials() {
                let _ = writeln!(o, "material = {}", material(r.material));
            }
            if let Some(n) = r.count {
                let _ = writeln!(o, "count = {n}");
            }
            if let Some(rate) = r.rate {
                let _ = writeln!(o, "rate = {}", f(rate));
            }
            let _ = writeln!(o, "start = {}", f(r.start));
            if r.stop.is_finite() {
                let _ = writeln!(o, "stop = {}", f(r.stop));
            }
            let radius = match &r.radius {
                RadiusDistribution::Uniform { min, max } => format!(
                    "{{ distribution = \"uniform\", min = {}, max = {} }}",
                    f(*min),
                    f(*max)
                ),
                RadiusDistribution::Normal {
                    mean,
                    std,
                    min,
                    max,
                } => format!(
                    "{{ distribution = \"normal\", mean = {}, std = {}, min = {}, max = {} }}",
                    f(*mean),
                    f(*std),
                    f(*min),
                    f(*max)
                ),
                RadiusDistribution::LogNormal {
                    mean,
                    std,
                    min,
                    max,
                } => format!(
                    "{{ distribution = \"lognormal\", mean = {}, std = {}, min = {}, max = {} }}",
                    f(*mean),
                    f(*std),
                    f(*min),
                    f(*max)
                ),
                RadiusDistribution::Table { radii, weights } => format!(
                    "{{ distribution = \"table\", radii = {}, weights = {} }}",
                    list(radii),
                    list(weights)
                ),
            };
            let _ = writeln!(o, "radius = {radius}");
        }
        if let Some(p) = &self.particles {
            let _ = writeln!(o, "\n[input]\nparticles = {}", path(p));
        }
        o += "\n[output]\n";
        let _ = writeln!(o, "dir = {}", path(&self.output_dir));
        let _ = writeln!(o, "checkpoint_every = {}", self.checkpoint_every);
        let _ = writeln!(o, "checkpoint_minutes = {}", f(self.checkpoint_minutes));
        let mut formats = Vec::new();
        if self.formats.csv {
            formats.push("\"csv\"");
        }
        if self.formats.vtk {
            formats.push("\"vtk\"");
        }
        let _ = writeln!(o, "formats = [{}]", formats.join(", "));
        let _ = writeln!(o, "wall_forces = {}", self.wall_forces);
        let _ = writeln!(o, "contacts = {}", self.contact_network);
        o
    }

    /// Whether the scenario names its materials (`[[materials]]`) rather than having the one
    /// `[material]`.
    pub fn uses_materials(&self) -> bool {
        self.materials.len() > 1 || self.materials[0].name != "default"
    }

    /// The time step of Eq. (50) for the stiffest, lightest of the materials.
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
            cohesion: pick(given.and_then(|i| i.cohesion), m.cohesion, n.cohesion),
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
            m.file = abs(&m.file);
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
mod tests {
    use super::*;

    #[test]
    fn defaults_are_table_2() {
        let s = Scenario::default();
        assert_eq!(s.geometry.radius_min, 0.002);
        assert!((s.material.friction_twisting - 0.2).abs() < 1e-15);
        assert_eq!(s.simulation.frames * s.simulation.steps_per_frame, 50_000);
        // Eq. (50): 0.002 * sqrt(1000 * 0.91 / 1e6)
        assert!((s.simulation.timestep - 6.0332412e-5).abs() < 1e-12);
    }

    #[test]
    fn unknown_key_is_named() {
        let e = Scenario::parse("[material]\ndensityy = 3\n", Path::new("s.toml")).unwrap_err();
        let msg = format!("{e:#}");
        assert!(msg.contains("densityy") && msg.contains("s.toml"), "{msg}");
    }

    #[test]
    fn out_of_range_value_names_key_and_range() {
        let e =
            Scenario::parse("[material]\npoisson_ratio = 0.7\n", Path::new("s.toml")).unwrap_err();
        let msg = format!("{e:#}");
        assert!(
            msg.contains("poisson_ratio") && msg.contains("(-1, 0.5]"),
            "{msg}"
        );
    }

    #[test]
    fn the_resolved_toml_parses_back_to_the_same_scenario() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenarios/good");
        for name in ["full.toml", "minimal.toml", "materials.toml"] {
            let s = Scenario::load(&dir.join(name)).unwrap();
            let again = Scenario::parse(&s.to_toml(), Path::new("run.toml")).unwrap();
            assert_eq!(again, s, "{name}:\n{}", s.to_toml());
        }
        let moving = Scenario::parse(
            "[[meshes]]\nfile = \"a.stl\"\nmotion = { type = \"harmonic\", amplitude = 1e-3, frequency = 25.0, direction = [0.0, 0.0, 1.0] }\n\
             [[meshes]]\nfile = \"b c.off\"\nradii = [0.001, 0.0]\nmotion = { type = \"velocity\", velocity = [0.1, 0.0, 0.0] }\n\
             [[meshes]]\nfile = \"d.off\"\nmotion = { type = \"rotation\", center = [0.0, 1.0, 0.0], axis = [0.0, 1.0, 0.0], angular_velocity = -3.0 }\n\
             [[tags]]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\ntag = 3\n",
            Path::new("s.toml"),
        )
        .unwrap();
        let again = Scenario::parse(&moving.to_toml(), Path::new("run.toml")).unwrap();
        assert_eq!(again, moving, "{}", moving.to_toml());
        // The default run's names the built-in mesh, and reads back as it.
        let d = Scenario::default();
        assert!(
            d.to_toml()
                .contains("mesh = \"builtin:hourglass\"  # hourglass.off (built in)")
        );
        let again = Scenario::parse(&d.to_toml(), Path::new("run.toml")).unwrap();
        assert_eq!(again, d);
    }

    #[test]
    fn changes_name_each_key() {
        let old = Scenario::parse(
            "[material]\nfriction_sliding = 0.3\n[[meshes]]\nfile = \"a.off\"\n[[meshes]]\nfile = \"plug.off\"\n",
            Path::new("s.toml"),
        )
        .unwrap();
        let new = Scenario::parse(
            "[material]\nfriction_sliding = 0.5\n[[meshes]]\nfile = \"a.off\"\n[[outlets]]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n[simulation]\nframes = 7\n",
            Path::new("s.toml"),
        )
        .unwrap();
        let c = changes(&old.to_toml(), &new.to_toml());
        assert_eq!(
            c,
            [
                "[material] friction_sliding: 0.3 -> 0.5",
                "[material] friction_twisting: 0.19999999999999998 -> 0.3333333333333333",
                "[simulation] frames: 100 -> 7",
                "[[outlets]] #1 min: added [0.0, 0.0, 0.0]",
                "[[outlets]] #1 max: added [1.0, 1.0, 1.0]",
                "[[meshes]] #2 file: removed (was \"plug.off\")",
                "[[meshes]] #2 radii: removed (was [0.0])",
                "[[meshes]] #2 contacts: removed (was \"merged\")",
            ]
        );
        assert!(changes(&new.to_toml(), &new.to_toml()).is_empty());
    }

    #[test]
    fn paths_are_relative_to_the_scenario() {
        let s = Scenario::parse(
            "[input]\nparticles = \"p.csv\"\n",
            Path::new("cases/a/s.toml"),
        )
        .unwrap();
        assert_eq!(s.particles, Some(PathBuf::from("cases/a/p.csv")));
        // Given or not, the output directory is relative to the scenario too.
        assert_eq!(s.output_dir, PathBuf::from("cases/a/output"));
    }
}
