//! Particle spawning (paper Section 3.1): in the `[geometry]` spawn box, or in `[[spawn]]`
//! regions with a count, a rate, a time window, a material, a velocity and a distribution of
//! radii.

use glam::DVec3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rustc_hash::FxHashMap;

use crate::geometry::mesh::Face;
use crate::model::bodies::{Body, BodyId};
use crate::model::particles::{Id, Particle, Particles};
use crate::neighbours::{FaceGrid, Periodic, cell_of, key};
use crate::scenario::{
    ClumpTemplate, RadiusDistribution, Region, Scenario, SpawnClump, SpawnRegion,
};

/// Draws spawn attempts from a seeded random stream, so the same seed gives the same run.
#[derive(Clone, Debug)]
pub struct Spawner {
    rng: ChaCha8Rng,
    /// A radius whose attempt failed, carried over to the next attempt so that the size
    /// distribution is not biased toward small particles (the spawn box's).
    pending_radius: Option<f64>,
    /// What each `[[spawn]]` region has done so far.
    regions: Vec<RegionState>,
    /// The periodic axes of the domain, as they are now (its shear offset), to test
    /// candidates against the images of particles across the sides.
    pub periodic: Option<Periodic>,
    /// The spawn box is off: a stage whose scenario has no `[[spawn]]` region and names no
    /// spawn box spawns nothing (rather than in the paper's default box).
    pub box_off: bool,
}

/// How far a `[[spawn]]` region has got: particles inserted, and its pending radius.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RegionState {
    pub inserted: u64,
    pub pending_radius: Option<f64>,
}

/// Uniform in [lo, hi]; exactly `lo` for a degenerate interval (2D and 1D spawn regions).
fn uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    if hi > lo {
        rng.random_range(lo..=hi)
    } else {
        lo
    }
}

/// A standard normal number (Box-Muller, from two uniform draws).
fn standard_normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = 1.0 - rng.random_range(0.0..1.0); // in (0, 1]
    let u2: f64 = rng.random_range(0.0..1.0);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// A radius drawn from `d`. Truncated distributions draw again outside their bounds (at
/// most a thousand times, then the nearest bound: only for a range far in a tail).
fn draw(rng: &mut ChaCha8Rng, d: &RadiusDistribution) -> f64 {
    let truncated = |rng: &mut ChaCha8Rng, min: f64, max: f64, f: &dyn Fn(f64) -> f64| {
        let mut r = f(standard_normal(rng));
        for _ in 0..1000 {
            if (min..=max).contains(&r) {
                return r;
            }
            r = f(standard_normal(rng));
        }
        r.clamp(min, max)
    };
    match *d {
        RadiusDistribution::Uniform { min, max } => uniform(rng, min, max),
        RadiusDistribution::Normal {
            mean,
            std,
            min,
            max,
        } => truncated(rng, min, max, &|z| mean + std * z),
        RadiusDistribution::LogNormal {
            mean,
            std,
            min,
            max,
        } => {
            let (mu, sigma2) = crate::scenario::log_normal(mean, std);
            truncated(rng, min, max, &|z| (mu + sigma2.sqrt() * z).exp())
        }
        RadiusDistribution::Table {
            ref radii,
            ref weights,
        } => {
            let total: f64 = weights.iter().sum();
            let u = rng.random_range(0.0..1.0) * total;
            let mut sum = 0.0;
            for (r, w) in radii.iter().zip(weights) {
                sum += w;
                if u < sum {
                    return *r;
                }
            }
            *radii.last().expect("at least one radius")
        }
    }
}

/// How many particles region `r` should have inserted by the end of the step at `t`:
/// floor(rate (t + dt - start)), or its count.
fn due(r: &SpawnRegion, dt: f64, t: f64) -> u64 {
    match r.rate {
        Some(rate) => (rate * (t + dt - r.start)).floor() as u64,
        None => u64::MAX,
    }
    .min(r.count.unwrap_or(u64::MAX))
}

/// The position of a spawner in its random stream, for checkpoints.
#[derive(Clone, Debug, PartialEq)]
pub struct SpawnerState {
    pub word_pos: u128,
    pub pending_radius: Option<f64>,
    pub regions: Vec<RegionState>,
    pub box_off: bool,
}

/// The particles of `particles` from index `from` on at temperature `t`, if particles hold
/// temperatures (heat transfer).
fn warm(particles: &mut Particles, from: usize, t: f64) {
    if particles.active.temperature {
        particles.temperature[from..].fill(t);
    }
}

