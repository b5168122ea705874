//! The energy ledger (`[output] energy_ledger`): where the energy of a run goes.
//!
//! The semi-implicit Euler of Eqs. (45)-(49) moves a sphere by v' = v + Δt F/m, so its
//! kinetic energy changes by exactly ½ m (v'² - v²) = Δt F·(v + v')/2: the work of the
//! step's forces at the mean of the velocities before and after (likewise the torque's at
//! the mean angular velocity). Each contact's force and torques are split by mode
//! ([`ContactParts`]) and each part's work is taken with the two bodies' mean velocities
//! at the contact point the law used: the parts add up to the work on both bodies, so the
//! modes' work, gravity's and the walls' account for every change of kinetic energy.
//!
//! A mode's energy either sits in its contacts (the elastic overlap, the springs, the
//! adhesion: `ContactLaw::stored`, a function of the state) or is gone: what a mode
//! dissipated is the work done against it less what it holds now. The residual
//! kinetic + stored + dissipated - work - (kinetic + stored at the start) is then zero
//! but for what the ledger misses (a force it does not know of, a contact counted twice)
//! and the rounding: it checks the bookkeeping, not the physics. The physics is in the
//! split: a head-on impact with restitution e dissipates (1 - e²) of its energy in the
//! normal mode, and nothing else.
//!
//! The work of each step is summed exactly (`exact.rs`), so the ledger gives the same bits
//! for any number of threads or processes and any storage order.

use glam::DVec3;
use wide::f64x8;

use crate::model::contact::ContactParts;
use crate::model::exact::{Scale, Scales8, Sum6};

/// The contact modes of the ledger, in the order of its sums and of `log.csv`.
pub const MODES: [&str; 5] = ["normal", "sliding", "rolling", "twisting", "adhesion"];

/// The partner of an [`Entry`] that is a wall.
pub const WALL: u32 = u32::MAX;

/// One contact of one step as the contact stages leave it for the ledger: the bodies,
/// where the law took the contact point, and the force and torques by mode.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    /// Body i's storage index, and body j's (or [`WALL`]).
    pub i: u32,
    pub j: u32,
    /// n̂, from j to i, and the distances of the contact point from the centres (r_j = 0
    /// for a wall).
    pub n: DVec3,
    pub r_i: f64,
    pub r_j: f64,
    /// The motion of the frame body j is seen in: a wall's material velocity at the
    /// contact point and its angular velocity; the velocity of a periodic image across a
    /// sheared side relative to its particle.
    pub frame_v: DVec3,
    pub frame_w: DVec3,
    pub parts: ContactParts,
}

/// The motion of a body over a step: the means of its velocities before and after.
#[derive(Clone, Copy, Debug, Default)]
pub struct Mean {
    pub v: DVec3,
    pub w: DVec3,
}

impl Entry {
    /// The work on the two bodies over the step `dt` by each mode of [`MODES`], and the
    /// work of the frame (a wall's motion, a sheared side): components 0-5 of the result.
    pub fn work(&self, i: Mean, j: Mean, dt: f64) -> f64x8 {
        let ContactParts {
            f_normal,
            pull,
            f_s,
            tau_r,
            tau_t,
        } = self.parts;
        // The relative velocity of the material points at the contact (Eq. 26) and the
        // relative angular velocity (Eq. 38), i against j in its frame.
        let v = i.v - j.v - self.frame_v + self.n.cross(i.w * self.r_i + j.w * self.r_j);
        let w = i.w - j.w - self.frame_w;
        let v_n = self.n.dot(v);
        let f = self.n * (f_normal - pull) + f_s;
        let frame = f.dot(self.frame_v) + (tau_r + tau_t).dot(self.frame_w);
        f64x8::from([
            f_normal * v_n * dt,
            f_s.dot(v) * dt,
            tau_r.dot(w) * dt,
            tau_t.dot(w) * dt,
            -pull * v_n * dt,
            frame * dt,
            0.0,
            0.0,
        ])
    }
}

/// What the ledger adds up over a run, exactly: the work of each contact mode and of the
/// walls, of gravity and of the fluid's drag, the kinetic energy brought by spawning and
/// taken by removal.
#[derive(Clone, Copy, Debug)]
pub struct Ledger {
    scales: Scales8,
    /// Components: the modes of [`MODES`], then the walls.
    contacts: Sum6,
    /// Components: gravity, drag, spawned, removed.
    particles: Sum6,
    /// The kinetic and stored energy when the ledger started (at the first frame).
    pub start: Option<f64>,
    /// The stored energy of each mode then.
    pub stored_start: [f64; 5],
}

