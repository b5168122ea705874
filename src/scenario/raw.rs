//! The file format: the serde types of a scenario file as written, every key optional,
//! unknown keys rejected. `validate.rs` makes a [`Scenario`](super::Scenario) of them.

use std::path::PathBuf;

use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMesh {
    pub(super) file: Option<PathBuf>,
    pub(super) shape: Option<RawShape>,
    pub(super) radii: Option<Vec<f64>>,
    pub(super) contacts: Option<String>,
    pub(super) material: Option<String>,
    pub(super) motion: Option<RawMotion>,
    pub(super) temperature: Option<f64>,
}

/// `[[meshes]] shape = { type = ... }`: a built-in shape (`geometry/shapes.rs`).
#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub(super) enum RawShape {
    Box {
        min: [f64; 3],
        max: [f64; 3],
        open: Option<Vec<String>>,
    },
    Cylinder {
        center: [f64; 3],
        axis: [f64; 3],
        radius: f64,
        height: f64,
        open: Option<Vec<String>>,
        orifice: Option<f64>,
        resolution: Option<i64>,
    },
    Drum {
        center: [f64; 3],
        axis: [f64; 3],
        radius: f64,
        length: f64,
        resolution: Option<i64>,
    },
    Plane {
        point: [f64; 3],
        normal: [f64; 3],
        size: f64,
    },
    Hopper {
        center: [f64; 3],
        axis: [f64; 3],
        top_radius: f64,
        outlet_radius: f64,
        height: f64,
        resolution: Option<i64>,
    },
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub(super) enum RawMotion {
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
    Servo {
        direction: [f64; 3],
        force: Option<f64>,
        stress: Option<f64>,
        max_speed: f64,
        gain: Option<f64>,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawTag {
    pub(super) min: [f64; 3],
    pub(super) max: [f64; 3],
    pub(super) tag: u32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSpawn {
    pub(super) min: [f64; 3],
    pub(super) max: [f64; 3],
    pub(super) material: Option<String>,
    pub(super) velocity: Option<[f64; 3]>,
    pub(super) count: Option<u64>,
    pub(super) volume_fraction: Option<f64>,
    pub(super) rate: Option<f64>,
    pub(super) start: Option<f64>,
    pub(super) stop: Option<f64>,
    pub(super) radius: Option<RawRadius>,
    pub(super) clump: Option<String>,
    pub(super) scale: Option<RawScale>,
    pub(super) temperature: Option<f64>,
}

/// A `[[spawn]]` region's `scale` of its clumps: a factor, or uniform in `min`..`max`.
#[derive(Deserialize)]
#[serde(untagged, deny_unknown_fields)]
pub(super) enum RawScale {
    Factor(f64),
    Uniform { min: f64, max: f64 },
}

#[derive(Deserialize)]
#[serde(tag = "distribution", rename_all = "lowercase", deny_unknown_fields)]
pub(super) enum RawRadius {
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
pub(super) struct RawDomain {
    pub(super) min: [f64; 3],
    pub(super) max: [f64; 3],
    pub(super) periodic: Option<[bool; 3]>,
    pub(super) lees_edwards: Option<RawShear>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawShear {
    pub(super) velocity: f64,
    pub(super) shear_axis: String,
    pub(super) gradient_axis: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBox {
    pub(super) min: [f64; 3],
    pub(super) max: [f64; 3],
}

/// `[[clumps]]`: a template of rigidly joined spheres.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawClump {
    pub(super) name: String,
    pub(super) spheres: Option<Vec<[f64; 4]>>,
    pub(super) file: Option<PathBuf>,
    pub(super) material: Option<String>,
    pub(super) mass: Option<f64>,
    pub(super) inertia: Option<[f64; 3]>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawScenario {
    #[serde(default)]
    pub(super) meshes: Vec<RawMesh>,
    #[serde(default)]
    pub(super) materials: Vec<RawNamedMaterial>,
    #[serde(default)]
    pub(super) interactions: Vec<RawInteraction>,
    #[serde(default)]
    pub(super) tags: Vec<RawTag>,
    pub(super) domain: Option<RawDomain>,
    #[serde(default)]
    pub(super) outlets: Vec<RawBox>,
    #[serde(default)]
    pub(super) fixed: Vec<RawBox>,
    #[serde(default)]
    pub(super) spawn: Vec<RawSpawn>,
    #[serde(default)]
    pub(super) clumps: Vec<RawClump>,
    #[serde(default)]
    pub(super) geometry: RawGeometry,
    #[serde(default)]
    pub(super) material: RawMaterial,
    #[serde(default)]
    pub(super) kinetics: RawKinetics,
    #[serde(default)]
    pub(super) simulation: RawSimulation,
    #[serde(default)]
    pub(super) input: RawInput,
    #[serde(default)]
    pub(super) output: RawOutput,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawGeometry {
    pub(super) radius_min: Option<f64>,
    pub(super) radius_max: Option<f64>,
    pub(super) mesh: Option<PathBuf>,
    pub(super) mesh_radii: Option<Vec<f64>>,
    pub(super) mesh_contacts: Option<String>,
    pub(super) mesh_material: Option<String>,
    pub(super) spawn_min: Option<[f64; 3]>,
    pub(super) spawn_max: Option<[f64; 3]>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMaterial {
    pub(super) cohesion: Option<f64>,
    pub(super) surface_energy: Option<f64>,
    pub(super) liquid_volume: Option<f64>,
    pub(super) surface_tension: Option<f64>,
    pub(super) contact_angle: Option<f64>,
    pub(super) hooke_stiffness: Option<f64>,
    pub(super) hooke_stiffness_ratio: Option<f64>,
    pub(super) normal_model: Option<String>,
    pub(super) adhesion_model: Option<String>,
    pub(super) rolling_model: Option<String>,
    pub(super) tangential_coulomb: Option<String>,
    pub(super) density: Option<f64>,
    pub(super) youngs_modulus: Option<f64>,
    pub(super) poisson_ratio: Option<f64>,
    pub(super) restitution: Option<f64>,
    pub(super) friction_sliding: Option<f64>,
    pub(super) friction_rolling: Option<f64>,
    pub(super) friction_twisting: Option<f64>,
    pub(super) viscosity: Option<f64>,
    pub(super) thermal_conductivity: Option<f64>,
    pub(super) heat_capacity: Option<f64>,
    pub(super) initial_temperature: Option<f64>,
    pub(super) heat_source: Option<f64>,
    pub(super) surface_heat_transfer: Option<f64>,
}

impl RawMaterial {
    /// Whether it sets a property of the particles (anything but the fluid's viscosity).
    pub(super) fn has_particle_keys(&self) -> bool {
        self.density.is_some()
            || self.youngs_modulus.is_some()
            || self.poisson_ratio.is_some()
            || self.restitution.is_some()
            || self.friction_sliding.is_some()
            || self.friction_rolling.is_some()
            || self.friction_twisting.is_some()
            || self.cohesion.is_some()
            || self.surface_energy.is_some()
            || self.liquid_volume.is_some()
            || self.surface_tension.is_some()
            || self.contact_angle.is_some()
            || self.hooke_stiffness.is_some()
            || self.hooke_stiffness_ratio.is_some()
            || self.normal_model.is_some()
            || self.adhesion_model.is_some()
            || self.rolling_model.is_some()
            || self.tangential_coulomb.is_some()
            || self.has_thermal_keys()
    }

    /// Whether it sets a thermal property.
    pub(super) fn has_thermal_keys(&self) -> bool {
        self.thermal_conductivity.is_some()
            || self.heat_capacity.is_some()
            || self.initial_temperature.is_some()
            || self.heat_source.is_some()
            || self.surface_heat_transfer.is_some()
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawNamedMaterial {
    pub(super) name: String,
    pub(super) cohesion: Option<f64>,
    pub(super) surface_energy: Option<f64>,
    pub(super) liquid_volume: Option<f64>,
    pub(super) surface_tension: Option<f64>,
    pub(super) contact_angle: Option<f64>,
    pub(super) hooke_stiffness: Option<f64>,
    pub(super) hooke_stiffness_ratio: Option<f64>,
    pub(super) normal_model: Option<String>,
    pub(super) adhesion_model: Option<String>,
    pub(super) rolling_model: Option<String>,
    pub(super) tangential_coulomb: Option<String>,
    pub(super) density: Option<f64>,
    pub(super) youngs_modulus: Option<f64>,
    pub(super) poisson_ratio: Option<f64>,
    pub(super) restitution: Option<f64>,
    pub(super) friction_sliding: Option<f64>,
    pub(super) friction_rolling: Option<f64>,
    pub(super) friction_twisting: Option<f64>,
    pub(super) thermal_conductivity: Option<f64>,
    pub(super) heat_capacity: Option<f64>,
    pub(super) initial_temperature: Option<f64>,
    pub(super) heat_source: Option<f64>,
    pub(super) surface_heat_transfer: Option<f64>,
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
            surface_energy: m.surface_energy,
            liquid_volume: m.liquid_volume,
            surface_tension: m.surface_tension,
            contact_angle: m.contact_angle,
            hooke_stiffness: m.hooke_stiffness,
            hooke_stiffness_ratio: m.hooke_stiffness_ratio,
            normal_model: m.normal_model,
            adhesion_model: m.adhesion_model,
            rolling_model: m.rolling_model,
            tangential_coulomb: m.tangential_coulomb,
            thermal_conductivity: m.thermal_conductivity,
            heat_capacity: m.heat_capacity,
            initial_temperature: m.initial_temperature,
            heat_source: m.heat_source,
            surface_heat_transfer: m.surface_heat_transfer,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawInteraction {
    pub(super) materials: [String; 2],
    pub(super) cohesion: Option<f64>,
    pub(super) surface_energy: Option<f64>,
    pub(super) liquid_volume: Option<f64>,
    pub(super) surface_tension: Option<f64>,
    pub(super) contact_angle: Option<f64>,
    pub(super) hooke_stiffness: Option<f64>,
    pub(super) hooke_stiffness_ratio: Option<f64>,
    pub(super) normal_model: Option<String>,
    pub(super) adhesion_model: Option<String>,
    pub(super) rolling_model: Option<String>,
    pub(super) tangential_coulomb: Option<String>,
    pub(super) restitution: Option<f64>,
    pub(super) friction_sliding: Option<f64>,
    pub(super) friction_rolling: Option<f64>,
    pub(super) friction_twisting: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawKinetics {
    pub(super) initial_velocity: Option<[f64; 3]>,
    pub(super) initial_angular_velocity: Option<[f64; 3]>,
    pub(super) gravity: Option<[f64; 3]>,
    pub(super) ambient_temperature: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSimulation {
    pub(super) timestep: Option<f64>,
    pub(super) max_particles: Option<u64>,
    pub(super) frames: Option<u64>,
    pub(super) steps_per_frame: Option<u64>,
    pub(super) spawn_attempts: Option<u64>,
    pub(super) seed: Option<u64>,
    pub(super) skin: Option<f64>,
    pub(super) friction_springs: Option<String>,
    pub(super) thermal_time_scale: Option<f64>,
    pub(super) conduction_model: Option<String>,
    pub(super) until: Option<RawUntil>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawUntil {
    pub(super) kinetic_energy_below: Option<f64>,
    pub(super) time: Option<f64>,
    pub(super) removed_at_least: Option<u64>,
    pub(super) servo_within: Option<f64>,
    pub(super) combine: Option<String>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawInput {
    pub(super) particles: Option<PathBuf>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawOutput {
    pub(super) dir: Option<PathBuf>,
    pub(super) checkpoint_every: Option<u64>,
    pub(super) checkpoint_minutes: Option<f64>,
    pub(super) formats: Option<Vec<String>>,
    pub(super) wall_forces: Option<bool>,
    pub(super) energy_ledger: Option<bool>,
    pub(super) contacts: Option<bool>,
    pub(super) forces: Option<bool>,
    pub(super) gather: Option<String>,
}
