//! Making a simulation: from a scenario and what its files hold (`from_inputs`,
//! `from_parts`), from a checkpoint of the same run (`restore_from`: bit for bit) or as a
//! new stage after another run (`stage_from`). The constructors that read the files first
//! (`new`, `restore`, `stage`) are in `io/inputs.rs`.

use super::*;
use anyhow::Context;

/// What the files a scenario names hold, read (`io::inputs`): the main mesh (`[geometry]
/// mesh`) and each `[[meshes]]` file in order, each with its name, and the initial
/// particles (`[input] particles`).
pub struct Inputs {
    pub meshes: Vec<(Mesh, String)>,
    pub particles: Particles,
}

impl Simulation {
    /// Sets up a simulation from a scenario and what its files hold.
    pub fn from_inputs(scenario: Scenario, inputs: Inputs) -> Result<Simulation> {
        let g = &scenario.geometry;
        let mut meshes = inputs.meshes.into_iter();
        let (mut mesh, name) = meshes.next().unwrap_or_default();
        mesh = mesh.with_contacts(g.mesh_contacts);
        let mut files = vec![MeshFile {
            name,
            faces: 0..mesh.faces.len(),
            contacts: g.mesh_contacts,
            torque_about: DVec3::ZERO,
            material: g.mesh_material,
            center: MeshFile::center_of(&mesh.faces),
        }];
        let mut moving = Vec::new();
        for (k, (spec, (part, _))) in scenario.meshes.iter().zip(meshes).enumerate() {
            let part = part.with_contacts(spec.contacts);
            let faces = mesh.faces.len()..mesh.faces.len() + part.faces.len();
            if let Some(motion) = spec.motion {
                moving.push((faces.clone(), Drive::Prescribed(motion)));
            }
            if let Some(servo) = spec.servo {
                let control = servo_control(&scenario, servo, spec.material, &part.faces)
                    .with_context(|| format!("[[meshes]] #{} motion", k + 1))?;
                let state = servo::State::default();
                let file = k + 1;
                moving.push((
                    faces.clone(),
                    Drive::Servo {
                        control,
                        state,
                        file,
                    },
                ));
            }
            files.push(MeshFile {
                name: spec.input.name(),
                faces,
                contacts: spec.contacts,
                torque_about: match spec.motion {
                    Some(Motion::Rotation { center, .. }) => center,
                    _ => DVec3::ZERO,
                },
                material: spec.material,
                center: MeshFile::center_of(&part.faces),
            });
            mesh.append(part);
        }
        let mut sim = Simulation::from_parts(scenario, mesh, inputs.particles)?;
        let w = &mut sim.walls;
        w.files = files;
        for file in &w.files {
            w.face_material[file.faces.clone()].fill(file.material);
        }
        sim.sum_wall_loads();
        sim.start_heat()?;
        for (faces, drive) in moving {
            sim.walls.add_moving(faces, drive);
        }
        sim.walls.move_to(sim.time);
        Ok(sim)
    }

