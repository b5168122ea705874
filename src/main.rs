//! The `tinydem` command line.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};

use std::sync::atomic::{AtomicBool, Ordering};

use glam::DVec3;
use tinydem::check::{describe, describe_stage};
use tinydem::comm::Comm;
use tinydem::render::{Animation, ColorBy, Fixed, Style, View};
use tinydem::run::{Interrupted, Options, Requests, Summary, Verbosity, run_on};
use tinydem::scenario::Scenario;
use tinydem::simulation::Stage;

/// A granular DEM simulator (the model of the TinyDEM paper). With no arguments, runs the
/// paper's default simulation: 1000 particles falling through an hourglass, into ./output.
#[derive(Parser)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Number of worker threads (default: all cores; under mpirun, the cores shared among
    /// the processes of this machine).
    #[arg(long, global = true)]
    threads: Option<usize>,
    /// Continue the interrupted default run from its checkpoint.
    #[arg(long)]
    resume: Option<PathBuf>,
    /// Replace the output of an earlier default run in ./output.
    #[arg(long)]
    overwrite: bool,
    /// Run the default simulation even if `check` would refuse it.
    #[arg(long)]
    force: bool,
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
        #[arg(long, conflicts_with = "from")]
        resume: Option<PathBuf>,
        /// Start a new stage of a study from the checkpoint of another run (its particles
        /// and contact history; the rest from SCENARIO, whose clock starts at 0).
        #[arg(long)]
        from: Option<PathBuf>,
        /// Replace the output of an earlier run in the output directory (its frames, logs
        /// and checkpoint; other files stay).
        #[arg(long)]
        overwrite: bool,
        /// Run even with a time step far past Eq. 50, or output that may not fit the free
        /// space (see `tinydem check`).
        #[arg(long)]
        force: bool,
    },
    /// Validate a scenario and print derived quantities.
    Check {
        scenario: PathBuf,
        /// Also say what the scenario changes as a stage after this checkpoint.
        #[arg(long)]
        from: Option<PathBuf>,
        /// The output directory the run would use (for its free space; default [output] dir).
        #[arg(long, short)]
        output: Option<PathBuf>,
    },
    /// Measure every frame of an output directory: kinetic energy, coordination number,
    /// packing fraction; optionally the angle of repose and the height of large particles.
    Analyze {
        /// Output directory with frames particlesNNNNNN.csv.
        dir: PathBuf,
        /// The run's scenario, for frame times and the density.
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// Fit the angle of repose of a pile in the x-z plane (both flanks, with errors): the
        /// resting grains' surface, from 3 to 30 diameters below the apex (see --window).
        #[arg(long)]
        repose: bool,
        /// With --repose: grains slower than this rest [m/s]; only they make the pile.
        #[arg(long, default_value_t = 0.01, requires = "repose")]
        rest_speed: f64,
        /// With --repose: the fitted part of each flank, FROM,TO grain diameters below the apex
        /// (leaving out the rounded apex and the curved foot).
        #[arg(
            long,
            value_name = "FROM,TO",
            value_delimiter = ',',
            requires = "repose"
        )]
        window: Option<Vec<f64>>,
        /// Report the mean height of the particles with at least this radius.
        #[arg(long)]
        large: Option<f64>,
        /// Report the number and mean height of the particles with this tag.
        #[arg(long)]
        tag: Option<u32>,
        /// Also write the table as CSV to this file.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Also plot one column against time as a PNG (see --column).
        #[arg(long)]
        plot: Option<PathBuf>,
        /// The column to plot (a name from the table's header).
        #[arg(long, default_value = "kinetic_energy")]
        column: String,
    },
    /// Draw a frame (CSV) as a PNG picture, or every frame of an output directory.
    Render {
        /// A frame `particlesNNNNNN.csv`, or an output directory.
        path: PathBuf,
        /// Output PNG (for a frame) or directory (for a directory; default: beside the frames).
        #[arg(long, short)]
        output: Option<PathBuf>,
        /// Draw the meshes of this scenario (moving meshes at the frame's time).
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// Draw this mesh file (OFF or STL); may be repeated.
        #[arg(long)]
        mesh: Vec<PathBuf>,
        #[arg(long, default_value_t = 800)]
        width: u32,
        #[arg(long, default_value_t = 600)]
        height: u32,
        /// Particle colour.
        #[arg(long, value_enum, default_value_t = ColorBy::Speed)]
        color: ColorBy,
        /// Direction of view.
        #[arg(long, value_enum, default_value_t = View::Iso)]
        view: View,
        /// For a directory, also write an animated GIF `animation.gif`.
        #[arg(long)]
        gif: bool,
        /// For a directory, also write a movie `animation.mp4` (with the system's ffmpeg;
        /// an animated GIF where there is none).
        #[arg(long, conflicts_with = "gif")]
        movie: bool,
        /// The values at the ends of the colour bar, LO,HI (default: fitted to all frames).
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
        range: Option<Vec<f64>>,
        /// The box to show, X0,Y0,Z0,X1,Y1,Z1 [m] (default: fitted to all frames).
        #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
        bounds: Option<Vec<f64>>,
        /// Draw a scale bar.
        #[arg(long)]
        scale_bar: bool,
    },
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
        /// Process counts to split each size over, under `mpirun --oversubscribe` (a build
        /// with the `mpi` feature; default: 1).
        #[arg(long, value_delimiter = ',', default_values_t = [1])]
        ranks: Vec<usize>,
        /// Steps per timed segment (default: about 10^7 particle-steps, at least 100).
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

