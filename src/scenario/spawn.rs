//! Validation of `[[spawn]]` regions: their boxes (inside the domain), materials, rates and
//! windows, and radius distributions within [R_min, R_max].

use anyhow::{Result, bail};
use glam::DVec3;

use super::raw::*;
use super::validate::{Range, check, check_vec, region};
use super::*;

/// `[[spawn]]`, each inside the domain, or the `[geometry]` spawn box inside it when
/// there are none.
pub(super) fn spawn(
    raw: Vec<RawSpawn>,
    index: &dyn Fn(&str, &str) -> Result<u16>,
    (clumps, materials): (&[ClumpTemplate], &[MaterialSpec]),
    kinetics: &Kinetics,
    geometry: &Geometry,
    simulation: &SimulationTable,
    domain: Option<Region>,
) -> Result<Vec<SpawnRegion>> {
    let (radius_min, radius_max) = (geometry.radius_min, geometry.radius_max);
    let spawn = raw
        .into_iter()
        .enumerate()
        .map(|(k, r)| {
            spawn_region(
                &format!("[[spawn]] #{}", k + 1),
                r,
                &index,
                (clumps, materials),
                kinetics.initial_velocity,
                (radius_min, radius_max),
            )
        })
        .collect::<Result<Vec<_>>>()?;
    for (k, r) in spawn.iter().enumerate() {
        if let Some(d) = domain
            && !(d.contains(r.region.min) && d.contains(r.region.max))
        {
            bail!(
                "[[spawn]] #{} box {} .. {} must lie inside [domain] {} .. {}",
                k + 1,
                r.region.min,
                r.region.max,
                d.min,
                d.max
            );
        }
    }
    if geometry.spawn_box_named
        && let Some(why) = box_outside(geometry, simulation, domain)
    {
        bail!("{why}");
    }
    Ok(spawn)
}

/// Why the spawn box (with no `[[spawn]]` regions) cannot be spawned in: it reaches out of
/// the domain (a named box is refused at once; the default one only by a run that would
/// spawn in it, not by a stage, which spawns in no box it does not name).
pub(super) fn box_outside(
    g: &Geometry,
    simulation: &SimulationTable,
    domain: Option<Region>,
) -> Option<String> {
    let d = domain?;
    let spawning = simulation.max_particles > 0 && simulation.spawn_attempts > 0;
    if !spawning || d.contains(g.spawn_min) && d.contains(g.spawn_max) {
        return None;
    }
    let default = if g.spawn_box_named {
        ""
    } else {
        " (the paper's default, as the scenario names no spawn box: name one, add [[spawn]] \
         regions, or set [simulation] max_particles = 0)"
    };
    Some(format!(
        "[geometry] spawn box {} .. {} must lie inside [domain] {} .. {} (particles spawned \
         outside it would be removed at once){default}",
        g.spawn_min, g.spawn_max, d.min, d.max
    ))
}

/// Validates one `[[spawn]]` region: `index` finds a material by name, `velocity` is the
/// default initial velocity, radii must lie in [R_min, R_max] (`radii`).
fn spawn_region(
    key: &str,
    r: RawSpawn,
    index: &dyn Fn(&str, &str) -> Result<u16>,
    (clumps, materials): (&[ClumpTemplate], &[MaterialSpec]),
    velocity: DVec3,
    radii: (f64, f64),
) -> Result<SpawnRegion> {
    let k = |name: &str| format!("{key} {name}");
    let region = region(
        key,
        RawBox {
            min: r.min,
            max: r.max,
        },
        false,
    )?;
    let clump = match &r.clump {
        Some(name) => {
            if r.radius.is_some() || r.material.is_some() {
                bail!(
                    "{key} clump = \"{name}\" takes its spheres and material from [[clumps]]: \
                     leave out radius and material"
                );
            }
            Some(super::clumps::spawned(key, name, r.scale, clumps, radii)?)
        }
        None if r.scale.is_some() => {
            bail!("{key} scale applies to clumps: it needs clump = \"name\"")
        }
        None => None,
    };
    let material = (r.material.as_ref())
        .map(|name| index(&k("material"), name))
        .transpose()?
        .unwrap_or(0);
    let velocity = (r
        .velocity
        .map(|v| check_vec(&k("velocity"), v))
        .transpose()?)
    .unwrap_or(velocity);
    let temperature = super::heat::temperature(&k("temperature"), r.temperature)?;
    let rate = r
        .rate
        .map(|x| check(&k("rate"), x, Range::Positive))
        .transpose()?;
    let radius = Radii {
        key,
        lo: radii.0,
        hi: radii.1,
    }
    .distribution(r.radius)?;
    let count = match (r.count, r.volume_fraction) {
        (Some(_), Some(_)) => {
            bail!("{key} has a count and a volume_fraction: give one of them")
        }
        (None, Some(phi)) => {
            let grain = match clump {
                Some(c) => clump_volume(c, clumps, materials),
                None => 4.0 / 3.0 * std::f64::consts::PI * radius.mean_cube(),
            };
            Some(count_of(key, phi, region, grain)?)
        }
        (n, None) => n,
    };
    if count.is_none() && rate.is_none() {
        bail!(
            "{key} needs a count (particles in all), a volume_fraction (of its box, as many \
             particles as make it) or a rate (particles per second)"
        );
    }
    let (start, stop) = window(&k, r.start, r.stop)?;
    Ok(SpawnRegion {
        region,
        material,
        velocity,
        temperature,
        count,
        rate,
        start,
        stop,
        radius,
        clump,
    })
}

