//! What moves between the processes of a split run when the lists are rebuilt: the own
//! particles to the owners of the boxes they are in, with the springs of their contacts
//! (`migrate`), and the copies each process needs of the others' (`exchange_ghosts`). A
//! rigid body moves whole, to the process of its centre of mass.

use super::*;
use crate::model::contact_state::ActiveState;

/// The boxes cut anew (collective) when the counts of own particles, at `own`, are out of
/// balance (or never cut).
fn recut(d: &mut Share, own: &[DVec3]) {
    let k = d.comm.size();
    let counts: Vec<u64> = d
        .comm
        .all_gather((own.len() as u64).to_le_bytes().to_vec())
        .iter()
        .map(|c| Reader::new(c).u64())
        .collect();
    let mean = counts.iter().sum::<u64>() as f64 / k as f64;
    let largest = counts.iter().copied().max().unwrap_or(0) as f64;
    if d.tree.is_none() || largest > REBALANCE * mean.max(1.0) {
        d.tree = Some(Tree::bisect(&*d.comm, own));
        d.cuts += 1;
    }
}

/// Own particles of `p` (but those of ids in `gone`) to the owners of the boxes they are
/// in, placed at `anchors` if given (collective; the boxes cut anew first if need be), with
/// the springs of their contacts: the particles this process owns afterwards, their
/// anchors if given, and their springs. A pair's springs go to the owners of both
/// partners, each sent by its partner's old owner (both have the same springs), and are
/// kept once. A rigid body goes whole, with its record, to the owner of its centre.
pub(super) fn migrate(
    d: &mut Share,
    (p, periodic): (Particles, Option<Periodic>),
    anchors: Option<Vec<DVec3>>,
    gone: &FxHashSet<Id>,
    (entries, active): (Entries, ActiveState),
) -> (Particles, Option<Vec<DVec3>>, Entries) {
    let carry = anchors.is_some();
    // Where each particle is placed: at its anchor, or where it is now.
    let place: std::borrow::Cow<[DVec3]> = match anchors {
        Some(a) => a.into(),
        None => p.x.as_slice().into(),
    };
    let at = owner_places(&p, &place, periodic);
    let own: Vec<DVec3> = (0..p.len())
        .filter(|&i| d.owned[i] && !gone.contains(&p.id[i]))
        .map(|i| at[i])
        .collect();
    recut(d, &own);
    drop(own);
    let d = &*d;
    let to = Destinations::of(d, &p, &at, gone, &entries);
    drop(at);
    let me = d.comm.rank();
    let messages: Vec<Vec<u8>> = (0..d.comm.size())
        .map(|q| match q == me {
            true => Vec::new(), // what stays, stays
            false => to.message(q, &p, carry.then_some(&*place), (&entries, &active)),
        })
        .collect();
    let mut held = p.empty_like();
    let mut held_at = carry.then(Vec::new);
    for &i in &to.particles[me] {
        held.insert(p.id[i as usize], p.get(i as usize));
        if let Some(at) = &mut held_at {
            at.push(place[i as usize]);
        }
    }
    for &b in &to.bodies[me] {
        held.bodies.insert(p.bodies.list[b as usize].clone());
    }
    let (pairs, faces) = &entries;
    let mut kept = (
        to.pairs[me].iter().map(|&e| pairs[e]).collect(),
        to.faces[me].iter().map(|&e| faces[e]).collect(),
    );
    drop((place, to, entries));
    drop(p);
    for (q, m) in d.comm.all_to_all(messages).iter().enumerate() {
        if q != me {
            let mut r = Reader::new(m);
            receive(&mut r, &mut held, held_at.as_mut(), (&mut kept, &active));
        }
    }
    // A pair whose partners had two owners came from both.
    kept.0.sort_unstable_by_key(|e| (e.0, e.1));
    kept.0.dedup_by_key(|e| (e.0, e.1));
    held.locate_bodies();
    (held, held_at, kept)
}

/// Where each particle of `p` (at `place`) is placed to find its owner: its place, or for
/// a sphere of a rigid body its body's centre of mass ([`centre_in_box`]), so that a body
/// goes whole to the process of its centre.
pub(in crate::engine) fn owner_places<'a>(
    p: &Particles,
    place: &'a [DVec3],
    periodic: Option<Periodic>,
) -> std::borrow::Cow<'a, [DVec3]> {
    if p.bodies.is_empty() {
        return place.into();
    }
    let mut at = place.to_vec();
    for (b, body) in p.bodies.list.iter().enumerate() {
        let c = centre_in_box(body, periodic);
        p.bodies.members(b).iter().for_each(|&k| at[k as usize] = c);
    }
    at.into()
}

/// The centre of mass of `body`, put back into a periodic box (a body's centre is never
/// wrapped in the step, as its spheres are at rebuilds): the place that decides its owner.
pub(in crate::engine) fn centre_in_box(body: &RigidBody, periodic: Option<Periodic>) -> DVec3 {
    periodic.map_or(body.x, |periodic| periodic.wrap(body.x))
}

