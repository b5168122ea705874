//! The walls of a run (`Walls`): the mesh files it is put together from, the parts that
//! move and stage 0, which moves them; the loads on each file.

use super::*;

/// `face_part` of a face that does not move.
const STATIC: u32 = u32::MAX;

/// What moves a part of the mesh: a prescribed motion, a function of time, or a servo,
/// which follows the load of the particles on its mesh file (`file`).
#[derive(Clone, Copy, Debug)]
pub(super) enum Drive {
    Prescribed(Motion),
    Servo {
        control: servo::Control,
        state: servo::State,
        file: usize,
    },
}

impl Drive {
    /// The pose at time `t` (a servo's: where it is now).
    fn pose(&self, t: f64) -> Pose {
        match self {
            Drive::Prescribed(m) => m.pose(t),
            Drive::Servo { control, state, .. } => control.pose(state.position),
        }
    }

    /// The velocity field at time `t` (a servo's: its speed now).
    fn velocity(&self, t: f64) -> RigidVelocity {
        match self {
            Drive::Prescribed(m) => m.velocity(t),
            Drive::Servo { control, state, .. } => control.velocity(state.speed),
        }
    }
}

/// A mesh file whose faces move.
#[derive(Clone, Debug)]
pub(super) struct MovingPart {
    pub(super) faces: std::ops::Range<usize>,
    pub(super) drive: Drive,
    /// Pose and velocity field at the current time.
    pub(super) pose: Pose,
    pub(super) velocity: RigidVelocity,
    /// Corners of its faces at rest, to measure how far they moved.
    pub(super) corners: Vec<DVec3>,
    /// Pose at the last neighbour-list rebuild.
    pub(super) pose_at_build: Pose,
}

/// Where a mesh file's faces are in [`Walls::mesh`]: `[geometry] mesh` first, then the
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
    /// Its reference point at rest (`walls.csv`): the mean of its faces' corners.
    pub center: DVec3,
}

impl MeshFile {
    /// The mean of the corners of `faces` (the origin if there are none).
    pub fn center_of(faces: &[Face]) -> DVec3 {
        let corners: Vec<DVec3> = faces.iter().flat_map(Face::corners).collect();
        match corners.len() {
            0 => DVec3::ZERO,
            n => corners.iter().sum::<DVec3>() / n as f64,
        }
    }
}

/// The walls of a run: the mesh as it is now, the files it is put together from, the parts
/// that move, what each face belongs to, and the loads the particles put on each file.
#[derive(Clone, Debug)]
pub struct Walls {
    /// The mesh at the current time (its moving parts posed).
    pub mesh: Mesh,
    /// The mesh files `mesh` was put together from.
    pub files: Vec<MeshFile>,
    /// The mesh as read (at t = 0).
    pub(super) rest_faces: Vec<Face>,
    /// Parts of the mesh that follow a prescribed motion.
    pub(super) moving: Vec<MovingPart>,
    /// For each face, its moving part, or `STATIC`.
    pub(super) face_part: Vec<u32>,
    /// Largest displacement of a moving face since the last neighbour-list rebuild.
    pub(super) drift: f64,
    /// For each face, its mesh file (an index of `files`).
    pub(super) face_file: Vec<u32>,
    /// The heat into each mesh file \[quanta of the heat model\] since the last
    /// [`Walls::take_heat`] (over all processes).
    pub(super) heat: Vec<i128>,
    /// For each face, its material.
    pub(super) face_material: Vec<u16>,
    /// The loads on each mesh file summed over the steps since the last
    /// [`Walls::take_loads`] (`[output] wall_forces`): each step's exactly (over all
    /// contacts, and all processes), then the steps in order.
    pub(super) sums: Vec<Wrench>,
    /// The resolutions of the wall loads' sums of a step.
    pub(super) scales: Scales8,
}

impl Walls {
    /// `mesh`, static, as one file of faces of `material`, whose loads are not summed.
    pub(super) fn of(mesh: Mesh, material: u16) -> Walls {
        let n = mesh.faces.len();
        Walls {
            files: vec![MeshFile {
                name: "mesh".into(),
                faces: 0..n,
                contacts: mesh
                    .faces
                    .first()
                    .map_or_else(Contacts::default, |f| f.contacts),
                torque_about: DVec3::ZERO,
                material,
                center: MeshFile::center_of(&mesh.faces),
            }],
            rest_faces: mesh.faces.clone(),
            moving: Vec::new(),
            face_part: vec![STATIC; n],
            drift: 0.0,
            face_file: Vec::new(),
            heat: Vec::new(),
            face_material: vec![material; n],
            sums: Vec::new(),
            scales: Scales8::new([Scale::for_largest(1.0); 8]),
            mesh,
        }
    }

    /// The faces `faces` follow `drive` from now on.
    pub(super) fn add_moving(&mut self, faces: std::ops::Range<usize>, drive: Drive) {
        for f in faces.clone() {
            self.face_part[f] = self.moving.len() as u32;
        }
        let corners = self.rest_faces[faces.clone()]
            .iter()
            .flat_map(Face::corners)
            .collect();
        self.moving.push(MovingPart {
            faces,
            drive,
            pose: Pose::REST,
            velocity: RigidVelocity::default(),
            corners,
            pose_at_build: Pose::REST,
        });
    }

