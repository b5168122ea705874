//! Running a scenario: frames and checkpoints written to the output directory, status on
//! stderr, a clean stop on SIGINT/SIGTERM and a loud one when the run becomes unstable.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, Result};

use crate::engine::{Simulation, StageTimes, Thermo};
use crate::io::checkpoint;
use crate::io::csv::{Extra, frame_name, write_frame};
use crate::io::lock::Lock;
use crate::io::output::{claim_output, take_output};
use crate::parallel::comm::Comm;
use crate::scenario::{Formats, Scenario};

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
    pub output_seconds: f64,
    /// Pairs that overlapped by more than the smaller radius (warned of, not stopped), and
    /// the likely cause.
    pub warnings: usize,
    pub advice: String,
    /// Particles removed by the outlets and the domain bounds.
    pub removed: crate::engine::records::Removed,
}

/// Per-pair warning lines shown during a run; further pairs are only counted.
const WARNING_LINES: usize = 10;

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

/// Writes frames in the scenario's formats, and the ParaView collection.
struct Frames<'a> {
    dir: &'a Path,
    formats: Formats,
    /// The CSV frames' columns beyond the fourteen.
    extra: Extra,
    /// Simulated time between frames.
    frame_time: f64,
}

impl Frames<'_> {
    /// Files that do not change during the run (the static mesh).
    fn start(&self, sim: &Simulation) -> Result<()> {
        if self.formats.vtk && !sim.mesh_moves() && sim.is_writer() {
            crate::io::vtk::write_mesh(&self.dir.join("mesh.vtu"), &sim.mesh)?;
        }
        Ok(())
    }

    /// Frame `k` (collective in a split run: all processes gather, the first writes).
    fn write(&self, k: u64, sim: &Simulation) -> Result<()> {
        let particles = sim.particles_in_domain();
        let contacts = sim.scenario.contact_network.then(|| sim.contact_network());
        if !sim.is_writer() {
            return Ok(());
        }
        if self.formats.csv {
            write_frame(self.dir, k, &particles, self.extra)?;
        }
        if let Some(contacts) = contacts {
            crate::io::csv::write_contacts(self.dir, &format!("contacts{k:06}.csv"), &contacts)?;
            if self.formats.vtk {
                let name = format!("contacts{k:06}.vtp");
                crate::io::vtk::write_contacts(&self.dir.join(&name), &particles, &contacts)?;
                let entries: Vec<(f64, String)> = (0..=k)
                    .map(|f| (f as f64 * self.frame_time, format!("contacts{f:06}.vtp")))
                    .collect();
                crate::io::vtk::write_collection(&self.dir.join("contacts.pvd"), &entries)?;
            }
        }
        if self.formats.vtk {
            let name = format!("particles{k:06}.vtu");
            crate::io::vtk::write_particles(&self.dir.join(&name), &particles)?;
            let entries: Vec<(f64, String)> = (0..=k)
                .map(|f| (f as f64 * self.frame_time, format!("particles{f:06}.vtu")))
                .collect();
            crate::io::vtk::write_collection(&self.dir.join("particles.pvd"), &entries)?;
            if sim.mesh_moves() {
                crate::io::vtk::write_mesh(&self.dir.join(format!("mesh{k:06}.vtu")), &sim.mesh)?;
                let entries: Vec<(f64, String)> = (0..=k)
                    .map(|f| (f as f64 * self.frame_time, format!("mesh{f:06}.vtu")))
                    .collect();
                crate::io::vtk::write_collection(&self.dir.join("mesh.pvd"), &entries)?;
            }
        }
        Ok(())
    }
}

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
    let frames = scenario.simulation.frames;
    let steps_per_frame = scenario.simulation.steps_per_frame;
    let checkpoint_every = scenario.checkpoint_every;
    let checkpoint_interval =
        std::time::Duration::from_secs_f64(scenario.checkpoint_minutes * 60.0);
    let opened = open(scenario, options.resume, options.from);
    let (mut sim, notes) = match comm.filter(|c| c.size() > 1) {
        Some(comm) => {
            let (sim, notes) = crate::parallel::domain::agree(&*comm, opened)?;
            let split = sim.split(comm);
            (split?, notes)
        }
        None => opened?,
    };
    let writer = sim.is_writer();
    let options = Options {
        verbosity: if writer {
            options.verbosity
        } else {
            Verbosity::Quiet
        },
        ..options
    };
    if options.verbosity == Verbosity::Normal
        && let Some(path) = options.from
    {
        eprintln!("stage from {}: {}", path.display(), notes.join("; "));
    }
    if !options.force {
        let n = crate::driver::check::most_particles(&sim.scenario, sim.particle_count());
        let why = if writer {
            crate::driver::check::refusals(&sim.scenario, n, output_dir)
        } else {
            Vec::new()
        };
        sim.agree(if why.is_empty() {
            Ok(())
        } else {
            Err(anyhow::anyhow!(
                "{}\n(run with --force to run it anyway)",
                why.join("\n")
            ))
        })?;
    }
    let _lock = sim.agree(
        writer
            .then(|| -> Result<Lock> {
                let lock = take_output(output_dir)?;
                if options.resume.is_none() {
                    claim_output(output_dir, options.overwrite)?;
                }
                Ok(lock)
            })
            .transpose(),
    )?;
    let start = Instant::now();
    let out = Frames {
        dir: output_dir,
        formats: sim.scenario.formats,
        extra: Extra {
            tag: sim.has_tags(),
            ids: sim.frames_carry_ids(),
        },
        frame_time: steps_per_frame as f64 * sim.scenario.simulation.timestep,
    };
    sim.agree(out.start(&sim))?;
    let mut frames_written = 0;
    let mut output_seconds = 0.0;
    // The logs, continued after the checkpoint's last complete frame when resuming.
    let resumed_at = options.resume.map(|_| sim.steps / steps_per_frame);
    let s = &sim.scenario;
    let logs = writer
        .then(|| -> Result<_> {
            let outlets = (!s.outlets.is_empty())
                .then(|| {
                    Log::open(
                        output_dir,
                        OUTLETS,
                        "frame,time,outlet,count,mass",
                        resumed_at,
                    )
                })
                .transpose()?;
            let walls = s
                .wall_forces
                .then(|| {
                    Log::open(
                        output_dir,
                        WALLS,
                        "frame,time,mesh,fx,fy,fz,tx,ty,tz",
                        resumed_at,
                    )
                })
                .transpose()?;
            write_run_toml(output_dir, s)?;
            Ok((
                Log::open(output_dir, FRAMES, "frame,step,time", resumed_at)?,
                Log::open(output_dir, LOG, LOG_HEADER, resumed_at)?,
                outlets,
                walls,
            ))
        })
        .transpose();
    let mut logs = sim.agree(logs)?;
    // A frame's lines in the logs (collective in a split run: the state over all
    // processes; the first writes).
    let mut log = |sim: &mut Simulation, frame: u64| -> Result<Thermo> {
        let th = sim.thermo();
        let loads = if frame > 0 {
            sim.take_wall_loads()
        } else {
            Vec::new()
        };
        let Some((frame_log, thermo_log, outlets, walls)) = logs.as_mut() else {
            return Ok(th);
        };
        frame_log.row(&[&frame, &sim.steps, &sim.time])?;
        thermo_log.row(&[
            &frame,
            &sim.steps,
            &sim.time,
            &th.particles,
            &th.kinetic_energy,
            &th.rotational_energy,
            &th.contacts_per_particle(),
            &th.pair_contacts,
            &th.wall_contacts,
            &th.max_overlap,
            &th.removed,
        ])?;
        if let Some(log) = outlets {
            for (k, o) in sim.removed.outlets.iter().enumerate() {
                log.row(&[&frame, &sim.time, &k, &o.count, &o.mass])?;
            }
        }
        if let Some(log) = walls.as_mut().filter(|_| frame > 0) {
            // The mean over the steps since the last frame.
            let steps = steps_per_frame as f64;
            for (k, w) in loads.iter().enumerate() {
                let (f, t) = (w.f / steps, w.tau / steps);
                log.row(&[&frame, &sim.time, &k, &f.x, &f.y, &f.z, &t.x, &t.y, &t.z])?;
            }
        }
        Ok(th)
    };
    let mut first = None;
    if options.resume.is_none() {
        let written = out.write(0, &sim);
        sim.agree(written)?;
        frames_written += 1;
        let logged = log(&mut sim, 0);
        first = Some(sim.agree(logged)?);
    }

    let total_steps = frames * steps_per_frame;
    let bar =
        (options.verbosity == Verbosity::Normal && std::io::stderr().is_terminal()).then(|| {
            let bar = indicatif::ProgressBar::new(total_steps);
            bar.set_style(
                indicatif::ProgressStyle::with_template(
                    "{bar:40} {pos}/{len} steps  {per_sec}  ETA {eta}  {msg}",
                )
                .expect("valid template"),
            );
            bar.set_position(sim.steps);
            bar
        });
    let mut warned = 0;
    let mut status = |sim: &mut Simulation, frame: u64, th: &Thermo| {
        let fresh = sim.take_new_warnings();
        if options.verbosity == Verbosity::Normal {
            let mut lines = Vec::new();
            let removed = match th.removed {
                0 => String::new(),
                n => format!("  removed {n}"),
            };
            for w in fresh {
                warned += 1;
                if warned <= WARNING_LINES {
                    lines.push(format!("warning: {w}"));
                }
                if warned == WARNING_LINES {
                    lines.push("warning: further deep overlaps are only counted".into());
                }
            }
            let deep = match sim.warnings().count() {
                0 => String::new(),
                n => format!("  deep overlaps {n}"),
            };
            lines.push(format!(
                "frame {frame:>6}  t = {:.6e} s  particles {}  E_k {:.4e} J  contacts/particle {:.2}  overlap/R {:.2e}{removed}{deep}",
                sim.time,
                th.particles,
                th.kinetic_energy,
                th.contacts_per_particle(),
                th.max_overlap,
            ));
            for line in lines {
                match &bar {
                    Some(bar) => bar.println(line),
                    None => eprintln!("{line}"),
                }
            }
        }
    };
    if let Some(th) = first {
        status(&mut sim, 0, &th);
    }

    let mut last_checkpoint = Instant::now();
    // The step of the last checkpoint this run wrote.
    let mut checkpointed_at = None;
    // The step and time of the last checkpoint asked by SIGCONT.
    let mut sigcont_checkpoint = None;
    while sim.steps < total_steps {
        if let Err(unstable) = sim.step() {
            let last = sim.steps.saturating_sub(1) / steps_per_frame.max(1);
            let state = sim.particles_in_domain();
            let written = writer
                && crate::io::csv::write_frame_as(output_dir, UNSTABLE, &state, out.extra).is_ok();
            anyhow::bail!(
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
            );
        }
        if sim.steps.is_multiple_of(steps_per_frame) {
            let t = Instant::now();
            let frame = sim.steps / steps_per_frame;
            let written = out.write(frame, &sim);
            sim.agree(written)?;
            let logged = log(&mut sim, frame);
            let th = sim.agree(logged)?;
            frames_written += 1;
            status(&mut sim, frame, &th);
            if checkpoint_every > 0 && frame.is_multiple_of(checkpoint_every) {
                save_checkpoint(output_dir, &sim)?;
                (last_checkpoint, checkpointed_at) = (Instant::now(), Some(sim.steps));
            }
            output_seconds += t.elapsed().as_secs_f64();
        }
        // Checkpoints by wall time: the clock of any process decides, every 100 steps (the
        // same steps on all).
        if !checkpoint_interval.is_zero()
            && sim.steps.is_multiple_of(100)
            && sim.any(last_checkpoint.elapsed() >= checkpoint_interval)
        {
            save_checkpoint(output_dir, &sim)?;
            (last_checkpoint, checkpointed_at) = (Instant::now(), Some(sim.steps));
        }
        if let Some(bar) = bar.as_ref().filter(|_| sim.steps.is_multiple_of(100)) {
            bar.set_position(sim.steps);
        }
        // Asked by signals: a checkpoint now, a stop (any process asks, all do it; one
        // collective a step for both).
        let asked = |flag: fn(&Requests) -> &AtomicBool| {
            options
                .requests
                .is_some_and(|r| flag(r).swap(false, Ordering::Relaxed))
        };
        let [checkpoint_now, mut stop_now] =
            sim.any_each([asked(|r| &r.checkpoint), asked(|r| &r.stop)]);
        if checkpoint_now && checkpointed_at != Some(sim.steps) {
            let path = save_pieces(output_dir, &sim)?;
            checkpointed_at = Some(sim.steps);
            sigcont_checkpoint = Some((sim.steps, Instant::now()));
            if writer {
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
        if stop_now {
            if let Some(bar) = &bar {
                bar.abandon();
            }
            // The checkpoint to keep: one of this step, or one SIGCONT asked for a moment
            // ago (the launcher's warning: its SIGKILL may come before another is written).
            let recent =
                sigcont_checkpoint.filter(|w: &(u64, Instant)| w.1.elapsed() < SIGCONT_KEEPS);
            let keep = match checkpointed_at == Some(sim.steps) {
                true => Some(sim.steps),
                false => sim
                    .any(recent.is_some())
                    .then(|| sigcont_checkpoint.expect("recent").0),
            };
            return Err(stop(output_dir, &sim, out.extra, keep)?.into());
        }
    }
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    // Every run ends with a checkpoint, so that it can be extended or staged.
    let t = Instant::now();
    save_checkpoint(output_dir, &sim)?;
    output_seconds += t.elapsed().as_secs_f64();
    if writer {
        let _ = std::fs::remove_file(output_dir.join(INTERRUPTED));
    }
    Ok(Summary {
        frames_written,
        particles: sim.particle_count(),
        steps: sim.steps,
        rebuilds: sim.rebuilds(),
        wall_seconds: start.elapsed().as_secs_f64(),
        stage_times: sim.stage_times.clone(),
        output_seconds,
        warnings: sim.warnings().count(),
        advice: sim.advice(),
        removed: sim.removed.clone(),
    })
}

/// Writes `run.toml`: the resolved scenario of the run (every default filled in, paths
/// absolute), with the program version and command line, so that the output directory says
/// what made it and `analyze` and `render` need no `--scenario`.
fn write_run_toml(dir: &Path, s: &Scenario) -> Result<()> {
    let command: Vec<String> = std::env::args().collect();
    let text = format!(
        "# The resolved scenario of the run whose output is in this directory: every default\n\
         # filled in, paths absolute. Written by tinydem {}.\n# command: {}\n{}",
        env!("CARGO_PKG_VERSION"),
        command.join(" "),
        s.absolute().to_toml()
    );
    let path = dir.join(RUN_TOML);
    crate::io::files::write_bytes_atomically(&path, text.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))
}

