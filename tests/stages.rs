//! Staged runs (`tinydem run NEXT --from CHECKPOINT`): a stage that only adds frames gives
//! the bits of one uninterrupted run; removing the plug of a filled silo starts its discharge;
//! `check --from` says what a stage changes.

use crate::common;

use std::path::Path;

fn write(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap();
}

fn run(dir: &Path, args: &[&str]) -> String {
    let out = common::tinydem(args, dir);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "tinydem {args:?}: {err}");
    err + &String::from_utf8_lossy(&out.stdout)
}

fn read(path: impl AsRef<Path>) -> String {
    std::fs::read_to_string(path.as_ref())
        .unwrap_or_else(|e| panic!("{}: {e}", path.as_ref().display()))
}

/// The silo of `tests/data/stages` filling from above, with `frames` frames and the plug
/// in place or not.
fn silo(frames: u32, plug: bool) -> String {
    let plug = if plug {
        "[[meshes]]\nfile = \"plug.off\"\n"
    } else {
        ""
    };
    format!(
        "[geometry]\nradius_min = 0.003\nradius_max = 0.004\nmesh = \"silo.off\"\nmesh_radii = [0.0]\n\
         spawn_min = [-0.05, -0.05, 0.06]\nspawn_max = [0.05, 0.05, 0.14]\n\
         [material]\nrestitution = 0.3\nfriction_sliding = 0.5\nfriction_rolling = 0.1\n\
         [simulation]\nmax_particles = 300\nframes = {frames}\nsteps_per_frame = 400\n\
         [domain]\nmin = [-0.1, -0.1, -0.2]\nmax = [0.1, 0.1, 0.2]\n\
         [[outlets]]\nmin = [-0.1, -0.1, -0.2]\nmax = [0.1, 0.1, -0.05]\n\
         {plug}[output]\nwall_forces = true\n"
    )
}

fn setup() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for f in ["silo.off", "plug.off"] {
        std::fs::copy(common::data(&format!("stages/{f}")), dir.path().join(f)).unwrap();
    }
    dir
}

#[test]
fn a_stage_that_only_adds_frames_gives_the_bits_of_one_run() {
    let dir = setup();
    let d = dir.path();
    write(d, "whole.toml", &silo(4, true));
    write(d, "first.toml", &silo(2, true));
    write(d, "next.toml", &silo(2, true));
    run(d, &["run", "whole.toml", "-o", "whole", "-q"]);
    run(d, &["run", "first.toml", "-o", "first", "-q"]);
    let said = run(
        d,
        &[
            "run",
            "next.toml",
            "-o",
            "next",
            "--from",
            "first/checkpoint.bin",
        ],
    );
    assert!(
        said.contains("spawning continues the random stream"),
        "{said}"
    );
    let snapshot = tinydem::io::checkpoint::load(&d.join("first/checkpoint.bin"), None).unwrap();
    // 47 touching pairs of the 300 grains (measured).
    assert!(
        snapshot.pair_history.len() > 30,
        "grains touch at the stage boundary"
    );
    assert!(
        snapshot.face_history.len() > 20,
        "grains rest on the plug and floor"
    );
    for k in 0..=2 {
        let name = |k: u32| format!("particles{k:06}.csv");
        assert!(
            read(d.join("next").join(name(k))) == read(d.join("whole").join(name(k + 2))),
            "frame {k} of the stage differs from frame {} of the whole run",
            k + 2
        );
    }
}

