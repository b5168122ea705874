//! Particle storage (paper Table 3), struct-of-arrays, in creation order.

use glam::{DQuat, DVec3};

/// The state of every particle. Index `i` is the particle's identity: particles keep their
/// creation order, which is also their order in every output frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Particles {
    /// R [L]
    pub radius: Vec<f64>,
    /// x [L]
    pub x: Vec<DVec3>,
    /// v [L/T]
    pub v: Vec<DVec3>,
    /// Orientation q̂, mapping body to world coordinates.
    pub q: Vec<DQuat>,
    /// ω [1/T], world frame.
    pub w: Vec<DVec3>,
    /// A label per particle (0 by default), set by `[[tags]]` regions, e.g. to dye grains by
    /// the path they took.
    pub tag: Vec<u32>,
}

/// One particle's state, as read from and written to CSV.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Particle {
    pub x: DVec3,
    pub radius: f64,
    pub v: DVec3,
    pub q: DQuat,
    pub w: DVec3,
    pub tag: u32,
}

impl Particles {
    pub fn len(&self) -> usize {
        self.x.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    pub fn push(&mut self, p: Particle) {
        self.radius.push(p.radius);
        self.x.push(p.x);
        self.v.push(p.v);
        self.q.push(p.q);
        self.w.push(p.w);
        self.tag.push(p.tag);
    }

    pub fn get(&self, i: usize) -> Particle {
        Particle {
            x: self.x[i],
            radius: self.radius[i],
            v: self.v[i],
            q: self.q[i],
            w: self.w[i],
            tag: self.tag[i],
        }
    }

    pub fn iter(&self) -> impl Iterator<Item = Particle> + '_ {
        (0..self.len()).map(|i| self.get(i))
    }

    /// Whether any particle carries a tag.
    pub fn tagged(&self) -> bool {
        self.tag.iter().any(|&t| t != 0)
    }

    /// Largest radius present, or 0.
    pub fn max_radius(&self) -> f64 {
        self.radius.iter().copied().fold(0.0, f64::max)
    }
}

impl FromIterator<Particle> for Particles {
    fn from_iter<I: IntoIterator<Item = Particle>>(iter: I) -> Self {
        let mut p = Particles::default();
        for x in iter {
            p.push(x);
        }
        p
    }
}
