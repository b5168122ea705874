//! The Python module `tinydem._tinydem`: the engine itself, stepped from Python. Arrays are
//! numpy copies in id order (the order of the frames); `tinydem/__init__.py` adds the
//! readers of output directories on top.

use std::path::PathBuf;
use std::sync::Arc;

use glam::{DQuat, DVec3};
use numpy::ndarray::{Array1, Array2};
use numpy::{
    AllowTypeChange, IntoPyArray, PyArray1, PyArray2, PyArrayLike1, PyArrayLike2, PyArrayLikeDyn,
};
use pyo3::exceptions::{
    PyFileExistsError, PyFileNotFoundError, PyKeyError, PyOSError, PyPermissionError,
    PyRuntimeError, PyRuntimeWarning, PyValueError,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use tinydem::io::csv::Extra;
use tinydem::scenario::Scenario;

/// An error of the engine as a Python exception, with its whole chain of causes: a file
/// not found, there already or not permitted as the OSError of its kind, other failures to
/// read or write as OSError, and the rest as RuntimeError.
fn error(e: anyhow::Error) -> PyErr {
    if e.downcast_ref::<tinydem::driver::run::Refused>().is_some() {
        return PyValueError::new_err(pythonic(&format!("{e:#}")));
    }
    match io_kind(&e) {
        Some(kind) => os_error(kind, pythonic(&format!("{e:#}"))),
        None => PyRuntimeError::new_err(pythonic(&format!("{e:#}"))),
    }
}

/// An error in what the caller gave (a scenario, a file, an argument): the OSError of a
/// file's trouble, else ValueError.
fn input_error(e: anyhow::Error) -> PyErr {
    match io_kind(&e) {
        Some(kind) => os_error(kind, pythonic(&format!("{e:#}"))),
        None => PyValueError::new_err(pythonic(&format!("{e:#}"))),
    }
}

/// The kind of the first io error among the causes of `e`.
fn io_kind(e: &anyhow::Error) -> Option<std::io::ErrorKind> {
    e.chain()
        .find_map(|c| c.downcast_ref::<std::io::Error>())
        .map(std::io::Error::kind)
}

/// The OSError Python raises for an io error of `kind`.
fn os_error(kind: std::io::ErrorKind, message: String) -> PyErr {
    use std::io::ErrorKind::*;
    match kind {
        NotFound => PyFileNotFoundError::new_err(message),
        AlreadyExists => PyFileExistsError::new_err(message),
        PermissionDenied => PyPermissionError::new_err(message),
        _ => PyOSError::new_err(message),
    }
}

/// Says `message` as a Python warning (RuntimeWarning), as the command line says it with
/// `warning:`; an error if the warnings filter turns warnings into errors.
fn warn(py: Python<'_>, message: &str) -> PyResult<()> {
    let text = std::ffi::CString::new(pythonic(message).replace('\0', " "))
        .expect("no NUL left in the message");
    PyErr::warn(py, &py.get_type::<PyRuntimeWarning>(), &text, 1)
}

/// A message of the engine with the command line's options named as Python's arguments.
fn pythonic(message: &str) -> String {
    [
        (
            "pass --overwrite to replace it",
            "pass overwrite=True to replace it",
        ),
        (
            "--resume to continue it",
            "resume=its checkpoint to continue it",
        ),
        ("or --output another directory", "or another output="),
        (
            "(run with --force to run it anyway)",
            "(pass force=True to run it anyway)",
        ),
        ("continue with --resume", "continue with resume="),
        (" --output ", " output="),
    ]
    .iter()
    .fold(message.to_string(), |m, (cli, python)| {
        m.replace(cli, python)
    })
}

/// A thread pool of `threads` workers (None: all cores).
fn pool(threads: Option<usize>) -> PyResult<Arc<rayon::ThreadPool>> {
    if threads == Some(0) {
        return Err(PyValueError::new_err("threads must be at least 1"));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map(Arc::new)
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start the thread pool: {e}")))
}

/// Wall time between checks for Ctrl-C while stepping.
const SIGNAL_CHECK: std::time::Duration = std::time::Duration::from_millis(100);

/// A panic of the engine (a bug) as a RuntimeError, which `except Exception` catches,
/// rather than PyO3's PanicException, which it does not.
fn panic_error(payload: Box<dyn std::any::Any + Send>) -> PyErr {
    let what = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic".to_string());
    PyRuntimeError::new_err(format!(
        "internal error of tinydem (a bug: please report it): {what}"
    ))
}

/// Runs `f`, turning a panic into a RuntimeError.
fn guarded<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f))
        .unwrap_or_else(|p| Err(panic_error(p)))
}

