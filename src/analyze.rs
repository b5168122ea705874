//! Measurements on frames (`tinydem analyze`): kinetic energy, coordination number, packing
//! fraction, the angle of repose of a quasi-2D pile, and the mean height of large particles.

use glam::DVec3;

use crate::integrate::Inertia;
use crate::neighbours::CellGrid;
use crate::particles::Particles;

/// Kinetic energy, translational and rotational [J], for the density `rho[m]` of each
/// particle's material m.
pub fn kinetic_energy(p: &Particles, rho: &[f64]) -> f64 {
    (0..p.len())
        .map(|k| {
            let density = rho.get(p.material[k] as usize).copied().unwrap_or(rho[0]);
            let b = Inertia::new(p.radius[k], density, 0.0);
            0.5 * b.m * p.v[k].length_squared() + 0.5 * b.i * p.w[k].length_squared()
        })
        .sum()
}

/// Mean number of particle-particle contacts per particle (each contact counts for both).
pub fn coordination_number(p: &Particles) -> f64 {
    if p.is_empty() {
        return 0.0;
    }
    let grid = CellGrid::of_points(&p.x, 2.0 * p.max_radius());
    let mut contacts = 0usize;
    for i in 0..p.len() {
        grid.for_each_near(p.x[i], |j| {
            let j = j as usize;
            if j != i && p.x[i].distance(p.x[j]) < p.radius[i] + p.radius[j] {
                contacts += 1;
            }
        });
    }
    contacts as f64 / p.len() as f64
}

/// Solid fraction in the bulk of the packings of a frame, however many heaps it holds:
/// around each particle, the volume of the particles whose centres lie within L = 4 mean
/// radii, over the volume of that sphere; the median over the particles inside a packing,
/// those whose neighbours within L surround them (their centroid lies within L/5 of the
/// centre: a particle on a free surface or a wall has them on one side, a centroid about
/// 3L/8 off). 0 if no particle is inside a packing (a gas, a monolayer, too few grains).
/// Whole spheres are counted, so the error is of order R/L.
pub fn packing_fraction(p: &Particles) -> f64 {
    if p.len() < 20 {
        return 0.0;
    }
    let r_mean = p.radius.iter().sum::<f64>() / p.len() as f64;
    let l = 4.0 * r_mean;
    let ball = 4.0 / 3.0 * std::f64::consts::PI;
    let grid = CellGrid::of_points(&p.x, l);
    let mut fractions: Vec<f64> = (0..p.len())
        .filter_map(|i| {
            let (mut volume, mut centroid, mut n) = (0.0, DVec3::ZERO, 0usize);
            grid.for_each_near(p.x[i], |j| {
                let j = j as usize;
                let d = p.x[j] - p.x[i];
                if d.length_squared() <= l * l {
                    volume += ball * p.radius[j].powi(3);
                    if j != i {
                        centroid += d;
                        n += 1;
                    }
                }
            });
            let surrounded = n >= 6 && (centroid / n as f64).length() < 0.2 * l;
            surrounded.then_some(volume / (ball * l * l * l))
        })
        .collect();
    if fractions.is_empty() {
        return 0.0;
    }
    fractions.sort_by(f64::total_cmp);
    fractions[fractions.len() / 2]
}