/// What one insertion draws from and where it puts its particles.
struct Source<'a> {
    region: Region,
    radius: &'a RadiusDistribution,
    velocity: DVec3,
    material: u16,
    /// Clumps instead of spheres.
    clump: Option<SpawnClump>,
}

impl Spawner {
    pub fn state(&self) -> SpawnerState {
        SpawnerState {
            word_pos: self.rng.get_word_pos(),
            pending_radius: self.pending_radius,
            regions: self.regions.clone(),
            box_off: self.box_off,
        }
    }

    /// A spawner for `seed` continued at `state`.
    pub fn resume(seed: u64, state: SpawnerState) -> Self {
        let mut s = Spawner::new(seed);
        s.rng.set_word_pos(state.word_pos);
        s.pending_radius = state.pending_radius;
        s.regions = state.regions;
        s.box_off = state.box_off;
        s
    }

    pub fn new(seed: u64) -> Self {
        Spawner {
            rng: ChaCha8Rng::seed_from_u64(seed),
            pending_radius: None,
            regions: Vec::new(),
            periodic: None,
            box_off: false,
        }
    }

    /// Particles inserted by each `[[spawn]]` region so far.
    pub fn inserted(&self) -> Vec<u64> {
        self.regions.iter().map(|r| r.inserted).collect()
    }

    /// The `[[spawn]]` regions that made fewer than they were asked for by time `t`, its
    /// count or its rate over its window, `next_id` particles having been made: said, with
    /// the likely cause (every try overlapped a wall or a grain, or `max_particles` ran out).
    pub fn shortfalls(&self, s: &Scenario, next_id: Id, t: f64) -> Vec<String> {
        let dt = s.simulation.timestep;
        (s.spawn.iter().enumerate())
            .filter(|(_, r)| t >= r.start)
            .filter_map(|(k, r)| {
                let made = self.regions.get(k).map_or(0, |st| st.inserted);
                let asked = due(r, dt, t.min(r.stop) - dt);
                let spheres = r
                    .clump
                    .map_or(1, |c| s.clumps[c.template as usize].spheres.len());
                let capped = next_id + spheres as u64 > s.simulation.max_particles;
                (made < asked).then(|| {
                    let what = if r.clump.is_some() {
                        "clumps"
                    } else {
                        "particles"
                    };
                    let why = if capped {
                        format!(
                            "[simulation] max_particles = {} was reached",
                            s.simulation.max_particles
                        )
                    } else {
                        "its tries overlapped a wall or other grains (a region on a wall, or \
                         full?)"
                            .to_string()
                    };
                    format!("[[spawn]] #{} made {made} of {asked} {what}: {why}", k + 1)
                })
            })
            .collect()
    }

    /// Whether a step at time `t` would try to spawn, `next_id` particles having been made.
    pub fn active(&self, s: &Scenario, next_id: Id, t: f64) -> bool {
        if s.simulation.spawn_attempts == 0 || next_id >= s.simulation.max_particles {
            return false;
        }
        if s.spawn.is_empty() {
            return !self.box_off;
        }
        s.spawn.iter().enumerate().any(|(k, r)| {
            let inserted = self.regions.get(k).map_or(0, |st| st.inserted);
            t >= r.start && t < r.stop && inserted < due(r, s.simulation.timestep, t)
        })
    }

    /// Whether no step from time `t` on will spawn, `next_id` particles having been made:
    /// `N_max` reached, or every `[[spawn]]` region past its `stop` or its `count` (the
    /// spawn box tries until `N_max`).
    pub fn finished(&self, s: &Scenario, next_id: Id, t: f64) -> bool {
        if s.simulation.spawn_attempts == 0 || next_id >= s.simulation.max_particles {
            return true;
        }
        if s.spawn.is_empty() && self.box_off {
            return true;
        }
        !s.spawn.is_empty()
            && s.spawn.iter().enumerate().all(|(k, r)| {
                let inserted = self.regions.get(k).map_or(0, |st| st.inserted);
                t >= r.stop || r.count.is_some_and(|n| inserted >= n)
            })
    }

    /// The boxes spawned into: the `[[spawn]]` regions, or the spawn box.
    pub fn regions(s: &Scenario) -> Vec<Region> {
        if s.spawn.is_empty() {
            vec![Region {
                min: s.geometry.spawn_min,
                max: s.geometry.spawn_max,
            }]
        } else {
            s.spawn.iter().map(|r| r.region).collect()
        }
    }