    /// Continues a run from a snapshot taken by [`Simulation::snapshot`] with the same
    /// scenario (and its meshes in `inputs`; the particles are the snapshot's): the result
    /// is bitwise the same as if the run had not stopped.
    pub fn restore_from(
        scenario: Scenario,
        inputs: Inputs,
        snapshot: Snapshot,
    ) -> Result<Simulation> {
        let input = scenario.particles.clone();
        let mut sim = Simulation::from_inputs(
            Scenario {
                particles: None,
                ..scenario
            },
            inputs,
        )?;
        // The particles come from the snapshot; the scenario keeps its input file, so that
        // its `run.toml` reruns the run.
        sim.scenario.particles = input;
        sim.check_same_run(&snapshot).map_err(misfit)?;
        let history = Histories {
            pairs: History::in_storage(&snapshot.particles, &snapshot.pair_history, true)
                .map_err(misfit)?,
            faces: History::in_storage(&snapshot.particles, &snapshot.face_history, false)
                .map_err(misfit)?,
        };
        sim.particles = snapshot.particles;
        sim.start_heat()?;
        sim.neighbours.state = snapshot.contact_state;
        sim.spawner = Spawner::resume(sim.scenario.simulation.seed, snapshot.spawner);
        sim.removed.domain = snapshot.removed.domain;
        sim.removed.outlets[..snapshot.removed.outlets.len()]
            .copy_from_slice(&snapshot.removed.outlets);
        if !sim.walls.sums.is_empty() && snapshot.wall_sums.len() == sim.walls.sums.len() {
            sim.walls.sums = snapshot.wall_sums;
        }
        sim.walls.set_servos(&snapshot.servos);
        if sim.model.heat.is_some() && snapshot.wall_heat.len() == sim.walls.heat.len() {
            sim.walls.heat = snapshot.wall_heat;
        }
        // The ledger goes on where it was (a run that did not keep it starts it here).
        if let (Some(books), Some(kept)) = (&mut sim.books, &snapshot.ledger) {
            books.resume(kept);
        }
        let dt = sim.scenario.simulation.timestep;
        if snapshot.anchors.is_empty() {
            // Taken before the first step: the lists are made as that step would make them.
            sim.steps = snapshot.steps;
            sim.time = sim.steps as f64 * dt;
            sim.walls.move_to(sim.time);
            let state = sim.neighbours.state;
            sim.neighbours =
                Neighbours::with_periodic(sim.neighbours.skin, sim.neighbours.periodic);
            sim.neighbours.state = state;
            return Ok(sim);
        }
        // The lists of the last rebuild, built again with the mesh (and sheared images)
        // where they were then.
        (sim.steps, sim.time) = (snapshot.steps, snapshot.steps as f64 * dt);
        let now = sim.rewind_to(snapshot.built_at);
        sim.rebuild_as_built(snapshot.anchors, snapshot.lonely, &history);
        sim.wind_on(now);
        Ok(sim)
    }

    /// A process's share of a checkpoint in parts (`checkpoint::load_share`), restored as
    /// [`Simulation::restore_from`] restores a whole one, for
    /// [`Simulation::split_shares_with`]: with the springs of its particles' contacts with
    /// particles of other shares beside it, for the split to send to their owners.
    pub fn restore_share_from(
        scenario: Scenario,
        inputs: Inputs,
        mut snapshot: Snapshot,
    ) -> Result<(Simulation, Entries)> {
        let index = IdIndex::of(&snapshot.particles);
        let held = |id: Id| index.get(id).is_some();
        let (pairs, pending) = std::mem::take(&mut snapshot.pair_history)
            .into_iter()
            .partition(|e| held(e.0) && held(e.1));
        drop(index);
        snapshot.pair_history = pairs;
        let built_at = snapshot.built_at;
        let mut sim = Simulation::restore_from(scenario, inputs, snapshot)?;
        // A share of no particles has no anchors: its clock of the last rebuild is still
        // that of all, for the split's rebuild to place the walls alike.
        sim.built_at = built_at;
        Ok((sim, (pending, Vec::new())))
    }

