//! Checkpoints: the complete state of a run in a versioned binary file with a checksum, so
//! that a resumed run is bitwise identical to an uninterrupted one. The bytes are those of
//! `engine::records::bytes` (its documentation gives the layout); this module puts them
//! into files, checks them against the scenario, and reads them back.

use std::path::Path;

use crate::engine::records::Snapshot;
pub use crate::engine::records::{decode, encode, encode_into, hash, join, shared_part};
use crate::geometry::mesh::Mesh;
use crate::model::registry::NormalModel;
use crate::scenario::{FrictionSprings, GivenModels, Scenario, beyond_defaults};
use anyhow::{Context, Result};

pub mod parts;
pub use parts::{
    is_part, load_parts, load_share, merge, newer_parts, part_path, remove_parts, save_part,
};

/// A fingerprint of everything a checkpoint's state depends on: the physics, time step,
/// spawning and mesh. The number of frames and the output may change on resume.
pub fn fingerprint(s: &Scenario, mesh: &Mesh) -> u64 {
    // The material as checkpoints of format 2 wrote it (cohesion, when there is any, is
    // added below), so that they resume.
    let m = &s.material;
    let material = format!(
        "Material {{ density: {:?}, youngs_modulus: {:?}, poisson_ratio: {:?}, restitution: {:?}, friction_sliding: {:?}, friction_rolling: {:?}, friction_twisting: {:?}, viscosity: {:?} }}",
        m.density,
        m.youngs_modulus,
        m.poisson_ratio,
        m.restitution,
        m.friction_sliding,
        m.friction_rolling,
        m.friction_twisting,
        m.viscosity
    );
    // `[kinetics]` as its struct's `Debug` text was before the surroundings' temperature.
    let k = &s.kinetics;
    let kinetics = format!(
        "Kinetics {{ initial_velocity: {:?}, initial_angular_velocity: {:?}, gravity: {:?} }}",
        k.initial_velocity, k.initial_angular_velocity, k.gravity
    );
    let text = format!(
        "{:?}|{}|{}|{:?}|{}|{}|{}|{}|{:?}",
        s.geometry.mesh_radii,
        material,
        kinetics,
        (
            s.geometry.radius_min,
            s.geometry.radius_max,
            s.geometry.spawn_min,
            s.geometry.spawn_max
        ),
        s.simulation.timestep,
        s.simulation.steps_per_frame,
        s.simulation.max_particles,
        s.simulation.spawn_attempts,
        (s.simulation.seed, &mesh.faces),
    );
    let text = if m.cohesion != 0.0 {
        format!("{text}|cohesion {:?}", m.cohesion)
    } else {
        text
    };
    // The springs' order: checkpoints written before it was a choice are in the paper's,
    // and resume in it only.
    let text = match s.simulation.friction_springs {
        FrictionSprings::Paper => text,
        FrictionSprings::AdvanceFirst => format!("{text}|springs advance_first"),
    };
    // Named materials (absent from older checkpoints, which stay valid without them).
    let text = if s.uses_materials() {
        format!("{text}|{}|{}", materials_text(s), s.geometry.mesh_material)
    } else {
        text
    };
    // Heat transfer (absent from checkpoints of runs without it).
    let text = if s.heat() {
        format!("{text}|heat {}", heat_text(s))
    } else {
        text
    };
    hash(&text)
}

/// What heat transfer depends on: each material's thermal properties, the surroundings,
/// the thermal step, the conduction model and the meshes' temperatures.
fn heat_text(s: &Scenario) -> String {
    let materials: Vec<String> = (s.materials.iter())
        .map(|m| {
            let t = &m.properties.thermal;
            format!(
                "{:?} {:?} {:?} {:?} {:?}",
                t.conductivity, t.capacity, t.initial_temperature, t.source, t.surface_transfer
            )
        })
        .collect();
    let walls: Vec<Option<f64>> = s.meshes.iter().map(|m| m.temperature).collect();
    format!(
        "[{}] {:?} {:?} {} {:?}",
        materials.join(", "),
        s.kinetics.ambient_temperature,
        s.simulation.thermal_time_scale,
        s.simulation.conduction_model.key(),
        walls
    )
}

