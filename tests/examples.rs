//! Every example scenario in `examples/` loads and runs a few steps at a reduced size.

use std::path::{Path, PathBuf};

use tinydem::driver::run::{Options, Verbosity, run};
use tinydem::scenario::Scenario;

#[test]
fn every_example_runs_a_few_frames() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut count = 0;
    let mut dirs: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    for dir in dirs {
        // Scenarios on their own (`scenario.toml`, a size series `pile_5000.toml`, ...), and
        // stages `1_*.toml`, `2_*.toml`, ... each run from the checkpoint of the one before.
        let (mut stages, alone): (Vec<_>, Vec<_>) = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .partition(|p| {
                let name = p.file_name().unwrap().to_string_lossy();
                name.starts_with(|c: char| c.is_ascii_digit())
            });
        stages.sort();
        for file in alone {
            count += run_briefly(&[file]);
        }
        count += run_briefly(&stages);
    }
    assert!(count >= 12, "found {count} scenarios");
}

/// Runs the scenarios `files` for two frames of 50 steps with at most 300 particles, each
/// from the checkpoint of the one before; the number of scenarios run.
fn run_briefly(files: &[PathBuf]) -> usize {
    let out = tempfile::tempdir().unwrap();
    for (k, file) in files.iter().enumerate() {
        let mut s = Scenario::load(file).unwrap_or_else(|e| panic!("{}: {e:#}", file.display()));
        s.simulation.frames = 2;
        s.simulation.steps_per_frame = 50;
        s.simulation.max_particles = s.simulation.max_particles.min(300);
        let stage = out.path().join(k.to_string());
        let from = (k > 0).then(|| out.path().join((k - 1).to_string()).join("checkpoint.bin"));
        let options = Options {
            verbosity: Verbosity::Quiet,
            resume: None,
            from: from.as_deref(),
            overwrite: false,
            force: false,
            requests: None,
        };
        let summary =
            run(s, &stage, options).unwrap_or_else(|e| panic!("{}: {e:#}", file.display()));
        assert_eq!(summary.frames_written, 3);
        assert!(summary.particles > 0, "{}: no particles", file.display());
    }
    files.len()
}
