//! Validation of `[[meshes]]`: a file or a built-in shape, its radii, contacts, material
//! and motion.

use std::path::Path;

use anyhow::{Result, bail};
use glam::DVec3;

use super::raw::*;
use super::validate::{Range, check, check_vec, contacts};
use super::*;
use crate::geometry::shapes::{BOX_SIDES, CYLINDER_ENDS, Shape};

/// The faces per 2 pi of a round shape unless `resolution` says otherwise.
pub const DEFAULT_RESOLUTION: u32 = 48;

/// `[[meshes]]`, their materials by name (`index`).
pub(super) fn meshes(
    raw: Vec<RawMesh>,
    base: &Path,
    index: &dyn Fn(&str, &str) -> Result<u16>,
) -> Result<Vec<MeshSpec>> {
    raw.into_iter()
        .enumerate()
        .map(|(k, mut m)| {
            let name = m.material.take();
            let mut spec = mesh_spec(k, m, base)?;
            if let Some(name) = name {
                spec.material = index(&format!("[[meshes]] #{} material", k + 1), &name)?;
            }
            Ok(spec)
        })
        .collect()
}

/// Validates one `[[meshes]]` entry.
fn mesh_spec(k: usize, m: RawMesh, base: &Path) -> Result<MeshSpec> {
    let key = |name: &str| format!("[[meshes]] #{} {name}", k + 1);
    let input = match (m.file, m.shape) {
        (Some(file), None) => MeshInput::File(base.join(file)),
        (None, Some(raw)) => MeshInput::Shape(shape(&key, raw)?),
        (None, None) => bail!(
            "[[meshes]] #{} needs a `file` (OFF or STL) or a `shape` (box, cylinder, drum, plane, hopper)",
            k + 1
        ),
        (Some(_), Some(_)) => bail!(
            "[[meshes]] #{} has both a `file` and a `shape`: give one of them",
            k + 1
        ),
    };
    let radii = m.radii.unwrap_or_else(|| vec![0.0]);
    if radii.is_empty() {
        bail!("{} must hold at least one radius", key("radii"));
    }
    if matches!(input, MeshInput::Shape(_)) && radii.len() > 1 {
        bail!(
            "{} holds {} radii: a shape's faces have one radius",
            key("radii"),
            radii.len()
        );
    }
    for (i, &r) in radii.iter().enumerate() {
        check(&key(&format!("radii[{i}]")), r, Range::NonNegative)?;
    }
    let (motion, servo) = match m.motion {
        None => (None, None),
        Some(RawMotion::Servo {
            direction,
            force,
            stress,
            max_speed,
            gain,
        }) => {
            let key = |name: &str| key(&format!("motion.{name}"));
            let target = match (force, stress) {
                (Some(f), None) => Target::Force(check(&key("force"), f, Range::Positive)?),
                (None, Some(s)) => Target::Stress(check(&key("stress"), s, Range::Positive)?),
                _ => bail!(
                    "[[meshes]] #{} motion: a servo needs either `force` [N] or `stress` [Pa], not both",
                    k + 1
                ),
            };
            let servo = Servo {
                direction: unit(&key("direction"), direction)?,
                target,
                max_speed: check(&key("max_speed"), max_speed, Range::Positive)?,
                gain: gain
                    .map(|g| check(&key("gain"), g, Range::Positive))
                    .transpose()?,
            };
            (None, Some(servo))
        }
        Some(raw) => (Some(motion(&key, raw)?), None),
    };
    Ok(MeshSpec {
        input,
        radii,
        contacts: contacts(&key("contacts"), m.contacts)?,
        motion,
        servo,
        material: 0,
        temperature: super::heat::temperature(&key("temperature"), m.temperature)?,
    })
}

/// A unit vector along `v`, which must not be zero: scaled by its largest component
/// first, so that components whose squares overflow (1e200) or vanish (1e-200) still give
/// their direction, and without negative zeros.
pub(super) fn unit(key: &str, v: [f64; 3]) -> Result<DVec3> {
    let v = check_vec(key, v)?;
    let largest = v.abs().max_element();
    if largest == 0.0 {
        bail!("{key} must not be the zero vector");
    }
    Ok((v / largest).normalize() + DVec3::ZERO)
}

