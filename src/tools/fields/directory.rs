//! Fields of a run's output directory: its frames with their contact networks, the masses
//! from its scenario's materials, written as `fieldsNNNNNN.vti` and `.csv` (or
//! `fields_mean.*` averaged over frames).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use glam::DVec3;

use super::{Fields, Grid, Kernel, Sums};
use crate::io::pieces::{frame_number, load_frame_as_grains, load_network};
use crate::model::integrate::Inertia;
use crate::model::particles::Particles;
use crate::scenario::Scenario;

/// The kernel's shape; its width is `Options::width`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    Gaussian,
    Lucy,
    /// The grid's cells as bins (`Kernel::Cell`).
    Cell,
}

/// What `tinydem analyze --fields` is asked for; `None`s take the defaults.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Between points \[m\] (default: the mean diameter).
    pub spacing: Option<f64>,
    pub shape: Option<Shape>,
    /// Of the Gaussian, its standard deviation (default: the mean radius); of Lucy's, its
    /// reach (default: three mean radii).
    pub width: Option<f64>,
    /// Slices along this axis instead of a grid.
    pub slices: Option<usize>,
    /// These frames, first and last (default: the last frame).
    pub frames: Option<(u64, u64)>,
    /// One set of fields averaged over the frames, instead of one per frame.
    pub average: bool,
    /// The box (default: the scenario's domain, else the particles' extent).
    pub bounds: Option<(DVec3, DVec3)>,
}

/// The fields of the frames of `dir` (of the run of `scenario`, default its `run.toml`),
/// written beside them: each set with the files it went to.
pub fn of_directory(
    dir: &Path,
    scenario: Option<&Path>,
    options: &Options,
) -> Result<Vec<(Fields, [PathBuf; 2])>> {
    let scenario = match scenario
        .map(Path::to_path_buf)
        .or_else(|| crate::io::output::run_toml(dir))
    {
        Some(s) => Scenario::load(&s)?,
        None => bail!(
            "{}: no run.toml: give the run's scenario (--scenario)",
            dir.display()
        ),
    };
    let frames = selected(dir, options.frames)?;
    let read = |k: u64| -> Result<(Particles, Vec<crate::engine::records::ContactRecord>)> {
        let p = load_frame_as_grains(&dir.join(crate::io::csv::frame_name(k)), &scenario)?;
        let name = format!("contacts{k:06}.csv");
        let contacts = load_network(&dir.join(&name)).with_context(|| {
            format!("the contact stress needs the contact network {name}: run with [output] contacts = true")
        })?;
        Ok((p, contacts))
    };
    let first = read(frames[0])?.0;
    let (grid, kernel) = grid_and_kernel(&scenario, &first, options)?;
    let densities: Vec<f64> = scenario
        .materials
        .iter()
        .map(|m| m.properties.density)
        .collect();
    let mut out = Vec::new();
    let mut sums = Sums::new(grid.clone(), kernel);
    for (n, &k) in frames.iter().enumerate() {
        let (p, contacts) = read(k)?;
        let mass = masses(&p, &densities);
        let volume = |i: usize| mass[i] / densities[p.material[i] as usize];
        sums.add_grains(&p, |i| (mass[i], volume(i)), Some(&contacts));
        if !options.average || n + 1 == frames.len() {
            let name = file_name(options, k);
            let fields = sums.fields();
            let files = write(dir, &name, &fields)?;
            out.push((fields, files));
            if !options.average {
                sums = Sums::new(grid.clone(), kernel);
            }
        }
    }
    Ok(out)
}

/// The name (without extension) of the fields of frame `k`: `fieldsNNNNNN` on a grid,
/// `slices_zNNNNNN` in slices along z (so that the slices of a frame do not replace its
/// grid), `fields_mean` and `slices_z_mean` averaged.
pub fn file_name(options: &Options, k: u64) -> String {
    let kind = match options.slices {
        Some(a) => format!("slices_{}", ["x", "y", "z"][a]),
        None => "fields".to_string(),
    };
    match options.average {
        true => format!("{kind}_mean"),
        false => format!("{kind}{k:06}"),
    }
}

