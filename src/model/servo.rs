//! Servo walls: a mesh part driven along a direction so that the particles' load on it
//! approaches a target force (an oedometer's lid, a triaxial cell's walls, a shear box's
//! normal load). Unlike the prescribed motions of `motion.rs`, its motion follows the run,
//! so its state is part of a checkpoint.
//!
//! The control law is proportional in velocity: after each step, with `F` the load of the
//! particles on the part resisting its `direction` (F = -f . d for the load f), the part
//! moves at
//!
//! ```text
//! v = clamp(gain (F_target - F), -max_speed, max_speed)
//! ```
//!
//! along `direction`, and its position follows with that speed (the speed first, then the
//! position, as the particles' semi-implicit Euler). It starts at rest; while no particle
//! touches it (no load at all), it approaches at `max_speed`.

use glam::DVec3;

use crate::model::motion::{Pose, RigidVelocity};

/// What a servo holds to: a force, or a stress over the part's area projected normal to
/// its direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Target {
    /// \[N\]
    Force(f64),
    /// \[Pa\]
    Stress(f64),
}

/// A servo as the scenario gives it (`motion = { type = "servo", ... }`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Servo {
    /// The unit vector the part moves along to press harder.
    pub direction: DVec3,
    pub target: Target,
    /// \[m/s\]
    pub max_speed: f64,
    /// \[m/(s N)\]; `None`: [`default_gain`].
    pub gain: Option<f64>,
}

/// A servo's control law, its target a force and its gain resolved (at setup, from the
/// part's area and the contact stiffness).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Control {
    pub direction: DVec3,
    /// \[N\]
    pub force: f64,
    pub max_speed: f64,
    pub gain: f64,
}

/// Where a servo is: its displacement along its direction from where the mesh put it, its
/// speed, its displacement at the last neighbour-list rebuild, and the load resisting it in
/// its last step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct State {
    pub position: f64,
    pub speed: f64,
    pub built: f64,
    pub load: f64,
}

impl Control {
    /// The load `f` of the particles on the part, as the force resisting its direction.
    #[inline]
    pub fn resisting(&self, f: DVec3) -> f64 {
        -f.dot(self.direction) + 0.0 // (no -0 when nothing touches it)
    }

    /// The state after a step of `dt` in which the particles' load on the part was `f`:
    /// touching nothing (no load at all), it approaches at `max_speed`.
    pub fn advance(&self, s: State, f: DVec3, dt: f64) -> State {
        let load = self.resisting(f);
        let speed = if f == DVec3::ZERO {
            self.max_speed
        } else {
            (self.gain * (self.force - load)).clamp(-self.max_speed, self.max_speed)
        };
        State {
            position: s.position + speed * dt,
            speed,
            built: s.built,
            load,
        }
    }

    /// The pose at displacement `position`.
    pub fn pose(&self, position: f64) -> Pose {
        Pose {
            shift: position * self.direction,
            ..Pose::REST
        }
    }

    /// The velocity field at speed `speed`.
    pub fn velocity(&self, speed: f64) -> RigidVelocity {
        RigidVelocity {
            v0: speed * self.direction,
            ..Default::default()
        }
    }
}

/// A gain for a step `dt` from the stiffness K of the layer of grains under the part at the
/// target: `area / (pi r^2)` grains of radius `r` (0.9 of the area covered), each carrying
/// its share of `force` by a Hertz contact with the wall (k = 3/2 F_c / delta, Eq. 12 with
/// R* = r and E* = `e_star`); the gain is 0.5 / (K dt). Measured (`tests/servo.rs`, 2026-12-06):
/// on a settled bed of 400 grains under a lid at 1 kPa the load overshoots from
/// K gain dt = 1 on and oscillates by 10 % at 4; under a lid at 1 kPa on a periodic layer
/// of 300 grains sheared at 3/s the frame means of the load deviate by 3 % at 0.2, by
/// 1.2 % at 0.5 (sd 0.6 %) and by 6 % at 2.5. The bed below the layer is softer (grains
/// in series, and rearranging): it slows the approach, it does not destabilise it.
pub fn default_gain(force: f64, area: f64, r: f64, e_star: f64, dt: f64) -> f64 {
    let grains = (0.9 * area / (std::f64::consts::PI * r * r)).max(1.0);
    let per_grain = force / grains;
    // Hertz with a wall: F = 4/3 E* sqrt(r) delta^(3/2).
    let delta = (3.0 * per_grain / (4.0 * e_star * r.sqrt())).powf(2.0 / 3.0);
    let stiffness = grains * 1.5 * per_grain / delta;
    0.5 / (stiffness * dt)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn control() -> Control {
        Control {
            direction: -DVec3::Z,
            force: 10.0,
            max_speed: 0.5,
            gain: 0.01,
        }
    }

    #[test]
    fn it_presses_on_below_the_target_and_backs_off_above_it() {
        let c = control();
        // The particles push the lid up (+z): the resisting force is f_z.
        let below = c.advance(State::default(), DVec3::new(0.0, 0.0, 4.0), 0.1);
        assert_eq!(below.speed, 0.01 * 6.0);
        assert!((below.position - 0.006).abs() < 1e-15);
        let above = c.advance(below, DVec3::new(0.0, 0.0, 30.0), 0.1);
        assert_eq!(above.speed, -0.2);
        // Never faster than max_speed, at which it comes while no particle touches it.
        let free = c.advance(State::default(), DVec3::ZERO, 0.1);
        assert_eq!(free.speed, 0.5);
        let far = Control { gain: 1.0, ..c }.advance(State::default(), DVec3::Z * 1e-3, 0.1);
        assert_eq!(far.speed, 0.5);
        assert_eq!(c.pose(0.3).point(DVec3::ZERO), DVec3::new(0.0, 0.0, -0.3));
        assert_eq!(c.velocity(2.0).at(DVec3::X), DVec3::new(0.0, 0.0, -2.0));
    }

    #[test]
    fn on_a_layer_of_hertz_contacts_the_default_gain_converges_without_overshoot() {
        // The layer the estimate assumes: 1 kPa on a 0.1 m square lid over grains of 5 mm,
        // E* = 1.1 MPa, dt = 1e-4 s; its stiffness is that of the linearised Hertz contacts.
        let (area, r, e_star, dt) = (0.01, 0.005, 1.1e6, 1e-4);
        let force = 1000.0 * area;
        let gain = default_gain(force, area, r, e_star, dt);
        let grains = 0.9 * area / (std::f64::consts::PI * r * r);
        let delta = (3.0 * force / grains / (4.0 * e_star * r.sqrt())).powf(2.0 / 3.0);
        let c = Control {
            direction: -DVec3::Z,
            force,
            max_speed: 0.01,
            gain,
        };
        // The grains' Hertz force on the lid at its displacement x (touching at x = 0, which
        // it approaches at max_speed).
        let load = |x: f64| grains * 4.0 / 3.0 * e_star * r.sqrt() * x.max(0.0).powf(1.5);
        let mut s = State::default();
        let mut most: f64 = 0.0;
        for step in 0..2000 {
            s = c.advance(s, DVec3::new(0.0, 0.0, load(s.position)), dt);
            most = most.max(load(s.position));
            if step == 1999 {
                assert!((load(s.position) - force).abs() < 1e-3 * force);
            }
        }
        assert!(most <= force * (1.0 + 1e-9), "overshoot to {most}");
        assert!((s.position - delta).abs() < 1e-3 * delta);
    }
}
