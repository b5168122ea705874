//! Running a scenario: frames and checkpoints written to the output directory, status on
//! stderr, a clean stop on SIGINT/SIGTERM and a loud one when the run becomes unstable.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, Result};

use super::outputs::{Frames, Logs};
use super::status::Status;
use crate::engine::{Simulation, StageTimes};
use crate::io::checkpoint;
use crate::io::csv::{Extra, frame_name};
use crate::io::lock::Lock;
use crate::io::output::{claim_output, take_output};
use crate::neighbours::Entries;
use crate::parallel::comm::Comm;
use crate::scenario::{Met, Scenario};

pub use crate::io::output::{
    CHECKPOINT, FRAMES, INTERRUPTED, LOG, LOG_HEADER, OUTLETS, RUN_TOML, UNSTABLE, WALLS,
};

/// How much to tell the user while running.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verbosity {
    Quiet,
    /// One status line per frame, and a progress bar on a terminal.
    Normal,
}

/// How to run.
#[derive(Clone, Copy, Debug)]
pub struct Options<'a> {
    pub verbosity: Verbosity,
    /// Continue from this checkpoint instead of starting afresh.
    pub resume: Option<&'a Path>,
    /// Start from the particles and contacts of this checkpoint of another run (a stage).
    pub from: Option<&'a Path>,
    /// Clear the output of an earlier run from the directory first (otherwise such a
    /// directory is refused, unless resuming).
    pub overwrite: bool,
    /// Run even when the scenario's time step is far past Eq. 50 or its output may not fit
    /// the free space (`check::refusals`).
    pub force: bool,
    /// What signals ask of the run, seen after every step.
    pub requests: Option<&'a Requests>,
}

/// What signals ask of a running run (set by signal handlers, seen after every step, on
/// every process: one asked of any process is done by all at the same step).
#[derive(Debug, Default)]
pub struct Requests {
    /// Stop after the current step with a checkpoint (SIGINT, SIGTERM, SIGHUP, SIGUSR1).
    pub stop: AtomicBool,
    /// Write a checkpoint after the current step and go on (SIGCONT: mpirun and Slurm send
    /// it before SIGTERM, so the checkpoint is on disk before the stop is asked; a stop in
    /// the same step writes no other).
    pub checkpoint: AtomicBool,
}

/// Summary of a finished run.
#[derive(Clone, Debug)]
pub struct Summary {
    pub frames_written: u64,
    pub particles: usize,
    pub steps: u64,
    /// Neighbour-list rebuilds.
    pub rebuilds: u64,
    pub wall_seconds: f64,
    /// Wall time per stage of the step, and for writing frames and checkpoints.
    pub stage_times: StageTimes,
    /// Wall time spent writing frames (with their logs) and checkpoints.
    pub frame_seconds: f64,
    pub checkpoint_seconds: f64,
    /// Pairs that overlapped by more than the smaller radius (warned of, not stopped), and
    /// the likely cause.
    pub warnings: usize,
    pub advice: String,
    /// The `[[spawn]]` regions that made fewer particles than asked, with the likely cause.
    pub spawn_shortfalls: Vec<String>,
    /// Particles removed by the outlets and the domain bounds.
    pub removed: crate::engine::records::Removed,
    /// The condition of `[simulation] until` that ended the run before its last frame, and
    /// the frame it ended at.
    pub ended_by: Option<(Met, u64)>,
}

/// A run stopped on request, with its checkpoint written.
#[derive(Clone, Debug)]
pub struct Interrupted {
    pub step: u64,
    pub time: f64,
    pub checkpoint: PathBuf,
    /// The step the checkpoint is of: `step`, or that of a checkpoint SIGCONT asked for
    /// just before.
    pub checkpoint_step: u64,
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (path, dir) = (
            self.checkpoint.display(),
            self.checkpoint
                .parent()
                .map_or_else(|| ".".into(), |d| d.display().to_string()),
        );
        write!(
            f,
            "interrupted after step {} (t = {:.6e} s); ",
            self.step, self.time
        )?;
        if self.checkpoint_step == self.step {
            write!(f, "checkpoint written to {path}")?;
        } else {
            let step = self.checkpoint_step;
            write!(
                f,
                "the checkpoint of step {step}, written on SIGCONT, is {path}"
            )?;
        }
        write!(f, ": continue with --resume {path} --output {dir}")
    }
}

