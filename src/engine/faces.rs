//! Stage 4 of the step: the contacts of particles with the faces of the mesh, one contact per
//! touch of a surface (`surface.rs`), blocks of the particle-face list in parallel.

use super::*;

/// A face within reach of a particle, in stage 4.
struct Near {
    /// The particle, and the face's slot in the block of the particle-face list.
    owner: u32,
    slot: usize,
    kin: Kinematics,
    /// Separation x - p_F and whether p_F counts as inside the face (see `surface::snap`).
    d: DVec3,
    interior: bool,
}

/// Buffers of one block of the mesh-contact stage.
#[derive(Default)]
struct MeshScratch {
    /// The block's faces within reach.
    near: Vec<Near>,
    /// Which of `near` are contacts of their own, for the law.
    contacts: Vec<u32>,
    /// One particle's faces within reach as candidates, and what becomes of them.
    candidates: Vec<Candidate>,
    order: Vec<usize>,
    fates: Vec<Fate>,
}

/// What stage 4 reads, shared by the tasks of all blocks.
struct FaceStage<'a> {
    p: &'a Particles,
    law: &'a ContactLaw,
    /// The faces, what they belong to and the scales of the loads on them.
    walls: &'a Walls,
    densities: &'a [Density],
    uniform: bool,
    one_wall: Coefficients<Group>,
    scales: &'a LoadScales,
    /// The number of files whose loads are summed (0: none).
    files: usize,
    /// The own particles of a split run.
    owned: Option<&'a [bool]>,
    /// The particle-face list's run starts and faces.
    start: &'a [u32],
    partner: &'a [u32],
}

/// Stage 4 (Sections 2.2, 3.3): the force of every contact of a particle of `p` with a
/// face of `walls` in `list` (the particle-face list), added to the particles' `loads`.
/// Returns what it found, and the step's exact sums of the reactions on each mesh file
/// (of the `owned` particles of a split run; empty unless wall loads are summed).
///
/// Each block of the list holds whole runs of owners. For each particle it finds the
/// faces within reach (closest point, kinematics), decides which of them are contacts
/// of their own (one per touch of a connected surface, `surface.rs`; with `per_face`
/// every face is a surface of its own), hands the springs of the others to the contact
/// that absorbs them, then evaluates the law for `WIDTH` contacts at a time in SIMD
/// lanes (bit for bit as alone).
pub(super) fn run(
    model: &Model,
    p: &Particles,
    (walls, owned): (&Walls, Option<&[bool]>),
    list: &mut ContactList,
    (loads, ledger): (&mut [Load], Option<&mut Vec<LedgerEntry>>),
) -> (Findings, Vec<Sum6>) {
    with_models!(model.law.choice(), M => run_with::<M>(model, p, (walls, owned), list, (loads, ledger)))
}

/// [`run`] with the sub-models `M`.
#[inline(never)] // a stage of its own in profiles
fn run_with<M: Models>(
    model: &Model,
    p: &Particles,
    (walls, owned): (&Walls, Option<&[bool]>),
    list: &mut ContactList,
    (loads, mut ledger): (&mut [Load], Option<&mut Vec<LedgerEntry>>),
) -> (Findings, Vec<Sum6>) {
    let found = Found::new(ledger.as_deref_mut());
    let law = &model.law;
    let ContactList {
        start,
        partner,
        contact,
        blocks: bounds,
        stores,
    } = list;
    let stage = FaceStage {
        p,
        law,
        walls,
        densities: &model.densities,
        uniform: law.uniform(),
        one_wall: law.with_wall(0, 0).splat(),
        scales: &model.scales,
        files: walls.sums.len(),
        owned,
        start,
        partner,
    };
    thread_local! {
        static SCRATCH: std::cell::RefCell<MeshScratch> = Default::default();
    }
    let all = blocks(bounds, loads, start, contact, stores);
    let blocks: Vec<(Vec<Sum6>, bool)> = all
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN.div_ceil(FACE_BLOCK))
        .map(|block| SCRATCH.with_borrow_mut(|scratch| stage.block::<M>(block, scratch, &found)))
        .collect();
    let mut found = found.into_inner(ledger);
    // The blocks' sums of the loads on the mesh files, in order.
    let mut step = vec![Sum6::default(); walls.sums.len()];
    if !step.is_empty() {
        for (block, fine) in blocks {
            found.beyond_range |= !fine;
            for (sum, w) in step.iter_mut().zip(&block) {
                sum.merge(w);
            }
        }
    }
    (found, step)
}

impl Simulation {
    /// A step's sums of the loads on the mesh files (of this process's own particles),
    /// added to the files' sums (over all processes of a split run).
    pub(super) fn add_wall_loads(&mut self, mut step: Vec<Sum6>) {
        if !step.is_empty() {
            self.reduce_walls(&mut step);
            self.walls.add_step(&step);
            let dt = self.scenario.simulation.timestep;
            self.walls.drive_servos(&step, dt);
        }
    }
}