    /// Face count and a hash of the rest geometry of each mesh file (shape, radius and
    /// contact mode of its faces, in order).
    pub fn signatures(&self) -> Vec<(u64, u64)> {
        self.files
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

    /// Stage 0: the moving parts to their pose at time `t`, with their velocity.
    pub(super) fn move_to(&mut self, t: f64) {
        let mut drift: f64 = 0.0;
        for part in &mut self.moving {
            let pose = part.drive.pose(t);
            for f in part.faces.clone() {
                self.mesh.faces[f] = self.rest_faces[f].moved(&pose);
            }
            part.velocity = part.drive.velocity(t);
            part.pose = pose;
            for &c in &part.corners {
                drift = drift.max(pose.point(c).distance(part.pose_at_build.point(c)));
            }
        }
        self.drift = drift;
    }

    /// Records the pose at time `t` as that of a neighbour-list rebuild.
    pub(super) fn mark_built(&mut self, t: f64) {
        for part in &mut self.moving {
            part.pose_at_build = part.drive.pose(t);
            if let Drive::Servo { state, .. } = &mut part.drive {
                state.built = state.position;
            }
        }
        self.drift = 0.0;
    }

    /// The servos' states, with their mesh files (ascending).
    pub fn servos(&self) -> Vec<(u32, servo::State)> {
        let state = |p: &MovingPart| match p.drive {
            Drive::Servo { state, file, .. } => Some((file as u32, state)),
            Drive::Prescribed(_) => None,
        };
        self.moving.iter().filter_map(state).collect()
    }

    /// Each servo's mesh file, control law and state.
    pub fn servo_controls(&self) -> Vec<(usize, servo::Control, servo::State)> {
        let servo = |p: &MovingPart| match p.drive {
            Drive::Servo {
                control,
                state,
                file,
            } => Some((file, control, state)),
            Drive::Prescribed(_) => None,
        };
        self.moving.iter().filter_map(servo).collect()
    }

    /// Sets the states of the servos of the files `states` names (from a checkpoint, or back
    /// after [`Walls::rewind_servos`]).
    pub(super) fn set_servos(&mut self, states: &[(u32, servo::State)]) {
        for part in &mut self.moving {
            if let Drive::Servo { state, file, .. } = &mut part.drive
                && let Some(&(_, s)) = states.iter().find(|s| s.0 as usize == *file)
            {
                *state = s;
            }
        }
    }

    /// Puts the servos of the files `positions` names at those displacements (for pictures
    /// of a run's frames, from its `log.csv`); stage 0 or [`Walls::at`] poses the mesh.
    pub fn place_servos(&mut self, positions: &[(u32, f64)]) {
        let states: Vec<(u32, servo::State)> = (positions.iter())
            .map(|&(k, position)| {
                let state = servo::State {
                    position,
                    ..Default::default()
                };
                (k, state)
            })
            .collect();
        self.set_servos(&states);
    }

    /// The servos back where they were at the last rebuild (for the lists to be built
    /// again as then, with the clock there too); their states now, to set back after.
    pub(super) fn rewind_servos(&mut self) -> Vec<(u32, servo::State)> {
        let now = self.servos();
        for part in &mut self.moving {
            if let Drive::Servo { state, .. } = &mut part.drive {
                state.position = state.built;
            }
        }
        now
    }

    /// After a step's contacts, whose loads on each file are `step`: each servo's speed
    /// from the load on its file, then its position.
    pub(super) fn drive_servos(&mut self, step: &[Sum6], dt: f64) {
        for part in &mut self.moving {
            if let Drive::Servo {
                control,
                state,
                file,
            } = &mut part.drive
            {
                let [fx, fy, fz, ..] = step[*file].value(&self.scales);
                *state = control.advance(*state, DVec3::new(fx, fy, fz), dt);
            }
        }
    }

    /// The velocity field of face `f` (zero for a static one).
    #[inline]
    pub(super) fn velocity(&self, f: usize) -> RigidVelocity {
        match self.face_part[f] {
            STATIC => RigidVelocity::default(),
            part => self.moving[part as usize].velocity,
        }
    }

    /// The rest geometry of the mesh (for checkpoint fingerprints).
    pub fn rest_mesh(&self) -> Mesh {
        Mesh {
            faces: self.rest_faces.clone(),
            vertices: self.mesh.vertices.clone(),
        }
    }

    /// The mesh as it is at time `t` (for pictures of frames); the walls are then at `t`
    /// until stage 0 of the next step poses them again.
    pub fn at(&mut self, t: f64) -> &Mesh {
        let drift = self.drift;
        self.move_to(t);
        self.drift = drift;
        &self.mesh
    }

    /// Where the reference point of mesh file `k` (its [`MeshFile::center`]) is now.
    pub fn reference(&self, k: usize) -> DVec3 {
        let file = &self.files[k];
        match self.moving.iter().find(|p| p.faces == file.faces) {
            Some(part) => part.pose.point(file.center),
            None => file.center,
        }
    }

    /// Whether some part of the mesh moves.
    pub fn move_at_all(&self) -> bool {
        !self.moving.is_empty()
    }

    /// The loads on each mesh file summed over the steps since the last call, and the
    /// sums set back to zero (empty unless `[output] wall_forces`).
    pub fn take_loads(&mut self) -> Vec<Wrench> {
        let zero = vec![Wrench::default(); self.sums.len()];
        std::mem::replace(&mut self.sums, zero)
    }

    /// The heat into each mesh file since the last call (in quanta), and the sums set back
    /// to zero.
    pub fn take_heat(&mut self) -> Vec<i128> {
        let zero = vec![0; self.heat.len()];
        std::mem::replace(&mut self.heat, zero)
    }

    /// Adds a step's exact sums of the loads on each file (over all processes).
    pub(super) fn add_step(&mut self, step: &[Sum6]) {
        for (sum, w) in self.sums.iter_mut().zip(step) {
            let [fx, fy, fz, tx, ty, tz] = w.value(&self.scales);
            *sum += Wrench {
                f: DVec3::new(fx, fy, fz),
                tau: DVec3::new(tx, ty, tz),
            };
        }
    }
}