impl std::error::Error for Interrupted {}

/// Runs `scenario`, writing frames 0..=N_frames into `output_dir`.
pub fn run(scenario: Scenario, output_dir: &Path, options: Options) -> Result<Summary> {
    run_on(scenario, output_dir, options, None)
}

/// Runs `scenario` as [`run`] does, split over the processes of `comm` if it has more
/// than one (each calls it): the first writes the output, all step together.
pub fn run_on(
    scenario: Scenario,
    output_dir: &Path,
    options: Options,
    comm: Option<Box<dyn Comm>>,
) -> Result<Summary> {
    let steps_per_frame = scenario.simulation.steps_per_frame;
    let total_steps = scenario.simulation.frames * steps_per_frame;
    let mut checkpoints = Checkpoints::of(&scenario);
    let (mut sim, notes) = open_on(scenario, &options, comm)?;
    let options = quiet_unless_writer(options, &sim);
    if options.verbosity == Verbosity::Normal
        && let Some(path) = options.from
    {
        eprintln!("stage from {}: {}", path.display(), notes.join("; "));
    }
    if !options.force {
        refuse(&sim, output_dir)?;
    }
    if options.verbosity == Verbosity::Normal {
        for c in crate::driver::check::cautions(&sim.scenario) {
            eprintln!("warning: {c}");
        }
    }
    let _lock = lock_output(&sim, output_dir, &options)?;
    let start = Instant::now();
    let mut record = Record::open(output_dir, &sim, &options, total_steps)?;
    if options.resume.is_none() {
        record.frame(&mut sim, 0)?;
    } else {
        record.resumed(&mut sim);
    }
    while sim.steps < total_steps && record.ended_by.is_none() {
        if let Err(unstable) = sim.step() {
            return Err(unstable_error(
                &unstable,
                output_dir,
                &sim,
                record.out.extra,
            ));
        }
        if sim.steps.is_multiple_of(steps_per_frame) {
            let frame = sim.steps / steps_per_frame;
            record.frame(&mut sim, frame)?;
            checkpoints.after_frame(output_dir, &sim, frame)?;
        }
        checkpoints.timed(output_dir, &sim)?;
        record.status.progress(sim.steps);
        if let Some(keep) = checkpoints.asked(output_dir, &sim, options.requests)? {
            record.status.abandon();
            return Err(stop(output_dir, &sim, record.out.extra, keep)?.into());
        }
    }
    record.finish(output_dir, &sim, (start, checkpoints.seconds))
}

/// `options`, silenced on the processes that do not write.
fn quiet_unless_writer<'a>(options: Options<'a>, sim: &Simulation) -> Options<'a> {
    Options {
        verbosity: if sim.is_writer() {
            options.verbosity
        } else {
            Verbosity::Quiet
        },
        ..options
    }
}

/// The lock on the output directory, held by the writer for the run (collective), with
/// the output of an earlier run cleared or refused first unless resuming.
fn lock_output(sim: &Simulation, output_dir: &Path, options: &Options) -> Result<Option<Lock>> {
    sim.agree(
        sim.is_writer()
            .then(|| -> Result<Lock> {
                let lock = take_output(output_dir)?;
                if options.resume.is_none() {
                    claim_output(output_dir, options.overwrite)?;
                }
                Ok(lock)
            })
            .transpose(),
    )
}

/// What a run writes as it goes (frames, logs, status) and how much of it.
struct Record<'a> {
    out: Frames<'a>,
    logs: Option<Logs>,
    status: Status,
    frames_written: u64,
    /// Wall time spent writing frames and their logs.
    frame_seconds: f64,
    /// The condition of `[simulation] until` that ends the run, and its frame.
    ended_by: Option<(Met, u64)>,
}