/// A simulation of a scenario file, stepped from Python.
///
/// Simulation(scenario, threads=None, resume=None, from_checkpoint=None, force=False)
///
/// `scenario` is a scenario TOML file (or a `run.toml` of an output directory). `threads`
/// is the number of worker threads (default: all cores; results are the same for any
/// number). `resume` continues an interrupted run of the same scenario from its checkpoint;
/// `from_checkpoint` starts a new stage from another run's checkpoint. A time step `tinydem
/// run` refuses is refused unless `force=True`. Stepping gives bitwise the states of
/// `tinydem run`; once a step has become unstable, later steps raise its diagnosis unless
/// `force=True`.
#[pyclass(module = "tinydem")]
struct Simulation {
    sim: tinydem::engine::Simulation,
    pool: Arc<rayon::ThreadPool>,
    /// The diagnosis of the step that became unstable, if one did.
    unstable: Option<String>,
}

impl Simulation {
    /// The number of components of the optional field `name`, if the particles hold it.
    fn held(&self, name: &str) -> PyResult<usize> {
        let active = self.sim.particles.active;
        let held = active.framed();
        match held.iter().find(|f| f.name == name) {
            Some(f) => Ok(f.suffixes.len()),
            None => Err(PyKeyError::new_err(format!(
                "the particles hold no field '{name}' (they hold: {})",
                match held.is_empty() {
                    true => "none".to_string(),
                    false => held.iter().map(|f| f.name).collect::<Vec<_>>().join(", "),
                }
            ))),
        }
    }

    /// Particle indices in id order.
    fn order(&self) -> Vec<usize> {
        self.sim.particles.id_order()
    }

    /// An (N, 3) array of `field` in id order.
    fn vectors<'py>(
        &self,
        py: Python<'py>,
        field: impl Fn(usize) -> DVec3,
    ) -> Bound<'py, PyArray2<f64>> {
        let order = self.order();
        let flat: Vec<f64> = order.iter().flat_map(|&i| field(i).to_array()).collect();
        Array2::from_shape_vec((order.len(), 3), flat)
            .expect("three per particle")
            .into_pyarray(py)
    }

    /// The rows of an (N, 3) array in id order, checked against the particle count.
    /// The rows of `a` (in id order) for the particles' `now` values (storage order); a
    /// sphere of a clump must keep its value, which the clump's motion sets.
    fn rows(&self, name: &str, a: Vectors, now: &[DVec3]) -> PyResult<Vec<(usize, DVec3)>> {
        let p = &self.sim.particles;
        let v = vectors(name, a, p.len())?;
        let rows: Vec<(usize, DVec3)> = self.order().into_iter().zip(v).collect();
        let moved = |&(i, v): &(usize, DVec3)| p.body[i].is_some() && v != now[i];
        if let Some((k, &(i, _))) = rows.iter().enumerate().find(|(_, r)| moved(r)) {
            return Err(PyValueError::new_err(format!(
                "{name}[{k}]: particle {} is a sphere of the clump {}, which moves as one body: \
                 its spheres' {name} cannot be set (yet)",
                p.id[i],
                p.body[i].expect("a clump's").first()
            )));
        }
        Ok(rows)
    }
}

