//! Measurements on frames (`tinydem analyze`): kinetic energy, coordination number, packing
//! fraction, the angle of repose of a quasi-2D pile, and the mean height of large particles.

use glam::DVec3;

use crate::model::integrate::Inertia;
use crate::model::particles::Particles;
use crate::neighbours::CellGrid;

/// A grain of a frame: a plain sphere, or a clump (a rigid body of several spheres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grain {
    /// Its centre (of mass) \[L\].
    pub x: DVec3,
    /// Its volume \[L³\] (of a clump: its mass over its material's density, so its spheres'
    /// overlaps count once).
    pub volume: f64,
}

/// The grains of a frame whose clumps are given as their spheres and bodies
/// (`io::inputs::with_clumps`), with the density `rho[m]` of each material m; and for each
/// particle (sphere), the index of its grain.
pub fn grains(p: &Particles, rho: &[f64]) -> (Vec<Grain>, Vec<usize>) {
    let density = |m: usize| rho.get(m).copied().unwrap_or(rho[0]);
    let mut grains = Vec::with_capacity(p.len());
    let mut of = vec![usize::MAX; p.len()];
    for k in (0..p.len()).filter(|&k| p.body[k].is_none()) {
        of[k] = grains.len();
        let r = p.radius[k];
        grains.push(Grain {
            x: p.x[k],
            volume: 4.0 / 3.0 * std::f64::consts::PI * r * r * r,
        });
    }
    for (b, body) in p.bodies.list.iter().enumerate() {
        let members = p.bodies.members(b);
        let material = members
            .first()
            .map_or(0, |&k| p.material[k as usize] as usize);
        for &k in members {
            of[k as usize] = grains.len();
        }
        grains.push(Grain {
            x: body.x,
            volume: body.mass / density(material),
        });
    }
    (grains, of)
}

/// Kinetic energy, translational and rotational \[J\], for the density `rho[m]` of each
/// particle's material m: a plain sphere's of its own, a clump's (its spheres given with
/// their body, `io::inputs::with_clumps`) that of its body.
pub fn kinetic_energy(p: &Particles, rho: &[f64]) -> f64 {
    let spheres: f64 = (0..p.len())
        .filter(|&k| p.body[k].is_none())
        .map(|k| {
            let density = rho.get(p.material[k] as usize).copied().unwrap_or(rho[0]);
            let b = Inertia::new(p.radius[k], density, 0.0);
            0.5 * b.m * p.v[k].length_squared() + 0.5 * b.i * p.w[k].length_squared()
        })
        .sum();
    let bodies: f64 = (p.bodies.list.iter())
        .map(|b| {
            let (t, r) = b.kinetic_energy();
            t + r
        })
        .sum();
    spheres + bodies
}

/// Mean number of grains touching a grain (each contact counts for both): spheres of one
/// clump do not touch each other, and two clumps touching at several spheres touch once.
pub fn coordination_number(p: &Particles) -> f64 {
    if p.is_empty() {
        return 0.0;
    }
    let (grains, of) = grains(p, &[1.0]);
    let grid = CellGrid::of_points(&p.x, 2.0 * p.max_radius());
    let mut touching: Vec<(usize, usize)> = Vec::new();
    for i in 0..p.len() {
        grid.for_each_near(p.x[i], |j| {
            let j = j as usize;
            let (a, b) = (of[i], of[j]);
            if a < b && p.x[i].distance(p.x[j]) < p.radius[i] + p.radius[j] {
                touching.push((a, b));
            }
        });
    }
    touching.sort_unstable();
    touching.dedup();
    2.0 * touching.len() as f64 / grains.len() as f64
}

