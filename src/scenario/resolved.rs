//! The resolved scenario as TOML (`to_toml`: every default filled in, stored in run.toml and
//! in checkpoints) and what one resolved scenario changes with respect to another
//! (`changes`, for staged runs).

use std::fmt::Write;

use glam::DVec3;

use super::models;
use super::*;
use crate::geometry::shapes::{BOX_SIDES, CYLINDER_ENDS};

impl Scenario {
    /// The scenario as TOML with every default filled in: parsed again (from a file in the
    /// current directory) it gives the same scenario. A built-in mesh is named in a comment.
    pub fn to_toml(&self) -> String {
        let mut o = String::new();
        self.geometry_toml(&mut o);
        self.materials_toml(&mut o);
        self.kinetics_toml(&mut o);
        self.simulation_toml(&mut o);
        self.meshes_toml(&mut o);
        self.regions_toml(&mut o);
        self.spawn_toml(&mut o);
        self.clumps_toml(&mut o);
        self.output_toml(&mut o);
        o
    }

    /// The name of material `k`, as TOML.
    fn material_name(&self, k: u16) -> String {
        text(&self.materials[k as usize].name)
    }

    fn geometry_toml(&self, o: &mut String) {
        let g = &self.geometry;
        *o += "[geometry]\n";
        let _ = writeln!(o, "radius_min = {}", num(g.radius_min));
        let _ = writeln!(o, "radius_max = {}", num(g.radius_max));
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
        if self.uses_materials() {
            let _ = writeln!(o, "mesh_material = {}", self.material_name(g.mesh_material));
        }
        if g.spawn_box_named {
            let _ = writeln!(o, "spawn_min = {}", vec3(g.spawn_min));
            let _ = writeln!(o, "spawn_max = {}", vec3(g.spawn_max));
        }
    }