impl<'a> Record<'a> {
    /// The record of `sim`'s run into `output_dir` (collective), with the logs continued
    /// after the checkpoint's last complete frame when resuming.
    fn open(
        output_dir: &'a Path,
        sim: &Simulation,
        options: &Options,
        total_steps: u64,
    ) -> Result<Record<'a>> {
        let out = Frames::of(output_dir, sim);
        sim.agree(out.start(sim))?;
        let steps_per_frame = sim.scenario.simulation.steps_per_frame;
        let resumed_at = options.resume.map(|_| sim.steps / steps_per_frame);
        let logs = sim
            .is_writer()
            .then(|| Logs::open(output_dir, &sim.scenario, resumed_at))
            .transpose();
        let logs = sim.agree(logs)?;
        Ok(Record {
            out,
            logs,
            status: Status::new(options.verbosity, total_steps, sim.steps),
            frames_written: 0,
            frame_seconds: 0.0,
            ended_by: None,
        })
    }

    /// Frame `frame`: its files, its lines in the logs and its status line, and whether a
    /// condition of `[simulation] until` ends the run at it (collective).
    fn frame(&mut self, sim: &mut Simulation, frame: u64) -> Result<()> {
        let t = Instant::now();
        let written = self.out.write(frame, sim);
        sim.agree(written)?;
        self.frames_written += 1;
        let th = sim.thermo();
        // Checked from the first frame after a step on.
        let met = (sim.steps > 0)
            .then(|| sim.scenario.simulation.until.met(&sim.frame_state(&th)))
            .flatten();
        let logged = Logs::frame(self.logs.as_mut(), sim, frame, (&th, met.as_ref()));
        sim.agree(logged)?;
        self.frame_seconds += t.elapsed().as_secs_f64();
        self.status.frame(sim, frame, &th);
        self.ended_by = met.map(|m| (m, frame));
        Ok(())
    }

    /// A run resumed at a frame where a condition of `[simulation] until` holds ended
    /// there: it ends again at once (collective).
    fn resumed(&mut self, sim: &mut Simulation) {
        let steps_per_frame = sim.scenario.simulation.steps_per_frame;
        let until = sim.scenario.simulation.until;
        if until.is_empty() || sim.steps == 0 || !sim.steps.is_multiple_of(steps_per_frame) {
            return;
        }
        let th = sim.thermo();
        let met = until.met(&sim.frame_state(&th));
        self.ended_by = met.map(|m| (m, sim.steps / steps_per_frame));
    }

    /// The end of a complete run: its last checkpoint, so that it can be extended or
    /// staged, and its summary.
    /// `clock`: the run's start and the time its checkpoints took so far.
    fn finish(
        self,
        output_dir: &Path,
        sim: &Simulation,
        (start, checkpoint_seconds): (Instant, f64),
    ) -> Result<Summary> {
        self.status.finish();
        let t = Instant::now();
        save_checkpoint(output_dir, sim)?;
        let checkpoint_seconds = checkpoint_seconds + t.elapsed().as_secs_f64();
        if sim.is_writer() {
            let _ = std::fs::remove_file(output_dir.join(INTERRUPTED));
        }
        Ok(Summary {
            frames_written: self.frames_written,
            particles: sim.particle_count(),
            steps: sim.steps,
            rebuilds: sim.rebuilds(),
            wall_seconds: start.elapsed().as_secs_f64(),
            stage_times: sim.stage_times.clone(),
            frame_seconds: self.frame_seconds,
            checkpoint_seconds,
            warnings: sim.warnings().count(),
            advice: sim.advice(),
            spawn_shortfalls: sim.spawn_shortfalls(),
            removed: sim.removed.clone(),
            ended_by: self.ended_by,
        })
    }
}

/// The simulation of `scenario` as [`open`] makes it, split over `comm`'s processes when
/// there are several (an error on any process is the error of all).
fn open_on(
    scenario: Scenario,
    options: &Options,
    comm: Option<Box<dyn Comm>>,
) -> Result<(Simulation, Vec<String>)> {
    let Some(comm) = comm.filter(|c| c.size() > 1) else {
        return open(scenario, options.resume, options.from);
    };
    let fresh = options.resume.is_none() && options.from.is_none();
    if fresh && scenario.particles.is_some() {
        // Each process reads its share of the particle file, none them all.
        if let Some(why) = scenario.spawn_box_outside() {
            anyhow::bail!("{why}");
        }
        let inputs = crate::io::inputs::read_share(&scenario, &*comm);
        let sim = inputs.and_then(|i| Simulation::from_inputs(scenario, i));
        let sim = crate::parallel::decomposition::agree(&*comm, sim)?;
        return Ok((sim.split_shares(comm)?, Vec::new()));
    }
    if let Some(path) = options.resume {
        // Each process reads its share of a checkpoint in parts, none them all.
        if let Some((sim, pending)) = resume_share(&scenario, path, &*comm)? {
            return Ok((sim.split_shares_with(comm, pending)?, Vec::new()));
        }
    }
    let opened = open(scenario, options.resume, options.from);
    let (sim, notes) = crate::parallel::decomposition::agree(&*comm, opened)?;
    Ok((sim.split(comm)?, notes))
}

