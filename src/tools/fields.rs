//! Continuum fields from particles by coarse-graining (Goldhirsch 2010; Weinhart et al. 2012,
//! as MercuryDPM's MercuryCG): density, velocity and the Cauchy stress, its contact and
//! kinetic parts, on a grid of points or in slices, with a Gaussian or Lucy kernel, over one
//! frame or averaged over frames (`tinydem analyze --fields`, `tinydem.fields`).
//!
//! With φ the kernel, particle i of mass m_i at x_i with velocity v_i, and each contact c
//! with the force f_c on its particle and branch b_c (from its partner's centre, or the
//! contact point on a face, to the particle's centre):
//!
//! ```text
//! ρ(r)   = Σ_i m_i φ(r − x_i)                         density
//! p(r)   = Σ_i m_i v_i φ(r − x_i),   V = p / ρ         momentum, velocity
//! σ_k(r) = Σ_i m_i v_i ⊗ v_i φ(r − x_i) − ρ V ⊗ V      kinetic stress
//! σ_c(r) = Σ_c f_c ⊗ b_c ∫_0^1 φ(r − x_i + s b_c) ds   contact stress
//! ```
//!
//! Stresses are positive in compression (the granular convention): a column at rest has
//! σ_zz = ρ g (H − z). Averaged over frames, each sum is averaged and V and σ_k follow from
//! the averages, so σ_k holds the fluctuations in time too. The branch of a pair contact
//! comes from the contact record alone (n = (x_i − c)/|x_i − c| and |b| = R_i + R_j − δ), so
//! pairs across periodic and Lees-Edwards sides need no images; a periodic axis that the
//! grid spans wraps the kernel around.

use glam::{DMat3, DVec3};
use rustc_hash::FxHashMap;

use crate::engine::records::{ContactRecord, Partner};
use crate::model::particles::{Id, Particles};

/// The coarse-graining function φ, normalised to a unit integral.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kernel {
    /// exp(−r²/2w²), cut at 3w (and normalised as cut).
    Gaussian { width: f64 },
    /// Lucy's polynomial (1 + 3q)(1 − q)³ with q = r / width (zero beyond `width`).
    Lucy { width: f64 },
    /// The grid's cells as bins (LIGGGHTS's `ave/euler`): 1/V of the cell that holds the
    /// point, 0 elsewhere; a slice's cell spans the box across its axis.
    Cell,
}

/// Of a Gaussian cut at 3 standard deviations, the part of its integral inside the cut:
/// erf(3/√2) − √(2/π) 3 e^(−9/2).
const GAUSSIAN_INSIDE: f64 = 0.970_709_140_760_959_2;

impl Kernel {
    /// Where it ends (0 for cells: at the cell's faces).
    pub fn cutoff(&self) -> f64 {
        match *self {
            Kernel::Gaussian { width } => 3.0 * width,
            Kernel::Lucy { width } => width,
            Kernel::Cell => 0.0,
        }
    }

    /// φ at squared distance `r2` \[1/L³\].
    pub fn value(&self, r2: f64) -> f64 {
        match *self {
            Kernel::Gaussian { width } => {
                if r2 >= 9.0 * width * width {
                    return 0.0;
                }
                let norm = (std::f64::consts::TAU * width * width).powf(1.5) * GAUSSIAN_INSIDE;
                (-r2 / (2.0 * width * width)).exp() / norm
            }
            Kernel::Lucy { width } => {
                let q = r2.sqrt() / width;
                if q >= 1.0 {
                    return 0.0;
                }
                let norm = 16.0 * std::f64::consts::PI * width.powi(3) / 105.0;
                (1.0 + 3.0 * q) * (1.0 - q).powi(3) / norm
            }
            Kernel::Cell => unreachable!("cells are spread by the grid"),
        }
    }

    /// φ integrated over a plane at distance `z` from the point \[1/L\]: the kernel of slices.
    pub fn marginal(&self, z: f64) -> f64 {
        let z = z.abs();
        if z >= self.cutoff() {
            return 0.0;
        }
        match *self {
            Kernel::Gaussian { width } => {
                // ∫ 2π ρ φ dρ over the disk at height z inside the cut sphere.
                let w2 = width * width;
                let norm = (std::f64::consts::TAU * w2).powf(1.5) * GAUSSIAN_INSIDE;
                std::f64::consts::TAU * w2 * ((-z * z / (2.0 * w2)).exp() - (-4.5f64).exp()) / norm
            }
            Kernel::Lucy { width } => {
                // 2π c² C [F(1) − F(q0)], F(q) = q²/2 − 3q⁴/2 + 8q⁵/5 − q⁶/2, F(1) = 1/10.
                let q = z / width;
                let f = |q: f64| q * q / 2.0 - 1.5 * q.powi(4) + 1.6 * q.powi(5) - 0.5 * q.powi(6);
                let c = 105.0 / (16.0 * std::f64::consts::PI * width.powi(3));
                std::f64::consts::TAU * width * width * c * (0.1 - f(q))
            }
            Kernel::Cell => unreachable!("cells are spread by the grid"),
        }
    }
}