    fn materials_toml(&self, o: &mut String) {
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
                let _ = writeln!(o, "{key} = {}", num(x));
            }
            if m.surface_energy > 0.0 {
                let _ = writeln!(o, "surface_energy = {}", num(m.surface_energy));
            }
            if m.liquid.wet() {
                let l = &m.liquid;
                let _ = writeln!(o, "liquid_volume = {}", num(l.volume));
                let _ = writeln!(o, "surface_tension = {}", num(l.surface_tension));
                let _ = writeln!(o, "contact_angle = {}", num(l.contact_angle));
            }
            if m.models.normal == NormalModel::Hooke {
                let _ = writeln!(o, "hooke_stiffness = {}", num(m.hooke_stiffness));
                let _ = writeln!(
                    o,
                    "hooke_stiffness_ratio = {}",
                    num(m.hooke_stiffness_ratio)
                );
            }
            for (key, name) in models::beyond_defaults(m).named() {
                let _ = writeln!(o, "{key} = {}", text(name));
            }
            let t = &m.thermal;
            for (key, x) in [
                ("thermal_conductivity", t.conductivity),
                ("heat_capacity", t.capacity),
                ("initial_temperature", t.initial_temperature),
                ("heat_source", t.source),
                ("surface_heat_transfer", t.surface_transfer),
            ] {
                // Only where given: a run without heat writes what it wrote before.
                if x != 0.0 {
                    let _ = writeln!(o, "{key} = {}", num(x));
                }
            }
        };
        if self.uses_materials() {
            for m in &self.materials {
                let _ = writeln!(o, "\n[[materials]]\nname = {}", text(&m.name));
                properties(o, &m.properties);
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
                        let _ = writeln!(o, "{key} = {}", num(x));
                    }
                }
                for (key, name) in i.models.named() {
                    let _ = writeln!(o, "{key} = {}", text(name));
                }
            }
            *o += "\n[material]\n";
        } else {
            *o += "\n[material]\n";
            properties(o, &self.material);
        }
        let _ = writeln!(o, "viscosity = {}", num(self.material.viscosity));
    }

    fn kinetics_toml(&self, o: &mut String) {
        let k = &self.kinetics;
        *o += "\n[kinetics]\n";
        let _ = writeln!(o, "initial_velocity = {}", vec3(k.initial_velocity));
        let _ = writeln!(
            o,
            "initial_angular_velocity = {}",
            vec3(k.initial_angular_velocity)
        );
        let _ = writeln!(o, "gravity = {}", vec3(k.gravity));
        if let Some(t) = k.ambient_temperature {
            let _ = writeln!(o, "ambient_temperature = {}", num(t));
        }
    }

    fn simulation_toml(&self, o: &mut String) {
        let s = &self.simulation;
        *o += "\n[simulation]\n";
        let _ = writeln!(o, "timestep = {}", num(s.timestep));
        for (key, n) in [
            ("max_particles", s.max_particles),
            ("frames", s.frames),
            ("steps_per_frame", s.steps_per_frame),
            ("spawn_attempts", s.spawn_attempts),
            ("seed", s.seed),
        ] {
            let _ = writeln!(o, "{key} = {n}");
        }
        let _ = writeln!(o, "skin = {}", num(s.skin));
        let _ = writeln!(o, "friction_springs = {}", text(s.friction_springs.key()));
        if self.heat() {
            let _ = writeln!(o, "thermal_time_scale = {}", num(s.thermal_time_scale));
            let _ = writeln!(o, "conduction_model = {}", text(s.conduction_model.key()));
        }
        let u = &s.until;
        if !u.is_empty() {
            let mut conditions = Vec::new();
            if let Some(e) = u.kinetic_energy_below {
                conditions.push(format!("kinetic_energy_below = {}", num(e)));
            }
            if let Some(t) = u.time {
                conditions.push(format!("time = {}", num(t)));
            }
            if let Some(n) = u.removed_at_least {
                conditions.push(format!("removed_at_least = {n}"));
            }
            if let Some(f) = u.servo_within {
                conditions.push(format!("servo_within = {}", num(f)));
            }
            if u.all {
                conditions.push(format!("combine = {}", text("all")));
            }
            let _ = writeln!(o, "until = {{ {} }}", conditions.join(", "));
        }
    }

    fn meshes_toml(&self, o: &mut String) {
        for mesh in &self.meshes {
            *o += "\n[[meshes]]\n";
            match &mesh.input {
                MeshInput::File(p) => {
                    let _ = writeln!(o, "file = {}", path(p));
                }
                MeshInput::Shape(s) => {
                    let _ = writeln!(o, "shape = {}", shape(s));
                }
            }
            let _ = writeln!(o, "radii = {}", list(&mesh.radii));
            let _ = writeln!(o, "contacts = {}", contacts(mesh.contacts));
            if self.uses_materials() {
                let _ = writeln!(o, "material = {}", self.material_name(mesh.material));
            }
            if let Some(m) = mesh.motion {
                let _ = writeln!(o, "motion = {}", motion(m));
            }
            if let Some(t) = mesh.temperature {
                let _ = writeln!(o, "temperature = {}", num(t));
            }
            if let Some(s) = mesh.servo {
                let _ = writeln!(o, "motion = {}", servo(s));
            }
        }
    }

    /// `[[tags]]`, `[domain]`, `[[outlets]]` and `[[fixed]]`.
    fn regions_toml(&self, o: &mut String) {
        for t in &self.tags {
            *o += "\n[[tags]]\n";
            let _ = writeln!(
                o,
                "min = {}\nmax = {}\ntag = {}",
                vec3(t.min),
                vec3(t.max),
                t.tag
            );
        }
        if let Some(d) = self.domain {
            let _ = writeln!(
                o,
                "\n[domain]\nmin = {}\nmax = {}",
                vec3(d.min),
                vec3(d.max)
            );
            let [x, y, z] = self.periodic;
            let _ = writeln!(o, "periodic = [{x}, {y}, {z}]");
            if let Some((velocity, s, g)) = self.lees_edwards {
                let name = |a: usize| ["x", "y", "z"][a];
                let _ = writeln!(
                    o,
                    "lees_edwards = {{ velocity = {}, shear_axis = \"{}\", gradient_axis = \"{}\" }}",
                    num(velocity),
                    name(s),
                    name(g)
                );
            }
        }
        for (name, boxes) in [("outlets", &self.outlets), ("fixed", &self.fixed)] {
            for b in boxes {
                let (min, max) = (vec3(b.min), vec3(b.max));
                let _ = writeln!(o, "\n[[{name}]]\nmin = {min}\nmax = {max}");
            }
        }
    }

    fn spawn_toml(&self, o: &mut String) {
        for r in &self.spawn {
            let _ = writeln!(
                o,
                "\n[[spawn]]\nmin = {}\nmax = {}\nvelocity = {}",
                vec3(r.region.min),
                vec3(r.region.max),
                vec3(r.velocity)
            );
            if let Some(c) = r.clump {
                let name = text(&self.clumps[c.template as usize].name);
                let (min, max) = (num(c.scale.0), num(c.scale.1));
                let _ = writeln!(o, "clump = {name}\nscale = {{ min = {min}, max = {max} }}");
            } else if self.uses_materials() {
                let _ = writeln!(o, "material = {}", self.material_name(r.material));
            }
            if let Some(t) = r.temperature {
                let _ = writeln!(o, "temperature = {}", num(t));
            }
            if let Some(n) = r.count {
                let _ = writeln!(o, "count = {n}");
            }
            if let Some(rate) = r.rate {
                let _ = writeln!(o, "rate = {}", num(rate));
            }
            let _ = writeln!(o, "start = {}", num(r.start));
            if r.stop.is_finite() {
                let _ = writeln!(o, "stop = {}", num(r.stop));
            }
            if r.clump.is_none() {
                let _ = writeln!(o, "radius = {}", radius(&r.radius));
            }
        }
    }

    fn clumps_toml(&self, o: &mut String) {
        for c in &self.clumps {
            let spheres: Vec<String> = (c.given.iter())
                .map(|s| list(&[s.centre.x, s.centre.y, s.centre.z, s.radius]))
                .collect();
            let _ = writeln!(
                o,
                "\n[[clumps]]\nname = {}\nspheres = [{}]\nmaterial = {}",
                text(&c.name),
                spheres.join(", "),
                self.material_name(c.material)
            );
            if c.source == super::MassSource::Given {
                let _ = writeln!(o, "mass = {}\ninertia = {}", num(c.mass), vec3(c.inertia));
            }
        }
    }

    fn output_toml(&self, o: &mut String) {
        if let Some(p) = &self.particles {
            let _ = writeln!(o, "\n[input]\nparticles = {}", path(p));
        }
        *o += "\n[output]\n";
        let _ = writeln!(o, "dir = {}", path(&self.output_dir));
        let _ = writeln!(o, "checkpoint_every = {}", self.checkpoint_every);
        let _ = writeln!(o, "checkpoint_minutes = {}", num(self.checkpoint_minutes));
        let mut formats = Vec::new();
        if self.formats.csv {
            formats.push("\"csv\"");
        }
        if self.formats.vtk {
            formats.push("\"vtk\"");
        }
        let _ = writeln!(o, "formats = [{}]", formats.join(", "));
        let _ = writeln!(o, "wall_forces = {}", self.wall_forces);
        let _ = writeln!(o, "energy_ledger = {}", self.energy_ledger);
        let _ = writeln!(o, "contacts = {}", self.contact_network);
        let _ = writeln!(o, "forces = {}", self.forces);
        let _ = writeln!(o, "gather = \"{}\"", self.gather.name());
    }
}