/// Solid fraction in the bulk of the packings of a frame, however many heaps it holds:
/// around each grain, the volume of the grains whose centres lie within L = 4 mean radii
/// (of the spheres of equal volume), over the volume of that sphere; the median over the
/// grains inside a packing, those whose neighbours within L surround them (their centroid
/// lies within L/5 of the centre: a grain on a free surface or a wall has them on one side,
/// a centroid about 3L/8 off). 0 if no grain is inside a packing (a gas, a monolayer, too
/// few grains). Whole grains are counted, so the error is of order R/L. Clumps count as
/// their bodies (`grains`).
pub fn packing_fraction(p: &Particles, rho: &[f64]) -> f64 {
    let (grains, _) = grains(p, rho);
    if grains.len() < 20 {
        return 0.0;
    }
    let ball = 4.0 / 3.0 * std::f64::consts::PI;
    let r_mean = grains.iter().map(|g| (g.volume / ball).cbrt()).sum::<f64>() / grains.len() as f64;
    let l = 4.0 * r_mean;
    let x: Vec<DVec3> = grains.iter().map(|g| g.x).collect();
    let grid = CellGrid::of_points(&x, l);
    let mut fractions: Vec<f64> = (0..grains.len())
        .filter_map(|i| {
            let (mut volume, mut centroid, mut n) = (0.0, DVec3::ZERO, 0usize);
            grid.for_each_near(x[i], |j| {
                let j = j as usize;
                let d = x[j] - x[i];
                if d.length_squared() <= l * l {
                    volume += grains[j].volume;
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

/// How [`angle_of_repose`] reads a pile: which grains rest, and which part of each flank it
/// fits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReposeWindow {
    /// Grains slower than this rest [m/s]; the others (the feed, avalanches) are left out.
    pub rest_speed: f64,
    /// The fitted part of each flank, as the drop below the apex in mean grain diameters:
    /// from `from` (below the rounded apex) to `to` (above the foot, where a pile's flank
    /// curves out: the paper's "logarithmic deviation at the bottom ends").
    pub from: f64,
    pub to: f64,
}

impl ReposeWindow {
    /// The window of `--rest-speed V` and `--window FROM,TO` (None: 3 to 30 diameters),
    /// checked: a positive speed and two numbers with 0 <= FROM < TO.
    pub fn of(rest_speed: f64, window: Option<&[f64]>) -> anyhow::Result<ReposeWindow> {
        let mut w = ReposeWindow {
            rest_speed,
            ..ReposeWindow::default()
        };
        if let Some(v) = window {
            let [from, to] = v[..] else {
                anyhow::bail!("--window FROM,TO takes two numbers, got {}", v.len());
            };
            (w.from, w.to) = (from, to);
        }
        anyhow::ensure!(
            w.rest_speed > 0.0,
            "--rest-speed must be positive, got {}",
            w.rest_speed
        );
        anyhow::ensure!(
            w.from >= 0.0 && w.to > w.from,
            "--window FROM,TO needs 0 <= FROM < TO, got {},{}",
            w.from,
            w.to
        );
        Ok(w)
    }
}

impl Default for ReposeWindow {
    fn default() -> Self {
        ReposeWindow {
            rest_speed: 0.01,
            from: 3.0,
            to: 30.0,
        }
    }
}

/// One flank's angle of repose \[degrees\], with the standard error of the least-squares
/// slope, over `columns` surface columns one grain diameter wide.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flank {
    pub angle: f64,
    pub error: f64,
    pub columns: usize,
}

/// The angles of a pile's two flanks, its height above the floor \[m\] and the grains at rest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Repose {
    pub left: Flank,
    pub right: Flank,
    pub height: f64,
    pub resting: usize,
}

/// Why a frame holds no pile to measure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NoPile {
    /// Fewer than 20 grains at rest.
    TooFewResting(usize),
    /// A flank has fewer than 3 surface columns in the window (the pile is too small, or the
    /// apex sits at the end of the bed).
    ShortFlank { side: &'static str, columns: usize },
}

impl std::fmt::Display for NoPile {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            NoPile::TooFewResting(n) => write!(f, "{n} grains at rest, fewer than 20"),
            NoPile::ShortFlank { side, columns } => write!(
                f,
                "the {side} flank has {columns} columns in the window, fewer than 3"
            ),
        }
    }
}

/// The angle of repose of a pile in the x-z plane (a quasi-2D heap between plates normal to
/// y), left and right flank, as the paper measures it: the straight part of each flank of the
/// resting pile.
///
/// The surface is the highest top of a resting grain in columns one mean diameter d wide
/// along x; the apex is the highest column. From there each flank is followed outwards, column
/// by column, until a column is empty, reaches the floor (its top within d of the lowest
/// resting grain's bottom) or lies more than `window.to` diameters below the apex; the columns
/// between `window.from` and `window.to` diameters below the apex are fitted by least squares,
/// z against x. The error is the standard error of that slope, as an angle.
pub fn angle_of_repose(p: &Particles, window: ReposeWindow) -> Result<Repose, NoPile> {
    let resting: Vec<usize> = (0..p.len())
        .filter(|&k| p.v[k].length() < window.rest_speed)
        .collect();
    if resting.len() < 20 {
        return Err(NoPile::TooFewResting(resting.len()));
    }
    let d = 2.0 * resting.iter().map(|&k| p.radius[k]).sum::<f64>() / resting.len() as f64;
    let floor = resting
        .iter()
        .map(|&k| p.x[k].z - p.radius[k])
        .fold(f64::INFINITY, f64::min);
    let (xmin, xmax) = resting
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &k| {
            (a.min(p.x[k].x), b.max(p.x[k].x))
        });
    let columns = (((xmax - xmin) / d).floor() as usize) + 1;
    let mut top = vec![f64::NEG_INFINITY; columns];
    for &k in &resting {
        let c = (((p.x[k].x - xmin) / d) as usize).min(columns - 1);
        top[c] = top[c].max(p.x[k].z + p.radius[k] - floor);
    }
    let apex = (0..columns)
        .max_by(|&a, &b| top[a].total_cmp(&top[b]))
        .expect("at least one column");
    let height = top[apex];
    let flank = |side: &'static str, columns: &mut dyn Iterator<Item = usize>| {
        let mut points = Vec::new();
        for c in columns {
            let drop = height - top[c];
            if !top[c].is_finite() || top[c] < d || drop > window.to * d {
                break;
            }
            if drop >= window.from * d {
                points.push((xmin + (c as f64 + 0.5) * d, top[c]));
            }
        }
        fit_slope(&points)
            .map(|(slope, error)| Flank {
                angle: slope.abs().atan().to_degrees(),
                error: (error / (1.0 + slope * slope)).to_degrees(),
                columns: points.len(),
            })
            .ok_or(NoPile::ShortFlank {
                side,
                columns: points.len(),
            })
    };
    Ok(Repose {
        left: flank("left", &mut (0..apex).rev())?,
        right: flank("right", &mut (apex + 1..columns))?,
        height,
        resting: resting.len(),
    })
}