/// The angle of repose of a pile in the x-z plane, left and right flank [degrees].
///
/// The surface is the highest particle top in bins of two mean diameters along x; each flank
/// is fitted by least squares over the bins between 25 % and 85 % of the pile's height
/// (leaving out the rounded apex and the foot).
pub fn angle_of_repose(p: &Particles) -> Option<(f64, f64)> {
    if p.len() < 20 {
        return None;
    }
    let r_mean = p.radius.iter().sum::<f64>() / p.len() as f64;
    let w = 4.0 * r_mean;
    let floor = p.x.iter().map(|x| x.z).fold(f64::INFINITY, f64::min) - r_mean;
    let (xmin, xmax) =
        p.x.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x.x), b.max(x.x))
            });
    let nbins = (((xmax - xmin) / w).ceil() as usize).max(1);
    let mut top = vec![f64::NEG_INFINITY; nbins];
    for (x, r) in p.x.iter().zip(&p.radius) {
        let b = (((x.x - xmin) / w) as usize).min(nbins - 1);
        top[b] = top[b].max(x.z + r - floor);
    }
    let apex = (0..nbins).max_by(|&a, &b| top[a].total_cmp(&top[b]))?;
    let h = top[apex];
    let fit = |bins: &mut dyn Iterator<Item = usize>| -> Option<f64> {
        let pts: Vec<(f64, f64)> = bins
            .filter(|&b| top[b] > 0.25 * h && top[b] < 0.85 * h)
            .map(|b| (xmin + (b as f64 + 0.5) * w, top[b]))
            .collect();
        if pts.len() < 3 {
            return None;
        }
        let n = pts.len() as f64;
        let (sx, sz) = pts.iter().fold((0.0, 0.0), |(a, b), (x, z)| (a + x, b + z));
        let (mx, mz) = (sx / n, sz / n);
        let sxx: f64 = pts.iter().map(|(x, _)| (x - mx).powi(2)).sum();
        let sxz: f64 = pts.iter().map(|(x, z)| (x - mx) * (z - mz)).sum();
        Some((sxz / sxx).abs().atan().to_degrees())
    };
    Some((fit(&mut (0..apex))?, fit(&mut (apex + 1..nbins))?))
}

/// Mean height of the particles with radius at least `r` (None if there are none).
pub fn mean_height_of_large(p: &Particles, r: f64) -> Option<f64> {
    let z: Vec<f64> = (0..p.len())
        .filter(|&k| p.radius[k] >= r)
        .map(|k| p.x[k].z)
        .collect();
    (!z.is_empty()).then(|| z.iter().sum::<f64>() / z.len() as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::particles::Particle;
    use glam::DQuat;

    fn at(x: f64, z: f64, r: f64) -> Particle {
        Particle {
            x: DVec3::new(x, 0.0, z),
            radius: r,
            v: DVec3::ZERO,
            q: DQuat::IDENTITY,
            w: DVec3::ZERO,
            tag: 0,
            material: 0,
        }
    }

    #[test]
    fn a_triangular_heap_has_its_angles() {
        // Particles filling a triangle with flanks of 40° (left) and 50° (right).
        let r = 0.001;
        let mut p = Particles::default();
        let (tl, tr) = (40f64.to_radians().tan(), 50f64.to_radians().tan());
        let mut x = -0.2;
        while x < 0.2 {
            let top = if x < 0.0 { 0.1 + x * tl } else { 0.1 - x * tr };
            let mut z = r;
            while z + r <= top {
                p.push(at(x, z, r));
                z += 2.0 * r;
            }
            x += 2.0 * r;
        }
        let (left, right) = angle_of_repose(&p).unwrap();
        assert!(
            (left - 40.0).abs() < 1.5 && (right - 50.0).abs() < 1.5,
            "{left} {right}"
        );
    }

    #[test]
    fn packing_fraction_of_two_lattice_blocks() {
        // Two separate blocks of a simple cubic lattice of touching spheres: pi/6 each.
        let r = 0.005;
        let mut p = Particles::default();
        for block in [0.0, 1.0] {
            for i in 0..10 {
                for j in 0..10 {
                    for k in 0..10 {
                        let mut q = at(2.0 * r * i as f64 + block, 2.0 * r * k as f64 + r, r);
                        q.x.y = 2.0 * r * j as f64;
                        p.push(q);
                    }
                }
            }
        }
        let phi = packing_fraction(&p);
        assert!((phi - std::f64::consts::PI / 6.0).abs() < 0.03, "{phi}");
        // A sparse gas has no bulk.
        let mut gas = Particles::default();
        for k in 0..50 {
            gas.push(at(0.1 * k as f64, 0.0, 0.01));
        }
        assert_eq!(packing_fraction(&gas), 0.0);
    }

    #[test]
    fn coordination_and_energy() {
        let mut p = Particles::default();
        p.push(at(0.0, 0.0, 0.01));
        p.push(at(0.019, 0.0, 0.01));
        p.push(at(0.1, 0.0, 0.01));
        assert!((coordination_number(&p) - 2.0 / 3.0).abs() < 1e-12);
        p.v[2] = DVec3::X;
        let m = 4.0 / 3.0 * std::f64::consts::PI * 1000.0 * 1e-6;
        assert!((kinetic_energy(&p, &[1000.0]) - 0.5 * m).abs() < 1e-15);
        assert_eq!(mean_height_of_large(&p, 0.02), None);
    }
}