fn num(x: f64) -> String {
    format!("{x:?}")
}

fn vec3(x: DVec3) -> String {
    format!("[{:?}, {:?}, {:?}]", x.x, x.y, x.z)
}

fn list(xs: &[f64]) -> String {
    let items: Vec<String> = xs.iter().map(|&x| num(x)).collect();
    format!("[{}]", items.join(", "))
}

fn text(t: &str) -> String {
    toml::Value::String(t.to_string()).to_string()
}

fn path(p: &Path) -> String {
    text(&p.display().to_string())
}

fn contacts(c: Contacts) -> &'static str {
    match c {
        Contacts::Merged => "\"merged\"",
        Contacts::PerFace => "\"per_face\"",
    }
}

/// A mesh's motion as an inline table.
fn motion(m: Motion) -> String {
    match m {
        Motion::Harmonic {
            amplitude,
            frequency,
            direction,
            phase,
        } => format!(
            "{{ type = \"harmonic\", amplitude = {}, frequency = {}, direction = {}, phase = {} }}",
            num(amplitude),
            num(frequency),
            vec3(direction),
            num(phase)
        ),
        Motion::Velocity { velocity } => {
            format!("{{ type = \"velocity\", velocity = {} }}", vec3(velocity))
        }
        Motion::Rotation {
            center,
            axis,
            angular_velocity,
        } => format!(
            "{{ type = \"rotation\", center = {}, axis = {}, angular_velocity = {} }}",
            vec3(center),
            vec3(axis),
            num(angular_velocity)
        ),
    }
}

