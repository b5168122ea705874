//! Changes to a simulation from outside its step (Python's setters, `add`, `remove`): the
//! particles placed, added or removed between steps, and the lists made to fit.

use super::*;

/// Whether particles added from outside the step may overlap others deeply.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Overlap {
    /// More than [`DEEPEST_ADDED`] of the smaller radius is refused.
    Refused,
    Allowed,
}

/// The deepest overlap of an added particle with another or a face that is taken without
/// being asked for (`Overlap::Allowed`), as a fraction of the smaller radius: a packing made
/// elsewhere may overlap a little; deeper, the contact law throws the grains apart.
pub const DEEPEST_ADDED: f64 = 0.1;

impl Simulation {
    /// After particles were moved from outside the step: the lists are made anew at the
    /// next step (with the springs of the contacts they keep).
    pub fn particles_moved(&mut self) {
        self.neighbours.forget_anchors();
    }

    /// Adds `new` particles with the next ids (returned); the lists take them in at the
    /// next step. Their materials must be the scenario's.
    pub fn add_particles(
        &mut self,
        new: &[crate::model::particles::Particle],
        overlap: Overlap,
    ) -> Result<Vec<Id>> {
        self.refuse_split("add particles")?;
        let n = self.scenario.materials.len();
        if let Some(p) = new.iter().find(|p| p.material as usize >= n) {
            bail!(
                "material {} is not one of the scenario's {n} (0 to {})",
                p.material,
                n - 1
            );
        }
        let g = &self.scenario.geometry;
        let (lo, hi) = (g.radius_min, g.radius_max);
        if let Some(k) = new.iter().position(|p| !(lo..=hi).contains(&p.radius)) {
            bail!(
                "radius {} of particle {k} is outside [geometry] radius_min..radius_max = \
                 {lo}..{hi} (the neighbour lists are made for those)",
                new[k].radius
            );
        }
        if overlap == Overlap::Refused {
            let spheres: Vec<(DVec3, f64)> = new.iter().map(|p| (p.x, p.radius)).collect();
            self.refuse_deep_overlaps(&spheres, false)?;
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
        overlap: Overlap,
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
        let q = q.normalize();
        if overlap == Overlap::Refused {
            let spheres: Vec<(DVec3, f64)> = (t.spheres.iter())
                .map(|s| (x + q * (scale * s.centre), scale * s.radius))
                .collect();
            self.refuse_deep_overlaps(&spheres, true)?;
        }
        let first = self.particles.next_id;
        let motion = (x, q, v, w);
        spawn::place_clump(&mut self.particles, (t, template as u16), scale, motion);
        self.particles_moved();
        Ok(first)
    }

    /// Refuses new spheres `(centre, radius)` that would overlap a particle present, a mesh
    /// face or (unless they are the spheres of one clump, `one_body`) one another by more
    /// than [`DEEPEST_ADDED`] of the smaller radius: the contact law would throw them apart.
    fn refuse_deep_overlaps(&self, new: &[(DVec3, f64)], one_body: bool) -> Result<()> {
        let p = &self.particles;
        let reach = 2.0
            * p.max_radius()
                .max(new.iter().map(|s| s.1).fold(0.0, f64::max));
        let mut x: Vec<DVec3> = p.x.clone();
        let mut radius: Vec<f64> = p.radius.clone();
        if !one_body {
            x.extend(new.iter().map(|s| s.0));
            radius.extend(new.iter().map(|s| s.1));
        }
        let grid = crate::neighbours::CellGrid::of_points(&x, reach.max(f64::MIN_POSITIVE));
        let name = |j: usize| match j.checked_sub(p.len()) {
            None => format!("particle {}", p.id[j]),
            Some(k) => format!("new particle {k}"),
        };
        for (k, &(at, r)) in new.iter().enumerate() {
            if !(at.is_finite() && r.is_finite()) {
                bail!("particle {k}: its place and radius must be finite");
            }
            let mut found = None;
            grid.for_each_near(at, |j| {
                let j = j as usize;
                let gap = at.distance(x[j]) - r - radius[j];
                let other = j != p.len() + k;
                if found.is_none() && other && gap < -DEEPEST_ADDED * r.min(radius[j]) {
                    found = Some((j, -gap / r.min(radius[j])));
                }
            });
            if let Some((j, depth)) = found {
                bail!(
                    "new particle {k} would overlap {} by {:.0} % of the smaller radius",
                    name(j),
                    100.0 * depth
                );
            }
            for &f in self.face_grid.at(at).iter() {
                let face = &self.walls.mesh.faces[f as usize];
                let gap = face.separation(at).length() - r - face.radius;
                if gap < -DEEPEST_ADDED * r {
                    bail!(
                        "new particle {k} would overlap mesh face {f} by {:.0} % of its radius",
                        -100.0 * gap / r
                    );
                }
            }
        }
        Ok(())
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
        if self.share.is_some() {
            bail!("a run split over processes cannot {what} from outside its step");
        }
        Ok(())
    }
}