/// Where the fields are: points at the centres of the cells of a box, `counts` along x,
/// y, z; or slices, cells that span the box but along one axis (`slices`): within the box
/// across that axis, averaged over its cross-section. An axis that `wrap`s is periodic and
/// spanned by the box.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    pub min: DVec3,
    pub spacing: DVec3,
    pub counts: [usize; 3],
    pub wrap: [bool; 3],
    pub slices: Option<usize>,
}

impl Grid {
    /// A grid over `min`-`max` with cells about `spacing` wide (each axis divided evenly),
    /// in slices along axis `slices` if given; the axes of `periodic` wrap.
    pub fn over(
        min: DVec3,
        max: DVec3,
        spacing: f64,
        slices: Option<usize>,
        periodic: [bool; 3],
    ) -> Grid {
        let size = max - min;
        let counts: [usize; 3] = std::array::from_fn(|a| match slices {
            Some(s) if s != a => 1,
            _ => ((size[a] / spacing).round() as usize).max(1),
        });
        Grid {
            min,
            spacing: DVec3::from_array(std::array::from_fn(|a| size[a] / counts[a] as f64)),
            counts,
            wrap: periodic,
            slices,
        }
    }

    pub fn len(&self) -> usize {
        self.counts.iter().product()
    }

    /// Calls `add(cell index, 1/V)` for the cell of the box that holds `at`, if one does
    /// (across a wrapping axis, the cell of its image).
    fn bin(&self, at: DVec3, mut add: impl FnMut(usize, f64)) {
        let mut index = [0usize; 3];
        for a in 0..3 {
            let n = self.counts[a] as i64;
            let i = ((at[a] - self.min[a]) / self.spacing[a]).floor() as i64;
            index[a] = match self.wrap[a] {
                true => i.rem_euclid(n) as usize,
                false if (0..n).contains(&i) => i as usize,
                false => return,
            };
        }
        let [nx, ny, _] = self.counts;
        add(
            index[0] + nx * (index[1] + ny * index[2]),
            1.0 / self.spacing.element_product(),
        );
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The point of index `k` (x fastest).
    pub fn point(&self, k: usize) -> DVec3 {
        let [nx, ny, _] = self.counts;
        let idx = [k % nx, (k / nx) % ny, k / (nx * ny)];
        self.min + DVec3::from_array(idx.map(|i| i as f64 + 0.5)) * self.spacing
    }

    /// Calls `add(point index, φ)` for each point within the kernel's reach of `at`. A slice
    /// spans the box across its axis, and no further: what lies outside the box across it
    /// (unless that axis wraps) adds nothing, so that a slice's density is that of its box.
    fn spread(&self, kernel: &Kernel, at: DVec3, mut add: impl FnMut(usize, f64)) {
        let reach = kernel.cutoff();
        let h = self.spacing;
        if let Some(s) = self.slices {
            let outside = |a: usize| {
                let hi = self.min[a] + h[a] * self.counts[a] as f64;
                a != s && !self.wrap[a] && !(self.min[a] <= at[a] && at[a] < hi)
            };
            if (0..3).any(outside) {
                return;
            }
        }
        if *kernel == Kernel::Cell {
            return self.bin(at, add);
        }
        // The index range per axis (all of an axis a slice spans), and the offset along it.
        let range = |a: usize| -> (i64, i64) {
            if self.slices.is_some_and(|s| s != a) {
                return (0, 0);
            }
            let lo = ((at[a] - reach - self.min[a]) / h[a] - 0.5).floor() as i64;
            let hi = ((at[a] + reach - self.min[a]) / h[a] - 0.5).ceil() as i64;
            match self.wrap[a] {
                true => (lo, hi),
                // (Points beyond the grid are skipped anyway.)
                false => (lo.max(0), hi.min(self.counts[a] as i64 - 1)),
            }
        };
        let index = |a: usize, i: i64| -> Option<usize> {
            let n = self.counts[a] as i64;
            match self.wrap[a] {
                true => Some(i.rem_euclid(n) as usize),
                false => (0..n).contains(&i).then_some(i as usize),
            }
        };
        let ([x0, x1], [y0, y1], [z0, z1]) = (
            <[i64; 2]>::from(range(0)),
            <[i64; 2]>::from(range(1)),
            <[i64; 2]>::from(range(2)),
        );
        let [nx, ny, _] = self.counts;
        let area = |s: usize| (0..3).filter(|&a| a != s).map(|a| h[a]).product::<f64>();
        for iz in z0..=z1 {
            let Some(kz) = index(2, iz) else { continue };
            for iy in y0..=y1 {
                let Some(ky) = index(1, iy) else { continue };
                for ix in x0..=x1 {
                    let Some(kx) = index(0, ix) else { continue };
                    let d = at
                        - self.min
                        - DVec3::new(ix as f64 + 0.5, iy as f64 + 0.5, iz as f64 + 0.5) * h;
                    let phi = match self.slices {
                        Some(s) => kernel.marginal(d[s]) / area(s),
                        None => kernel.value(d.length_squared()),
                    };
                    if phi > 0.0 {
                        add(kx + nx * (ky + ny * kz), phi);
                    }
                }
            }
        }
    }
}

/// The coarse-grained sums at each point of a grid, summed over the frames added.
#[derive(Clone, Debug)]
pub struct Sums {
    grid: Grid,
    kernel: Kernel,
    frames: usize,
    density: Vec<f64>,
    /// Σ V φ: the solid fraction.
    volume: Vec<f64>,
    momentum: Vec<DVec3>,
    /// Σ m v ⊗ v φ.
    flux: Vec<DMat3>,
    contact: Vec<DMat3>,
    /// Σ m T φ, of frames with temperatures (heat transfer).
    heat: Option<Vec<f64>>,
}

/// Gauss-Legendre nodes and weights on [0, 1], four points.
const NODES: [(f64, f64); 4] = [
    (0.069_431_844_202_973_71, 0.173_927_422_568_726_93),
    (0.330_009_478_207_571_9, 0.326_072_577_431_273_07),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_07),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_93),
];

