//! The outputs of a run but its checkpoints: frames in each format (and the ParaView
//! collections), the CSV logs with a row per frame, and `run.toml`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::engine::records::{ContactRecord, contact_loads};
use crate::engine::{Simulation, Thermo};
use crate::io::csv::{Extra, write_frame_as};
use crate::io::output::{FRAMES, LOG, LOG_HEADER, OUTLETS, RUN_TOML, WALLS};
use crate::io::vtk;
use crate::model::particles::Particles;
use crate::parallel::comm::Reach;
use crate::scenario::{Formats, Gather, Met, Scenario};

/// The rows of a frame's files: the particles `own` (all, or a process's own), among those
/// it `held` (for the partners of their contacts), with the columns `extra` and the `body`
/// array if `bodies`.
struct Rows<'p> {
    own: &'p Particles,
    held: &'p Particles,
    bodies: bool,
    extra: Extra<'static>,
}

/// Writes frames in the scenario's formats, and the ParaView collection.
pub(super) struct Frames<'a> {
    dir: &'a Path,
    formats: Formats,
    /// The CSV frames' columns beyond the fourteen (the loads, with `[output] forces`,
    /// frame by frame).
    pub(super) extra: Extra<'static>,
    /// Simulated time between frames.
    frame_time: f64,
    /// Whether each process of a split run writes its own piece of each frame
    /// (`[output] gather`): `particlesNNNNNN_K.*`, listed by `particlesNNNNNN.pvtu`.
    pieces: bool,
    /// The files each ParaView collection lists so far, frame by frame, by its stem.
    listed: std::cell::RefCell<std::collections::HashMap<String, Vec<String>>>,
}