/// A region's window `start`..`stop` [s] (default: always), `stop` after `start`.
fn window(k: &dyn Fn(&str) -> String, start: Option<f64>, stop: Option<f64>) -> Result<(f64, f64)> {
    let start = check(&k("start"), start.unwrap_or(0.0), Range::NonNegative)?;
    let stop = match stop {
        Some(t) => check(&k("stop"), t, Range::NonNegative)?,
        None => f64::INFINITY,
    };
    if stop <= start {
        bail!("{} = {stop} must be after start = {start}", k("stop"));
    }
    Ok((start, stop))
}

/// The mean volume of a clump of `c`: its template's mass over its material's density, times
/// the mean cube of a scale uniform in its range.
fn clump_volume(c: SpawnClump, clumps: &[ClumpTemplate], materials: &[MaterialSpec]) -> f64 {
    let t = &clumps[c.template as usize];
    let volume = t.mass / materials[t.material as usize].properties.density;
    let (a, b) = c.scale;
    let scale_cubed = if b > a {
        (b.powi(4) - a.powi(4)) / (4.0 * (b - a))
    } else {
        a.powi(3)
    };
    volume * scale_cubed
}

/// The count of grains of mean volume `grain` that fill the fraction `phi` of `region` (as
/// LIGGGHTS's `insert/pack` with `volumefraction_region`).
fn count_of(key: &str, phi: f64, region: Region, grain: f64) -> Result<u64> {
    if !(phi > 0.0 && phi < 1.0) {
        bail!("{key} volume_fraction = {phi} is not allowed: it must be in (0, 1)");
    }
    let volume = (region.max - region.min).element_product();
    if volume <= 0.0 {
        bail!(
            "{key} volume_fraction = {phi}: its box {} .. {} has no volume to fill (give a count)",
            region.min,
            region.max
        );
    }
    Ok(((phi * volume / grain).round() as u64).max(1))
}

/// The radius distribution of a `[[spawn]]` region (`key`), its radii within
/// [R_min, R_max] = [`lo`, `hi`].
struct Radii<'a> {
    key: &'a str,
    lo: f64,
    hi: f64,
}

