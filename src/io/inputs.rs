//! The inputs a scenario names, read: the scenario file itself, its mesh files and its
//! initial particles. The constructors that read them before they build (`Scenario::load`,
//! `Mesh::load`, `Simulation::new`, `restore`, `stage`) are here, so that the layers below
//! parse and build from what was read and never open a file.

use std::path::Path;

use anyhow::{Context, Result, bail};

use crate::engine::Simulation;
use crate::engine::records::Snapshot;
use crate::engine::setup::Inputs;
use crate::geometry::mesh::Mesh;
use crate::io::{csv, files};
use crate::model::particles::Particles;
use crate::scenario::{MeshInput, MeshSource, Scenario};

impl Scenario {
    /// Reads and validates a scenario file.
    pub fn load(path: &Path) -> Result<Scenario> {
        let text = files::read_to_string(path)
            .with_context(|| format!("cannot read scenario file {}", path.display()))?;
        Scenario::parse(&text, path)
    }
}

impl Mesh {
    /// Reads a mesh file: STL (ASCII or binary) if its name ends in `.stl`, else OFF.
    pub fn load(path: &Path, radii: &[f64]) -> Result<Mesh> {
        let bytes = files::read(path)
            .map_err(|e| anyhow::anyhow!("cannot read mesh file {}: {e}", path.display()))?;
        let name = path.display().to_string();
        let is_stl = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("stl"));
        if is_stl {
            return Mesh::parse_stl(&bytes, &name, radii[0]);
        }
        let text = std::str::from_utf8(&bytes)
            .map_err(|_| anyhow::anyhow!("{name}: not a text file, expected an OFF mesh"))?;
        Mesh::parse_off(text, &name, radii)
    }
}

/// The meshes of `scenario`: its main mesh and each `[[meshes]]` file, in order.
pub fn meshes(scenario: &Scenario) -> Result<Vec<(Mesh, String)>> {
    let g = &scenario.geometry;
    let main = match &g.mesh {
        MeshSource::None => (Mesh::default(), String::new()),
        MeshSource::File(path) => (Mesh::load(path, &g.mesh_radii)?, path.display().to_string()),
        MeshSource::Embedded { name, text } => (
            Mesh::parse_off(text, name, &g.mesh_radii)?,
            name.to_string(),
        ),
    };
    let mut all = vec![main];
    for spec in &scenario.meshes {
        let mesh = match &spec.input {
            MeshInput::File(path) => Mesh::load(path, &spec.radii)?,
            MeshInput::Shape(shape) => shape.mesh(spec.radii[0]),
        };
        all.push((mesh, spec.input.name()));
    }
    Ok(all)
}

/// Everything the files of `scenario` hold: its meshes and its initial particles.
pub fn read(scenario: &Scenario) -> Result<Inputs> {
    let meshes = meshes(scenario)?;
    let particles = match &scenario.particles {
        Some(path) => {
            let g = &scenario.geometry;
            let limits = csv::Limits {
                materials: scenario.materials.len(),
                radius_min: g.radius_min,
                radius_max: g.radius_max,
            };
            csv::load_particles_within(path, &limits)?
        }
        None => Particles::default(),
    };
    Ok(Inputs { meshes, particles })
}

impl Simulation {
    /// Sets up a simulation: reads the mesh and the initial particles.
    pub fn new(scenario: Scenario) -> Result<Simulation> {
        let inputs = read(&scenario)?;
        Simulation::from_inputs(scenario, inputs)
    }

    /// Continues a run from a snapshot taken by [`Simulation::snapshot`] with the same
    /// scenario (its meshes read again): the result is bitwise the same as if the run had
    /// not stopped. See [`Simulation::restore_from`].
    pub fn restore(scenario: Scenario, snapshot: Snapshot) -> Result<Simulation> {
        let meshes = meshes(&scenario)?;
        let inputs = Inputs {
            meshes,
            particles: Particles::default(),
        };
        Simulation::restore_from(scenario, inputs, snapshot)
    }

    /// Starts a new stage of a study from the snapshot of another run, with the meshes of
    /// `scenario` read: see [`Simulation::stage_from`].
    pub fn stage(scenario: Scenario, snapshot: Snapshot) -> Result<(Simulation, Vec<String>)> {
        if scenario.particles.is_some() {
            bail!(
                "[input] particles cannot be combined with --from: the particles are those of the checkpoint"
            );
        }
        let inputs = Inputs {
            meshes: meshes(&scenario)?,
            particles: Particles::default(),
        };
        Simulation::stage_from(scenario, inputs, snapshot)
    }
}
