//! `tinydem check`: what a scenario implies before it runs (time step against Eq. 50,
//! masses, stiffness, run length, output size, a timed trial for the wall time), and the
//! checks that make `run` refuse a scenario unless `--force`: a time step far past Eq. 50,
//! output that does not fit the free space.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use glam::DVec3;

use crate::engine::Simulation;
use crate::geometry::mesh::Contacts;
use crate::io::checkpoint;
use crate::io::output::{OUTLETS, WALLS};
use crate::model::contact::{ContactLaw, damping_factor};
use crate::model::integrate::Inertia;
use crate::scenario::{FrictionSprings, MassSource, MeshInput, Scenario, Target};

use super::materials::{material_lines, model_lines};

/// The derived quantities `tinydem check` prints.
pub fn describe(s: &Scenario, out: &Path) -> Result<String> {
    if let Some(why) = s.spawn_box_outside() {
        anyhow::bail!("{why}");
    }
    describe_start(s, out, Simulation::new(s.clone())?)
}

/// The derived quantities of a run of `s` that starts as `sim` (fresh, or a stage after a
/// checkpoint): its particles, the most it can hold and the timed trial are `sim`'s.
fn describe_start(s: &Scenario, out: &Path, sim: Simulation) -> Result<String> {
    let g = &s.geometry;
    let m = &s.material;
    let dt = s.simulation.timestep;
    let law = ContactLaw::new(m, dt, s.simulation.friction_springs);
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
    let max_n = most_particles(s, sim.particles.len());
    let size = OutputEstimate::of(s, max_n, sim.walls.mesh.faces.len());
    let meshes = mesh_lines(s, &sim) + &servo_lines(s, &sim);
    let bounds = bound_lines(s, &sim);
    let materials = material_lines(s) + &clump_lines(s);
    let default_dt = s.eq50_timestep();
    let until = until_line(s) + &s.thermal_line();
    let reach = super::materials::skin_line(s, sim.neighbours.skin);
    Ok(format!(
        "scenario is valid\n\
         {meshes}\
         {materials}\
         {bounds}\
         initial particles      {}\n\
         time step              {dt:.6e} s ({:.3} x {})\n\
         friction springs       {}\n\
         {}\
         particle mass          {m_min:.6e} .. {m_max:.6e} kg\n\
         stiffness k_n at 10%   {k_10:.6e} N/m (two R_min particles, delta = 0.1 R_min)\n\
         half contact period    {period:.6e} s = {:.1} time steps\n\
         total simulated time   {:.6} s ({} frames x {} steps)\n\
         {until}\
         output                 {} files ({}), up to {} a frame, {} in all{}\n\
         wall time              {}\n\
         {}",
        sim.particles.len(),
        dt / default_dt,
        s.timestep_rule(),
        match s.simulation.friction_springs {
            FrictionSprings::AdvanceFirst => "advance_first (advanced, then their force taken)",
            FrictionSprings::Paper =>
                "paper (the force of the previous step's spring, Eqs. 53-55; the original program's)",
        },
        model_lines(s, m_min) + &reach,
        period / dt,
        s.total_time(),
        s.simulation.frames,
        s.simulation.steps_per_frame,
        size.files,
        size.formats.join(", "),
        human_bytes(size.per_frame as f64),
        human_bytes(size.total as f64),
        match free_space(out) {
            Some(free) => format!("; {} free in {}", human_bytes(free as f64), out.display()),
            None => String::new(),
        },
        Trial::run(s, sim, TRIAL).describe(s, max_n),
        refusals(s, max_n, out)
            .iter()
            .map(|r| format!("warning: {r} (run refuses it unless --force)\n"))
            .chain(cautions(s).iter().map(|c| format!("warning: {c}\n")))
            .collect::<String>(),
    ))
}

/// The line of `[simulation] until`'s conditions, if it has any.
fn until_line(s: &Scenario) -> String {
    let u = &s.simulation.until;
    let mut any = Vec::new();
    if let Some(e) = u.kinetic_energy_below {
        any.push(format!("kinetic energy < {e:e} J (none left to spawn)"));
    }
    if let Some(t) = u.time {
        any.push(format!("t >= {t:e} s"));
    }
    if let Some(n) = u.removed_at_least {
        any.push(format!("{n} particles removed"));
    }
    if let Some(f) = u.servo_within {
        any.push(format!("every servo's load within {f:e} of its target"));
    }
    if any.is_empty() {
        return String::new();
    }
    let joined = if u.all {
        any.join(", and ")
    } else {
        any.join(", or ")
    };
    format!("ends early             at the first frame with {joined}\n")
}