/// A CSV log in the output directory with a row per frame (or several).
struct Log {
    out: std::io::BufWriter<std::fs::File>,
    path: PathBuf,
    line: String,
}

impl Log {
    /// Creates `dir/name` with `header`, or, when resuming after frame `resumed_at`, keeps
    /// the rows of frames up to it (a later checkpoint's rows, or a half-written last line,
    /// are dropped) and continues it.
    fn open(dir: &Path, name: &str, header: &str, resumed_at: Option<u64>) -> Result<Log> {
        let path = dir.join(name);
        let mut text = format!("{header}\n");
        if let Some(last) = resumed_at
            && let Ok(old) = std::fs::read_to_string(&path)
        {
            for line in old.lines().skip(1) {
                let frame = line.split(',').next().and_then(|f| f.parse::<u64>().ok());
                if frame.is_some_and(|f| f <= last)
                    && line.split(',').count() == header.split(',').count()
                {
                    text += line;
                    text.push('\n');
                }
            }
        }
        std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(Log {
            out: std::io::BufWriter::new(file),
            path,
            line: String::new(),
        })
    }

    /// Appends a row (numbers in full precision) and flushes it.
    fn row(&mut self, values: &[&dyn LogValue]) -> Result<()> {
        use std::io::Write;
        self.line.clear();
        for (k, v) in values.iter().enumerate() {
            if k > 0 {
                self.line.push(',');
            }
            v.put(&mut self.line);
        }
        self.line.push('\n');
        self.out
            .write_all(self.line.as_bytes())
            .and_then(|()| self.out.flush())
            .with_context(|| format!("cannot write {}", self.path.display()))
    }
}

