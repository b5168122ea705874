//! The status of a running run for the user: a line per frame on stderr (with the deep
//! overlaps warned of, the first few in full), and a progress bar on a terminal.

use std::io::IsTerminal;

use super::run::Verbosity;
use crate::engine::{Simulation, Thermo};

/// Per-pair warning lines shown during a run; further pairs are only counted.
const WARNING_LINES: usize = 10;

pub(super) struct Status {
    verbosity: Verbosity,
    bar: Option<indicatif::ProgressBar>,
    warned: usize,
}

impl Status {
    /// The status of a run of `total_steps`, `done` of them taken.
    pub(super) fn new(verbosity: Verbosity, total_steps: u64, done: u64) -> Status {
        let bar = (verbosity == Verbosity::Normal && std::io::stderr().is_terminal()).then(|| {
            let bar = indicatif::ProgressBar::new(total_steps);
            bar.set_style(
                indicatif::ProgressStyle::with_template(
                    "{bar:40} {pos}/{len} steps  {per_sec}  ETA {eta}  {msg}",
                )
                .expect("valid template"),
            );
            bar.set_position(done);
            bar
        });
        Status {
            verbosity,
            bar,
            warned: 0,
        }
    }

    /// The status line of frame `frame` with state `th`, after the new warnings.
    pub(super) fn frame(&mut self, sim: &mut Simulation, frame: u64, th: &Thermo) {
        let fresh = sim.take_new_warnings();
        if self.verbosity != Verbosity::Normal {
            return;
        }
        let mut lines = Vec::new();
        let removed = match th.removed {
            0 => String::new(),
            n => format!("  removed {n}"),
        };
        for w in fresh {
            self.warned += 1;
            if self.warned <= WARNING_LINES {
                lines.push(format!("warning: {w}"));
            }
            if self.warned == WARNING_LINES {
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
            match &self.bar {
                Some(bar) => bar.println(line),
                None => eprintln!("{line}"),
            }
        }
    }

    /// The bar at step `steps` (moved every 100 steps).
    pub(super) fn progress(&self, steps: u64) {
        if let Some(bar) = self.bar.as_ref().filter(|_| steps.is_multiple_of(100)) {
            bar.set_position(steps);
        }
    }

    /// The bar left where it is (a stop).
    pub(super) fn abandon(&self) {
        if let Some(bar) = &self.bar {
            bar.abandon();
        }
    }

    /// The bar cleared (the end of the run).
    pub(super) fn finish(self) {
        if let Some(bar) = self.bar {
            bar.finish_and_clear();
        }
    }
}
