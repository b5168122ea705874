//! The same bits however the particles are laid out: each particle's forces are summed in
//! the order of its partners' ids, so the storage order, the slabs of the pair stage and
//! the times of the neighbour-list rebuilds (which re-sort the particles) change nothing.
//! It is what a run split over processes rests on: each process holds its own particles in
//! its own order.

use crate::common;

use tinydem::engine::{Simulation, Wrench};
use tinydem::model::particles::Particles;
use tinydem::parallel::comm::{Comm, Threads};
use tinydem::scenario::Scenario;

/// Each particle's id with the bits of its state, in id order.
fn state_by_id(sim: &Simulation) -> Vec<(u64, Vec<u64>)> {
    bits_by_id(&sim.particles)
}

fn bits_by_id(particles: &Particles) -> Vec<(u64, Vec<u64>)> {
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
            // With heat transfer: the temperature and the exact content.
            bits.extend([
                p.temperature.to_bits(),
                p.heat as u64,
                (p.heat >> 64) as u64,
            ]);
            (id, bits)
        })
        .collect()
}

/// What a run ends with, to compare runs: every particle's bits, the loads on the walls
/// since the start, the particles removed and the energy.
#[derive(Debug, PartialEq)]
struct End {
    particles: Vec<(u64, Vec<u64>)>,
    /// Each rigid body's id with the bits of its x, v, q, w.
    bodies: Vec<(u64, Vec<u64>)>,
    walls: Vec<[u64; 6]>,
    removed: u64,
    kinetic_energy: u64,
    contacts: (usize, usize),
    /// The heat into each mesh file since the start, and the temperatures' numbers.
    heat: (Vec<u64>, Option<[u64; 4]>),
    /// The energy ledger's columns, if it is kept.
    energy: Option<[u64; 12]>,
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
    let wall_heat = sim.take_wall_heat().iter().map(|q| q.to_bits()).collect();
    let thermo = sim.thermo();
    let all = sim.gather_particles();
    let bodies = all
        .bodies
        .list
        .iter()
        .map(|b| {
            let state = [b.x.to_array(), b.v.to_array(), b.w.to_array()].concat();
            let bits = state.into_iter().chain(b.q.to_array()).map(f64::to_bits);
            (b.id.first(), bits.collect())
        })
        .collect();
    End {
        particles: bits_by_id(&all),
        bodies,
        walls,
        removed: thermo.removed,
        kinetic_energy: thermo.kinetic_energy.to_bits(),
        contacts: (thermo.pair_contacts, thermo.wall_contacts),
        heat: (
            wall_heat,
            thermo
                .heat
                .map(|t| [t.mean, t.min, t.max, t.content].map(f64::to_bits)),
        ),
        energy: thermo.energy.map(|b| b.columns().map(f64::to_bits)),
    }
}

