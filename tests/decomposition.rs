//! The same bits however the particles are laid out: each particle's forces are summed in
//! the order of its partners' ids, so the storage order, the slabs of the pair stage and
//! the times of the neighbour-list rebuilds (which re-sort the particles) change nothing.
//! It is what a run split over processes rests on: each process holds its own particles in
//! its own order.

mod common;

use tinydem::comm::{Comm, Threads};
use tinydem::particles::Particles;
use tinydem::simulation::{Simulation, Wrench};

/// Each particle's id with the bits of its state, in id order.
fn state_by_id(sim: &Simulation) -> Vec<(u32, Vec<u64>)> {
    bits_by_id(&sim.particles)
}

fn bits_by_id(particles: &Particles) -> Vec<(u32, Vec<u64>)> {
    particles
        .iter_by_id()
        .map(|(id, p)| {
            let mut bits: Vec<u64> = [p.x, p.v, p.w]
                .iter()
                .flat_map(|v| v.to_array())
                .chain(p.q.to_array())
                .map(f64::to_bits)
                .collect();
            bits.push(p.radius.to_bits());
            (id, bits)
        })
        .collect()
}

/// What a run ends with, to compare runs: every particle's bits, the loads on the walls
/// since the start, the particles removed and the energy.
#[derive(Debug, PartialEq)]
struct End {
    particles: Vec<(u32, Vec<u64>)>,
    walls: Vec<[u64; 6]>,
    removed: u64,
    kinetic_energy: u64,
    contacts: (usize, usize),
}

fn end_of(sim: &mut Simulation) -> End {
    let walls = sim
        .take_wall_loads()
        .iter()
        .map(|w: &Wrench| {
            let a = [w.f.to_array(), w.tau.to_array()].concat();
            std::array::from_fn(|c| a[c].to_bits())
        })
        .collect();
    let thermo = sim.thermo();
    End {
        particles: bits_by_id(&sim.gather_particles()),
        walls,
        removed: thermo.removed,
        kinetic_energy: thermo.kinetic_energy.to_bits(),
        contacts: (thermo.pair_contacts, thermo.wall_contacts),
    }
}

/// A scenario run for `steps` steps split over `k` processes (threads of this one), as
/// process 0 ends it; and how often the boxes were cut.
fn split_run(text: &str, steps: u64, k: usize) -> (End, u64) {
    let text = text.to_string();
    let handles: Vec<_> = Threads::group(k)
        .into_iter()
        .map(|comm| {
            let text = text.clone();
            std::thread::spawn(move || {
                let rank = comm.rank();
                let sim = Simulation::new(common::scenario(&text)).expect("starts");
                let mut sim = sim.split(Box::new(comm)).expect("splits");
                for _ in 0..steps {
                    sim.step().expect("stable");
                }
                let cuts = sim.domain().expect("split").cuts;
                (rank, end_of(&mut sim), cuts)
            })
        })
        .collect();
    let mut ends: Vec<(usize, End, u64)> = handles
        .into_iter()
        .map(|h| h.join().expect("no panic"))
        .collect();
    ends.sort_by_key(|e| e.0);
    let (_, first, cuts) = ends.remove(0);
    for (rank, end, _) in ends {
        assert!(end == first, "process {rank} ends otherwise than process 0");
    }
    (first, cuts)
}

/// The silo of `tests/data/stages` filling through its plug-less outlet: spawning, two
/// radii, friction of every kind, a mesh, outlets and the loads on the walls.
fn silo(skin: f64) -> String {
    format!(
        "[geometry]\nradius_min = 0.003\nradius_max = 0.004\nmesh = \"stages/silo.off\"\nmesh_radii = [0.0]\n\
         spawn_min = [-0.05, -0.05, 0.06]\nspawn_max = [0.05, 0.05, 0.14]\n\
         [material]\nrestitution = 0.3\nfriction_sliding = 0.5\nfriction_rolling = 0.1\nfriction_twisting = 0.1\n\
         [simulation]\nmax_particles = 300\nskin = {skin}\n\
         [domain]\nmin = [-0.1, -0.1, -0.2]\nmax = [0.1, 0.1, 0.2]\n\
         [[outlets]]\nmin = [-0.1, -0.1, -0.2]\nmax = [0.1, 0.1, -0.05]\n\
         [output]\nwall_forces = true\n"
    )
}

#[test]
fn the_skin_changes_how_often_the_lists_are_rebuilt_not_the_bits() {
    let steps = 2500;
    let runs: Vec<Simulation> = [0.5, 0.1, 2.0]
        .iter()
        .map(|&skin| common::simulate(&silo(skin), steps))
        .collect();
    let rebuilds: Vec<u64> = runs.iter().map(Simulation::rebuilds).collect();
    assert!(
        rebuilds[1] > 2 * rebuilds[0] && rebuilds[0] > 2 * rebuilds[2],
        "the skins should rebuild at very different times: {rebuilds:?}"
    );
    let reference = state_by_id(&runs[0]);
    assert!(reference.len() > 200, "{} particles", reference.len());
    assert!(
        runs[0].contact_count() > 100,
        "{} contacts: the grains should be packed",
        runs[0].contact_count()
    );
    for (sim, skin) in runs.iter().zip([0.5, 0.1, 2.0]).skip(1) {
        assert!(
            state_by_id(sim) == reference,
            "skin {skin}: the state differs from skin 0.5's"
        );
    }
}

#[test]
fn a_run_split_over_processes_gives_the_bits_of_one_process() {
    let steps = 2500;
    let text = silo(0.5);
    let mut single = common::simulate(&text, steps);
    let reference = end_of(&mut single);
    assert!(reference.removed > 0 && reference.particles.len() > 200);
    for k in [2, 3, 4] {
        let (end, cuts) = split_run(&text, steps, k);
        assert!(
            cuts > 1,
            "{k} processes: the boxes should be cut anew as the silo fills"
        );
        assert_eq!(
            end.particles.len(),
            reference.particles.len(),
            "{k} processes"
        );
        assert!(
            end == reference,
            "{k} processes: the run differs from one process's"
        );
    }
}