    /// One step of spawning at time `t` (the step ends at `t + dt`), until `N_max`
    /// particles have been created (those removed since included). Without `[[spawn]]`
    /// regions: up to `N_spawn` attempts in the spawn box, each with a uniform centre and a
    /// uniform radius in [R_min, R_max] (the paper's). With regions: each active one (from
    /// `start` until `stop`) makes up to `N_spawn` attempts until it has inserted what its
    /// rate asks for by the end of the step (floor(rate (t + dt - start))) or its count. An
    /// attempt is rejected if the sphere would overlap a particle or a mesh face. Returns
    /// the number of particles added. `present` is the largest radius of the particles
    /// that exist (`particles` may hold only those near the regions: a process's share).
    #[allow(clippy::too_many_arguments)]
    pub fn spawn(
        &mut self,
        s: &Scenario,
        particles: &mut Particles,
        faces: &[Face],
        face_grid: &FaceGrid,
        t: f64,
        present: f64,
    ) -> usize {
        let max = s.simulation.max_particles;
        let attempts = s.simulation.spawn_attempts;
        if attempts == 0 || particles.next_id >= max || (s.spawn.is_empty() && self.box_off) {
            return 0;
        }
        if s.spawn.is_empty() {
            let from = particles.len();
            let n = self.spawn_in_box(s, particles, faces, face_grid, present);
            warm(
                particles,
                from,
                s.materials[0].properties.thermal.initial_temperature,
            );
            return n;
        }
        self.regions.resize(s.spawn.len(), RegionState::default());
        let dt = s.simulation.timestep;
        let mut added = 0;
        for (k, r) in s.spawn.iter().enumerate() {
            if t < r.start || t >= r.stop {
                continue;
            }
            let due = due(r, dt, t);
            let state = self.regions[k];
            if state.inserted >= due {
                continue;
            }
            let source = Source {
                region: r.region,
                radius: &r.radius,
                velocity: r.velocity,
                material: r.material,
                clump: r.clump,
            };
            let mut pending = state.pending_radius;
            let from = particles.len();
            let insert = if r.clump.is_some() {
                Spawner::insert_clumps
            } else {
                Spawner::insert
            };
            let n = insert(
                self,
                s,
                &source,
                attempts,
                due - state.inserted,
                &mut pending,
                (particles, present),
                faces,
                face_grid,
            );
            // (A clump's spheres are of its template's material.)
            let material = r
                .clump
                .map_or(r.material, |c| s.clumps[c.template as usize].material);
            let t0 = s.materials[material as usize]
                .properties
                .thermal
                .initial_temperature;
            warm(particles, from, r.temperature.unwrap_or(t0));
            self.regions[k] = RegionState {
                inserted: state.inserted + n,
                pending_radius: pending,
            };
            added += n as usize;
        }
        added
    }

    /// Spawns in the `[geometry]` spawn box (a scenario without `[[spawn]]` regions): radii
    /// uniform in [R_min, R_max], material 0.
    fn spawn_in_box(
        &mut self,
        s: &Scenario,
        particles: &mut Particles,
        faces: &[Face],
        face_grid: &FaceGrid,
        present: f64,
    ) -> usize {
        let (g, attempts) = (&s.geometry, s.simulation.spawn_attempts);
        let uniform = RadiusDistribution::Uniform {
            min: g.radius_min,
            max: g.radius_max,
        };
        let source = Source {
            region: Region {
                min: g.spawn_min,
                max: g.spawn_max,
            },
            radius: &uniform,
            velocity: s.kinetics.initial_velocity,
            material: 0,
            clump: None,
        };
        let mut pending = self.pending_radius;
        let n = self.insert(
            s,
            &source,
            attempts,
            u64::MAX,
            &mut pending,
            (particles, present),
            faces,
            face_grid,
        );
        self.pending_radius = pending;
        n as usize
    }

