//! `tinydem bench`: the dense-packing benchmark of the paper's Section 5, each
//! configuration in a process of its own.

use anyhow::{Context, Result};
use clap::Args;

use tinydem::parallel::comm::Comm;

#[derive(Args)]
pub struct BenchArgs {
    /// Particle counts (1000, 10000, 100000, 1000000, 10000000).
    #[arg(long, value_delimiter = ',', default_values_t = [1_000, 10_000, 100_000, 1_000_000])]
    sizes: Vec<usize>,
    /// Also run 10^7 particles (about 3 GB of memory).
    #[arg(long)]
    huge: bool,
    /// Thread counts to run each size with (default: 1 and all cores).
    #[arg(long = "workers", value_delimiter = ',')]
    workers: Vec<usize>,
    /// Process counts to split each size over, under `mpirun --oversubscribe` (a build
    /// with the `mpi` feature; default: 1).
    #[arg(long, value_delimiter = ',', default_values_t = [1])]
    ranks: Vec<usize>,
    /// Steps per timed segment (default: about 10^7 particle-steps, at least 100).
    #[arg(long)]
    steps: Option<u64>,
    /// Timed segments per configuration; the median is reported.
    #[arg(long, default_value_t = 3)]
    repeats: usize,
    /// Make each grain of the packing a clump of this many spheres (1 to 4: a sphere, a
    /// dimer, a triangle, a tetrahedron inside the grain's sphere), to measure the cost
    /// per body-step of clumps.
    #[arg(long)]
    clumps: Option<usize>,
    /// With heat transfer: the grains conduct, from 300 K at the floor to 400 K at the top
    /// (to measure what heat costs).
    #[arg(long)]
    heat: bool,
    /// A line added to the bed's `[material]` (repeatable), e.g. `--material
    /// 'rolling_model = "cdt"'`: to measure what a contact model costs.
    #[arg(long = "material")]
    material: Vec<String>,
    /// Keep the energy ledger ([output] energy_ledger), to measure what it costs.
    #[arg(long)]
    ledger: bool,
    /// Run one configuration in this process (used by the benchmark itself).
    #[arg(long, hide = true)]
    pub single: bool,
}

impl BenchArgs {
    /// The table of every configuration; or, with `--single`, the row of one, measured
    /// in this process (on every process under mpirun; the `first` prints it).
    pub fn execute(mut self, world: Option<Box<dyn Comm>>, first: bool) -> Result<()> {
        if self.huge && !self.sizes.contains(&10_000_000) {
            self.sizes.push(10_000_000);
        }
        anyhow::ensure!(self.repeats >= 1, "--repeats must be at least 1");
        if self.single {
            let n = self.sizes[0];
            let steps = self
                .steps
                .unwrap_or(tinydem::tools::bench::default_steps(n));
            let bed = tinydem::tools::bench::Bed {
                n,
                clumps: self.clumps,
                heat: self.heat,
                material: self.material.clone(),
                ledger: self.ledger,
            };
            let m = tinydem::tools::bench::measure(&bed, steps, self.repeats, world)?;
            if first {
                println!("{}", m.row());
            }
            return Ok(());
        }
        anyhow::ensure!(
            self.ranks.iter().all(|&r| r >= 1),
            "--ranks must be at least 1"
        );
        self.in_children()
    }

    /// Runs every (size, workers, ranks) configuration in a child process (or `mpirun` of
    /// several), so that each reports its own peak memory, and prints the table.
    fn in_children(&self) -> Result<()> {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let workers: Vec<usize> = if self.workers.is_empty() {
            let mut w = vec![1, cores];
            w.dedup();
            w
        } else {
            self.workers.clone()
        };
        let exe = std::env::current_exe().context("cannot locate the tinydem executable")?;
        println!("{}", tinydem::tools::bench::Measurement::HEADER);
        for &n in &self.sizes {
            for (&t, &r) in workers
                .iter()
                .flat_map(|t| self.ranks.iter().map(move |r| (t, r)))
            {
                let mut cmd = if r == 1 {
                    std::process::Command::new(&exe)
                } else {
                    let mut c = std::process::Command::new("mpirun");
                    c.args(["--oversubscribe", "-np", &r.to_string()]).arg(&exe);
                    c
                };
                cmd.args(["bench", "--single", "--sizes", &n.to_string()]);
                cmd.args(["--threads", &t.to_string()]);
                cmd.args(["--repeats", &self.repeats.to_string()]);
                if let Some(s) = self.steps {
                    cmd.args(["--steps", &s.to_string()]);
                }
                if let Some(k) = self.clumps {
                    cmd.args(["--clumps", &k.to_string()]);
                }
                if self.heat {
                    cmd.arg("--heat");
                }
                if self.ledger {
                    cmd.arg("--ledger");
                }
                for line in &self.material {
                    cmd.args(["--material", line]);
                }
                let out = cmd.output().context("cannot run the benchmark process")?;
                if !out.status.success() {
                    anyhow::bail!(
                        "benchmark N = {n}, {t} threads, {r} processes failed: {}",
                        String::from_utf8_lossy(&out.stderr).trim()
                    );
                }
                print!("{}", String::from_utf8_lossy(&out.stdout));
            }
        }
        Ok(())
    }
}
