//! The simulation: state and the time step as named stages.
//!
//! ```text
//! step:  spawn -> update neighbours -> particle contacts -> mesh contacts -> integrate
//! ```

use anyhow::{Result, bail};
use glam::DVec3;
use rayon::prelude::*;

use crate::contact::{Body, ContactForce, ContactLaw, Kinematics, Other, Springs};
use crate::integrate::{Inertia, State, advance};
use crate::mesh::Mesh;
use crate::neighbours::{CellGrid, MIN_PARALLEL_LEN, Neighbours, face_grid};
use crate::particles::Particles;
use crate::scenario::{MeshSource, Scenario};
use crate::spawn::Spawner;

/// Resets the springs of a pair that is not touching (writing only if needed).
#[inline]
fn forget(springs: &mut Springs) {
    if *springs != Springs::default() {
        *springs = Springs::default();
    }
}

/// Verlet skin as a fraction of R_min.
const SKIN_PER_RADIUS: f64 = 0.25;

/// A running simulation.
pub struct Simulation {
    pub scenario: Scenario,
    pub particles: Particles,
    pub mesh: Mesh,
    law: ContactLaw,
    neighbours: Neighbours,
    face_grid: CellGrid,
    spawner: Spawner,
    /// Force of each particle pair slot and each particle-face slot, this step.
    pair_forces: Vec<ContactForce>,
    face_forces: Vec<ContactForce>,
    /// Simulated time [T] and number of steps taken.
    pub time: f64,
    pub steps: u64,
}

impl Simulation {
    /// Sets up a simulation: reads the mesh and the initial particles.
    pub fn new(scenario: Scenario) -> Result<Simulation> {
        let radii = &scenario.geometry.mesh_radii;
        let mesh = match &scenario.geometry.mesh {
            MeshSource::None => Mesh::default(),
            MeshSource::File(path) => Mesh::load_off(path, radii)?,
            MeshSource::Embedded { name, text } => Mesh::parse_off(text, name, radii)?,
        };
        let particles = match &scenario.particles {
            Some(path) => crate::csv::load_particles(path)?,
            None => Particles::default(),
        };
        Simulation::from_parts(scenario, mesh, particles)
    }

    /// Sets up a simulation from a mesh and particles already in memory.
    pub fn from_parts(scenario: Scenario, mesh: Mesh, particles: Particles) -> Result<Simulation> {
        let g = &scenario.geometry;
        let max_radius = g.radius_max.max(particles.max_radius());
        if particles.len() as u64 > u32::MAX as u64 / 2 {
            bail!("too many particles: {}", particles.len());
        }
        let skin = SKIN_PER_RADIUS * g.radius_min;
        let face_grid = face_grid(&mesh.faces, max_radius, skin);
        Ok(Simulation {
            law: ContactLaw::new(&scenario.material, scenario.simulation.timestep),
            neighbours: Neighbours::new(skin),
            face_grid,
            spawner: Spawner::new(scenario.simulation.seed),
            pair_forces: Vec::new(),
            face_forces: Vec::new(),
            time: 0.0,
            steps: 0,
            scenario,
            particles,
            mesh,
        })
    }

    /// Number of neighbour-list rebuilds so far.
    pub fn rebuilds(&self) -> u64 {
        self.neighbours.rebuilds
    }

    /// Number of listed particle pairs and particle-face pairs (Verlet list slots).
    pub fn list_slots(&self) -> (usize, usize) {
        (self.neighbours.pairs.slots(), self.neighbours.faces.slots())
    }

    /// Number of particle-particle and particle-face contacts in the last step.
    pub fn contact_count(&self) -> usize {
        let touching = |f: &ContactForce| *f != ContactForce::default();
        self.pair_forces.iter().filter(|f| touching(f)).count()
            + self.face_forces.iter().filter(|f| touching(f)).count()
    }

    /// Advances the simulation by one time step Δt.
    pub fn step(&mut self) {
        self.spawn();
        self.update_neighbours();
        self.particle_contacts();
        self.mesh_contacts();
        self.integrate();
        self.steps += 1;
        self.time = self.steps as f64 * self.scenario.simulation.timestep;
    }

    /// Stage 1 (Section 3.1): new particles in the spawn box.
    fn spawn(&mut self) {
        let s = &self.scenario;
        if self.particles.len() < s.simulation.max_particles as usize {
            self.spawner
                .spawn(s, &mut self.particles, &self.mesh.faces, &self.face_grid);
        }
    }

