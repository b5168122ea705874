//! Bounded domains, outlets and wall loads: removal keeps ids unique and conserves the
//! count, leaves the others' motion untouched; the load on the walls of a settled bed is its
//! weight; torques follow Newton's third law about the stated point.

use crate::common;

use std::collections::{BTreeMap, BTreeSet};

use glam::{DQuat, DVec3};
use tinydem::engine::Simulation;
use tinydem::geometry::mesh::Mesh;
use tinydem::model::integrate::Inertia;
use tinydem::model::particles::{Particle, Particles};

const R: f64 = 0.004;
const RHO: f64 = 1000.0;

fn at_rest(x: DVec3, v: DVec3) -> Particle {
    Particle {
        x,
        radius: R,
        v,
        q: DQuat::IDENTITY,
        w: DVec3::ZERO,
        tag: 0,
        material: 0,
        fixed: false,
        body: None,
        ..Particle::default()
    }
}

/// Grains spawned in a box fall out of it: those with x < 0 through an outlet, the others
/// out of the domain's floor.
#[test]
fn removal_keeps_ids_unique_and_conserves_the_count() {
    let mut sim = common::simulate(
        "[geometry]\nradius_min = 0.002\nradius_max = 0.004\n\
         spawn_min = [-0.05, -0.05, 0.0]\nspawn_max = [0.05, 0.05, 0.05]\n\
         [simulation]\nmax_particles = 200\n\
         [domain]\nmin = [-0.1, -0.1, -0.05]\nmax = [0.1, 0.1, 0.2]\n\
         [[outlets]]\nmin = [-1.0, -1.0, -0.03]\nmax = [0.0, 1.0, -0.02]\n",
        0,
    );
    let mut mass: BTreeMap<u64, f64> = BTreeMap::new();
    let mut gone: BTreeSet<u64> = BTreeSet::new();
    for step in 0..3000 {
        sim.step().unwrap();
        let p = &sim.particles;
        let ids: BTreeSet<u64> = p.id.iter().copied().collect();
        assert_eq!(ids.len(), p.len(), "step {step}: ids repeat");
        assert!(
            ids.is_disjoint(&gone),
            "step {step}: a removed id came back"
        );
        assert_eq!(
            p.len() as u64 + sim.removed.count(),
            p.next_id,
            "step {step}: inside + removed != created"
        );
        for (k, &id) in p.id.iter().enumerate() {
            mass.entry(id).or_insert(Inertia::mass(p.radius[k], RHO));
        }
        gone.extend(mass.keys().filter(|id| !ids.contains(id)));
    }
    let r = &sim.removed;
    assert_eq!(sim.particles.len(), 0, "every grain has fallen out");
    assert_eq!(r.outlets[0].count + r.domain.count, 200);
    assert!(r.outlets[0].count > 60 && r.domain.count > 60, "{r:?}");
    let total: f64 = mass.values().sum();
    let removed = r.outlets[0].mass + r.domain.mass;
    assert!(
        (removed / total - 1.0).abs() < 1e-12,
        "{removed} vs {total}"
    );
}

/// Two grains sliding over a floor, with and without a third far away that falls into an
/// outlet: the pair's motion (and its friction springs) are the same bits.
#[test]
fn removing_a_particle_leaves_the_others_untouched() {
    let run = |with_third: bool| {
        let s = common::scenario(&format!(
            "[geometry]\nradius_min = {R}\nradius_max = {R}\nmesh_radii = [0.0]\n\
             [material]\nfriction_sliding = 0.5\n\
             [simulation]\nmax_particles = 0\nspawn_attempts = 0\n\
             [[outlets]]\nmin = [0.5, -1.0, -1.0]\nmax = [1.0, 1.0, -0.1]\n"
        ));
        let floor = "OFF\n4 1 0\n-0.2 -0.2 0\n0.2 -0.2 0\n0.2 0.2 0\n-0.2 0.2 0\n4 0 1 2 3\n";
        let mesh = Mesh::parse_off(floor, "floor", &s.geometry.mesh_radii).unwrap();
        let mut p = vec![
            at_rest(DVec3::new(0.0, 0.0, R * 0.999), DVec3::new(0.3, 0.0, 0.0)),
            at_rest(
                DVec3::new(2.0 * R, 0.0, R * 0.999),
                DVec3::new(-0.1, 0.05, 0.0),
            ),
        ];
        if with_third {
            p.push(at_rest(
                DVec3::new(0.7, 0.0, -0.05),
                DVec3::new(0.0, 0.0, -1.0),
            ));
        }
        let mut sim =
            Simulation::from_parts(s, mesh, p.into_iter().collect::<Particles>()).unwrap();
        let mut trace = Vec::new();
        for _ in 0..3000 {
            sim.step().unwrap();
            let p = &sim.particles;
            let pair: Vec<_> = p
                .iter_by_id()
                .filter(|(id, _)| *id < 2)
                .map(|(_, q)| (q.x, q.v, q.w, q.q))
                .collect();
            trace.push(pair);
        }
        (trace, sim.removed.count())
    };
    let (alone, none) = run(false);
    let (with, one) = run(true);
    assert_eq!((none, one), (0, 1));
    assert!(alone == with, "the pair moved differently");
}

