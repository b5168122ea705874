//! Periodic axes of the domain and Lees-Edwards shear: the images of a particle, wrapping
//! into the box.

use glam::DVec3;

/// Periodic axes of the domain: space repeats with period `length` along each `axes[a]`,
/// from `min`; with `shear`, the images across the gradient axis slide (Lees-Edwards).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Periodic {
    pub min: DVec3,
    pub length: DVec3,
    pub axes: [bool; 3],
    pub shear: Option<Shear>,
}

/// Lees-Edwards boundaries: the image of the box beyond the `gradient` axis's upper side is
/// shifted along the `axis` by `offset` = V t and moves with `velocity` V along it (the one
/// below by -V t, with -V), which imposes a simple shear of rate V / L_gradient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shear {
    pub velocity: f64,
    pub axis: usize,
    pub gradient: usize,
    /// The current offset V t (not reduced by the period).
    pub offset: f64,
}

impl Periodic {
    /// Puts `x` back into [min, min + length) along the periodic axes.
    #[inline]
    pub fn wrap(&self, x: DVec3) -> DVec3 {
        self.wrap_state(x, DVec3::ZERO).0
    }

    /// Puts a particle at `x` with velocity `v` back into the box: crossing the gradient axis
    /// of a sheared domain also shifts it along the shear axis by the offset and changes its
    /// velocity by the image's.
    #[inline]
    pub fn wrap_state(&self, x: DVec3, v: DVec3) -> (DVec3, DVec3) {
        let (mut x, mut v) = (x, v);
        if let Some(sh) = self.shear
            && x[sh.gradient].is_finite()
        {
            let (lo, l) = (self.min[sh.gradient], self.length[sh.gradient]);
            let crossings = ((x[sh.gradient] - lo) / l).floor();
            if crossings != 0.0 {
                x[sh.gradient] -= crossings * l;
                x[sh.axis] -= crossings * self.offset_in_period(sh);
                v[sh.axis] -= crossings * sh.velocity;
            }
        }
        let mut x = x.to_array();
        for (a, x) in x.iter_mut().enumerate() {
            if self.axes[a] && x.is_finite() {
                let (lo, l) = (self.min[a], self.length[a]);
                let mut w = lo + (*x - lo).rem_euclid(l);
                if w >= lo + l {
                    w = lo; // rem_euclid of a tiny negative number rounds up to l
                }
                *x = w;
            }
        }
        (DVec3::from_array(x), v)
    }

    /// The shear offset reduced to [0, L) of the shear axis.
    pub(crate) fn offset_in_period(&self, sh: Shear) -> f64 {
        sh.offset.rem_euclid(self.length[sh.axis])
    }

    /// The image of a point at `x` nearest to a point at `to` (both in the box): its shift
    /// and how often it crosses the gradient axis of a sheared box (-1, 0, 1). The shift
    /// depends on the two points alone (not on how the image was found), so the pair of a
    /// particle and the other's image is seen with the same bits wherever it is listed.
    pub(crate) fn image_towards(&self, x: DVec3, to: DVec3) -> (DVec3, i8) {
        let periods = |a: usize, d: f64| (d / self.length[a]).round();
        let mut e = DVec3::ZERO;
        let mut n = 0.0;
        let gradient = self.shear.map(|sh| sh.gradient);
        if let Some(sh) = self.shear {
            n = periods(sh.gradient, to[sh.gradient] - x[sh.gradient]);
            e[sh.gradient] = n * self.length[sh.gradient];
            e[sh.axis] = n * self.offset_in_period(sh);
        }
        for a in (0..3).filter(|&a| self.axes[a] && Some(a) != gradient) {
            e[a] += periods(a, to[a] - x[a] - e[a]) * self.length[a];
        }
        (e, n as i8)
    }

    /// The images of a point at `x` (in the box) that come within `reach` of the box: their
    /// shifts and how many times each crosses the gradient axis (-1, 0, 1; 0 without
    /// shear). For each periodic axis where the point (or an image of it) is within `reach`
    /// of a side, the period towards the other side, and their combinations (edges,
    /// corners); across the gradient axis of a sheared box, with the offset along the shear
    /// axis, brought back into the period.
    pub(crate) fn image_shifts(&self, x: DVec3, reach: f64, out: &mut Vec<(DVec3, i8)>) {
        out.clear();
        out.push((DVec3::ZERO, 0));
        let near = |p: DVec3, a: usize| -> f64 {
            if p[a] - self.min[a] < reach {
                self.length[a]
            } else if self.min[a] + self.length[a] - p[a] < reach {
                -self.length[a]
            } else {
                0.0
            }
        };
        if let Some(sh) = self.shear {
            let (g, s) = (sh.gradient, sh.axis);
            let step = near(x, g);
            if step != 0.0 {
                let n = step.signum();
                let mut e = DVec3::ZERO;
                e[g] = step;
                e[s] = n * self.offset_in_period(sh);
                let (lo, l) = (self.min[s], self.length[s]);
                if x[s] + e[s] >= lo + l {
                    e[s] -= l;
                } else if x[s] + e[s] < lo {
                    e[s] += l;
                }
                out.push((e, n as i8));
            }
        }
        for a in 0..3 {
            if !self.axes[a] || self.shear.is_some_and(|sh| sh.gradient == a) {
                continue;
            }
            for k in 0..out.len() {
                let (e0, n) = out[k];
                let step = near(x + e0, a);
                if step != 0.0 {
                    let mut e = e0;
                    e[a] += step;
                    out.push((e, n));
                }
            }
        }
        out.remove(0);
    }
}