/// A scenario run for `steps` steps split over `k` processes (threads of this one), as
/// process 0 ends it (all end alike); and how often the boxes were cut.
fn split_run(
    make: impl Fn() -> Scenario + Send + Clone + 'static,
    steps: u64,
    k: usize,
) -> (End, u64) {
    let handles: Vec<_> = Threads::group(k)
        .into_iter()
        .map(|comm| {
            let make = make.clone();
            std::thread::spawn(move || {
                let rank = comm.rank();
                let sim = Simulation::new(make()).expect("starts");
                let mut sim = sim.split(Box::new(comm)).expect("splits");
                for _ in 0..steps {
                    sim.step().expect("stable");
                }
                let cuts = sim.share().expect("split").cuts;
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
        let text = text.clone();
        let (end, cuts) = split_run(move || common::scenario(&text), steps, k);
        // Two halves of the symmetric fill stay balanced (one cut, measured); three and
        // four boxes are cut anew as the silo fills (4 and 5 cuts).
        assert!(
            cuts > 1 || k == 2,
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

/// A rotating drum half full of grains: each grain goes round, across the boxes of the
/// processes and back, in contact with others and the wall all the while.
fn tumbler(mesh: &std::path::Path) -> String {
    format!(
        "[geometry]\nradius_min = 0.004\nradius_max = 0.005\n\
         spawn_min = [-0.035, -0.01, -0.035]\nspawn_max = [0.035, 0.01, 0.035]\n\
         [material]\nyoungs_modulus = 1e6\nrestitution = 0.3\nfriction_sliding = 0.6\nfriction_rolling = 0.1\nfriction_twisting = 0.1\n\
         [simulation]\nmax_particles = 120\n\
         [[meshes]]\nfile = \"{}\"\nradii = [0.0]\n\
         motion = {{ type = \"rotation\", center = [0.0, 0.0, 0.0], axis = [0.0, 1.0, 0.0], angular_velocity = 30.0 }}\n",
        mesh.display()
    )
}

#[test]
fn grains_crossing_between_processes_in_contact_keep_their_springs() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("drum.off");
    std::fs::write(&mesh, common::drum_off(24)).unwrap();
    let text = tumbler(&mesh);
    let steps = 6000;
    let mut single = common::simulate(&text, steps);
    let reference = end_of(&mut single);
    assert!(
        reference.contacts.0 > 50 && reference.contacts.1 > 10,
        "{:?}",
        reference.contacts
    );
    // How often grain 7 changes hands on 2 processes.
    let handles: Vec<_> = Threads::group(2)
        .into_iter()
        .map(|comm| {
            let text = text.clone();
            std::thread::spawn(move || {
                let sim = Simulation::new(common::scenario(&text)).expect("starts");
                let mut sim = sim.split(Box::new(comm)).expect("splits");
                let (mut changes, mut had) = (0, None);
                for _ in 0..steps {
                    sim.step().expect("stable");
                    let has = sim.owns(7);
                    changes += (had.is_some_and(|h| h != has)) as u32;
                    had = Some(has);
                }
                (end_of(&mut sim), changes)
            })
        })
        .collect();
    for h in handles {
        let (end, changes) = h.join().expect("no panic");
        assert!(changes >= 4, "grain 7 changed hands {changes} times");
        assert!(end == reference, "the split run differs from one process's");
    }
}

#[test]
fn the_reference_cases_split_over_processes_give_the_bits_of_one() {
    for case in [
        "headon",
        "oblique_spin",
        "floor_slide",
        "floor_twist",
        "primitives",
        "drag",
        "small_pile",
    ] {
        let path = common::data(&format!("reference/{case}/scenario.toml"));
        let make = move || Scenario::load(&path).expect("loads");
        let s = make();
        let steps = s.simulation.frames * s.simulation.steps_per_frame;
        let mut single = Simulation::new(make()).unwrap();
        for _ in 0..steps {
            single.step().unwrap();
        }
        let reference = end_of(&mut single);
        for k in [2, 3, 4] {
            let (end, _) = split_run(make.clone(), steps, k);
            assert!(
                end == reference,
                "{case} on {k} processes differs from one process"
            );
        }
    }
}

/// The silo filled from two regions, one hot, one cold: heat flows between the grains as
/// they fall and settle, and from the grains into a plate held at 280 K below the outlet.
fn heated_silo() -> String {
    "[geometry]\nradius_min = 0.003\nradius_max = 0.004\nmesh = \"stages/silo.off\"\nmesh_radii = [0.0]\n\
     [[materials]]\nname = \"grain\"\nrestitution = 0.3\nfriction_sliding = 0.5\n\
     thermal_conductivity = 2.0\nheat_capacity = 900.0\ninitial_temperature = 300.0\n\
     [[materials]]\nname = \"steel\"\nthermal_conductivity = 40.0\n\
     [[meshes]]\nshape = { type = \"plane\", point = [0.0, 0.0, -0.1], normal = [0.0, 0.0, 1.0], size = 0.2 }\n\
     material = \"steel\"\ntemperature = 280.0\n\
     [[spawn]]\nmin = [-0.05, -0.05, 0.06]\nmax = [0.0, 0.05, 0.14]\ncount = 150\ntemperature = 450.0\n\
     [[spawn]]\nmin = [0.0, -0.05, 0.06]\nmax = [0.05, 0.05, 0.14]\ncount = 150\n\
     [simulation]\nmax_particles = 300\nthermal_time_scale = 1000.0\n\
     [domain]\nmin = [-0.1, -0.1, -0.2]\nmax = [0.1, 0.1, 0.2]\n\
     [output]\nwall_forces = true\n"
        .into()
}

#[test]
fn heat_split_over_processes_gives_the_bits_of_one_process_and_resumes_on_another_count() {
    let steps = 2500;
    let mut single = common::simulate(&heated_silo(), steps);
    let reference = end_of(&mut single);
    let (walls, temperatures) = &reference.heat;
    assert!(
        f64::from_bits(walls[1]) > 0.0,
        "the grains warm the plate up: {walls:?}"
    );
    let t = temperatures.expect("heat is on").map(f64::from_bits);
    assert!(t[1] < 300.0 + 1.0 && t[2] > 449.0 && t[0] > 310.0, "{t:?}");
    for k in [2, 3] {
        let (end, _) = split_run(|| common::scenario(&heated_silo()), steps, k);
        assert!(
            end == reference,
            "{k} processes: the run differs from one process's"
        );
    }
    checkpoint_on_2_resumes_on_3(|| common::scenario(&heated_silo()), 1200, 1300);
}

#[test]
fn a_checkpoint_of_two_processes_resumes_on_three_with_the_same_bits() {
    // With the energy ledger, which the checkpoint keeps (`End::energy`).
    let text = silo(0.5).replace(
        "wall_forces = true\n",
        "wall_forces = true\nenergy_ledger = true\n",
    );
    checkpoint_on_2_resumes_on_3(move || common::scenario(&text), 1200, 1300);
}

#[test]
fn a_sheared_periodic_box_checkpointed_on_two_processes_resumes_on_three() {
    checkpoint_on_2_resumes_on_3(shear_cell, 700, 600);
}

/// A run of `first + then` steps in one process; and `first` steps on 2 processes, then
/// the checkpoint's snapshot resumed for `then` steps on 3 and in one: all end alike.
fn checkpoint_on_2_resumes_on_3(
    make: impl Fn() -> Scenario + Send + Clone + 'static,
    first: u64,
    then: u64,
) {
    let mut single = Simulation::new(make()).unwrap();
    for _ in 0..first + then {
        single.step().unwrap();
    }
    let reference = end_of(&mut single);
    // `first` steps on 2 processes, then the checkpoint's snapshot.
    let handles: Vec<_> = Threads::group(2)
        .into_iter()
        .map(|comm| {
            let make = make.clone();
            std::thread::spawn(move || {
                let sim = Simulation::new(make()).unwrap();
                let mut sim = sim.split(Box::new(comm)).unwrap();
                for _ in 0..first {
                    sim.step().unwrap();
                }
                // What the writer is handed to write, and the others not (they never
                // hold the whole): the snapshot and the particles of a frame.
                let for_writer = sim.snapshot_for_writer().unwrap();
                let frame = sim.particles_in_domain().into_owned();
                let all = sim.snapshot().unwrap();
                match sim.is_writer() {
                    true => {
                        assert!(for_writer.as_ref() == Some(&all) && frame.id == all.particles.id)
                    }
                    false => assert!(for_writer.is_none() && frame.is_empty()),
                }
                (all, sim.snapshot_piece())
            })
        })
        .collect();
    let (snapshots, pieces): (Vec<_>, Vec<_>) =
        handles.into_iter().map(|h| h.join().unwrap()).unzip();
    assert!(
        snapshots[0] == snapshots[1],
        "both processes should see the same snapshot"
    );
    let snapshot = snapshots[0].clone();
    assert!(!snapshot.pair_history.is_empty());
    // The pieces each process writes on a stop, read back as the checkpoint: the snapshot.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("checkpoint.bin");
    for (k, piece) in pieces.iter().enumerate() {
        assert!(piece.particles.len() < snapshot.particles.len());
        tinydem::io::checkpoint::save_part(&path, k, 2, piece, 7).unwrap();
    }
    let joined = tinydem::io::checkpoint::load(&path, Some(7)).unwrap();
    assert!(joined == snapshot, "the parts should join to the snapshot");
    // Resumed on 3 processes, and in one.
    let resumed = {
        let (snapshot, make) = (snapshot.clone(), make.clone());
        let open = move |comm: Threads| {
            let sim = Simulation::restore(make(), snapshot.clone()).unwrap();
            sim.split(Box::new(comm)).unwrap()
        };
        split_resume(open, then, 3)
    };
    // Resumed on 3 processes from the parts, each reading its share only (the first none
    // of the two parts, the others one each).
    let from_shares = {
        let (path, make, n) = (path.clone(), make.clone(), snapshot.particles.len());
        let open = move |comm: Threads| {
            let share = (comm.rank(), comm.size());
            let piece = tinydem::io::checkpoint::load_share(&path, Some(7), share).unwrap();
            let piece = piece.expect("a checkpoint in parts");
            assert!(piece.particles.len() < n, "no process reads all parts");
            let (sim, pending) = Simulation::restore_share(make(), piece).unwrap();
            sim.split_shares_with(Box::new(comm), pending).unwrap()
        };
        split_resume(open, then, 3)
    };
    let mut one = Simulation::restore(make(), snapshot).unwrap();
    for _ in 0..then {
        one.step().unwrap();
    }
    assert!(
        end_of(&mut one) == reference,
        "resumed in one process, the run differs"
    );
    assert!(
        resumed == reference,
        "resumed on 3 processes, the run differs"
    );
    assert!(
        from_shares == reference,
        "resumed on 3 processes from shares of the parts, the run differs"
    );
}

/// A run restored from a snapshot and continued for `steps` on `k` processes.
fn split_resume(
    open: impl Fn(Threads) -> Simulation + Send + Clone + 'static,
    steps: u64,
    k: usize,
) -> End {
    let handles: Vec<_> = Threads::group(k)
        .into_iter()
        .map(|comm| {
            let open = open.clone();
            std::thread::spawn(move || {
                let mut sim = open(comm);
                for _ in 0..steps {
                    sim.step().unwrap();
                }
                end_of(&mut sim)
            })
        })
        .collect();
    let mut ends: Vec<End> = handles.into_iter().map(|h| h.join().unwrap()).collect();
    let first = ends.remove(0);
    assert!(
        ends.iter().all(|e| *e == first),
        "the processes end otherwise"
    );
    first
}

#[test]
fn the_output_of_a_split_run_is_that_of_one_process_byte_for_byte() {
    use tinydem::driver::run::{Options, Verbosity, run_on};
    let mut text = silo(0.5);
    text.push_str("contacts = true\nformats = [\"csv\", \"vtk\"]\n");
    text = text.replace(
        "max_particles = 300\n",
        "max_particles = 300\nframes = 5\nsteps_per_frame = 400\n",
    );
    let options = Options {
        verbosity: Verbosity::Quiet,
        resume: None,
        from: None,
        overwrite: false,
        force: true,
        requests: None,
    };
    let one = tempfile::tempdir().unwrap();
    tinydem::driver::run::run(common::scenario(&text), one.path(), options).unwrap();
    let split = tempfile::tempdir().unwrap();
    let handles: Vec<_> = Threads::group(3)
        .into_iter()
        .map(|comm| {
            let (text, dir) = (text.clone(), split.path().to_path_buf());
            std::thread::spawn(move || {
                run_on(common::scenario(&text), &dir, options, Some(Box::new(comm)))
                    .map(|s| s.particles)
            })
        })
        .collect();
    for h in handles {
        h.join().unwrap().unwrap();
    }
    let mut names: Vec<String> = std::fs::read_dir(one.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n != "checkpoint.bin")
        .collect();
    names.sort();
    assert!(
        names.iter().any(|n| n == "walls.csv") && names.iter().any(|n| n == "contacts000005.csv"),
        "{names:?}"
    );
    for name in &names {
        let a = std::fs::read(one.path().join(name)).unwrap();
        let b = std::fs::read(split.path().join(name)).unwrap_or_default();
        assert!(a == b, "{name} differs");
    }
}

#[test]
fn an_instability_split_over_processes_stops_all_with_the_message_of_one() {
    // Twelve small grains shot into big ones along a line, across the processes' boxes: each
    // gets wholly inside its target within a step or two; the message names five of them.
    let dir = tempfile::tempdir().unwrap();
    let mut rows = String::from("x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n");
    for k in 0..12 {
        let x = 0.05 * k as f64;
        rows.push_str(&format!("{},0,0,0.002,5,0,0,1,0,0,0,0,0,0\n", x - 0.0125));
        rows.push_str(&format!("{x},0,0,0.01,0,0,0,1,0,0,0,0,0,0\n"));
    }
    let csv = dir.path().join("p.csv");
    std::fs::write(&csv, rows).unwrap();
    let text = format!(
        "[geometry]\nradius_min = 0.002\nradius_max = 0.01\n[kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
         [simulation]\nmax_particles = 0\ntimestep = 1e-3\n[input]\nparticles = \"{}\"\n",
        csv.display()
    );
    let mut single = Simulation::new(common::scenario(&text)).unwrap();
    let expected = loop {
        if let Err(e) = single.step() {
            break e.to_string();
        }
        assert!(single.steps < 100, "the run should become unstable");
    };
    assert_eq!(
        expected.matches("smaller diameter").count(),
        5,
        "{expected}"
    );
    for k in [2, 3] {
        let handles: Vec<_> = Threads::group(k)
            .into_iter()
            .map(|comm| {
                let text = text.clone();
                std::thread::spawn(move || {
                    let sim = Simulation::new(common::scenario(&text)).unwrap();
                    let mut sim = sim.split(Box::new(comm)).unwrap();
                    loop {
                        if let Err(e) = sim.step() {
                            break e.to_string();
                        }
                    }
                })
            })
            .collect();
        for h in handles {
            assert_eq!(h.join().unwrap(), expected, "{k} processes");
        }
    }
}

/// A chute periodic along x and y: grains spawned over the whole box fall onto a plate,
/// pile up and flow down the slope of gravity along x, across the periodic sides and the
/// processes' boxes, in contact all the while.
fn periodic_chute() -> String {
    "[geometry]\nradius_min = 0.003\nradius_max = 0.004\nmesh = \"domain/plate.off\"\nmesh_radii = [0.0]\n\
     [material]\nrestitution = 0.3\nfriction_sliding = 0.4\nfriction_rolling = 0.05\nfriction_twisting = 0.05\n\
     [kinetics]\ngravity = [4.0, 1.0, -9.0]\n\
     [simulation]\nmax_particles = 400\n\
     [domain]\nmin = [-0.04, -0.03, -0.05]\nmax = [0.04, 0.03, 0.2]\nperiodic = [true, true, false]\n\
     [[spawn]]\nmin = [-0.04, -0.03, 0.01]\nmax = [0.04, 0.03, 0.06]\ncount = 400\n\
     [output]\nwall_forces = true\n"
        .into()
}

#[test]
fn a_periodic_chute_split_over_processes_gives_the_bits_of_one() {
    let steps = 4000;
    let text = periodic_chute();
    let mut single = common::simulate(&text, steps);
    let crossed = single
        .particles
        .x
        .iter()
        .filter(|x| x.x.abs() > 0.04 || x.y.abs() > 0.03)
        .count();
    let reference = end_of(&mut single);
    eprintln!(
        "chute: {} grains, contacts {:?}, {crossed} beyond a side now, {} rebuilds",
        reference.particles.len(),
        reference.contacts,
        single.rebuilds()
    );
    assert!(reference.particles.len() >= 300);
    assert!(reference.contacts.0 > 100 && reference.contacts.1 > 50);
    for k in [2, 3, 4] {
        let text = text.clone();
        let (end, _) = split_run(move || common::scenario(&text), steps, k);
        assert!(
            end == reference,
            "{k} processes: the periodic chute differs from one process's"
        );
    }
}

/// The shear cell of the examples: a box periodic along x, y and z, sheared by
/// Lees-Edwards boundaries, with two materials.
fn shear_cell() -> Scenario {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/h_shear_cell/scenario.toml");
    Scenario::load(&path).expect("loads")
}

#[test]
fn a_sheared_periodic_box_split_over_processes_gives_the_bits_of_one() {
    let steps = 1500;
    let mut single = Simulation::new(shear_cell()).unwrap();
    for _ in 0..steps {
        single.step().unwrap();
    }
    let reference = end_of(&mut single);
    assert!(reference.contacts.0 > 300, "{:?}", reference.contacts);
    for k in [2, 3] {
        let (end, _) = split_run(shear_cell, steps, k);
        assert!(
            end == reference,
            "{k} processes: the sheared box differs from one process's"
        );
    }
}

/// Grains poured into a periodic cell whose lid, a servo, comes down at 0.5 m/s and
/// presses them with 0.5 N while they settle. Periodic, so that the bits depend on when the
/// lists are rebuilt (a rebuild wraps the positions), and so on the lid's drift since the
/// last rebuild being the same after a resume and a split.
fn servo_box() -> Scenario {
    common::scenario(
        "[geometry]\nradius_min = 0.003\nradius_max = 0.004\n\
         spawn_min = [-0.03, -0.03, 0.005]\nspawn_max = [0.03, 0.03, 0.05]\n\
         [material]\nrestitution = 0.3\nfriction_sliding = 0.5\nfriction_rolling = 0.1\n\
         [simulation]\nmax_particles = 250\n\
         [domain]\nmin = [-0.03, -0.03, -0.01]\nmax = [0.03, 0.03, 0.1]\nperiodic = [true, true, false]\n\
         [output]\nwall_forces = true\n\
         [[meshes]]\nshape = { type = \"plane\", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 0.4 }\n\
         [[meshes]]\nshape = { type = \"plane\", point = [0.0, 0.0, 0.06], normal = [0.0, 0.0, 1.0], size = 0.4 }\n\
         motion = { type = \"servo\", direction = [0.0, 0.0, -1.0], force = 0.5, max_speed = 0.5 }\n",
    )
}

#[test]
fn a_servo_lid_split_over_processes_and_resumed_gives_the_bits_of_one() {
    // The lid touches the grains at step ~650 and presses on them, more and more, past the
    // checkpoint (measured: 0.05 N over steps 1000-1200, 0.42 N by step 2500).
    let mut sim = Simulation::new(servo_box()).unwrap();
    for step in 0..1200 {
        if step == 1000 {
            sim.take_wall_loads();
        }
        sim.step().unwrap();
    }
    let lid = sim.take_wall_loads()[2].f.z / 200.0;
    assert!(lid > 0.02, "the lid should press on the grains: {lid} N");
    checkpoint_on_2_resumes_on_3(servo_box, 1200, 1300);
}

/// The silo of [`silo`] filled with dimers and triangles beside spheres, each from a
/// `[[spawn]]` region of its own, through the outlet below.
fn clump_silo() -> String {
    let spheres = "spawn_min = [-0.05, -0.05, 0.06]\nspawn_max = [0.05, 0.05, 0.14]\n";
    silo(0.5)
        .replace(spheres, "")
        .replace("max_particles = 300", "max_particles = 600")
        + "[[clumps]]\nname = \"dimer\"\nspheres = [[0.0, 0.0, 0.0, 0.0035], [0.005, 0.0, 0.0, 0.0035]]\n\
           [[clumps]]\nname = \"tri\"\nspheres = [[0.0, 0.0, 0.0, 0.0035], [0.006, 0.0, 0.0, 0.0035], [0.003, 0.0052, 0.0, 0.0035]]\n\
           [[spawn]]\nmin = [-0.05, -0.05, 0.06]\nmax = [0.05, 0.05, 0.14]\nclump = \"dimer\"\nscale = { min = 0.9, max = 1.1 }\ncount = 80\n\
           [[spawn]]\nmin = [-0.05, -0.05, 0.06]\nmax = [0.05, 0.05, 0.14]\nclump = \"tri\"\ncount = 60\n\
           [[spawn]]\nmin = [-0.05, -0.05, 0.06]\nmax = [0.05, 0.05, 0.14]\ncount = 60\n"
}

#[test]
fn clumps_split_over_processes_give_the_bits_of_one() {
    let steps = 2500;
    let text = clump_silo();
    let mut single = common::simulate(&text, steps);
    let reference = end_of(&mut single);
    eprintln!(
        "clump silo: {} spheres, {} bodies, {} removed, contacts {:?}",
        reference.particles.len(),
        reference.bodies.len(),
        reference.removed,
        reference.contacts
    );
    assert!(reference.bodies.len() > 80 && reference.removed > 0);
    assert!(reference.contacts.0 > 100 && reference.contacts.1 > 20);
    for k in [2, 3] {
        let text = text.clone();
        let (end, cuts) = split_run(move || common::scenario(&text), steps, k);
        assert!(cuts > 1, "{k} processes: the boxes should be cut anew");
        assert!(
            end == reference,
            "{k} processes: the clump silo differs from one process's"
        );
    }
}

#[test]
fn a_checkpoint_of_clumps_on_two_processes_resumes_on_three_with_the_same_bits() {
    let text = clump_silo();
    checkpoint_on_2_resumes_on_3(move || common::scenario(&text), 1200, 1000);
}

#[test]
fn clumps_in_a_periodic_chute_split_over_processes_give_the_bits_of_one() {
    let steps = 3000;
    let text = periodic_chute().replace("count = 400", "count = 150")
        + "[[clumps]]\nname = \"dimer\"\nspheres = [[0.0, 0.0, 0.0, 0.0035], [0.005, 0.0, 0.0, 0.0035]]\n\
           [[spawn]]\nmin = [-0.04, -0.03, 0.06]\nmax = [0.04, 0.03, 0.12]\nclump = \"dimer\"\ncount = 120\n";
    let mut single = common::simulate(&text, steps);
    let reference = end_of(&mut single);
    eprintln!(
        "clump chute: {} spheres, {} bodies, contacts {:?}",
        reference.particles.len(),
        reference.bodies.len(),
        reference.contacts
    );
    assert!(reference.bodies.len() >= 100);
    for k in [2, 3] {
        let text = text.clone();
        let (end, _) = split_run(move || common::scenario(&text), steps, k);
        assert!(
            end == reference,
            "{k} processes: the periodic clump chute differs from one process's"
        );
    }
}

#[test]
fn clumps_in_a_sheared_periodic_box_split_over_processes_give_the_bits_of_one() {
    let steps = 1500;
    let text = "[geometry]\nradius_min = 0.002\nradius_max = 0.002\n\
        [material]\nyoungs_modulus = 1e6\nrestitution = 0.5\nfriction_sliding = 0.4\nfriction_rolling = 0.05\n\
        [kinetics]\ngravity = [0.0, 0.0, 0.0]\n\
        [simulation]\nmax_particles = 1400\n\
        [domain]\nmin = [-0.025, -0.025, -0.025]\nmax = [0.025, 0.025, 0.025]\nperiodic = [true, true, true]\n\
        lees_edwards = { velocity = 0.5, shear_axis = \"x\", gradient_axis = \"z\" }\n\
        [[clumps]]\nname = \"dimer\"\nspheres = [[0.0, 0.0, 0.0, 0.002], [0.003, 0.0, 0.0, 0.002]]\n\
        [[spawn]]\nmin = [-0.025, -0.025, -0.025]\nmax = [0.025, 0.025, 0.025]\nclump = \"dimer\"\ncount = 500\n\
        [[spawn]]\nmin = [-0.025, -0.025, -0.025]\nmax = [0.025, 0.025, 0.025]\ncount = 300\n";
    let mut single = common::simulate(text, steps);
    let reference = end_of(&mut single);
    eprintln!(
        "sheared clumps: {} spheres, {} bodies, contacts {:?}, {} rebuilds",
        reference.particles.len(),
        reference.bodies.len(),
        reference.contacts,
        single.rebuilds()
    );
    assert!(reference.bodies.len() >= 400 && reference.contacts.0 > 100);
    for k in [2, 3] {
        let (end, _) = split_run(move || common::scenario(text), steps, k);
        assert!(
            end == reference,
            "{k} processes: the sheared box of clumps differs from one process's"
        );
    }
}

#[test]
fn the_contact_models_split_over_processes_give_the_bits_of_one_process() {
    let steps = 1500;
    for models in [
        "hooke_stiffness = 300.0\ntangential_coulomb = \"spring\"\nrolling_model = \"cdt\"\n",
        "rolling_model = \"epsd2\"\nadhesion_model = \"dmt\"\nsurface_energy = 0.02\n",
        "adhesion_model = \"jkr\"\nsurface_energy = 0.05\n",
        "liquid_volume = 1e-10\nsurface_tension = 0.07\ncontact_angle = 20.0\n",
    ] {
        // With the energy ledger, whose sums are exact as the loads.
        let text = silo(0.5)
            .replace(
                "friction_twisting = 0.1\n",
                &format!("friction_twisting = 0.1\n{models}"),
            )
            .replace(
                "wall_forces = true\n",
                "wall_forces = true\nenergy_ledger = true\n",
            );
        assert!(text.contains(models));
        let mut single = common::simulate(&text, steps);
        let reference = end_of(&mut single);
        assert!(reference.energy.is_some());
        for k in [2, 3] {
            let text = text.clone();
            let (end, _) = split_run(move || common::scenario(&text), steps, k);
            assert!(
                end == reference,
                "{models} on {k} processes differs from one"
            );
        }
    }
}