impl Radii<'_> {
    fn k(&self, name: &str) -> String {
        format!("{} {name}", self.key)
    }

    /// A radius `radius.name` within [R_min, R_max].
    fn within(&self, name: &str, x: f64) -> Result<f64> {
        let (lo, hi) = (self.lo, self.hi);
        let x = check(&self.k(&format!("radius.{name}")), x, Range::Positive)?;
        if x < lo || x > hi {
            bail!(
                "{} = {x} must lie within [geometry] radius_min = {lo} and radius_max = {hi}",
                self.k(&format!("radius.{name}"))
            );
        }
        Ok(x)
    }

    /// The truncation `min`, `max` (default R_min, R_max).
    fn bounds(&self, min: Option<f64>, max: Option<f64>) -> Result<(f64, f64)> {
        let (min, max) = (
            self.within("min", min.unwrap_or(self.lo))?,
            self.within("max", max.unwrap_or(self.hi))?,
        );
        if max < min {
            bail!("{} = {max} must be >= min = {min}", self.k("radius.max"));
        }
        Ok((min, max))
    }

    /// The `mean` and `std` of a distribution (of the radius, or `log`-normal) truncated to
    /// [`min`, `max`], which must hold at least 1 % of it: the sampler draws again outside
    /// and gives up after 1,000 draws (at 1 % that happens once in about 20,000 radii).
    fn spread(&self, mean: f64, std: f64, (min, max): (f64, f64), log: bool) -> Result<(f64, f64)> {
        let mean = check(&self.k("radius.mean"), mean, Range::Positive)?;
        let std = check(&self.k("radius.std"), std, Range::NonNegative)?;
        if std == 0.0 && (mean < min || mean > max) {
            bail!(
                "{} = {mean} must lie within [{min}, {max}]",
                self.k("radius.mean")
            );
        }
        let inside = if std == 0.0 {
            1.0
        } else if log {
            // ln R ~ N(mu, sigma^2) with the mean and deviation of R.
            let sigma = (1.0 + (std / mean).powi(2)).ln().sqrt();
            let mu = mean.ln() - 0.5 * sigma * sigma;
            normal_cdf((max.ln() - mu) / sigma) - normal_cdf((min.ln() - mu) / sigma)
        } else {
            normal_cdf((max - mean) / std) - normal_cdf((min - mean) / std)
        };
        if inside < 0.01 {
            bail!(
                "{}: the distribution (mean {mean}, std {std}) puts only {inside:.1e} of its radii within [{min}, {max}], where they are drawn; move the mean or widen the bounds",
                self.k("radius")
            );
        }
        Ok((mean, std))
    }

    /// A table of radii with weights by number (default all 1).
    fn table(&self, radii: Vec<f64>, weights: Option<Vec<f64>>) -> Result<RadiusDistribution> {
        if radii.is_empty() {
            bail!("{} must hold at least one radius", self.k("radius.radii"));
        }
        for (i, &x) in radii.iter().enumerate() {
            self.within(&format!("radii[{i}]"), x)?;
        }
        let weights = weights.unwrap_or_else(|| vec![1.0; radii.len()]);
        if weights.len() != radii.len() {
            bail!(
                "{} has {} entries, radii {}: one weight per radius",
                self.k("radius.weights"),
                weights.len(),
                radii.len()
            );
        }
        for (i, &w) in weights.iter().enumerate() {
            check(
                &self.k(&format!("radius.weights[{i}]")),
                w,
                Range::NonNegative,
            )?;
        }
        let total: f64 = weights.iter().sum();
        if total <= 0.0 {
            bail!("{} must not all be zero", self.k("radius.weights"));
        }
        Ok(RadiusDistribution::Table { radii, weights })
    }

    /// The distribution `raw` gives (default uniform in [R_min, R_max]).
    fn distribution(&self, raw: Option<RawRadius>) -> Result<RadiusDistribution> {
        Ok(match raw {
            None => RadiusDistribution::Uniform {
                min: self.lo,
                max: self.hi,
            },
            Some(RawRadius::Uniform { min, max }) => {
                let (min, max) = self.bounds(min, max)?;
                RadiusDistribution::Uniform { min, max }
            }
            Some(RawRadius::Normal {
                mean,
                std,
                min,
                max,
            }) => {
                let (min, max) = self.bounds(min, max)?;
                let (mean, std) = self.spread(mean, std, (min, max), false)?;
                RadiusDistribution::Normal {
                    mean,
                    std,
                    min,
                    max,
                }
            }
            Some(RawRadius::Lognormal {
                mean,
                std,
                min,
                max,
            }) => {
                let (min, max) = self.bounds(min, max)?;
                let (mean, std) = self.spread(mean, std, (min, max), true)?;
                RadiusDistribution::LogNormal {
                    mean,
                    std,
                    min,
                    max,
                }
            }
            Some(RawRadius::Table { radii, weights }) => self.table(radii, weights)?,
        })
    }
}

/// The standard normal distribution function, to 1.5e-7 (Abramowitz & Stegun 7.1.26 for
/// erf).
fn normal_cdf(x: f64) -> f64 {
    let z = x.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * z);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erf = 1.0 - poly * (-z * z).exp();
    if x >= 0.0 {
        0.5 * (1.0 + erf)
    } else {
        0.5 * (1.0 - erf)
    }
}

#[cfg(test)]
mod tests {
    use super::normal_cdf;

    #[test]
    fn the_normal_distribution_function_has_its_known_values() {
        for (x, p) in [
            (0.0, 0.5),
            (1.0, 0.841_344_746),
            (-1.96, 0.024_997_895),
            (3.0, 0.998_650_102),
        ] {
            assert!((normal_cdf(x) - p).abs() < 2e-7, "{x}: {}", normal_cdf(x));
        }
    }
}