/// Set by signals: the run stops after the current step with a checkpoint, or writes one
/// and goes on (see `catch_signals`).
static REQUESTS: Requests = Requests {
    stop: AtomicBool::new(false),
    checkpoint: AtomicBool::new(false),
};

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
    let first = tinydem::comm::launched().is_none_or(|(_, rank)| rank == 0);
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
type Finalize = Option<tinydem::comm::Finalize>;
#[cfg(not(feature = "mpi"))]
type Finalize = ();

/// The processes a run is split over when started by an MPI launcher (in a build with the
/// `mpi` feature); none otherwise.
fn world() -> Result<(Option<Box<dyn Comm>>, Finalize)> {
    let Some((size, _)) = tinydem::comm::launched() else {
        return Ok((None, Finalize::default()));
    };
    #[cfg(feature = "mpi")]
    {
        let _ = size;
        let (comm, finalize) = tinydem::comm::Mpi::init()?;
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

/// Installs the handlers of the signals a run answers: SIGINT, SIGTERM, SIGHUP and SIGUSR1
/// stop it after the current step with a checkpoint (SIGUSR1 is the one `mpirun` passes on
/// to the processes without killing them a second later); a second such signal ends the
/// process at once (a run blocked in a write or a read), keeping the last complete
/// checkpoint. SIGCONT, which `mpirun` and Slurm send a second before SIGTERM, writes a
/// checkpoint after the current step.
fn catch_signals() -> Result<()> {
    use signal_hook::consts::{SIGCONT, SIGHUP, SIGINT, SIGTERM, SIGUSR1};
    let mut signals =
        signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP, SIGUSR1, SIGCONT])
            .context("cannot install the signal handlers")?;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            let mut asked = false;
            for signal in signals.forever() {
                if signal == SIGCONT {
                    REQUESTS.checkpoint.store(true, Ordering::Relaxed);
                } else if asked {
                    eprintln!("a second signal: stopping now; the last complete checkpoint stays");
                    std::process::exit(130);
                } else {
                    asked = true;
                    REQUESTS.stop.store(true, Ordering::Relaxed);
                }
            }
        })
        .context("cannot start the signal thread")?;
    Ok(())
}

fn real_main(cli: Cli, world: Option<Box<dyn Comm>>) -> Result<()> {
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = cli.threads {
        anyhow::ensure!(n >= 1, "--threads must be at least 1");
        pool = pool.num_threads(n);
    } else if world.is_some() {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        pool = pool.num_threads((cores / tinydem::comm::processes_on_this_node()).max(1));
    }
    // The time loop runs on a worker of the pool, so that small parallel loops run inline
    // instead of waking another thread for every stage.
    let pool = pool.build().context("cannot start the thread pool")?;
    pool.install(|| execute(cli.command, cli.resume, cli.overwrite, cli.force, world))
}

