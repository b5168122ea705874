//! The loads of a step: each particle's force and torque, summed exactly, the scales of
//! their sums, and the loads on each mesh file (`[output] wall_forces`).

use super::*;

/// Force (components 0-2) and torque (3-5) on one particle, summed over its contacts during
/// a step (Eqs. 1-2), exactly (`exact.rs`): the same bits in whatever order the contacts add
/// to it.
pub(super) type Load = Sum6;

/// The resolutions of the force and torque sums, from the largest force and torque the
/// scenario's materials and radii can produce (see [`LoadScales::of`]).
#[derive(Clone, Copy, Debug)]
pub struct LoadScales {
    pub force: Scale,
    pub torque: Scale,
    /// Of a load's components.
    pub(super) lanes: Scales8,
}

impl LoadScales {
    /// The largest radius the scenario's particles can have.
    pub(super) fn largest_radius(s: &Scenario) -> f64 {
        let mut r_max = s.geometry.radius_max;
        for region in &s.spawn {
            r_max = r_max.max(region.radius.largest());
        }
        r_max
    }

    /// Room above the largest total load of one step on a wall: 2^20 contacts of the
    /// largest force (far more than the grains' weight); torques with the lever `lever`.
    const WALL_ROOM: f64 = 1048576.0;

    /// The scales of a step's loads on the walls, for torques about points at most `lever`
    /// from the particles.
    pub(super) fn walls(&self, lever: f64) -> Scales8 {
        let largest = LoadScales::WALL_ROOM * self.force.largest();
        let (force, torque) = (
            Scale::for_largest(largest),
            Scale::for_largest((largest * lever).max(f64::MIN_POSITIVE)),
        );
        Scales8::new([force, force, force, torque, torque, torque, force, force])
    }

    /// Room above the largest force of a contact, E* R_max^2 (Hertz at an overlap of R_max,
    /// Hooke's k_n R_max, or the cohesion k_c pi R_max^2): 2^12, which also holds particles up to 64 R_max.
    const ROOM: f64 = 4096.0;

    /// The scales of a scenario: from its parameters only (not from the particles of the
    /// moment), so that a resumed run and every process of a run use the same ones.
    pub fn of(s: &Scenario) -> LoadScales {
        let r_max = LoadScales::largest_radius(s);
        let mut stiffest: f64 = 0.0;
        let bridge = |tension: f64| 4.0 * std::f64::consts::PI * tension / r_max;
        for m in &s.materials {
            let m = &m.properties;
            let e_star = m.youngs_modulus / (1.0 - m.poisson_ratio * m.poisson_ratio);
            stiffest = stiffest.max(e_star).max(std::f64::consts::PI * m.cohesion);
            // Hooke: k_n R_max at an overlap of R_max.
            stiffest = stiffest.max(m.hooke_stiffness / r_max);
            // DMT: 2 pi gamma R_max (JKR's pull-off force is less).
            stiffest = stiffest.max(2.0 * std::f64::consts::PI * m.surface_energy / r_max);
            // A liquid bridge: 4 pi gamma_l R_max.
            stiffest = stiffest.max(bridge(m.liquid.surface_tension));
        }
        for i in &s.interactions {
            stiffest = stiffest.max(std::f64::consts::PI * i.cohesion.unwrap_or(0.0));
            stiffest = stiffest.max(i.hooke_stiffness.unwrap_or(0.0) / r_max);
            let gamma = i.surface_energy.unwrap_or(0.0);
            stiffest = stiffest.max(2.0 * std::f64::consts::PI * gamma / r_max);
            stiffest = stiffest.max(bridge(i.liquid.surface_tension.unwrap_or(0.0)));
        }
        let largest = (LoadScales::ROOM * stiffest * r_max * r_max).max(f64::MIN_POSITIVE);
        let (force, torque) = (
            Scale::for_largest(largest),
            Scale::for_largest((largest * r_max).max(f64::MIN_POSITIVE)),
        );
        LoadScales {
            force,
            torque,
            lanes: Scales8::new([force, force, force, torque, torque, torque, force, force]),
        }
    }
}

impl Simulation {
    /// Starts summing the loads (and the heat) on each mesh file (`take_wall_loads`), for `walls.csv` or
    /// for the servos, which follow the load on their file.
    pub(super) fn sum_wall_loads(&mut self) {
        let w = &mut self.walls;
        w.face_file = vec![0; w.mesh.faces.len()];
        for (k, file) in w.files.iter().enumerate() {
            w.face_file[file.faces.clone()].fill(k as u32);
        }
        w.heat = vec![0; w.files.len()];
        let servos = self.scenario.meshes.iter().any(|m| m.servo.is_some());
        if !(self.scenario.wall_forces || servos) {
            return;
        }
        w.sums = vec![Wrench::default(); w.files.len()];
        // The lever of a torque about a file's point: to its farthest corner, or across the
        // domain, and a particle's radius; 16 times that, for meshes that move.
        let mut lever: f64 = 0.0;
        for file in &w.files {
            for face in &w.rest_faces[file.faces.clone()] {
                for c in face.corners() {
                    lever = lever.max(c.distance(file.torque_about) + face.radius);
                }
            }
        }
        if let Some(d) = self.scenario.domain {
            lever = lever.max((d.max - d.min).length());
        }
        lever = 16.0 * (lever + LoadScales::largest_radius(&self.scenario));
        w.scales = self.model.scales.walls(lever);
    }

    /// The loads on each mesh file summed over the steps since the last call, and the
    /// sums set back to zero (empty unless `[output] wall_forces`).
    pub fn take_wall_loads(&mut self) -> Vec<Wrench> {
        self.walls.take_loads()
    }
}
