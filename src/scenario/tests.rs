//! The parser's unit tests: defaults, keys, errors.

use super::*;

#[test]
fn until_holds_on_the_first_condition_met() {
    let until = Until {
        kinetic_energy_below: Some(1e-6),
        time: Some(2.0),
        removed_at_least: Some(5),
        servo_within: None,
        all: false,
    };
    let still = FrameState {
        time: 1.0,
        kinetic_energy: 1e-7,
        particles: 10,
        spawning: false,
        removed: 0,
        servos: Vec::new(),
    };
    assert_eq!(until.met(&still).unwrap().key, "kinetic_energy_below");
    // Not while grains are still to come, nor with none at all.
    let filling = FrameState {
        spawning: true,
        ..still.clone()
    };
    assert_eq!(until.met(&filling), None);
    let empty = FrameState {
        particles: 0,
        ..still.clone()
    };
    assert_eq!(until.met(&empty), None);
    let late = FrameState {
        time: 2.0,
        ..filling.clone()
    };
    assert_eq!(until.met(&late).unwrap().key, "time");
    let drained = FrameState {
        removed: 5,
        ..filling.clone()
    };
    let met = until.met(&drained).unwrap();
    assert_eq!(
        met.to_string(),
        "until.removed_at_least: 5 removed, at least 5"
    );
    assert!(Until::default().is_empty());
    assert_eq!(Until::default().met(&still), None);
    // Servos: every one within the fraction of its target.
    let press = Until {
        servo_within: Some(0.01),
        ..Until::default()
    };
    let servos = |loads: &[f64]| FrameState {
        servos: loads.iter().map(|&l| (1, l, 2.0)).collect(),
        ..filling.clone()
    };
    assert_eq!(press.met(&servos(&[1.99])).unwrap().key, "servo_within");
    assert_eq!(press.met(&servos(&[1.99, 2.03])), None);
    assert_eq!(press.met(&servos(&[])), None);
}

#[test]
fn until_all_holds_where_every_condition_set_holds_at_once() {
    let until = Until {
        kinetic_energy_below: Some(1e-6),
        time: Some(2.0),
        all: true,
        ..Until::default()
    };
    let state = |time: f64, kinetic_energy: f64| FrameState {
        time,
        kinetic_energy,
        particles: 10,
        spawning: false,
        removed: 0,
        servos: Vec::new(),
    };
    // Still but early, late but moving: neither ends it.
    assert_eq!(until.met(&state(1.0, 1e-7)), None);
    assert_eq!(until.met(&state(2.5, 1e-3)), None);
    let met = until.met(&state(2.5, 1e-7)).unwrap();
    assert_eq!(met.key, "all");
    assert!(
        met.to_string().starts_with(
            "until.all: kinetic_energy_below: kinetic energy 1.0000e-7 J below 1e-6 J; time: t = "
        ),
        "{met}"
    );
    // Any of them (the default) ends it at the first.
    let any = Until {
        all: false,
        ..until
    };
    assert_eq!(
        any.met(&state(1.0, 1e-7)).unwrap().key,
        "kinetic_energy_below"
    );
    assert!(
        Until {
            all: true,
            ..Until::default()
        }
        .is_empty()
    );
}

#[test]
fn defaults_are_table_2() {
    let s = Scenario::default();
    assert_eq!(s.geometry.radius_min, 0.002);
    assert!((s.material.friction_twisting - 0.2).abs() < 1e-15);
    assert_eq!(s.simulation.frames * s.simulation.steps_per_frame, 50_000);
    // Eq. (50): 0.002 * sqrt(1000 * 0.91 / 1e6)
    assert!((s.simulation.timestep - 6.0332412e-5).abs() < 1e-12);
    // A run killed without warning loses at most ten minutes unless the user says.
    assert_eq!(s.checkpoint_minutes, 10.0);
}

#[test]
fn unknown_key_is_named() {
    let e = Scenario::parse("[material]\ndensityy = 3\n", Path::new("s.toml")).unwrap_err();
    let msg = format!("{e:#}");
    assert!(msg.contains("densityy") && msg.contains("s.toml"), "{msg}");
}

