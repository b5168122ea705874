//! `[simulation] until`: the conditions that end a run before its last frame.

/// `[simulation] until`: conditions checked at every frame after the first step; the run
/// ends at the first frame where any holds (`frames` stays the upper bound).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Until {
    /// The kinetic energy, translational and rotational (`log.csv`'s `kinetic_energy`), is
    /// below this \[M L²/T²\], with particles present and none left to spawn.
    pub kinetic_energy_below: Option<f64>,
    /// The run's clock has reached this \[T\].
    pub time: Option<f64>,
    /// At least this many particles were removed (by the outlets and the domain).
    pub removed_at_least: Option<u64>,
    /// Every servo's load (of its last step) is within this fraction of its target.
    pub servo_within: Option<f64>,
    /// The run ends where all the conditions set hold at one frame (`combine = "all"`),
    /// rather than any of them.
    pub all: bool,
}

/// The state a frame's check of [`Until`] looks at.
#[derive(Clone, Debug)]
pub struct FrameState {
    pub time: f64,
    pub kinetic_energy: f64,
    pub particles: usize,
    /// Particles still to be spawned after this step.
    pub spawning: bool,
    pub removed: u64,
    /// Each servo's mesh file, its load of the last step and its target \[N\].
    pub servos: Vec<(usize, f64, f64)>,
}

impl Until {
    /// Whether no condition is set.
    pub fn is_empty(&self) -> bool {
        self.conditions() == 0
    }

    /// How many conditions are set.
    pub fn conditions(&self) -> usize {
        [
            self.kinetic_energy_below.is_some(),
            self.time.is_some(),
            self.removed_at_least.is_some(),
            self.servo_within.is_some(),
        ]
        .iter()
        .filter(|&&set| set)
        .count()
    }

    /// The condition that holds in state `s`: the first of them, or, with `all`, every one
    /// set (said together, as `all`).
    pub fn met(&self, s: &FrameState) -> Option<Met> {
        let held = self.holding(s);
        if !self.all {
            return held.into_iter().next();
        }
        if held.len() < self.conditions() || held.is_empty() {
            return None;
        }
        let said: Vec<String> = held
            .iter()
            .map(|m| format!("{}: {}", m.key, m.said))
            .collect();
        Some(Met {
            key: "all",
            said: said.join("; "),
        })
    }

    /// Each condition set that holds in state `s`, in the order of the keys.
    fn holding(&self, s: &FrameState) -> Vec<Met> {
        let mut held = Vec::new();
        if let Some(e) = self.kinetic_energy_below
            && s.particles > 0
            && !s.spawning
            && s.kinetic_energy < e
        {
            held.push(Met {
                key: "kinetic_energy_below",
                said: format!("kinetic energy {:.4e} J below {e:e} J", s.kinetic_energy),
            });
        }
        if let Some(t) = self.time
            && s.time >= t
        {
            held.push(Met {
                key: "time",
                said: format!("t = {:.6e} s reached {t:e} s", s.time),
            });
        }
        if let Some(n) = self.removed_at_least
            && s.removed >= n
        {
            held.push(Met {
                key: "removed_at_least",
                said: format!("{} removed, at least {n}", s.removed),
            });
        }
        if let Some(f) = self.servo_within
            && !s.servos.is_empty()
            && s.servos
                .iter()
                .all(|&(_, load, target)| (load - target).abs() <= f * target)
        {
            let loads: Vec<String> = (s.servos.iter())
                .map(|(k, load, target)| format!("mesh {k}: {load:.6e} N of {target:.6e} N"))
                .collect();
            held.push(Met {
                key: "servo_within",
                said: format!(
                    "every servo within {f:e} of its target ({})",
                    loads.join("; ")
                ),
            });
        }
        held
    }
}

/// A condition of [`Until`] that held: its key, and what held.
#[derive(Clone, Debug, PartialEq)]
pub struct Met {
    pub key: &'static str,
    pub said: String,
}

impl std::fmt::Display for Met {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "until.{}: {}", self.key, self.said)
    }
}