    /// Stage 2 (Section 3.3): rebuild the Verlet lists when they may miss a contact.
    fn update_neighbours(&mut self) {
        let p = &self.particles;
        if self.neighbours.stale(&p.x) {
            self.neighbours
                .rebuild(&p.x, &p.radius, &self.mesh.faces, &self.face_grid);
        }
    }

    /// Stage 3 (Section 2.2): the force of every touching particle pair, once per pair.
    fn particle_contacts(&mut self) {
        let p = &self.particles;
        let law = &self.law;
        let density = self.scenario.material.density;
        let list = &mut self.neighbours.pairs;
        self.pair_forces
            .resize(list.partner.len(), ContactForce::default());
        self.pair_forces
            .par_iter_mut()
            .zip(list.springs.par_iter_mut())
            .zip(list.owner.par_iter().zip(list.partner.par_iter()))
            .with_min_len(MIN_PARALLEL_LEN)
            .for_each(|((force, springs), (&i, &j))| {
                let (i, j) = (i as usize, j as usize);
                let body = |k: usize| Body {
                    x: p.x[k],
                    radius: p.radius[k],
                    v: p.v[k],
                    w: p.w[k],
                };
                *force = match Kinematics::between_particles(&body(i), &body(j)) {
                    Some(kin) => {
                        let other = Other::Particle {
                            r: p.radius[j],
                            m: Inertia::mass(p.radius[j], density),
                        };
                        let m_i = Inertia::mass(p.radius[i], density);
                        law.evaluate(p.radius[i], m_i, other, &kin, springs)
                    }
                    None => {
                        forget(springs); // the contact ended: forget its history
                        ContactForce::default()
                    }
                };
            });
    }

    /// Stage 4 (Sections 2.2, 3.3): the force of every touching particle-face pair.
    fn mesh_contacts(&mut self) {
        let p = &self.particles;
        let law = &self.law;
        let faces = &self.mesh.faces;
        let density = self.scenario.material.density;
        let list = &mut self.neighbours.faces;
        self.face_forces
            .resize(list.partner.len(), ContactForce::default());
        self.face_forces
            .par_iter_mut()
            .zip(list.springs.par_iter_mut())
            .zip(list.owner.par_iter().zip(list.partner.par_iter()))
            .with_min_len(MIN_PARALLEL_LEN)
            .for_each(|((force, springs), (&i, &f))| {
                let i = i as usize;
                let face = &faces[f as usize];
                let body = Body {
                    x: p.x[i],
                    radius: p.radius[i],
                    v: p.v[i],
                    w: p.w[i],
                };
                let d = face.separation(body.x);
                *force = match Kinematics::with_wall(&body, d, face.radius) {
                    Some(kin) => {
                        let m_i = Inertia::mass(p.radius[i], density);
                        law.evaluate(p.radius[i], m_i, Other::Wall, &kin, springs)
                    }
                    None => {
                        forget(springs);
                        ContactForce::default()
                    }
                };
            });
    }

    /// Stage 5 (Section 2.3): sum each particle's contact forces and torques (Eqs. 1-2,
    /// with the reactions of Eqs. 56-60) and advance it by Δt.
    fn integrate(&mut self) {
        let s = &self.scenario;
        let (dt, g) = (s.simulation.timestep, s.kinetics.gravity);
        let (density, viscosity) = (s.material.density, s.material.viscosity);
        let nb = &self.neighbours;
        let (pair_forces, face_forces) = (&self.pair_forces, &self.face_forces);
        let p = &mut self.particles;
        (
            p.x.par_iter_mut(),
            p.v.par_iter_mut(),
            p.q.par_iter_mut(),
            p.w.par_iter_mut(),
            p.radius.par_iter(),
        )
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .enumerate()
            .for_each(|(i, (x, v, q, w, &radius))| {
                let mut f = DVec3::ZERO;
                let mut tau = DVec3::ZERO;
                let own = nb.pairs.start[i] as usize..nb.pairs.start[i + 1] as usize;
                for c in &pair_forces[own] {
                    f += c.f;
                    tau += c.tau_i;
                }
                let reverse = nb.reverse_start[i] as usize..nb.reverse_start[i + 1] as usize;
                for &slot in &nb.reverse_slot[reverse] {
                    let c = &pair_forces[slot as usize];
                    f -= c.f; // Eqs. (56), (57)
                    tau += c.tau_j; // Eqs. (58)-(60)
                }
                let faces = nb.faces.start[i] as usize..nb.faces.start[i + 1] as usize;
                for c in &face_forces[faces] {
                    f += c.f;
                    tau += c.tau_i;
                }
                let body = Inertia::new(radius, density, viscosity);
                advance(State { x, v, q, w }, &body, f, tau, g, dt);
            });
    }
}