    /// Why `snapshot` cannot continue this run, if it cannot: its counts of particles and
    /// anchors, materials, [[spawn]] regions, mesh files, outlets and faces must fit.
    fn check_same_run(&self, snapshot: &Snapshot) -> std::result::Result<(), String> {
        let n = snapshot.particles.len();
        if !snapshot.anchors.is_empty() && snapshot.anchors.len() != n {
            return Err("one anchor per particle".into());
        }
        check_materials(&snapshot.particles, &self.scenario).map_err(|e| format!("{e:#}"))?;
        let (regions, spawn) = (snapshot.spawner.regions.len(), self.scenario.spawn.len());
        if regions > spawn {
            return Err(format!(
                "it counts the insertions of {regions} [[spawn]] regions, the scenario has {spawn}"
            ));
        }
        let (sums, files) = (snapshot.wall_sums.len(), self.walls.files.len());
        if sums != 0 && sums != files {
            return Err(format!(
                "it sums the loads on {sums} mesh files, the scenario has {files}"
            ));
        }
        let (outlets, have) = (snapshot.removed.outlets.len(), self.removed.outlets.len());
        if outlets > have {
            return Err(format!(
                "it counts {outlets} outlets, the scenario has {have}"
            ));
        }
        let faces = self.walls.mesh.faces.len();
        if let Some(&(_, f, _)) = snapshot.face_history.iter().find(|e| e.1 as usize >= faces) {
            return Err(format!("contact with face {f}, which the mesh lacks"));
        }
        let files = |s: &[(u32, servo::State)]| s.iter().map(|s| s.0).collect::<Vec<_>>();
        let (held, have) = (files(&snapshot.servos), files(&self.walls.servos()));
        if held != have {
            return Err(format!(
                "it holds servos on mesh files {held:?}, the scenario has them on {have:?}"
            ));
        }
        Ok(())
    }

    /// Builds the lists again as a run had them at its last rebuild: from the particles'
    /// `anchors` (their positions then), with its `lonely` particles' allowances and the
    /// contact `history` it held.
    fn rebuild_as_built(
        &mut self,
        anchors: Vec<DVec3>,
        lonely: Vec<(u32, f64)>,
        history: &Histories,
    ) {
        self.regrid_faces();
        self.neighbours.restore(
            &self.particles,
            anchors,
            lonely,
            &self.walls.mesh.faces,
            &self.face_grid,
            history,
        );
        self.built();
    }

    /// Starts a new stage of a study from the snapshot of another run (`tinydem run NEXT
    /// --from CHECKPOINT`): the particles (ids, materials, tags) and all their contact
    /// history are the snapshot's, everything else is `scenario`'s, whose clock starts at 0
    /// (its meshes start their motions at rest, its frames count from 0). Contacts with a
    /// mesh file are carried when `scenario` has the same file (the same faces), wherever
    /// it stands in the list; the spawner continues its random stream if the seed is the
    /// same. When the mesh is the same too, the lists are rebuilt as the run had them, so a
    /// stage that only adds frames gives the bits of one uninterrupted run. Returns what was
    /// carried and dropped, for the user. `scenario` names no particle file (`stage`
    /// refuses one).
    pub fn stage_from(
        scenario: Scenario,
        inputs: Inputs,
        snapshot: Snapshot,
    ) -> Result<(Simulation, Vec<String>)> {
        let mut sim = Simulation::from_inputs(scenario, inputs)?;
        let p = snapshot.particles;
        check_materials(&p, &sim.scenario).map_err(|e| misfit(format!("{e:#}")))?;
        check_clumps(&p, &sim.scenario).map_err(|e| misfit(format!("{e:#}")))?;
        let mut notes = vec![sim.continue_spawner(&snapshot.scenario, snapshot.spawner)?];
        let g = &sim.scenario.geometry;
        if sim.scenario.spawn.is_empty()
            && !g.spawn_box_named
            && sim.spawner.active(&sim.scenario, 0, 0.0)
        {
            sim.spawner.box_off = true;
            notes.push(
                "nothing is spawned: the scenario has no [[spawn]] region and names no spawn box"
                    .into(),
            );
        }
        let new_files = sim.walls.signatures();
        let face_history = sim.carried_face_contacts(&snapshot.mesh_files, &snapshot.face_history);
        let dropped = snapshot.face_history.len() - face_history.len();
        notes.push(format!(
            "carried {} particles, {} particle contacts and {} contacts with meshes{}",
            p.len(),
            snapshot.pair_history.len(),
            face_history.len(),
            if dropped > 0 {
                format!(" ({dropped} with mesh files this scenario lacks were dropped)")
            } else {
                String::new()
            }
        ));
        let history = Histories {
            pairs: History::in_storage(&p, &snapshot.pair_history, true).map_err(misfit)?,
            faces: History::in_storage(&p, &face_history, false).map_err(misfit)?,
        };
        let built = !snapshot.anchors.is_empty();
        if built && snapshot.anchors.len() != p.len() {
            return Err(misfit("one anchor per particle".into()));
        }
        sim.particles = p;
        Self::fix_within(&mut sim.particles, &sim.scenario.fixed);
        sim.start_heat()?;
        let servos = sim.carried_servos(&snapshot.mesh_files, &snapshot.servos);
        if !servos.is_empty() {
            notes.push(format!("{} servo(s) carried where they were", servos.len()));
        }
        sim.walls.set_servos(&servos);
        if built {
            // The lists at the positions of the run's last rebuild (the servos there too);
            // the allowances of its lonely particles hold only for the same mesh.
            let lonely = if snapshot.mesh_files == new_files {
                snapshot.lonely
            } else {
                Vec::new()
            };
            let servos = sim.walls.rewind_servos();
            sim.walls.move_to(sim.time);
            sim.rebuild_as_built(snapshot.anchors, lonely, &history);
            sim.walls.set_servos(&servos);
        }
        sim.walls.move_to(sim.time);
        Ok((sim, notes))
    }

