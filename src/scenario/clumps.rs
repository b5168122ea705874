//! `[[clumps]]`: templates of rigidly joined spheres (non-spherical grains), validated, with
//! the mass, centre of mass and principal moments of the union of their spheres.

use std::path::Path;

use anyhow::{Context, Result, bail};
use glam::DVec3;

use super::raw::{RawClump, RawScale};
use super::{Geometry, MaterialSpec, SpawnClump};
use crate::model::clump::{Moments, Sphere};

/// A clump template, ready for the step.
#[derive(Clone, Debug, PartialEq)]
pub struct ClumpTemplate {
    pub name: String,
    /// The spheres as the scenario gives them (for `run.toml`).
    pub given: Vec<Sphere>,
    /// The spheres in the body frame: the centre of mass at the origin, the axes the
    /// principal axes (with `mass` and `inertia` given: as given).
    pub spheres: Vec<Sphere>,
    pub material: u16,
    /// Mass \[M\].
    pub mass: f64,
    /// Principal moments of inertia, ascending when computed \[M L²\].
    pub inertia: DVec3,
    /// Where mass and inertia came from: computed (with the estimated relative error of the
    /// quadrature) or given.
    pub source: MassSource,
    /// The radius of the sphere about the centre of mass that holds every sphere \[L\].
    pub bounding_radius: f64,
}

/// How a template's mass and inertia were found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MassSource {
    /// From the union of the spheres and the material's density; the relative error.
    Computed { error: f64 },
    /// `mass` and `inertia` from the scenario.
    Given,
}

/// `[[clumps]]`, relative files from `base`, materials by name (`index`).
pub(super) fn clumps(
    raw: Vec<RawClump>,
    base: &Path,
    geometry: &Geometry,
    materials: &[MaterialSpec],
    index: &dyn Fn(&str, &str) -> Result<u16>,
) -> Result<Vec<ClumpTemplate>> {
    let mut templates: Vec<ClumpTemplate> = Vec::new();
    for (k, c) in raw.into_iter().enumerate() {
        let key = format!("[[clumps]] #{} \"{}\"", k + 1, c.name);
        if c.name.trim().is_empty() {
            bail!("[[clumps]] #{}: name must not be empty", k + 1);
        }
        if templates.iter().any(|t| t.name == c.name) {
            bail!("{key}: the name is taken by an earlier clump");
        }
        let given = match (&c.spheres, &c.file) {
            (Some(s), None) => s.iter().map(|&[x, y, z, r]| sphere(x, y, z, r)).collect(),
            (None, Some(f)) => read_spheres(&base.join(f))?,
            _ => bail!("{key}: give either spheres = [[x, y, z, r], ...] or file = \"t.csv\""),
        };
        check_count(&key, given.len(), c.mass.is_some())?;
        check_spheres(&key, &given, geometry)?;
        let material = match &c.material {
            Some(name) => index(&format!("{key} material"), name)?,
            None => 0,
        };
        let density = materials[material as usize].properties.density;
        let template = match (c.mass, c.inertia) {
            (None, None) => computed(&c.name, given, material, density),
            (Some(mass), Some(inertia)) => {
                given_mass(&key, &c.name, given, material, mass, inertia)?
            }
            _ => bail!("{key}: give both mass and inertia = [I1, I2, I3], or neither"),
        };
        templates.push(template);
    }
    Ok(templates)
}