impl FaceStage<'_> {
    /// One block of the particle-face list: its contacts' loads added to its particles',
    /// and the block's sum of the reactions on each mesh file (and whether it was in range).
    #[inline]
    fn block<M: Models>(
        &self,
        block: Block,
        scratch: &mut MeshScratch,
        found: &Found,
    ) -> (Vec<Sum6>, bool) {
        let Block {
            owners,
            first,
            loads,
            contact,
            store,
        } = block;
        let MeshScratch {
            near,
            candidates,
            contacts,
            order,
            fates,
        } = scratch;
        self.near::<M>(owners.clone(), first, contact, store, near);
        self.one_per_touch(
            first,
            (contact, store),
            near,
            (candidates, order, fates),
            contacts,
            found,
        );
        // The law, `WIDTH` contacts at a time (as for particle pairs), added to the
        // particles' loads, and their reactions (of own particles, in a split run) to the
        // block's exact sum for each mesh file.
        let (mut wall, mut wall_fine) = (vec![Sum6::default(); self.files], true);
        for group in contacts.chunks(WIDTH) {
            let loads = (&mut *loads, owners.start);
            let slots = (&mut *contact, &mut *store);
            wall_fine &= self.law_of::<M>((group, near), first, slots, loads, &mut wall, found);
        }
        (wall, wall_fine)
    }

    /// The faces within reach of the particles `owners` (their slots from `first`), each with
    /// its closest point and kinematics, into `near`; the slots of a particle are
    /// consecutive, so are its candidates. A contact that ended forgets its springs; one
    /// beyond touch (JKR, a liquid bridge) lasts while its gap is within the reach.
    #[inline]
    fn near<M: Models>(
        &self,
        owners: std::ops::Range<usize>,
        first: usize,
        contact: &mut [u32],
        store: &mut Store,
        near: &mut Vec<Near>,
    ) {
        near.clear();
        for i in owners {
            let run = self.start[i] as usize..self.start[i + 1] as usize;
            if run.is_empty() {
                continue;
            }
            let body = Body {
                x: self.p.x[i],
                radius: self.p.radius[i],
                v: self.p.v[i],
                w: self.p.w[i],
            };
            for (k, &f) in run.clone().zip(&self.partner[run]) {
                let kl = k - first;
                let face = &self.walls.mesh.faces[f as usize];
                let gap = if M::BEYOND_TOUCH && contact[kl] != NONE {
                    let m = (self.p.material[i], self.walls.face_material[f as usize]);
                    ContactLaw::reach::<M>(self.law.with_wall(m.0, m.1), body.radius)
                } else {
                    0.0
                };
                let touch = if face.certainly_beyond(body.x, body.radius + face.radius + gap) {
                    None
                } else {
                    let wall = self.walls.velocity(f as usize);
                    let (d, feature) = face.separation_and_feature(body.x);
                    let (d, interior) = surface::snap(face, body.x, body.radius, d, feature);
                    Kinematics::with_wall_within(&body, d, face.radius, &wall, gap)
                        .map(|kin| (kin, d, interior))
                };
                match touch {
                    Some((kin, d, interior)) => near.push(Near {
                        owner: i as u32,
                        slot: kl,
                        kin,
                        d,
                        interior,
                    }),
                    None if contact[kl] != NONE => {
                        // The contact ended: forget its history.
                        store.close(contact[kl]);
                        contact[kl] = NONE;
                    }
                    None => {}
                }
            }
        }
    }

    /// One contact per touch, particle by particle, into `contacts` (indices of `near`); the
    /// absorbed hand over their springs and are treated as apart. Deep overlaps go to
    /// `found`.
    #[inline]
    fn one_per_touch(
        &self,
        first: usize,
        (contact, store): (&mut [u32], &mut Store),
        near: &[Near],
        (candidates, order, fates): (&mut Vec<Candidate>, &mut Vec<usize>, &mut Vec<Fate>),
        contacts: &mut Vec<u32>,
        found: &Found,
    ) {
        contacts.clear();
        let mut a = 0;
        while a < near.len() {
            let i = near[a].owner as usize;
            let mut b = a + 1;
            while b < near.len() && near[b].owner as usize == i {
                b += 1;
            }
            let (x, radius) = (self.p.x[i], self.p.radius[i]);
            let several = b - a > 1;
            if several {
                candidates.clear();
                candidates.extend(near[a..b].iter().map(|c| Candidate {
                    face: self.partner[first + c.slot],
                    point: x - c.d,
                    dist2: c.d.length_squared(),
                    interior: c.interior,
                }));
                let tol = surface::tolerance(x, radius);
                surface::resolve(candidates, &self.walls.mesh.faces, tol, order, fates);
                for (c, fate) in near[a..b].iter().zip(fates.iter()) {
                    let Fate::Absorbed(s) = *fate else { continue };
                    let (k, s) = (c.slot, near[a + s].slot);
                    let none = |e: u32| e == NONE || store.state.get(e as usize).is_first_touch();
                    if none(contact[s]) && contact[k] != NONE {
                        if contact[s] == NONE {
                            // The absorbing contact takes over the entry.
                            (contact[s], contact[k]) = (contact[k], NONE);
                        } else {
                            let e = store.state.get(contact[k] as usize);
                            store.state.set(contact[s] as usize, e);
                        }
                    }
                }
            }
            for (c, near) in near[a..b].iter().enumerate() {
                let k = near.slot;
                if !several || fates[c] == Fate::Contact {
                    if near.kin.delta > radius {
                        found.deep.lock().expect("not poisoned").push(Deep {
                            i,
                            other: Against::Face(self.partner[first + k] as usize),
                            delta: near.kin.delta,
                            limit: radius,
                        });
                    }
                    if contact[k] == NONE {
                        contact[k] = store.open();
                    }
                    contacts.push((a + c) as u32);
                } else if contact[k] != NONE {
                    store.close(contact[k]);
                    contact[k] = NONE;
                }
            }
            a = b;
        }
    }

    /// The energy ledger's entries of the contacts of particles `i` with the faces `faces`
    /// in a group's lanes, with the walls' motion at the contact points the law took
    /// (Eq. 26); the first `i.len()` are of the group.
    fn entries(
        &self,
        i: &[usize; WIDTH],
        faces: &[usize; WIDTH],
        (kin, parts): (&Kinematics<Group>, &ContactParts<Group>),
    ) -> [LedgerEntry; WIDTH] {
        let entry = super::pairs::entries(kin, parts);
        std::array::from_fn(|l| {
            let e = entry(l);
            let wall = self.walls.velocity(faces[l]);
            let point = self.p.x[i[l]] - e.n * e.r_i;
            LedgerEntry {
                i: i[l] as u32,
                frame_v: wall.at(point),
                frame_w: wall.omega,
                ..e
            }
        })
    }

    /// The law for one group of `WIDTH` contacts (indices of `near`), added to the loads of
    /// their particles (`loads` from owner `loads.1`) and their reactions to `wall`; whether
    /// the wall sums stayed in range.
    #[inline]
    fn law_of<M: Models>(
        &self,
        (group, near): (&[u32], &[Near]),
        first: usize,
        (contact, store): (&mut [u32], &mut Store),
        (loads, owners_start): (&mut [Load], usize),
        wall: &mut [Sum6],
        found: &Found,
    ) -> bool {
        let mut wall_fine = true;
        let c: [&Near; WIDTH] =
            std::array::from_fn(|l| &near[group[l.min(group.len() - 1)] as usize]);
        let e = c.map(|c| contact[c.slot]);
        let i = c.map(|c| c.owner as usize);
        let scalar = |get: fn(&Kinematics) -> f64| Group::gather(c.map(|c| get(&c.kin)));
        let vector = |get: fn(&Kinematics) -> DVec3| Group::gather_vec(c.map(|c| get(&c.kin)));
        let kin = Kinematics::<Group> {
            n: vector(|k| k.n),
            delta: scalar(|k| k.delta),
            r_i: scalar(|k| k.r_i),
            r_j: scalar(|k| k.r_j),
            v: vector(|k| k.v),
            omega: vector(|k| k.omega),
        };
        let radius = Group::gather(i.map(|i| self.p.radius[i]));
        let (mass, coef) = if self.uniform {
            (
                Inertia::mass_with(radius, Group::splat(self.densities[0].mass_per_r3)),
                self.one_wall,
            )
        } else {
            let m = i.map(|i| self.p.material[i]);
            let f = c.map(|c| self.walls.face_material[self.partner[first + c.slot] as usize]);
            (
                Inertia::mass_with(
                    radius,
                    Group::gather(m.map(|m| self.densities[m as usize].mass_per_r3)),
                ),
                Coefficients::gather(std::array::from_fn(|l| self.law.with_wall(m[l], f[l]))),
            )
        };
        let mass = body_masses(self.p, &i, mass);
        let mut lanes = gather_springs(store, e);
        let (force, parts) =
            self.law
                .compose_parts::<M, _>(&coef, (radius, mass), Other::Wall, &kin, &mut lanes);
        scatter_springs(lanes, store, &e[..group.len()]);
        let faces: [usize; WIDTH] = c.map(|c| self.partner[first + c.slot] as usize);
        found.enter(|| (self.entries(&i, &faces, (&kin, &parts)), group.len()));
        let (f, tau) = (Group::scatter_vec(force.f), Group::scatter_vec(force.tau_i));
        let mut fine = true;
        for l in 0..group.len() {
            let load = &mut loads[i[l] - owners_start];
            fine &= load.add(pack(f[l], tau[l]), &self.scales.lanes);
        }
        if !fine {
            found.beyond.store(true, Ordering::Relaxed);
        }
        if self.files > 0 {
            // The reaction on the mesh file (Newton's third law for the
            // force and for the torque about the file's reference point).
            for l in (0..group.len()).filter(|&l| self.owned.is_none_or(|o| o[i[l]])) {
                let w = self.walls;
                let k = w.face_file[faces[l]] as usize;
                let arm = self.p.x[i[l]] - w.files[k].torque_about;
                let reaction = pack(-f[l], -(arm.cross(f[l]) + tau[l]));
                wall_fine &= wall[k].add(reaction, &w.scales);
            }
        }
        wall_fine
    }
}
