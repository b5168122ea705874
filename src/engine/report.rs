//! What the run reports of its state: the contact network and the numbers of `log.csv`
//! (`Thermo`), over all processes of a split run.

use super::*;
use crate::parallel::comm::Reach;

impl Simulation {
    /// The contact network at the current state: every touching particle pair and
    /// particle-face contact (as the last step resolved them) with the force the law gives
    /// it now, from its current springs (left unchanged): the forces the next step applies.
    /// Pairs by (lower id, higher id), then contacts with faces by (id, face).
    pub fn contact_network(&self) -> Vec<ContactRecord> {
        self.contact_network_to(Reach::Everyone)
    }

    /// [`Simulation::contact_network`] on the processes `reach` names (collective in a
    /// split run); the others get none.
    pub(crate) fn contact_network_to(&self, reach: Reach) -> Vec<ContactRecord> {
        // Each contact from the process that owns its particle (of a pair, the lower id).
        let network = self.own_contact_network();
        match &self.share {
            Some(d) => super::split::gather_contacts((&*d.comm, reach), network),
            None => network,
        }
    }

    /// This process's piece of the contact network of a split run (the contacts of its own
    /// particles, of a pair the lower id's), in the order of [`Simulation::contact_network`];
    /// the whole network in one process.
    pub fn own_contact_network(&self) -> Vec<ContactRecord> {
        let mut network = self.held_contact_network();
        if let Some(own) = self.own_ids() {
            network.retain(|c| own.contains(&c.id));
        }
        network
    }

    /// The contacts of the particles this process holds (own and ghosts): in a split run,
    /// every contact of an own particle is among them.
    pub fn held_contacts(&self) -> Vec<ContactRecord> {
        self.held_contact_network()
    }

    /// The contact network of the particles this process holds (own and ghosts).
    pub(super) fn held_contact_network(&self) -> Vec<ContactRecord> {
        let mut out = Vec::new();
        self.each_held_contact(|i, other, kin, coef, springs, with| {
            out.push(self.record(i, other, kin, coef, springs, with));
        });
        out.sort_by_key(ContactRecord::network_order);
        out
    }

    /// `each` open contact of the particles this process holds, at the current state
    /// (particle i, the other body, the kinematics, the pair's coefficients, the springs
    /// and the partner): the pairs within the box, and across periodic sides with the
    /// partner at its image, each from the lower id; then the contacts with mesh faces,
    /// the face moving as its part does. An open contact may lie beyond touch (JKR, a
    /// liquid bridge), within its reach.
    pub(super) fn each_held_contact(
        &self,
        mut each: impl FnMut(usize, Other, &Kinematics, &Coefficients, Springs, Partner),
    ) {
        let p = &self.particles;
        let nb = &self.neighbours;
        let within = open_contacts(&nb.pairs).into_iter().map(|(a, b, s, _)| {
            let (i, j) = if p.id[a] < p.id[b] { (a, b) } else { (b, a) };
            (i, j, s, DVec3::ZERO, DVec3::ZERO)
        });
        let across = open_contacts(&nb.wrapped).into_iter().map(|(a, b, s, k)| {
            let (i, j, shift, dv) = nb.across(&p.id, a, b, k);
            (i, j, s, shift, dv)
        });
        for (i, j, springs, shift, dv) in within.chain(across) {
            let bj = Body {
                x: p.x[j] + shift,
                v: p.v[j] + dv,
                ..self.body_of(j)
            };
            let coef = self.model.law.pair(p.material[i], p.material[j]);
            let r_star = p.radius[i] * p.radius[j] / (p.radius[i] + p.radius[j]);
            let gap = self.model.law.reach_of(coef, r_star);
            let Some(kin) = Kinematics::between_particles_within(&self.body_of(i), &bj, gap) else {
                continue;
            };
            let other = Other::Particle {
                r: p.radius[j],
                m: self.mass_of(j),
            };
            each(i, other, &kin, coef, springs, Partner::Particle(p.id[j]));
        }
        for (i, f, springs, _) in open_contacts(&self.neighbours.faces) {
            let face = &self.walls.mesh.faces[f];
            let wall = self.walls.velocity(f);
            let b = self.body_of(i);
            let (d, feature) = face.separation_and_feature(b.x);
            let (d, _) = surface::snap(face, b.x, b.radius, d, feature);
            let coef = self
                .model
                .law
                .with_wall(p.material[i], self.walls.face_material[f]);
            let gap = self.model.law.reach_of(coef, b.radius);
            let Some(kin) = Kinematics::with_wall_within(&b, d, face.radius, &wall, gap) else {
                continue;
            };
            each(i, Other::Wall, &kin, coef, springs, Partner::Face(f));
        }
    }

    pub(super) fn mass_of(&self, k: usize) -> f64 {
        self.model.mass(&self.particles, k)
    }

    fn body_of(&self, k: usize) -> Body {
        let p = &self.particles;
        Body {
            x: p.x[k],
            radius: p.radius[k],
            v: p.v[k],
            w: p.w[k],
        }
    }