fn execute(
    command: Option<Command>,
    resume_default: Option<PathBuf>,
    overwrite_default: bool,
    force_default: bool,
    world: Option<Box<dyn Comm>>,
) -> Result<()> {
    let first = world.as_ref().is_none_or(|c| c.rank() == 0);
    // Under mpirun, a command that does not step a simulation runs on the first process
    // only: the others would do the same work and write the same files at the same time.
    let splits = matches!(
        command,
        None | Some(Command::Run { .. }) | Some(Command::Bench { single: true, .. })
    );
    if !first && !splits {
        return Ok(());
    }
    match command {
        None => {
            let s = Scenario::default();
            let out = s.output_dir.clone();
            catch_signals()?;
            let options = Options {
                verbosity: Verbosity::Normal,
                resume: resume_default.as_deref(),
                from: None,
                overwrite: overwrite_default,
                force: force_default,
                requests: Some(&REQUESTS),
            };
            let summary = run_on(s, &out, options, world)?;
            if first {
                report(&summary, &out);
            }
        }
        Some(Command::Run {
            scenario,
            output,
            quiet,
            resume,
            from,
            overwrite,
            force,
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
                from: from.as_deref(),
                overwrite,
                force,
                requests: Some(&REQUESTS),
            };
            let summary = run_on(s, &out, options, world)?;
            match (first, quiet) {
                (true, false) => report(&summary, &out),
                (true, true) => warn(&summary),
                (false, _) => {}
            }
        }
        Some(Command::Bench {
            mut sizes,
            huge,
            workers,
            ranks,
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
                    world,
                )?;
                if first {
                    println!("{}", m.row());
                }
                return Ok(());
            }
            anyhow::ensure!(ranks.iter().all(|&r| r >= 1), "--ranks must be at least 1");
            bench(&sizes, &workers, &ranks, steps, repeats)?;
        }
        Some(Command::Render {
            path,
            output,
            scenario,
            mesh,
            width,
            height,
            color,
            view,
            gif,
            movie,
            range,
            bounds,
            scale_bar,
        }) => {
            let style = Style {
                width,
                height,
                color,
                view,
                scale_bar,
            };
            if let Some(r) = range.as_ref().filter(|r| r.len() != 2) {
                anyhow::bail!("--range takes two numbers LO,HI, not {}", r.len());
            }
            if let Some(b) = bounds.as_ref().filter(|b| b.len() != 6) {
                anyhow::bail!(
                    "--bounds takes six numbers X0,Y0,Z0,X1,Y1,Z1, not {}",
                    b.len()
                );
            }
            let fixed = Fixed {
                range: range.map(|r| (r[0], r[1])),
                bounds: bounds
                    .map(|b| (DVec3::new(b[0], b[1], b[2]), DVec3::new(b[3], b[4], b[5]))),
            };
            if let Some((lo, hi)) = fixed.range {
                anyhow::ensure!(
                    lo < hi && lo.is_finite() && hi.is_finite(),
                    "--range {lo},{hi}: LO must be below HI"
                );
            }
            let animation = Animation::of(gif, movie);
            let done = tinydem::render::render_path(
                &path,
                output.as_deref(),
                scenario.as_deref(),
                &mesh,
                &style,
                &fixed,
                animation,
            )?;
            for note in &done.notes {
                eprintln!("note: {note}");
            }
            match done.pictures.as_slice() {
                [one] => eprintln!("picture in {}", one.display()),
                all => eprintln!(
                    "{} pictures in {}",
                    all.len(),
                    all[0]
                        .parent()
                        .map_or(".".into(), |d| d.display().to_string())
                ),
            }
            if let Some(a) = done.animation {
                eprintln!("animation in {}", a.display());
            }
        }
        Some(Command::Analyze {
            dir,
            scenario,
            repose,
            rest_speed,
            window,
            large,
            tag,
            csv,
            plot,
            column,
        }) => analyze_command(
            &dir,
            scenario,
            repose
                .then(|| tinydem::analyze::ReposeWindow::of(rest_speed, window.as_deref()))
                .transpose()?,
            large,
            tag,
            csv,
            plot.map(|p| (p, column)),
        )?,
        Some(Command::Check {
            scenario,
            from,
            output,
        }) => {
            let s = Scenario::load(&scenario)?;
            let out = output.unwrap_or_else(|| s.output_dir.clone());
            match from {
                None => print!("{}", describe(&s, &out)?),
                Some(from) => print!("{}", describe_stage(&s, &from, &out)?),
            }
        }
    }
    Ok(())
}