/// The named materials and interactions of `s` as the fingerprint holds them: in the text
/// earlier checkpoints hashed (the `Debug` text their structs had, written out here so that
/// a member added to the structs changes no fingerprint), then the contact sub-models each
/// names beyond the defaults, if any.
fn materials_text(s: &Scenario) -> String {
    let materials: Vec<String> = (s.materials.iter())
        .map(|m| {
            let p = &m.properties;
            format!(
                "MaterialSpec {{ name: {:?}, properties: Material {{ density: {:?}, youngs_modulus: {:?}, poisson_ratio: {:?}, restitution: {:?}, friction_sliding: {:?}, friction_rolling: {:?}, friction_twisting: {:?}, viscosity: {:?}, cohesion: {:?} }} }}",
                m.name,
                p.density,
                p.youngs_modulus,
                p.poisson_ratio,
                p.restitution,
                p.friction_sliding,
                p.friction_rolling,
                p.friction_twisting,
                p.viscosity,
                p.cohesion
            )
        })
        .collect();
    let interactions: Vec<String> = (s.interactions.iter())
        .map(|i| {
            format!(
                "Interaction {{ materials: {:?}, restitution: {:?}, friction_sliding: {:?}, friction_rolling: {:?}, friction_twisting: {:?}, cohesion: {:?} }}",
                i.materials,
                i.restitution,
                i.friction_sliding,
                i.friction_rolling,
                i.friction_twisting,
                i.cohesion
            )
        })
        .collect();
    let mut text = format!("[{}]|[{}]", materials.join(", "), interactions.join(", "));
    let named = |given: GivenModels| -> String {
        (given.named().iter())
            .map(|(key, name)| format!(" {key}={name}"))
            .collect()
    };
    for (k, m) in s.materials.iter().enumerate() {
        let p = &m.properties;
        let beyond = named(beyond_defaults(p));
        if !beyond.is_empty() {
            text += &format!("|models of material {k}:{beyond}");
        }
        if p.surface_energy > 0.0 {
            text += &format!("|surface energy of material {k}: {:?}", p.surface_energy);
        }
        if p.liquid.wet() {
            text += &format!("|liquid of material {k}: {:?}", p.liquid);
        }
        if p.models.normal == NormalModel::Hooke {
            let (k_n, ratio) = (p.hooke_stiffness, p.hooke_stiffness_ratio);
            text += &format!("|hooke of material {k}: {k_n:?} {ratio:?}");
        }
    }
    for i in &s.interactions {
        let given = named(i.models);
        if !given.is_empty() {
            text += &format!("|models of {:?}:{given}", i.materials);
        }
        if let Some(gamma) = i.surface_energy {
            text += &format!("|surface energy of {:?}: {gamma:?}", i.materials);
        }
        if i.liquid != Default::default() {
            text += &format!("|liquid of {:?}: {:?}", i.materials, i.liquid);
        }
        if i.hooke_stiffness.is_some() || i.hooke_stiffness_ratio.is_some() {
            let (k_n, ratio) = (i.hooke_stiffness, i.hooke_stiffness_ratio);
            text += &format!("|hooke of {:?}: {k_n:?} {ratio:?}", i.materials);
        }
    }
    text
}

/// Writes a checkpoint atomically (temporary file, then rename), and then removes the parts
/// of an earlier one at `path` (see [`parts`]).
pub fn save(path: &Path, snapshot: &Snapshot, fingerprint: u64) -> Result<()> {
    crate::io::files::write_bytes_atomically(path, &encode(snapshot, fingerprint))
        .with_context(|| format!("cannot write checkpoint {}", path.display()))?;
    remove_parts(path, None);
    Ok(())
}

/// Reads a checkpoint, for the scenario and mesh of `fingerprint` if given: the file at
/// `path`, or the parts beside it if a stop wrote them later (see [`parts`]).
pub fn load(path: &Path, fingerprint: Option<u64>) -> Result<Snapshot> {
    if let Some(parts) = newer_parts(path) {
        return load_parts(&parts, fingerprint);
    }
    let bytes = crate::io::files::read(path).map_err(|e| {
        let lacking = parts::missing_parts(path).map_or(String::new(), |m| {
            format!(" (nor its parts of a split run: {m} missing)")
        });
        let why = match e.kind() {
            std::io::ErrorKind::NotFound => never_written(path),
            _ => String::new(),
        };
        anyhow::anyhow!(
            "cannot read checkpoint {}{lacking}: {e}{why}",
            path.display()
        )
    })?;
    decode(&bytes, fingerprint).with_context(|| format!("cannot resume from {}", path.display()))
}

