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
use crate::model::particles::{Id, Particle, Particles};
use crate::neighbours::Entries;
use crate::parallel::comm::{Comm, Reader};
use crate::parallel::decomposition::agree;
use crate::scenario::{ClumpTemplate, MeshInput, MeshSource, Scenario};

impl Scenario {
    /// Reads and validates a scenario file.
    pub fn load(path: &Path) -> Result<Scenario> {
        // (Refused unread: a file of gigabytes would take many times its size to parse.)
        if let Ok(m) = std::fs::metadata(path)
            && m.len() > crate::scenario::MOST_SCENARIO_BYTES as u64
        {
            bail!(
                "{}: {} bytes, more than a scenario's {}: put long lists in files of their own \
                 ([input] particles, [[clumps]] file)",
                path.display(),
                m.len(),
                crate::scenario::MOST_SCENARIO_BYTES
            );
        }
        let text = files::read_to_string(path)
            .with_context(|| format!("cannot read scenario file {}", path.display()))?;
        let s = Scenario::parse(&text, path)?;
        s.check_files(path)?;
        Ok(s)
    }

    /// The files the scenario names (meshes, the particle file) are there to read: else an
    /// error naming the scenario, the key and the path tried, before anything runs.
    fn check_files(&self, path: &Path) -> Result<()> {
        let mut named: Vec<(String, &Path)> = Vec::new();
        if let MeshSource::File(f) = &self.geometry.mesh {
            named.push(("[geometry] mesh".into(), f));
        }
        for (k, m) in self.meshes.iter().enumerate() {
            if let MeshInput::File(f) = &m.input {
                named.push((format!("[[meshes]] #{} file", k + 1), f));
            }
        }
        if let Some(f) = &self.particles {
            named.push(("[input] particles".into(), f));
        }
        for (key, file) in named {
            if let Err(e) = files::open(file) {
                let absolute = |p: &Path| std::path::absolute(p).unwrap_or(p.to_path_buf());
                let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
                let dir = dir.unwrap_or(Path::new("."));
                // (The io error kept as the cause, so that Python raises FileNotFoundError.)
                let said = format!(
                    "{}: {key}: cannot read {}: {e} (a relative path is taken from the \
                     scenario's directory, {})",
                    path.display(),
                    absolute(file).display(),
                    absolute(dir).display()
                );
                return Err(std::io::Error::new(e.kind(), said).into());
            }
        }
        Ok(())
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
            match csv::load_grains_within(path, &limits)? {
                (particles, None) => particles,
                (rows, Some(clumps)) => with_clumps(scenario, rows, &clumps)
                    .with_context(|| format!("particle file {}", path.display()))?,
            }
        }
        None => Particles::default(),
    };
    Ok(Inputs { meshes, particles })
}

/// What the files of `scenario` hold for process `k` of a run split over the processes of
/// `comm` (collective): the meshes, and its share of the particle file
/// ([`csv::load_grains_share`]), with the ids the whole file gives them, so that no process
/// reads or holds them all. An error on any process is the error of all.
pub fn read_share(scenario: &Scenario, comm: &dyn Comm) -> Result<Inputs> {
    let read = || -> Result<_> {
        let meshes = meshes(scenario)?;
        let Some(path) = &scenario.particles else {
            return Ok((meshes, None));
        };
        let g = &scenario.geometry;
        let limits = csv::Limits {
            materials: scenario.materials.len(),
            radius_min: g.radius_min,
            radius_max: g.radius_max,
        };
        let share = csv::load_grains_share(path, &limits, (comm.rank(), comm.size()))?;
        Ok((meshes, Some((path, share))))
    };
    let (meshes, share) = agree(comm, read())?;
    let Some((path, (mut rows, clumps, ids))) = share else {
        return Ok(Inputs {
            meshes,
            particles: Particles::default(),
        });
    };
    // Without ids, a row's id is its place in the file, and a clump's spheres take the
    // next ones: the rows and ids of the shares before come first.
    let spheres = |t: Option<u16>| match t.and_then(|t| scenario.clumps.get(t as usize)) {
        Some(template) if template.spheres.len() > 1 => template.spheres.len() as u64,
        _ => 1,
    };
    let taken: u64 = match &clumps {
        Some(c) => c.templates.iter().map(|&t| spheres(t)).sum(),
        None => rows.len() as u64,
    };
    let before = |mine: u64| -> u64 {
        let all = comm.all_gather(mine.to_le_bytes().to_vec());
        all[..comm.rank()]
            .iter()
            .map(|m| Reader::new(m).u64())
            .sum()
    };
    let (rows_before, ids_before) = (before(rows.len() as u64), before(taken));
    if !ids {
        rows.id.iter_mut().for_each(|id| *id += rows_before);
        rows.next_id += rows_before;
    }
    let particles = match clumps {
        None => Ok(rows),
        Some(c) => with_clumps_from(scenario, rows, &c, ids_before)
            .with_context(|| format!("particle file {}", path.display())),
    };
    let mut particles = agree(comm, particles)?;
    let next = comm.all_gather(particles.next_id.to_le_bytes().to_vec());
    particles.next_id = next.iter().map(|m| Reader::new(m).u64()).max().unwrap_or(0);
    Ok(Inputs { meshes, particles })
}