/// The closing line of a run.
/// The end-of-run warning about overlaps past the smaller radius, if there were any.
fn warn(summary: &Summary) {
    let n = summary.warnings;
    if n > 0 {
        eprintln!(
            "warning: {n} {} overlapped by more than the smaller radius at some step (the run \
             went on: it stops only past the smaller diameter). Likely cause: {}",
            if n == 1 { "pair" } else { "pairs" },
            summary.advice
        );
    }
}

fn report(summary: &Summary, out: &std::path::Path) {
    warn(summary);
    eprintln!(
        "done: {} particles, {} steps ({} neighbour-list rebuilds), {} frames in {}, {:.2} s",
        summary.particles,
        summary.steps,
        summary.rebuilds,
        summary.frames_written,
        out.display(),
        summary.wall_seconds
    );
    let r = &summary.removed;
    if r.count() > 0 {
        let mut by = Vec::new();
        for (k, o) in r.outlets.iter().enumerate() {
            by.push(format!("outlet {k}: {} ({:.6e} kg)", o.count, o.mass));
        }
        if r.domain.count > 0 {
            by.push(format!(
                "left the domain: {} ({:.6e} kg)",
                r.domain.count, r.domain.mass
            ));
        }
        eprintln!("removed {} particles: {}", r.count(), by.join(", "));
    }
    let times = &summary.stage_times;
    let mut parts: Vec<(&str, f64)> = Stage::ALL
        .iter()
        .map(|&stage| (stage.name(), times.of(stage)))
        .collect();
    parts.push(("output", summary.output_seconds));
    let other = summary.wall_seconds - times.total() - summary.output_seconds;
    parts.push(("other", other.max(0.0)));
    let shown: Vec<String> = parts
        .iter()
        .filter(|(_, s)| *s >= 0.0005 * summary.wall_seconds)
        .map(|(name, s)| {
            format!(
                "{name} {s:.2} s ({:.0}%)",
                100.0 * s / summary.wall_seconds.max(1e-9)
            )
        })
        .collect();
    eprintln!("time: {}", shown.join(", "));
}

/// Runs every (size, workers, ranks) configuration in a child process (or `mpirun` of
/// several), so that each reports its own peak memory, and prints the table.
fn bench(
    sizes: &[usize],
    workers: &[usize],
    ranks: &[usize],
    steps: Option<u64>,
    repeats: usize,
) -> Result<()> {
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
        for (&t, &r) in workers
            .iter()
            .flat_map(|t| ranks.iter().map(move |r| (t, r)))
        {
            let mut cmd = if r == 1 {
                std::process::Command::new(&exe)
            } else {
                let mut c = std::process::Command::new("mpirun");
                c.args(["--oversubscribe", "-np", &r.to_string()]).arg(&exe);
                c
            };
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
                    "benchmark N = {n}, {t} threads, {r} processes failed: {}",
                    String::from_utf8_lossy(&out.stderr).trim()
                );
            }
            print!("{}", String::from_utf8_lossy(&out.stdout));
        }
    }
    Ok(())
}

