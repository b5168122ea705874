//! `tinydem run` and the default run (no command): the signals a run answers, and the
//! report at its end.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result};
use clap::Args;

use tinydem::driver::run::{Options, Requests, Summary, Verbosity, run_on};
use tinydem::engine::Stage;
use tinydem::parallel::comm::Comm;
use tinydem::scenario::Scenario;

/// How a run goes: where it writes, what it says, what it continues. The same for
/// `tinydem run SCENARIO` and the default run (`tinydem` with no command).
#[derive(Args)]
pub struct RunOptions {
    /// Output directory (overrides [output] dir).
    #[arg(long, short)]
    output: Option<PathBuf>,
    /// No status lines.
    #[arg(long, short)]
    quiet: bool,
    /// Continue an interrupted run from its checkpoint (written to the output
    /// directory on Ctrl-C/SIGTERM, every `[output] checkpoint_minutes` of wall time and
    /// every `checkpoint_every` frames).
    #[arg(long, conflicts_with = "from")]
    resume: Option<PathBuf>,
    /// Start a new stage of a study from the checkpoint of another run (its particles
    /// and contact history; the rest from the scenario, whose clock starts at 0).
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
}

#[derive(Args)]
pub struct RunArgs {
    scenario: PathBuf,
    #[command(flatten)]
    options: RunOptions,
}

impl RunArgs {
    /// Runs the scenario (on every process under mpirun; the `first` reports).
    pub fn execute(self, world: Option<Box<dyn Comm>>, first: bool) -> Result<()> {
        self.options
            .execute(Scenario::load(&self.scenario)?, world, first)
    }
}

impl RunOptions {
    /// Whether any option was given (they belong after `run SCENARIO` when a command is).
    pub fn any(&self) -> bool {
        self.output.is_some()
            || self.quiet
            || self.resume.is_some()
            || self.from.is_some()
            || self.overwrite
            || self.force
    }

    /// Runs scenario `s` (on every process under mpirun; the `first` reports).
    pub fn execute(self, s: Scenario, world: Option<Box<dyn Comm>>, first: bool) -> Result<()> {
        let out = self.output.unwrap_or_else(|| s.output_dir.clone());
        let verbosity = if self.quiet {
            Verbosity::Quiet
        } else {
            Verbosity::Normal
        };
        catch_signals()?;
        let options = Options {
            verbosity,
            resume: self.resume.as_deref(),
            from: self.from.as_deref(),
            overwrite: self.overwrite,
            force: self.force,
            requests: Some(&REQUESTS),
        };
        let summary = run_on(s, &out, options, world)?;
        match (first, self.quiet) {
            (true, false) => report(&summary, &out),
            (true, true) => warn(&summary),
            (false, _) => {}
        }
        Ok(())
    }
}

/// Set by signals: the run stops after the current step with a checkpoint, or writes one
/// and goes on (see `catch_signals`).
static REQUESTS: Requests = Requests {
    stop: AtomicBool::new(false),
    checkpoint: AtomicBool::new(false),
};

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

/// The end-of-run warnings: spawn regions that fell short, overlaps past the smaller
/// radius.
fn warn(summary: &Summary) {
    for short in &summary.spawn_shortfalls {
        eprintln!("warning: {short}");
    }
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

/// The closing lines of a run: what it did, what it removed, and where the time went.
fn report(summary: &Summary, out: &Path) {
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
    if let Some((met, frame)) = &summary.ended_by {
        eprintln!("ended at frame {frame} by {met}");
    }
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
    eprintln!("time: {}", time_shares(summary).join(", "));
}

/// The wall time of each stage, of the output and of the rest, with its share of the run
/// (the stages that took under 0.05 % left out).
fn time_shares(summary: &Summary) -> Vec<String> {
    let times = &summary.stage_times;
    let mut parts: Vec<(&str, f64)> = Stage::ALL
        .iter()
        .map(|&stage| (stage.name(), times.of(stage)))
        .collect();
    parts.push(("frames", summary.frame_seconds));
    parts.push(("checkpoints", summary.checkpoint_seconds));
    let other =
        summary.wall_seconds - times.total() - summary.frame_seconds - summary.checkpoint_seconds;
    parts.push(("other", other.max(0.0)));
    parts
        .iter()
        .filter(|(_, s)| *s >= 0.0005 * summary.wall_seconds)
        .map(|(name, s)| {
            format!(
                "{name} {s:.2} s ({:.0}%)",
                100.0 * s / summary.wall_seconds.max(1e-9)
            )
        })
        .collect()
}
