//! The dense-packing benchmark of the paper's Section 5: N spheres settled under gravity in
//! an open-top cubic box, timed over steps in the settled state.
//!
//! Packings of 10^3, 10^4 and 10^5 spheres (radii uniform in [4, 5] mm) are in
//! `bench/data/nN/` (from `shared/bench`). Larger sizes are made by placing copies of the
//! 10^5 packing side by side on one floor (5 x 2 tiles for 10^6, 10 x 10 for 10^7), inside a
//! box around all tiles: the same settled structure, contacts per particle and depth.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::DVec3;

use crate::engine::{Simulation, Stage};
use crate::geometry::mesh::Mesh;
use crate::model::particles::Particles;
use crate::scenario::Scenario;

/// The material and time step of the benchmark (`shared/bench/README.md`).
pub const SCENARIO: &str = "\
[geometry]\nradius_min = 0.004\nradius_max = 0.005\nmesh_radii = [0.0]\n\
[material]\ndensity = 1000.0\nyoungs_modulus = 1e6\npoisson_ratio = 0.3\nrestitution = 0.5\n\
friction_sliding = 0.3\nfriction_rolling = 0.3\nviscosity = 0.0\n\
[kinetics]\ngravity = [0.0, 0.0, -9.81]\n\
[simulation]\nmax_particles = 0\nspawn_attempts = 0\n";

/// Where the packings live: `TINYDEM_BENCH_DATA`, else `bench/data` of the source tree.
pub fn data_dir() -> PathBuf {
    std::env::var_os("TINYDEM_BENCH_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("bench/data"))
}

/// The stored packing sizes and how the larger ones are tiled from the largest.
fn tiling(n: usize) -> Result<(usize, usize, usize)> {
    Ok(match n {
        1_000 | 10_000 | 100_000 => (n, 1, 1),
        1_000_000 => (100_000, 5, 2),
        10_000_000 => (100_000, 10, 10),
        _ => bail!("no packing for N = {n}: sizes are 1000, 10000, 100000, 1000000, 10000000"),
    })
}

/// An open-top box of edges `lx`, `ly`, `lz` as OFF text (floor and four walls).
fn box_off(lx: f64, ly: f64, lz: f64) -> String {
    format!(
        "OFF\n8 5 0\n0 0 0\n{lx} 0 0\n{lx} {ly} 0\n0 {ly} 0\n0 0 {lz}\n{lx} 0 {lz}\n{lx} {ly} {lz}\n0 {ly} {lz}\n\
         4 0 1 2 3\n4 0 3 7 4\n4 1 2 6 5\n4 0 1 5 4\n4 3 2 6 7\n"
    )
}

/// The benchmark simulation with `n` particles.
pub fn setup(n: usize) -> Result<Simulation> {
    let (base, tx, ty) = tiling(n)?;
    let dir = data_dir().join(format!("n{base}"));
    let edge: f64 = std::fs::read_to_string(dir.join("edge.txt"))
        .with_context(|| {
            format!(
                "cannot read {}/edge.txt (set TINYDEM_BENCH_DATA)",
                dir.display()
            )
        })?
        .trim()
        .parse()
        .context("edge.txt holds no number")?;
    let file = dir.join("settled.csv.gz");
    let gz = flate2::read::GzDecoder::new(
        std::fs::File::open(&file).with_context(|| format!("cannot read {}", file.display()))?,
    );
    let tile = crate::io::csv::read_particles(gz, &file.display().to_string())?;
    let mut particles = Particles::default();
    for ix in 0..tx {
        for iy in 0..ty {
            let shift = DVec3::new(ix as f64 * edge, iy as f64 * edge, 0.0);
            for mut p in tile.iter() {
                p.x += shift;
                particles.push(p);
            }
        }
    }
    let scenario = Scenario::parse(SCENARIO, Path::new("bench"))?;
    let mesh = Mesh::parse_off(
        &box_off(tx as f64 * edge, ty as f64 * edge, edge),
        "benchmark box",
        &scenario.geometry.mesh_radii,
    )?;
    Simulation::from_parts(scenario, mesh, particles)
}

/// The spheres of a clump of `k` spheres (1 to 4: a sphere, a dimer, a triangle, a
/// tetrahedron) inside a grain of radius `a`, as `[[clumps]]` text.
fn clump_template(k: usize, a: f64) -> Result<String> {
    let (r, d, centres): (f64, f64, Vec<DVec3>) = match k {
        1 => (1.0, 0.0, vec![DVec3::ZERO]),
        2 => (0.6, 0.4, vec![DVec3::X, -DVec3::X]),
        3 => {
            let at = |t: f64| DVec3::new(t.cos(), t.sin(), 0.0);
            (
                0.58,
                0.42,
                (0..3)
                    .map(|i| at(i as f64 * std::f64::consts::TAU / 3.0))
                    .collect(),
            )
        }
        4 => {
            let v = [
                [1.0, 1.0, 1.0],
                [1.0, -1.0, -1.0],
                [-1.0, 1.0, -1.0],
                [-1.0, -1.0, 1.0],
            ];
            (
                0.55,
                0.45,
                v.map(|c| DVec3::from_array(c).normalize()).to_vec(),
            )
        }
        _ => bail!("--clumps {k}: clumps of 1 to 4 spheres"),
    };
    let spheres: Vec<String> = (centres.iter())
        .map(|c| {
            format!(
                "[{}, {}, {}, {}]",
                c.x * d * a,
                c.y * d * a,
                c.z * d * a,
                r * a
            )
        })
        .collect();
    Ok(format!(
        "[[clumps]]\nname = \"grain\"\nspheres = [{}]\n",
        spheres.join(", ")
    ))
}

/// The benchmark packing of `n` grains with each grain a clump of `k` spheres inside its
/// sphere (scaled to its radius, oriented at random): the same places, time step and
/// material; the clumps' spheres are smaller, so the packing settles further.
pub fn setup_clumps(n: usize, k: usize) -> Result<Simulation> {
    use rand::SeedableRng;
    let spheres = setup(n)?;
    let dt = spheres.scenario.simulation.timestep;
    let a = 0.0045;
    let text = SCENARIO.replace("radius_min = 0.004", "radius_min = 0.002")
        + &format!("timestep = {dt}\n")
        + &clump_template(k, a)?;
    let scenario = Scenario::parse(&text, Path::new("bench"))?;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let mut particles = Particles::default();
    let t = &scenario.clumps[0];
    for p in spheres.particles.iter() {
        let q = crate::engine::spawn::uniform_rotation(&mut rng);
        let motion = (p.x, q, p.v, p.w);
        crate::engine::spawn::place_clump(&mut particles, (t, 0), p.radius / a, motion);
    }
    let mesh = Mesh {
        faces: spheres.walls.mesh.faces.clone(),
        ..Mesh::default()
    };
    Simulation::from_parts(scenario, mesh, particles)
}

/// Figures of one benchmark configuration.
#[derive(Clone, Debug)]
pub struct Measurement {
    pub n: usize,
    /// Threads per process, and processes (a run split over several under mpirun).
    pub threads: usize,
    pub ranks: usize,
    /// Median over the repeats, milliseconds per step.
    pub ms_per_step: f64,
    /// N / (seconds per step).
    pub cundall: f64,
    /// Peak resident memory of the processes \[bytes\], and its growth per particle.
    pub peak_bytes: u64,
    pub bytes_per_particle: f64,
    /// Neighbour-list rebuilds per 100 timed steps.
    pub rebuilds_per_100_steps: f64,
    pub contacts_per_particle: f64,
    /// Verlet-list entries (pairs and particle-face pairs) per particle.
    pub slots_per_particle: f64,
    /// Shares of the timed wall time spent on the neighbour lists (checks and rebuilds)
    /// and on particle-particle contacts.
    pub lists_share: f64,
    pub pairs_share: f64,
    /// Share spent sending the new states of particles to the processes that hold them as
    /// ghosts (the exchange stage; the other messages are within their stages).
    pub exchange_share: f64,
}

/// Reads a field of `/proc/self/status` in bytes (Linux); 0 elsewhere.
pub fn proc_status_bytes(field: &str) -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with(field))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<u64>().ok())
        })
        .map_or(0, |kb| kb * 1024)
}

