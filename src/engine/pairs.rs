//! Stage 3 of the step: the contacts between particles, blocks of the pair list in parallel,
//! the law evaluated for groups of pairs in lanes, the loads summed exactly; and the pairs
//! across periodic sides.

use super::*;

/// Two distinct elements of a slice, mutably.
fn pair_mut<T>(v: &mut [T], a: usize, b: usize) -> (&mut T, &mut T) {
    assert_ne!(a, b);
    if a < b {
        let (lo, hi) = v.split_at_mut(b);
        (&mut lo[a], &mut hi[0])
    } else {
        let (lo, hi) = v.split_at_mut(a);
        (&mut hi[0], &mut lo[b])
    }
}

/// What stage 3 reads, shared by the tasks of all slabs.
struct PairStage<'a> {
    p: &'a Particles,
    law: &'a ContactLaw,
    densities: &'a [Density],
    /// One material: the same coefficients and density in every lane, set up once.
    uniform: bool,
    one_pair: Coefficients<Group>,
    scales: &'a LoadScales,
    /// The pair list's run starts and partners.
    start: &'a [u32],
    partner: &'a [u32],
}

/// The loads of a slab (from owner `.0`, to owner `.1`) and of the next one (from its first
/// owner).
type SlabLoads<'s, 'l> = (
    (usize, usize),
    &'s mut [Load],
    &'s mut Option<(usize, &'l mut [Load])>,
);

/// Stage 3 (Section 2.2): the force of every touching particle pair of `lists` (its pair
/// list and the pairs across periodic sides), once per pair, added to the `loads` of both
/// particles of `p` (with the reactions of Eqs. 56-60).
///
/// The owners are cut into slabs whose partners lie at most in the next slab
/// (`Neighbours::slabs`): the even slabs run at the same time, then the odd ones, so a
/// load is added to by one slab at a time, in an order that does not depend on the
/// number of threads. Each slab first sorts out its touching pairs (a pair that has just
/// parted forgets its springs), then evaluates them `WIDTH` at a time in SIMD lanes; a
/// lane gives the bits the pair would give alone. Body i of a pair is the particle of
/// the lower id, so a pair's force and springs do not depend on the storage order. With
/// the energy ledger, each contact's parts to `ledger`.
pub(super) fn run(
    model: &Model,
    p: &Particles,
    lists: &mut Neighbours,
    loads: &mut [Load],
    ledger: Option<&mut Vec<LedgerEntry>>,
) -> Findings {
    with_models!(model.law.choice(), M => run_with::<M>(model, p, lists, loads, ledger))
}

/// [`run`] with the sub-models `M`.
#[inline(never)] // a stage of its own in profiles
fn run_with<M: Models>(
    model: &Model,
    p: &Particles,
    lists: &mut Neighbours,
    loads: &mut [Load],
    mut ledger: Option<&mut Vec<LedgerEntry>>,
) -> Findings {
    let found = Found::new(ledger.as_deref_mut());
    let law = &model.law;
    let ContactList {
        start,
        partner,
        contact,
        blocks: slabs,
        stores,
    } = &mut lists.pairs;
    let (start, partner, slabs) = (&*start, &*partner, &*slabs);
    let stage = PairStage {
        p,
        law,
        densities: &model.densities,
        uniform: law.uniform(),
        one_pair: law.pair(0, 0).splat(),
        scales: &model.scales,
        start,
        partner,
    };
    thread_local! {
        static TOUCHING: std::cell::RefCell<Vec<[u32; 3]>> = Default::default();
    }
    for phase in 0..2 {
        let mut all: Vec<Option<Block>> = blocks(slabs, loads, start, contact, stores)
            .into_iter()
            .map(Some)
            .collect();
        // A slab, with the loads of the next one.
        let tasks: Vec<(Block, Option<Block>)> = (phase..all.len())
            .step_by(2)
            .map(|s| {
                let own = all[s].take().expect("each slab once");
                (own, all.get_mut(s + 1).and_then(Option::take))
            })
            .collect();
        tasks.into_par_iter().for_each(|(slab, next)| {
            TOUCHING.with_borrow_mut(|touching| stage.slab::<M>(slab, next, touching, &found));
        });
    }
    let mut found = found.into_inner(ledger.as_deref_mut());
    wrapped::<M>(model, p, lists, loads, (&mut found, ledger));
    found
}

