//! The recipes of the open core, tried: a per-particle field only the tests have (`probe`,
//! an optional row of the table in `model/particles.rs`) and the code that uses it (each
//! particle's path length, summed in the step); and a member of a contact's state only the
//! tests have (`touches`, an optional row of `model/contact_state.rs`) with the code that
//! uses it (the steps each contact has touched, counted where the law updates the
//! springs). Both are carried through ghosts, migration and checkpoints resumed on another
//! number of processes with the same bits as a run in one process (frames: `io/csv/tests.rs`,
//! `io/vtk.rs`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::sync::Arc;

use crate::engine::records::bytes;
use crate::model::particles::{Id, Particles};
use crate::parallel::comm::{Comm, Threads};
use crate::scenario::Scenario;

use super::Simulation;

/// The code that uses the field: each particle's path length, `|v| dt` a step.
pub(super) fn walk(p: &mut Particles, dt: f64) {
    if p.active.probe {
        for (s, v) in p.probe.iter_mut().zip(&p.v) {
            *s += v.length() * dt;
        }
    }
}

/// The code that uses the contact's state: each contact of entries `c` of `store` has
/// touched one step more.
pub(super) fn touch(store: &mut crate::neighbours::Store, c: &[u32]) {
    if store.state.active.touches {
        c.iter().for_each(|&c| store.state.touches[c as usize] += 1);
    }
}

/// A silo filling through its outlet: spawning, grains changing hands between processes,
/// removal.
fn silo() -> Scenario {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let text = "[geometry]\nradius_min = 0.003\nradius_max = 0.004\nmesh = \"stages/silo.off\"\n\
         mesh_radii = [0.0]\nspawn_min = [-0.05, -0.05, 0.06]\nspawn_max = [0.05, 0.05, 0.14]\n\
         [material]\nrestitution = 0.3\nfriction_sliding = 0.5\nfriction_rolling = 0.1\n\
         [simulation]\nmax_particles = 300\nskin = 0.5\n\
         [domain]\nmin = [-0.1, -0.1, -0.2]\nmax = [0.1, 0.1, 0.2]\n\
         [[outlets]]\nmin = [-0.1, -0.1, -0.2]\nmax = [0.1, 0.1, -0.05]\n";
    Scenario::parse(text, &data.join("inline.toml")).expect("a valid scenario")
}

fn with_probe(mut sim: Simulation) -> Simulation {
    assert!(sim.particles.activate("probe"));
    assert!(sim.neighbours.state.activate("touches"));
    sim
}

/// How many steps each contact with one of the particles `sim` owns has touched: by
/// (lower id, higher id) for pairs, (id, face) for faces.
fn touches(sim: &Simulation) -> BTreeMap<(Id, Id, bool), u32> {
    let p = &sim.particles;
    let own = |id: Id| {
        let i = p.id.iter().position(|&j| j == id).expect("held");
        sim.share().is_none_or(|d| d.owned[i])
    };
    let (pairs, faces) = sim.neighbours.entries_by_id(&p.id);
    let pairs = pairs.into_iter().filter(|e| own(e.0) || own(e.1));
    let faces = faces.into_iter().filter(|e| own(e.0));
    let pairs = pairs.map(|e| ((e.0, e.1, true), e.2.touches));
    pairs
        .chain(faces.map(|e| ((e.0, e.1, false), e.2.touches)))
        .collect()
}

/// Every so many steps the contacts' states are compared.
const EVERY: u64 = 50;

/// Each held particle's probe, by id.
fn probes(p: &Particles) -> BTreeMap<Id, u64> {
    (0..p.len())
        .map(|i| (p.id[i], p.probe[i].to_bits()))
        .collect()
}

/// What the run in one process holds after each step: the particles' probes, and every
/// [`EVERY`] steps the contacts' touches.
struct Reference {
    probes: Vec<BTreeMap<Id, u64>>,
    touches: Vec<BTreeMap<(Id, Id, bool), u32>>,
}

/// `steps` more steps of `sim`, checking after each that every particle held (own or ghost)
/// has the probe of the run in one process, and every [`EVERY`] steps that every contact
/// of an own particle has its touches. Returns the ids it ever owned.
fn step_checking_ghosts(sim: &mut Simulation, steps: u64, reference: &Reference) -> BTreeSet<Id> {
    let (mut ghosts, mut owned) = (0, BTreeSet::new());
    for _ in 0..steps {
        sim.step().expect("stable");
        let want = &reference.probes[sim.steps as usize];
        for (id, bits) in probes(&sim.particles) {
            let step = sim.steps;
            assert_eq!(want.get(&id), Some(&bits), "particle {id} at step {step}");
        }
        if sim.steps.is_multiple_of(EVERY) {
            let want = &reference.touches[(sim.steps / EVERY) as usize];
            for (contact, n) in touches(sim) {
                let step = sim.steps;
                assert_eq!(
                    want.get(&contact),
                    Some(&n),
                    "contact {contact:?} at step {step}"
                );
            }
        }
        let d = sim.share().expect("a split run");
        ghosts += d.owned.iter().filter(|&&o| !o).count();
        owned.extend(
            (0..d.owned.len())
                .filter(|&i| d.owned[i])
                .map(|i| sim.particles.id[i]),
        );
    }
    assert!(ghosts > 0, "the run should have had ghosts");
    owned
}