#[test]
fn removing_the_plug_of_a_filled_silo_starts_its_discharge() {
    let dir = setup();
    let d = dir.path();
    write(d, "fill.toml", &silo(4, true));
    write(d, "discharge.toml", &silo(4, false));
    run(d, &["run", "fill.toml", "-o", "fill", "-q"]);
    let count = |dir: &str| -> u64 {
        let log = read(d.join(dir).join("outlets.csv"));
        let last = log.lines().last().unwrap().to_string();
        last.split(',').nth(3).unwrap().parse().unwrap()
    };
    assert_eq!(count("fill"), 0, "the plug holds the grains");
    let check = run(
        d,
        &["check", "discharge.toml", "--from", "fill/checkpoint.bin"],
    );
    assert!(
        check.contains("[[meshes]] #1 file: removed (was \"plug.off\")"),
        "{check}"
    );
    assert!(
        check.contains("with mesh files this scenario lacks were dropped"),
        "{check}"
    );
    // Its particles, and the trial that times the stage, are the fill's, not a fresh start's.
    let grains = read(d.join("fill/particles000004.csv")).lines().count() - 1;
    assert!(
        check.contains(&format!("initial particles      {grains}\n")),
        "{grains}: {check}"
    );
    run(
        d,
        &[
            "run",
            "discharge.toml",
            "-o",
            "discharge",
            "-q",
            "--from",
            "fill/checkpoint.bin",
        ],
    );
    assert!(
        count("discharge") > 20,
        "{}",
        read(d.join("discharge/outlets.csv"))
    );
    // The stage starts from the filled state: frame 0 is the last frame of the fill.
    let last_fill = read(d.join("fill/particles000004.csv"));
    assert_eq!(read(d.join("discharge/particles000000.csv")), last_fill);
}

#[test]
fn a_stage_refuses_particles_of_its_own() {
    let dir = setup();
    let d = dir.path();
    write(d, "fill.toml", &silo(1, true));
    run(d, &["run", "fill.toml", "-o", "fill", "-q"]);
    std::fs::copy(common::data("domain/one_grain.csv"), d.join("one.csv")).unwrap();
    write(
        d,
        "next.toml",
        &format!("{}[input]\nparticles = \"one.csv\"\n", silo(1, true)),
    );
    let out = common::tinydem(&["run", "next.toml", "--from", "fill/checkpoint.bin"], d);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("[input] particles cannot be combined with --from"),
        "{err}"
    );
    let out = common::tinydem(&["run", "next.toml", "--from", "a", "--resume", "b"], d);
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot be used with"));
}

/// The number of particles of the last frame of `out` (its `log.csv`).
fn particles_at_end(out: &Path) -> u64 {
    let log = read(out.join("log.csv"));
    let last = log.lines().last().unwrap();
    last.split(',').nth(3).unwrap().parse().unwrap()
}

#[test]
fn a_stage_naming_no_spawn_box_spawns_nothing_even_resumed() {
    let dir = setup();
    let d = dir.path();
    // The fill makes its 300 grains.
    write(d, "fill.toml", &silo(2, true));
    run(d, &["run", "fill.toml", "-o", "fill", "-q"]);
    let filled = particles_at_end(&d.join("fill"));
    assert_eq!(filled, 300);
    // The next stage names neither [[spawn]] nor a spawn box: it spawns nothing (it used to
    // fill up to max_particles = 1000 in the paper's default box), and says so.
    let next = silo(2, true)
        .replace(
            "spawn_min = [-0.05, -0.05, 0.06]\nspawn_max = [0.05, 0.05, 0.14]\n",
            "",
        )
        .replace("max_particles = 300\n", "");
    write(d, "next.toml", &next);
    let said = run(d, &["check", "next.toml", "--from", "fill/checkpoint.bin"]);
    assert!(
        said.contains("nothing is spawned: the scenario has no [[spawn]] region"),
        "{said}"
    );
    assert!(
        said.contains("spawning               none (a stage spawns in the spawn box only if"),
        "{said}"
    );
    let said = run(
        d,
        &[
            "run",
            "next.toml",
            "--from",
            "fill/checkpoint.bin",
            "-o",
            "next",
        ],
    );
    assert!(said.contains("nothing is spawned"), "{said}");
    assert!(particles_at_end(&d.join("next")) <= filled);
    // Resumed for more frames, it still spawns nothing (the checkpoint keeps it).
    write(
        d,
        "next.toml",
        &next.replace("frames = 2\n", "frames = 4\n"),
    );
    run(
        d,
        &[
            "run",
            "next.toml",
            "-o",
            "next",
            "--resume",
            "next/checkpoint.bin",
            "-q",
        ],
    );
    assert!(particles_at_end(&d.join("next")) <= filled);
    // A stage that names its spawn box spawns in it (with room for 100 more).
    let more = silo(2, true).replace("max_particles = 300\n", "max_particles = 400\n");
    write(d, "more.toml", &more);
    run(
        d,
        &[
            "run",
            "more.toml",
            "--from",
            "fill/checkpoint.bin",
            "-o",
            "more",
            "-q",
        ],
    );
    assert!(particles_at_end(&d.join("more")) > filled);
}