    /// The record of particle `i`'s contact with `other`: the force the law gives it now,
    /// from a copy of its springs (the springs themselves left unchanged).
    fn record(
        &self,
        i: usize,
        other: Other,
        kin: &Kinematics,
        coef: &Coefficients,
        mut springs: Springs,
        with: Partner,
    ) -> ContactRecord {
        let p = &self.particles;
        let force =
            self.model
                .law
                .evaluate(coef, p.radius[i], self.mass_of(i), other, kin, &mut springs);
        let f_n = kin.n * kin.n.dot(force.f);
        ContactRecord {
            id: p.id[i],
            with,
            point: p.x[i] - kin.n * kin.r_i,
            f_n,
            f_t: force.f - f_n,
            overlap: kin.delta,
            tau_i: force.tau_i,
            tau_j: match with {
                Partner::Particle(_) => force.tau_j,
                Partner::Face(_) => DVec3::ZERO,
            },
        }
    }

    /// Each grain's id with its kinetic energies of translation and rotation, in id order:
    /// a plain sphere, or a rigid body (once, by its first sphere); of all processes.
    pub(super) fn grain_energies(&self) -> Vec<(Id, f64, f64)> {
        let p = &self.particles;
        let mut energies: Vec<(Id, f64, f64)> = (0..p.len())
            .filter(|&k| self.own(k) && p.body[k].is_none())
            .map(|k| {
                let m = Inertia::mass_with(
                    p.radius[k],
                    self.model.densities[p.material[k] as usize].mass_per_r3,
                );
                let i = 0.4 * m * p.radius[k] * p.radius[k];
                (
                    p.id[k],
                    0.5 * m * p.v[k].length_squared(),
                    0.5 * i * p.w[k].length_squared(),
                )
            })
            .collect();
        energies.extend(p.bodies_where(|k| self.own(k)).map(|b| {
            let b = &p.bodies.list[b];
            let (t, r) = b.kinetic_energy();
            (b.id.first(), t, r)
        }));
        if let Some(d) = &self.share {
            // Over all processes, still in id order.
            use crate::parallel::comm::{Reader, Writer};
            let mut w = Writer::default();
            for &(id, t, r) in &energies {
                w.u64(id);
                w.f64(t);
                w.f64(r);
            }
            energies.clear();
            for m in d.comm.all_gather(w.0) {
                let mut r = Reader::new(&m);
                while !r.done() {
                    energies.push((r.u64(), r.f64(), r.f64()));
                }
            }
        }
        energies.sort_unstable_by_key(|e| e.0);
        energies
    }

    /// What the status line and `log.csv` report of the current state, as LAMMPS's thermo
    /// output does: the energies (summed in id order, so the same for any storage order),
    /// the contacts of the last step and the deepest of them relative to the smaller radius.
    pub fn thermo(&self) -> Thermo {
        let p = &self.particles;
        let energies = self.grain_energies();
        let (translational, rotational) = energies
            .iter()
            .fold((0.0, 0.0), |(t, r), e| (t + e.1, r + e.2));
        let radius_of: rustc_hash::FxHashMap<Id, f64> =
            p.id.iter().copied().zip(p.radius.iter().copied()).collect();
        let own = self.own_ids();
        let mut thermo = Thermo {
            particles: energies.len(),
            kinetic_energy: translational + rotational,
            rotational_energy: rotational,
            removed: self.removed.count(),
            ..Thermo::default()
        };
        for c in self.held_contact_network() {
            if own.as_ref().is_some_and(|own| !own.contains(&c.id)) {
                continue; // told by the process that owns it
            }
            let r = radius_of[&c.id];
            let smaller = match c.with {
                Partner::Particle(j) => {
                    thermo.pair_contacts += 1;
                    r.min(radius_of[&(j as Id)])
                }
                Partner::Face(_) => {
                    thermo.wall_contacts += 1;
                    r
                }
            };
            thermo.max_overlap = thermo.max_overlap.max(c.overlap / smaller);
        }
        if let Some(d) = &self.share {
            let counts = d
                .comm
                .sum_i64(&[thermo.pair_contacts as i64, thermo.wall_contacts as i64]);
            (thermo.pair_contacts, thermo.wall_contacts) = (counts[0] as usize, counts[1] as usize);
            thermo.max_overlap = d.comm.max(thermo.max_overlap);
        }
        thermo.heat = self.temperatures();
        thermo.energy = self.balance(thermo.kinetic_energy);
        thermo
    }
}

/// Each open contact of `list`: owner, partner, springs and slot.
fn open_contacts(list: &ContactList) -> Vec<(usize, usize, Springs, usize)> {
    let mut v = Vec::new();
    for block in 0..list.blocks.len().saturating_sub(1) {
        let store = &list.stores[block];
        for i in list.blocks[block] as usize..list.blocks[block + 1] as usize {
            for k in list.run(i) {
                if list.contact[k] != NONE {
                    let springs = store.state.springs[list.contact[k] as usize];
                    v.push((i, list.partner[k] as usize, springs, k));
                }
            }
        }
    }
    v
}