/// The least-squares slope of z against x and its standard error; None for fewer than 3
/// points (or all at one x).
fn fit_slope(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as f64;
    let (sx, sz) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, z)| (a + x, b + z));
    let (mx, mz) = (sx / n, sz / n);
    let sxx: f64 = points.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    let sxz: f64 = points.iter().map(|(x, z)| (x - mx) * (z - mz)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let slope = sxz / sxx;
    let residuals: f64 = points
        .iter()
        .map(|(x, z)| (z - mz - slope * (x - mx)).powi(2))
        .sum();
    Some((slope, (residuals / (n - 2.0) / sxx).sqrt()))
}

/// The free surface of the bed in a rotating drum: its inclination in the plane normal to the
/// drum's axis \[degrees\], with the standard error of the fit, over `columns` surface
/// columns one grain diameter wide.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceAngle {
    pub angle: f64,
    pub error: f64,
    pub columns: usize,
}

/// Why a frame holds no drum bed to measure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NoSurface {
    TooFewGrains(usize),
    TooFewColumns(usize),
}

impl std::fmt::Display for NoSurface {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            NoSurface::TooFewGrains(n) => write!(f, "{n} grains, fewer than 20"),
            NoSurface::TooFewColumns(n) => {
                write!(
                    f,
                    "{n} surface columns in the middle of the bed, fewer than 3"
                )
            }
        }
    }
}