    /// Lets the spawner of a stage continue the random stream of the run before it (whose
    /// resolved scenario is `old`, empty if unknown) when the seed is the same; its
    /// [[spawn]] regions are its own, their counts start at 0 with its clock. Says which.
    fn continue_spawner(&mut self, old: &str, state: SpawnerState) -> Result<String> {
        let old_seed = if old.is_empty() {
            None
        } else {
            let old = Scenario::parse(old, std::path::Path::new("checkpoint"))
                .map_err(|e| misfit(format!("its scenario does not parse: {e:#}")))?;
            if old.lees_edwards.is_some() {
                bail!(
                    "a run with Lees-Edwards boundaries cannot start a stage yet (its images would jump back to offset 0): continue it with --resume"
                );
            }
            Some(old.simulation.seed)
        };
        let seed = self.scenario.simulation.seed;
        if old_seed != Some(seed) {
            return Ok(format!(
                "spawning draws from a new random stream (seed {seed})"
            ));
        }
        let state = SpawnerState {
            regions: Vec::new(),
            ..state
        };
        self.spawner = Spawner::resume(seed, state);
        Ok("spawning continues the random stream of the checkpoint".into())
    }

    /// For each mesh file of a run whose files were `old_files` (face count and hash), the
    /// file of this simulation with the same faces, if it has one (found wherever it stands,
    /// each file of this simulation once).
    fn same_files(&self, old_files: &[(u64, u64)]) -> Vec<Option<usize>> {
        let new_files = self.walls.signatures();
        let mut taken = vec![false; new_files.len()];
        old_files
            .iter()
            .map(|old| {
                let found = (0..new_files.len()).find(|&j| !taken[j] && new_files[j] == *old);
                if let Some(j) = found {
                    taken[j] = true;
                }
                found
            })
            .collect()
    }

    /// The contacts with meshes of a run whose mesh files were `old_files` that this
    /// simulation's mesh also has ([`Simulation::same_files`]), with the faces renumbered.
    fn carried_face_contacts(
        &self,
        old_files: &[(u64, u64)],
        face_history: &[Entry],
    ) -> Vec<Entry> {
        let mut face_map: Vec<Option<u32>> = Vec::new();
        for (old, found) in old_files.iter().zip(self.same_files(old_files)) {
            let start = found.map(|j| self.walls.files[j].faces.start as u32);
            face_map.extend((0..old.0 as u32).map(|f| start.map(|s| s + f)));
        }
        face_history
            .iter()
            .filter_map(|&(id, f, springs)| {
                let f = face_map.get(f as usize).copied().flatten()?;
                Some((id, f as Id, springs))
            })
            .collect()
    }