impl Sums {
    pub fn new(grid: Grid, kernel: Kernel) -> Sums {
        let n = grid.len();
        Sums {
            grid,
            kernel,
            frames: 0,
            density: vec![0.0; n],
            volume: vec![0.0; n],
            momentum: vec![DVec3::ZERO; n],
            flux: vec![DMat3::ZERO; n],
            contact: vec![DMat3::ZERO; n],
            heat: None,
        }
    }

    /// Adds a frame: its particles `p`, the mass of each (`mass(k)`), and its contact
    /// network (`None`: no contact stress); each particle's volume that of its sphere.
    pub fn add(
        &mut self,
        p: &Particles,
        mass: impl Fn(usize) -> f64,
        contacts: Option<&[ContactRecord]>,
    ) {
        let ball = |k: usize| 4.0 / 3.0 * std::f64::consts::PI * p.radius[k].powi(3);
        self.add_grains(p, |k| (mass(k), ball(k)), contacts);
    }

    /// [`Sums::add`] with the mass and volume of each particle (`of(k)`: the spheres of a
    /// clump share its mass and its volume, their overlaps counted once).
    pub fn add_grains(
        &mut self,
        p: &Particles,
        of: impl Fn(usize) -> (f64, f64),
        contacts: Option<&[ContactRecord]>,
    ) {
        self.frames += 1;
        if p.active.temperature && self.heat.is_none() {
            self.heat = Some(vec![0.0; self.density.len()]);
        }
        for k in 0..p.len() {
            let ((m, vol), v) = (of(k), p.v[k]);
            let mvv = DMat3::from_cols(v * (m * v.x), v * (m * v.y), v * (m * v.z));
            let Sums {
                grid,
                kernel,
                density,
                volume,
                momentum,
                flux,
                heat,
                ..
            } = self;
            let t = p.temperature.get(k).copied().unwrap_or(0.0);
            grid.spread(kernel, p.x[k], |g, phi| {
                density[g] += m * phi;
                volume[g] += vol * phi;
                momentum[g] += m * phi * v;
                flux[g] += mvv * phi;
                if let Some(heat) = heat.as_mut() {
                    heat[g] += m * t * phi;
                }
            });
        }
        if let Some(contacts) = contacts {
            let index: FxHashMap<Id, usize> =
                p.id.iter().enumerate().map(|(k, &id)| (id, k)).collect();
            for c in contacts {
                self.add_contact(p, &index, c);
            }
        }
    }