/// This process's share of the checkpoint at `path` restored, with the springs its
/// particles share with others' (collective; `None` on all if it is one file, which every
/// process reads).
fn resume_share(
    scenario: &Scenario,
    path: &Path,
    comm: &dyn Comm,
) -> Result<Option<(Simulation, Entries)>> {
    let load = || {
        let fresh = Simulation::new(Scenario {
            particles: None,
            ..scenario.clone()
        })?;
        let share = (comm.rank(), comm.size());
        checkpoint::load_share(path, Some(fingerprint(&fresh)), share)
    };
    let loaded = crate::parallel::decomposition::agree(comm, load())?;
    let (some, none) = (comm.any(loaded.is_some()), comm.any(loaded.is_none()));
    let Some(snapshot) = loaded.filter(|_| !none) else {
        anyhow::ensure!(
            !some,
            "the processes found different checkpoints at {}",
            path.display()
        );
        return Ok(None);
    };
    // Every share of one state: the parts each process read hold the same shared state (a
    // part of another run or step among them would not).
    let mine = checkpoint::encode(&checkpoint::shared_part(&snapshot), 0);
    let all = comm.all_gather(mine);
    anyhow::ensure!(
        all.iter().all(|s| *s == all[0]),
        "the parts of {} are not of one state (a part of another run or step among them?)",
        path.display()
    );
    let restored = Simulation::restore_share(scenario.clone(), snapshot);
    crate::parallel::decomposition::agree(comm, restored).map(Some)
}

/// What `tinydem check` would refuse the run for (collective): an error naming it all.
fn refuse(sim: &Simulation, output_dir: &Path) -> Result<()> {
    let n = crate::driver::check::most_particles(&sim.scenario, sim.particle_count());
    // (A resumed run's removals so far count toward until.removed_at_least.)
    let n = n + sim.removed.count() as usize;
    let why = if sim.is_writer() {
        crate::driver::check::refusals(&sim.scenario, n, output_dir)
    } else {
        Vec::new()
    };
    sim.agree(if why.is_empty() {
        Ok(())
    } else {
        Err(Refused(why).into())
    })
}

/// What `tinydem check` refuses a run for, said with the way past it (`--force`): an
/// error of its own type, so that Python raises it as a ValueError.
#[derive(Clone, Debug)]
pub struct Refused(pub Vec<String>);

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}\n(run with --force to run it anyway)",
            self.0.join("\n")
        )
    }
}

impl std::error::Error for Refused {}

/// The error of a run that became unstable, with the state at the failure written to
/// `unstable.csv` (collective).
fn unstable_error(
    unstable: &crate::engine::Unstable,
    output_dir: &Path,
    sim: &Simulation,
    extra: Extra,
) -> anyhow::Error {
    let last = sim.steps.saturating_sub(1) / sim.scenario.simulation.steps_per_frame.max(1);
    let state = sim.particles_in_domain();
    let written = sim.is_writer()
        && crate::io::csv::write_frame_as(output_dir, UNSTABLE, &state, extra).is_ok();
    anyhow::anyhow!(
        "{unstable}.\nThe last complete frame is {}{}.",
        output_dir.join(frame_name(last)).display(),
        if written {
            format!(
                "; the state at the failure is in {}",
                output_dir.join(UNSTABLE).display()
            )
        } else {
            String::new()
        }
    )
}

/// When a run writes its checkpoints: every `checkpoint_every` frames, every
/// `checkpoint_minutes` of wall time, and when a signal asks.
struct Checkpoints {
    every: u64,
    interval: std::time::Duration,
    last: Instant,
    /// The step of the last checkpoint this run wrote.
    at: Option<u64>,
    /// The step and time of the last checkpoint asked by SIGCONT.
    sigcont: Option<(u64, Instant)>,
    /// Wall time spent writing them.
    seconds: f64,
}

