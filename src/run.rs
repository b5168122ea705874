//! Running a scenario: frames and checkpoints written to the output directory, status on
//! stderr, a clean stop on SIGINT/SIGTERM and a loud one when the run becomes unstable.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, Result};

use crate::checkpoint;
use crate::contact::ContactLaw;
use crate::csv::{Extra, frame_name, write_frame};
use crate::integrate::Inertia;
use crate::mesh::Contacts;
use crate::scenario::{Formats, Scenario};
use crate::simulation::{Simulation, StageTimes, Thermo};

/// Name of the checkpoint file in the output directory.
pub const CHECKPOINT: &str = "checkpoint.bin";
/// Name of the frame written when a run is interrupted between frames.
pub const INTERRUPTED: &str = "interrupted.csv";
/// Name of the frame written when a run becomes unstable.
pub const UNSTABLE: &str = "unstable.csv";
/// Name of the log of particles removed by each outlet (`frame,time,outlet,count,mass`).
pub const OUTLETS: &str = "outlets.csv";
/// Name of the log of the loads on each mesh file (`frame,time,mesh,fx,fy,fz,tx,ty,tz`).
pub const WALLS: &str = "walls.csv";
/// Name of the list of frames written (`frame,step,time`).
pub const FRAMES: &str = "frames.csv";
/// Name of the log of the state at each frame (the columns of [`LOG_HEADER`]).
pub const LOG: &str = "log.csv";
/// The columns of `log.csv`: what the status line shows, as LAMMPS's thermo output.
pub const LOG_HEADER: &str = "frame,step,time,particles,kinetic_energy,rotational_energy,\
contacts_per_particle,pair_contacts,wall_contacts,max_overlap,removed";
/// Name of the resolved scenario of the run in its output directory.
pub const RUN_TOML: &str = "run.toml";

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
    /// Set (by a signal handler) to stop after the current step with a checkpoint.
    pub stop: Option<&'a AtomicBool>,
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
    pub removed: crate::simulation::Removed,
}

/// Per-pair warning lines shown during a run; further pairs are only counted.
const WARNING_LINES: usize = 10;

/// A run stopped on request, with its checkpoint written.
#[derive(Clone, Debug)]
pub struct Interrupted {
    pub step: u64,
    pub time: f64,
    pub checkpoint: PathBuf,
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "interrupted after step {} (t = {:.6e} s); checkpoint written to {}: continue with --resume {} --output {}",
            self.step,
            self.time,
            self.checkpoint.display(),
            self.checkpoint.display(),
            self.checkpoint
                .parent()
                .map_or_else(|| ".".into(), |d| d.display().to_string())
        )
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
        if self.formats.vtk && !sim.mesh_moves() {
            crate::vtk::write_mesh(&self.dir.join("mesh.vtu"), &sim.mesh)?;
        }
        Ok(())
    }

    fn write(&self, k: u64, sim: &Simulation) -> Result<()> {
        let particles = sim.particles_in_domain();
        if self.formats.csv {
            write_frame(self.dir, k, &particles, self.extra)?;
        }
        if sim.scenario.contact_network {
            let contacts = sim.contact_network();
            crate::csv::write_contacts(self.dir, &format!("contacts{k:06}.csv"), &contacts)?;
            if self.formats.vtk {
                let name = format!("contacts{k:06}.vtp");
                crate::vtk::write_contacts(&self.dir.join(&name), &particles, &contacts)?;
                let entries: Vec<(f64, String)> = (0..=k)
                    .map(|f| (f as f64 * self.frame_time, format!("contacts{f:06}.vtp")))
                    .collect();
                crate::vtk::write_collection(&self.dir.join("contacts.pvd"), &entries)?;
            }
        }
        if self.formats.vtk {
            let name = format!("particles{k:06}.vtu");
            crate::vtk::write_particles(&self.dir.join(&name), &particles)?;
            let entries: Vec<(f64, String)> = (0..=k)
                .map(|f| (f as f64 * self.frame_time, format!("particles{f:06}.vtu")))
                .collect();
            crate::vtk::write_collection(&self.dir.join("particles.pvd"), &entries)?;
            if sim.mesh_moves() {
                crate::vtk::write_mesh(&self.dir.join(format!("mesh{k:06}.vtu")), &sim.mesh)?;
                let entries: Vec<(f64, String)> = (0..=k)
                    .map(|f| (f as f64 * self.frame_time, format!("mesh{f:06}.vtu")))
                    .collect();
                crate::vtk::write_collection(&self.dir.join("mesh.pvd"), &entries)?;
            }
        }
        Ok(())
    }
}

