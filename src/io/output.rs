//! The output directory of a run: the names of the files in it, its claim (the lock first,
//! then the refusal of another run's output), and the scenario a directory's run was made
//! with (`run.toml`).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::io::checkpoint;
use crate::io::lock::Lock;

/// Name of the checkpoint file in the output directory.
pub const CHECKPOINT: &str = "checkpoint.bin";
/// Name of the frame written when a run is interrupted between frames.
pub const INTERRUPTED: &str = "interrupted.csv";
/// Name of the frame written when a run becomes unstable.
pub const UNSTABLE: &str = "unstable.csv";
/// Name of the log of particles removed by each outlet (`frame,time,outlet,count,mass`).
pub const OUTLETS: &str = "outlets.csv";
/// Name of the log of the loads on each mesh file (`frame,time,mesh,x,y,z,fx,fy,fz,tx,ty,tz`).
pub const WALLS: &str = "walls.csv";
/// Name of the list of frames written (`frame,step,time`).
pub const FRAMES: &str = "frames.csv";
/// Name of the log of the state at each frame (the columns of [`LOG_HEADER`]).
pub const LOG: &str = "log.csv";
/// The columns of `log.csv`: what the status line shows, as LAMMPS's thermo output.
pub const LOG_HEADER: &str = "frame,step,time,particles,kinetic_energy,rotational_energy,\
contacts_per_particle,pair_contacts,wall_contacts,max_overlap,removed";
/// Name of the resolved scenario of the run in its output directory.
pub const RUN_TOML: &str = "run.toml";

/// The `run.toml` an output directory holds, if any: the scenario of the run that wrote it.
pub fn run_toml(dir: &Path) -> Option<PathBuf> {
    let p = dir.join(RUN_TOML);
    p.is_file().then_some(p)
}

/// Takes the output directory (creating it): its lock first, so that a refused run
/// changes nothing there; then removes temporary files a killed run may have left and fails
/// early, before simulating, if the directory cannot be written.
pub fn take_output(dir: &Path) -> Result<Lock> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create output directory {}", dir.display()))?;
    let lock = Lock::take(dir)?;
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            let name = e.file_name();
            let name = name.to_string_lossy();
            if name.starts_with('.') && name.ends_with(".tmp") {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
    let probe = dir.join(".tinydem-write-test");
    std::fs::write(&probe, b"")
        .with_context(|| format!("output directory {} is not writable", dir.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(lock)
}

/// Whether a file name is output a run writes (frames, logs, checkpoints, its scenario), or
/// what the tools make of it beside its frames (pictures and animations, fields), which a
/// new run into the directory would leave stale.
pub fn is_run_output(name: &str) -> bool {
    // `prefixNNNNNN.ext`, or `prefixNNNNNN_K.ext`, piece K of a frame of a split run.
    let frame = |prefix: &str| {
        name.strip_prefix(prefix).is_some_and(|rest| {
            let number = rest.split('.').next().unwrap_or("");
            let digits = |d: &str| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit());
            match number.split_once('_') {
                Some((frame, piece)) => digits(frame) && digits(piece),
                None => digits(number),
            }
        })
    };
    frame("particles")
        || checkpoint::is_part(name)
        || frame("contacts")
        || frame("mesh")
        || frame("fields")
        || frame("wall_stress")
        || ["x", "y", "z"].iter().any(|a| {
            frame(&format!("slices_{a}")) || name.starts_with(&format!("slices_{a}_mean."))
        })
        || [
            RUN_TOML,
            FRAMES,
            LOG,
            OUTLETS,
            WALLS,
            CHECKPOINT,
            INTERRUPTED,
            UNSTABLE,
            "mesh.vtu",
            "particles.pvd",
            "mesh.pvd",
            "contacts.pvd",
            "animation.gif",
            "animation.mp4",
            "fields_mean.vti",
            "fields_mean.csv",
        ]
        .contains(&name)
}

/// Refuses a directory holding the output of an earlier run (frames would mix), unless
/// `overwrite`, which removes that output first (and nothing else).
pub fn claim_output(dir: &Path, overwrite: bool) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    let old: Vec<PathBuf> = entries
        .flatten()
        .filter(|e| is_run_output(&e.file_name().to_string_lossy()))
        .map(|e| e.path())
        .collect();
    if old.is_empty() {
        return Ok(());
    }
    if !overwrite {
        // (An io error of its kind, so that Python raises FileExistsError.)
        return Err(std::io::Error::new(
            std::io::ErrorKind::AlreadyExists,
            format!(
                "{} holds the output of an earlier run ({} files, e.g. {}): pass --overwrite to replace it, --resume to continue it, or --output another directory",
                dir.display(),
                old.len(),
                old[0].file_name().unwrap_or_default().to_string_lossy()
            ),
        )
        .into());
    }
    for p in old {
        std::fs::remove_file(&p).with_context(|| format!("cannot remove {}", p.display()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::is_run_output;

    #[test]
    fn frames_their_pieces_and_listings_are_run_output() {
        for name in [
            "particles000003.csv",
            "particles000003_1.csv",
            "particles000003_12.vtu",
            "particles000003.pvtu",
            "contacts000003_0.vtp",
            "contacts000003.pvtp",
            "checkpoint.bin.40.part-1-of-2",
        ] {
            assert!(is_run_output(name), "{name}");
        }
        for name in [
            "particles_a.csv",
            "particles000003_.csv",
            "notes.csv",
            "bed.csv",
        ] {
            assert!(!is_run_output(name), "{name}");
        }
    }
}
