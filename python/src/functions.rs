//! The module's functions beside `Simulation`: `run`, `render`, `fields`, `read_csv`.

use std::sync::atomic::Ordering;

use tinydem::driver::run::{Options, Verbosity};

use super::*;

/// Runs a scenario file as `tinydem run` does, writing its output directory (frames,
/// run.toml, frames.csv, log.csv, the checkpoint); returns that directory.
#[pyfunction]
#[pyo3(signature = (scenario, output=None, threads=None, overwrite=false, force=false, resume=None, from_checkpoint=None, quiet=true))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn run(
    py: Python<'_>,
    scenario: PathBuf,
    output: Option<PathBuf>,
    threads: Option<usize>,
    overwrite: bool,
    force: bool,
    resume: Option<PathBuf>,
    from_checkpoint: Option<PathBuf>,
    quiet: bool,
) -> PyResult<PathBuf> {
    let s = Scenario::load(&scenario).map_err(input_error)?;
    let out = output.unwrap_or_else(|| s.output_dir.clone());
    let pool = pool(threads)?;
    let requests = tinydem::driver::run::Requests::default();
    let options = Options {
        verbosity: if quiet {
            Verbosity::Quiet
        } else {
            Verbosity::Normal
        },
        resume: resume.as_deref(),
        from: from_checkpoint.as_deref(),
        overwrite,
        force,
        requests: Some(&requests),
    };
    // The run on a thread of its own; this one watches for Ctrl-C, which stops the run
    // after its current step with a checkpoint (as on the command line).
    let mut interrupt = None;
    let result = std::thread::scope(|scope| {
        let running = scope.spawn(|| pool.install(|| tinydem::driver::run::run(s, &out, options)));
        while !running.is_finished() {
            py.detach(|| std::thread::sleep(std::time::Duration::from_millis(20)));
            if let Err(e) = py.check_signals() {
                requests.stop.store(true, Ordering::Relaxed);
                interrupt.get_or_insert(e);
            }
        }
        running.join()
    });
    let result = match result {
        Ok(result) => result,
        Err(panic) => return Err(panic_error(panic)),
    };
    match (result, interrupt) {
        (Ok(summary), _) => {
            // What the command line warns of at the end of a run.
            for short in &summary.spawn_shortfalls {
                warn(py, short)?;
            }
            if summary.warnings > 0 {
                warn(
                    py,
                    &format!(
                        "{} pairs overlapped by more than the smaller radius at some step (the \
                         run went on: it stops only past the smaller diameter). Likely cause: {}",
                        summary.warnings, summary.advice
                    ),
                )?;
            }
            Ok(out)
        }
        (Err(e), Some(signal)) => {
            // A stop with its checkpoint is said by the run itself.
            if e.downcast_ref::<tinydem::driver::run::Interrupted>()
                .is_none()
            {
                eprintln!("{e:#}");
            }
            Err(signal)
        }
        (Err(e), None) => Err(error(e)),
    }
}