    /// One contact's f ⊗ b, spread along its branch.
    fn add_contact(&mut self, p: &Particles, index: &FxHashMap<Id, usize>, c: &ContactRecord) {
        let Some(&i) = index.get(&c.id) else {
            return;
        };
        let x = p.x[i];
        let to_centre = x - c.point;
        let branch = match c.with {
            Partner::Face(_) => to_centre,
            Partner::Particle(j) => {
                let Some(&j) = index.get(&(j as Id)) else {
                    return;
                };
                let reach = p.radius[i] + p.radius[j] - c.overlap;
                to_centre.normalize_or_zero() * reach
            }
        };
        let f = c.f_n + c.f_t;
        let fb = DMat3::from_cols(f * branch.x, f * branch.y, f * branch.z);
        // Segments no longer than a third of the kernel's reach (of cells: a third of the
        // narrowest), four nodes each.
        let reach = match self.kernel {
            Kernel::Cell => self.grid.spacing.min_element(),
            k => k.cutoff(),
        };
        let segments = (3.0 * branch.length() / reach).ceil().max(1.0) as usize;
        let Sums {
            grid,
            kernel,
            contact,
            ..
        } = self;
        for s in 0..segments {
            for (node, weight) in NODES {
                let t = (s as f64 + node) / segments as f64;
                let w = weight / segments as f64;
                grid.spread(kernel, x - t * branch, |g, phi| {
                    contact[g] += fb * (w * phi)
                });
            }
        }
    }

    /// The fields: the sums averaged over the frames, the velocity and kinetic stress from
    /// the averages.
    pub fn fields(&self) -> Fields {
        let n = self.frames.max(1) as f64;
        let density: Vec<f64> = self.density.iter().map(|d| d / n).collect();
        let velocity: Vec<DVec3> = (self.momentum.iter().zip(&density))
            .map(|(p, &rho)| if rho > 0.0 { *p / n / rho } else { DVec3::ZERO })
            .collect();
        let kinetic = (self.flux.iter().zip(&density).zip(&velocity))
            .map(|((f, &rho), &v)| {
                *f * (1.0 / n) - DMat3::from_cols(v * (rho * v.x), v * (rho * v.y), v * (rho * v.z))
            })
            .collect();
        // The mass-weighted mean temperature where there are grains.
        let temperature = (self.heat.as_ref()).map(|heat| {
            (heat.iter().zip(&density))
                .map(|(h, &rho)| if rho > 0.0 { h / n / rho } else { 0.0 })
                .collect()
        });
        Fields {
            grid: self.grid.clone(),
            frames: self.frames,
            temperature,
            density,
            volume_fraction: self.volume.iter().map(|v| v / n).collect(),
            velocity,
            contact: self.contact.iter().map(|c| *c * (1.0 / n)).collect(),
            kinetic,
        }
    }
}

/// Fields on a grid (`Sums::fields`).
#[derive(Clone, Debug)]
pub struct Fields {
    pub grid: Grid,
    /// How many frames they average.
    pub frames: usize,
    /// \[M/L³\]
    pub density: Vec<f64>,
    /// The solid fraction: the grains' volume per volume \[-\].
    pub volume_fraction: Vec<f64>,
    /// \[L/T\]
    pub velocity: Vec<DVec3>,
    /// The contact and kinetic stress \[M/(L T²)\], compression positive; element (r, c)
    /// is `matrix.col(c)[r]`.
    pub contact: Vec<DMat3>,
    pub kinetic: Vec<DMat3>,
    /// The mass-weighted mean temperature \[K\] (0 where there are no grains), of frames
    /// with temperatures.
    pub temperature: Option<Vec<f64>>,
}

impl Fields {
    /// The stress, contact and kinetic.
    pub fn stress(&self, k: usize) -> DMat3 {
        self.contact[k] + self.kinetic[k]
    }

    /// The columns of [`Fields::row`].
    pub fn header(&self) -> String {
        let tensor = |p: &str| {
            ["xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz"]
                .map(|c| format!("{p}_{c}"))
                .join(",")
        };
        let temperature = if self.temperature.is_some() {
            ",temperature"
        } else {
            ""
        };
        format!(
            "x,y,z,density,volume_fraction,vx,vy,vz,{},{},{}{temperature}",
            tensor("stress"),
            tensor("contact"),
            tensor("kinetic")
        )
    }

    /// Point `k`'s values in the order of [`Fields::header`].
    pub fn row(&self, k: usize) -> Vec<f64> {
        let rows = |m: DMat3| {
            let t = m.transpose();
            [t.x_axis, t.y_axis, t.z_axis]
                .map(|c| c.to_array())
                .concat()
        };
        let x = self.grid.point(k);
        let v = self.velocity[k];
        let mut row = vec![
            x.x,
            x.y,
            x.z,
            self.density[k],
            self.volume_fraction[k],
            v.x,
            v.y,
            v.z,
        ];
        row.extend(rows(self.stress(k)));
        row.extend(rows(self.contact[k]));
        row.extend(rows(self.kinetic[k]));
        row.extend(self.temperature.as_ref().map(|t| t[k]));
        row
    }
}

mod directory;
pub use directory::{Options, Shape, of_directory};

#[cfg(test)]
mod tests;
