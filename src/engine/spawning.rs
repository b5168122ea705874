//! Stage 1 (Section 3.1): new particles in the spawn box or the `[[spawn]]` regions, made
//! by the `Spawner` (`spawn.rs`): into the particles of a one-process run, or, in a split
//! run, among the particles of all processes near the regions, each process keeping those
//! in its box.

use glam::DVec3;
use rustc_hash::FxHashSet;

use super::Simulation;
use super::spawn::Spawner;
use super::split::{centre_in_box, owner_places};
use crate::model::particles::{Id, Particles};
use crate::parallel::comm::Reach;
use crate::parallel::decomposition::{Placement, gather_by_id};

impl Simulation {
    /// Stage 1 (Section 3.1): new particles in the spawn box or the `[[spawn]]` regions
    /// (collective in a split run).
    #[inline(never)] // a stage of its own in profiles
    pub(super) fn spawn(&mut self) {
        if self.share.is_some() {
            return self.spawn_among_all();
        }
        let s = &self.scenario;
        if self.particles.next_id < s.simulation.max_particles {
            self.spawner.spawn(
                s,
                &mut self.particles,
                &self.walls.mesh.faces,
                &self.face_grid,
                self.time,
                0.0,
            );
        }
    }

    /// Stage 1 of a split run (collective): every process draws the same candidates and
    /// tests them against the particles of all processes near the spawn regions; each keeps
    /// the new particles in its box.
    fn spawn_among_all(&mut self) {
        let s = &self.scenario;
        let p = &self.particles;
        if !self.spawner.active(s, p.next_id, self.time) {
            return;
        }
        let d = self.share.as_ref().expect("a split run");
        let mut largest = s.geometry.radius_max;
        // How far a clump's spheres reach beyond its centre, which is in the region.
        let mut beyond: f64 = 0.0;
        for r in &s.spawn {
            largest = largest.max(r.radius.largest());
            if let Some(c) = &r.clump {
                beyond = beyond.max(s.clumps[c.template as usize].bounding_radius * c.scale.1);
            }
        }
        let own_max = (0..p.len())
            .filter(|&i| d.owned[i])
            .map(|i| p.radius[i])
            .fold(0.0, f64::max);
        let present = d.comm.max(own_max).max(0.0);
        // Twice the largest radius is the reach of a test; a little more keeps rounding
        // (of images across the sides) from leaving out a particle at that reach.
        let margin = DVec3::splat(2.5 * largest.max(present) + beyond);
        let regions = Spawner::regions(s);
        let in_reach = |x: DVec3| {
            regions
                .iter()
                .any(|r| x.cmpge(r.min - margin).all() && x.cmple(r.max + margin).all())
        };
        // In a periodic domain, also the particles whose images are near (the spawner sees
        // them through the sides).
        let periodic = self.spawner.periodic;
        let mut images = Vec::new();
        let mut near = |x: DVec3| match periodic {
            None => in_reach(x),
            Some(periodic) => {
                let x = periodic.wrap(x);
                periodic.image_shifts(x, margin.x, &mut images);
                in_reach(x) || images.iter().any(|&(s, _)| in_reach(x + s))
            }
        };
        let mut picked: Vec<bool> = (0..p.len()).map(|i| d.owned[i] && near(p.x[i])).collect();
        // A rigid body whole, if any of its spheres is near.
        for b in 0..p.bodies.len() {
            let members = p.bodies.members(b);
            if members.iter().any(|&k| picked[k as usize]) {
                members.iter().for_each(|&k| picked[k as usize] = true);
            }
        }
        let old_next = p.next_id;
        let mut around = gather_by_id((&*d.comm, Reach::Everyone), p, |i| picked[i]);
        self.spawner.spawn(
            s,
            &mut around,
            &self.walls.mesh.faces,
            &self.face_grid,
            self.time,
            present,
        );
        if around.next_id == old_next {
            return;
        }
        self.keep_spawned(&around, old_next);
        self.particles.next_id = around.next_id;
        self.redistribute(&FxHashSet::default(), Placement::Now);
    }

    /// The particles of ids from `first` in `around` (spawned on every process) that are in
    /// this process's box: a rigid body whole, by its centre.
    fn keep_spawned(&mut self, around: &Particles, first: Id) {
        let d = self.share.as_mut().expect("a split run");
        let tree = d.tree.as_ref().expect("cut");
        let me = d.comm.rank();
        let periodic = self.neighbours.periodic;
        let at = owner_places(around, &around.x, periodic);
        for i in (0..around.len()).filter(|&i| around.id[i] >= first) {
            if tree.owner(at[i]) == me {
                self.particles.insert(around.id[i], around.get(i));
                d.owned.push(true);
            }
        }
        for b in &around.bodies.list {
            if b.id.first() >= first && tree.owner(centre_in_box(b, periodic)) == me {
                self.particles.bodies.insert(b.clone());
            }
        }
        self.particles.locate_bodies();
    }

    /// Particles inserted by each `[[spawn]]` region so far.
    pub fn spawned(&self) -> Vec<u64> {
        let mut n = self.spawner.inserted();
        n.resize(self.scenario.spawn.len(), 0);
        n
    }

    /// The `[[spawn]]` regions that have made fewer particles than they were asked for so
    /// far, each said with its likely cause (see [`Spawner::shortfalls`]).
    pub fn spawn_shortfalls(&self) -> Vec<String> {
        (self.spawner).shortfalls(&self.scenario, self.particles.next_id, self.time)
    }
}
