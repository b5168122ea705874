//! The `tinydem` command line.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};

use tinydem::run::{Summary, Verbosity, describe, run};
use tinydem::scenario::Scenario;

/// A granular DEM simulator (the model of the TinyDEM paper). With no arguments, runs the
/// paper's default simulation: 1000 particles falling through an hourglass, into ./output.
#[derive(Parser)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Number of worker threads (default: all cores).
    #[arg(long, global = true)]
    threads: Option<usize>,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scenario file.
    Run {
        scenario: PathBuf,
        /// Output directory (overrides [output] dir).
        #[arg(long, short)]
        output: Option<PathBuf>,
        /// No status lines.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Validate a scenario and print derived quantities.
    Check { scenario: PathBuf },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match real_main(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn real_main(cli: Cli) -> Result<()> {
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = cli.threads {
        anyhow::ensure!(n >= 1, "--threads must be at least 1");
        pool = pool.num_threads(n);
    }
    // The time loop runs on a worker of the pool, so that small parallel loops run inline
    // instead of waking another thread for every stage.
    let pool = pool.build().context("cannot start the thread pool")?;
    pool.install(|| execute(cli.command))
}

fn execute(command: Option<Command>) -> Result<()> {
    match command {
        None => {
            let s = Scenario::default();
            let out = s.output_dir.clone();
            let summary = run(s, &out, Verbosity::Normal)?;
            report(&summary, &out);
        }
        Some(Command::Run {
            scenario,
            output,
            quiet,
        }) => {
            let s = Scenario::load(&scenario)?;
            let out = output.unwrap_or_else(|| s.output_dir.clone());
            let verbosity = if quiet {
                Verbosity::Quiet
            } else {
                Verbosity::Normal
            };
            let summary = run(s, &out, verbosity)?;
            if !quiet {
                report(&summary, &out);
            }
        }
        Some(Command::Check { scenario }) => {
            let s = Scenario::load(&scenario)?;
            print!("{}", describe(&s)?);
        }
    }
    Ok(())
}

/// The closing line of a run.
fn report(summary: &Summary, out: &std::path::Path) {
    eprintln!(
        "done: {} particles, {} steps ({} neighbour-list rebuilds), {} frames in {}, {:.2} s",
        summary.particles,
        summary.steps,
        summary.rebuilds,
        summary.frames_written,
        out.display(),
        summary.wall_seconds
    );
}
