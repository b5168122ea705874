//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use tinydem::scenario::Scenario;
use tinydem::simulation::Simulation;

pub fn data(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(path)
}

/// A scenario from TOML text; relative paths resolve against `tests/data`.
pub fn scenario(text: &str) -> Scenario {
    Scenario::parse(text, &data("inline.toml")).expect("valid test scenario")
}

/// Runs `steps` steps of a scenario given as TOML text.
pub fn simulate(text: &str, steps: u64) -> Simulation {
    let mut sim = Simulation::new(scenario(text)).expect("simulation starts");
    for _ in 0..steps {
        sim.step().unwrap();
    }
    sim
}

/// Runs the `tinydem` binary with `args` in `dir`.
pub fn tinydem(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tinydem"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("binary runs")
}

/// Runs the `tinydem` binary with `args` in `dir`, with the environment variables `env` set.
pub fn tinydem_with_env(args: &[&str], dir: &Path, env: &[(&str, &str)]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tinydem"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(dir)
        .output()
        .expect("binary runs")
}
