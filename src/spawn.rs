//! Particle spawning in a box (paper Section 3.1).

use glam::{DQuat, DVec3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rustc_hash::FxHashMap;

use crate::mesh::Face;
use crate::neighbours::{CellGrid, cell_of, key};
use crate::particles::{Particle, Particles};
use crate::scenario::Scenario;

/// Draws spawn attempts from a seeded random stream, so the same seed gives the same run.
#[derive(Clone, Debug)]
pub struct Spawner {
    rng: ChaCha8Rng,
    /// A radius whose attempt failed, carried over to the next attempt so that the size
    /// distribution is not biased toward small particles.
    pending_radius: Option<f64>,
}

/// Uniform in [lo, hi]; exactly `lo` for a degenerate interval (2D and 1D spawn regions).
fn uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    if hi > lo {
        rng.random_range(lo..=hi)
    } else {
        lo
    }
}

/// The position of a spawner in its random stream, for checkpoints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpawnerState {
    pub word_pos: u128,
    pub pending_radius: Option<f64>,
}

impl Spawner {
    pub fn state(&self) -> SpawnerState {
        SpawnerState {
            word_pos: self.rng.get_word_pos(),
            pending_radius: self.pending_radius,
        }
    }

    /// A spawner for `seed` continued at `state`.
    pub fn resume(seed: u64, state: SpawnerState) -> Self {
        let mut s = Spawner::new(seed);
        s.rng.set_word_pos(state.word_pos);
        s.pending_radius = state.pending_radius;
        s
    }

    pub fn new(seed: u64) -> Self {
        Spawner {
            rng: ChaCha8Rng::seed_from_u64(seed),
            pending_radius: None,
        }
    }

    /// Makes up to `N_spawn` attempts (until `N_max` particles have been created, those
    /// removed since included): a uniform centre in
    /// the spawn box and a uniform radius in [R_min, R_max], rejected if the sphere would
    /// overlap a particle or a mesh face. Returns the number of particles added.
    pub fn spawn(
        &mut self,
        s: &Scenario,
        particles: &mut Particles,
        faces: &[Face],
        face_grid: &CellGrid,
    ) -> usize {
        let g = &s.geometry;
        let max = s.simulation.max_particles as usize;
        if s.simulation.spawn_attempts == 0 || particles.next_id as usize >= max {
            return 0;
        }
        // A grid of the current particles, grown as particles are added.
        let h = 2.0 * g.radius_max.max(particles.max_radius());
        let inv_h = 1.0 / h;
        let mut cells: FxHashMap<u64, Vec<u32>> = FxHashMap::default();
        for (i, &x) in particles.x.iter().enumerate() {
            cells
                .entry(key(cell_of(x, inv_h)))
                .or_default()
                .push(i as u32);
        }

        let before = particles.len();
        for _ in 0..s.simulation.spawn_attempts {
            if particles.next_id as usize >= max {
                break;
            }
            let radius = match self.pending_radius {
                Some(r) => r,
                None => uniform(&mut self.rng, g.radius_min, g.radius_max),
            };
            let x = DVec3::new(
                uniform(&mut self.rng, g.spawn_min.x, g.spawn_max.x),
                uniform(&mut self.rng, g.spawn_min.y, g.spawn_max.y),
                uniform(&mut self.rng, g.spawn_min.z, g.spawn_max.z),
            );
            let c = cell_of(x, inv_h);
            let mut free = true;
            'cells: for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let Some(list) = cells.get(&key(c + glam::IVec3::new(dx, dy, dz))) else {
                            continue;
                        };
                        for &j in list {
                            let j = j as usize;
                            let reach = radius + particles.radius[j];
                            if (x - particles.x[j]).length_squared() < reach * reach {
                                free = false;
                                break 'cells;
                            }
                        }
                    }
                }
            }
            free = free
                && face_grid.at(x).iter().all(|&f| {
                    let face = &faces[f as usize];
                    let reach = radius + face.radius;
                    face.separation(x).length_squared() >= reach * reach
                });
            if !free {
                self.pending_radius = Some(radius);
                continue;
            }
            self.pending_radius = None;
            cells
                .entry(key(c))
                .or_default()
                .push(particles.len() as u32);
            particles.push(Particle {
                x,
                radius,
                v: s.kinetics.initial_velocity,
                q: DQuat::IDENTITY,
                w: s.kinetics.initial_angular_velocity,
                tag: 0,
                material: 0,
            });
        }
        particles.len() - before
    }
}