/// An array-like of numbers (lists, ints, float32 converted to float64).
type Vectors<'py> = PyArrayLike2<'py, f64, AllowTypeChange>;
type Numbers<'py> = PyArrayLike1<'py, f64, AllowTypeChange>;

/// The rows of `a`, an (n, 3) array-like named `name`, finite.
fn vectors(name: &str, a: Vectors, n: usize) -> PyResult<Vec<DVec3>> {
    let a = a.as_array();
    if a.shape() != [n, 3] {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape ({n}, 3), not {:?}",
            a.shape()
        )));
    }
    let rows: Vec<DVec3> = (0..n)
        .map(|k| DVec3::new(a[[k, 0]], a[[k, 1]], a[[k, 2]]))
        .collect();
    if let Some(k) = rows.iter().position(|v| !v.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "{name}[{k}] = {} must be finite",
            rows[k]
        )));
    }
    Ok(rows)
}

#[pymethods]
impl Simulation {
    #[new]
    #[pyo3(signature = (scenario, threads=None, resume=None, from_checkpoint=None, force=false))]
    fn new(
        py: Python<'_>,
        scenario: PathBuf,
        threads: Option<usize>,
        resume: Option<PathBuf>,
        from_checkpoint: Option<PathBuf>,
        force: bool,
    ) -> PyResult<Simulation> {
        if resume.is_some() && from_checkpoint.is_some() {
            return Err(PyValueError::new_err(
                "give resume (the same run) or from_checkpoint (a new stage), not both",
            ));
        }
        let pool = pool(threads)?;
        let s = Scenario::load(&scenario).map_err(input_error)?;
        let (sim, _) = guarded(|| {
            pool.install(|| {
                tinydem::driver::run::open(s, resume.as_deref(), from_checkpoint.as_deref())
            })
            .map_err(input_error)
        })?;
        // What the command line refuses (unless --force) and what it warns of.
        let n = tinydem::driver::check::most_particles(&sim.scenario, sim.particle_count())
            + sim.removed.count() as usize;
        let out = sim.scenario.output_dir.clone();
        let refused = tinydem::driver::check::refusals(&sim.scenario, n, &out);
        if !refused.is_empty() && !force {
            return Err(PyValueError::new_err(format!(
                "{} (pass force=True to run it anyway)",
                refused.join("\n")
            )));
        }
        for why in refused {
            warn(py, &format!("{why} (forced)"))?;
        }
        for caution in tinydem::driver::check::cautions(&sim.scenario) {
            warn(py, &caution)?;
        }
        Ok(Simulation {
            sim,
            pool,
            unstable: None,
        })
    }

    /// Advances the simulation by `n` time steps (the GIL is released meanwhile; Ctrl-C
    /// stops it between steps, seen within 0.1 s). Raises RuntimeError when the run
    /// becomes unstable, and so does every later call, with that diagnosis, unless
    /// `force=True` (the state is as the failing step left it).
    #[pyo3(signature = (n=1, force=false))]
    fn step(&mut self, py: Python<'_>, n: i64, force: bool) -> PyResult<()> {
        let Ok(n) = u64::try_from(n) else {
            return Err(PyValueError::new_err(format!(
                "step({n}): the number of steps must be >= 0"
            )));
        };
        if let Some(why) = self.unstable.as_ref().filter(|_| !force) {
            return Err(PyRuntimeError::new_err(format!(
                "{why}\n(this simulation became unstable then; its state is as that step left it: step(force=True) steps on anyway)"
            )));
        }
        let mut left = n;
        while left > 0 {
            let (sim, pool) = (&mut self.sim, &self.pool);
            let done = guarded(|| {
                Ok(py
                    .detach(|| {
                        pool.install(|| {
                            let start = std::time::Instant::now();
                            let mut done = 0;
                            while done < left && (done == 0 || start.elapsed() < SIGNAL_CHECK) {
                                sim.step()?;
                                done += 1;
                            }
                            Ok::<u64, tinydem::engine::Unstable>(done)
                        })
                    })
                    .map_err(|e| e.to_string()))
            });
            let done = match done {
                Ok(Ok(done)) => done,
                Ok(Err(why)) => {
                    self.unstable.get_or_insert(why.clone());
                    return Err(PyRuntimeError::new_err(why));
                }
                Err(e) => return Err(e),
            };
            left -= done;
            // What the command line warns of: overlaps past the smaller radius.
            for said in self.sim.take_new_warnings() {
                warn(
                    py,
                    &format!(
                        "{said} (the run goes on: it stops only past the smaller diameter). \
                         Likely cause: {}",
                        self.sim.advice()
                    ),
                )?;
            }
            py.check_signals()?;
        }
        Ok(())
    }

