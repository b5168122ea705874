//! The `tinydem` command line: its arguments, and the processes and threads a command
//! runs on; each command in a module of its own.

mod analyze;
mod bench;
mod plot;
mod render;
mod run;
mod verify;

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};

use tinydem::driver::check::{describe, describe_stage};
use tinydem::driver::run::Interrupted;
use tinydem::parallel::comm::Comm;
use tinydem::scenario::Scenario;

use run::RunOptions;

/// A granular DEM simulator (the model of the TinyDEM paper). With no command, runs the
/// paper's default simulation: 1000 particles falling through an hourglass, into ./output
/// (the options of `tinydem run` apply to it: --output, --quiet, --resume, --overwrite, ...).
#[derive(Parser)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Number of worker threads (default: all cores; under mpirun, the cores shared among
    /// the processes of this machine).
    #[arg(long, global = true)]
    threads: Option<usize>,
    /// The default run's options (as `tinydem run`'s).
    #[command(flatten)]
    default: RunOptions,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scenario file.
    Run(run::RunArgs),
    /// Validate a scenario and print derived quantities.
    Check(CheckArgs),
    /// Measure every frame of an output directory: kinetic energy, coordination number,
    /// packing fraction; optionally the angle of repose and the height of large particles.
    Analyze(analyze::AnalyzeArgs),
    /// Draw a frame (CSV) as a PNG picture, or every frame of an output directory.
    Render(render::RenderArgs),
    /// Draw columns of a CSV table (log.csv, walls.csv, analyze --csv) against one of them,
    /// as SVG or PNG: a legend, units, log axes.
    Plot(plot::PlotArgs),
    /// Checkpoints: `merge` joins the parts a split run wrote (`checkpoint.bin.STEP.part-K-of-N`)
    /// into the one file.
    #[command(subcommand)]
    Checkpoint(CheckpointCommand),
    /// The dense-packing benchmark of the paper's Section 5: timed steps in settled
    /// packings; each size and thread count runs in its own process.
    Bench(bench::BenchArgs),
    /// Run the analytic verification cases (Hertz impacts, Chung & Ooi's test 2,
    /// restitution, oblique sliding, slip to rolling, static overlaps) with this build: a table of each quantity against
    /// its reference; fails if any is beyond its tolerance.
    Verify(verify::VerifyArgs),
}

impl Command {
    /// The command's name on the command line.
    fn name(&self) -> &'static str {
        match self {
            Command::Run(_) => "run SCENARIO",
            Command::Check(_) => "check",
            Command::Analyze(_) => "analyze",
            Command::Render(_) => "render",
            Command::Plot(_) => "plot",
            Command::Checkpoint(_) => "checkpoint",
            Command::Bench(_) => "bench",
            Command::Verify(_) => "verify",
        }
    }
}

#[derive(Subcommand)]
enum CheckpointCommand {
    /// Join the newest complete set of parts of a checkpoint into the one file (as a run in
    /// one process writes it) and remove the parts.
    Merge {
        /// The checkpoint, e.g. output/checkpoint.bin (its parts are beside it).
        checkpoint: PathBuf,
    },
}

impl CheckpointCommand {
    fn execute(self) -> Result<()> {
        match self {
            CheckpointCommand::Merge { checkpoint } => {
                let n = tinydem::io::checkpoint::merge(&checkpoint)?;
                eprintln!("joined {n} parts into {}", checkpoint.display());
                Ok(())
            }
        }
    }
}

#[derive(Args)]
struct CheckArgs {
    scenario: PathBuf,
    /// Also say what the scenario changes as a stage after this checkpoint.
    #[arg(long)]
    from: Option<PathBuf>,
    /// The output directory the run would use (for its free space; default [output] dir).
    #[arg(long, short)]
    output: Option<PathBuf>,
}

impl CheckArgs {
    /// Prints what the run of the scenario would be, or the error that refuses it.
    fn execute(self) -> Result<()> {
        let s = Scenario::load(&self.scenario)?;
        let out = self.output.unwrap_or_else(|| s.output_dir.clone());
        match self.from {
            None => print!("{}", describe(&s, &out)?),
            Some(from) => print!("{}", describe_stage(&s, &from, &out)?),
        }
        Ok(())
    }
}

/// Large allocations (1 MiB and up) go straight to the operating system and back. glibc
/// otherwise raises that threshold to the size of the largest block freed: the neighbour
/// lists, tens of megabytes freed and made again at every rebuild, then come from a heap
/// that fragments and never shrinks (a 10^5 benchmark grew from 540 to 1,190 bytes per
/// particle over seven rebuilds; with the fixed threshold it stays at 550).
fn fix_mmap_threshold() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets an allocator parameter; called before any thread starts.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 1 << 20);
    }
}