/// Stage 3, across periodic sides: the pairs of `Neighbours::wrapped`, partner j seen at
/// its image x_j + shift, one by one in slot order (they are few: those at the sides),
/// after the slabs; the law as for any pair, body i the lower id.
fn wrapped<M: Models>(
    model: &Model,
    p: &Particles,
    nb: &mut Neighbours,
    loads: &mut [Load],
    (found, mut ledger): (&mut Findings, Option<&mut Vec<LedgerEntry>>),
) {
    let law = &model.law;
    let images: Vec<(DVec3, DVec3)> = (0..nb.shift.len()).map(|k| nb.image(k)).collect();
    let ContactList {
        start,
        partner,
        contact,
        blocks,
        stores,
    } = &mut nb.wrapped;
    for block in 0..blocks.len().saturating_sub(1) {
        let store = &mut stores[block];
        for a in blocks[block] as usize..blocks[block + 1] as usize {
            for k in start[a] as usize..start[a + 1] as usize {
                let b = partner[k] as usize;
                // Seen from the lower id: the other at its image (and its velocity), as
                // `Neighbours::across`.
                let (shift, dv) = images[k];
                let (i, j) = if p.id[a] < p.id[b] { (a, b) } else { (b, a) };
                let body = |k: usize, x: DVec3, dv: DVec3| Body {
                    x,
                    radius: p.radius[k],
                    v: p.v[k] + dv,
                    w: p.w[k],
                };
                let (bi, bj) = (body(i, p.x[i], DVec3::ZERO), body(j, p.x[j] + shift, dv));
                // An open contact beyond touch lasts within its reach.
                let gap = match contact[k] {
                    NONE => 0.0,
                    _ => stage_reach::<M>(law, p, i, j),
                };
                let Some(kin) = Kinematics::between_particles_within(&bi, &bj, gap) else {
                    if contact[k] != NONE {
                        store.close(contact[k]);
                        contact[k] = NONE;
                    }
                    continue;
                };
                if contact[k] == NONE {
                    contact[k] = store.open();
                }
                #[cfg(test)]
                super::open_core_tests::touch(store, &[contact[k]]);
                let springs = &mut store.state.springs[contact[k] as usize];
                let other = Other::Particle {
                    r: p.radius[j],
                    m: model.mass(p, j),
                };
                let coef = law.pair(p.material[i], p.material[j]);
                let (r_i, m_i) = (p.radius[i], model.mass(p, i));
                let (force, parts) =
                    law.compose_parts::<M, _>(coef, (r_i, m_i), other, &kin, springs);
                if let Some(ledger) = ledger.as_deref_mut() {
                    ledger.push(LedgerEntry {
                        i: i as u32,
                        j: j as u32,
                        n: kin.n,
                        r_i: kin.r_i,
                        r_j: kin.r_j,
                        frame_v: dv,
                        frame_w: DVec3::ZERO,
                        parts,
                    });
                }
                let lanes = &model.scales.lanes;
                let (load_i, load_j) = pair_mut(loads, i, j);
                let fine = load_i.add(pack(force.f, force.tau_i), lanes)
                    & load_j.add(pack(-force.f, force.tau_j), lanes); // Eqs. (56)-(60)
                found.beyond_range |= !fine;
                let limit = p.radius[i].min(p.radius[j]);
                if kin.delta > limit {
                    found.deep.push(Deep {
                        i,
                        other: Against::Particle(j),
                        delta: kin.delta,
                        limit,
                    });
                }
            }
        }
    }
}