/// How far the spheres of this process's bodies of `held` (at `held_at`, or where they
/// are) are from their bodies' centres ([`centre_in_box`]; across periodic sides, the
/// nearest image): a body's owner's box holds its centre, so its spheres are within this
/// of the box, and their partners within this more than a sphere's reach.
fn body_spread(held: &Particles, held_at: Option<&[DVec3]>, periodic: Option<Periodic>) -> f64 {
    let mut spread: f64 = 0.0;
    for (b, body) in held.bodies.list.iter().enumerate() {
        let c = centre_in_box(body, periodic);
        for &k in held.bodies.members(b) {
            let a = held_at.map_or(held.x[k as usize], |at| at[k as usize]);
            let a = periodic.map_or(a, |periodic| a + periodic.image_towards(a, c).0);
            spread = spread.max(a.distance(c));
        }
    }
    spread
}

/// Where [`migrate`] sends each own particle (by index) and the springs of each contact
/// (by entry), per process.
struct Destinations {
    particles: Vec<Vec<u32>>,
    /// Rigid bodies (indices in `bodies.list`).
    bodies: Vec<Vec<u32>>,
    pairs: Vec<Vec<usize>>,
    faces: Vec<Vec<usize>>,
}

impl Destinations {
    /// To the owner of the box each kept own particle of `p` is placed in (at `place`):
    /// the particle, its contacts with faces, and its contacts with particles of higher id
    /// (to the owners of both partners); a rigid body's record to the owner of its spheres.
    fn of(
        d: &Share,
        p: &Particles,
        place: &[DVec3],
        gone: &FxHashSet<Id>,
        (pairs, faces): &Entries,
    ) -> Destinations {
        let k = d.comm.size();
        let index: FxHashMap<Id, u32> =
            p.id.iter()
                .enumerate()
                .map(|(i, &id)| (id, i as u32))
                .collect();
        let tree = d.tree.as_ref().expect("cut");
        let owner = |id: Id| tree.owner(place[index[&id] as usize]);
        // (A share of a checkpoint's parts has springs of particles it does not hold.)
        let mine = |id: Id| index.get(&id).is_some_and(|&i| d.owned[i as usize]);
        let mut to = Destinations {
            particles: vec![Vec::new(); k],
            bodies: vec![Vec::new(); k],
            pairs: vec![Vec::new(); k],
            faces: vec![Vec::new(); k],
        };
        for i in (0..p.len()).filter(|&i| d.owned[i] && !gone.contains(&p.id[i])) {
            to.particles[tree.owner(place[i])].push(i as u32);
        }
        for b in p.bodies_where(|i| d.owned[i] && !gone.contains(&p.id[i])) {
            let first = p.bodies.members(b)[0] as usize;
            to.bodies[tree.owner(place[first])].push(b as u32);
        }
        // A pair's springs go from the owner of each partner to where that partner goes
        // (only its owner knows: a ghost body's centre is that of the last rebuild); the
        // copies are the same bits, and [`migrate`] keeps one.
        for (e, &(a, b, _)) in pairs.iter().enumerate() {
            if gone.contains(&a) || gone.contains(&b) {
                continue;
            }
            let qa = mine(a).then(|| owner(a));
            let qb = mine(b).then(|| owner(b)).filter(|&qb| Some(qb) != qa);
            qa.into_iter().chain(qb).for_each(|q| to.pairs[q].push(e));
        }
        for (e, &(a, _, _)) in faces.iter().enumerate() {
            if !gone.contains(&a) && mine(a) {
                to.faces[owner(a)].push(e);
            }
        }
        to
    }

    /// What goes to process `q`: its particles (with their places if `place`), its rigid
    /// bodies, then its springs of pairs and of contacts with faces, each list after its
    /// length.
    fn message(
        &self,
        q: usize,
        p: &Particles,
        place: Option<&[DVec3]>,
        ((pairs, faces), active): (&Entries, &ActiveState),
    ) -> Vec<u8> {
        let mut w = Writer::default();
        w.u64(self.particles[q].len() as u64);
        for &i in &self.particles[q] {
            put_particle(&mut w, &p.active, p.id[i as usize], &p.get(i as usize));
            if let Some(place) = place {
                w.vec3(place[i as usize]);
            }
        }
        w.u64(self.bodies[q].len() as u64);
        for &b in &self.bodies[q] {
            put_body(&mut w, &p.bodies.list[b as usize]);
        }
        w.u64(self.pairs[q].len() as u64);
        self.pairs[q]
            .iter()
            .for_each(|&e| put_entry(&mut w, active, &pairs[e]));
        w.u64(self.faces[q].len() as u64);
        self.faces[q]
            .iter()
            .for_each(|&e| put_entry(&mut w, active, &faces[e]));
        w.0
    }
}