/// The dynamic angle of repose of the bed in a drum turning about the axis `axis` through
/// `centre`, gravity along `down`: the inclination of its free surface against the
/// horizontal, in the plane normal to the axis (what a user of a drum fits by hand).
///
/// The bed's centroid lies on the normal to the surface's chord through the drum's centre
/// (exactly so for the circular segment a flat surface cuts): that normal gives a first
/// estimate of the surface's direction. Along that direction, in columns one mean diameter d
/// wide, the highest top of a grain is the surface; the columns of the middle 60 % of the
/// chord (away from the wall, where the surface curves into it) are fitted by least squares,
/// and the fit's slope corrects the estimate. An S-shaped surface (a fast drum) is fitted in
/// its middle, as a straight line.
pub fn drum_angle(
    p: &Particles,
    centre: DVec3,
    axis: DVec3,
    down: DVec3,
) -> Result<SurfaceAngle, NoSurface> {
    if p.len() < 20 {
        return Err(NoSurface::TooFewGrains(p.len()));
    }
    let a = axis.normalize();
    let up = -(down - a * down.dot(a)).normalize();
    let across = up.cross(a);
    let plane = |x: DVec3| glam::DVec2::new((x - centre).dot(across), (x - centre).dot(up));
    let n = p.len() as f64;
    let centroid = (0..p.len()).map(|k| plane(p.x[k])).sum::<glam::DVec2>() / n;
    let inward = -centroid.normalize();
    let along = glam::DVec2::new(inward.y, -inward.x);
    let d = 2.0 * p.radius.iter().sum::<f64>() / n;
    let (sigma, eta): (Vec<f64>, Vec<f64>) = (0..p.len())
        .map(|k| {
            let q = plane(p.x[k]);
            (q.dot(along), q.dot(inward) + p.radius[k])
        })
        .unzip();
    let lo = sigma.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = sigma.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let columns = (((hi - lo) / d).floor() as usize) + 1;
    let mut top = vec![f64::NEG_INFINITY; columns];
    for (s, e) in sigma.iter().zip(&eta) {
        let c = (((s - lo) / d) as usize).min(columns - 1);
        top[c] = top[c].max(*e);
    }
    let middle = (lo + 0.2 * (hi - lo))..(hi - 0.2 * (hi - lo));
    let points: Vec<(f64, f64)> = (0..columns)
        .map(|c| (lo + (c as f64 + 0.5) * d, top[c]))
        .filter(|&(s, t)| middle.contains(&s) && t.is_finite())
        .collect();
    let (slope, error) = fit_slope(&points).ok_or(NoSurface::TooFewColumns(points.len()))?;
    let first = along.y.atan2(along.x);
    let angle = (first + slope.atan()).to_degrees();
    // An inclination against the horizontal, whichever way the surface rises.
    let angle = angle.rem_euclid(180.0);
    Ok(SurfaceAngle {
        angle: if angle > 90.0 { 180.0 - angle } else { angle },
        error: (error / (1.0 + slope * slope)).to_degrees(),
        columns: points.len(),
    })
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
    use crate::model::particles::Particle;

    fn at(x: f64, z: f64, r: f64) -> Particle {
        Particle {
            x: DVec3::new(x, 0.0, z),
            radius: r,
            ..Default::default()
        }
    }

    /// Columns of touching grains (radius r, one diameter apart) up to the surface `top(x)`.
    fn heap(r: f64, xs: std::ops::Range<f64>, top: impl Fn(f64) -> f64) -> Particles {
        let mut p = Particles::default();
        let mut x = xs.start;
        while x < xs.end {
            let mut z = r;
            while z + r <= top(x) {
                p.push(at(x, z, r));
                z += 2.0 * r;
            }
            x += 2.0 * r;
        }
        p
    }

    #[test]
    fn a_triangular_heap_has_its_angles() {
        // Flanks of 40° (left) and 50° (right), 50 diameters tall.
        let r = 0.001;
        let (tl, tr) = (40f64.to_radians().tan(), 50f64.to_radians().tan());
        let p = heap(r, -0.2..0.2, |x| {
            if x < 0.0 { 0.1 + x * tl } else { 0.1 - x * tr }
        });
        let a = angle_of_repose(&p, ReposeWindow::default()).unwrap();
        assert!(
            (a.left.angle - 40.0).abs() < 1.0 && (a.right.angle - 50.0).abs() < 1.0,
            "{a:?}"
        );
        // The staircase of grains is a rough surface: the error is small but not zero, and
        // the true angle lies within a few of it.
        assert!(a.left.error > 0.0 && a.left.error < 0.5, "{a:?}");
        assert!(
            (a.left.angle - 40.0).abs() < 4.0 * a.left.error + 0.2,
            "{a:?}"
        );
        assert!((a.height - 0.1).abs() < 2.0 * r, "{a:?}");
    }

    #[test]
    fn moving_grains_and_the_foot_are_left_out() {
        // A 45° flank whose foot, the last 10 diameters above the floor, curves out to 20°;
        // the window (3 to 25 diameters below the apex of a 40-diameter heap) sees the
        // straight part only.
        let r = 0.001;
        let (d, foot) = (2.0 * r, 10.0 * 2.0 * r);
        let (t45, t20) = (1.0, 20f64.to_radians().tan());
        let p0 = heap(r, -0.2..0.2, |x| {
            let z = 0.08 - x.abs() * t45;
            if z > foot {
                z
            } else {
                foot - (foot - z) * t20 / t45
            }
        });
        let window = ReposeWindow {
            to: 25.0,
            ..ReposeWindow::default()
        };
        let a = angle_of_repose(&p0, window).unwrap();
        assert!((a.left.angle - 45.0).abs() < 1.0, "{a:?}");
        assert!((a.right.angle - 45.0).abs() < 1.0, "{a:?}");
        // Reaching down to the foot, the fit tilts.
        let all = angle_of_repose(&p0, ReposeWindow { to: 40.0, ..window }).unwrap();
        assert!(all.left.angle < a.left.angle - 3.0, "{all:?} {a:?}");
        // Grains of the feed falling above the apex and sliding down a flank are not the pile.
        let mut p = p0.clone();
        for k in 0..30 {
            let mut q = at(0.001 * k as f64, 0.1 + 0.01 * k as f64, r);
            q.v = DVec3::new(0.0, 0.0, -1.0);
            p.push(q);
            let mut s = at(0.02 + 0.002 * k as f64, 0.07, r);
            s.v = DVec3::new(0.5, 0.0, -0.5);
            p.push(s);
        }
        assert_eq!(angle_of_repose(&p, window).unwrap(), a);
        assert!(a.height > 40.0 * d - 2.0 * d, "{a:?}");
    }

    #[test]
    fn no_pile_says_why() {
        let mut gas = heap(0.001, -0.1..0.1, |_| 0.1);
        for k in 0..gas.len() {
            gas.v[k] = DVec3::new(1.0, 0.0, 0.0);
        }
        assert_eq!(
            angle_of_repose(&gas, ReposeWindow::default()),
            Err(NoPile::TooFewResting(0))
        );
        let flat = heap(0.001, -0.1..0.1, |_| 0.01);
        let e = angle_of_repose(&flat, ReposeWindow::default()).unwrap_err();
        assert!(matches!(e, NoPile::ShortFlank { columns: 0, .. }), "{e:?}");
        assert!(e.to_string().contains("flank has 0 columns"), "{e}");
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
        let phi = packing_fraction(&p, &[1000.0]);
        assert!((phi - std::f64::consts::PI / 6.0).abs() < 0.03, "{phi}");
        // A sparse gas has no bulk.
        let mut gas = Particles::default();
        for k in 0..50 {
            gas.push(at(0.1 * k as f64, 0.0, 0.01));
        }
        assert_eq!(packing_fraction(&gas, &[1000.0]), 0.0);
    }

    #[test]
    fn the_surface_of_a_bed_in_a_drum_has_its_angle() {
        // A drum of radius 0.1 along y, half filled below a surface through its axis tilted
        // by 35 degrees (and by 20, falling the other way), grains on a square lattice.
        let r = 0.002;
        for tilt in [35.0f64, -20.0] {
            let t = tilt.to_radians();
            let (normal, mut p) = (glam::DVec2::new(-t.sin(), t.cos()), Particles::default());
            let step = 2.0 * r;
            let n = (0.1 / step) as i32;
            for i in -n..=n {
                for k in -n..=n {
                    let q = glam::DVec2::new(i as f64 * step, k as f64 * step);
                    if q.length() < 0.1 - r && q.dot(normal) < -0.01 {
                        for j in 0..3 {
                            p.push(at(q.x, q.y, r));
                            let last = p.len() - 1;
                            p.x[last].y = j as f64 * step;
                        }
                    }
                }
            }
            let a = drum_angle(&p, DVec3::ZERO, DVec3::Y, DVec3::NEG_Z).unwrap();
            assert!((a.angle - tilt.abs()).abs() < 0.5, "{tilt}: {a:?}");
            assert!(a.columns > 10 && a.error < 1.0, "{a:?}");
        }
        let few = heap(0.001, -0.01..0.01, |_| 0.003);
        assert!(drum_angle(&few, DVec3::ZERO, DVec3::Y, DVec3::NEG_Z).is_err());
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