/// The mass of each particle: a plain sphere's of its radius and material, a clump's sphere
/// its share of the clump's mass (by the cubes of the radii of its spheres), so that a
/// clump counts once, with the mass of its body.
fn masses(p: &Particles, densities: &[f64]) -> Vec<f64> {
    let mut mass: Vec<f64> = (0..p.len())
        .map(|i| Inertia::mass(p.radius[i], densities[p.material[i] as usize]))
        .collect();
    for (b, body) in p.bodies.list.iter().enumerate() {
        let members = p.bodies.members(b);
        let cubes: f64 = members.iter().map(|&k| p.radius[k as usize].powi(3)).sum();
        for &k in members {
            mass[k as usize] = body.mass * p.radius[k as usize].powi(3) / cubes;
        }
    }
    mass
}

/// The numbers of the frames of `dir` from `range` (inclusive), or its last.
fn selected(dir: &Path, range: Option<(u64, u64)>) -> Result<Vec<u64>> {
    let mut all: Vec<u64> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read {}", dir.display()))?
        .filter_map(|e| frame_number(e.ok()?.file_name().to_str()?))
        .collect();
    all.sort_unstable();
    let picked: Vec<u64> = match range {
        Some((a, b)) => {
            if a > b {
                bail!("--frames {a},{b}: FROM must not be after TO");
            }
            let picked: Vec<u64> = all
                .iter()
                .copied()
                .filter(|k| (a..=b).contains(k))
                .collect();
            // Every frame asked for is there: an average over a frame deleted, or past the
            // run's end, would quietly be over fewer.
            let missing: Vec<u64> = (a..=b)
                .filter(|k| picked.binary_search(k).is_err())
                .collect();
            if !missing.is_empty() && !all.is_empty() {
                let shown: Vec<String> = missing.iter().take(5).map(u64::to_string).collect();
                bail!(
                    "{}: --frames {a},{b} asks for frames it does not hold: {}{} (it has frames \
                     {} to {}{})",
                    dir.display(),
                    shown.join(", "),
                    if missing.len() > 5 {
                        format!(" and {} more", missing.len() - 5)
                    } else {
                        String::new()
                    },
                    all[0],
                    all[all.len() - 1],
                    if all.len() as u64 == all[all.len() - 1] - all[0] + 1 {
                        ""
                    } else {
                        ", with gaps"
                    }
                );
            }
            picked
        }
        None => all.last().copied().into_iter().collect(),
    };
    if picked.is_empty() {
        bail!(
            "{}: no frames particlesNNNNNN.csv{}",
            dir.display(),
            match range {
                Some((a, b)) => format!(" from {a} to {b}"),
                None => String::new(),
            }
        );
    }
    Ok(picked)
}