/// A line per mesh file: its faces, contact mode (and surfaces) and material.
fn mesh_lines(s: &Scenario, sim: &Simulation) -> String {
    let mut meshes = String::new();
    for (k, file) in sim.walls.files.iter().enumerate() {
        if file.faces.is_empty() && k == 0 {
            meshes += "mesh                   none\n";
            continue;
        }
        let faces = &sim.walls.mesh.faces[file.faces.clone()];
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
            "{:<23}{}: {} {}, contacts {contacts}\n",
            if k == 0 {
                "mesh".to_string()
            } else {
                format!("mesh {k}")
            },
            file.name,
            faces.len(),
            if faces.len() == 1 { "face" } else { "faces" }
        );
    }
    meshes
}

/// A line per servo: its direction, target force (and the stress and area it is from),
/// gain and speed limit.
fn servo_lines(s: &Scenario, sim: &Simulation) -> String {
    let mut lines = String::new();
    for (k, c, _) in sim.walls.servo_controls() {
        let from = match s.meshes[k - 1].servo.map(|v| v.target) {
            Some(Target::Stress(p)) => format!(" ({p} Pa over {:.6e} m^2)", c.force / p),
            _ => String::new(),
        };
        lines += &format!(
            "{:<23}along {}: {:.6e} N{from}, gain {:.3e} m/(s N), at most {} m/s\n",
            format!("servo (mesh {k})"),
            c.direction,
            c.force,
            c.gain,
            c.max_speed
        );
    }
    lines
}