/// Terms per partial sum before it is merged (a low word takes 2048 terms).
pub const CHUNK: usize = 2048;

impl Ledger {
    /// A ledger whose terms are at most `largest` \[J\]; sums hold 2^11 times that.
    pub fn new(largest: f64) -> Ledger {
        Ledger {
            scales: Scales8::new([Scale::for_largest(largest); 8]),
            contacts: Sum6::default(),
            particles: Sum6::default(),
            start: None,
            stored_start: [0.0; 5],
        }
    }

    /// The exact sum of the contacts' works `terms` (up to [`CHUNK`] of them), and whether
    /// each was in range.
    pub fn sum(&self, terms: impl Iterator<Item = f64x8>) -> (Sum6, bool) {
        let (mut sum, mut fine) = (Sum6::default(), true);
        for t in terms {
            fine &= sum.add(t, &self.scales);
        }
        sum.carry();
        (sum, fine)
    }

    /// Adds a step's sums of the contacts' works.
    pub fn add_contacts(&mut self, step: &Sum6) {
        self.contacts.merge(step);
    }

    /// Adds a step's sums of gravity's and the drag's work, or of the energy spawned and
    /// removed.
    pub fn add_particles(&mut self, step: &Sum6) {
        self.particles.merge(step);
    }

    /// The work of the modes and of the walls \[J\] (0-5), then of gravity and the drag,
    /// the energy spawned and the energy removed (6-9).
    pub fn totals(&self) -> [f64; 10] {
        let (c, p) = (
            self.contacts.value(&self.scales),
            self.particles.value(&self.scales),
        );
        [c[0], c[1], c[2], c[3], c[4], c[5], p[0], p[1], p[2], p[3]]
    }

    /// The value of a sum of this ledger's scales given by its integers `words` (summed
    /// over processes, say).
    pub fn value(&self, words: &[i64]) -> [f64; 6] {
        let mut sum = Sum6::from_words(words.try_into().expect("12 words"));
        sum.carry();
        sum.value(&self.scales)
    }

    /// The integers of the sums (to add them over processes, or to keep them).
    pub fn words(&self) -> [i64; 24] {
        let mut w = [0; 24];
        w[..12].copy_from_slice(&self.contacts.words());
        w[12..].copy_from_slice(&self.particles.words());
        w
    }

    /// The ledger with the sums `words` (of [`Ledger::words`]).
    pub fn with_words(mut self, words: &[i64]) -> Ledger {
        let part = |k: usize| -> [i64; 12] { words[k..k + 12].try_into().expect("12 words") };
        self.contacts = Sum6::from_words(part(0));
        self.particles = Sum6::from_words(part(12));
        self.contacts.carry();
        self.particles.carry();
        self
    }
}

/// What a checkpoint keeps of a ledger: its sums' integers, and where it started.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Kept {
    pub words: [i64; 24],
    pub start: Option<f64>,
    pub stored_start: [f64; 5],
}

impl Ledger {
    /// What a checkpoint keeps of it.
    pub fn kept(&self) -> Kept {
        Kept {
            words: self.words(),
            start: self.start,
            stored_start: self.stored_start,
        }
    }

    /// The ledger continued from `kept`.
    pub fn with_kept(self, kept: &Kept) -> Ledger {
        Ledger {
            start: kept.start,
            stored_start: kept.stored_start,
            ..self.with_words(&kept.words)
        }
    }
}

/// A ledger's columns of `log.csv` at one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Balance {
    pub work_gravity: f64,
    pub work_walls: f64,
    /// The energy the contacts hold (elastic overlap, springs, adhesion).
    pub stored_elastic: f64,
    /// What each mode of [`MODES`] dissipated, and the fluid's drag.
    pub dissipated: [f64; 5],
    pub dissipated_drag: f64,
    /// Kinetic energy brought by spawned particles and taken by removed ones.
    pub spawned: f64,
    pub removed: f64,
    /// kinetic + stored + dissipated - work - spawned + removed - (the same at the start).
    pub residual: f64,
}

/// The names of [`Balance`]'s columns in `log.csv`, in order.
pub const COLUMNS: [&str; 12] = [
    "work_gravity",
    "work_walls",
    "stored_elastic",
    "dissipated_normal",
    "dissipated_sliding",
    "dissipated_rolling",
    "dissipated_twisting",
    "dissipated_adhesion",
    "dissipated_drag",
    "energy_spawned",
    "energy_removed",
    "energy_residual",
];