/// `tinydem analyze`: a table of measurements, one row per frame.
fn analyze_command(
    dir: &std::path::Path,
    scenario: Option<PathBuf>,
    repose: Option<tinydem::analyze::ReposeWindow>,
    large: Option<f64>,
    tag: Option<u32>,
    csv: Option<PathBuf>,
    plot: Option<(PathBuf, String)>,
) -> Result<()> {
    use tinydem::analyze::*;
    let s = match scenario.or_else(|| tinydem::output::run_toml(dir)) {
        Some(p) => Scenario::load(&p)?,
        None => Scenario::parse("", std::path::Path::new("defaults"))?,
    };
    let frame_time = s.simulation.steps_per_frame as f64 * s.simulation.timestep;
    let mut frames: Vec<(u64, PathBuf)> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read directory {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter_map(|p| {
            let k = p
                .file_name()?
                .to_str()?
                .strip_prefix("particles")?
                .strip_suffix(".csv")?
                .parse()
                .ok()?;
            Some((k, p))
        })
        .collect();
    frames.sort();
    anyhow::ensure!(
        !frames.is_empty(),
        "{}: no frames particlesNNNNNN.csv",
        dir.display()
    );
    let mut header = vec![
        "frame",
        "time",
        "particles",
        "kinetic_energy",
        "coordination",
        "packing_fraction",
    ];
    if repose.is_some() {
        header.extend([
            "repose_left_deg",
            "repose_left_err_deg",
            "repose_right_deg",
            "repose_right_err_deg",
        ]);
    }
    if large.is_some() {
        header.push("large_mean_height");
    }
    if tag.is_some() {
        header.extend(["tagged", "tagged_mean_height"]);
    }
    let densities: Vec<f64> = s.materials.iter().map(|m| m.properties.density).collect();
    let mut rows = Vec::new();
    let mut no_pile = Vec::new();
    println!(
        "{}",
        header
            .iter()
            .map(|h| format!("{h:>17}"))
            .collect::<String>()
    );
    let count = frames.len();
    for (k, path) in frames {
        let p = tinydem::csv::load_particles(&path)?;
        let mut row = vec![
            k.to_string(),
            format!("{:.6e}", k as f64 * frame_time),
            p.len().to_string(),
            format!("{:.6e}", kinetic_energy(&p, &densities)),
            format!("{:.4}", coordination_number(&p)),
            format!("{:.4}", packing_fraction(&p)),
        ];
        if let Some(w) = repose {
            match angle_of_repose(&p, w) {
                Ok(a) => row.extend(
                    [a.left.angle, a.left.error, a.right.angle, a.right.error]
                        .map(|v| format!("{v:.2}")),
                ),
                Err(why) => {
                    no_pile.push((k, why));
                    row.extend(["nan"; 4].map(String::from))
                }
            }
        }
        if let Some(r) = large {
            row.push(mean_height_of_large(&p, r).map_or("nan".into(), |z| format!("{z:.6e}")));
        }
        if let Some(t) = tag {
            let z: Vec<f64> = (0..p.len())
                .filter(|&k| p.tag[k] == t)
                .map(|k| p.x[k].z)
                .collect();
            row.push(z.len().to_string());
            row.push(if z.is_empty() {
                "nan".into()
            } else {
                format!("{:.6e}", z.iter().sum::<f64>() / z.len() as f64)
            });
        }
        println!(
            "{}",
            row.iter().map(|v| format!("{v:>17}")).collect::<String>()
        );
        rows.push(row.join(","));
    }
    if let (Some(w), false) = (repose, no_pile.is_empty()) {
        let (k, why) = &no_pile[no_pile.len() - 1];
        eprintln!(
            "note: --repose found no pile in {} of {count} frames (nan), e.g. frame {k}: {why}. It \
             fits the surface of the grains slower than {} m/s, {} to {} diameters below the \
             highest, on both sides (--rest-speed, --window)",
            no_pile.len(),
            w.rest_speed,
            w.from,
            w.to
        );
    }
    if let Some(path) = csv {
        std::fs::write(
            &path,
            format!("{}\n{}\n", header.join(","), rows.join("\n")),
        )
        .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some((path, column)) = plot {
        let Some(c) = header.iter().position(|h| *h == column) else {
            anyhow::bail!(
                "--column {column}: not a column of this table ({})",
                header.join(", ")
            );
        };
        let points: Vec<(f64, f64)> = rows
            .iter()
            .map(|r| {
                let v: Vec<&str> = r.split(',').collect();
                (
                    v[1].parse().unwrap_or(f64::NAN),
                    v[c].parse().unwrap_or(f64::NAN),
                )
            })
            .collect();
        let unit = match column.as_str() {
            "time" => " [s]",
            "kinetic_energy" => " [J]",
            "large_mean_height" | "tagged_mean_height" => " [m]",
            c if c.starts_with("repose_") => " [°]",
            "coordination" => " [contacts per particle]",
            _ => "",
        };
        let y = format!("{column}{unit}");
        let axes = tinydem::plot::Axes {
            x: "time [s]",
            y: &y,
        };
        tinydem::plot::line_plot(&points, 800, 500, &axes)?
            .save(&path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        eprintln!("plot of {column} against time in {}", path.display());
    }
    Ok(())
}