/// Renders a frame `particlesNNNNNN.csv` to a PNG, or every frame of an output directory
/// in one view and colour range (as `tinydem render`); returns a dict with the `pictures`
/// written and the `animation` (GIF, or MP4 with the system's ffmpeg), if any.
///
/// color: "speed", "height", "radius", "tag", "material", "clump" (a colour per clump) or "temperature"; view: "front", "side", "top"
/// or "iso"; range: (lo, hi) of the colour bar; bounds: ((x0, y0, z0), (x1, y1, z1)), the
/// box to show; scenario: whose meshes to draw (default: the directory's run.toml).
#[pyfunction]
#[pyo3(signature = (path, output=None, color="speed", view="iso", width=1600, height=1200, gif=false, movie=false, range=None, bounds=None, scale_bar=false, scenario=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn render<'py>(
    py: Python<'py>,
    path: PathBuf,
    output: Option<PathBuf>,
    color: &str,
    view: &str,
    width: u32,
    height: u32,
    gif: bool,
    movie: bool,
    range: Option<(f64, f64)>,
    bounds: Option<([f64; 3], [f64; 3])>,
    scale_bar: bool,
    scenario: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    use tinydem::tools::render::{Animation, ColorBy, Fixed, Style, View};
    let color = match color {
        "speed" => ColorBy::Speed,
        "height" => ColorBy::Height,
        "radius" => ColorBy::Radius,
        "tag" => ColorBy::Tag,
        "material" => ColorBy::Material,
        "clump" => ColorBy::Clump,
        "temperature" => ColorBy::Temperature,
        other => {
            return Err(PyValueError::new_err(format!(
                "color {other:?}: one of speed, height, radius, tag, material, clump, temperature"
            )));
        }
    };
    let view = match view {
        "front" => View::Front,
        "side" => View::Side,
        "top" => View::Top,
        "iso" => View::Iso,
        other => {
            return Err(PyValueError::new_err(format!(
                "view {other:?}: one of front, side, top, iso"
            )));
        }
    };
    if let Some((lo, hi)) = range
        && !(lo < hi && lo.is_finite() && hi.is_finite())
    {
        return Err(PyValueError::new_err("range (lo, hi) needs lo < hi"));
    }
    let style = Style {
        width,
        height,
        color,
        view,
        scale_bar,
    };
    let fixed = Fixed {
        range,
        bounds: bounds.map(|(a, b)| (DVec3::from_array(a), DVec3::from_array(b))),
    };
    let animation = Animation::of(gif, movie);
    let done = guarded(|| {
        py.detach(|| {
            tinydem::tools::render::render_path(
                &path,
                output.as_deref(),
                scenario.as_deref(),
                &[],
                &style,
                &fixed,
                animation,
            )
        })
        .map_err(error)
    })?;
    let d = PyDict::new(py);
    d.set_item("pictures", done.pictures)?;
    d.set_item("animation", done.animation)?;
    d.set_item("notes", done.notes)?;
    Ok(d)
}