/// Fails early, before simulating, if the output directory cannot be written, and removes
/// temporary files a killed run may have left.
fn prepare_output(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create output directory {}", dir.display()))?;
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            let name = e.file_name();
            let name = name.to_string_lossy();
            if name.starts_with('.') && name.ends_with(".tmp") {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
    let probe = dir.join(".tinydem-write-test");
    std::fs::write(&probe, b"")
        .with_context(|| format!("output directory {} is not writable", dir.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// The name of the lock file a running run keeps in its output directory.
pub const LOCK: &str = ".tinydem.lock";

/// A run's claim on its output directory: a lock file with its process id, removed when
/// the run ends (a lock whose process is gone, after a kill, is taken over).
struct Lock(PathBuf);

impl Lock {
    fn take(dir: &Path) -> Result<Lock> {
        let path = dir.join(LOCK);
        for _ in 0..2 {
            match std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&path)
            {
                Ok(mut f) => {
                    use std::io::Write;
                    let _ = writeln!(f, "{}", std::process::id());
                    return Ok(Lock(path));
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let pid = std::fs::read_to_string(&path).unwrap_or_default();
                    let pid = pid.trim();
                    let alive = !pid.is_empty() && Path::new("/proc").join(pid).exists();
                    if alive && pid != std::process::id().to_string() {
                        anyhow::bail!(
                            "another tinydem run (process {pid}) is writing into {}: wait for it, or choose another directory with --output",
                            dir.display()
                        );
                    }
                    let _ = std::fs::remove_file(&path); // left by a run that was killed
                }
                Err(e) => {
                    return Err(e).with_context(|| format!("cannot create {}", path.display()));
                }
            }
        }
        anyhow::bail!("cannot take the lock {}", path.display())
    }
}

impl Drop for Lock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// Whether a file name is output a run writes (frames, logs, checkpoints, its scenario).
fn is_run_output(name: &str) -> bool {
    let frame = |prefix: &str| {
        name.strip_prefix(prefix).is_some_and(|rest| {
            let digits = rest.split('.').next().unwrap_or("");
            !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())
        })
    };
    frame("particles")
        || frame("contacts")
        || frame("mesh")
        || [
            RUN_TOML,
            FRAMES,
            LOG,
            OUTLETS,
            WALLS,
            CHECKPOINT,
            INTERRUPTED,
            UNSTABLE,
            "mesh.vtu",
            "particles.pvd",
            "mesh.pvd",
            "contacts.pvd",
        ]
        .contains(&name)
}

/// Refuses a directory holding the output of an earlier run (frames would mix), unless
/// `overwrite`, which removes that output first (and nothing else).
fn claim_output(dir: &Path, overwrite: bool) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    let old: Vec<PathBuf> = entries
        .flatten()
        .filter(|e| is_run_output(&e.file_name().to_string_lossy()))
        .map(|e| e.path())
        .collect();
    if old.is_empty() {
        return Ok(());
    }
    if !overwrite {
        anyhow::bail!(
            "{} holds the output of an earlier run ({} files, e.g. {}): pass --overwrite to replace it, --resume to continue it, or --output another directory",
            dir.display(),
            old.len(),
            old[0].file_name().unwrap_or_default().to_string_lossy()
        );
    }
    for p in old {
        std::fs::remove_file(&p).with_context(|| format!("cannot remove {}", p.display()))?;
    }
    Ok(())
}

/// Runs `scenario`, writing frames 0..=N_frames into `output_dir`.
pub fn run(scenario: Scenario, output_dir: &Path, options: Options) -> Result<Summary> {
    prepare_output(output_dir)?;
    let _lock = Lock::take(output_dir)?;
    if options.resume.is_none() {
        claim_output(output_dir, options.overwrite)?;
    }
    let frames = scenario.simulation.frames;
    let steps_per_frame = scenario.simulation.steps_per_frame;
    let checkpoint_every = scenario.checkpoint_every;
    let mut sim = match options.resume {
        None => match options.from {
            None => Simulation::new(scenario)?,
            Some(path) => {
                let snapshot = checkpoint::load(path, None)?;
                let (sim, notes) = Simulation::stage(scenario, snapshot)
                    .with_context(|| format!("cannot start a stage from {}", path.display()))?;
                if options.verbosity == Verbosity::Normal {
                    eprintln!("stage from {}: {}", path.display(), notes.join("; "));
                }
                sim
            }
        },
        Some(path) => {
            let fresh = Simulation::new(Scenario {
                particles: None,
                ..scenario.clone()
            })?;
            let snapshot = checkpoint::load(path, Some(fingerprint(&fresh)))?;
            Simulation::restore(scenario, snapshot)?
        }
    };
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
    out.start(&sim)?;
    let mut frames_written = 0;
    let mut output_seconds = 0.0;
    // The logs, continued after the checkpoint's last complete frame when resuming.
    let resumed_at = options.resume.map(|_| sim.steps / steps_per_frame);
    let mut outlets = (!sim.scenario.outlets.is_empty())
        .then(|| {
            Log::open(
                output_dir,
                OUTLETS,
                "frame,time,outlet,count,mass",
                resumed_at,
            )
        })
        .transpose()?;
    let mut walls = sim
        .scenario
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
    let mut frame_log = Log::open(output_dir, FRAMES, "frame,step,time", resumed_at)?;
    let mut thermo_log = Log::open(output_dir, LOG, LOG_HEADER, resumed_at)?;
    write_run_toml(output_dir, &sim.scenario)?;
    let mut log = |sim: &mut Simulation, frame: u64| -> Result<Thermo> {
        frame_log.row(&[&frame, &sim.steps, &sim.time])?;
        let th = sim.thermo();
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
        if let Some(log) = &mut outlets {
            for (k, o) in sim.removed.outlets.iter().enumerate() {
                log.row(&[&frame, &sim.time, &k, &o.count, &o.mass])?;
            }
        }
        if let Some(log) = walls.as_mut().filter(|_| frame > 0) {
            // The mean over the steps since the last frame.
            let steps = steps_per_frame as f64;
            for (k, w) in sim.take_wall_loads().iter().enumerate() {
                let (f, t) = (w.f / steps, w.tau / steps);
                log.row(&[&frame, &sim.time, &k, &f.x, &f.y, &f.z, &t.x, &t.y, &t.z])?;
            }
        }
        Ok(th)
    };
    let mut first = None;
    if options.resume.is_none() {
        out.write(0, &sim)?;
        frames_written += 1;
        first = Some(log(&mut sim, 0)?);
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

    while sim.steps < total_steps {
        if let Err(unstable) = sim.step() {
            let last = sim.steps.saturating_sub(1) / steps_per_frame.max(1);
            let written = crate::csv::write_frame_as(
                output_dir,
                UNSTABLE,
                &sim.particles_in_domain(),
                out.extra,
            )
            .is_ok();
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
            out.write(frame, &sim)?;
            let th = log(&mut sim, frame)?;
            frames_written += 1;
            status(&mut sim, frame, &th);
            if checkpoint_every > 0 && frame.is_multiple_of(checkpoint_every) {
                save_checkpoint(output_dir, &sim)?;
            }
            output_seconds += t.elapsed().as_secs_f64();
        }
        if let Some(bar) = bar.as_ref().filter(|_| sim.steps.is_multiple_of(100)) {
            bar.set_position(sim.steps);
        }
        if options.stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            let path = save_checkpoint(output_dir, &sim)?;
            let particles = sim.particles_in_domain();
            crate::csv::write_frame_as(output_dir, INTERRUPTED, &particles, out.extra)?;
            if let Some(bar) = &bar {
                bar.abandon();
            }
            return Err(Interrupted {
                step: sim.steps,
                time: sim.time,
                checkpoint: path,
            }
            .into());
        }
    }
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    // Every run ends with a checkpoint, so that it can be extended or staged.
    let t = Instant::now();
    save_checkpoint(output_dir, &sim)?;
    output_seconds += t.elapsed().as_secs_f64();
    let _ = std::fs::remove_file(output_dir.join(INTERRUPTED));
    Ok(Summary {
        frames_written,
        particles: sim.particles.len(),
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
    let tmp = dir.join(format!(".{RUN_TOML}.tmp"));
    std::fs::write(&tmp, text)
        .and_then(|()| std::fs::rename(&tmp, &path))
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

/// Writes the checkpoint of `sim` into `dir`, returning its path.
fn save_checkpoint(dir: &Path, sim: &Simulation) -> Result<PathBuf> {
    let path = dir.join(CHECKPOINT);
    checkpoint::save(&path, &sim.snapshot(), fingerprint(sim))?;
    Ok(path)
}

/// The fingerprint of a simulation's scenario and mesh, for checkpoints.
fn fingerprint(sim: &Simulation) -> u64 {
    checkpoint::fingerprint(&sim.scenario, &sim.rest_mesh())
}

/// The derived quantities `tinydem check` prints.
pub fn describe(s: &Scenario) -> Result<String> {
    let sim = Simulation::new(s.clone())?;
    let g = &s.geometry;
    let m = &s.material;
    let dt = s.simulation.timestep;
    let law = ContactLaw::new(m, dt);
    let densities = s.materials.iter().map(|m| m.properties.density);
    let m_min = Inertia::mass(
        g.radius_min,
        densities.clone().fold(f64::INFINITY, f64::min),
    );
    let m_max = Inertia::mass(g.radius_max, densities.fold(0.0, f64::max));
    // Stiffness of two R_min particles at 10 % relative indentation δ / (2 R*) (Section 2.3).
    let r = g.radius_min;
    let k_10 = law.normal_stiffness(r, r, 0.1 * r);
    let period = std::f64::consts::PI * (0.5 * m_min / k_10).sqrt();
    let max_n = (s.simulation.max_particles as usize).max(sim.particles.len());
    let frame_bytes = 40 + max_n * 14 * 22;
    let mut meshes = String::new();
    for (k, file) in sim.mesh_files.iter().enumerate() {
        if file.faces.is_empty() && k == 0 {
            meshes += "mesh                   none\n";
            continue;
        }
        let faces = &sim.mesh.faces[file.faces.clone()];
        let surfaces: std::collections::BTreeSet<u32> = faces.iter().map(|f| f.surface).collect();
        let contacts = match file.contacts {
            Contacts::Merged => format!(
                "merged (one per touch of a connected surface; {} {})",
                surfaces.len(),
                if surfaces.len() == 1 {
                    "surface"
                } else {
                    "surfaces"
                }
            ),
            Contacts::PerFace => "per face (the original program's)".to_string(),
        };
        let contacts = if s.materials.len() > 1 {
            format!(
                "{contacts}, material \"{}\"",
                s.materials[file.material as usize].name
            )
        } else {
            contacts
        };
        meshes += &format!(
            "{:<23}{}: {} faces, contacts {contacts}\n",
            if k == 0 {
                "mesh".to_string()
            } else {
                format!("mesh {k}")
            },
            file.name,
            faces.len()
        );
    }
    let mut bounds = String::new();
    if let Some(d) = s.domain {
        bounds += &format!(
            "domain                 {} .. {} (particles leaving it are removed)\n",
            d.min, d.max
        );
        let outside = sim.particles.x.iter().filter(|&&x| !d.contains(x)).count();
        if outside > 0 {
            bounds += &format!(
                "                       warning: {outside} initial particles lie outside it and are removed at the first step\n"
            );
        }
    }
    for (k, o) in s.outlets.iter().enumerate() {
        bounds += &format!(
            "outlet {k:<16}{} .. {} (removes particles entering it; {OUTLETS})\n",
            o.min, o.max
        );
    }
    if s.wall_forces {
        bounds += &format!(
            "wall loads             force and torque on each mesh file, mean per frame ({WALLS})\n"
        );
    }
    let mut materials = String::new();
    if s.materials.len() > 1 || s.materials[0].name != "default" {
        for (k, m) in s.materials.iter().enumerate() {
            let p = &m.properties;
            materials += &format!(
                "{:<23}{k} \"{}\": density {}, E {:e}, nu {}, e_n {}, mu_s {}, mu_r {}, mu_t {}{}\n",
                if k == 0 { "materials" } else { "" },
                m.name,
                num(p.density),
                p.youngs_modulus,
                num(p.poisson_ratio),
                num(p.restitution),
                num(p.friction_sliding),
                num(p.friction_rolling),
                num(p.friction_twisting),
                if p.cohesion > 0.0 {
                    format!(", cohesion {} J/m^3", num(p.cohesion))
                } else {
                    String::new()
                }
            );
        }
        let n = s.materials.len() as u16;
        let mut first = true;
        for a in 0..n {
            for b in a..n {
                let c = s.pair(a, b);
                let how = if a == b {
                    "its own".to_string()
                } else {
                    let given: Vec<&str> = s
                        .interactions
                        .iter()
                        .find(|i| i.materials == (a, b))
                        .map_or_else(Vec::new, |i| {
                            i.coefficients()
                                .iter()
                                .filter(|c| c.2.is_some())
                                .map(|c| c.1)
                                .collect()
                        });
                    match given.len() {
                        0 => "means of the two".to_string(),
                        5 => "[[interactions]]".to_string(),
                        _ => format!("{} from [[interactions]], the rest means", given.join(", ")),
                    }
                };
                materials += &format!(
                    "{:<23}{} - {}: e_n {}, mu_s {}, mu_r {}, mu_t {}, k_c {} ({how})\n",
                    if first { "pairs" } else { "" },
                    s.materials[a as usize].name,
                    s.materials[b as usize].name,
                    num(c.restitution),
                    num(c.friction_sliding),
                    num(c.friction_rolling),
                    num(c.friction_twisting),
                    num(c.cohesion)
                );
                first = false;
            }
        }
    }
    let default_dt = s.eq50_timestep();
    Ok(format!(
        "scenario is valid\n\
         {meshes}\
         {materials}\
         {bounds}\
         initial particles      {}\n\
         time step              {dt:.6e} s ({:.3} x Eq. 50)\n\
         particle mass          {m_min:.6e} .. {m_max:.6e} kg\n\
         stiffness k_n at 10%   {k_10:.6e} N/m (two R_min particles, delta = 0.1 R_min)\n\
         half contact period    {period:.6e} s = {:.1} time steps\n\
         total simulated time   {:.6} s ({} frames x {} steps)\n\
         output                 {} files, up to {} each, {} in all\n",
        sim.particles.len(),
        dt / default_dt,
        period / dt,
        s.total_time(),
        s.simulation.frames,
        s.simulation.steps_per_frame,
        s.simulation.frames + 1,
        human_bytes(frame_bytes as f64),
        human_bytes(frame_bytes as f64 * (s.simulation.frames + 1) as f64),
    ))
}

/// What `tinydem check SCENARIO --from CHECKPOINT` prints: the scenario's derived
/// quantities, then what it changes as a stage after the checkpoint's run and what it
/// carries over.
pub fn describe_stage(s: &Scenario, from: &Path) -> Result<String> {
    let mut out = describe(s)?;
    let snapshot = checkpoint::load(from, None)?;
    let old = snapshot.scenario.clone();
    let steps = snapshot.steps;
    let (_, notes) = Simulation::stage(s.clone(), snapshot)
        .with_context(|| format!("cannot start a stage from {}", from.display()))?;
    out += &format!(
        "stage from             {} (step {steps} of its run); the clock starts at 0\n",
        from.display()
    );
    if old.is_empty() {
        out += "changes                unknown (the checkpoint predates format 3)\n";
    } else {
        let changes = crate::scenario::changes(&old, &s.to_toml());
        if changes.is_empty() {
            out += "changes                none\n";
        }
        for (k, c) in changes.iter().enumerate() {
            out += &format!("{:<23}{c}\n", if k == 0 { "changes" } else { "" });
        }
    }
    for (k, note) in notes.iter().enumerate() {
        out += &format!("{:<23}{note}\n", if k == 0 { "carries" } else { "" });
    }
    Ok(out)
}

/// A coefficient for people: at most 10 significant digits, no trailing zeros.
fn num(x: f64) -> String {
    let s = format!("{:.10e}", x);
    let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
    let value: f64 = format!("{mantissa}e{exp}").parse().unwrap_or(x);
    format!("{value}")
}

/// A byte count in kB, MB or GB.
fn human_bytes(b: f64) -> String {
    match b {
        b if b < 1e6 => format!("{:.1} kB", b / 1e3),
        b if b < 1e9 => format!("{:.1} MB", b / 1e6),
        b => format!("{:.2} GB", b / 1e9),
    }
}