/// `motion = { type = ... }`.
fn motion(key: &dyn Fn(&str) -> String, raw: RawMotion) -> Result<Motion> {
    Ok(match raw {
        RawMotion::Harmonic {
            amplitude,
            frequency,
            direction,
            phase,
        } => Motion::Harmonic {
            amplitude: check(&key("motion.amplitude"), amplitude, Range::NonNegative)?,
            frequency: check(&key("motion.frequency"), frequency, Range::NonNegative)?,
            direction: unit(&key("motion.direction"), direction)?,
            phase: check(&key("motion.phase"), phase.unwrap_or(0.0), Range::Finite)?,
        },
        RawMotion::Velocity { velocity } => Motion::Velocity {
            velocity: check_vec(&key("motion.velocity"), velocity)?,
        },
        RawMotion::Rotation {
            center,
            axis,
            angular_velocity,
        } => Motion::Rotation {
            center: check_vec(&key("motion.center"), center)?,
            axis: unit(&key("motion.axis"), axis)?,
            angular_velocity: check(
                &key("motion.angular_velocity"),
                angular_velocity,
                Range::Finite,
            )?,
        },
        RawMotion::Servo { .. } => unreachable!("a servo is read by mesh_spec"),
    })
}

/// The checks of a shape's keys, each error naming `[[meshes]] #k shape.KEY`.
struct Keys<'a> {
    mesh: &'a dyn Fn(&str) -> String,
}

impl Keys<'_> {
    fn key(&self, name: &str) -> String {
        (self.mesh)(&format!("shape.{name}"))
    }
    fn positive(&self, name: &str, x: f64) -> Result<f64> {
        check(&self.key(name), x, Range::Positive)
    }
    fn point(&self, name: &str, v: [f64; 3]) -> Result<DVec3> {
        check_vec(&self.key(name), v)
    }
    fn axis(&self, name: &str, v: [f64; 3]) -> Result<DVec3> {
        unit(&self.key(name), v)
    }
    fn resolution(&self, r: Option<i64>) -> Result<u32> {
        resolution(&self.key("resolution"), r)
    }
}

/// `shape = { type = ... }`: lengths positive, axes not zero, open sides by name, and its
/// faces within double precision (made once here, so that the run can make them).
fn shape(key: &dyn Fn(&str) -> String, raw: RawShape) -> Result<Shape> {
    let shape = shape_keys(key, raw)?;
    if let Err(why) = shape.try_mesh(0.0) {
        bail!(
            "{}: the {} cannot be made: {why}; its lengths and places must be far below 1e150 m",
            key("shape"),
            shape.kind()
        );
    }
    Ok(shape)
}

/// The keys of `shape = { type = ... }`, each checked.
fn shape_keys(key: &dyn Fn(&str) -> String, raw: RawShape) -> Result<Shape> {
    let k = Keys { mesh: key };
    Ok(match raw {
        RawShape::Box { min, max, open } => box_shape(&k, min, max, open)?,
        RawShape::Cylinder { .. } => cylinder(&k, raw)?,
        RawShape::Drum {
            center,
            axis,
            radius,
            length,
            resolution,
        } => Shape::Drum {
            center: k.point("center", center)?,
            axis: k.axis("axis", axis)?,
            radius: k.positive("radius", radius)?,
            length: k.positive("length", length)?,
            resolution: k.resolution(resolution)?,
        },
        RawShape::Plane {
            point,
            normal,
            size,
        } => Shape::Plane {
            point: k.point("point", point)?,
            normal: k.axis("normal", normal)?,
            size: k.positive("size", size)?,
        },
        RawShape::Hopper { .. } => hopper(&k, raw)?,
    })
}

