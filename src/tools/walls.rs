//! The load of the grains on each face of the walls (LIGGGHTS's `mesh/surface/stress`), from
//! a frame's contact network: the force on the face, the pressure (compression positive) and
//! the shear stress, as `wall_stressNNNNNN.vtu` (the mesh as it was then, with these as cell
//! arrays) and `.csv` beside the frames.
//!
//! With f the force of a contact on its particle, and n the face's normal turned toward the
//! particle's centre, over a face of area A:
//!
//! ```text
//! F   = −Σ f                          the force on the face
//! p   = Σ f·n / A                     pressure, > 0 where the grains push on it
//! τ   = |Σ (f − (f·n) n)| / A         shear stress
//! ```
//!
//! These are the loads of the frame's state (the law's forces then), not averages over the
//! steps between frames (`walls.csv` averages each mesh file's total).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use glam::DVec3;
use rustc_hash::FxHashMap;

use crate::engine::records::{ContactRecord, Partner};
use crate::geometry::mesh::Mesh;
use crate::model::particles::{Id, Particles};
use crate::tools::frames::{RunFrames, frame_number, frames_of};

/// The load on one face.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FaceLoad {
    /// The force of the grains on the face \[N\].
    pub force: DVec3,
    /// \[Pa\]; 0 on faces without area (points, edges).
    pub pressure: f64,
    pub shear: f64,
    pub contacts: u32,
}

/// The load on each face of `mesh` from the `contacts` of the particles `p`.
pub fn face_loads(mesh: &Mesh, p: &Particles, contacts: &[ContactRecord]) -> Vec<FaceLoad> {
    let at: FxHashMap<Id, usize> = p.id.iter().enumerate().map(|(k, &id)| (id, k)).collect();
    let mut normal = vec![0.0; mesh.faces.len()];
    let mut tangential = vec![DVec3::ZERO; mesh.faces.len()];
    let mut loads = vec![FaceLoad::default(); mesh.faces.len()];
    for c in contacts {
        let (Partner::Face(f), Some(&i)) = (c.with, at.get(&c.id)) else {
            continue;
        };
        let Some(load) = loads.get_mut(f) else {
            continue;
        };
        let force = c.f_n + c.f_t;
        load.force -= force;
        load.contacts += 1;
        if let Some(n) = mesh.faces[f].normal() {
            let n = if n.dot(p.x[i] - c.point) < 0.0 { -n } else { n };
            normal[f] += force.dot(n);
            tangential[f] += force - n * force.dot(n);
        }
    }
    for (f, load) in loads.iter_mut().enumerate() {
        let area = mesh.faces[f].area();
        if area > 0.0 {
            load.pressure = normal[f] / area;
            load.shear = tangential[f].length() / area;
        }
    }
    loads
}

/// The wall stresses of every frame of `dir` that has its contact network (the run's
/// scenario `scenario`, default its `run.toml`), written beside them; the files written.
pub fn of_directory(dir: &Path, scenario: Option<&Path>) -> Result<Vec<PathBuf>> {
    let mut run = RunFrames::open(dir, scenario, &[])?;
    let Some(sim) = &run.sim else {
        bail!(
            "{}: no run.toml: give the run's scenario (--scenario)",
            dir.display()
        );
    };
    let files: Vec<(String, std::ops::Range<usize>)> = (sim.walls.files.iter())
        .map(|f| (f.name.clone(), f.faces.clone()))
        .collect();
    let mut written = Vec::new();
    for frame in frames_of(dir)? {
        let k = frame_number(&frame).expect("a frame's name");
        let network = dir.join(format!("contacts{k:06}.csv"));
        if !network.exists() && !dir.join(format!("contacts{k:06}_0.csv")).exists() {
            continue;
        }
        let contacts = crate::io::pieces::load_network(&network)?;
        let p = run.particles_of(&frame)?;
        let t = run.time_of(&frame);
        let mesh = run.mesh_of(&frame, t);
        let loads = face_loads(&mesh, &p, &contacts);
        written.extend(write(dir, k, &mesh, &loads, &files)?);
    }
    if written.is_empty() {
        bail!(
            "{}: no frame has its contact network: the wall stresses need [output] contacts = true",
            dir.display()
        );
    }
    Ok(written)
}

/// Writes frame `k`'s `wall_stressNNNNNN.vtu` and `.csv` (a row per face, with its mesh file
/// of `files`).
fn write(
    dir: &Path,
    k: u64,
    mesh: &Mesh,
    loads: &[FaceLoad],
    files: &[(String, std::ops::Range<usize>)],
) -> Result<[PathBuf; 2]> {
    let vtu = dir.join(format!("wall_stress{k:06}.vtu"));
    let force: Vec<f64> = loads.iter().flat_map(|l| l.force.to_array()).collect();
    let column = |f: fn(&FaceLoad) -> f64| loads.iter().map(f).collect::<Vec<f64>>();
    crate::io::vtk::write_mesh_with(
        &vtu,
        mesh,
        &[
            ("force", 3, &force),
            ("pressure", 1, &column(|l| l.pressure)),
            ("shear_stress", 1, &column(|l| l.shear)),
            ("contacts", 1, &column(|l| l.contacts as f64)),
        ],
    )?;
    let csv = dir.join(format!("wall_stress{k:06}.csv"));
    let file_of = |f: usize| files.iter().position(|(_, r)| r.contains(&f)).unwrap_or(0);
    crate::io::files::write_atomically(&csv, |w| {
        use std::io::Write;
        writeln!(w, "face,mesh,area,fx,fy,fz,pressure,shear_stress,contacts")?;
        for (f, l) in loads.iter().enumerate() {
            writeln!(
                w,
                "{f},{},{:e},{:e},{:e},{:e},{:e},{:e},{}",
                file_of(f),
                mesh.faces[f].area(),
                l.force.x,
                l.force.y,
                l.force.z,
                l.pressure,
                l.shear,
                l.contacts
            )?;
        }
        Ok(())
    })
    .with_context(|| format!("cannot write {}", csv.display()))?;
    Ok([vtu, csv])
}
