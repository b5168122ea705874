//! The snapshot of a split run from its pieces (one a process): the gathered snapshot and
//! the checkpoint joined from its parts are made by this one function.

use anyhow::{Result, bail, ensure};
use glam::DVec3;

use super::Snapshot;
use crate::model::particles::{Id, Particle};
use crate::neighbours::Entry;

/// The state all pieces of a snapshot share: `piece` without its particles, anchors and
/// springs (the piece of a process that holds none).
pub fn shared_part(piece: &Snapshot) -> Snapshot {
    Snapshot {
        particles: piece.particles.empty_like(),
        anchors: Vec::new(),
        lonely: Vec::new(),
        pair_history: Vec::new(),
        face_history: Vec::new(),
        ..piece.clone()
    }
}

/// The snapshot the pieces of all processes make (each the state of one process's
/// particles, the springs of the contacts it holds one of, and the state all share): all
/// particles in id order with their anchors, and every contact's springs once.
pub fn join(pieces: Vec<Snapshot>) -> Result<Snapshot> {
    let Some(first) = pieces.first() else {
        bail!("no parts");
    };
    for (k, p) in pieces.iter().enumerate() {
        ensure!(
            p.steps == first.steps
                && p.built_at == first.built_at
                && p.particles.next_id == first.particles.next_id
                && p.spawner == first.spawner
                && p.removed == first.removed
                && p.wall_sums == first.wall_sums
                && p.wall_heat == first.wall_heat
                && p.scenario == first.scenario
                && p.mesh_files == first.mesh_files
                && p.servos == first.servos
                && p.ledger == first.ledger,
            "corrupt: part {k} is not of the state of part 0 (another step or run)"
        );
        ensure!(
            p.lonely.is_empty(),
            "corrupt: part {k} lists lonely particles"
        );
        let anchored = p.anchors.len() == p.particles.len() || p.particles.is_empty();
        ensure!(
            anchored,
            "corrupt: part {k} lacks the anchors of its particles"
        );
    }
    let mut all: Vec<(Id, Particle, DVec3)> = Vec::new();
    for p in &pieces {
        let q = &p.particles;
        all.extend((0..q.len()).map(|i| (q.id[i], q.get(i), p.anchors[i])));
    }
    all.sort_unstable_by_key(|e| e.0);
    if let Some(w) = all.windows(2).find(|w| w[0].0 == w[1].0) {
        bail!("corrupt: particle {} is in two parts", w[0].0);
    }
    let mut particles = first.particles.empty_like();
    let mut anchors = Vec::with_capacity(all.len());
    for (id, particle, anchor) in all {
        particles.insert(id, particle);
        anchors.push(anchor);
    }
    // Each rigid body is in the part that holds its spheres (a body is owned whole).
    for p in &pieces {
        p.particles
            .bodies
            .list
            .iter()
            .for_each(|b| particles.bodies.insert(b.clone()));
    }
    particles.locate_bodies();
    let springs = |of: fn(&Snapshot) -> &Vec<Entry>| {
        dedup(pieces.iter().flat_map(|p| of(p).iter().copied()).collect())
    };
    Ok(Snapshot {
        contact_state: first.contact_state,
        steps: first.steps,
        built_at: first.built_at,
        particles,
        spawner: first.spawner.clone(),
        anchors,
        lonely: Vec::new(),
        pair_history: springs(|p| &p.pair_history),
        face_history: springs(|p| &p.face_history),
        removed: first.removed.clone(),
        wall_sums: first.wall_sums.clone(),
        wall_heat: first.wall_heat.clone(),
        scenario: first.scenario.clone(),
        mesh_files: first.mesh_files.clone(),
        servos: first.servos.clone(),
        ledger: first.ledger,
    })
}

/// Entries sorted by their pair of keys, each once (the copies two processes hold of a
/// contact are the same bits: both evaluated it from the same states).
fn dedup(mut entries: Vec<Entry>) -> Vec<Entry> {
    entries.sort_unstable_by_key(|e| (e.0, e.1));
    entries.dedup_by_key(|e| (e.0, e.1));
    entries
}