/// The particles of an input file's `rows` whose `clump` column names a template: those
/// rows become clumps (x, v, q, w their body's; scaled by R over the template's bounding
/// radius, so that a run's frame reads back as it was written), the others stay spheres.
/// A clump of row id b takes the ids b, b + 1, ... for its spheres; in a file without ids,
/// each row takes the next free ids.
pub fn with_clumps(s: &Scenario, rows: Particles, clumps: &csv::ClumpColumn) -> Result<Particles> {
    with_clumps_from(s, rows, clumps, 0)
}

/// [`with_clumps`] for rows whose ids, if the file gives none, start at `first` (a share of
/// the file that follows others).
fn with_clumps_from(
    s: &Scenario,
    rows: Particles,
    clumps: &csv::ClumpColumn,
    first: Id,
) -> Result<Particles> {
    let mut particles = Particles {
        next_id: first,
        ..Particles::default()
    };
    let mut taken = rustc_hash::FxHashSet::default();
    for k in rows.id_order() {
        let row = rows.get(k);
        if clumps.ids {
            particles.next_id = rows.id[k];
        }
        let id = particles.next_id;
        match clumps.templates[k] {
            None => particles.push(row),
            Some(t) => {
                let Some(template) = s.clumps.get(t as usize) else {
                    bail!(
                        "row {}: clump {t}, but the scenario has {} [[clumps]]",
                        k + 1,
                        s.clumps.len()
                    );
                };
                if let [_] = template.spheres[..] {
                    // A clump of one sphere is that sphere, at its row's place and radius.
                    let material = template.material;
                    particles.push(Particle { material, ..row });
                } else {
                    place_row(&mut particles, (template, t), id, row);
                }
            }
        }
        if particles.next_id > crate::model::particles::MAX_ID {
            bail!(
                "row {}: the clump of id {id} takes the ids {id} to {} for its spheres, but ids \
                 must be below {}",
                k + 1,
                particles.next_id - 1,
                crate::model::particles::MAX_ID
            );
        }
        for id in id..particles.next_id {
            if !taken.insert(id) {
                bail!(
                    "row {}: id {id} is taken (a clump of row id b takes b, b + 1, ... for its spheres)",
                    k + 1
                );
            }
        }
    }
    particles.next_id = rows.next_id.max(taken.iter().max().map_or(0, |m| m + 1));
    Ok(particles)
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

    /// A process's share of a checkpoint in parts, with the meshes of `scenario` read: see
    /// [`Simulation::restore_share_from`].
    pub fn restore_share(scenario: Scenario, snapshot: Snapshot) -> Result<(Simulation, Entries)> {
        let inputs = Inputs {
            meshes: meshes(&scenario)?,
            particles: Particles::default(),
        };
        Simulation::restore_share_from(scenario, inputs, snapshot)
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

/// Places the clump of template `t` (its index `template`) that the row `row` of id `id`
/// describes: scaled by R over the template's bounding radius, its bounding radius as
/// written (to the bit), its spheres tagged as the row.
fn place_row(
    particles: &mut Particles,
    (t, template): (&ClumpTemplate, u16),
    id: Id,
    row: Particle,
) {
    let first = particles.len();
    let scale = row.radius / t.bounding_radius;
    let motion = (row.x, row.q, row.v, row.w);
    crate::engine::spawn::place_clump(particles, (t, template), scale, motion);
    particles.tag[first..].fill(row.tag);
    particles.fixed[first..].fill(row.fixed);
    if let Some(body) = (particles.bodies.list.last_mut()).filter(|b| b.id.first() == id) {
        body.bounding_radius = row.radius;
    }
}