/// A box: `min` below `max`, not every side open.
fn box_shape(k: &Keys, min: [f64; 3], max: [f64; 3], open: Option<Vec<String>>) -> Result<Shape> {
    let (min, max) = (k.point("min", min)?, k.point("max", max)?);
    if !min.cmplt(max).all() {
        bail!(
            "{} = {:?} must be below {} = {:?} in x, y and z",
            k.key("min"),
            min.to_array(),
            k.key("max"),
            max.to_array()
        );
    }
    let open = open_sides(&k.key("open"), open, BOX_SIDES)?;
    if open.iter().all(|&o| o) {
        bail!("{} opens all six sides: nothing is left", k.key("open"));
    }
    Ok(Shape::Box { min, max, open })
}

/// A cylinder: an orifice below the radius, and only in a closed bottom.
fn cylinder(k: &Keys, raw: RawShape) -> Result<Shape> {
    let RawShape::Cylinder {
        center,
        axis,
        radius,
        height,
        open,
        orifice,
        resolution,
    } = raw
    else {
        unreachable!("cylinder is called for cylinders")
    };
    let radius = k.positive("radius", radius)?;
    let open = open_sides(&k.key("open"), open, CYLINDER_ENDS)?;
    let orifice = orifice.unwrap_or(0.0);
    if !(0.0..radius).contains(&orifice) {
        bail!(
            "{} = {orifice} is not allowed: it must be >= 0 and below the radius {radius}",
            k.key("orifice")
        );
    }
    if orifice > 0.0 && open[0] {
        bail!(
            "{} = {orifice} needs a bottom, but {} opens it",
            k.key("orifice"),
            k.key("open")
        );
    }
    Ok(Shape::Cylinder {
        center: k.point("center", center)?,
        axis: k.axis("axis", axis)?,
        radius,
        height: k.positive("height", height)?,
        open,
        orifice,
        resolution: k.resolution(resolution)?,
    })
}

/// A hopper: radii not both zero.
fn hopper(k: &Keys, raw: RawShape) -> Result<Shape> {
    let RawShape::Hopper {
        center,
        axis,
        top_radius,
        outlet_radius,
        height,
        resolution,
    } = raw
    else {
        unreachable!("hopper is called for hoppers")
    };
    let top = check(&k.key("top_radius"), top_radius, Range::NonNegative)?;
    let outlet = check(&k.key("outlet_radius"), outlet_radius, Range::NonNegative)?;
    if top == 0.0 && outlet == 0.0 {
        bail!(
            "{} and {} are both 0: one of them must be > 0",
            k.key("top_radius"),
            k.key("outlet_radius")
        );
    }
    if outlet >= top {
        bail!(
            "{} = {outlet} must be below {} = {top}: a hopper narrows from its top down to \
             its outlet (for a funnel that widens along `axis`, turn the axis round and put \
             `center` at the narrow end; outlet_radius = 0 closes it in a cone)",
            k.key("outlet_radius"),
            k.key("top_radius")
        );
    }
    Ok(Shape::Hopper {
        center: k.point("center", center)?,
        axis: k.axis("axis", axis)?,
        top_radius: top,
        outlet_radius: outlet,
        height: k.positive("height", height)?,
        resolution: k.resolution(resolution)?,
    })
}

/// Faces per 2 pi: 3 to 100,000, default [`DEFAULT_RESOLUTION`].
fn resolution(key: &str, value: Option<i64>) -> Result<u32> {
    match value {
        None => Ok(DEFAULT_RESOLUTION),
        Some(n @ 3..=100_000) => Ok(n as u32),
        Some(n) => bail!("{key} = {n} is not allowed: it must be a whole number in [3, 100000]"),
    }
}

/// Which of `names` the list `open` names, each at most once.
fn open_sides<const N: usize>(
    key: &str,
    open: Option<Vec<String>>,
    names: [&str; N],
) -> Result<[bool; N]> {
    let mut out = [false; N];
    for side in open.unwrap_or_default() {
        let Some(k) = names.iter().position(|n| *n == side) else {
            let all: Vec<String> = names.iter().map(|n| format!("\"{n}\"")).collect();
            bail!(
                "{key}: \"{side}\" is not a side: it must be one of {}",
                all.join(", ")
            );
        };
        if out[k] {
            bail!("{key} names \"{side}\" twice");
        }
        out[k] = true;
    }
    Ok(out)
}