/// A servo as an inline table (its gain only if given: the default is derived at setup).
fn servo(s: Servo) -> String {
    let target = match s.target {
        Target::Force(f) => format!("force = {}", num(f)),
        Target::Stress(p) => format!("stress = {}", num(p)),
    };
    let gain = s
        .gain
        .map(|g| format!(", gain = {}", num(g)))
        .unwrap_or_default();
    format!(
        "{{ type = \"servo\", direction = {}, {target}, max_speed = {}{gain} }}",
        vec3(s.direction),
        num(s.max_speed)
    )
}

/// A built-in shape as an inline table.
fn shape(s: &Shape) -> String {
    let names = |open: &[bool], names: &[&str]| {
        let named: Vec<String> = names
            .iter()
            .zip(open)
            .filter(|&(_, &o)| o)
            .map(|(n, _)| text(n))
            .collect();
        format!("[{}]", named.join(", "))
    };
    let fields = match *s {
        Shape::Box { min, max, open } => format!(
            "min = {}, max = {}, open = {}",
            vec3(min),
            vec3(max),
            names(&open, &BOX_SIDES)
        ),
        Shape::Cylinder {
            center,
            axis,
            radius,
            height,
            open,
            orifice,
            resolution,
        } => format!(
            "center = {}, axis = {}, radius = {}, height = {}, open = {}, orifice = {}, resolution = {resolution}",
            vec3(center),
            vec3(axis),
            num(radius),
            num(height),
            names(&open, &CYLINDER_ENDS),
            num(orifice)
        ),
        Shape::Drum {
            center,
            axis,
            radius,
            length,
            resolution,
        } => format!(
            "center = {}, axis = {}, radius = {}, length = {}, resolution = {resolution}",
            vec3(center),
            vec3(axis),
            num(radius),
            num(length)
        ),
        Shape::Plane {
            point,
            normal,
            size,
        } => format!(
            "point = {}, normal = {}, size = {}",
            vec3(point),
            vec3(normal),
            num(size)
        ),
        Shape::Hopper {
            center,
            axis,
            top_radius,
            outlet_radius,
            height,
            resolution,
        } => format!(
            "center = {}, axis = {}, top_radius = {}, outlet_radius = {}, height = {}, resolution = {resolution}",
            vec3(center),
            vec3(axis),
            num(top_radius),
            num(outlet_radius),
            num(height)
        ),
    };
    format!("{{ type = \"{}\", {fields} }}", s.kind())
}

/// A spawn region's radius distribution as an inline table.
fn radius(r: &RadiusDistribution) -> String {
    match r {
        RadiusDistribution::Uniform { min, max } => format!(
            "{{ distribution = \"uniform\", min = {}, max = {} }}",
            num(*min),
            num(*max)
        ),
        RadiusDistribution::Normal {
            mean,
            std,
            min,
            max,
        } => format!(
            "{{ distribution = \"normal\", mean = {}, std = {}, min = {}, max = {} }}",
            num(*mean),
            num(*std),
            num(*min),
            num(*max)
        ),
        RadiusDistribution::LogNormal {
            mean,
            std,
            min,
            max,
        } => format!(
            "{{ distribution = \"lognormal\", mean = {}, std = {}, min = {}, max = {} }}",
            num(*mean),
            num(*std),
            num(*min),
            num(*max)
        ),
        RadiusDistribution::Table { radii, weights } => format!(
            "{{ distribution = \"table\", radii = {}, weights = {} }}",
            list(radii),
            list(weights)
        ),
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