impl PairStage<'_> {
    /// The density quotient of the particles `idx` in lanes.
    #[inline(always)]
    fn mass_per_r3(&self, idx: &[usize; WIDTH]) -> Group {
        if self.uniform {
            Group::splat(self.densities[0].mass_per_r3)
        } else {
            Group::gather(idx.map(|k| self.densities[self.p.material[k] as usize].mass_per_r3))
        }
    }

    /// The masses of the particles `idx` (of radii `radius`) in lanes: a sphere of a rigid
    /// body enters the law with the body's mass.
    #[inline(always)]
    fn masses(&self, idx: &[usize; WIDTH], radius: Group) -> Group {
        body_masses(
            self.p,
            idx,
            Inertia::mass_with(radius, self.mass_per_r3(idx)),
        )
    }

    /// One slab of the pair list: its touching pairs, then the law for `WIDTH` of them at a
    /// time, added to the loads of the slab's particles and of the `next` slab's.
    #[inline]
    fn slab<M: Models>(
        &self,
        slab: Block,
        next: Option<Block>,
        touching: &mut Vec<[u32; 3]>,
        found: &Found,
    ) {
        let Block {
            owners,
            first,
            loads,
            contact,
            store,
        } = slab;
        let mut next_loads = next.map(|n| (n.owners.start, n.loads));
        self.touching::<M>(owners.clone(), first, contact, store, touching);
        let at = (owners.start, owners.end);
        for group in touching.chunks(WIDTH) {
            self.group::<M>(group, store, (at, &mut *loads, &mut next_loads), found);
        }
    }

    /// The touching pairs of owners `owners` (their slots from `first`): the particle of the
    /// lower id (body i of the law, whatever the storage order), the other, and the
    /// contact's entry in the slab's store (opened at first touch, closed when the pair
    /// parts, or, beyond touch, when its gap passes the adhesion's reach).
    #[inline]
    fn touching<M: Models>(
        &self,
        owners: std::ops::Range<usize>,
        first: usize,
        contact: &mut [u32],
        store: &mut Store,
        touching: &mut Vec<[u32; 3]>,
    ) {
        // Room for every slot of the slab, written in turn and counted when touching (no
        // branch on the outcome, which is a coin toss; a contact that opens or closes is
        // the rare case that branches).
        let slots = self.start[owners.end] as usize - self.start[owners.start] as usize;
        touching.clear();
        touching.resize(slots + 1, [0; 3]);
        let mut n = 0;
        for i in owners {
            let (xi, ri) = (self.p.x[i], self.p.radius[i]);
            let run = self.start[i] as usize - first..self.start[i + 1] as usize - first;
            for kl in run {
                let j = self.partner[first + kl] as usize;
                let reach = ri + self.p.radius[j];
                let dist2 = (xi - self.p.x[j]).length_squared();
                let mut touches = dist2 < reach * reach;
                if M::BEYOND_TOUCH && !touches && contact[kl] != NONE {
                    let within = reach + stage_reach::<M>(self.law, self.p, i, j);
                    touches = dist2 < within * within;
                }
                if touches != (contact[kl] != NONE) {
                    if touches {
                        contact[kl] = store.open();
                    } else {
                        // The contact ended: forget its history.
                        store.close(contact[kl]);
                        contact[kl] = NONE;
                    }
                }
                let lower = self.p.id[i] < self.p.id[j];
                let (a, b) = if lower { (i, j) } else { (j, i) };
                touching[n] = [a as u32, b as u32, contact[kl]];
                n += touches as usize;
            }
        }
        touching.truncate(n);
    }

    /// The law for one group of touching pairs, added to both particles' loads; deep
    /// overlaps and loads out of range to `found`.
    #[inline]
    fn group<M: Models>(
        &self,
        group: &[[u32; 3]],
        store: &mut Store,
        (at, loads, next_loads): SlabLoads,
        found: &Found,
    ) {
        // A short last group repeats its last pair in the spare lanes.
        let (mut i, mut j, mut c) = ([0; WIDTH], [0; WIDTH], [0; WIDTH]);
        for l in 0..WIDTH {
            let [a, b, e] = group[l.min(group.len() - 1)];
            (i[l], j[l], c[l]) = (a as usize, b as usize, e);
        }
        let body = |idx: [usize; WIDTH]| Body::<Group> {
            x: Group::gather_vec_at(&self.p.x, &idx),
            radius: Group::gather_at(&self.p.radius, &idx),
            v: Group::gather_vec_at(&self.p.v, &idx),
            w: Group::gather_vec_at(&self.p.w, &idx),
        };
        let (body_i, body_j) = (body(i), body(j));
        let d = body_i.x - body_j.x; // Eq. (8)
        let kin = Kinematics::of_touching_particles(&body_i, &body_j, d, Group::dot(d, d));
        let mut lanes = gather_springs(store, c);
        let other = Other::Particle {
            r: body_j.radius,
            m: self.masses(&j, body_j.radius),
        };
        let m_i = self.masses(&i, body_i.radius);
        let coef = if self.uniform {
            self.one_pair
        } else {
            Coefficients::gather(std::array::from_fn(|l| {
                self.law.pair(self.p.material[i[l]], self.p.material[j[l]])
            }))
        };
        let (force, parts) =
            self.law
                .compose_parts::<M, _>(&coef, (body_i.radius, m_i), other, &kin, &mut lanes);
        scatter_springs(lanes, store, &c[..group.len()]);
        found.enter(|| {
            let entry = entries(&kin, &parts);
            let e = std::array::from_fn(|l| LedgerEntry {
                i: i[l] as u32,
                j: j[l] as u32,
                ..entry(l)
            });
            (e, group.len())
        });
        let (f, tau_i, tau_j) = (
            Group::scatter_vec(force.f),
            Group::scatter_vec(force.tau_i),
            Group::scatter_vec(force.tau_j),
        );
        let (lanes, mut fine) = (&self.scales.lanes, true);
        for l in 0..group.len() {
            let load_i = load(i[l], at, loads, next_loads);
            fine &= load_i.add(pack(f[l], tau_i[l]), lanes);
            let load_j = load(j[l], at, loads, next_loads);
            fine &= load_j.add(pack(-f[l], tau_j[l]), lanes); // Eqs. (56)-(60)
        }
        if !fine {
            found.beyond.store(true, Ordering::Relaxed);
        }
        if kin.delta.simd_gt(body_i.radius.min(body_j.radius)).any() {
            let delta = kin.delta.scatter();
            for l in 0..group.len() {
                let limit = self.p.radius[i[l]].min(self.p.radius[j[l]]);
                if delta[l] > limit {
                    found.deep.lock().expect("not poisoned").push(Deep {
                        i: i[l],
                        other: Against::Particle(j[l]),
                        delta: delta[l],
                        limit,
                    });
                }
            }
        }
    }
}

