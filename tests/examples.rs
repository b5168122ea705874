//! Every example scenario in `examples/` loads and runs a few steps at a reduced size.

use std::path::Path;

use tinydem::run::{Options, Verbosity, run};
use tinydem::scenario::Scenario;

#[test]
fn every_example_runs_a_few_frames() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut count = 0;
    let mut dirs: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    dirs.sort();
    for dir in dirs {
        let file = dir.join("scenario.toml");
        if !file.exists() {
            continue;
        }
        let mut s = Scenario::load(&file).unwrap_or_else(|e| panic!("{}: {e:#}", file.display()));
        s.simulation.frames = 2;
        s.simulation.steps_per_frame = 50;
        s.simulation.max_particles = s.simulation.max_particles.min(300);
        let out = tempfile::tempdir().unwrap();
        let options = Options {
            verbosity: Verbosity::Quiet,
            resume: None,
            from: None,
            stop: None,
        };
        let summary =
            run(s, out.path(), options).unwrap_or_else(|e| panic!("{}: {e:#}", file.display()));
        assert_eq!(summary.frames_written, 3);
        assert!(summary.particles > 0, "{}: no particles", file.display());
        count += 1;
    }
    assert!(count >= 4, "found {count} examples");
}
