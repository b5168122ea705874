//! Validation: a [`Scenario`] from the raw file, every value checked against Table 2's
//! "Requirements" column, every default filled in; errors name the key and the range.

use std::path::Path;

use anyhow::{Context, Result, bail};
use glam::DVec3;

use super::meshes::meshes;
use super::models::{GivenLiquid, Hooke};
use super::raw::*;
use super::spawn::spawn;
use super::*;
use crate::model::registry::AdhesionModel;

/// A range check of Table 2's "Requirements" column.
#[derive(Clone, Copy)]
pub(super) enum Range {
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

pub(super) fn check(key: &str, x: f64, range: Range) -> Result<f64> {
    if !range.contains(x) {
        bail!(
            "{key} = {x} is not allowed: it must be {}",
            range.describe()
        );
    }
    Ok(x)
}

pub(super) fn check_vec(key: &str, v: [f64; 3]) -> Result<DVec3> {
    for (c, x) in ["x", "y", "z"].iter().zip(v) {
        check(&format!("{key}.{c}"), x, Range::Finite)?;
    }
    Ok(DVec3::from_array(v))
}

/// A box from `min` and `max` under `key`: `max >= min` in every component, or `max > min`
/// if `strict` (a box of space that must hold particles).
pub(super) fn region(key: &str, b: RawBox, strict: bool) -> Result<Region> {
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

/// Validates the properties of one material (`key` names it in messages).
fn material(table: &str, m: RawMaterial, viscosity: f64) -> Result<Material> {
    let key = |name: &str| format!("{table} {name}");
    let cohesion = check(
        &key("cohesion"),
        m.cohesion.unwrap_or(0.0),
        Range::NonNegative,
    )?;
    let surface_energy = check(
        &key("surface_energy"),
        m.surface_energy.unwrap_or(0.0),
        Range::NonNegative,
    )?;
    let liquid = GivenLiquid::read(table, [m.liquid_volume, m.surface_tension, m.contact_angle])?
        .of_material(table)?;
    let thermal = super::heat::thermal(table, &m)?;
    let names = [
        m.normal_model,
        m.adhesion_model,
        m.rolling_model,
        m.tangential_coulomb,
    ];
    let mut given = GivenModels::read(table, names)?;
    let hooke = Hooke::read(table, [m.hooke_stiffness, m.hooke_stiffness_ratio])?;
    hooke.choose(table, &mut given.normal)?;
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
        cohesion,
        surface_energy,
        liquid,
        hooke_stiffness: hooke.stiffness.unwrap_or(0.0),
        hooke_stiffness_ratio: hooke.ratio.unwrap_or(super::models::HOOKE_RATIO),
        models: given.of_material(table, cohesion, surface_energy)?,
        thermal,
    })
}