/// Coarse-grained fields of a run's output directory (as `tinydem analyze --fields`):
/// density, velocity and stress (compression positive) with its contact and kinetic parts,
/// on a grid or in slices, each set also written as fieldsNNNNNN.vti and .csv beside the
/// frames (slices_zNNNNNN.* in slices along z, so that they never replace a grid's;
/// fields_mean.* and slices_z_mean.* averaged). Returns a list of dicts of numpy arrays: points (N, 3),
/// counts (3,), density (N,), velocity (N, 3), stress, contact_stress, kinetic_stress
/// (N, 3, 3), frames (how many it averages) and files.
///
/// kernel: "gaussian" or "lucy"; width: the Gaussian's standard deviation or Lucy's reach
/// [m]; slices: "x", "y" or "z"; frames: (first, last), default the last frame; bounds:
/// ((x0, y0, z0), (x1, y1, z1)), default the domain or the particles' extent.
#[pyfunction]
#[pyo3(signature = (directory, scenario=None, spacing=None, kernel="gaussian", width=None, slices=None, frames=None, average=false, bounds=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn fields<'py>(
    py: Python<'py>,
    directory: PathBuf,
    scenario: Option<PathBuf>,
    spacing: Option<f64>,
    kernel: &str,
    width: Option<f64>,
    slices: Option<&str>,
    frames: Option<(u64, u64)>,
    average: bool,
    bounds: Option<([f64; 3], [f64; 3])>,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    use tinydem::tools::fields::{Options, Shape, of_directory};
    let shape = match kernel {
        "gaussian" => Shape::Gaussian,
        "lucy" => Shape::Lucy,
        "cell" => Shape::Cell,
        other => {
            return Err(PyValueError::new_err(format!(
                "kernel {other:?}: \"gaussian\", \"lucy\" or \"cell\""
            )));
        }
    };
    let slices = match slices {
        None => None,
        Some("x") => Some(0),
        Some("y") => Some(1),
        Some("z") => Some(2),
        Some(other) => {
            return Err(PyValueError::new_err(format!(
                "slices {other:?}: \"x\", \"y\" or \"z\""
            )));
        }
    };
    let options = Options {
        spacing,
        shape: Some(shape),
        width,
        slices,
        frames,
        average,
        bounds: bounds.map(|(a, b)| (DVec3::from_array(a), DVec3::from_array(b))),
    };
    let sets = guarded(|| {
        py.detach(|| of_directory(&directory, scenario.as_deref(), &options))
            .map_err(error)
    })?;
    let tensors = |m: &[glam::DMat3]| -> PyResult<_> {
        let flat: Vec<f64> = m
            .iter()
            .flat_map(|m| m.transpose().to_cols_array())
            .collect();
        numpy::ndarray::Array3::from_shape_vec((m.len(), 3, 3), flat)
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))
    };
    let mut out = Vec::new();
    for (f, files) in sets {
        let n = f.grid.len();
        let d = PyDict::new(py);
        let points: Vec<f64> = (0..n).flat_map(|k| f.grid.point(k).to_array()).collect();
        let velocity: Vec<f64> = f.velocity.iter().flat_map(|v| v.to_array()).collect();
        let stress: Vec<glam::DMat3> = (0..n).map(|k| f.stress(k)).collect();
        let shaped = |v: Vec<f64>| Array2::from_shape_vec((n, 3), v).expect("three per point");
        d.set_item("points", shaped(points).into_pyarray(py))?;
        d.set_item(
            "counts",
            Array1::from_vec(f.grid.counts.map(|c| c as i64).to_vec()).into_pyarray(py),
        )?;
        d.set_item(
            "density",
            Array1::from_vec(f.density.clone()).into_pyarray(py),
        )?;
        d.set_item(
            "volume_fraction",
            Array1::from_vec(f.volume_fraction.clone()).into_pyarray(py),
        )?;
        d.set_item("velocity", shaped(velocity).into_pyarray(py))?;
        d.set_item("stress", tensors(&stress)?.into_pyarray(py))?;
        d.set_item("contact_stress", tensors(&f.contact)?.into_pyarray(py))?;
        d.set_item("kinetic_stress", tensors(&f.kinetic)?.into_pyarray(py))?;
        d.set_item("frames", f.frames)?;
        d.set_item("files", files.to_vec())?;
        out.push(d);
    }
    Ok(out)
}

/// Reads a numeric CSV file with a header line (a frame, `log.csv`, `frames.csv`):
/// the column names and the values, row by row, as an (rows, columns) array.
#[pyfunction]
pub(crate) fn read_csv<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(Vec<String>, Bound<'py, PyArray2<f64>>)> {
    let text = tinydem::io::files::read_to_string(&path)
        .map_err(|e| os_error(e.kind(), format!("cannot read {}: {e}", path.display())))?;
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .ok_or_else(|| PyValueError::new_err(format!("{}: empty file", path.display())))?
        .split(',')
        .map(|c| c.trim().to_string())
        .collect();
    let mut values = Vec::new();
    let mut rows = 0;
    for (k, line) in lines.enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let before = values.len();
        for v in line.split(',') {
            values.push(v.trim().parse::<f64>().map_err(|_| {
                PyValueError::new_err(format!(
                    "{} line {}: {v:?} is not a number",
                    path.display(),
                    k + 2
                ))
            })?);
        }
        if values.len() - before != header.len() {
            return Err(PyValueError::new_err(format!(
                "{} line {}: {} values for {} columns",
                path.display(),
                k + 2,
                values.len() - before,
                header.len()
            )));
        }
        rows += 1;
    }
    let array = Array2::from_shape_vec((rows, header.len()), values).expect("checked per row");
    Ok((header, array.into_pyarray(py)))
}
