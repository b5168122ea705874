//! A run's frames as the tools read them: the particles of each (clumps as their spheres),
//! its time, and the meshes as they were then (moving parts at the frame's time, servos
//! where the run's log has them).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::engine::Simulation;
use crate::geometry::mesh::Mesh;
use crate::model::particles::Particles;
use crate::scenario::Scenario;

/// The number of a frame file `particlesNNNNNN.csv` (or `particlesNNNNNN_0.csv`, the
/// first piece of one a split run wrote in pieces).
pub fn frame_number(p: &Path) -> Option<u64> {
    crate::io::pieces::frame_number(p.file_name()?.to_str()?)
}

/// The times of the frames listed in a directory's `frames.csv`, by frame number.
fn frame_times(dir: &Path) -> std::collections::HashMap<u64, f64> {
    let Ok(text) = std::fs::read_to_string(dir.join(crate::io::output::FRAMES)) else {
        return Default::default();
    };
    text.lines()
        .skip(1)
        .filter_map(|l| {
            let v: Vec<&str> = l.split(',').collect();
            Some((v.first()?.parse().ok()?, v.get(2)?.parse().ok()?))
        })
        .collect()
}

/// Each servo's displacement at each frame, from the run's `log.csv` (`meshK_position`).
fn servo_positions(dir: &Path) -> std::collections::HashMap<u64, Vec<(u32, f64)>> {
    let Ok(text) = std::fs::read_to_string(dir.join(crate::io::output::LOG)) else {
        return Default::default();
    };
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default();
    let columns: Vec<(usize, u32)> = (header.split(',').enumerate())
        .filter_map(|(c, name)| {
            let k = name.strip_prefix("mesh")?.strip_suffix("_position")?;
            Some((c, k.parse().ok()?))
        })
        .collect();
    if columns.is_empty() {
        return Default::default();
    }
    lines
        .filter_map(|l| {
            let v: Vec<&str> = l.split(',').collect();
            let at = |&(c, k): &(usize, u32)| Some((k, v.get(c)?.parse().ok()?));
            let positions = columns.iter().map(at).collect::<Option<Vec<_>>>()?;
            Some((v.first()?.parse().ok()?, positions))
        })
        .collect()
}

/// What the tools (pictures, wall stresses) read a run's frames with: the run's simulation (for its
/// meshes at each frame's time and its materials), further mesh files, the frames' times
/// and where its servos were.
pub struct RunFrames {
    /// The run's simulation (none without a scenario), at the last frame asked for.
    pub sim: Option<Simulation>,
    extra: Mesh,
    times: std::collections::HashMap<u64, f64>,
    servos: std::collections::HashMap<u64, Vec<(u32, f64)>>,
}

impl RunFrames {
    /// The source of the frames in `dir`: `scenario` (default: the run's `run.toml`) and
    /// the mesh files `meshes`.
    pub fn open(dir: &Path, scenario: Option<&Path>, meshes: &[PathBuf]) -> Result<RunFrames> {
        let scenario = scenario
            .map(Path::to_path_buf)
            .or_else(|| crate::io::output::run_toml(dir));
        let sim = match &scenario {
            Some(s) => Some(Simulation::new(Scenario {
                particles: None,
                ..Scenario::load(s)?
            })?),
            None => None,
        };
        let mut extra = Mesh::default();
        for m in meshes {
            // Radii do not show in pictures; accept any radius index of an OFF file.
            let part = Mesh::load(m, &[0.0; 1024])?;
            extra.faces.extend(part.faces);
        }
        Ok(RunFrames {
            sim,
            extra,
            times: frame_times(dir),
            servos: servo_positions(dir),
        })
    }

    /// The particles of a frame: a clump's row (with the scenario's templates) as its
    /// spheres.
    pub fn particles_of(&self, frame: &Path) -> Result<Particles> {
        match &self.sim {
            Some(sim) => crate::io::pieces::load_frame_as_grains(frame, &sim.scenario),
            None => Ok(crate::io::pieces::load_frame(frame)?.0),
        }
    }

    /// The time of a frame: from `frames.csv`, else from its number and the scenario.
    pub fn time_of(&self, frame: &Path) -> Option<f64> {
        let k = frame_number(frame)?;
        self.times.get(&k).copied().or_else(|| {
            self.sim.as_ref().map(|sim| {
                let s = &sim.scenario.simulation;
                k as f64 * s.steps_per_frame as f64 * s.timestep
            })
        })
    }

    /// The meshes of `frame`, at its time `t` (servos where the run's log has them).
    pub fn mesh_of(&mut self, frame: &Path, t: Option<f64>) -> Mesh {
        let mut mesh = self.extra.clone();
        if let Some(sim) = self.sim.as_mut() {
            if let Some(at) = frame_number(frame).and_then(|k| self.servos.get(&k)) {
                sim.walls.place_servos(at);
            }
            mesh.faces
                .extend(sim.walls.at(t.unwrap_or(0.0)).faces.iter().copied());
        }
        mesh
    }
}

/// The frames of `path`: itself, or every `particlesNNNNNN.csv` of a directory, in order.
pub fn frames_of(path: &Path) -> Result<Vec<PathBuf>> {
    if !path.is_dir() {
        return Ok(vec![path.to_path_buf()]);
    }
    let mut f: Vec<PathBuf> = std::fs::read_dir(path)
        .with_context(|| format!("cannot read directory {}", path.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter_map(|p| Some(path.join(crate::io::csv::frame_name(frame_number(&p)?))))
        .collect();
    f.sort();
    anyhow::ensure!(
        !f.is_empty(),
        "{}: no frames particlesNNNNNN.csv",
        path.display()
    );
    Ok(f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn servos_are_placed_where_the_log_has_them() {
        let dir = tempfile::tempdir().unwrap();
        let header = crate::io::output::LOG_HEADER;
        let zeros = "0,".repeat(8);
        let log = format!(
            "{header},mesh2_position,mesh2_load,mesh4_position,mesh4_load\n\
         0,0,0.0,{zeros}0.0,0.0,0.0,0.0\n\
         3,300,0.1,{zeros}0.0125,2.5,-0.5,0.0\n"
        );
        std::fs::write(dir.path().join(crate::io::output::LOG), log).unwrap();
        let at = servo_positions(dir.path());
        assert_eq!(at[&3], vec![(2, 0.0125), (4, -0.5)]);
        assert_eq!(at[&0], vec![(2, 0.0), (4, 0.0)]);
        // A run without servos, or without a log: none.
        std::fs::write(
            dir.path().join(crate::io::output::LOG),
            format!("{header}\n"),
        )
        .unwrap();
        assert!(servo_positions(dir.path()).is_empty());
        assert!(servo_positions(&dir.path().join("none")).is_empty());
    }
}
