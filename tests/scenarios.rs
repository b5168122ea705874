//! Scenario files good and bad (`tests/scenarios/{good,bad}`). Each bad file states on its
//! first line, after `# error: `, text its error message must contain.

use std::path::{Path, PathBuf};

use tinydem::engine::Simulation;
use tinydem::geometry::mesh::Contacts;
use tinydem::scenario::{FrictionSprings, Scenario};

fn files(kind: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/scenarios")
        .join(kind);
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v
}

#[test]
fn good_scenarios_load_and_run() {
    let good = files("good");
    assert!(good.len() >= 2);
    for path in good {
        let s = Scenario::load(&path).unwrap_or_else(|e| panic!("{}: {e:#}", path.display()));
        let steps = s.simulation.steps_per_frame;
        let mut sim = Simulation::new(s).unwrap_or_else(|e| panic!("{}: {e:#}", path.display()));
        for _ in 0..steps {
            sim.step().unwrap();
        }
    }
}

#[test]
fn full_scenario_sets_every_key() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenarios/good");
    let s = Scenario::load(&dir.join("full.toml")).unwrap();
    assert_eq!(s.geometry.mesh_radii, vec![0.0, 0.001]);
    assert_eq!(s.material.friction_twisting, 0.2);
    assert_eq!(s.simulation.seed, 42);
    let until = tinydem::scenario::Until {
        kinetic_energy_below: Some(1e-9),
        time: Some(1.0),
        removed_at_least: Some(3),
        servo_within: None,
        all: false,
    };
    assert_eq!(s.simulation.until, until);
    assert_eq!(s.particles, Some(dir.join("two.csv")));
    assert_eq!(s.output_dir, dir.join("out"));
    assert_eq!(s.geometry.mesh_contacts, Contacts::PerFace);
    assert_eq!(s.simulation.friction_springs, FrictionSprings::Paper);
    assert_eq!(s.meshes[0].contacts, Contacts::Merged);
    assert_eq!(s.domain.unwrap().max, glam::DVec3::splat(0.5));
    assert_eq!(s.outlets.len(), 1);
    assert_eq!(s.periodic, [true, false, false]);
    assert!(s.wall_forces);
    let sim = Simulation::new(s).unwrap();
    assert_eq!(sim.walls.mesh.faces.len(), 10);
    assert_eq!(sim.walls.mesh.faces[1].radius, 0.001);
    // The main box per face (five surfaces), the second one merged: its four faces of
    // radius 0 one surface, the face of radius 0.001 another.
    assert_eq!(sim.walls.mesh.surfaces(), 7);
    assert_eq!(sim.particles.len(), 2);
}

#[test]
fn bad_scenarios_fail_with_their_stated_error() {
    let bad = files("bad");
    assert!(bad.len() >= 10);
    for path in bad {
        let text = std::fs::read_to_string(&path).unwrap();
        let expected = text
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("# error: "))
            .unwrap_or_else(|| panic!("{}: first line must be '# error: ...'", path.display()));
        let err = match Scenario::load(&path) {
            Ok(_) => panic!("{} was accepted", path.display()),
            Err(e) => format!("{e:#}"),
        };
        assert!(
            err.contains(expected),
            "{}: error\n  {err}\ndoes not contain\n  {expected}",
            path.display()
        );
        let name = path.file_name().unwrap().to_str().unwrap();
        assert!(
            err.contains(name),
            "{}: error does not name the file: {err}",
            path.display()
        );
    }
}

#[test]
fn materials_scenario_sets_meshes_and_particles_materials() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenarios/good");
    let s = Scenario::load(&dir.join("materials.toml")).unwrap();
    assert_eq!(s.materials.len(), 2);
    assert_eq!(s.geometry.mesh_material, 1);
    assert_eq!(s.meshes[0].material, 0);
    assert_eq!(s.material.viscosity, 1e-5);
    assert_eq!(s.materials[1].properties.viscosity, 1e-5);
    let c = s.pair(0, 1);
    assert_eq!((c.friction_sliding, c.restitution), (0.2, 0.7));
    assert_eq!(
        (c.cohesion, s.pair(0, 0).cohesion, s.pair(1, 1).cohesion),
        (50.0, 200.0, 0.0)
    );
    let sim = Simulation::new(s).unwrap();
    assert_eq!(sim.particles.material, vec![1, 1]);
}

#[test]
fn particles_of_a_material_the_scenario_lacks_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("p.csv");
    std::fs::write(
        &csv,
        "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,material\n0,0,0,0.005,0,0,0,1,0,0,0,0,0,0,2\n",
    )
    .unwrap();
    let toml = dir.path().join("s.toml");
    std::fs::write(&toml, "[input]\nparticles = \"p.csv\"\n").unwrap();
    let err = format!(
        "{:#}",
        Simulation::new(Scenario::load(&toml).unwrap())
            .err()
            .unwrap()
    );
    assert!(
        err.contains("p.csv:2: material 2, but the scenario has 1 material (0 to 0)"),
        "{err}"
    );
}