/// The value of a `mesh_contacts` or `contacts` key (default "merged").
pub(super) fn contacts(key: &str, value: Option<String>) -> Result<Contacts> {
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

/// The boxes of `[[name]]` entries (`[[outlets]]`, `[[fixed]]`), validated.
fn boxes(name: &str, raw: Vec<RawBox>) -> Result<Vec<Region>> {
    (raw.into_iter().enumerate())
        .map(|(k, b)| region(&format!("[[{name}]] #{}", k + 1), b, false))
        .collect()
}

impl Scenario {
    /// Parses and validates scenario text; `path` names the file in messages and anchors
    /// relative paths.
    pub fn parse(text: &str, path: &Path) -> Result<Scenario> {
        let raw: RawScenario = super::text::raw_scenario(text, path)?;
        let base = path.parent().unwrap_or(Path::new("."));
        Scenario::from_raw(raw, base)
            .with_context(|| format!("{}: invalid scenario", path.display()))
    }

    pub(super) fn from_raw(raw: RawScenario, base: &Path) -> Result<Scenario> {
        let mut g = raw.geometry;
        let g_mesh_material = g.mesh_material.take();
        let mut geometry = geometry(g, base)?;
        let radius_max = geometry.radius_max;
        let materials = materials(raw.material, raw.materials)?;
        let index = |key: &str, name: &str| material_index(&materials, key, name);
        let interactions = interactions(raw.interactions, &index)?;
        let material = materials[0].properties.clone();
        let kinetics = kinetics(raw.kinetics)?;
        let simulation = simulation(raw.simulation, &materials, geometry.radius_min)?;
        if let Some(name) = &g_mesh_material {
            geometry.mesh_material = index("[geometry] mesh_material", name)?;
        }
        let meshes = meshes(raw.meshes, base, &index)?;
        let tags = tags(raw.tags)?;
        let periodic = raw
            .domain
            .as_ref()
            .and_then(|d| d.periodic)
            .unwrap_or([false; 3]);
        let lees_edwards = match raw.domain.as_ref().and_then(|d| d.lees_edwards.as_ref()) {
            None => None,
            Some(le) => Some(lees_edwards(le, periodic)?),
        };
        let domain = domain(raw.domain, &simulation, radius_max, periodic)?;
        let outlets = boxes("outlets", raw.outlets)?;
        let fixed = boxes("fixed", raw.fixed)?;
        let clumps = super::clumps::clumps(raw.clumps, base, &geometry, &materials, &index)?;
        let spawn = spawn(
            raw.spawn,
            &index,
            (&clumps, &materials),
            &kinetics,
            &geometry,
            &simulation,
            domain,
        )?;
        let scenario = Scenario {
            clumps,
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
            fixed,
            spawn,
            particles: raw.input.particles.map(|p| base.join(p)),
            output_dir: raw
                .output
                .dir
                .map_or_else(|| base.join("output"), |d| base.join(d)),
            checkpoint_every: raw.output.checkpoint_every.unwrap_or(0),
            checkpoint_minutes: check(
                "[output] checkpoint_minutes",
                raw.output
                    .checkpoint_minutes
                    .unwrap_or(DEFAULT_CHECKPOINT_MINUTES),
                Range::NonNegative,
            )?,
            formats: Formats::parse(raw.output.formats)?,
            wall_forces: raw.output.wall_forces.unwrap_or(false),
            energy_ledger: raw.output.energy_ledger.unwrap_or(false),
            contact_network: raw.output.contacts.unwrap_or(false),
            forces: raw.output.forces.unwrap_or(false),
            gather: Gather::parse(raw.output.gather)?,
        };
        scenario.consistent()?;
        scenario.consistent_models()?;
        Ok(scenario)
    }

    /// What holds between tables: an `until` that can hold, clumps that can be spawned.
    fn consistent(&self) -> Result<()> {
        let until = &self.simulation.until;
        if until.servo_within.is_some() && self.meshes.iter().all(|m| m.servo.is_none()) {
            bail!(
                "[simulation] until.servo_within needs a servo: no [[meshes]] has motion = {{ type = \"servo\", ... }}"
            );
        }
        let removes =
            !self.outlets.is_empty() || (self.domain.is_some() && self.periodic != [true; 3]);
        if until.removed_at_least.is_some() && !removes {
            bail!(
                "[simulation] until.removed_at_least can never hold: nothing removes particles \
                 (no [[outlets]], and no [domain] with a side that is not periodic)"
            );
        }
        if self.energy_ledger && self.lees_edwards.is_some() {
            bail!(
                "[output] energy_ledger: the ledger of a sheared domain ([domain] lees_edwards) is \
                 not built yet (a grain crossing the sheared side changes its velocity)"
            );
        }
        if self.energy_ledger && !self.clumps.is_empty() {
            bail!(
                "[output] energy_ledger: the ledger of runs with [[clumps]] is not built yet (a \
                 clump's spheres move with its rotation, which the contacts' work does not see)"
            );
        }
        for (k, r) in self.spawn.iter().enumerate() {
            let Some(c) = r.clump else { continue };
            let (max, t) = (
                self.simulation.max_particles,
                &self.clumps[c.template as usize],
            );
            if max > 0 && (t.spheres.len() as u64) > max {
                bail!(
                    "[[spawn]] #{} clump = \"{}\" has {} spheres, more than [simulation] \
                     max_particles = {max} (which counts spheres): not one clump could be made",
                    k + 1,
                    t.name,
                    t.spheres.len()
                );
            }
        }
        Ok(())
    }
}

/// `[geometry]`, but its mesh material (a name of the materials).
fn geometry(g: RawGeometry, base: &Path) -> Result<Geometry> {
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
    let spawn_box_named = g.spawn_min.is_some() || g.spawn_max.is_some();
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
    Ok(Geometry {
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
        spawn_box_named,
    })
}

/// `[material]` or `[[materials]]`, each with the fluid's viscosity of `[material]`.
fn materials(one: RawMaterial, many: Vec<RawNamedMaterial>) -> Result<Vec<MaterialSpec>> {
    let viscosity = check(
        "[material] viscosity",
        one.viscosity.unwrap_or(0.0),
        Range::NonNegative,
    )?;
    let materials: Vec<MaterialSpec> = if many.is_empty() {
        vec![MaterialSpec {
            name: "default".into(),
            properties: material("[material]", one, viscosity)?,
        }]
    } else {
        if one.has_particle_keys() {
            bail!(
                "[material] may only set viscosity (of the surrounding fluid) when [[materials]] are given: set the other properties in [[materials]]"
            );
        }
        let mut names = std::collections::BTreeSet::new();
        many.into_iter()
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
    Ok(materials)
}

/// The index of the material `name`, given as `key`.
fn material_index(materials: &[MaterialSpec], key: &str, name: &str) -> Result<u16> {
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
}

/// `[[interactions]]`, their materials by name (`index`).
fn interactions(
    raw: Vec<RawInteraction>,
    index: &dyn Fn(&str, &str) -> Result<u16>,
) -> Result<Vec<Interaction>> {
    let mut interactions: Vec<Interaction> = Vec::new();
    for (k, i) in raw.into_iter().enumerate() {
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
        let cohesion = opt("cohesion", i.cohesion, Range::NonNegative)?;
        let surface_energy = opt("surface_energy", i.surface_energy, Range::NonNegative)?;
        let table = format!("[[interactions]] #{}", k + 1);
        let mut models = GivenModels::read(
            &table,
            [
                i.normal_model,
                i.adhesion_model,
                i.rolling_model,
                i.tangential_coulomb,
            ],
        )?;
        let hooke = Hooke::read(&table, [i.hooke_stiffness, i.hooke_stiffness_ratio])?;
        let liquid = GivenLiquid::read(
            &table,
            [i.liquid_volume, i.surface_tension, i.contact_angle],
        )?;
        hooke.choose(&table, &mut models.normal)?;
        if models.adhesion == Some(AdhesionModel::None) && cohesion.is_some_and(|k_c| k_c > 0.0) {
            bail!(
                "{} = \"none\" contradicts cohesion: drop one of them",
                key("adhesion_model")
            );
        }
        interactions.push(Interaction {
            materials: pair,
            restitution: opt("restitution", i.restitution, Range::Closed(0.0, 1.0))?,
            friction_sliding: opt("friction_sliding", i.friction_sliding, Range::NonNegative)?,
            friction_rolling: opt("friction_rolling", i.friction_rolling, Range::NonNegative)?,
            friction_twisting: opt("friction_twisting", i.friction_twisting, Range::NonNegative)?,
            cohesion,
            surface_energy,
            liquid,
            hooke_stiffness: hooke.stiffness,
            hooke_stiffness_ratio: hooke.ratio,
            models,
        });
    }
    Ok(interactions)
}

/// `[kinetics]`.
fn kinetics(k: RawKinetics) -> Result<Kinetics> {
    Ok(Kinetics {
        initial_velocity: check_vec(
            "[kinetics] initial_velocity",
            k.initial_velocity.unwrap_or([0.0, 0.0, -1.0]),
        )?,
        initial_angular_velocity: check_vec(
            "[kinetics] initial_angular_velocity",
            k.initial_angular_velocity.unwrap_or([0.0; 3]),
        )?,
        gravity: check_vec("[kinetics] gravity", k.gravity.unwrap_or([0.0, 0.0, -9.81]))?,
        ambient_temperature: super::heat::temperature(
            "[kinetics] ambient_temperature",
            k.ambient_temperature,
        )?,
    })
}

/// `[simulation]`; the time step by default Eq. (50)'s of the stiffest, lightest material.
fn simulation(
    s: RawSimulation,
    materials: &[MaterialSpec],
    radius_min: f64,
) -> Result<SimulationTable> {
    let timestep = match s.timestep {
        Some(dt) => check("[simulation] timestep", dt, Range::Positive)?,
        None => materials
            .iter()
            .map(|m| default_timestep(radius_min, &m.properties))
            .fold(f64::INFINITY, f64::min),
    };
    let simulation = SimulationTable {
        timestep,
        max_particles: s.max_particles.unwrap_or(1000),
        frames: s.frames.unwrap_or(100),
        steps_per_frame: s.steps_per_frame.unwrap_or(500),
        spawn_attempts: s.spawn_attempts.unwrap_or(100),
        seed: s.seed.unwrap_or(1),
        skin: check("[simulation] skin", s.skin.unwrap_or(0.5), Range::Positive)?,
        friction_springs: friction_springs(s.friction_springs)?,
        thermal_time_scale: super::heat::thermal_time_scale(s.thermal_time_scale)?,
        conduction_model: super::heat::conduction_model(s.conduction_model)?,
        until: until(s.until)?,
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
    Ok(simulation)
}

/// `[simulation] until`: each condition set is checked; an empty table is refused.
fn until(raw: Option<RawUntil>) -> Result<Until> {
    let Some(raw) = raw else {
        return Ok(Until::default());
    };
    let positive = |key: &str, x: Option<f64>| {
        x.map(|x| check(&format!("[simulation] until.{key}"), x, Range::Positive))
            .transpose()
    };
    let until = Until {
        kinetic_energy_below: positive("kinetic_energy_below", raw.kinetic_energy_below)?,
        time: positive("time", raw.time)?,
        removed_at_least: raw.removed_at_least,
        servo_within: raw
            .servo_within
            .map(|f| check("[simulation] until.servo_within", f, Range::Positive))
            .transpose()?,
        all: match raw.combine.as_deref() {
            None | Some("any") => false,
            Some("all") => true,
            Some(other) => bail!(
                "[simulation] until.combine = \"{other}\" is not allowed: it must be \"any\" (the \
                 run ends where one condition holds) or \"all\" (where all hold at one frame)"
            ),
        },
    };
    if until.servo_within.is_some_and(|f| f >= 1.0) {
        bail!(
            "[simulation] until.servo_within = {} is not allowed: it is a fraction of the target, below 1 (0.01: within 1 %)",
            until.servo_within.unwrap_or_default()
        );
    }
    if until.removed_at_least == Some(0) {
        bail!("[simulation] until.removed_at_least = 0 is not allowed: it must be at least 1");
    }
    if until.is_empty() {
        bail!(
            "[simulation] until = {{}} names no condition: give kinetic_energy_below, time, \
             removed_at_least or servo_within"
        );
    }
    Ok(until)
}

/// `[[tags]]`.
fn tags(raw: Vec<RawTag>) -> Result<Vec<TagRegion>> {
    raw.into_iter()
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
        .collect()
}

/// `[domain] lees_edwards`: the velocity, the shear and the gradient axis.
fn lees_edwards(le: &RawShear, periodic: [bool; 3]) -> Result<(f64, usize, usize)> {
    let key = "[domain] lees_edwards";
    let axis = |name: &str, value: &str| -> Result<usize> {
        match value {
            "x" => Ok(0),
            "y" => Ok(1),
            "z" => Ok(2),
            other => {
                bail!("{key} {name} = \"{other}\" is not allowed: it must be \"x\", \"y\" or \"z\"")
            }
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
    Ok((
        check(&format!("{key} velocity"), le.velocity, Range::Finite)?,
        s,
        g,
    ))
}

/// `[domain]`, its periods at least `SimulationTable::shortest_period` largest radii.
fn domain(
    raw: Option<RawDomain>,
    simulation: &SimulationTable,
    radius_max: f64,
    periodic: [bool; 3],
) -> Result<Option<Region>> {
    let domain = raw
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
    Ok(domain)
}
