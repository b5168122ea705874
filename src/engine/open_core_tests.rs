//! The recipes of the open core, tried: a per-particle field only the tests have (`probe`,
//! an optional row of the table in `model/particles.rs`) and the code that uses it (each
//! particle's path length, summed in the step), carried through ghosts, migration,
//! checkpoints resumed on another number of processes, and frames, with the same bits as
//! a run in one process.

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
    sim
}

/// Each held particle's probe, by id.
fn probes(p: &Particles) -> BTreeMap<Id, u64> {
    (0..p.len())
        .map(|i| (p.id[i], p.probe[i].to_bits()))
        .collect()
}

/// `steps` more steps of `sim`, checking after each that every particle held (own or ghost)
/// has the probe of the run in one process, `reference`. Returns the ids it ever owned.
fn step_checking_ghosts(
    sim: &mut Simulation,
    steps: u64,
    reference: &[BTreeMap<Id, u64>],
) -> BTreeSet<Id> {
    let (mut ghosts, mut owned) = (0, BTreeSet::new());
    for _ in 0..steps {
        sim.step().expect("stable");
        let want = &reference[sim.steps as usize];
        for (id, bits) in probes(&sim.particles) {
            assert_eq!(
                want.get(&id),
                Some(&bits),
                "particle {id} at step {}",
                sim.steps
            );
        }
        let d = sim.domain().expect("a split run");
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

/// The probes of the run in one process after each step (0 to `steps`).
fn one_process(steps: u64) -> Vec<BTreeMap<Id, u64>> {
    let mut sim = with_probe(Simulation::new(silo()).unwrap());
    let mut all = vec![probes(&sim.particles)];
    for _ in 0..steps {
        sim.step().unwrap();
        all.push(probes(&sim.particles));
    }
    assert!(
        all[steps as usize]
            .values()
            .any(|&b| f64::from_bits(b) > 0.0)
    );
    all
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
fn a_field_declared_once_travels_through_ghosts_migration_checkpoints_and_frames() {
    let (first, then) = (2500, 2500);
    let reference = Arc::new(one_process(first + then));
    // `first` steps on 2 processes, every held probe checked each step; then the
    // checkpoint's bytes.
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
        assert!(sim.particles.active.probe);
        let mut sim = sim.split(comm).unwrap();
        step_checking_ghosts(&mut sim, then, &r)
    });
    assert!(migrated(&owned), "some particle should change hands");
    // A frame holds the field's column and reads back with the same bits.
    let snapshot = bytes::decode(&checkpoint, Some(7)).unwrap();
    let p = &snapshot.particles;
    let mut csv = Vec::new();
    crate::io::csv::write_particles(&mut csv, p, Default::default()).unwrap();
    let header = String::from_utf8_lossy(&csv[..csv.iter().position(|&b| b == b'\n').unwrap()]);
    assert!(header.ends_with(",probe"), "{header}");
    let back = crate::io::csv::read_particles(&csv[..], "frame.csv").unwrap();
    let by_id: BTreeMap<Id, u64> = probes(p);
    assert!(back.active.probe);
    assert_eq!(
        back.probe.iter().map(|s| s.to_bits()).collect::<Vec<_>>(),
        by_id.values().copied().collect::<Vec<_>>()
    );
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
    let mut csv = Vec::new();
    crate::io::csv::write_particles(&mut csv, &sim.particles, Default::default()).unwrap();
    assert!(!String::from_utf8_lossy(&csv).contains("probe"));
}

#[test]
fn a_frame_missing_part_of_a_field_or_with_a_bad_value_is_refused() {
    let header = "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,probe\n";
    let ok = format!("{header}0,0,0,1,0,0,0,1,0,0,0,0,0,0,2.5\n");
    let p = crate::io::csv::read_particles(ok.as_bytes(), "f.csv").unwrap();
    assert_eq!(p.probe, vec![2.5]);
    let bad = format!("{header}0,0,0,1,0,0,0,1,0,0,0,0,0,0,nan\n");
    let e = crate::io::csv::read_particles(bad.as_bytes(), "f.csv").unwrap_err();
    assert!(format!("{e:#}").contains("f.csv:2: probe"), "{e:#}");
    let twice = "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,probe,probe\n";
    let e = crate::io::csv::read_particles(twice.as_bytes(), "f.csv").unwrap_err();
    assert!(format!("{e:#}").contains("'probe' appears twice"), "{e:#}");
}