    /// The states of a run's servos (on its files `old_files`) for the servos of this
    /// simulation on the same files: a lid that presses on in the next stage stays where it
    /// was, with its speed.
    fn carried_servos(
        &self,
        old_files: &[(u64, u64)],
        servos: &[(u32, servo::State)],
    ) -> Vec<(u32, servo::State)> {
        let map = self.same_files(old_files);
        servos
            .iter()
            .filter_map(|&(file, state)| {
                let new = map.get(file as usize).copied().flatten()?;
                Some((new as u32, state))
            })
            .collect()
    }

    /// Fixes the particles whose centre lies in one of `boxes` (`[[fixed]]`): a clump
    /// whole, if its centre of mass does.
    fn fix_within(p: &mut Particles, boxes: &[crate::scenario::Region]) {
        let inside = |x: DVec3| boxes.iter().any(|b| b.contains(x));
        for ((x, fixed), body) in p.x.iter().zip(&mut p.fixed).zip(&p.body) {
            *fixed |= body.is_none() && inside(*x);
        }
        for (b, body) in p.bodies.list.iter().enumerate() {
            if inside(body.x) {
                p.bodies
                    .members(b)
                    .iter()
                    .for_each(|&k| p.fixed[k as usize] = true);
            }
        }
    }

    /// Sets up a simulation from a mesh and particles already in memory.
    /// The particles in `[[fixed]]` boxes are fixed.
    pub fn from_parts(
        scenario: Scenario,
        mesh: Mesh,
        mut particles: Particles,
    ) -> Result<Simulation> {
        Self::fix_within(&mut particles, &scenario.fixed);
        let g = &scenario.geometry;
        let max_radius = g.radius_max.max(particles.max_radius());
        if particles.len() as u64 > u32::MAX as u64 / 2 {
            bail!("too many particles: {}", particles.len());
        }
        check_materials(&particles, &scenario)?;
        let law = contact_law(&scenario);
        // The lists' skin covers the gap at which a contact beyond touch (JKR, a liquid
        // bridge) ends, so that its pair stays listed while it lasts.
        let asked = scenario.simulation.skin * g.radius_max;
        let skin = asked.max(law.largest_reach(max_radius));
        if let Some(periodic) = scenario.periodicity() {
            let periods = scenario.simulation.shortest_period();
            // With the skin raised, the widest pair's reach grows with it.
            let shortest = periods * max_radius + 2.0 * (skin - asked);
            let raised = if skin > asked {
                " and twice the skin's rise to the reach of contacts beyond touch"
            } else {
                ""
            };
            for a in 0..3 {
                if periodic.axes[a] && periodic.length[a] < shortest {
                    bail!(
                        "the period {} of the domain along axis {a} is shorter than {periods} times the largest radius{raised} ({shortest})",
                        periodic.length[a]
                    );
                }
            }
        }
        let face_grid = FaceGrid::of(&mesh.faces, max_radius, skin);
        let mut sim = Simulation {
            model: Model {
                law,
                densities: scenario
                    .materials
                    .iter()
                    .map(|m| Density::new(m.properties.density, m.properties.viscosity))
                    .collect(),
                scales: LoadScales::of(&scenario),
                heat: None,
            },
            neighbours: Neighbours::with_periodic(skin, scenario.periodicity()),
            face_grid,
            spawner: Spawner::new(scenario.simulation.seed),
            loads: Vec::new(),
            built_at: 0,
            time: 0.0,
            steps: 0,
            stage_times: StageTimes::default(),
            warnings: Warnings::default(),
            walls: Walls::of(mesh, scenario.geometry.mesh_material),
            removed: Removed {
                outlets: vec![Outflow::default(); scenario.outlets.len()],
                domain: Outflow::default(),
            },
            face_grid_radius: max_radius,
            books: scenario.energy_ledger.then(|| {
                let r_max = LoadScales::largest_radius(&scenario).max(max_radius);
                super::ledger::Books::new(&LoadScales::of(&scenario), r_max)
            }),
            share: None,
            scenario,
            particles,
        };
        if sim.model.law.beyond_touch() {
            // An open contact is kept while it lasts, whatever its springs.
            sim.neighbours.state.activate("beyond");
        }
        sim.sum_wall_loads();
        sim.start_heat()?;
        Ok(sim)
    }
}