    /// Simulated time [s].
    #[getter]
    fn time(&self) -> f64 {
        self.sim.time
    }

    /// Time steps taken.
    #[getter]
    fn steps(&self) -> u64 {
        self.sim.steps
    }

    /// The time step Δt [s].
    #[getter]
    fn timestep(&self) -> f64 {
        self.sim.scenario.simulation.timestep
    }

    /// Number of particles.
    fn __len__(&self) -> usize {
        self.sim.particles.len()
    }

    /// Particle centres [m], (N, 3), in id order.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.vectors(py, |i| self.sim.particles.x[i])
    }

    /// Sets the centres (any (N, 3) array-like of numbers); the neighbour lists are made
    /// anew at the next step.
    #[setter]
    fn set_positions(&mut self, x: Vectors) -> PyResult<()> {
        for (i, x) in self.rows("positions", x, &self.sim.particles.x)? {
            self.sim.particles.x[i] = x;
        }
        self.sim.particles_moved();
        Ok(())
    }

    /// Adds a clump of the scenario's `[[clumps]]` template `clump` (its name or index)
    /// with its centre of mass at `position` [m], `orientation` (q0, q1, q2, q3) (default
    /// unrotated: the template's principal axes along x, y, z), `velocity`,
    /// `angular_velocity` and lengths scaled by `scale`; returns the body's id (that of its
    /// first sphere; its spheres have the next ids). A clump that would overlap a particle
    /// or a mesh face by more than a tenth of the smaller radius is refused (ValueError)
    /// unless `allow_overlap=True`.
    #[pyo3(signature = (clump, position, orientation=None, velocity=None, angular_velocity=None, scale=1.0, allow_overlap=false))]
    #[allow(clippy::too_many_arguments)] // Python's keyword arguments
    fn add_clump(
        &mut self,
        clump: &Bound<'_, PyAny>,
        position: [f64; 3],
        orientation: Option<[f64; 4]>,
        velocity: Option<[f64; 3]>,
        angular_velocity: Option<[f64; 3]>,
        scale: f64,
        allow_overlap: bool,
    ) -> PyResult<i64> {
        let templates = &self.sim.scenario.clumps;
        let template = match clump.extract::<usize>() {
            Ok(k) => k,
            Err(_) => {
                let name: String = clump.extract()?;
                (templates.iter().position(|t| t.name == name)).ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "clump: no [[clumps]] template is named {name:?}"
                    ))
                })?
            }
        };
        let [w, x, y, z] = orientation.unwrap_or([1.0, 0.0, 0.0, 0.0]);
        let motion = (
            DVec3::from_array(position),
            DQuat::from_xyzw(x, y, z, w),
            DVec3::from_array(velocity.unwrap_or_default()),
            DVec3::from_array(angular_velocity.unwrap_or_default()),
        );
        let id = (self
            .sim
            .add_clump(template, scale, motion, overlap(allow_overlap)))
        .map_err(|e| PyValueError::new_err(format!("{e:#}")))?;
        Ok(id as i64)
    }

    /// The body each particle is a sphere of (its id: that of its first sphere), -1 for a
    /// plain sphere, (N,), in id order.
    #[getter]
    fn bodies<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let p = &self.sim.particles;
        let body = |i: usize| p.body[i].map_or(-1, |b| b.first() as i64);
        Array1::from_iter(self.order().into_iter().map(body)).into_pyarray(py)
    }

    /// Adds particles at `positions` (N, 3) with `radii` (N,) [m], `velocities` and
    /// `angular_velocities` (default zero), `material` (an index of the scenario's
    /// materials) and `tag`; returns their ids (the next ones). Array-likes of numbers.
    /// Radii must lie within the scenario's [geometry] radius_min..radius_max, and a
    /// particle that would overlap another (new or present) or a mesh face by more than a
    /// tenth of the smaller radius is refused (ValueError) unless `allow_overlap=True`.
    #[pyo3(signature = (positions, radii, velocities=None, angular_velocities=None, material=0, tag=0, allow_overlap=false))]
    #[allow(clippy::too_many_arguments)] // Python's keyword arguments
    fn add<'py>(
        &mut self,
        py: Python<'py>,
        positions: Vectors,
        radii: Numbers,
        velocities: Option<Vectors>,
        angular_velocities: Option<Vectors>,
        material: u16,
        tag: u32,
        allow_overlap: bool,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let r = radii.as_array().to_vec();
        let n = r.len();
        let x = vectors("positions", positions, n)?;
        let zero = vec![DVec3::ZERO; n];
        let v = velocities.map_or(Ok(zero.clone()), |v| vectors("velocities", v, n))?;
        let w = angular_velocities.map_or(Ok(zero), |w| vectors("angular_velocities", w, n))?;
        if let Some(k) = r.iter().position(|&r| !(r > 0.0 && r.is_finite())) {
            return Err(PyValueError::new_err(format!(
                "radii[{k}] = {} must be a finite number > 0",
                r[k]
            )));
        }
        let new: Vec<tinydem::model::particles::Particle> = (0..n)
            .map(|k| tinydem::model::particles::Particle {
                x: x[k],
                radius: r[k],
                v: v[k],
                w: w[k],
                tag,
                material,
                ..Default::default()
            })
            .collect();
        let ids = self
            .sim
            .add_particles(&new, overlap(allow_overlap))
            .map_err(|e| PyValueError::new_err(format!("{e:#}")))?;
        Ok(Array1::from_iter(ids.into_iter().map(|id| id as i64)).into_pyarray(py))
    }

    /// Removes the particles of `ids` (an array-like of ids), with the springs of their
    /// contacts; not counted as removed by an outlet.
    fn remove(&mut self, ids: PyArrayLike1<'_, i64, AllowTypeChange>) -> PyResult<()> {
        let ids = ids_of(ids)?;
        self.sim
            .remove_particles(&ids)
            .map_err(|e| PyValueError::new_err(format!("ids: {e:#}")))
    }

    /// Fixes the particles of `ids` (an array-like of ids): from the next step they stay
    /// where they are, at rest, whatever acts on them (as particles in a `[[fixed]]` box).
    /// A sphere of a clump freezes its clump whole.
    fn freeze(&mut self, ids: PyArrayLike1<'_, i64, AllowTypeChange>) -> PyResult<()> {
        let ids = ids_of(ids)?;
        self.sim
            .fix_particles(&ids, true)
            .map_err(|e| PyValueError::new_err(format!("ids: {e:#}")))
    }

    /// Lets the particles of `ids` move again (from rest); a sphere of a clump, its clump.
    fn unfreeze(&mut self, ids: PyArrayLike1<'_, i64, AllowTypeChange>) -> PyResult<()> {
        let ids = ids_of(ids)?;
        self.sim
            .fix_particles(&ids, false)
            .map_err(|e| PyValueError::new_err(format!("ids: {e:#}")))
    }

    /// Whether each particle is fixed, (N,) booleans, in id order.
    #[getter]
    fn fixed<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        let p = &self.sim.particles;
        Array1::from_iter(self.order().into_iter().map(|i| p.fixed[i])).into_pyarray(py)
    }

    /// Velocities [m/s], (N, 3), in id order.
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.vectors(py, |i| self.sim.particles.v[i])
    }

    #[setter]
    fn set_velocities(&mut self, v: Vectors) -> PyResult<()> {
        for (i, v) in self.rows("velocities", v, &self.sim.particles.v)? {
            self.sim.particles.v[i] = v;
        }
        Ok(())
    }

    /// Angular velocities [rad/s], (N, 3), in id order.
    #[getter]
    fn angular_velocities<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.vectors(py, |i| self.sim.particles.w[i])
    }

    #[setter]
    fn set_angular_velocities(&mut self, w: Vectors) -> PyResult<()> {
        for (i, w) in self.rows("angular_velocities", w, &self.sim.particles.w)? {
            self.sim.particles.w[i] = w;
        }
        Ok(())
    }

    /// Orientations as unit quaternions (q0, q1, q2, q3) = (w, x, y, z), (N, 4), id order.
    #[getter]
    fn orientations<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let order = self.order();
        let q: &[DQuat] = &self.sim.particles.q;
        let flat: Vec<f64> = order
            .iter()
            .flat_map(|&i| [q[i].w, q[i].x, q[i].y, q[i].z])
            .collect();
        Array2::from_shape_vec((order.len(), 4), flat)
            .expect("four per particle")
            .into_pyarray(py)
    }

    /// Radii [m], (N,), in id order.
    #[getter]
    fn radii<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let p = &self.sim.particles;
        Array1::from_iter(self.order().into_iter().map(|i| p.radius[i])).into_pyarray(py)
    }

    /// Particle ids, (N,), ascending: the order of every array.
    #[getter]
    fn ids<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let p = &self.sim.particles;
        Array1::from_iter(self.order().into_iter().map(|i| p.id[i] as i64)).into_pyarray(py)
    }

    /// Tags, (N,), in id order.
    #[getter]
    fn tags<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let p = &self.sim.particles;
        Array1::from_iter(self.order().into_iter().map(|i| p.tag[i] as i64)).into_pyarray(py)
    }

    /// The names of the optional per-particle fields the particles hold (those a feature
    /// of the scenario asked for, or a column of the particle file brought).
    #[getter]
    fn fields(&self) -> Vec<&'static str> {
        let active = self.sim.particles.active;
        active.framed().into_iter().map(|f| f.name).collect()
    }

    /// The optional per-particle field `name` (see `fields`) in id order: (N,) for a
    /// scalar, (N, k) for k components.
    fn field<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let (p, k) = (&self.sim.particles, self.held(name)?);
        let mut numbers = Vec::with_capacity(k * p.len());
        self.order()
            .into_iter()
            .for_each(|i| p.numbers(name, i, &mut numbers));
        Ok(match k {
            1 => Array1::from_vec(numbers).into_pyarray(py).into_any(),
            _ => Array2::from_shape_vec((numbers.len() / k, k), numbers)
                .expect("k per particle")
                .into_pyarray(py)
                .into_any(),
        })
    }

    /// Sets the optional per-particle field `name` (see `fields`) from `values`, in id
    /// order: (N,) for a scalar, (N, k) for k components.
    fn set_field(
        &mut self,
        name: &str,
        values: PyArrayLikeDyn<'_, f64, AllowTypeChange>,
    ) -> PyResult<()> {
        let k = self.held(name)?;
        let a = values.as_array();
        let n = self.sim.particles.len();
        let shape = a.shape().to_vec();
        let fits = match k {
            1 => shape == [n] || shape == [n, 1],
            _ => shape == [n, k],
        };
        if !fits {
            return Err(PyValueError::new_err(format!(
                "{name}: expected an array of shape ({n}{}), found one of shape {shape:?}",
                if k == 1 {
                    String::new()
                } else {
                    format!(", {k}")
                }
            )));
        }
        let flat: Vec<f64> = a.iter().copied().collect();
        for (row, i) in self.order().into_iter().enumerate() {
            let value = &flat[row * k..(row + 1) * k];
            if !self.sim.particles.set_numbers(name, i, value) {
                return Err(PyValueError::new_err(format!(
                    "{name}[{row}] = {value:?} is not a valid {name}"
                )));
            }
        }
        Ok(())
    }

    /// Material indices (into the scenario's [[materials]]), (N,), in id order.
    #[getter]
    fn materials<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let p = &self.sim.particles;
        Array1::from_iter(self.order().into_iter().map(|i| p.material[i] as i64)).into_pyarray(py)
    }

    /// What `log.csv` records of the current state: particles, kinetic_energy and
    /// rotational_energy [J], contacts_per_particle, pair_contacts, wall_contacts,
    /// max_overlap (relative to the smaller radius), removed.
    fn thermo<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let th = self.sim.thermo();
        let d = PyDict::new(py);
        d.set_item("particles", th.particles)?;
        d.set_item("kinetic_energy", th.kinetic_energy)?;
        d.set_item("rotational_energy", th.rotational_energy)?;
        d.set_item("contacts_per_particle", th.contacts_per_particle())?;
        d.set_item("pair_contacts", th.pair_contacts)?;
        d.set_item("wall_contacts", th.wall_contacts)?;
        d.set_item("max_overlap", th.max_overlap)?;
        d.set_item("removed", th.removed)?;
        Ok(d)
    }

    /// Writes the particles as a CSV frame (the format of `particlesNNNNNN.csv`, the same
    /// columns as the run's frames).
    fn write_frame(&self, path: PathBuf) -> PyResult<()> {
        let extra = Extra {
            tag: self.sim.has_tags(),
            ids: self.sim.frames_carry_ids(),
            fixed: self.sim.has_fixed(),
            clump: !self.sim.scenario.clumps.is_empty(),
            loads: None,
        };
        let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
        let name = path
            .file_name()
            .ok_or_else(|| PyValueError::new_err("write_frame needs a file name"))?;
        guarded(|| {
            tinydem::io::csv::write_frame_as(
                dir.unwrap_or(std::path::Path::new(".")),
                &name.to_string_lossy(),
                &self.sim.particles_in_domain(),
                extra,
            )
            .map(|_| ())
            .map_err(error)
        })
    }

    /// Writes a checkpoint: `tinydem run --resume` (or `Simulation(..., resume=path)`)
    /// continues it exactly; `--from` starts a new stage from it.
    fn checkpoint(&self, path: PathBuf) -> PyResult<()> {
        guarded(|| tinydem::driver::run::write_checkpoint(&path, &self.sim).map_err(error))
    }

    fn __repr__(&self) -> String {
        format!(
            "<tinydem.Simulation: {} particles, step {}, t = {:.6e} s>",
            self.sim.particles.len(),
            self.sim.steps,
            self.sim.time
        )
    }
}

/// Panics inside the engine's guard: for the test that a panic reaches Python as a
/// RuntimeError.
#[pyfunction]
fn _internal_panic() -> PyResult<()> {
    guarded(|| panic!("the test's own panic"))
}

mod functions;
use functions::{fields, read_csv, render, run};

#[pymodule]
fn _tinydem(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Simulation>()?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(read_csv, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(fields, m)?)?;
    m.add_function(wrap_pyfunction!(_internal_panic, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

/// The engine's overlap rule for an `allow_overlap` argument.
fn overlap(allow: bool) -> tinydem::engine::Overlap {
    match allow {
        true => tinydem::engine::Overlap::Allowed,
        false => tinydem::engine::Overlap::Refused,
    }
}

/// Particle ids from Python: whole numbers from 0 (64-bit, as numpy's int64 holds them).
fn ids_of(ids: PyArrayLike1<'_, i64, AllowTypeChange>) -> PyResult<Vec<u64>> {
    ids.as_array()
        .iter()
        .map(|&id| {
            u64::try_from(id).map_err(|_| PyValueError::new_err(format!("ids: {id} is no id")))
        })
        .collect()
}
