//! The energy ledger (`[output] energy_ledger`): an impact's loss in the normal mode alone,
//! a sliding sphere's 2/7 in sliding, an elastic impact's energy returned; the balance
//! closing in a pour, a drum and with each contact model; bad keys.

use crate::common;

use glam::DVec3;
use tinydem::engine::Simulation;
use tinydem::geometry::mesh::Mesh;
use tinydem::model::integrate::Inertia;
use tinydem::model::ledger::Balance;
use tinydem::model::particles::Particle;

const R: f64 = 0.005;
const RHO: f64 = 2500.0;
/// A floor (a rectangle facing up at z = 0).
const FLOOR: &str = "OFF\n4 1 0\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n4 0 1 2 3\n";

/// A simulation of `particles` (radius `R`) keeping the ledger, with the `[material]` lines
/// `material`, gravity `g` along -z and the mesh `off` (none if empty).
fn sim(material: &str, g: f64, off: &str, particles: Vec<Particle>) -> Simulation {
    let s = common::scenario(&format!(
        "[geometry]\nradius_min = {R}\nradius_max = {R}\nmesh_radii = [0.0]\n\
         [material]\ndensity = {RHO}\nyoungs_modulus = 1e7\n{material}\n\
         [kinetics]\ngravity = [0.0, 0.0, {}]\n\
         [simulation]\ntimestep = 1e-6\nmax_particles = 0\nspawn_attempts = 0\n\
         [output]\nenergy_ledger = true\n",
        -g
    ));
    let mesh = match off {
        "" => Mesh::default(),
        off => Mesh::parse_off(off, "mesh", &s.geometry.mesh_radii).unwrap(),
    };
    Simulation::from_parts(s, mesh, particles.into_iter().collect()).unwrap()
}

fn balance(s: &Simulation) -> Balance {
    s.thermo().energy.expect("the ledger is kept")
}

#[test]
fn a_head_on_impact_loses_its_energy_in_the_normal_mode_alone() {
    let v = 0.5;
    let grains = vec![
        common::sphere(
            R,
            DVec3::new(-1.01 * R, 0.0, 0.0),
            DVec3::X * v,
            DVec3::ZERO,
        ),
        common::sphere(
            R,
            DVec3::new(1.01 * R, 0.0, 0.0),
            -DVec3::X * v,
            DVec3::ZERO,
        ),
    ];
    for e in [0.5, 0.9, 1.0] {
        let mut s = sim(
            &format!("restitution = {e}\nfriction_sliding = 0.5"),
            0.0,
            "",
            grains.clone(),
        );
        let before = s.thermo().kinetic_energy;
        for _ in 0..2000 {
            s.step().unwrap();
        }
        assert_eq!(s.held_contacts().len(), 0, "they parted");
        let after = s.thermo().kinetic_energy;
        let b = balance(&s);
        eprintln!(
            "e {e}: measured e {:.4}, normal {:.3e} of the loss, others {:?}, residual {:.1e}",
            (after / before).sqrt(),
            b.dissipated[0] / (before - after) - 1.0,
            &b.dissipated[1..],
            b.residual / before
        );
        // What the impact took is what the normal mode dissipated.
        assert!((b.dissipated[0] - (before - after)).abs() < 1e-9 * before);
        assert!(b.dissipated[1..].iter().all(|d| d.abs() < 1e-12 * before));
        assert!(b.stored_elastic == 0.0 && b.residual.abs() < 1e-12 * before);
        if e == 1.0 {
            // An elastic impact gives back what it stored, to the integration's error.
            assert!(b.dissipated[0].abs() < 1e-4 * before, "{}", b.dissipated[0]);
        }
    }
}

/// A sphere set sliding on a floor without spin rolls after a while at 5/7 of its speed:
/// sliding friction took 2/7 of its kinetic energy.
#[test]
fn a_sliding_sphere_loses_two_sevenths_of_its_energy_in_sliding() {
    let m = Inertia::mass(R, RHO);
    let g = 9.81;
    // Resting on the floor at Hertz's overlap under its weight (E* of the wall).
    let e_star = 1e7 / (1.0 - 0.3 * 0.3);
    let overlap = (3.0 * m * g / (4.0 * e_star * R.sqrt())).powf(2.0 / 3.0);
    let v0 = 0.5;
    let grain = common::sphere(
        R,
        DVec3::new(0.0, 0.0, R - overlap),
        DVec3::X * v0,
        DVec3::ZERO,
    );
    let material = "restitution = 0.5\nfriction_sliding = 0.3\nfriction_rolling = 0.0\nfriction_twisting = 0.0";
    let mut s = sim(material, g, FLOOR, vec![grain]);
    let before = 0.5 * m * v0 * v0;
    // Sliding stops after v0 (2/7) / (μ g) = 49 ms.
    for _ in 0..80_000 {
        s.step().unwrap();
    }
    let b = balance(&s);
    let p = &s.particles;
    eprintln!(
        "v/v0 {:.5}, sliding {:+.2e} of 2/7, normal {:.2e}, residual {:.1e}",
        p.v[0].x / v0,
        b.dissipated[1] / (2.0 / 7.0 * before) - 1.0,
        b.dissipated[0] / before,
        b.residual / before
    );
    assert!((p.v[0].x / v0 - 5.0 / 7.0).abs() < 1e-3);
    assert!((b.dissipated[1] / (2.0 / 7.0 * before) - 1.0).abs() < 1e-3);
    assert!(b.residual.abs() < 1e-9 * before);
}

/// The largest magnitude among a frame's energies: the scale the residual is measured by.
fn scale(kinetic: f64, b: &Balance) -> f64 {
    let all = [
        kinetic,
        b.work_gravity,
        b.work_walls,
        b.stored_elastic,
        b.spawned,
        b.removed,
    ];
    all.into_iter()
        .chain(b.dissipated)
        .chain([b.dissipated_drag])
        .fold(0.0, |m, e| m.max(e.abs()))
}

