//! `[simulation] until`: a run ends at the first frame where one of its conditions holds, with
//! that frame, its log row (naming the condition) and a checkpoint; resumed runs keep the
//! conditions, and a stage checks its own.

use crate::common;

use std::path::Path;

use crate::common::tinydem;

/// A closed box 6 cm wide, 20 cm tall.
const BOX: &str = "OFF\n8 5 0\n-0.03 -0.03 0\n0.03 -0.03 0\n0.03 0.03 0\n-0.03 0.03 0\n\
    -0.03 -0.03 0.2\n0.03 -0.03 0.2\n0.03 0.03 0.2\n-0.03 0.03 0.2\n\
    4 0 1 2 3\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";

/// Sixty grains poured into the box, at most `frames` frames of 1000 steps, ended by
/// `until` (a line of `[simulation]`); `extra` adds tables.
fn pour(dir: &Path, frames: u64, until: &str, extra: &str) {
    std::fs::write(dir.join("box.off"), BOX).unwrap();
    std::fs::write(
        dir.join("s.toml"),
        format!(
            "[geometry]\nradius_min = 0.004\nradius_max = 0.005\nmesh = \"box.off\"\n\
             mesh_radii = [0.0]\n\
             [simulation]\nframes = {frames}\nsteps_per_frame = 1000\n{until}\n\
             [[spawn]]\nmin = [-0.025, -0.025, 0.02]\nmax = [0.025, 0.025, 0.1]\ncount = 60\n\
             {extra}"
        ),
    )
    .unwrap();
}

/// The rows of `log.csv` as name -> value maps.
fn log(out: &Path) -> Vec<std::collections::HashMap<String, String>> {
    let text = std::fs::read_to_string(out.join("log.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            let values = l.split(',').map(String::from);
            header.iter().cloned().zip(values).collect()
        })
        .collect()
}

fn value(row: &std::collections::HashMap<String, String>, key: &str) -> f64 {
    row[key].parse().unwrap()
}

/// The frame files of `out`, by name.
fn frames_of(out: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(out)
        .unwrap()
        .map(|e| e.unwrap())
        .filter(|e| e.file_name().to_string_lossy().starts_with("particles"))
        .map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            (name, std::fs::read(e.path()).unwrap())
        })
        .collect();
    v.sort();
    v
}

fn run(dir: &Path, args: &[&str]) -> String {
    let o = tinydem(args, dir);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{err}");
    err
}

const STILL: &str = "until = { kinetic_energy_below = 1e-7 }";

#[test]
fn a_pour_ends_at_the_first_frame_it_is_still() {
    let t = tempfile::tempdir().unwrap();
    pour(t.path(), 100, STILL, "");
    let err = run(t.path(), &["run", "s.toml", "-o", "out"]);
    let out = t.path().join("out");
    let rows = log(&out);
    let last = rows.len() - 1;
    assert!((1..100).contains(&last), "ended at frame {last}");
    // The frame where it held is the last one, and the first after a step where it holds.
    assert_eq!(rows[last]["until"], "kinetic_energy_below");
    assert!(value(&rows[last], "kinetic_energy") < 1e-7);
    assert_eq!(value(&rows[last], "particles"), 60.0);
    for row in &rows[1..last] {
        assert_eq!(row["until"], "");
        assert!(value(row, "kinetic_energy") >= 1e-7, "{row:?}");
    }
    assert_eq!(frames_of(&out).len(), last + 1);
    assert!(out.join("checkpoint.bin").exists());
    assert!(
        err.contains(&format!(
            "ended at frame {last} by until.kinetic_energy_below"
        )),
        "{err}"
    );
    // `check` says so.
    let o = tinydem(&["check", "s.toml"], t.path());
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(
        said.contains("ends early             at the first frame with kinetic energy < 1e-7 J"),
        "{said}"
    );
}

#[test]
fn time_and_removals_end_a_run_at_their_frame() {
    let t = tempfile::tempdir().unwrap();
    // Frames are 1000 steps of Eq. 50's 1.2066e-4 s apart: t = 0.25 s is first reached at
    // frame 3.
    pour(t.path(), 100, "until = { time = 0.25 }", "");
    run(t.path(), &["run", "s.toml", "-q", "-o", "out"]);
    let rows = log(&t.path().join("out"));
    assert_eq!(rows.len(), 4);
    assert_eq!(rows[3]["until"], "time");
    // An outlet across the floor takes the grains as they land: the run ends once it has
    // taken 10.
    pour(
        t.path(),
        100,
        "until = { removed_at_least = 10, time = 100.0 }",
        "[[outlets]]\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 0.012]\n",
    );
    run(t.path(), &["run", "s.toml", "-q", "-o", "gone"]);
    let rows = log(&t.path().join("gone"));
    let last = rows.len() - 1;
    assert_eq!(rows[last]["until"], "removed_at_least");
    assert!(value(&rows[last], "removed") >= 10.0);
    assert!(value(&rows[last - 1], "removed") < 10.0);
    // Without conditions, log.csv keeps its columns.
    pour(t.path(), 2, "", "");
    run(t.path(), &["run", "s.toml", "-q", "-o", "plain"]);
    let text = std::fs::read_to_string(t.path().join("plain/log.csv")).unwrap();
    assert_eq!(
        text.lines().next().unwrap(),
        tinydem::driver::run::LOG_HEADER
    );
}