/// Steps per timed segment: enough for about 10^7 particle-steps, and at least 100 so that a
/// segment spans several neighbour-list rebuilds (one every 20-50 steps in a settled packing;
/// ten-step segments at 10^6 caught zero, one or two and misstated the cost by up to 20 %).
pub fn default_steps(n: usize) -> u64 {
    (10_000_000 / n as u64).clamp(100, 5000)
}

/// The bed with `lines` added to its `[material]` (a contact model's keys, heat's), keeping
/// the energy ledger if `ledger`.
fn with_material(sim: Simulation, lines: &str, ledger: bool) -> Result<Simulation> {
    let text =
        (sim.scenario.to_toml()).replace("viscosity = 0", &format!("{lines}\nviscosity = 0"));
    let mut scenario = Scenario::parse(&text, Path::new("bench"))?;
    scenario.energy_ledger = ledger;
    let mesh = Mesh {
        faces: sim.walls.mesh.faces.clone(),
        ..Mesh::default()
    };
    Simulation::from_parts(scenario, mesh, sim.particles)
}

/// The benchmark with heat transfer: the grains conduct (glass-like, k = 1 W/(m K), c = 800
/// J/(kg K)) and start with temperatures from 300 K at the floor to 400 K at the box's top,
/// so that heat flows through every contact.
pub fn heated(mut sim: Simulation) -> Result<Simulation> {
    let top = sim
        .walls
        .mesh
        .faces
        .iter()
        .flat_map(|f| f.corners())
        .fold(0.0, |z, c| c.z.max(z));
    let p = &mut sim.particles;
    p.activate("T");
    for (t, x) in p.temperature.iter_mut().zip(&p.x) {
        *t = 300.0 + 100.0 * (x.z / top).clamp(0.0, 1.0);
    }
    let ledger = sim.scenario.energy_ledger;
    let sim = with_material(
        sim,
        "thermal_conductivity = 1.0\nheat_capacity = 800.0\ninitial_temperature = 300.0",
        ledger,
    )?;
    anyhow::ensure!(
        sim.scenario.heat(),
        "the benchmark's material did not take the heat keys"
    );
    Ok(sim)
}