/// A servo's control law on the faces `faces` of material `wall`: the target as a force
/// (a stress times [`servo_area`]), the gain given or [`servo::default_gain`] for grains of
/// R_min against the stiffest material.
/// A stress on faces that show no area normal to the direction (a plate edge-on to it) is
/// refused: its target force would be 0 and its gain not a number.
pub(super) fn servo_control(
    s: &Scenario,
    servo: crate::scenario::Servo,
    wall: u16,
    faces: &[Face],
) -> Result<servo::Control> {
    let d = servo.direction;
    let area = servo_area(s, d, faces);
    let force = match servo.target {
        crate::scenario::Target::Force(f) => f,
        crate::scenario::Target::Stress(p) => {
            let whole: f64 = faces.iter().map(Face::area).sum();
            if area.partial_cmp(&(1e-9 * whole)) != Some(std::cmp::Ordering::Greater) {
                bail!(
                    "stress = {p} Pa acts on the faces' area projected normal to direction \
                     {:?}, and that is {area:.3e} m^2 (of {whole:.3e} m^2 of faces: they lie along \
                     the direction, as a plate edge-on to it): turn the faces or the direction, \
                     or give a force [N]",
                    d.to_array()
                );
            }
            p * area
        }
    };
    let law = contact_law(s);
    let e_star = (0..s.materials.len() as u16)
        .map(|a| law.with_wall(a, wall).normal.e_star)
        .fold(0.0, f64::max);
    let (r, dt) = (s.geometry.radius_min, s.simulation.timestep);
    let gain = servo
        .gain
        .unwrap_or_else(|| servo::default_gain(force, area, r, e_star, dt));
    anyhow::ensure!(
        gain.is_finite() && gain > 0.0,
        "the servo's gain {gain:e} m/(s N) is not a positive number: give gain"
    );
    Ok(servo::Control {
        direction: d,
        force,
        max_speed: servo.max_speed,
        gain,
    })
}

/// The area a servo's stress acts on: its faces' area projected normal to its direction
/// `d`, sum |n . d| A_f (a plate's area; a closed body counts both sides), and no more than
/// the domain's cross-section when `d` is along an axis and the two others are periodic
/// (a lid spanning a periodic cell presses on the cell).
pub fn servo_area(s: &Scenario, d: DVec3, faces: &[Face]) -> f64 {
    let projected = |f: &Face| f.normal().map_or(0.0, |n| n.dot(d).abs()) * f.area();
    let area: f64 = faces.iter().map(projected).sum();
    let axis = (0..3).find(|&a| d[a].abs() == 1.0);
    match (s.domain, axis) {
        (Some(domain), Some(a)) => {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            if s.periodic[b] && s.periodic[c] {
                let size = domain.max - domain.min;
                area.min(size[b] * size[c])
            } else {
                area
            }
        }
        _ => area,
    }
}

/// The contact law of the scenario's materials and interactions.
fn contact_law(s: &Scenario) -> ContactLaw {
    let materials: Vec<_> = s.materials.iter().map(|m| m.properties.clone()).collect();
    let (dt, springs) = (s.simulation.timestep, s.simulation.friction_springs);
    ContactLaw::of(&materials, |a, b| s.pair(a, b), dt, springs)
}

/// The error of a checkpoint that does not fit the run it is to continue.
fn misfit(what: String) -> anyhow::Error {
    anyhow::anyhow!("the checkpoint does not fit: {what}")
}
