//! The meshes of a run: the mesh files it is put together from, the parts that move and
//! stage 0, which moves them.

use super::*;

/// `face_part` of a face that does not move.
pub(super) const STATIC: u32 = u32::MAX;

/// A mesh file whose faces follow a prescribed motion.
#[derive(Clone, Debug)]
pub(super) struct MovingPart {
    pub(super) faces: std::ops::Range<usize>,
    pub(super) motion: Motion,
    /// Velocity field at the current time.
    pub(super) velocity: RigidVelocity,
    /// Corners of its faces at rest, to measure how far they moved.
    pub(super) corners: Vec<DVec3>,
    /// Pose at the last neighbour-list rebuild.
    pub(super) pose_at_build: Pose,
}

/// Where a mesh file's faces are in [`Simulation::mesh`]: `[geometry] mesh` first, then the
/// `[[meshes]]` in order.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshFile {
    pub name: String,
    pub faces: std::ops::Range<usize>,
    pub contacts: Contacts,
    /// The point torques on it are taken about: the origin, or the centre of its rotation.
    pub torque_about: DVec3,
    /// The material of its faces.
    pub material: u16,
}

impl Simulation {
    /// Face count and a hash of the rest geometry of each mesh file (shape, radius and
    /// contact mode of its faces, in order).
    pub fn mesh_signatures(&self) -> Vec<(u64, u64)> {
        self.mesh_files
            .iter()
            .map(|file| {
                let faces = &self.rest_faces[file.faces.clone()];
                let text: String = faces
                    .iter()
                    .map(|f| format!("{:?}{:?}{:?};", f.shape, f.radius, f.contacts))
                    .collect();
                (faces.len() as u64, crate::engine::records::hash(&text))
            })
            .collect()
    }

    /// Stage 0: moving mesh parts to their pose at the current time, with their velocity.
    pub(crate) fn move_meshes(&mut self) {
        let t = self.time;
        let mut drift: f64 = 0.0;
        for part in &mut self.moving {
            let pose = part.motion.pose(t);
            for f in part.faces.clone() {
                self.mesh.faces[f] = self.rest_faces[f].moved(&pose);
            }
            part.velocity = part.motion.velocity(t);
            for &c in &part.corners {
                drift = drift.max(pose.point(c).distance(part.pose_at_build.point(c)));
            }
        }
        self.mesh_drift = drift;
    }

    /// Records the mesh pose at a neighbour-list rebuild, and re-bins moved faces.
    pub(super) fn mark_mesh_built(&mut self) {
        let t = self.time;
        for part in &mut self.moving {
            part.pose_at_build = part.motion.pose(t);
        }
        self.mesh_drift = 0.0;
    }

    /// The rest geometry of the mesh (for checkpoint fingerprints).
    pub fn rest_mesh(&self) -> Mesh {
        Mesh {
            faces: self.rest_faces.clone(),
            vertices: self.mesh.vertices.clone(),
        }
    }

    /// The mesh as it is at time `t` (for pictures of frames).
    pub fn mesh_at(&mut self, t: f64) -> &Mesh {
        let now = self.time;
        self.time = t;
        self.move_meshes();
        self.time = now;
        &self.mesh
    }

    /// Whether some part of the mesh moves.
    pub fn mesh_moves(&self) -> bool {
        !self.moving.is_empty()
    }
}