/// A value of a log row.
trait LogValue {
    fn put(&self, line: &mut String);
}

impl LogValue for f64 {
    fn put(&self, line: &mut String) {
        line.push_str(ryu::Buffer::new().format(*self));
    }
}

macro_rules! whole_log_values {
    ($($t:ty),*) => {$(
        impl LogValue for $t {
            fn put(&self, line: &mut String) {
                line.push_str(itoa::Buffer::new().format(*self));
            }
        }
    )*};
}
whole_log_values!(u64, usize, i32);

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
        (None, None) => Ok((Simulation::new(scenario)?, Vec::new())),
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
    if writer && sim.process().is_some() && checkpoint::newer_parts(&path).is_some() {
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

/// Writes the checkpoint of `sim` into `dir`, returning its path.
fn save_checkpoint(dir: &Path, sim: &Simulation) -> Result<PathBuf> {
    let path = dir.join(CHECKPOINT);
    write_checkpoint(&path, sim)?;
    Ok(path)
}

/// Writes the checkpoint of `sim` to `path` (`--resume` continues it exactly, `--from`
/// starts a stage from it). In a split run: collective, one file (as of one process)
/// written by the first.
pub fn write_checkpoint(path: &Path, sim: &Simulation) -> Result<()> {
    let snapshot = sim.snapshot()?;
    let saved = if sim.is_writer() {
        checkpoint::save(path, &snapshot, fingerprint(sim))
    } else {
        Ok(())
    };
    sim.agree(saved)
}

/// The fingerprint of a simulation's scenario and mesh, for checkpoints.
fn fingerprint(sim: &Simulation) -> u64 {
    checkpoint::fingerprint(&sim.scenario, &sim.rest_mesh())
}