/// The grid over the box and the kernel of `options`, their defaults from the particles `p`
/// (mean radius) and the scenario's domain (whose periodic axes wrap when the box spans it).
fn grid_and_kernel(s: &Scenario, p: &Particles, options: &Options) -> Result<(Grid, Kernel)> {
    if p.is_empty() {
        bail!("the first frame has no particles");
    }
    let r = p.radius.iter().sum::<f64>() / p.len() as f64;
    if options.shape == Some(Shape::Cell) && options.width.is_some() {
        bail!("--width: cells have no kernel width; --spacing sets their size");
    }
    let width = options.width.unwrap_or(match options.shape {
        Some(Shape::Lucy) => 3.0 * r,
        _ => r,
    });
    let kernel = match options.shape.unwrap_or(Shape::Gaussian) {
        Shape::Gaussian => Kernel::Gaussian { width },
        Shape::Lucy => Kernel::Lucy { width },
        Shape::Cell => Kernel::Cell,
    };
    let (min, max) = match (options.bounds, s.domain) {
        (Some(b), _) => b,
        (None, Some(d)) => (d.min, d.max),
        (None, None) => {
            let lo = (0..p.len()).fold(DVec3::INFINITY, |m, k| m.min(p.x[k] - p.radius[k]));
            let hi = (0..p.len()).fold(DVec3::NEG_INFINITY, |m, k| m.max(p.x[k] + p.radius[k]));
            (lo, hi)
        }
    };
    if !(min.is_finite() && max.is_finite()) {
        bail!("the box {min} .. {max} is not finite");
    }
    if !min.cmplt(max).all() {
        bail!("the box {min} .. {max} is empty");
    }
    let spacing = options.spacing.unwrap_or(2.0 * r);
    if !(spacing > 0.0 && spacing.is_finite()) {
        bail!("--spacing {spacing}: it must be a finite length > 0");
    }
    if !(width > 0.0 && width.is_finite()) {
        bail!("--width {width}: it must be a finite length > 0");
    }
    let side = (max - min).max_element();
    if kernel.cutoff() > side {
        bail!(
            "--width {width}: the kernel reaches {:.3e} m, beyond the box's largest side \
             {side:.3e} m (a field that smooth is the box's mean): give a width below {:.3e} m",
            kernel.cutoff(),
            width * side / kernel.cutoff()
        );
    }
    let wrap: [bool; 3] = std::array::from_fn(|a| {
        s.periodic[a]
            && s.domain
                .is_some_and(|d| d.min[a] == min[a] && d.max[a] == max[a])
    });
    let grid = Grid::over(min, max, spacing, options.slices, wrap);
    if grid.len() > 50_000_000 {
        bail!("{} points: give a coarser --spacing", grid.len());
    }
    Ok((grid, kernel))
}

/// Writes `fields` as `name.vti` and `name.csv` in `dir`.
fn write(dir: &Path, name: &str, fields: &Fields) -> Result<[PathBuf; 2]> {
    let n = fields.grid.len();
    let vti = dir.join(format!("{name}.vti"));
    let tensor = |m: &[glam::DMat3]| -> Vec<f64> {
        m.iter()
            .flat_map(|m| m.transpose().to_cols_array())
            .collect()
    };
    let stress: Vec<glam::DMat3> = (0..n).map(|k| fields.stress(k)).collect();
    let velocity: Vec<f64> = fields.velocity.iter().flat_map(|v| v.to_array()).collect();
    let image = crate::io::vtk::Image {
        origin: fields.grid.point(0),
        spacing: fields.grid.spacing,
        counts: fields.grid.counts,
    };
    let (stress, contact, kinetic) = (
        tensor(&stress),
        tensor(&fields.contact),
        tensor(&fields.kinetic),
    );
    let mut arrays: Vec<(&str, usize, &[f64])> = vec![
        ("density", 1, &fields.density),
        ("volume_fraction", 1, &fields.volume_fraction),
        ("velocity", 3, &velocity),
        ("stress", 9, &stress),
        ("contact_stress", 9, &contact),
        ("kinetic_stress", 9, &kinetic),
    ];
    if let Some(t) = &fields.temperature {
        arrays.push(("temperature", 1, t));
    }
    image.write(&vti, &arrays)?;
    let csv = dir.join(format!("{name}.csv"));
    crate::io::files::write_atomically(&csv, |w| {
        use std::io::Write;
        writeln!(w, "{}", fields.header())?;
        let mut buf = ryu::Buffer::new();
        for k in 0..n {
            let values = fields.row(k);
            let mut line = String::with_capacity(values.len() * 24);
            for (c, v) in values.iter().enumerate() {
                if c > 0 {
                    line.push(',');
                }
                line.push_str(buf.format(*v));
            }
            writeln!(w, "{line}")?;
        }
        Ok(())
    })
    .with_context(|| format!("cannot write {}", csv.display()))?;
    Ok([vti, csv])
}