/// An open box with a floor of two triangles (a shared diagonal) and four walls.
const BOX: &str = "OFF\n8 6 0\n\
    -0.03 -0.03 0\n0.03 -0.03 0\n0.03 0.03 0\n-0.03 0.03 0\n\
    -0.03 -0.03 0.1\n0.03 -0.03 0.1\n0.03 0.03 0.1\n-0.03 0.03 0.1\n\
    3 0 1 2\n3 0 2 3\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";

/// 150 grains poured into the open box, after `steps` steps (summing the wall loads).
fn settled_bed(steps: u32) -> Simulation {
    let s = common::scenario(
        "[geometry]\nradius_min = 0.003\nradius_max = 0.004\nmesh_radii = [0.0]\n\
         spawn_min = [-0.025, -0.025, 0.01]\nspawn_max = [0.025, 0.025, 0.09]\n\
         [material]\nrestitution = 0.2\n\
         [kinetics]\ninitial_velocity = [0.0, 0.0, 0.0]\n\
         [simulation]\nmax_particles = 150\n\
         [output]\nwall_forces = true\n",
    );
    let mesh = Mesh::parse_off(BOX, "box", &s.geometry.mesh_radii).unwrap();
    let mut sim = Simulation::from_parts(s, mesh, Particles::default()).unwrap();
    for _ in 0..steps {
        sim.step().unwrap();
    }
    sim
}

#[test]
fn the_load_on_the_walls_of_a_settled_bed_is_its_weight() {
    let mut sim = settled_bed(12_000);
    sim.take_wall_loads();
    let n = 2000;
    for _ in 0..n {
        sim.step().unwrap();
    }
    let loads = sim.take_wall_loads();
    assert_eq!(loads.len(), 1);
    let f = loads[0].f / n as f64;
    let p = &sim.particles;
    assert_eq!(p.len(), 150);
    let weight: f64 = p.radius.iter().map(|&r| Inertia::mass(r, RHO) * 9.81).sum();
    assert!(
        (f.z / -weight - 1.0).abs() < 0.01,
        "vertical load {} N vs weight {weight} N",
        f.z
    );
    assert!(
        f.x.abs() < 0.01 * weight && f.y.abs() < 0.01 * weight,
        "{f}"
    );
}

/// A grain resting on a plate at x = a presses with its weight m g; about the origin that
/// is a torque a m g about y, about a point under the grain none.
#[test]
fn wall_torques_are_taken_about_the_origin_or_the_centre_of_rotation() {
    let a = 0.05;
    let load = |rotation: bool| {
        let motion = if rotation {
            format!(
                "motion = {{ type = \"rotation\", center = [{a}, 0.0, 0.0], axis = [0.0, 0.0, 1.0], angular_velocity = 0.0 }}\n"
            )
        } else {
            String::new()
        };
        let mut sim = common::simulate(
            &format!(
                "[geometry]\nradius_min = {R}\nradius_max = {R}\n\
                 [simulation]\nmax_particles = 0\nspawn_attempts = 0\n\
                 [input]\nparticles = \"domain/one_grain.csv\"\n\
                 [[meshes]]\nfile = \"domain/plate.off\"\n{motion}\
                 [output]\nwall_forces = true\n"
            ),
            20_000,
        );
        sim.take_wall_loads();
        for _ in 0..100 {
            sim.step().unwrap();
        }
        let w = sim.take_wall_loads()[1];
        (w.f / 100.0, w.tau / 100.0)
    };
    let mg = Inertia::mass(R, RHO) * 9.81;
    let (f, tau) = load(false);
    assert!((f.z / -mg - 1.0).abs() < 1e-6, "{f} vs {mg}");
    assert!((tau.y / (a * mg) - 1.0).abs() < 1e-6, "{tau}");
    assert!(tau.x.abs() < 1e-9 * mg && tau.z.abs() < 1e-9 * mg, "{tau}");
    let (_, tau) = load(true);
    assert!(tau.length() < 1e-6 * a * mg, "{tau}");
}

