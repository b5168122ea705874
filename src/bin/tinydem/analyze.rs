//! `tinydem analyze`: a table of measurements of every frame of an output directory, on
//! stdout and optionally as CSV, and one of its columns plotted against time.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;

use tinydem::model::particles::Particles;
use tinydem::scenario::Scenario;
use tinydem::tools::analyze::{
    NoPile, ReposeWindow, angle_of_repose, coordination_number, drum_angle, kinetic_energy,
    mean_height_of_large, packing_fraction,
};

#[derive(Args)]
pub struct AnalyzeArgs {
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
    /// Fit the dynamic angle of repose of the bed in a rotating drum: the inclination of its
    /// free surface in the plane normal to the drum's axis (the drum: the scenario's first
    /// built-in drum, or mesh turning about an axis).
    #[arg(long)]
    drum: bool,
    /// Instead of the table: the load of the grains on each mesh face of every frame with
    /// a contact network (force, pressure, shear stress), as wall_stressNNNNNN.vtu (the mesh
    /// with cell arrays) and .csv beside the frames. Needs [output] contacts = true.
    #[arg(long, conflicts_with = "fields")]
    wall_stress: bool,
    /// Instead of the table: where the energy went, from log.csv's energy ledger ([output]
    /// energy_ledger = true): at the last frame, what holds it and what took it, each with
    /// its share of the energy put in; with --plot, the ledger's columns against time.
    #[arg(long, conflicts_with_all = ["fields", "wall_stress"])]
    energy: bool,
    /// Report the mean height of the particles with at least this radius.
    #[arg(long)]
    large: Option<f64>,
    /// Report the number and mean height of the particles with this tag.
    #[arg(long)]
    tag: Option<u32>,
    /// Also write the table as CSV to this file.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Also plot columns against time, as SVG if the name ends in .svg, else PNG (see
    /// --column).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// The columns to plot, comma-separated (names from the table's header).
    #[arg(long, value_delimiter = ',', default_value = "kinetic_energy")]
    column: Vec<String>,
    #[command(flatten)]
    style: crate::plot::Style,
    #[command(flatten)]
    fields: FieldArgs,
}