    /// Up to `attempts` attempts to insert at most `budget` particles from `source`
    /// (and no more than `N_max` created in all); `pending` is the radius carried over
    /// from a failed attempt. Returns how many it inserted.
    #[allow(clippy::too_many_arguments)]
    fn insert(
        &mut self,
        s: &Scenario,
        source: &Source,
        attempts: u64,
        budget: u64,
        pending: &mut Option<f64>,
        (particles, present): (&mut Particles, f64),
        faces: &[Face],
        face_grid: &FaceGrid,
    ) -> u64 {
        let max = s.simulation.max_particles;
        // A grid of the particles that a sphere in the region could touch, grown as
        // particles are added.
        let h = 2.0
            * s.geometry
                .radius_max
                .max(particles.max_radius())
                .max(present);
        let mut crowd = Crowd::of(particles, &source.region, h, self.periodic);
        let (lo, hi) = (source.region.min, source.region.max);
        let mut inserted = 0;
        for _ in 0..attempts {
            if particles.next_id >= max || inserted >= budget {
                break;
            }
            let radius = match *pending {
                Some(r) => r,
                None => draw(&mut self.rng, source.radius),
            };
            let x = DVec3::new(
                uniform(&mut self.rng, lo.x, hi.x),
                uniform(&mut self.rng, lo.y, hi.y),
                uniform(&mut self.rng, lo.z, hi.z),
            );
            let free =
                crowd.free(particles, x, radius) && clear_of_faces((faces, face_grid), x, radius);
            if !free {
                *pending = Some(radius);
                continue;
            }
            *pending = None;
            crowd.add(x, particles.len());
            particles.push(Particle {
                x,
                radius,
                v: source.velocity,
                w: s.kinetics.initial_angular_velocity,
                material: source.material,
                ..Particle::default() // unrotated, untagged, free
            });
            inserted += 1;
        }
        inserted
    }
}

impl Spawner {
    /// As [`Spawner::insert`], for a region that inserts clumps: each attempt draws a scale
    /// (`pending` carries a failed attempt's over), an orientation uniform over rotations
    /// and a centre, and is rejected if any of the clump's spheres would overlap a particle
    /// or a face. A clump of one sphere is inserted as a plain sphere. Returns how many
    /// clumps it inserted.
    #[allow(clippy::too_many_arguments)]
    fn insert_clumps(
        &mut self,
        s: &Scenario,
        source: &Source,
        attempts: u64,
        budget: u64,
        pending: &mut Option<f64>,
        (particles, present): (&mut Particles, f64),
        faces: &[Face],
        face_grid: &FaceGrid,
    ) -> u64 {
        let clump = source.clump.expect("a clump region");
        let t = &s.clumps[clump.template as usize];
        let max = s.simulation.max_particles;
        let h = 2.0
            * s.geometry
                .radius_max
                .max(particles.max_radius())
                .max(present);
        let reach = t.bounding_radius * clump.scale.1;
        let near = Region {
            min: source.region.min - DVec3::splat(reach),
            max: source.region.max + DVec3::splat(reach),
        };
        let mut crowd = Crowd::of(particles, &near, h, self.periodic);
        let (lo, hi) = (source.region.min, source.region.max);
        let mut inserted = 0;
        for _ in 0..attempts {
            if particles.next_id + t.spheres.len() as u64 > max || inserted >= budget {
                break;
            }
            let scale = match *pending {
                Some(f) => f,
                None => uniform(&mut self.rng, clump.scale.0, clump.scale.1),
            };
            let q = uniform_rotation(&mut self.rng);
            let x = DVec3::new(
                uniform(&mut self.rng, lo.x, hi.x),
                uniform(&mut self.rng, lo.y, hi.y),
                uniform(&mut self.rng, lo.z, hi.z),
            );
            let spheres: Vec<(DVec3, f64)> = (t.spheres.iter())
                .map(|sp| (x + q * (sp.centre * scale), sp.radius * scale))
                .collect();
            let free = spheres.iter().all(|&(at, radius)| {
                crowd.free(particles, at, radius) && clear_of_faces((faces, face_grid), at, radius)
            });
            if !free {
                *pending = Some(scale);
                continue;
            }
            *pending = None;
            let first = particles.len();
            for (k, &(at, _)) in spheres.iter().enumerate() {
                crowd.add(at, first + k);
            }
            let motion = (x, q, source.velocity, s.kinetics.initial_angular_velocity);
            place_clump(particles, (t, clump.template), scale, motion);
            inserted += 1;
        }
        inserted
    }
}

/// Adds a clump of template `t` (its index `template`) scaled by `scale`, with its centre of
/// mass at `x`, orientation `q`, velocity `v` and angular velocity `w` (`motion`): a rigid
/// body of its spheres, or a plain sphere for a template of one sphere (which moves as a
/// body of it would).
pub(crate) fn place_clump(
    particles: &mut Particles,
    (t, template): (&ClumpTemplate, u16),
    scale: f64,
    (x, q, v, w): (DVec3, glam::DQuat, DVec3, DVec3),
) {
    let sphere = Particle {
        v,
        w,
        q,
        material: t.material,
        ..Particle::default()
    };
    if let [one] = t.spheres[..] {
        let (at, radius) = (x + q * (one.centre * scale), one.radius * scale);
        particles.push(Particle {
            x: at,
            radius,
            ..sphere
        });
        return;
    }
    let radii: Vec<f64> = t.spheres.iter().map(|s| s.radius * scale).collect();
    let body = Body {
        id: BodyId::new(0), // set by push_body
        template,
        scale,
        x,
        v,
        q,
        w,
        mass: t.mass * scale.powi(3),
        inertia: t.inertia * scale.powi(5),
        offsets: t.spheres.iter().map(|sp| sp.centre * scale).collect(),
        bounding_radius: t.bounding_radius * scale,
    };
    particles.push_body(body, &radii, sphere);
}