impl Checkpoints {
    fn of(s: &Scenario) -> Checkpoints {
        Checkpoints {
            every: s.checkpoint_every,
            interval: std::time::Duration::from_secs_f64(s.checkpoint_minutes * 60.0),
            last: Instant::now(),
            at: None,
            sigcont: None,
            seconds: 0.0,
        }
    }

    /// A checkpoint now, timed.
    fn save(&mut self, dir: &Path, sim: &Simulation) -> Result<()> {
        let t = Instant::now();
        save_checkpoint(dir, sim)?;
        self.seconds += t.elapsed().as_secs_f64();
        (self.last, self.at) = (Instant::now(), Some(sim.steps));
        Ok(())
    }

    /// After frame `frame` was written: `checkpoint_every`.
    fn after_frame(&mut self, dir: &Path, sim: &Simulation, frame: u64) -> Result<()> {
        if self.every > 0 && frame.is_multiple_of(self.every) {
            self.save(dir, sim)?;
        }
        Ok(())
    }

    /// By wall time: the clock of any process decides, every 100 steps (the same steps on
    /// all).
    fn timed(&mut self, dir: &Path, sim: &Simulation) -> Result<()> {
        if !self.interval.is_zero()
            && sim.steps.is_multiple_of(100)
            && sim.any(self.last.elapsed() >= self.interval)
        {
            self.save(dir, sim)?;
        }
        Ok(())
    }

    /// What signals asked (any process asks, all do it; one collective a step for both):
    /// a checkpoint now, written here; a stop, returned with the step of the checkpoint
    /// to keep, if any.
    fn asked(
        &mut self,
        dir: &Path,
        sim: &Simulation,
        requests: Option<&Requests>,
    ) -> Result<Option<Option<u64>>> {
        let asked = |flag: fn(&Requests) -> &AtomicBool| {
            requests.is_some_and(|r| flag(r).swap(false, Ordering::Relaxed))
        };
        let [checkpoint_now, mut stop_now] =
            sim.any_each([asked(|r| &r.checkpoint), asked(|r| &r.stop)]);
        if checkpoint_now && self.at != Some(sim.steps) {
            let t = Instant::now();
            let path = save_pieces(dir, sim)?;
            self.seconds += t.elapsed().as_secs_f64();
            self.at = Some(sim.steps);
            self.sigcont = Some((sim.steps, Instant::now()));
            if sim.is_writer() {
                eprintln!(
                    "SIGCONT: checkpoint of step {} written to {} (a launcher stopping the run sends SIGCONT before SIGTERM)",
                    sim.steps,
                    path.display()
                );
            }
            // A stop asked while it was written (mpirun's SIGTERM follows its SIGCONT)
            // is done now, with this checkpoint.
            stop_now |= sim.any(asked(|r| &r.stop));
        }
        if !stop_now {
            return Ok(None);
        }
        // The checkpoint to keep: one of this step, or one SIGCONT asked for a moment
        // ago (the launcher's warning: its SIGKILL may come before another is written).
        let recent = self
            .sigcont
            .filter(|w: &(u64, Instant)| w.1.elapsed() < SIGCONT_KEEPS);
        let keep = match self.at == Some(sim.steps) {
            true => Some(sim.steps),
            false => sim
                .any(recent.is_some())
                .then(|| self.sigcont.expect("recent").0),
        };
        Ok(Some(keep))
    }
}

/// The simulation of `scenario` from its start, continued from the checkpoint `resume`
/// of an interrupted run of it, or as a stage after the checkpoint `from` of another run
/// (with what the stage carries over from it).
pub fn open(
    scenario: Scenario,
    resume: Option<&Path>,
    from: Option<&Path>,
) -> Result<(Simulation, Vec<String>)> {
    match (resume, from) {
        (Some(path), _) => {
            let fresh = Simulation::new(Scenario {
                particles: None,
                ..scenario.clone()
            })?;
            let snapshot = checkpoint::load(path, Some(fingerprint(&fresh)))?;
            Ok((Simulation::restore(scenario, snapshot)?, Vec::new()))
        }
        (None, Some(path)) => {
            let snapshot = checkpoint::load(path, None)?;
            Simulation::stage(scenario, snapshot)
                .with_context(|| format!("cannot start a stage from {}", path.display()))
        }
        (None, None) => {
            // A fresh run spawns in the default box where a stage would not.
            if let Some(why) = scenario.spawn_box_outside() {
                anyhow::bail!("{why}");
            }
            Ok((Simulation::new(scenario)?, Vec::new()))
        }
    }
}