/// The clumps of a `[[spawn]]` region (`key`): template `name` of `templates`, scaled by
/// `scale` (a factor or a uniform range; 1 by default), its scaled radii within
/// [R_min, R_max] = `radii`.
pub(super) fn spawned(
    key: &str,
    name: &str,
    scale: Option<RawScale>,
    templates: &[ClumpTemplate],
    (lo, hi): (f64, f64),
) -> Result<SpawnClump> {
    let Some(template) = templates.iter().position(|t| t.name == name) else {
        let names: Vec<&str> = templates.iter().map(|t| t.name.as_str()).collect();
        bail!(
            "{key} clump = \"{name}\" is not among [[clumps]] ({})",
            names.join(", ")
        );
    };
    let (min, max) = match scale {
        None => (1.0, 1.0),
        Some(RawScale::Factor(s)) => (s, s),
        Some(RawScale::Uniform { min, max }) => (min, max),
    };
    if !(min > 0.0 && min.is_finite() && max.is_finite() && max >= min) {
        bail!("{key} scale: expected a factor > 0 or {{ min, max }} with 0 < min <= max");
    }
    let t = &templates[template];
    let smallest = t
        .spheres
        .iter()
        .map(|s| s.radius)
        .fold(f64::INFINITY, f64::min);
    let largest = t.spheres.iter().map(|s| s.radius).fold(0.0, f64::max);
    if smallest * min < lo * (1.0 - 1e-12) || largest * max > hi * (1.0 + 1e-12) {
        bail!(
            "{key} scale {min}..{max} makes spheres of clump \"{name}\" from {} to {}, outside \
             [geometry] radius_min..radius_max = {lo}..{hi}",
            smallest * min,
            largest * max
        );
    }
    Ok(SpawnClump {
        template: template as u16,
        scale: (min, max),
    })
}

fn sphere(x: f64, y: f64, z: f64, r: f64) -> Sphere {
    Sphere {
        centre: DVec3::new(x, y, z),
        radius: r,
    }
}

/// The spheres of a CSV file with the header `x,y,z,r`.
fn read_spheres(path: &Path) -> Result<Vec<Sphere>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read clump file {}", path.display()))?;
    let file = path.display();
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    match lines.next() {
        Some((_, h)) if h.split(',').map(str::trim).eq(["x", "y", "z", "r"]) => {}
        _ => bail!("{file}:1: expected the header 'x,y,z,r'"),
    }
    lines
        .map(|(n, line)| {
            let v: Vec<f64> = line
                .split(',')
                .map(|t| t.trim().parse())
                .collect::<Result<_, _>>()
                .ok()
                .filter(|v: &Vec<f64>| v.len() == 4)
                .with_context(|| format!("{file}:{}: expected four numbers x,y,z,r", n + 1))?;
            Ok(sphere(v[0], v[1], v[2], v[3]))
        })
        .collect()
}

/// The most spheres of a template whose mass properties the ray quadrature finds: its cost
/// grows with the spheres and their neighbours (about 25 s for 1,000 on two cores).
pub const MOST_SPHERES_COMPUTED: usize = 1_000;

/// The most spheres of a template with its mass and inertia given: each clump of it is that
/// many particles.
pub const MOST_SPHERES: usize = 100_000;

/// A template's sphere count within what its mass properties and its clumps can cost.
fn check_count(key: &str, n: usize, mass_given: bool) -> Result<()> {
    if n > MOST_SPHERES {
        bail!(
            "{key}: {n} spheres: a clump is one rigid body of at most {MOST_SPHERES} spheres \
             (each clump of it is that many particles)"
        );
    }
    if n > MOST_SPHERES_COMPUTED && !mass_given {
        bail!(
            "{key}: {n} spheres: the mass properties of more than {MOST_SPHERES_COMPUTED} \
             spheres would take minutes to compute (about 25 s for 1,000): give mass and \
             inertia = [I1, I2, I3] (the spheres then placed as given about the centre of mass \
             at the origin, along the principal axes), or use fewer spheres"
        );
    }
    Ok(())
}

