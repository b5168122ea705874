//! Changes to a simulation from outside its step (Python's setters, `add`, `remove`): the
//! particles placed, added or removed between steps, and the lists made to fit.

use super::*;

impl Simulation {
    /// After particles were moved from outside the step: the lists are made anew at the
    /// next step (with the springs of the contacts they keep).
    pub fn particles_moved(&mut self) {
        self.neighbours.forget_anchors();
    }

    /// Adds `new` particles with the next ids (returned); the lists take them in at the
    /// next step. Their materials must be the scenario's.
    pub fn add_particles(&mut self, new: &[crate::model::particles::Particle]) -> Result<Vec<Id>> {
        self.refuse_split("add particles")?;
        let n = self.scenario.materials.len();
        if let Some(p) = new.iter().find(|p| p.material as usize >= n) {
            bail!(
                "material {} is not one of the scenario's {n} (0 to {})",
                p.material,
                n - 1
            );
        }
        let first = self.particles.next_id;
        for p in new {
            self.particles.push(*p);
        }
        self.particles_moved();
        Ok((first..self.particles.next_id).collect())
    }

    /// Adds a clump of `[[clumps]]` template `template`, its lengths scaled by `scale`, with
    /// its centre of mass at `x`, orientation `q` (body to world), velocity `v` and angular
    /// velocity `w`; returns the id of its first sphere (the body's id). Overlaps are not
    /// checked; the lists take it in at the next step.
    pub fn add_clump(
        &mut self,
        template: usize,
        scale: f64,
        (x, q, v, w): (DVec3, glam::DQuat, DVec3, DVec3),
    ) -> Result<Id> {
        self.refuse_split("add clumps")?;
        let Some(t) = self.scenario.clumps.get(template) else {
            bail!(
                "there is no clump template {template} ({} in [[clumps]])",
                self.scenario.clumps.len()
            );
        };
        if !(scale > 0.0 && scale.is_finite()) {
            bail!("scale = {scale} must be finite and > 0");
        }
        if !(q.length() > 0.0 && q.is_finite() && x.is_finite() && v.is_finite() && w.is_finite()) {
            bail!(
                "a clump's position, orientation and velocities must be finite, the orientation not zero"
            );
        }
        let first = self.particles.next_id;
        let motion = (x, q.normalize(), v, w);
        spawn::place_clump(&mut self.particles, (t, template as u16), scale, motion);
        self.particles_moved();
        Ok(first)
    }

    /// Removes the particles of `ids` (each must be present) and the springs of their
    /// contacts; the others keep theirs. Not counted as outflow.
    pub fn remove_particles(&mut self, ids: &[Id]) -> Result<()> {
        self.refuse_split("remove particles")?;
        let mut gone = self.stored_at(ids)?;
        // A sphere of a clump takes its whole body with it.
        let p = &self.particles;
        for k in gone.clone() {
            if let Some(b) = p.body[k as usize] {
                let b = p.bodies.index_of(b).expect("a listed body");
                gone.extend_from_slice(p.bodies.members(b));
            }
        }
        gone.sort_unstable();
        gone.dedup();
        self.drop_stored(&gone);
        Ok(())
    }

    /// Fixes the particles of `ids` (each must be present): from the next step they stay
    /// where they are, at rest; or, with `fixed` false, lets them move again. A sphere of a
    /// clump fixes (or frees) its clump whole.
    pub fn fix_particles(&mut self, ids: &[Id], fixed: bool) -> Result<()> {
        self.refuse_split("fix particles")?;
        let mut at = self.stored_at(ids)?;
        let p = &mut self.particles;
        for k in at.clone() {
            if let Some(b) = p.body[k as usize] {
                let b = p.bodies.index_of(b).expect("a listed body");
                at.extend_from_slice(p.bodies.members(b));
                if fixed {
                    let body = &mut p.bodies.list[b];
                    (body.v, body.w) = (DVec3::ZERO, DVec3::ZERO);
                }
            }
        }
        for k in at {
            let k = k as usize;
            p.fixed[k] = fixed;
            if fixed {
                (p.v[k], p.w[k]) = (DVec3::ZERO, DVec3::ZERO);
            }
        }
        Ok(())
    }

    /// Removes the particles stored at `gone` (ascending, each once) and the springs of
    /// their contacts, and makes the lists anew for the others.
    pub(super) fn drop_stored(&mut self, gone: &[u32]) {
        self.neighbours.rebuild_without(
            &mut self.particles,
            gone,
            &self.walls.mesh.faces,
            &self.face_grid,
        );
        self.built();
    }

    /// The storage index of each particle of `ids` (each must be present).
    fn stored_at(&self, ids: &[Id]) -> Result<Vec<u32>> {
        let at: rustc_hash::FxHashMap<Id, u32> = (self.particles.id.iter().enumerate())
            .map(|(k, &id)| (id, k as u32))
            .collect();
        ids.iter()
            .map(|id| match at.get(id) {
                Some(&k) => Ok(k),
                None => bail!("there is no particle {id}"),
            })
            .collect()
    }

    fn refuse_split(&self, what: &str) -> Result<()> {
        if self.domain.is_some() {
            bail!("a run split over processes cannot {what} from outside its step");
        }
        Ok(())
    }
}
