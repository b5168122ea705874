//! Prescribed rigid motions of mesh parts (vibrated beds, conveyor plates, drums): harmonic
//! translation, constant velocity, and rotation about an axis. The motion is a function of
//! time only, so a checkpoint needs no extra state to resume it.

use glam::{DQuat, DVec3};

/// A prescribed motion of a mesh part, relative to its position in the mesh file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Motion {
    /// Displacement A sin(2π f t + φ) along the unit vector `direction`.
    Harmonic {
        amplitude: f64,
        frequency: f64,
        direction: DVec3,
        phase: f64,
    },
    /// Displacement `velocity` t.
    Velocity { velocity: DVec3 },
    /// Rotation by `angular_velocity` t about the unit `axis` through `center` (right hand).
    Rotation {
        center: DVec3,
        axis: DVec3,
        angular_velocity: f64,
    },
}

/// Where a moving part is at one instant: p ↦ rotation (p - center) + center + shift.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    pub rotation: DQuat,
    pub center: DVec3,
    pub shift: DVec3,
}

impl Pose {
    pub const REST: Pose = Pose {
        rotation: DQuat::IDENTITY,
        center: DVec3::ZERO,
        shift: DVec3::ZERO,
    };

    #[inline]
    pub fn point(&self, p: DVec3) -> DVec3 {
        self.rotation * (p - self.center) + self.center + self.shift
    }

    #[inline]
    pub fn vector(&self, v: DVec3) -> DVec3 {
        self.rotation * v
    }
}

/// The rigid velocity field of a part at one instant: v(p) = v0 + Ω × (p - origin).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct RigidVelocity {
    pub v0: DVec3,
    pub origin: DVec3,
    pub omega: DVec3,
}

impl RigidVelocity {
    #[inline]
    pub fn at(&self, p: DVec3) -> DVec3 {
        self.v0 + self.omega.cross(p - self.origin)
    }
}

impl Motion {
    /// The pose at time `t`.
    pub fn pose(&self, t: f64) -> Pose {
        match *self {
            Motion::Harmonic {
                amplitude,
                frequency,
                direction,
                phase,
            } => Pose {
                shift: amplitude
                    * (2.0 * std::f64::consts::PI * frequency * t + phase).sin()
                    * direction,
                ..Pose::REST
            },
            Motion::Velocity { velocity } => Pose {
                shift: velocity * t,
                ..Pose::REST
            },
            Motion::Rotation {
                center,
                axis,
                angular_velocity,
            } => Pose {
                rotation: DQuat::from_axis_angle(axis, angular_velocity * t),
                center,
                shift: DVec3::ZERO,
            },
        }
    }

    /// The velocity field at time `t`.
    pub fn velocity(&self, t: f64) -> RigidVelocity {
        match *self {
            Motion::Harmonic {
                amplitude,
                frequency,
                direction,
                phase,
            } => {
                let omega = 2.0 * std::f64::consts::PI * frequency;
                RigidVelocity {
                    v0: amplitude * omega * (omega * t + phase).cos() * direction,
                    ..Default::default()
                }
            }
            Motion::Velocity { velocity } => RigidVelocity {
                v0: velocity,
                ..Default::default()
            },
            Motion::Rotation {
                center,
                axis,
                angular_velocity,
            } => RigidVelocity {
                v0: DVec3::ZERO,
                origin: center,
                omega: angular_velocity * axis,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn velocity_is_the_time_derivative_of_the_pose() {
        let motions = [
            Motion::Harmonic {
                amplitude: 0.01,
                frequency: 3.0,
                direction: DVec3::Z,
                phase: 0.4,
            },
            Motion::Velocity {
                velocity: DVec3::new(0.1, -0.2, 0.3),
            },
            Motion::Rotation {
                center: DVec3::new(0.1, 0.0, 0.2),
                axis: DVec3::Y,
                angular_velocity: 2.5,
            },
        ];
        let p = DVec3::new(0.3, -0.1, 0.05);
        for m in motions {
            for t in [0.0, 0.1, 0.77] {
                let h = 1e-6;
                let numeric = (m.pose(t + h).point(p) - m.pose(t - h).point(p)) / (2.0 * h);
                let at = m.pose(t).point(p);
                let analytic = m.velocity(t).at(at);
                assert!(
                    (numeric - analytic).length() < 1e-7,
                    "{m:?} t={t}: {numeric} vs {analytic}"
                );
            }
        }
    }
}