/// How long after a checkpoint asked by SIGCONT a stop keeps it instead of writing another.
const SIGCONT_KEEPS: std::time::Duration = std::time::Duration::from_secs(10);

/// Stops a run on request (collective): the checkpoint first (unless one of step `keep`
/// is to be kept), said as soon as it is complete (a launcher may send SIGKILL a second after
/// SIGTERM), then the state as a CSV frame. In a split run the first process joins the
/// parts of the checkpoint into the one file after saying it.
fn stop(dir: &Path, sim: &Simulation, extra: Extra, keep: Option<u64>) -> Result<Interrupted> {
    let path = match keep {
        Some(_) => dir.join(CHECKPOINT),
        None => save_pieces(dir, sim)?,
    };
    let stop = Interrupted {
        step: sim.steps,
        time: sim.time,
        checkpoint: path.clone(),
        checkpoint_step: keep.unwrap_or(sim.steps),
    };
    let writer = sim.is_writer();
    if writer {
        eprintln!("{stop}");
    }
    let join = sim.process().is_some() && !super::outputs::in_pieces(sim);
    if writer && join && checkpoint::newer_parts(&path).is_some() {
        let fp = fingerprint(sim);
        let joined =
            checkpoint::load(&path, Some(fp)).and_then(|s| checkpoint::save(&path, &s, fp));
        if let Err(e) = joined {
            eprintln!("warning: {e:#}; its parts hold the checkpoint, and --resume reads them");
        }
    }
    let particles = sim.particles_in_domain();
    let written = if writer {
        crate::io::csv::write_frame_as(dir, INTERRUPTED, &particles, extra).map(|_| ())
    } else {
        Ok(())
    };
    sim.agree(written)?;
    Ok(stop)
}

/// Writes the checkpoint of `sim` into `dir` at once (collective), returning its path: in
/// a split run each process its own part, with no gather (see `checkpoint::parts`).
fn save_pieces(dir: &Path, sim: &Simulation) -> Result<PathBuf> {
    let path = dir.join(CHECKPOINT);
    match sim.process() {
        Some((k, n)) => {
            let piece = sim.snapshot_piece();
            let saved = checkpoint::save_part(&path, k, n, &piece, fingerprint(sim));
            sim.agree(saved)?;
            if sim.is_writer() {
                checkpoint::remove_parts(&path, Some(sim.steps));
            }
        }
        None => write_checkpoint(&path, sim)?,
    }
    Ok(path)
}

/// Writes the checkpoint of `sim` into `dir`, returning its path: one file, or in a split
/// run that writes in pieces (`[output] gather`) its parts, one per process, with no
/// gather (reading the checkpoint joins them; the one file of an earlier step goes).
fn save_checkpoint(dir: &Path, sim: &Simulation) -> Result<PathBuf> {
    if super::outputs::in_pieces(sim) {
        let path = save_pieces(dir, sim)?;
        if sim.is_writer() {
            let _ = std::fs::remove_file(&path);
        }
        return Ok(path);
    }
    let path = dir.join(CHECKPOINT);
    write_checkpoint(&path, sim)?;
    Ok(path)
}

/// Writes the checkpoint of `sim` to `path` (`--resume` continues it exactly, `--from`
/// starts a stage from it). In a split run: collective, one file (as of one process)
/// written by the first.
pub fn write_checkpoint(path: &Path, sim: &Simulation) -> Result<()> {
    let snapshot = sim.snapshot_for_writer()?;
    let saved = snapshot.map_or(Ok(()), |s| checkpoint::save(path, &s, fingerprint(sim)));
    sim.agree(saved)
}

/// The fingerprint of a simulation's scenario and mesh, for checkpoints.
fn fingerprint(sim: &Simulation) -> u64 {
    checkpoint::fingerprint(&sim.scenario, &sim.walls.rest_mesh())
}