/// Whether a sphere at `x` of `radius` keeps clear of the `faces` (binned in `face_grid`).
fn clear_of_faces((faces, face_grid): (&[Face], &FaceGrid), x: DVec3, radius: f64) -> bool {
    face_grid.at(x).iter().all(|&f| {
        let face = &faces[f as usize];
        let reach = radius + face.radius;
        face.separation(x).length_squared() >= reach * reach
    })
}

/// A rotation uniform over all rotations (Shoemake's subgroup algorithm, 1992).
pub(crate) fn uniform_rotation(rng: &mut ChaCha8Rng) -> glam::DQuat {
    let (u1, u2, u3) = (
        uniform(rng, 0.0, 1.0),
        uniform(rng, 0.0, std::f64::consts::TAU),
        uniform(rng, 0.0, std::f64::consts::TAU),
    );
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    glam::DQuat::from_xyzw(a * u2.sin(), a * u2.cos(), b * u3.sin(), b * u3.cos()).normalize()
}

/// The particles a sphere spawned in a region could touch, binned in cells of edge `h`
/// (twice the largest radius), with their images in a periodic domain.
struct Crowd {
    cells: FxHashMap<u64, Vec<u32>>,
    h: f64,
    inv_h: f64,
    periodic: Option<Periodic>,
    shifts: Vec<(DVec3, i8)>,
}

impl Crowd {
    /// The particles within `h` of `region` (all of them in a periodic domain, where a
    /// sphere may touch the images of particles near the far side).
    fn of(particles: &Particles, region: &Region, h: f64, periodic: Option<Periodic>) -> Crowd {
        let near = Region {
            min: region.min - DVec3::splat(h),
            max: region.max + DVec3::splat(h),
        };
        let mut crowd = Crowd {
            cells: FxHashMap::default(),
            h,
            inv_h: 1.0 / h,
            periodic,
            shifts: Vec::new(),
        };
        for (i, &x) in particles.x.iter().enumerate() {
            let x = crowd.wrap(x);
            if periodic.is_some() || near.contains(x) {
                crowd.add_wrapped(x, i);
            }
        }
        crowd
    }

    fn wrap(&self, x: DVec3) -> DVec3 {
        self.periodic.map_or(x, |p| p.wrap(x))
    }

    fn add_wrapped(&mut self, x: DVec3, i: usize) {
        self.cells
            .entry(key(cell_of(x, self.inv_h)))
            .or_default()
            .push(i as u32);
    }

    /// Adds particle `i`, placed at `x`.
    fn add(&mut self, x: DVec3, i: usize) {
        self.add_wrapped(self.wrap(x), i);
    }

    /// Whether a sphere at `at` of `radius` overlaps one of the particles (at their
    /// wrapped places).
    fn overlaps(&self, particles: &Particles, at: DVec3, radius: f64) -> bool {
        let c = cell_of(at, self.inv_h);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let Some(list) = self.cells.get(&key(c + glam::IVec3::new(dx, dy, dz))) else {
                        continue;
                    };
                    for &j in list {
                        let j = j as usize;
                        let reach = radius + particles.radius[j];
                        if (at - self.wrap(particles.x[j])).length_squared() < reach * reach {
                            return true;
                        }
                    }
                }
            }
        }
        false
    }

    /// Whether a sphere at `x` of `radius` is clear of every particle and, in a periodic
    /// domain, of their images.
    fn free(&mut self, particles: &Particles, x: DVec3, radius: f64) -> bool {
        let mut free = !self.overlaps(particles, x, radius);
        if free && let Some(p) = self.periodic {
            let at = self.wrap(x);
            let mut shifts = std::mem::take(&mut self.shifts);
            p.image_shifts(at, self.h, &mut shifts);
            free = shifts
                .iter()
                .all(|&(s, _)| !self.overlaps(particles, at + s, radius));
            self.shifts = shifts;
        }
        free
    }
}