/// At least one sphere, finite, radii within [R_min, R_max], and one connected body: every
/// sphere reached from the first through spheres that overlap or touch.
fn check_spheres(key: &str, spheres: &[Sphere], g: &Geometry) -> Result<()> {
    if spheres.is_empty() {
        bail!("{key}: a clump needs at least one sphere");
    }
    for (k, s) in spheres.iter().enumerate() {
        if !s.centre.is_finite() || !s.radius.is_finite() {
            bail!("{key}: sphere {} is not finite", k + 1);
        }
        if s.radius < g.radius_min || s.radius > g.radius_max {
            bail!(
                "{key}: sphere {} has radius {}, outside [geometry] radius_min..radius_max = {}..{}",
                k + 1,
                s.radius,
                g.radius_min,
                g.radius_max
            );
        }
    }
    // Joined: every sphere reached from the first along pairs that overlap or touch.
    let earlier = crate::model::clump::earlier_overlapping(spheres);
    let mut touching: Vec<Vec<u32>> = vec![Vec::new(); spheres.len()];
    for (k, before) in earlier.iter().enumerate() {
        for &j in before {
            touching[k].push(j);
            touching[j as usize].push(k as u32);
        }
    }
    let mut reached = vec![false; spheres.len()];
    let mut todo = vec![0];
    reached[0] = true;
    while let Some(i) = todo.pop() {
        for &j in &touching[i] {
            if !std::mem::replace(&mut reached[j as usize], true) {
                todo.push(j as usize);
            }
        }
    }
    if let Some(k) = reached.iter().position(|r| !r) {
        let s = spheres[k];
        bail!(
            "{key}: sphere {} (at {}, radius {}) is not joined to sphere 1: a clump is one body, \
             each sphere overlapping or touching another",
            k + 1,
            s.centre,
            s.radius
        );
    }
    Ok(())
}

/// A template whose mass and inertia come from the union of its spheres.
fn computed(name: &str, given: Vec<Sphere>, material: u16, density: f64) -> ClumpTemplate {
    let moments = Moments::of_union(&given);
    let (principal, rotation) = moments.principal();
    let to_body = rotation.inverse();
    let spheres: Vec<Sphere> = (given.iter())
        .map(|s| Sphere {
            centre: to_body * (s.centre - moments.centroid),
            radius: s.radius,
        })
        .collect();
    ClumpTemplate {
        name: name.to_string(),
        bounding_radius: bounding(&spheres),
        given,
        spheres,
        material,
        mass: density * moments.volume,
        inertia: density * principal,
        source: MassSource::Computed {
            error: moments.error,
        },
    }
}

/// A template with the user's mass and principal moments; its spheres are taken to be in
/// the principal frame with the centre of mass at the origin.
fn given_mass(
    key: &str,
    name: &str,
    given: Vec<Sphere>,
    material: u16,
    mass: f64,
    inertia: [f64; 3],
) -> Result<ClumpTemplate> {
    let i = DVec3::from_array(inertia);
    if !(mass > 0.0 && mass.is_finite() && i.cmpgt(DVec3::ZERO).all() && i.is_finite()) {
        bail!("{key}: mass and inertia must be finite and > 0");
    }
    // A body's centre of mass lies within it, so within the box of its spheres.
    let lo = given
        .iter()
        .map(|s| s.centre - s.radius)
        .fold(DVec3::INFINITY, DVec3::min);
    let hi = given
        .iter()
        .map(|s| s.centre + s.radius)
        .fold(DVec3::NEG_INFINITY, DVec3::max);
    if !(lo.cmple(DVec3::ZERO).all() && hi.cmpge(DVec3::ZERO).all()) {
        bail!(
            "{key}: with mass and inertia given, the spheres are placed about the centre of \
             mass at the origin, but the origin lies outside them (their box is {:?} .. {:?}): \
             give the spheres relative to the centre of mass",
            lo.to_array(),
            hi.to_array()
        );
    }
    // The moments of a body obey the triangle inequality: each at most the sum of the others.
    if (0..3).any(|a| i[a] > (i.element_sum() - i[a]) * (1.0 + 1e-12)) {
        bail!(
            "{key}: inertia = {inertia:?} cannot be a body's: each moment must be at most the sum of the other two"
        );
    }
    Ok(ClumpTemplate {
        name: name.to_string(),
        bounding_radius: bounding(&given),
        spheres: given.clone(),
        given,
        material,
        mass,
        inertia: i,
        source: MassSource::Given,
    })
}

fn bounding(spheres: &[Sphere]) -> f64 {
    spheres
        .iter()
        .map(|s| s.centre.length() + s.radius)
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests;