/// `--fields` and its options.
#[derive(Args)]
struct FieldArgs {
    /// Instead of the table: coarse-grained density, velocity and stress (contact and
    /// kinetic parts, compression positive) on a grid or in slices, as fieldsNNNNNN.vti and
    /// .csv beside the frames (slices_zNNNNNN.* in slices along z; fields_mean.* and
    /// slices_z_mean.* with --average). Needs the contact networks
    /// ([output] contacts = true).
    #[arg(long)]
    fields: bool,
    /// Between the points [m] (default: the mean diameter).
    #[arg(long, requires = "fields")]
    spacing: Option<f64>,
    /// The coarse-graining function.
    #[arg(long, value_enum, default_value = "gaussian", requires = "fields")]
    kernel: KernelArg,
    /// The kernel's width [m]: the Gaussian's standard deviation (cut at 3 widths; default
    /// the mean radius), or Lucy's reach (default three mean radii).
    #[arg(long, requires = "fields")]
    width: Option<f64>,
    /// Slices along this axis (each spanning the box across it) instead of a grid.
    #[arg(long, value_enum, requires = "fields")]
    slices: Option<AxisArg>,
    /// The frames FROM,TO (default: the last frame).
    #[arg(
        long,
        value_name = "FROM,TO",
        value_delimiter = ',',
        requires = "fields"
    )]
    frames: Option<Vec<u64>>,
    /// One set of fields averaged over the frames.
    #[arg(long, requires = "fields")]
    average: bool,
    /// The box X0,Y0,Z0,X1,Y1,Z1 (default: the domain, else the particles' extent).
    #[arg(
        long,
        value_name = "X0,Y0,Z0,X1,Y1,Z1",
        value_delimiter = ',',
        requires = "fields",
        allow_hyphen_values = true
    )]
    bounds: Option<Vec<f64>>,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum KernelArg {
    Gaussian,
    Lucy,
    /// The grid's cells as bins, as LIGGGHTS's ave/euler (no width).
    Cell,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum AxisArg {
    X,
    Y,
    Z,
}

impl FieldArgs {
    /// The fields of the frames of `dir`, with a line per file written.
    fn execute(&self, dir: &Path, scenario: Option<&Path>) -> Result<()> {
        use tinydem::tools::fields::{Options, Shape, of_directory};
        if self.frames.as_ref().is_some_and(|f| f.len() != 2) {
            anyhow::bail!("--frames takes two frame numbers, FROM,TO");
        }
        if self.bounds.as_ref().is_some_and(|b| b.len() != 6) {
            anyhow::bail!("--bounds takes six numbers, X0,Y0,Z0,X1,Y1,Z1");
        }
        let options = Options {
            spacing: self.spacing,
            shape: Some(match self.kernel {
                KernelArg::Gaussian => Shape::Gaussian,
                KernelArg::Lucy => Shape::Lucy,
                KernelArg::Cell => Shape::Cell,
            }),
            width: self.width,
            slices: self.slices.map(|a| a as usize),
            frames: self.frames.as_ref().map(|f| (f[0], f[1])),
            average: self.average,
            bounds: self.bounds.as_ref().map(|b| {
                (
                    glam::DVec3::new(b[0], b[1], b[2]),
                    glam::DVec3::new(b[3], b[4], b[5]),
                )
            }),
        };
        for (fields, files) in of_directory(dir, scenario, &options)? {
            let g = &fields.grid;
            println!(
                "{} and {}: {} x {} x {} points, {} frame(s)",
                files[0].display(),
                files[1].display(),
                g.counts[0],
                g.counts[1],
                g.counts[2],
                fields.frames
            );
        }
        Ok(())
    }
}

impl AnalyzeArgs {
    /// `--energy`: the ledger's breakdown at the last frame, and its plot.
    fn energy_ledger(self) -> Result<()> {
        let path = self.dir.join("log.csv");
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        let table = tinydem::tools::plot::Table::parse(&text, "log.csv")?;
        println!(
            "{:<22} {:>14} {:>9}",
            "at the last frame", "energy [J]", "of input"
        );
        for s in tinydem::tools::ledger::breakdown(&table)? {
            println!(
                "{:<22} {:>14.6e} {:>8.3}%",
                s.column,
                s.value,
                100.0 * s.share
            );
        }
        if let Some(plot) = &self.plot {
            let y = tinydem::tools::ledger::plotted(&table);
            crate::plot::draw(&table, "time", &y, self.style, plot)?;
        }
        Ok(())
    }

    /// Measures every frame, printing a row each, then writes the CSV and the plot.
    pub fn execute(self) -> Result<()> {
        if self.fields.fields {
            return self.fields.execute(&self.dir, self.scenario.as_deref());
        }
        if self.energy {
            return self.energy_ledger();
        }
        if self.wall_stress {
            let written = tinydem::tools::walls::of_directory(&self.dir, self.scenario.as_deref())?;
            for pair in written.chunks(2) {
                println!("{} and {}", pair[0].display(), pair[1].display());
            }
            return Ok(());
        }
        let repose = self
            .repose
            .then(|| ReposeWindow::of(self.rest_speed, self.window.as_deref()))
            .transpose()?;
        let s = match self
            .scenario
            .or_else(|| tinydem::io::output::run_toml(&self.dir))
        {
            Some(p) => Scenario::load(&p)?,
            None => Scenario::parse("", Path::new("defaults"))?,
        };
        let frames = frames_in(&self.dir)?;
        let drum = self.drum.then(|| drum_of(&s)).transpose()?;
        let table = Table {
            frame_time: s.simulation.steps_per_frame as f64 * s.simulation.timestep,
            densities: s.materials.iter().map(|m| m.properties.density).collect(),
            repose,
            drum,
            large: self.large,
            tag: self.tag,
        };
        let header = table.header();
        println!("{}", aligned(&header));
        let mut rows = Vec::new();
        let mut no_pile = Vec::new();
        let count = frames.len();
        for (k, path) in frames {
            // Clumps as their spheres and bodies (a frame holds a row per body).
            let p = tinydem::io::pieces::load_frame_as_grains(&path, &s)?;
            let row = table.row(k, &p, &mut no_pile);
            println!("{}", aligned(&row));
            rows.push(row.join(","));
        }
        if let (Some(w), Some((k, why))) = (repose, no_pile.last()) {
            eprintln!(
                "note: --repose found no pile in {} of {count} frames (nan), e.g. frame {k}: \
                 {why}. It fits the surface of the grains slower than {} m/s, {} to {} \
                 diameters below the highest, on both sides (--rest-speed, --window)",
                no_pile.len(),
                w.rest_speed,
                w.from,
                w.to
            );
        }
        if let Some(path) = self.csv {
            std::fs::write(
                &path,
                format!("{}\n{}\n", header.join(","), rows.join("\n")),
            )
            .with_context(|| format!("cannot write {}", path.display()))?;
        }
        if let Some(path) = self.plot {
            let text = format!("{}\n{}\n", header.join(","), rows.join("\n"));
            let table = tinydem::tools::plot::Table::parse(&text, "the table")?;
            let y: Vec<&str> = self.column.iter().map(String::as_str).collect();
            crate::plot::draw(&table, "time", &y, self.style, &path)?;
        }
        Ok(())
    }
}

/// The frames `particlesNNNNNN.csv` in `dir` (or their pieces), by number.
fn frames_in(dir: &Path) -> Result<Vec<(u64, PathBuf)>> {
    let mut frames: Vec<(u64, PathBuf)> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read directory {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter_map(|p| {
            let k = tinydem::io::pieces::frame_number(p.file_name()?.to_str()?)?;
            Some((k, dir.join(tinydem::io::csv::frame_name(k))))
        })
        .collect();
    frames.sort();
    anyhow::ensure!(
        !frames.is_empty(),
        "{}: no frames particlesNNNNNN.csv",
        dir.display()
    );
    Ok(frames)
}

/// The values of a row, right-aligned in columns 17 wide, or two more than the longest
/// column name (so that names never run together).
fn aligned<T: std::fmt::Display>(row: &[T]) -> String {
    row.iter().map(|v| format!("{v:>COLUMN$}")).collect()
}

/// The width of a column of the table.
const COLUMN: usize = 22;

/// The drum of a scenario, for `--drum`: its centre, axis and the direction of gravity.
fn drum_of(s: &Scenario) -> Result<(glam::DVec3, glam::DVec3, glam::DVec3)> {
    use tinydem::model::motion::Motion;
    use tinydem::scenario::{MeshInput, Shape};
    let found = s.meshes.iter().find_map(|m| match (&m.input, m.motion) {
        (MeshInput::Shape(Shape::Drum { center, axis, .. }), _) => Some((*center, *axis)),
        (_, Some(Motion::Rotation { center, axis, .. })) => Some((center, axis)),
        _ => None,
    });
    let Some((centre, axis)) = found else {
        anyhow::bail!(
            "--drum: the scenario has no drum (a [[meshes]] shape of type \"drum\", or a mesh \
             with motion = {{ type = \"rotation\", ... }})"
        );
    };
    let g = s.kinetics.gravity;
    let down = if g.length_squared() > 0.0 && g.cross(axis).length_squared() > 0.0 {
        g.normalize()
    } else {
        glam::DVec3::NEG_Z
    };
    Ok((centre, axis, down))
}

/// What the table measures of each frame.
struct Table {
    /// Simulated time between frames.
    frame_time: f64,
    /// The density of each material.
    densities: Vec<f64>,
    repose: Option<ReposeWindow>,
    /// A drum's centre, axis and gravity's direction.
    drum: Option<(glam::DVec3, glam::DVec3, glam::DVec3)>,
    large: Option<f64>,
    tag: Option<u32>,
}

impl Table {
    /// The names of the columns.
    fn header(&self) -> Vec<&'static str> {
        let mut header = vec![
            "frame",
            "time",
            "particles",
            "kinetic_energy",
            "coordination",
            "packing_fraction",
        ];
        if self.repose.is_some() {
            header.extend([
                "repose_left_deg",
                "repose_left_err_deg",
                "repose_right_deg",
                "repose_right_err_deg",
            ]);
        }
        if self.drum.is_some() {
            header.extend(["drum_angle_deg", "drum_angle_err_deg"]);
        }
        if self.large.is_some() {
            header.push("large_mean_height");
        }
        if self.tag.is_some() {
            header.extend(["tagged", "tagged_mean_height"]);
        }
        header
    }

    /// The row of frame `k` with particles `p` (clumps as their spheres and bodies); a
    /// frame with no pile to fit is added to `no_pile` with the reason. A pile of clumps is
    /// fitted on its spheres (its surface, and their diameters for the window); the other
    /// columns count grains (plain spheres and clumps).
    fn row(&self, k: u64, p: &Particles, no_pile: &mut Vec<(u64, NoPile)>) -> Vec<String> {
        let grains = p.len() - p.body.iter().filter(|b| b.is_some()).count() + p.bodies.len();
        let mut row = vec![
            k.to_string(),
            format!("{:.6e}", k as f64 * self.frame_time),
            grains.to_string(),
            format!("{:.6e}", kinetic_energy(p, &self.densities)),
            format!("{:.4}", coordination_number(p)),
            format!("{:.4}", packing_fraction(p, &self.densities)),
        ];
        if let Some(w) = self.repose {
            match angle_of_repose(p, w) {
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
        if let Some((centre, axis, down)) = self.drum {
            match drum_angle(p, centre, axis, down) {
                Ok(a) => row.extend([a.angle, a.error].map(|v| format!("{v:.2}"))),
                Err(_) => row.extend(["nan"; 2].map(String::from)),
            }
        }
        if let Some(r) = self.large {
            row.push(mean_height_of_large(p, r).map_or("nan".into(), |z| format!("{z:.6e}")));
        }
        if let Some(t) = self.tag {
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
        row
    }
}