#[test]
fn out_of_range_value_names_key_and_range() {
    let e = Scenario::parse("[material]\npoisson_ratio = 0.7\n", Path::new("s.toml")).unwrap_err();
    let msg = format!("{e:#}");
    assert!(
        msg.contains("poisson_ratio") && msg.contains("(-1, 0.5]"),
        "{msg}"
    );
}

#[test]
fn the_resolved_toml_parses_back_to_the_same_scenario() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenarios/good");
    for name in [
        "full.toml",
        "minimal.toml",
        "materials.toml",
        "shapes.toml",
        "servo.toml",
    ] {
        let s = Scenario::load(&dir.join(name)).unwrap();
        let again = Scenario::parse(&s.to_toml(), Path::new("run.toml")).unwrap();
        assert_eq!(again, s, "{name}:\n{}", s.to_toml());
    }
    let moving = Scenario::parse(
        "[[meshes]]\nfile = \"a.stl\"\nmotion = { type = \"harmonic\", amplitude = 1e-3, frequency = 25.0, direction = [0.0, 0.0, 1.0] }\n\
         [[meshes]]\nfile = \"b c.off\"\nradii = [0.001, 0.0]\nmotion = { type = \"velocity\", velocity = [0.1, 0.0, 0.0] }\n\
         [[meshes]]\nfile = \"d.off\"\nmotion = { type = \"rotation\", center = [0.0, 1.0, 0.0], axis = [0.0, 1.0, 0.0], angular_velocity = -3.0 }\n\
         [[tags]]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\ntag = 3\n",
        Path::new("s.toml"),
    )
    .unwrap();
    let again = Scenario::parse(&moving.to_toml(), Path::new("run.toml")).unwrap();
    assert_eq!(again, moving, "{}", moving.to_toml());
    // The default run's names the built-in mesh, and reads back as it.
    let d = Scenario::default();
    assert!(
        d.to_toml()
            .contains("mesh = \"builtin:hourglass\"  # hourglass.off (built in)")
    );
    let again = Scenario::parse(&d.to_toml(), Path::new("run.toml")).unwrap();
    assert_eq!(again, d);
}

#[test]
fn changes_name_each_key() {
    let old = Scenario::parse(
        "[material]\nfriction_sliding = 0.3\n[[meshes]]\nfile = \"a.off\"\n[[meshes]]\nfile = \"plug.off\"\n",
        Path::new("s.toml"),
    )
    .unwrap();
    let new = Scenario::parse(
        "[material]\nfriction_sliding = 0.5\n[[meshes]]\nfile = \"a.off\"\n[[outlets]]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n[simulation]\nframes = 7\n",
        Path::new("s.toml"),
    )
    .unwrap();
    let c = changes(&old.to_toml(), &new.to_toml());
    assert_eq!(
        c,
        [
            "[material] friction_sliding: 0.3 -> 0.5",
            "[material] friction_twisting: 0.19999999999999998 -> 0.3333333333333333",
            "[simulation] frames: 100 -> 7",
            "[[outlets]] #1 min: added [0.0, 0.0, 0.0]",
            "[[outlets]] #1 max: added [1.0, 1.0, 1.0]",
            "[[meshes]] #2 file: removed (was \"plug.off\")",
            "[[meshes]] #2 radii: removed (was [0.0])",
            "[[meshes]] #2 contacts: removed (was \"merged\")",
        ]
    );
    assert!(changes(&new.to_toml(), &new.to_toml()).is_empty());
}

#[test]
fn paths_are_relative_to_the_scenario() {
    let s = Scenario::parse(
        "[input]\nparticles = \"p.csv\"\n",
        Path::new("cases/a/s.toml"),
    )
    .unwrap();
    assert_eq!(s.particles, Some(PathBuf::from("cases/a/p.csv")));
    // Given or not, the output directory is relative to the scenario too.
    assert_eq!(s.output_dir, PathBuf::from("cases/a/output"));
}