/// The domain (and the initial particles outside it), the outlets and the wall loads.
fn bound_lines(s: &Scenario, sim: &Simulation) -> String {
    let mut bounds = domain_lines(s, sim);
    for (k, o) in s.outlets.iter().enumerate() {
        bounds += &format!(
            "outlet {k:<16}{} .. {} (removes particles entering it; {OUTLETS})\n",
            o.min, o.max
        );
    }
    for (k, b) in s.fixed.iter().enumerate() {
        // A grain each: a sphere by its centre, a clump by its centre of mass.
        let p = &sim.particles;
        let spheres = (0..p.len()).filter(|&i| p.body[i].is_none() && b.contains(p.x[i]));
        let clumps = p.bodies.list.iter().filter(|c| b.contains(c.x));
        let held = spheres.count() + clumps.count();
        bounds += &format!(
            "fixed {k:<17}{} .. {} (holds the {held} initial grains in it in place)\n",
            b.min, b.max
        );
    }
    bounds += &spawn_lines(s, sim.spawner.box_off);
    if s.wall_forces {
        bounds += &format!(
            "wall loads             force and torque on each mesh file, mean per frame ({WALLS})\n"
        );
    }
    bounds
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// The domain: its periodic axes and Lees-Edwards shear, and the initial particles it will
/// remove (outside it across a side that is not periodic; across a periodic one they are put
/// back in).
fn domain_lines(s: &Scenario, sim: &Simulation) -> String {
    let Some(d) = s.domain else {
        return String::new();
    };
    let periodic: Vec<&str> = (0..3).filter(|&a| s.periodic[a]).map(|a| AXES[a]).collect();
    let leaving = match periodic.len() {
        0 => "particles leaving it are removed".to_string(),
        3 => "periodic along x, y and z: nothing leaves it".to_string(),
        _ => format!(
            "periodic along {}: particles leaving it across another side are removed",
            periodic.join(" and ")
        ),
    };
    let mut lines = format!(
        "domain                 {} .. {} ({leaving})\n",
        d.min, d.max
    );
    if let Some((velocity, axis, gradient)) = s.lees_edwards {
        lines += &format!(
            "Lees-Edwards           the images across the {g} sides move at {velocity} m/s along {a} (shear rate {:.6e}/s)\n",
            velocity / (d.max[gradient] - d.min[gradient]),
            g = AXES[gradient],
            a = AXES[axis],
        );
    }
    let removed =
        |x: &DVec3| (0..3).any(|a| !s.periodic[a] && (x[a] < d.min[a] || x[a] > d.max[a]));
    let outside = sim.particles.x.iter().filter(|x| removed(x)).count();
    if outside > 0 {
        lines += &format!(
            "                       warning: {outside} initial particles lie outside it and are removed at the first step\n"
        );
    }
    lines
}

/// Where particles come from: the `[[spawn]]` regions, or the spawn box (unless it is
/// `box_off`, in a stage that names none).
fn spawn_lines(s: &Scenario, box_off: bool) -> String {
    let most = s.simulation.max_particles;
    if s.simulation.spawn_attempts == 0 || most == 0 {
        return format!("{:<23}none\n", "spawning");
    }
    if s.spawn.is_empty() && box_off {
        return format!(
            "{:<23}none (a stage spawns in the spawn box only if its scenario names one)\n",
            "spawning"
        );
    }
    if s.spawn.is_empty() {
        let g = &s.geometry;
        return format!(
            "spawning               the spawn box {} .. {}, up to {most} particles, R uniform in [{}, {}]\n",
            g.spawn_min, g.spawn_max, g.radius_min, g.radius_max
        );
    }
    let mut lines = String::new();
    for (k, r) in s.spawn.iter().enumerate() {
        let what = if r.clump.is_some() {
            "clumps"
        } else {
            "particles"
        };
        let amount = match (r.count, r.rate) {
            (Some(n), Some(q)) => format!("{n} {what} at {q}/s"),
            (Some(n), None) => format!("{n} {what}"),
            (None, Some(q)) => format!("{q} {what}/s"),
            (None, None) => what.to_string(),
        };
        let made_of = match r.clump {
            Some(c) => format!(
                "clump \"{}\" scaled by {} to {}, oriented at random",
                s.clumps[c.template as usize].name, c.scale.0, c.scale.1
            ),
            None => format!("R {}", radius_words(&r.radius)),
        };
        let window = match (r.start, r.stop) {
            (a, b) if a == 0.0 && b == f64::INFINITY => String::new(),
            (a, b) => format!(", from t = {a} to {b} s"),
        };
        lines += &format!(
            "{:<23}{} .. {}: {amount}{window}, {made_of}\n",
            format!("spawn region {}", k + 1),
            r.region.min,
            r.region.max,
        );
    }
    lines + &format!("                       in all at most {most} particles (max_particles)\n")
}

/// A radius distribution in words.
fn radius_words(r: &crate::scenario::RadiusDistribution) -> String {
    use crate::scenario::RadiusDistribution::*;
    match r {
        Uniform { min, max } => format!("uniform in [{min}, {max}]"),
        Normal {
            mean,
            std,
            min,
            max,
        } => format!("normal ({mean} +- {std}) in [{min}, {max}]"),
        LogNormal {
            mean,
            std,
            min,
            max,
        } => {
            format!("log-normal ({mean} +- {std}) in [{min}, {max}]")
        }
        Table { radii, weights } => format!("from {radii:?} weighted {weights:?}"),
    }
}

/// Each clump template: its spheres, mass, principal moments and how they were found.
fn clump_lines(s: &Scenario) -> String {
    let mut lines = String::new();
    for (k, c) in s.clumps.iter().enumerate() {
        let how = match c.source {
            MassSource::Computed { error } => {
                format!("of the union, overlaps once: ray quadrature, error ~{error:.1e}")
            }
            MassSource::Given => "given".into(),
        };
        lines += &format!(
            "{:<23}{k} \"{}\": {} spheres, bounding radius {:.6e} m, mass {:.6e} kg, principal \
             moments {:.6e} {:.6e} {:.6e} kg m^2 ({how})\n",
            if k == 0 { "clumps" } else { "" },
            c.name,
            c.spheres.len(),
            c.bounding_radius,
            c.mass,
            c.inertia.x,
            c.inertia.y,
            c.inertia.z
        );
    }
    lines
}

/// What `tinydem check SCENARIO --from CHECKPOINT` prints: the scenario's derived
/// quantities, then what it changes as a stage after the checkpoint's run and what it
/// carries over.
pub fn describe_stage(s: &Scenario, from: &Path, dir: &Path) -> Result<String> {
    let snapshot = checkpoint::load(from, None)?;
    let old = snapshot.scenario.clone();
    let steps = snapshot.steps;
    let (sim, notes) = Simulation::stage(s.clone(), snapshot)
        .with_context(|| format!("cannot start a stage from {}", from.display()))?;
    let mut out = describe_start(s, dir, sim)?;
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
pub(super) fn num(x: f64) -> String {
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

/// How far the time step may exceed Eq. 50 before `run` refuses it. At twice Eq. 50 a
/// contact of two R_min particles at 10 % indentation lasts 6 steps (its half period), the
/// fewest that resolve its force; the default hourglass runs at 3x with twice the
/// neighbour-list rebuilds and blows up at 5x (step 226).
pub const TIMESTEP_TOLERANCE: f64 = 2.0;

/// How long `check` steps the scenario to estimate the wall time of the run.
pub const TRIAL: Duration = Duration::from_millis(500);

/// The most particles a run of `s` that starts with `initial` can hold.
pub fn most_particles(s: &Scenario, initial: usize) -> usize {
    if s.simulation.spawn_attempts > 0 {
        (s.simulation.max_particles as usize).max(initial)
    } else {
        initial
    }
}

/// Why `run` refuses `s` (with at most `n` particles, into `out`) unless `--force`: a time
/// step past [`TIMESTEP_TOLERANCE`] times Eq. 50, more output than the free space.
pub fn refusals(s: &Scenario, n: usize, out: &Path) -> Vec<String> {
    let mut why: Vec<String> = timestep_refusal(s).into_iter().collect();
    why.extend(s.thermal_refusal());
    why.extend(until_refusal(s, n as u64));
    let need = OutputEstimate::of(s, n, 0).total;
    if let Some(free) = free_space(out)
        && need > free
    {
        why.push(format!(
            "the output may grow to {}, more than the {} free in {}: write fewer frames \
             ([simulation] frames, steps_per_frame) or formats ([output] formats)",
            human_bytes(need as f64),
            human_bytes(free as f64),
            out.display()
        ));
    }
    why
}

/// Why `[simulation] until` can never end the run: more removals asked for than the `n`
/// particles the run can ever hold (those removed before a resume counted in).
pub fn until_refusal(s: &Scenario, n: u64) -> Option<String> {
    let asked = s.simulation.until.removed_at_least?;
    (asked > n).then(|| {
        format!(
            "[simulation] until.removed_at_least = {asked} can never hold: this run makes at \
             most {n} particles ([simulation] max_particles = {}, and those it starts with), \
             so it would run all its {} frames",
            s.simulation.max_particles, s.simulation.frames
        )
    })
}

/// The largest time step (as a fraction of Eq. 50's) at which a grain seated on `n` faces
/// at once with damping factor `beta` (Eq. 21) of the pair's restitution settles. The `n`
/// contacts act in parallel: their dampers bound n beta dt/dt_50 (semi-implicit Euler needs
/// gamma dt < 2 - omega^2 dt^2 / 2), their springs n (dt/dt_50)^2. Measured with one grain
/// dropped into built-in hoppers and a cylinder's orifice of 8 to 96 faces
/// (`tests/shapes.rs`): the grain's spin flips sign every step (bounded) above
/// n beta dt/dt_50 = 4.4-4.8 at restitution 0.1, 0.3 and 0.5, and gains energy above
/// n (dt/dt_50)^2 = 30-40 at 0.5; the bounds here keep a margin of 1.5.
pub fn seat_timestep(n: u32, beta: f64) -> f64 {
    let n = n as f64;
    (3.0 / (n * beta)).min((20.0 / n).sqrt())
}

/// What `run` warns of but runs: built-in shapes in which a grain of R_max sits on more
/// faces at once than the time step resolves ([`seat_timestep`]).
pub fn cautions(s: &Scenario) -> Vec<String> {
    let (dt, eq50) = (s.simulation.timestep, s.eq50_timestep());
    let mut why = s.idle_heat_keys();
    for (k, mesh) in s.meshes.iter().enumerate() {
        let MeshInput::Shape(shape) = &mesh.input else {
            continue;
        };
        let r = s.geometry.radius_max + mesh.radii[0];
        let per_face = mesh.contacts == Contacts::PerFace;
        let Some((n, place)) = shape.seat(r, per_face) else {
            continue;
        };
        // The most damped pair of a grain's material with the shape's.
        let beta = (0..s.materials.len() as u16)
            .map(|a| damping_factor(s.pair(a, mesh.material).restitution))
            .fold(0.0, f64::max);
        let most = eq50 * seat_timestep(n, beta);
        if dt > most {
            why.push(format!(
                "a grain seated {place} of [[meshes]] #{} (a built-in {}) touches {n} faces at \
                 once, which act on it together: at this time step it may not settle (set \
                 [simulation] timestep at most {most:.3e} s, or a coarser shape.resolution)",
                k + 1,
                shape.kind()
            ));
        }
    }
    why
}

/// Why the time step is refused: past [`TIMESTEP_TOLERANCE`] times Eq. 50.
pub fn timestep_refusal(s: &Scenario) -> Option<String> {
    let (dt, eq50) = (s.simulation.timestep, s.eq50_timestep());
    (dt > TIMESTEP_TOLERANCE * eq50).then(|| {
        format!(
            "time step {dt:.3e} s is {:.1} x {}'s {eq50:.3e} s, more than the {TIMESTEP_TOLERANCE} x \
             a contact tolerates: the run is likely to blow up (leave [simulation] timestep unset, \
             or set it at most {:.3e} s)",
            dt / eq50,
            s.timestep_rule(),
            TIMESTEP_TOLERANCE * eq50
        )
    })
}

/// The largest the output of a run can grow, in all its formats.
#[derive(Clone, Debug, PartialEq)]
pub struct OutputEstimate {
    pub files: u64,
    pub formats: Vec<&'static str>,
    /// Bytes written per frame, at most, and in all (frames, logs and the checkpoint, which
    /// is written beside the last one before it replaces it).
    pub per_frame: u64,
    pub total: u64,
}

impl OutputEstimate {
    /// For `n` particles and `faces` mesh faces. Numbers are counted at their longest
    /// (25 characters with the comma), contact networks at 4 contacts per particle.
    pub fn of(s: &Scenario, n: usize, faces: usize) -> OutputEstimate {
        const FLOAT: u64 = 25;
        const WHOLE: u64 = 11;
        const CONTACTS_PER_PARTICLE: u64 = 4;
        let (n, frames) = (n as u64, s.simulation.frames + 1);
        let mut formats = Vec::new();
        let (mut per_frame, mut files_per_frame, mut once, mut files) = (0, 0, 0, 3);
        if s.formats.csv {
            formats.push("CSV");
            per_frame += 100 + n * (14 * FLOAT + 3 * WHOLE);
            files_per_frame += 1;
        }
        if s.formats.vtk {
            formats.push("VTK");
            // id, radius, v, w, q, tag, x, connectivity, offsets, type; the collection's line.
            per_frame += 2_000 + n * (4 + 8 + 24 + 24 + 32 + 4 + 24 + 8 + 8 + 1) + 80 * frames;
            files_per_frame += 1;
            once += 1_000 + 120 * faces as u64;
            files += 2;
        }
        if s.contact_network {
            formats.push("contacts");
            let contacts = CONTACTS_PER_PARTICLE * n;
            per_frame += contacts * (3 * WHOLE + 10 * FLOAT);
            files_per_frame += 1;
            if s.formats.vtk {
                per_frame += 2_000 + contacts * (24 + 8 + 48 + 8 + 8) + n * 24 + 80 * frames;
                files_per_frame += 1;
            }
        }
        // log.csv and frames.csv; outlets.csv and walls.csv.
        per_frame += 11 * FLOAT + 3 * FLOAT;
        per_frame += s.outlets.len() as u64 * (3 * WHOLE + 2 * FLOAT);
        if s.wall_forces {
            per_frame += (1 + s.meshes.len() as u64) * (2 * WHOLE + 7 * FLOAT);
        }
        // The checkpoint: the state of each particle and the springs of its contacts, twice.
        let springs = std::mem::size_of::<crate::model::springs::Springs>() as u64 + 8;
        once += 2 * (n * (14 * 8 + 10) + n * CONTACTS_PER_PARTICLE * springs);
        OutputEstimate {
            files: files + files_per_frame * frames,
            formats,
            per_frame,
            total: per_frame * frames + once,
        }
    }
}

/// Bytes free for an unprivileged user on the file system that holds `dir` (or would: its
/// nearest existing ancestor), if the system says.
pub fn free_space(dir: &Path) -> Option<u64> {
    use std::os::unix::ffi::OsStrExt;
    let mut at = std::path::absolute(dir).ok()?;
    while !at.exists() {
        at = at.parent()?.to_path_buf();
    }
    let path = std::ffi::CString::new(at.as_os_str().as_bytes()).ok()?;
    // SAFETY: `path` is a NUL-terminated string and `stat` a zeroed struct statvfs that the
    // call fills in; neither outlives this function.
    let mut stat: libc::statvfs = unsafe { std::mem::zeroed() };
    if unsafe { libc::statvfs(path.as_ptr(), &mut stat) } != 0 {
        return None;
    }
    Some(stat.f_bavail as u64 * stat.f_frsize as u64)
}

/// A short timed run from the start of a run, to estimate the wall time. Its first step
/// (which builds the neighbour lists from nothing) is timed apart, so that a trial of a few
/// steps of a large system does not take that build for the cost of every step.
#[derive(Clone, Debug)]
pub struct Trial {
    /// Steps taken, the first included.
    pub steps: u64,
    /// Wall time of the first step and of the steps after it \[s\].
    pub first: f64,
    pub seconds: f64,
    /// Sum over the steps after the first of the particles stepped.
    pub particle_steps: f64,
    /// Particles at its end.
    pub particles: usize,
    /// Why it stopped early, if the run became unstable.
    pub failure: Option<String>,
}

impl Trial {
    /// Steps `sim`, the start of a run of `s`, for `budget` of wall time (or to its end).
    pub fn run(s: &Scenario, mut sim: Simulation, budget: Duration) -> Trial {
        let total = s.simulation.frames * s.simulation.steps_per_frame;
        let begin = Instant::now();
        let mut failure = sim.step().err().map(|unstable| unstable.to_string());
        let first = begin.elapsed().as_secs_f64();
        let start = Instant::now();
        let mut particle_steps = 0.0;
        while failure.is_none() && sim.steps < total && begin.elapsed() < budget {
            particle_steps += sim.particles.len().max(1) as f64;
            if let Err(unstable) = sim.step() {
                failure = Some(unstable.to_string());
            }
        }
        Trial {
            steps: sim.steps,
            first,
            seconds: start.elapsed().as_secs_f64(),
            particle_steps,
            particles: sim.particles.len(),
            failure,
        }
    }

    /// The estimated wall time of the whole run of `s`, with at most `n` particles: the
    /// first step, then the trial's cost per particle-step for every further step with `n`
    /// particles (an upper bound when the run spawns or removes particles).
    pub fn estimate(&self, s: &Scenario, n: usize) -> f64 {
        let total = s.simulation.frames * s.simulation.steps_per_frame;
        if self.steps >= total || self.particle_steps == 0.0 {
            return self.first + self.seconds;
        }
        let per = self.seconds / self.particle_steps;
        self.first + per * (total - 1) as f64 * n.max(1) as f64
    }

    /// The `wall time` line of `check`.
    fn describe(&self, s: &Scenario, n: usize) -> String {
        if let Some(why) = &self.failure {
            return format!(
                "unknown: the trial became unstable: {why}\nwarning: the run will fail"
            );
        }
        let total = s.simulation.frames * s.simulation.steps_per_frame;
        let threads = rayon::current_num_threads();
        if self.steps >= total {
            return format!(
                "{} (the whole run, timed, {threads} threads)",
                human_seconds(self.first + self.seconds)
            );
        }
        format!(
            "about {} on {threads} threads, without output (a trial of {} steps in {:.2} s, \
             the first {:.2} s: {:.2e} s per particle-step after it, for {n} particles{})",
            human_seconds(self.estimate(s, n)),
            self.steps,
            self.first + self.seconds,
            self.first,
            self.seconds / self.particle_steps.max(1.0),
            if n != self.particles {
                format!(
                    ", the most the run holds; {} at the trial's end",
                    self.particles
                )
            } else {
                String::new()
            }
        )
    }
}

/// A duration for people: seconds, minutes, hours or days.
fn human_seconds(t: f64) -> String {
    match t {
        t if t < 120.0 => format!("{t:.1} s"),
        t if t < 7_200.0 => format!("{:.1} min", t / 60.0),
        t if t < 172_800.0 => format!("{:.1} h", t / 3_600.0),
        t => format!("{:.1} days", t / 86_400.0),
    }
}
