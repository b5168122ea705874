//! Running a scenario: frames written to the output directory, status on stderr.

use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};

use crate::contact::ContactLaw;
use crate::csv::write_frame;
use crate::integrate::Inertia;
use crate::scenario::{MeshSource, Scenario};
use crate::simulation::Simulation;

/// How much to tell the user while running.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verbosity {
    Quiet,
    /// One status line per frame, and a progress bar on a terminal.
    Normal,
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
}

/// Runs `scenario`, writing frames 0..=N_frames into `output_dir`.
pub fn run(scenario: Scenario, output_dir: &Path, verbosity: Verbosity) -> Result<Summary> {
    std::fs::create_dir_all(output_dir)
        .with_context(|| format!("cannot create output directory {}", output_dir.display()))?;
    let probe = output_dir.join(".tinydem-write-test");
    std::fs::write(&probe, b"")
        .with_context(|| format!("output directory {} is not writable", output_dir.display()))?;
    let _ = std::fs::remove_file(&probe);

    let frames = scenario.simulation.frames;
    let steps_per_frame = scenario.simulation.steps_per_frame;
    let mut sim = Simulation::new(scenario)?;
    let start = Instant::now();
    write_frame(output_dir, 0, &sim.particles)?;

    let bar = (verbosity == Verbosity::Normal && std::io::stderr().is_terminal()).then(|| {
        let bar = indicatif::ProgressBar::new(frames * steps_per_frame);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} steps  {per_sec}  ETA {eta}  {msg}",
            )
            .expect("valid template"),
        );
        bar
    });
    let status = |line: String| match &bar {
        Some(bar) => bar.println(line),
        None => eprintln!("{line}"),
    };
    if verbosity == Verbosity::Normal {
        status(format!(
            "frame {:>6}  t = {:.6e} s  particles {}",
            0,
            sim.time,
            sim.particles.len()
        ));
    }

    for frame in 1..=frames {
        for _ in 0..steps_per_frame {
            sim.step();
        }
        write_frame(output_dir, frame, &sim.particles)?;
        if verbosity == Verbosity::Normal {
            status(format!(
                "frame {frame:>6}  t = {:.6e} s  particles {}",
                sim.time,
                sim.particles.len()
            ));
        }
        if let Some(bar) = &bar {
            bar.set_position(frame * steps_per_frame);
        }
    }
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    Ok(Summary {
        frames_written: frames + 1,
        particles: sim.particles.len(),
        steps: sim.steps,
        rebuilds: sim.rebuilds(),
        wall_seconds: start.elapsed().as_secs_f64(),
    })
}

/// The derived quantities `tinydem check` prints.
pub fn describe(s: &Scenario) -> Result<String> {
    let sim = Simulation::new(s.clone())?;
    let g = &s.geometry;
    let m = &s.material;
    let dt = s.simulation.timestep;
    let law = ContactLaw::new(m, dt);
    let m_min = Inertia::mass(g.radius_min, m.density);
    let m_max = Inertia::mass(g.radius_max, m.density);
    // Stiffness of two R_min particles at 10 % relative indentation δ / (2 R*) (Section 2.3).
    let r = g.radius_min;
    let k_10 = law.normal_stiffness(r, r, 0.1 * r);
    let period = std::f64::consts::PI * (0.5 * m_min / k_10).sqrt();
    let max_n = (s.simulation.max_particles as usize).max(sim.particles.len());
    let frame_bytes = 40 + max_n * 14 * 22;
    let mesh = match &g.mesh {
        MeshSource::None => "none".to_string(),
        MeshSource::File(p) => p.display().to_string(),
        MeshSource::Embedded { name, .. } => name.to_string(),
    };
    let default_dt = crate::scenario::default_timestep(g.radius_min, m);
    Ok(format!(
        "scenario is valid\n\
         mesh                   {mesh}: {} faces\n\
         initial particles      {}\n\
         time step              {dt:.6e} s ({:.3} x Eq. 50)\n\
         particle mass          {m_min:.6e} .. {m_max:.6e} kg\n\
         stiffness k_n at 10%   {k_10:.6e} N/m (two R_min particles, delta = 0.1 R_min)\n\
         half contact period    {period:.6e} s = {:.1} time steps\n\
         total simulated time   {:.6} s ({} frames x {} steps)\n\
         output                 {} files, up to {} each, {} in all\n",
        sim.mesh.faces.len(),
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

/// A byte count in kB, MB or GB.
fn human_bytes(b: f64) -> String {
    match b {
        b if b < 1e6 => format!("{:.1} kB", b / 1e3),
        b if b < 1e9 => format!("{:.1} MB", b / 1e6),
        b => format!("{:.2} GB", b / 1e9),
    }
}