impl<'a> Frames<'a> {
    /// The frames of `sim` into `dir` (collective in a split run).
    pub(super) fn of(dir: &'a Path, sim: &Simulation) -> Frames<'a> {
        Frames {
            pieces: in_pieces(sim),
            dir,
            formats: sim.scenario.formats,
            extra: Extra {
                tag: sim.has_tags(),
                ids: sim.frames_carry_ids(),
                fixed: sim.has_fixed(),
                clump: !sim.scenario.clumps.is_empty(),
                loads: None,
            },
            frame_time: sim.scenario.simulation.steps_per_frame as f64
                * sim.scenario.simulation.timestep,
            listed: Default::default(),
        }
    }

    /// Files that do not change during the run (the static mesh).
    pub(super) fn start(&self, sim: &Simulation) -> Result<()> {
        if self.formats.vtk && !sim.walls.move_at_all() && sim.is_writer() {
            crate::io::vtk::write_mesh(&self.dir.join("mesh.vtu"), &sim.walls.mesh)?;
        }
        Ok(())
    }

    /// Frame `k` (collective in a split run: all processes gather, the first writes; or
    /// each writes its piece).
    pub(super) fn write(&self, k: u64, sim: &Simulation) -> Result<()> {
        if self.pieces {
            return self.write_pieces(k, sim);
        }
        let particles = sim.particles_in_domain();
        let s = &sim.scenario;
        let contacts =
            (s.contact_network || s.forces).then(|| sim.contact_network_to(Reach::Writer));
        if !sim.is_writer() {
            return Ok(());
        }
        let network = contacts.as_deref().filter(|_| s.forces);
        let contacts = contacts.as_deref().filter(|_| s.contact_network);
        let whole = |stem: &str, ext: &str| format!("{stem}{k:06}.{ext}");
        let rows = Rows {
            own: &particles,
            held: &particles,
            bodies: !particles.bodies.is_empty(),
            extra: self.extra,
        };
        self.files(whole, rows, network, contacts)?;
        if self.formats.vtk {
            if contacts.is_some() {
                self.collection("contacts", k, "vtp")?;
            }
            self.collection("particles", k, "vtu")?;
            self.moving_mesh(k, sim)?;
        }
        Ok(())
    }

    /// Frame `k` of a split run in pieces (collective): each process writes its own
    /// particles (CSV with ids, VTK) and the contacts it owns; once all are on disk, the
    /// first writes the `.pvtu` and `.pvtp` files that list the VTK pieces.
    fn write_pieces(&self, k: u64, sim: &Simulation) -> Result<()> {
        let (rank, size) = sim.process().expect("a split run");
        let (own, held) = sim.own_particles_in_domain();
        let contacts = (sim.scenario.contact_network).then(|| sim.own_contact_network());
        // Every contact of an own particle is among those this process holds (its ghosts are
        // within reach): the loads of its own rows from them.
        let network = sim.scenario.forces.then(|| sim.held_contacts());
        let piece = |stem: &str, ext: &str| format!("{stem}{k:06}_{rank}.{ext}");
        let bodies = self.extra.clump;
        let rows = Rows {
            own: &own,
            held: &held,
            bodies,
            extra: Extra {
                ids: true,
                ..self.extra
            },
        };
        let written = self.files(piece, rows, network.as_deref(), contacts.as_deref());
        // Every piece on disk before a list names it.
        sim.agree(written)?;
        if !sim.is_writer() || !self.formats.vtk {
            return Ok(());
        }
        let pieces = |stem: &str, ext: &str| -> Vec<String> {
            (0..size)
                .map(|q| format!("{stem}{k:06}_{q}.{ext}"))
                .collect()
        };
        let list = self.dir.join(format!("particles{k:06}.pvtu"));
        let forces = sim.scenario.forces;
        let (sources, active) = (pieces("particles", "vtu"), sim.particles.active);
        vtk::write_particle_list(&list, &sources, (bodies, forces), active)?;
        self.collection("particles", k, "pvtu")?;
        if contacts.is_some() {
            let list = self.dir.join(format!("contacts{k:06}.pvtp"));
            vtk::write_contact_list(&list, &pieces("contacts", "vtp"))?;
            self.collection("contacts", k, "pvtp")?;
        }
        self.moving_mesh(k, sim)
    }

    /// The files of one frame or of this process's piece of it, named by `name(stem,
    /// ext)`: the particles of `rows` in each format, with their contact loads from
    /// `network` (`[output] forces`), and the contacts `contacts` (`[output] contacts`).
    fn files(
        &self,
        name: impl Fn(&str, &str) -> String,
        rows: Rows,
        network: Option<&[ContactRecord]>,
        contacts: Option<&[ContactRecord]>,
    ) -> Result<()> {
        // The contact force and torque of each row (clumps whole) and of each sphere.
        let loads = |whole: bool| network.map(|n| contact_loads(rows.held, n, whole));
        let (whole, spheres) = (loads(true), loads(false));
        if self.formats.csv {
            let extra = Extra {
                loads: whole.as_ref(),
                ..rows.extra
            };
            write_frame_as(self.dir, &name("particles", "csv"), rows.own, extra)?;
        }
        if let Some(contacts) = contacts {
            crate::io::csv::write_contacts(self.dir, &name("contacts", "csv"), contacts)?;
            if self.formats.vtk {
                let path = self.dir.join(name("contacts", "vtp"));
                vtk::write_contacts(&path, rows.held, contacts)?;
            }
        }
        if self.formats.vtk {
            let path = self.dir.join(name("particles", "vtu"));
            vtk::write_particle_piece(&path, rows.own, rows.bodies, spheres.as_ref())?;
        }
        Ok(())
    }

    /// The mesh of frame `k`, if it moves, and its collection.
    fn moving_mesh(&self, k: u64, sim: &Simulation) -> Result<()> {
        if sim.walls.move_at_all() {
            vtk::write_mesh(&self.dir.join(format!("mesh{k:06}.vtu")), &sim.walls.mesh)?;
            self.collection("mesh", k, "vtu")?;
        }
        Ok(())
    }

    /// The ParaView collection `stem.pvd` of frames 0 to `k`: frame k's file of extension
    /// `ext`; an earlier frame's listing of pieces if it was written in pieces (a run
    /// resumed on another number of processes may change), else its one file.
    /// Each earlier frame's file is looked for once (those this run did not write).
    fn collection(&self, stem: &str, k: u64, ext: &str) -> Result<()> {
        let one = if stem == "contacts" { "vtp" } else { "vtu" };
        let listing = if stem == "contacts" { "pvtp" } else { "pvtu" };
        let mut listed = self.listed.borrow_mut();
        let files = listed.entry(stem.to_string()).or_default();
        let k = k as usize;
        files.truncate(k);
        for f in files.len()..k {
            let name = |e: &str| format!("{stem}{f:06}.{e}");
            let written_in_pieces = self.dir.join(name(listing)).exists();
            files.push(name(if written_in_pieces { listing } else { one }));
        }
        files.push(format!("{stem}{k:06}.{ext}"));
        let entries: Vec<(f64, String)> = (files.iter().enumerate())
            .map(|(f, file)| (f as f64 * self.frame_time, file.clone()))
            .collect();
        vtk::write_collection(&self.dir.join(format!("{stem}.pvd")), &entries)
    }
}

/// Whether `sim`, a split run, writes its frames and checkpoints in pieces, one per
/// process (`[output] gather`; `auto`: if the run starts with, or may spawn, 10^7
/// particles or more). Collective.
pub(super) fn in_pieces(sim: &Simulation) -> bool {
    let s = &sim.scenario;
    let many = || {
        let most = (sim.particle_count() as u64).max(s.simulation.max_particles);
        most >= Gather::AUTO_LIMIT
    };
    sim.process().is_some()
        && match s.gather {
            Gather::Always => false,
            Gather::Never => true,
            Gather::Auto => many(),
        }
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

impl LogValue for &str {
    fn put(&self, line: &mut String) {
        line.push_str(self);
    }
}

/// The logs of a run: `frames.csv` and `log.csv`, `outlets.csv` and `walls.csv` when the
/// scenario asks for them.
pub(super) struct Logs {
    frames: Log,
    thermo: Log,
    outlets: Option<Log>,
    walls: Option<Log>,
    steps_per_frame: u64,
    /// Whether `log.csv` has the column `until` (the scenario has conditions).
    until: bool,
    /// The mesh files held at a temperature (with heat transfer), whose heat `log.csv` has.
    heated: Vec<usize>,
    /// The thermal step [s], to turn the heat of a frame into a mean power.
    thermal_dt: f64,
}

impl Logs {
    /// The logs of scenario `s` in `dir`, continued after frame `resumed_at` when resuming;
    /// and `run.toml`.
    pub(super) fn open(dir: &Path, s: &Scenario, resumed_at: Option<u64>) -> Result<Logs> {
        let outlets = (!s.outlets.is_empty())
            .then(|| Log::open(dir, OUTLETS, "frame,time,outlet,count,mass", resumed_at))
            .transpose()?;
        let walls = s
            .wall_forces
            .then(|| {
                let heat = if s.heat() { ",heat" } else { "" };
                let header = format!("frame,time,mesh,x,y,z,fx,fy,fz,tx,ty,tz{heat}");
                Log::open(dir, WALLS, &header, resumed_at)
            })
            .transpose()?;
        write_run_toml(dir, s)?;
        let until = !s.simulation.until.is_empty();
        // Each servo's mesh file (`[[meshes]]` #k is file k), in the order of the walls'.
        let mut header = LOG_HEADER.to_string();
        for (k, _) in s
            .meshes
            .iter()
            .enumerate()
            .filter(|(_, m)| m.servo.is_some())
        {
            header += &format!(",mesh{}_position,mesh{}_load", k + 1, k + 1);
        }
        // The temperatures, and the heat into each mesh held at a temperature.
        let heated: Vec<usize> = match s.heat() {
            true => (s.meshes.iter().enumerate())
                .filter(|(_, m)| m.temperature.is_some())
                .map(|(k, _)| k + 1)
                .collect(),
            false => Vec::new(),
        };
        if s.heat() {
            header += ",T_mean,T_min,T_max,heat_content";
            for k in &heated {
                header += &format!(",mesh{k}_heat");
            }
        }
        if s.energy_ledger {
            for c in crate::model::ledger::COLUMNS {
                header += &format!(",{c}");
            }
        }
        if until {
            header += ",until";
        }
        Ok(Logs {
            frames: Log::open(dir, FRAMES, "frame,step,time", resumed_at)?,
            thermo: Log::open(dir, LOG, &header, resumed_at)?,
            outlets,
            walls,
            steps_per_frame: s.simulation.steps_per_frame,
            until,
            heated,
            thermal_dt: s.simulation.timestep * s.simulation.thermal_time_scale,
        })
    }

    /// A frame's lines in the logs, with its state `th` (over all processes) and the
    /// condition of `[simulation] until` that ends the run at it, if one does (collective in
    /// a split run: the first writes, holding the logs).
    pub(super) fn frame(
        logs: Option<&mut Logs>,
        sim: &mut Simulation,
        frame: u64,
        (th, met): (&Thermo, Option<&Met>),
    ) -> Result<()> {
        let (loads, heat) = if frame > 0 {
            (sim.take_wall_loads(), sim.take_wall_heat())
        } else {
            (Vec::new(), Vec::new())
        };
        let Some(logs) = logs else {
            return Ok(());
        };
        logs.frames.row(&[&frame, &sim.steps, &sim.time])?;
        let ended = met.map_or("", |m| m.key);
        let row: [&dyn LogValue; 11] = [
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
        ];
        // Each servo's displacement along its direction and the mean load resisting it
        // since the last frame.
        let servos: Vec<(f64, f64)> = sim
            .walls
            .servo_controls()
            .iter()
            .map(|&(k, control, state)| {
                let load = loads.get(k).map_or(0.0, |w| control.resisting(w.f));
                (state.position, load / logs.steps_per_frame as f64)
            })
            .collect();
        let mut row: Vec<&dyn LogValue> = row.to_vec();
        for (position, load) in &servos {
            row.extend([position as &dyn LogValue, load]);
        }
        // The mean power into each file since the last frame [W].
        let seconds = logs.steps_per_frame as f64 * logs.thermal_dt;
        let watts: Vec<f64> = (0..sim.walls.files.len())
            .map(|k| heat.get(k).map_or(0.0, |q| q / seconds))
            .collect();
        if let Some(t) = &th.heat {
            row.extend([&t.mean as &dyn LogValue, &t.min, &t.max, &t.content]);
            row.extend(logs.heated.iter().map(|&k| &watts[k] as &dyn LogValue));
        }
        let balance = th.energy.map(|b| b.columns());
        if let Some(b) = &balance {
            row.extend(b.iter().map(|v| v as &dyn LogValue));
        }
        if logs.until {
            row.push(&ended);
        }
        logs.thermo.row(&row)?;
        if let Some(log) = &mut logs.outlets {
            for (k, o) in sim.removed.outlets.iter().enumerate() {
                log.row(&[&frame, &sim.time, &k, &o.count, &o.mass])?;
            }
        }
        if frame > 0 {
            logs.wall_loads(sim, frame, &loads, th.heat.is_some().then_some(&watts[..]))?;
        }
        Ok(())
    }

    /// A frame's rows of `walls.csv` (if it is written): each mesh file's mean load over the
    /// steps since the last frame of the sums `loads`, and its heat `watts` with heat.
    fn wall_loads(
        &mut self,
        sim: &Simulation,
        frame: u64,
        loads: &[crate::engine::Wrench],
        watts: Option<&[f64]>,
    ) -> Result<()> {
        let Some(log) = &mut self.walls else {
            return Ok(());
        };
        let steps = self.steps_per_frame as f64;
        for (k, w) in loads.iter().enumerate() {
            let (f, t) = (w.f / steps, w.tau / steps);
            let x = sim.walls.reference(k);
            let mut row: Vec<&dyn LogValue> = vec![
                &frame, &sim.time, &k, &x.x, &x.y, &x.z, &f.x, &f.y, &f.z, &t.x, &t.y, &t.z,
            ];
            if let Some(watts) = watts {
                row.push(&watts[k]);
            }
            log.row(&row)?;
        }
        Ok(())
    }
}