/// Runs `text` for `steps` steps, checking the ledger every `every`: the worst residual
/// against the energy scale, and the last balance.
fn worst_residual(text: &str, steps: u64, every: u64) -> (f64, Balance) {
    let mut s = Simulation::new(common::scenario(text)).expect("starts");
    let mut worst: f64 = 0.0;
    let mut last = Balance::default();
    for k in 1..=steps {
        s.step().unwrap();
        if k % every == 0 {
            let th = s.thermo();
            let b = th.energy.expect("kept");
            worst = worst.max(b.residual.abs() / scale(th.kinetic_energy, &b));
            last = b;
        }
    }
    (worst, last)
}

const MODELS: [&str; 8] = [
    "",
    "viscosity = 1e-3\n",
    "hooke_stiffness = 300.0\ntangential_coulomb = \"spring\"\nrolling_model = \"cdt\"\n",
    "rolling_model = \"epsd2\"\nadhesion_model = \"dmt\"\nsurface_energy = 0.02\n",
    "cohesion = 2e4\n",
    "adhesion_model = \"jkr\"\nsurface_energy = 0.05\n",
    "adhesion_model = \"jkr_force\"\nsurface_energy = 0.05\n",
    "liquid_volume = 1e-10\nsurface_tension = 0.07\ncontact_angle = 20.0\n",
];

/// A silo filling through its open outlet: spawning, removal, two radii, friction of
/// every kind and a mesh, with the `[material]` lines `models`.
fn silo(models: &str) -> String {
    format!(
        "[geometry]\nradius_min = 0.003\nradius_max = 0.004\nmesh = \"stages/silo.off\"\nmesh_radii = [0.0]\n\
         spawn_min = [-0.05, -0.05, 0.06]\nspawn_max = [0.05, 0.05, 0.14]\n\
         [material]\nrestitution = 0.3\nfriction_sliding = 0.5\nfriction_rolling = 0.1\nfriction_twisting = 0.1\n{models}\
         [simulation]\nmax_particles = 300\n\
         [domain]\nmin = [-0.1, -0.1, -0.2]\nmax = [0.1, 0.1, 0.2]\n\
         [[outlets]]\nmin = [-0.1, -0.1, -0.2]\nmax = [0.1, 0.1, -0.05]\n\
         [output]\nenergy_ledger = true\n"
    )
}

#[test]
fn the_ledger_closes_in_a_pour_with_each_contact_model() {
    for models in MODELS {
        let (worst, last) = worst_residual(&silo(models), 3000, 100);
        eprintln!("{models:?}: worst residual {worst:.1e}, {last:?}");
        assert!(
            worst < 1e-6,
            "{models}: residual {worst:e} of the energy scale"
        );
        assert!(last.dissipated[0] > 0.0 && last.work_gravity > 0.0 && last.spawned > 0.0);
    }
}

/// Grains tumbling in a drum turning at 2 rad/s: the drum's motion does work.
#[test]
fn the_ledger_closes_in_a_turning_drum() {
    let dir = std::env::temp_dir().join(format!("tinydem-ledger-drum-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mesh = dir.join("drum.off");
    std::fs::write(&mesh, common::drum_off(24)).unwrap();
    let text = format!(
        "[geometry]\nradius_min = 0.003\nradius_max = 0.004\nmesh_radii = [0.0]\n\
         spawn_min = [-0.03, -0.01, -0.03]\nspawn_max = [0.03, 0.01, 0.02]\n\
         [[meshes]]\nfile = \"{}\"\nmotion = {{ type = \"rotation\", center = [0.0, 0.0, 0.0], axis = [0.0, 1.0, 0.0], angular_velocity = 2.0 }}\n\
         [material]\nrestitution = 0.5\nfriction_sliding = 0.5\nfriction_rolling = 0.05\n\
         [simulation]\nmax_particles = 150\n\
         [output]\nenergy_ledger = true\n",
        mesh.display()
    );
    let (worst, last) = worst_residual(&text, 4000, 200);
    std::fs::remove_dir_all(&dir).ok();
    eprintln!("drum: worst residual {worst:.1e}, {last:?}");
    assert!(worst < 1e-6, "residual {worst:e} of the energy scale");
    assert!(
        last.work_walls.abs() > 1e-3 * last.work_gravity.abs(),
        "the drum works"
    );
}

#[test]
fn the_ledger_gives_the_same_bits_on_one_and_two_threads() {
    let text = silo(MODELS[7]);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let text = text.clone();
        pool.install(move || {
            let (_, b) = worst_residual(&text, 1500, 1500);
            b.columns().map(f64::to_bits)
        })
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn the_ledger_refuses_what_it_cannot_follow_yet() {
    let clumps = "[[clumps]]\nname = \"pair\"\nspheres = [[0.0, 0.0, 0.0, 0.003], [0.004, 0.0, 0.0, 0.003]]\n\
         [output]\nenergy_ledger = true\n";
    let e = tinydem::scenario::Scenario::parse(clumps, &common::data("inline.toml")).unwrap_err();
    assert!(format!("{e:#}").contains("clumps"), "{e:#}");
    let sheared = "[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [0.1, 0.1, 0.1]\nperiodic = [true, true, true]\n\
         lees_edwards = { velocity = 0.1, shear_axis = \"x\", gradient_axis = \"z\" }\n\
         [output]\nenergy_ledger = true\n";
    let e = tinydem::scenario::Scenario::parse(sheared, &common::data("inline.toml")).unwrap_err();
    assert!(format!("{e:#}").contains("lees_edwards"), "{e:#}");
}