fn main() -> ExitCode {
    fix_mmap_threshold();
    let cli = Cli::parse();
    // Under mpirun, the first process speaks for all (they fail alike, see `domain::agree`).
    let first = tinydem::parallel::comm::launched().is_none_or(|(_, rank)| rank == 0);
    // Held to the end, after the last words: only then may the other processes exit
    // (see `Finalize`).
    let (world, _finalize) = match world() {
        Ok(w) => w,
        Err(e) => return last_words(first, Err(e)),
    };
    last_words(first, real_main(cli, world))
}

/// Prints how the command ended (from the first process only) and gives the exit code.
fn last_words(first: bool, outcome: Result<()>) -> ExitCode {
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        // Said by the run as soon as its checkpoint was complete.
        Err(e) if e.downcast_ref::<Interrupted>().is_some() => ExitCode::from(130),
        Err(e) => {
            if first {
                eprintln!("error: {e:#}");
            }
            ExitCode::FAILURE
        }
    }
}

/// Holds MPI initialized until dropped (nothing without the `mpi` feature).
#[cfg(feature = "mpi")]
type Finalize = Option<tinydem::parallel::comm::Finalize>;
#[cfg(not(feature = "mpi"))]
type Finalize = ();

/// The processes a run is split over when started by an MPI launcher (in a build with the
/// `mpi` feature); none otherwise.
fn world() -> Result<(Option<Box<dyn Comm>>, Finalize)> {
    let Some((size, _)) = tinydem::parallel::comm::launched() else {
        return Ok((None, Finalize::default()));
    };
    #[cfg(feature = "mpi")]
    {
        let _ = size;
        let (comm, finalize) = tinydem::parallel::comm::Mpi::init()?;
        // (For the test that a panic on one process ends them all, tests/mpi.rs.)
        let panic_on = std::env::var("TINYDEM_TEST_PANIC_RANK").ok();
        if panic_on.and_then(|r| r.parse().ok()) == Some(comm.rank()) {
            panic!("a panic on process {} for the test", comm.rank());
        }
        let comm: Box<dyn Comm> = Box::new(comm);
        Ok((Some(comm), Some(finalize)))
    }
    #[cfg(not(feature = "mpi"))]
    {
        anyhow::ensure!(
            size <= 1,
            "started as one of {size} processes, but this tinydem was built without MPI: \
             build it with `cargo build --release --features mpi` (needs an MPI library, \
             e.g. Debian's libopenmpi-dev, and libclang-dev)"
        );
        Ok((None, ()))
    }
}

fn real_main(cli: Cli, world: Option<Box<dyn Comm>>) -> Result<()> {
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = cli.threads {
        anyhow::ensure!(n >= 1, "--threads must be at least 1");
        pool = pool.num_threads(n);
    } else if world.is_some() {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        pool = pool.num_threads((cores / tinydem::parallel::comm::processes_on_this_node()).max(1));
    }
    // The time loop runs on a worker of the pool, so that small parallel loops run inline
    // instead of waking another thread for every stage.
    let pool = pool.build().context("cannot start the thread pool")?;
    if let Some(command) = &cli.command
        && cli.default.any()
    {
        anyhow::bail!(
            "the run options (--output, --quiet, --resume, --from, --overwrite, --force) go \
             after the command: tinydem {} ... --output DIR",
            command.name()
        );
    }
    pool.install(|| execute(cli.command, cli.default, world))
}

/// Runs `command` (the default run when there is none) on the processes of `world`.
fn execute(
    command: Option<Command>,
    default: RunOptions,
    world: Option<Box<dyn Comm>>,
) -> Result<()> {
    let first = world.as_ref().is_none_or(|c| c.rank() == 0);
    // Under mpirun, a command that does not step a simulation runs on the first process
    // only: the others would do the same work and write the same files at the same time.
    let splits = match &command {
        None | Some(Command::Run(_)) => true,
        Some(Command::Bench(b)) => b.single,
        _ => false,
    };
    if !first && !splits {
        return Ok(());
    }
    match command {
        None => default.execute(Scenario::default(), world, first),
        Some(Command::Run(args)) => args.execute(world, first),
        Some(Command::Bench(args)) => args.execute(world, first),
        Some(Command::Render(args)) => args.execute(),
        Some(Command::Analyze(args)) => args.execute(),
        Some(Command::Plot(args)) => args.execute(),
        Some(Command::Check(args)) => args.execute(),
        Some(Command::Checkpoint(c)) => c.execute(),
        Some(Command::Verify(args)) => args.execute(),
    }
}

/// `--size WIDTHxHEIGHT`.
pub(crate) fn size(text: &str) -> Result<(u32, u32), String> {
    let parse = |t: &str| t.trim().parse::<u32>().ok();
    match text
        .split_once(['x', 'X'])
        .map(|(w, h)| (parse(w), parse(h)))
    {
        Some((Some(w), Some(h))) => Ok((w, h)),
        _ => Err(format!("{text:?} is no WIDTHxHEIGHT, e.g. 1600x1200")),
    }
}