#[test]
fn a_resumed_run_keeps_its_conditions() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    pour(a.path(), 100, STILL, "");
    run(a.path(), &["run", "s.toml", "-q", "-o", "out"]);
    let whole = frames_of(&a.path().join("out"));
    assert!(whole.len() > 2);
    // The same run in two pieces: one frame, then extended with --resume.
    pour(b.path(), 1, STILL, "");
    run(b.path(), &["run", "s.toml", "-q", "-o", "out"]);
    pour(b.path(), 100, STILL, "");
    let checkpoint = "out/checkpoint.bin";
    run(
        b.path(),
        &["run", "s.toml", "-o", "out", "--resume", checkpoint],
    );
    assert!(
        frames_of(&b.path().join("out")) == whole,
        "the pieces differ"
    );
    let (x, y) = (a.path().join("out/log.csv"), b.path().join("out/log.csv"));
    assert_eq!(std::fs::read(x).unwrap(), std::fs::read(y).unwrap());
    // Resumed from the frame where it ended, it ends again at once.
    let err = run(
        a.path(),
        &["run", "s.toml", "-o", "out", "--resume", checkpoint],
    );
    let last = whole.len() - 1;
    assert!(
        err.contains(&format!(
            "ended at frame {last} by until.kinetic_energy_below"
        )),
        "{err}"
    );
    assert!(err.contains(&format!("{} steps", last * 1000)), "{err}");
    assert!(frames_of(&a.path().join("out")) == whole);
}

#[test]
fn a_stage_checks_its_own_conditions_on_its_own_clock() {
    let t = tempfile::tempdir().unwrap();
    pour(t.path(), 100, STILL, "");
    run(t.path(), &["run", "s.toml", "-q", "-o", "fill"]);
    std::fs::write(
        t.path().join("tilt.toml"),
        "[geometry]\nradius_min = 0.004\nradius_max = 0.005\nmesh = \"box.off\"\n\
         mesh_radii = [0.0]\n[kinetics]\ngravity = [2.0, 0.0, -9.6]\n\
         [simulation]\nframes = 50\nsteps_per_frame = 1000\nspawn_attempts = 0\n\
         until = { time = 0.2 }\n",
    )
    .unwrap();
    let from = "fill/checkpoint.bin";
    run(
        t.path(),
        &["run", "tilt.toml", "-q", "-o", "tilt", "--from", from],
    );
    let rows = log(&t.path().join("tilt"));
    assert_eq!(rows.len(), 3, "t = 0.2 s is reached at the stage's frame 2");
    assert_eq!(rows[2]["until"], "time");
    assert_eq!(value(&rows[0], "particles"), 60.0);
}

/// A lid over the box, a servo pressing the poured grains with 0.5 N.
const LID: &str = "[[meshes]]\n\
    shape = { type = \"plane\", point = [0.0, 0.0, 0.15], normal = [0.0, 0.0, 1.0], size = 0.059 }\n\
    motion = { type = \"servo\", direction = [0.0, 0.0, -1.0], force = 0.5, max_speed = 0.3 }\n";

#[test]
fn a_press_ends_when_its_servo_holds_its_load_and_so_does_its_resume() {
    let t = tempfile::tempdir().unwrap();
    pour(t.path(), 100, "until = { servo_within = 0.001 }", LID);
    let err = run(t.path(), &["run", "s.toml", "-o", "out"]);
    let rows = log(&t.path().join("out"));
    let last = rows.last().unwrap();
    assert_eq!(last["until"], "servo_within", "{err}");
    assert!(rows.len() < 101, "not ended early");
    // The frame's mean load includes its approach; the last step's is within 0.1 %.
    assert!((value(last, "mesh1_load") - 0.5).abs() < 0.05, "{last:?}");
    assert!(
        err.contains("by until.servo_within: every servo within 1e-3 of its target (mesh 1: 4.99"),
        "{err}"
    );
    // Resumed at that frame, the checkpoint's servo state ends it at once.
    let err = run(
        t.path(),
        &[
            "run",
            "s.toml",
            "-o",
            "out",
            "--resume",
            "out/checkpoint.bin",
        ],
    );
    let frame = rows.len() - 1;
    assert!(
        err.contains(&format!("ended at frame {frame} by until.servo_within")),
        "{err}"
    );
}

#[test]
fn removals_beyond_the_particles_a_run_can_make_are_refused() {
    let t = tempfile::tempdir().unwrap();
    std::fs::write(
        t.path().join("s.toml"),
        "[simulation]\nmax_particles = 100\nuntil = { removed_at_least = 500 }\n\
         [[outlets]]\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, -0.5]\n",
    )
    .unwrap();
    let o = common::tinydem(&["run", "s.toml", "-q"], t.path());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(
        err.contains("until.removed_at_least = 500 can never hold: this run makes at most 100"),
        "{err}"
    );
    let o = common::tinydem(&["check", "s.toml"], t.path());
    let out = String::from_utf8_lossy(&o.stderr) + String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("can never hold"), "{out}");
}