impl Balance {
    /// The balance of `ledger` (its sums over all processes) with the kinetic energy
    /// `kinetic` and each mode's stored energy `stored` now.
    pub fn of(ledger: &Ledger, kinetic: f64, stored: [f64; 5]) -> Balance {
        let start = ledger.start.unwrap_or_default();
        let t = ledger.totals();
        // Energy a mode took from the bodies, less what it still holds (+ 0: no -0 in the
        // logs).
        let dissipated: [f64; 5] =
            std::array::from_fn(|m| -t[m] - (stored[m] - ledger.stored_start[m]) + 0.0);
        let stored_elastic = stored.iter().sum::<f64>();
        let [work_walls, work_gravity, drag, spawned, removed] = [t[5], t[6], t[7], t[8], t[9]];
        Balance {
            work_gravity,
            work_walls,
            stored_elastic,
            dissipated,
            dissipated_drag: -drag + 0.0,
            spawned,
            removed,
            residual: kinetic + stored_elastic + dissipated.iter().sum::<f64>()
                - drag
                - work_gravity
                - work_walls
                - spawned
                + removed
                - start,
        }
    }

    /// The values of [`COLUMNS`].
    pub fn columns(&self) -> [f64; 12] {
        let d = self.dissipated;
        [
            self.work_gravity,
            self.work_walls,
            self.stored_elastic,
            d[0],
            d[1],
            d[2],
            d[3],
            d[4],
            self.dissipated_drag,
            self.spawned,
            self.removed,
            self.residual,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The modes' work on two bodies adds up to the work of the force and torques the law
    /// gives them (Eqs. 56-60), at any velocities.
    #[test]
    fn modes_add_up_to_the_work_on_both_bodies() {
        let n = DVec3::new(0.3, -0.4, 0.5).normalize();
        let (r_i, r_j) = (0.004, 0.0025);
        let f_s = DVec3::new(1.0, 2.0, -0.7).reject_from(n) * 0.1;
        let parts = ContactParts {
            f_normal: 3.5,
            pull: 0.25,
            f_s,
            tau_r: DVec3::new(0.01, -0.02, 0.005),
            tau_t: n * 0.003,
        };
        let e = Entry {
            i: 0,
            j: 1,
            n,
            r_i,
            r_j,
            frame_v: DVec3::new(0.0, 0.2, 0.0),
            frame_w: DVec3::ZERO,
            parts,
        };
        let i = Mean {
            v: DVec3::new(0.3, -1.0, 0.2),
            w: DVec3::new(5.0, 1.0, -3.0),
        };
        let j = Mean {
            v: DVec3::new(-0.1, 0.4, 0.9),
            w: DVec3::new(-2.0, 7.0, 1.0),
        };
        let dt = 1e-5;
        let w = e.work(i, j, dt).to_array();
        // The law's force on i, its torques on i and j (Eqs. 31, 56-60).
        let f = n * (parts.f_normal - parts.pull) + f_s;
        let tau_s = f_s.cross(n) * r_i;
        let tau_i = tau_s + parts.tau_r + parts.tau_t;
        let tau_j = tau_s * (r_j / r_i) - parts.tau_r - parts.tau_t;
        let on_bodies = (f.dot(i.v) + tau_i.dot(i.w) - f.dot(j.v) + tau_j.dot(j.w)) * dt;
        let modes: f64 = w[..5].iter().sum();
        assert!(
            ((modes + w[5]) - on_bodies).abs() < 1e-15 * on_bodies.abs().max(1e-6),
            "{modes} + {} vs {on_bodies}",
            w[5]
        );
        // The frame's share is its velocity's work: -f·frame_v is what the modes miss.
        assert!((w[5] - f.dot(e.frame_v) * dt).abs() < 1e-18);
    }

    /// The exact sums give the same bits in any order, and back from their words.
    #[test]
    fn sums_are_exact_in_any_order() {
        let mut a = Ledger::new(1.0);
        let terms: Vec<f64x8> = (0..100)
            .map(|k| f64x8::splat((k as f64 * 0.37).sin() * 1e-7))
            .collect();
        let (s1, fine) = a.sum(terms.iter().copied());
        let (s2, _) = a.sum(terms.iter().rev().copied());
        assert!(fine);
        assert_eq!(s1, s2);
        a.add_contacts(&s1);
        let b = Ledger::new(1.0).with_words(&a.words());
        assert_eq!(a.totals(), b.totals());
    }
}