/// Whether some particle was owned by two processes in turn (it migrated).
fn migrated(owned: &[BTreeSet<Id>]) -> bool {
    owned
        .iter()
        .enumerate()
        .any(|(a, ids)| owned[a + 1..].iter().any(|other| !ids.is_disjoint(other)))
}

/// The run in one process for `steps` steps.
fn one_process(steps: u64) -> Reference {
    let mut sim = with_probe(Simulation::new(silo()).unwrap());
    let mut reference = Reference {
        probes: vec![probes(&sim.particles)],
        touches: vec![touches(&sim)],
    };
    for _ in 0..steps {
        sim.step().unwrap();
        reference.probes.push(probes(&sim.particles));
        if sim.steps.is_multiple_of(EVERY) {
            reference.touches.push(touches(&sim));
        }
    }
    let last = &reference.probes[steps as usize];
    assert!(last.values().any(|&b| f64::from_bits(b) > 0.0));
    let last = reference.touches.last().unwrap();
    assert!(
        last.iter().any(|(c, &n)| c.2 && n > 100),
        "long pair contacts"
    );
    assert!(
        last.iter().any(|(c, &n)| !c.2 && n > 100),
        "long wall contacts"
    );
    reference
}

/// On `k` threads: each runs `body` on its share and returns what it returns.
fn on_threads<T: Send + 'static>(
    k: usize,
    body: impl Fn(Box<dyn Comm>) -> T + Send + Sync + 'static,
) -> Vec<T> {
    let body = Arc::new(body);
    let handles: Vec<_> = Threads::group(k)
        .into_iter()
        .map(|comm| {
            let body = body.clone();
            std::thread::spawn(move || body(Box::new(comm)))
        })
        .collect();
    handles.into_iter().map(|h| h.join().unwrap()).collect()
}

#[test]
fn a_field_and_a_contact_state_declared_once_travel_through_ghosts_migrations_and_checkpoints() {
    let (first, then) = (2500, 2500);
    let reference = Arc::new(one_process(first + then));
    // `first` steps on 2 processes, every held probe checked each step (and the touches
    // every `EVERY`); then the checkpoint's bytes.
    let r = reference.clone();
    let checkpoints = on_threads(2, move |comm| {
        let sim = with_probe(Simulation::new(silo()).unwrap());
        let mut sim = sim.split(comm).unwrap();
        let owned = step_checking_ghosts(&mut sim, first, &r);
        (bytes::encode(&sim.snapshot().unwrap(), 7), owned)
    });
    let (checkpoints, owned): (Vec<_>, Vec<_>) = checkpoints.into_iter().unzip();
    assert!(migrated(&owned), "some particle should change hands");
    let checkpoint = checkpoints[0].clone();
    assert_eq!(checkpoints[1], checkpoint);
    assert_eq!(
        u32::from_le_bytes(checkpoint[12..16].try_into().unwrap()),
        8
    );
    // Resumed on 3 processes.
    let r = reference.clone();
    let c = checkpoint.clone();
    let owned = on_threads(3, move |comm| {
        let snapshot = bytes::decode(&c, Some(7)).unwrap();
        let sim = Simulation::restore(silo(), snapshot).unwrap();
        assert!(sim.particles.active.probe && sim.neighbours.state.touches);
        let mut sim = sim.split(comm).unwrap();
        step_checking_ghosts(&mut sim, then, &r)
    });
    assert!(migrated(&owned), "some particle should change hands");
}

#[test]
fn a_run_without_the_optional_fields_writes_the_format_without_them() {
    let mut sim = Simulation::new(silo()).unwrap();
    for _ in 0..50 {
        sim.step().unwrap();
    }
    let checkpoint = bytes::encode(&sim.snapshot().unwrap(), 7);
    assert_eq!(
        u32::from_le_bytes(checkpoint[12..16].try_into().unwrap()),
        7
    );
    let back = bytes::decode(&checkpoint, Some(7)).unwrap();
    assert!(!back.particles.active.probe && back.particles.probe.is_empty());
}