/// The ledger's entry of lane `l` of a group's kinematics `kin` and parts `parts` (its
/// bodies and frame left to fill in).
pub(super) fn entries(
    kin: &Kinematics<Group>,
    parts: &ContactParts<Group>,
) -> impl Fn(usize) -> LedgerEntry {
    let (n, r_i, r_j) = (
        Group::scatter_vec(kin.n),
        kin.r_i.scatter(),
        kin.r_j.scatter(),
    );
    let (f_normal, pull) = (parts.f_normal.scatter(), parts.pull.scatter());
    let (f_s, tau_r, tau_t) = (
        Group::scatter_vec(parts.f_s),
        Group::scatter_vec(parts.tau_r),
        Group::scatter_vec(parts.tau_t),
    );
    move |l| LedgerEntry {
        i: 0,
        j: WALL,
        n: n[l],
        r_i: r_i[l],
        r_j: if r_j[l].is_finite() { r_j[l] } else { 0.0 },
        frame_v: DVec3::ZERO,
        frame_w: DVec3::ZERO,
        parts: ContactParts {
            f_normal: f_normal[l],
            pull: pull[l],
            f_s: f_s[l],
            tau_r: tau_r[l],
            tau_t: tau_t[l],
        },
    }
}

/// The gap at which an open contact of particles `i` and `j` ends under the sub-models `M`
/// (0: at touch).
#[inline]
fn stage_reach<M: Models>(law: &ContactLaw, p: &Particles, i: usize, j: usize) -> f64 {
    if !M::BEYOND_TOUCH {
        return 0.0;
    }
    let (r_i, r_j) = (p.radius[i], p.radius[j]);
    let coef = law.pair(p.material[i], p.material[j]);
    ContactLaw::reach::<M>(coef, r_i * r_j / (r_i + r_j))
}

/// The load of a particle of this slab (from owner `base` to `owned`) or of the next one.
#[inline(always)]
fn load<'l>(
    idx: usize,
    (base, owned): (usize, usize),
    loads: &'l mut [Load],
    next: &'l mut Option<(usize, &mut [Load])>,
) -> &'l mut Load {
    if idx < owned {
        &mut loads[idx - base]
    } else {
        let (start, next) = next.as_mut().expect("partners reach the next slab only");
        &mut next[idx - *start]
    }
}