/// Adds what a [`Destinations::message`] holds to the particles `held` (and their places to
/// `held_at`, if carried) and the contacts' states `kept` (holding the optional members
/// `active`).
fn receive(
    r: &mut Reader,
    held: &mut Particles,
    mut held_at: Option<&mut Vec<DVec3>>,
    ((pairs, faces), active): (&mut Entries, &ActiveState),
) {
    for _ in 0..r.u64() {
        let (id, particle) = get_particle(r, &held.active);
        held.insert(id, particle);
        if let Some(at) = held_at.as_mut() {
            at.push(r.vec3());
        }
    }
    for _ in 0..r.u64() {
        held.bodies.insert(get_body(r));
    }
    for _ in 0..r.u64() {
        pairs.push(get_entry(r, active));
    }
    for _ in 0..r.u64() {
        faces.push(get_entry(r, active));
    }
}

/// Ghosts: copies of own particles (all `held` holds) for the processes whose boxes are
/// within reach of them or, across periodic sides, of their images (collective); `reach`
/// is the largest radius of all processes, the skin and the periodic sides. A rigid body
/// goes whole, with its record, to every process one of its spheres is within reach of.
/// Returns the ids sent to and received from each process.
pub(super) fn exchange_ghosts(
    d: &Share,
    held: &mut Particles,
    held_at: &mut Option<Vec<DVec3>>,
    reach: (f64, f64, Option<Periodic>),
) -> (Vec<Vec<Id>>, Vec<Vec<Id>>) {
    let k = d.comm.size();
    let (ghosts_to, bodies_to) = ghost_destinations(d, held, held_at.as_deref(), reach);
    let messages: Vec<Vec<u8>> = (0..k)
        .map(|q| {
            let mut w = Writer::default();
            w.u64(ghosts_to[q].len() as u64);
            for &i in &ghosts_to[q] {
                put_particle(
                    &mut w,
                    &held.active,
                    held.id[i as usize],
                    &held.get(i as usize),
                );
                if let Some(at) = held_at.as_ref() {
                    w.vec3(at[i as usize]);
                }
            }
            w.u64(bodies_to[q].len() as u64);
            for &b in &bodies_to[q] {
                put_body(&mut w, &held.bodies.list[b as usize]);
            }
            w.0
        })
        .collect();
    let ghosts_to: Vec<Vec<Id>> = ghosts_to
        .into_iter()
        .map(|list| list.into_iter().map(|i| held.id[i as usize]).collect())
        .collect();
    let mut ghosts_from: Vec<Vec<Id>> = vec![Vec::new(); k];
    for (q, m) in d.comm.all_to_all(messages).into_iter().enumerate() {
        let mut r = Reader::new(&m);
        for _ in 0..r.u64() {
            let (id, particle) = get_particle(&mut r, &held.active);
            held.insert(id, particle);
            if let Some(at) = held_at.as_mut() {
                at.push(r.vec3());
            }
            ghosts_from[q].push(id);
        }
        for _ in 0..r.u64() {
            held.bodies.insert(get_body(&mut r));
        }
    }
    (ghosts_to, ghosts_from)
}

/// Which own particles of `held` (storage indices) go as ghosts to each process, and which
/// rigid bodies (indices in `bodies.list`): those within `r_i + r_max + skin` of its box,
/// or whose images are, and more by the spread of the bodies ([`body_spread`], the
/// largest of all processes): an own sphere may lie that far outside the box.
fn ghost_destinations(
    d: &Share,
    held: &Particles,
    held_at: Option<&[DVec3]>,
    (r_max, skin, periodic): (f64, f64, Option<Periodic>),
) -> (Vec<Vec<u32>>, Vec<Vec<u32>>) {
    let (me, k) = (d.comm.rank(), d.comm.size());
    let tree = d.tree.as_ref().expect("cut");
    let spread = d.comm.max(body_spread(held, held_at, periodic)).max(0.0);
    let mut ghosts_to: Vec<Vec<u32>> = vec![Vec::new(); k];
    let mut bodies_to: Vec<Vec<u32>> = vec![Vec::new(); k];
    let (mut near, mut images, mut to) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..held.len() {
        let x = held_at.map_or(held.x[i], |at| at[i]);
        let reach = held.radius[i] + r_max + skin + spread;
        to.clear();
        tree.near(x, reach, &mut near);
        to.extend_from_slice(&near);
        if let Some(periodic) = periodic {
            periodic.image_shifts(x, reach, &mut images);
            for &(s, _) in &images {
                tree.near(x + s, reach, &mut near);
                to.extend_from_slice(&near);
            }
        }
        to.sort_unstable();
        to.dedup();
        for &q in to.iter().filter(|&&q| q != me) {
            match held.body[i] {
                None => ghosts_to[q].push(i as u32),
                Some(b) => bodies_to[q].push(held.bodies.index_of(b).expect("held") as u32),
            }
        }
    }
    // A body whole, once.
    for (q, bodies) in bodies_to.iter_mut().enumerate() {
        bodies.sort_unstable();
        bodies.dedup();
        for &b in bodies.iter() {
            ghosts_to[q].extend_from_slice(held.bodies.members(b as usize));
        }
    }
    (ghosts_to, bodies_to)
}