/// The logs of a run: `outlets.csv` (cumulative count and mass per outlet), `walls.csv`
/// (the mean load per mesh file over each frame), frames with ids, a checkpoint at the end;
/// a resumed run continues the logs from its checkpoint's frame.
#[test]
fn a_run_logs_outlets_and_wall_loads_and_resumes_them() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        common::data("domain/plate.off"),
        dir.path().join("plate.off"),
    )
    .unwrap();
    let scenario = |frames: u32| {
        format!(
            "[geometry]\nradius_min = 0.003\nradius_max = 0.004\n\
             spawn_min = [-0.25, -0.05, 0.01]\nspawn_max = [0.05, 0.05, 0.05]\n\
             [simulation]\nmax_particles = 60\nframes = {frames}\nsteps_per_frame = 200\n\
             [domain]\nmin = [-0.3, -0.3, -0.5]\nmax = [0.3, 0.3, 0.5]\n\
             [[outlets]]\nmin = [-0.3, -0.3, -0.5]\nmax = [0.0, 0.3, -0.01]\n\
             [[meshes]]\nfile = \"plate.off\"\n\
             [output]\nwall_forces = true\ncheckpoint_every = 2\n"
        )
    };
    std::fs::write(dir.path().join("s.toml"), scenario(4)).unwrap();
    let out = common::tinydem(&["run", "s.toml", "-o", "a", "-q"], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let a = dir.path().join("a");
    let read = |p: std::path::PathBuf| std::fs::read_to_string(p).unwrap();
    let outlets = read(a.join("outlets.csv"));
    let lines: Vec<&str> = outlets.lines().collect();
    assert_eq!(lines[0], "frame,time,outlet,count,mass");
    assert_eq!(lines.len(), 1 + 5, "{outlets}");
    assert!(lines[1].starts_with("0,0.0,0,0,0.0"), "{outlets}");
    let count = |line: &str| line.split(',').nth(3).unwrap().parse::<u64>().unwrap();
    assert!(
        count(lines[5]) > 0,
        "nothing fell past the plate: {outlets}"
    );
    let walls = read(a.join("walls.csv"));
    let lines: Vec<&str> = walls.lines().collect();
    assert_eq!(lines[0], "frame,time,mesh,x,y,z,fx,fy,fz,tx,ty,tz");
    // Frames 1-4, two mesh files each (the empty main mesh, the plate).
    assert_eq!(lines.len(), 1 + 8, "{walls}");
    assert!(
        lines[1].starts_with("1,") && lines[2].starts_with("1,"),
        "{walls}"
    );
    let frame = read(a.join("particles000004.csv"));
    assert!(frame.lines().next().unwrap().ends_with(",wz,id,material"));
    assert!(a.join("checkpoint.bin").exists());

    // Resume from the checkpoint of frame 2 in another directory holding the logs up to
    // frame 4: the rows of frames 3 and 4 are written again, once, with the same numbers.
    let b = dir.path().join("b");
    std::fs::create_dir(&b).unwrap();
    std::fs::write(dir.path().join("s2.toml"), scenario(2)).unwrap();
    let out = common::tinydem(&["run", "s2.toml", "-o", "b", "-q"], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::copy(a.join("outlets.csv"), b.join("outlets.csv")).unwrap();
    std::fs::copy(a.join("walls.csv"), b.join("walls.csv")).unwrap();
    let out = common::tinydem(
        &[
            "run",
            "s.toml",
            "-o",
            "b",
            "-q",
            "--resume",
            "b/checkpoint.bin",
        ],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(read(b.join("outlets.csv")), outlets);
    assert_eq!(read(b.join("walls.csv")), walls);
    assert_eq!(read(b.join("particles000004.csv")), frame);
}

/// The contact network of a settled bed: the faces hold up its weight, every grain is in
/// balance under its contacts and gravity, and each contact point lies r_i from the centre.
#[test]
fn the_contact_network_of_a_settled_bed_balances_every_grain() {
    use tinydem::engine::Partner;
    let sim = settled_bed(14_000);
    let network = sim.contact_network();
    let p = &sim.particles;
    let at = |id: u64| p.id.iter().position(|&k| k == id).unwrap();
    let mut net = vec![DVec3::ZERO; p.len()];
    let mut from_faces = DVec3::ZERO;
    let (mut pairs, mut faces) = (0, 0);
    for c in &network {
        let i = at(c.id);
        let f = c.f_n + c.f_t;
        assert!(c.f_n.dot(c.f_t).abs() <= 1e-9 * f.length_squared().max(1e-30));
        net[i] += f;
        let lever = (c.point - p.x[i]).length();
        assert!(
            (lever - (p.radius[i] - 0.5 * c.overlap)).abs() < 1e-12,
            "{c:?}"
        );
        match c.with {
            Partner::Particle(j) => {
                assert!(j > c.id, "a pair is listed under its lower id");
                net[at(j)] -= f;
                pairs += 1;
            }
            Partner::Face(_) => {
                from_faces += f;
                faces += 1;
            }
        }
    }
    assert!(pairs > 150 && faces > 30, "{pairs} pairs, {faces} faces");
    let weight: f64 = p.radius.iter().map(|&r| Inertia::mass(r, RHO) * 9.81).sum();
    assert!(
        (from_faces.z / weight - 1.0).abs() < 0.01,
        "{from_faces} vs {weight}"
    );
    // Every grain at rest: its contacts balance its weight.
    for (k, f) in net.iter().enumerate() {
        let w = Inertia::mass(p.radius[k], RHO) * 9.81;
        let residual = (*f + DVec3::new(0.0, 0.0, -w)).length();
        assert!(
            residual < 0.05 * w,
            "grain {}: residual {residual} of {w}",
            p.id[k]
        );
    }
}

/// Ids past 2^32 (a long insertion run's, or a file's) round-trip: read from a particle
/// file, written in every frame, kept with their springs in the checkpoint, and a run
/// resumed from it writes the frames of the run never cut.
#[test]
fn ids_beyond_2_to_the_32_round_trip_through_frames_and_checkpoints() {
    let dir = tempfile::tempdir().unwrap();
    let ids: [u64; 3] = [5_000_000_000, 5_000_000_007, 1 << 40];
    // Two grains touching as they fall (their springs by those ids), one apart.
    let rows = [(0.0, 0.0099), (0.0, 0.0), (0.05, 0.0)];
    let mut csv = String::from("x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,id\n");
    for ((x, y), id) in rows.iter().zip(ids) {
        csv += &format!("{x},{y},0,0.005,0.1,0,0,1,0,0,0,0,0,5,{id}\n");
    }
    std::fs::write(dir.path().join("grains.csv"), csv).unwrap();
    let scenario = |frames: u32| {
        format!(
            "[material]\nfriction_sliding = 0.5\nfriction_rolling = 0.1\n\
             [simulation]\nmax_particles = 0\nspawn_attempts = 0\nframes = {frames}\nsteps_per_frame = 100\n\
             [input]\nparticles = \"grains.csv\"\n"
        )
    };
    std::fs::write(dir.path().join("s2.toml"), scenario(2)).unwrap();
    std::fs::write(dir.path().join("s4.toml"), scenario(4)).unwrap();
    let run = |args: &[&str]| {
        let out = common::tinydem(args, dir.path());
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    run(&["run", "s4.toml", "-o", "whole", "-q"]);
    run(&["run", "s2.toml", "-o", "cut", "-q"]);
    run(&[
        "run",
        "s4.toml",
        "-o",
        "cut",
        "-q",
        "--resume",
        "cut/checkpoint.bin",
    ]);
    let read =
        |d: &str| std::fs::read_to_string(dir.path().join(d).join("particles000004.csv")).unwrap();
    let frame = read("whole");
    assert_eq!(
        read("cut"),
        frame,
        "resumed from the checkpoint, the run differs"
    );
    let header = frame.lines().next().unwrap();
    let at = header
        .split(',')
        .position(|c| c == "id")
        .expect("an id column");
    let written: Vec<u64> = frame
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(at).unwrap().parse().unwrap())
        .collect();
    assert_eq!(written, ids);
    // A checkpoint after one step holds the touching pair's springs under those ids.
    let one_step = scenario(1).replace("steps_per_frame = 100", "steps_per_frame = 1");
    std::fs::write(dir.path().join("s1.toml"), one_step).unwrap();
    run(&["run", "s1.toml", "-o", "step", "-q"]);
    let snapshot =
        tinydem::io::checkpoint::load(&dir.path().join("step/checkpoint.bin"), None).unwrap();
    assert_eq!(snapshot.particles.next_id, (1 << 40) + 1);
    assert!(
        snapshot
            .pair_history
            .iter()
            .any(|e| (e.0, e.1) == (ids[0], ids[1])),
        "{:?}",
        snapshot.pair_history
    );
}
