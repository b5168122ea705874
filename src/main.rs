//! The `tinydem` command line.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};

use std::sync::atomic::{AtomicBool, Ordering};

use tinydem::run::{Interrupted, Options, Summary, Verbosity, describe, run};
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
    /// Continue the interrupted default run from its checkpoint.
    #[arg(long)]
    resume: Option<PathBuf>,
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
        /// Continue an interrupted run from its checkpoint (written to the output
        /// directory on Ctrl-C/SIGTERM and every `[output] checkpoint_every` frames).
        #[arg(long)]
        resume: Option<PathBuf>,
    },
    /// Validate a scenario and print derived quantities.
    Check { scenario: PathBuf },
    /// The dense-packing benchmark of the paper's Section 5: timed steps in settled
    /// packings; each size and thread count runs in its own process.
    Bench {
        /// Particle counts (1000, 10000, 100000, 1000000, 10000000).
        #[arg(long, value_delimiter = ',', default_values_t = [1_000, 10_000, 100_000, 1_000_000])]
        sizes: Vec<usize>,
        /// Also run 10^7 particles (about 3 GB of memory).
        #[arg(long)]
        huge: bool,
        /// Thread counts to run each size with (default: 1 and all cores).
        #[arg(long = "workers", value_delimiter = ',')]
        workers: Vec<usize>,
        /// Steps per timed segment (default: about 10^7 particle-steps, at least 10).
        #[arg(long)]
        steps: Option<u64>,
        /// Timed segments per configuration; the median is reported.
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// Run one configuration in this process (used by the benchmark itself).
        #[arg(long, hide = true)]
        single: bool,
    },
}

/// Set on SIGINT or SIGTERM: the run stops after the current step with a checkpoint.
static STOP: AtomicBool = AtomicBool::new(false);

fn main() -> ExitCode {
    let cli = Cli::parse();
    match real_main(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.downcast_ref::<Interrupted>().is_some() => {
            eprintln!("{e:#}");
            ExitCode::from(130)
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Installs the handler that turns SIGINT/SIGTERM into a clean stop.
fn catch_signals() -> Result<()> {
    ctrlc::set_handler(|| STOP.store(true, Ordering::Relaxed))
        .context("cannot install the signal handler")
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
    pool.install(|| execute(cli.command, cli.resume))
}

fn execute(command: Option<Command>, resume_default: Option<PathBuf>) -> Result<()> {
    match command {
        None => {
            let s = Scenario::default();
            let out = s.output_dir.clone();
            catch_signals()?;
            let options = Options {
                verbosity: Verbosity::Normal,
                resume: resume_default.as_deref(),
                stop: Some(&STOP),
            };
            let summary = run(s, &out, options)?;
            report(&summary, &out);
        }
        Some(Command::Run {
            scenario,
            output,
            quiet,
            resume,
        }) => {
            let s = Scenario::load(&scenario)?;
            let out = output.unwrap_or_else(|| s.output_dir.clone());
            let verbosity = if quiet {
                Verbosity::Quiet
            } else {
                Verbosity::Normal
            };
            catch_signals()?;
            let options = Options {
                verbosity,
                resume: resume.as_deref(),
                stop: Some(&STOP),
            };
            let summary = run(s, &out, options)?;
            if !quiet {
                report(&summary, &out);
            }
        }
        Some(Command::Bench {
            mut sizes,
            huge,
            workers,
            steps,
            repeats,
            single,
        }) => {
            if huge && !sizes.contains(&10_000_000) {
                sizes.push(10_000_000);
            }
            anyhow::ensure!(repeats >= 1, "--repeats must be at least 1");
            if single {
                let n = sizes[0];
                let m = tinydem::bench::measure(
                    n,
                    steps.unwrap_or(tinydem::bench::default_steps(n)),
                    repeats,
                )?;
                println!("{}", m.row());
                return Ok(());
            }
            bench(&sizes, &workers, steps, repeats)?;
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

/// Runs every (size, workers) configuration in a child process, so that each reports its
/// own peak memory, and prints the table.
fn bench(sizes: &[usize], workers: &[usize], steps: Option<u64>, repeats: usize) -> Result<()> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let workers: Vec<usize> = if workers.is_empty() {
        let mut w = vec![1, cores];
        w.dedup();
        w
    } else {
        workers.to_vec()
    };
    let exe = std::env::current_exe().context("cannot locate the tinydem executable")?;
    println!("{}", tinydem::bench::Measurement::HEADER);
    for &n in sizes {
        for &t in &workers {
            let mut cmd = std::process::Command::new(&exe);
            cmd.args([
                "bench",
                "--single",
                "--sizes",
                &n.to_string(),
                "--threads",
                &t.to_string(),
            ]);
            cmd.args(["--repeats", &repeats.to_string()]);
            if let Some(s) = steps {
                cmd.args(["--steps", &s.to_string()]);
            }
            let out = cmd.output().context("cannot run the benchmark process")?;
            if !out.status.success() {
                anyhow::bail!(
                    "benchmark N = {n}, {t} threads failed: {}",
                    String::from_utf8_lossy(&out.stderr).trim()
                );
            }
            print!("{}", String::from_utf8_lossy(&out.stdout));
        }
    }
    Ok(())
}