/// A benchmark bed: `n` particles (grains: clumps of `clumps` spheres each, if given),
/// conducting heat if `heat`, with the lines `material` added to its `[material]`, keeping
/// the energy ledger if `ledger`.
#[derive(Clone, Debug, Default)]
pub struct Bed {
    pub n: usize,
    pub clumps: Option<usize>,
    pub heat: bool,
    pub material: Vec<String>,
    pub ledger: bool,
}

/// Runs the benchmark `bed` on the current thread pool, split over the processes of
/// `world` if given: a warm-up, then `repeats` timed segments of `steps` steps.
pub fn measure(
    bed: &Bed,
    steps: u64,
    repeats: usize,
    world: Option<Box<dyn crate::parallel::comm::Comm>>,
) -> Result<Measurement> {
    let rss_before = proc_status_bytes("VmRSS:");
    let n = bed.n;
    let mut sim = match bed.clumps {
        None => setup(n)?,
        Some(k) => setup_clumps(n, k)?,
    };
    if !bed.material.is_empty() || bed.ledger {
        sim = with_material(sim, &bed.material.join("\n"), bed.ledger)?;
    }
    if bed.heat {
        sim = heated(sim)?;
    }
    let ranks = world.as_ref().map_or(1, |w| w.size());
    if let Some(world) = world.filter(|w| w.size() > 1) {
        sim = sim.split(world)?;
    }
    for _ in 0..steps.min(20) {
        sim.step()?; // warm-up: first neighbour lists, caches
    }
    let rebuilds_before = sim.rebuilds();
    let stages_before = sim.stage_times.clone();
    let timed = Instant::now();
    let mut times = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        let t = Instant::now();
        for _ in 0..steps {
            sim.step()?;
        }
        times.push(t.elapsed().as_secs_f64() / steps as f64);
    }
    let timed = timed.elapsed().as_secs_f64();
    let share = |stage: Stage| {
        (sim.stage_times.of(stage) - stages_before.of(stage)) / timed.max(f64::MIN_POSITIVE)
    };
    let (lists_share, pairs_share) = (share(Stage::Neighbours), share(Stage::ParticleContacts));
    let exchange_share = share(Stage::Exchange);
    times.sort_by(f64::total_cmp);
    let per_step = times[times.len() / 2];
    // Over all processes: memory (before counting the contacts, which takes some), list
    // slots (ghosts' included) and contacts.
    let (p, f) = sim.list_slots();
    let mine = [
        proc_status_bytes("VmHWM:") as i64,
        rss_before as i64,
        (p + f) as i64,
    ];
    let thermo = sim.thermo();
    let [peak, before, slots] = match sim.share() {
        Some(d) => d.comm.sum_i64(&mine).try_into().expect("three sums"),
        None => mine,
    };
    let peak = peak as u64;
    Ok(Measurement {
        n,
        threads: rayon::current_num_threads(),
        ranks,
        ms_per_step: per_step * 1e3,
        cundall: n as f64 / per_step,
        peak_bytes: peak,
        bytes_per_particle: peak.saturating_sub(before as u64) as f64 / n as f64,
        rebuilds_per_100_steps: (sim.rebuilds() - rebuilds_before) as f64 * 100.0
            / (steps * repeats as u64) as f64,
        contacts_per_particle: (thermo.pair_contacts + thermo.wall_contacts) as f64 / n as f64,
        slots_per_particle: slots as f64 / n as f64,
        lists_share,
        pairs_share,
        exchange_share,
    })
}

impl Measurement {
    pub const HEADER: &'static str = "       N  threads  ranks   ms/step    Cundall   peak MB  B/particle  rebuilds/100  contacts/particle  list/particle  lists %  pairs %  exchange %";

    pub fn row(&self) -> String {
        format!(
            "{:>8}  {:>7}  {:>5}  {:>8.3}  {:>9.3e}  {:>8.1}  {:>10.0}  {:>12.2}  {:>17.2}  {:>13.2}  {:>7.0}  {:>7.0}  {:>10.0}",
            self.n,
            self.threads,
            self.ranks,
            self.ms_per_step,
            self.cundall,
            self.peak_bytes as f64 / 1e6,
            self.bytes_per_particle,
            self.rebuilds_per_100_steps,
            self.contacts_per_particle,
            self.slots_per_particle,
            100.0 * self.lists_share,
            100.0 * self.pairs_share,
            100.0 * self.exchange_share
        )
    }
}