/// Why a checkpoint that is not there may be missing, from what its directory holds.
fn never_written(path: &Path) -> String {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
    let dir = dir.unwrap_or(Path::new("."));
    let Ok(entries) = std::fs::read_dir(dir) else {
        return format!(". There is no directory {}", dir.display());
    };
    let frames = entries
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.starts_with("particles") && n.ends_with(".csv"))
        .max();
    match frames {
        Some(last) => format!(
            ". {} holds frames up to {last} but no checkpoint: the run ended before it wrote \
             one (a run writes its checkpoint every [output] checkpoint_minutes of wall time, \
             10 unless the scenario says otherwise, every checkpoint_every frames, on Ctrl-C or \
             SIGTERM and at its end; a kill -9 before the first leaves none). Start the run \
             again with --overwrite",
            dir.display()
        ),
        None => format!(". {} holds no frames of a run either", dir.display()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::records::bytes::encode_v6;
    use crate::engine::records::{Outflow, Removed, Wrench};
    use crate::engine::spawn::{RegionState, SpawnerState};
    use crate::model::contact_state::ContactState;
    use crate::model::particles::{Particle, Particles};
    use crate::model::springs::Springs;
    use glam::{DQuat, DVec3};

    pub(super) fn snapshot() -> Snapshot {
        let mut particles = Particles::default();
        particles.push(Particle {
            x: DVec3::new(0.1, 0.2, 0.3),
            radius: 0.004,
            v: DVec3::new(-1.0, 1e-300, 2.5),
            q: DQuat::from_rotation_y(0.7),
            w: DVec3::new(1.0, 2.0, 3.0),
            tag: 7,
            ..Default::default()
        });
        let springs = Springs {
            u_s: DVec3::new(1e-5, 2e-6, 0.0),
            u_r: DVec3::ZERO,
            u_t: -3e-7,
        };
        let s = ContactState {
            springs,
            ..ContactState::default()
        };
        particles.id = vec![3];
        particles.next_id = 5;
        Snapshot {
            contact_state: Default::default(),
            steps: 12345,
            built_at: 12300,
            particles,
            spawner: SpawnerState {
                word_pos: 987654321,
                pending_radius: Some(0.0042),
                regions: vec![
                    RegionState {
                        inserted: 7,
                        pending_radius: None,
                    },
                    RegionState {
                        inserted: 0,
                        pending_radius: Some(0.003),
                    },
                ],
                box_off: true,
            },
            anchors: vec![DVec3::new(0.1, 0.2, 0.2999)],
            lonely: vec![(0, 0.25)],
            pair_history: vec![(3, 4, s)],
            face_history: vec![(3, 3, s)],
            removed: Removed {
                outlets: vec![Outflow {
                    count: 3,
                    mass: 1.5e-4,
                }],
                domain: Outflow {
                    count: 1,
                    mass: 2e-5,
                },
            },
            wall_sums: vec![Wrench {
                f: DVec3::new(1.0, -2.0, 3.0),
                tau: DVec3::new(0.5, 0.25, -1e-9),
            }],
            wall_heat: Vec::new(),
            scenario: "[simulation]\nframes = 3\n".into(),
            mesh_files: vec![(0, 1), (12, 0xdead_beef)],
            servos: vec![(
                1,
                crate::model::servo::State {
                    position: 0.0125,
                    speed: -3e-4,
                    built: 0.0124,
                    load: 2.5,
                },
            )],
            ledger: None,
        }
    }

    /// The built-in hourglass as scenario `s` makes it.
    fn hourglass(s: &Scenario) -> crate::geometry::mesh::Mesh {
        crate::geometry::mesh::Mesh::parse_off(
            crate::scenario::HOURGLASS_OFF,
            "hourglass",
            &s.geometry.mesh_radii,
        )
        .unwrap()
        .with_contacts(s.geometry.mesh_contacts)
    }

    /// The fingerprint of the default scenario in the checkpoints of the build of
    /// 2026-12-02 (format 2, commit 40d4a3a).
    const FORMAT_2_DEFAULT: u64 = 3511474096700281170;

    #[test]
    fn the_fingerprint_of_the_default_scenario_is_that_of_format_2() {
        // As written by the build of 2026-12-02 (format 2), so its checkpoints resume in
        // the order of the springs they were made with (the paper's); in the default order
        // they are another scenario.
        let mut s = Scenario::default();
        s.simulation.friction_springs = crate::scenario::FrictionSprings::Paper;
        let mesh = hourglass(&s);
        assert_eq!(fingerprint(&s, &mesh), FORMAT_2_DEFAULT);
        let default = Scenario::default();
        assert_ne!(fingerprint(&default, &mesh), FORMAT_2_DEFAULT);
    }

    /// The fingerprint of a scenario of named materials in the checkpoints of commit
    /// 26f0eb7 (format 8, before the contact sub-models had keys).
    const FORMAT_8_MATERIALS: u64 = 15390153614767865885;

    #[test]
    fn the_fingerprint_of_named_materials_is_that_of_format_8() {
        let text = "[[materials]]\nname = \"glass\"\ncohesion = 200.0\n\
            [[materials]]\nname = \"steel\"\ndensity = 7800.0\n\
            [[interactions]]\nmaterials = [\"steel\", \"glass\"]\nfriction_sliding = 0.2\n\
            [geometry]\nmesh_material = \"steel\"\n";
        let of = |text: &str| {
            let s = Scenario::parse(text, Path::new("s.toml")).unwrap();
            fingerprint(&s, &hourglass(&s))
        };
        assert_eq!(of(text), FORMAT_8_MATERIALS);
        // The defaults named change nothing; a model beyond them is another scenario.
        let named = text.replace(
            "cohesion = 200.0",
            "cohesion = 200.0\nadhesion_model = \"sjkr\"",
        );
        assert_eq!(of(&named), FORMAT_8_MATERIALS);
        let dry_pair = format!(
            "{text}[[interactions]]\nmaterials = [\"glass\", \"glass\"]\nadhesion_model = \"none\"\n"
        );
        assert_ne!(of(&dry_pair), FORMAT_8_MATERIALS);
        let sticky_steel = text.replace(
            "density = 7800.0",
            "density = 7800.0\nadhesion_model = \"sjkr\"",
        );
        assert_ne!(of(&sticky_steel), FORMAT_8_MATERIALS);
    }

    #[test]
    fn round_trip_is_exact() {
        let mut s = snapshot();
        assert_eq!(decode(&encode(&s, 7), Some(7)).unwrap(), s);
        s.particles.fixed[0] = true;
        assert_eq!(decode(&encode(&s, 7), Some(7)).unwrap(), s);
        // Ids past 2^32 (a long run's), in the particles, the springs and the next id.
        let big = 5_000_000_000;
        s.particles.id[0] += big;
        s.particles.next_id += big;
        s.pair_history[0].0 += big;
        s.pair_history[0].1 += big;
        s.face_history[0].0 += big;
        assert_eq!(decode(&encode(&s, 7), Some(7)).unwrap(), s);
        // With heat transfer: the temperatures, contents and the heat into each mesh file.
        s.particles.activate("T");
        s.particles.activate("heat");
        (s.particles.temperature[0], s.particles.heat[0]) = (351.25, -(1 << 100) - 3);
        s.wall_heat = vec![1 << 90, -17];
        let bytes = encode(&s, 7);
        assert_eq!(u32::from_le_bytes(bytes[12..16].try_into().unwrap()), 9);
        assert_eq!(decode(&bytes, Some(7)).unwrap(), s);
        // Heat into walls for other mesh files than the checkpoint's: refused.
        s.wall_heat.push(1);
        let e = decode(&encode(&s, 7), Some(7)).unwrap_err();
        assert!(
            format!("{e:#}").contains("the heat of 3 mesh files, for 2 files"),
            "{e:#}"
        );
        // With the energy ledger (format 10), with and without heat transfer.
        s.wall_heat.pop();
        let mut words = [0i64; 24];
        (words[0], words[7], words[23]) = (-3, 1 << 60, 42);
        s.ledger = Some(crate::model::ledger::Kept {
            words,
            start: Some(1.25),
            stored_start: [1e-3, 2e-4, 0.0, -5e-6, 7.0],
        });
        let bytes = encode(&s, 7);
        assert_eq!(u32::from_le_bytes(bytes[12..16].try_into().unwrap()), 10);
        assert_eq!(decode(&bytes, Some(7)).unwrap(), s);
        s.wall_heat.clear();
        assert_eq!(decode(&encode(&s, 7), Some(7)).unwrap(), s);
    }

    /// A snapshot's bytes with format `version` for `bytes` of the newest format whose
    /// byte ranges `cut` (start, end) are left out.
    fn older(bytes: &[u8], version: u32, cut: &[(usize, usize)]) -> Vec<u8> {
        let body = &bytes[..bytes.len() - 4];
        let mut old = Vec::new();
        let mut from = 0;
        for &(start, end) in cut {
            old.extend_from_slice(&body[from..start]);
            from = end;
        }
        old.extend_from_slice(&body[from..]);
        old[12..16].copy_from_slice(&version.to_le_bytes());
        let crc = crc32fast::hash(&old);
        old.extend_from_slice(&crc.to_le_bytes());
        old
    }

    #[test]
    fn version_2_is_read() {
        // A version 2 file: no material per particle, nothing removed, no wall loads.
        let mut s = snapshot();
        (s.removed, s.wall_sums) = (Removed::default(), Vec::new());
        (s.scenario, s.mesh_files) = (String::new(), Vec::new());
        (s.spawner.regions, s.servos) = (Vec::new(), Vec::new());
        s.spawner.box_off = false;
        let v6 = encode_v6(&s, 7);
        let n = v6.len() - 4;
        // The one particle's record starts at byte 77 (after the header and the count); its
        // material and fixed flag are the last 3 of its 123 bytes; the counts of removals,
        // loads, scenario, mesh files, spawn regions, the spawn box's flag, servos and bodies
        // end the body.
        let v2 = older(&v6, 2, &[(77 + 120, 77 + 123), (n - 73, n)]);
        assert_eq!(decode(&v2, Some(7)).unwrap(), s);
    }

    #[test]
    fn versions_3_to_6_are_read() {
        let mut s = snapshot();
        let v6 = encode_v6(&s, 7);
        assert_eq!(decode(&v6, Some(7)).unwrap(), s, "format 6: ids of 4 bytes");
        let n = v6.len() - 4;
        // Format 5 has no bodies (their count ends format 6).
        let v5 = older(&v6, 5, &[(n - 8, n)]);
        assert_eq!(decode(&v5, Some(7)).unwrap(), s);
        // Format 4 has no fixed flag either (the last byte of the particle's record).
        let v4 = older(&v6, 4, &[(77 + 122, 77 + 123), (n - 8, n)]);
        assert_eq!(decode(&v4, Some(7)).unwrap(), s);
        // Format 3 ends before the spawn box's flag and the count of servos.
        (s.servos, s.spawner.box_off) = (Vec::new(), false);
        let v6 = encode_v6(&s, 7);
        let n = v6.len() - 4;
        let v3 = older(&v6, 3, &[(77 + 122, 77 + 123), (n - 17, n)]);
        assert_eq!(decode(&v3, Some(7)).unwrap(), s);
    }

    #[test]
    fn damage_is_refused() {
        let bytes = encode(&snapshot(), 7);
        let msg = |b: &[u8], f| format!("{:#}", decode(b, Some(f)).unwrap_err());
        assert!(msg(&bytes, 8).contains("different scenario"));
        assert!(msg(&bytes[..bytes.len() - 9], 7).contains("checksum"));
        let mut flipped = bytes.clone();
        flipped[40] ^= 1;
        assert!(msg(&flipped, 7).contains("checksum"));
        let mut version = bytes.clone();
        version[12] = 11;
        assert!(msg(&version, 7).contains("version 11"));
        version[12] = 1;
        assert!(msg(&version, 7).contains("version 1"));
        assert!(msg(b"hello world, not a checkpoint", 7).contains("not a tinydem checkpoint"));
        assert!(msg(b"", 7).contains("not a tinydem checkpoint"));
    }
}
