//! The state of a run as a checkpoint holds it (`records::Snapshot`): of a one-process run,
//! or of a split run as the pieces of its processes joined; one function makes both.

use anyhow::Result;
use rustc_hash::FxHashSet;

use super::Simulation;
use super::records::{Snapshot, decode, encode, join};
use crate::parallel::decomposition::agree;

impl Simulation {
    /// The complete state of the run (collective in a split run, where it fails if the
    /// state of some process is not one a checkpoint may hold). In a split run: the pieces of all processes, joined (`checkpoint::join`) as the
    /// parts of a stop checkpoint are, so that both give the same checkpoint.
    pub fn snapshot(&self) -> Result<Snapshot> {
        let Some(d) = &self.share else {
            return Ok(self.state_of(None));
        };
        let mine = encode(&self.snapshot_piece(), 0);
        join_pieces(&d.comm.all_gather(mine))
    }

    /// The state of the particles `owned` marks (all of them without), with the springs of
    /// every contact one of them is in, and the state all processes share: the snapshot of
    /// a one-process run, or a process's piece of a split run's (`snapshot_piece`).
    fn state_of(&self, owned: Option<&[bool]>) -> Snapshot {
        let p = &self.particles;
        let (mut pairs, mut faces) = self.neighbours.entries_by_id(&p.id);
        let (anchors, lonely) = self.neighbours.anchors();
        let (particles, anchors, lonely) = match owned {
            None => {
                // Each once, in (id, partner) order (`checkpoint::join` sorts the pieces').
                pairs.sort_unstable_by_key(|e| (e.0, e.1));
                faces.sort_unstable_by_key(|e| (e.0, e.1));
                (p.clone(), anchors.to_vec(), lonely.to_vec())
            }
            Some(owned) => {
                let mut own = p.empty_like();
                let mut own_anchors = Vec::new();
                let mut own_ids = FxHashSet::default();
                for k in (0..p.len()).filter(|&k| owned[k]) {
                    own.insert(p.id[k], p.get(k));
                    own_anchors.push(anchors.get(k).copied().unwrap_or(p.x[k]));
                    own_ids.insert(p.id[k]);
                }
                for b in p.bodies_where(|k| owned[k]) {
                    own.bodies.insert(p.bodies.list[b].clone());
                }
                own.locate_bodies();
                pairs.retain(|e| own_ids.contains(&e.0) || own_ids.contains(&e.1));
                faces.retain(|e| own_ids.contains(&e.0));
                (own, own_anchors, Vec::new())
            }
        };
        Snapshot {
            contact_state: self.neighbours.state,
            steps: self.steps,
            built_at: self.built_at,
            particles,
            spawner: self.spawner.state(),
            anchors,
            lonely,
            pair_history: pairs,
            face_history: faces,
            removed: self.removed.clone(),
            wall_sums: self.walls.sums.clone(),
            wall_heat: match self.model.heat {
                Some(_) => self.walls.heat.clone(),
                None => Vec::new(),
            },
            scenario: self.scenario.to_toml(),
            mesh_files: self.walls.signatures(),
            servos: self.walls.servos(),
            ledger: self.books.as_ref().map(|b| b.kept()),
        }
    }

    /// The snapshot of the run on the writer, `None` on the other processes of a split run
    /// (collective), which never hold more than their own piece.
    pub fn snapshot_for_writer(&self) -> Result<Option<Snapshot>> {
        let Some(d) = &self.share else {
            return self.snapshot().map(Some);
        };
        let mine = encode(&self.snapshot_piece(), 0);
        let pieces = d.comm.gather(mine);
        let joined = (!pieces.is_empty()).then(|| join_pieces(&pieces));
        agree(&*d.comm, joined.transpose())
    }

    /// This process's piece of the state of a split run: its own particles (with their
    /// anchors of the last rebuild), the springs of every contact one of them is in, and the
    /// state all processes share. `checkpoint::join` makes the snapshot of the pieces.
    pub fn snapshot_piece(&self) -> Snapshot {
        let d = self.share.as_ref().expect("a split run");
        self.state_of(Some(&d.owned))
    }
}

/// The snapshot of the encoded pieces of every process.
fn join_pieces(pieces: &[Vec<u8>]) -> Result<Snapshot> {
    let pieces = pieces
        .iter()
        .map(|bytes| decode(bytes, Some(0)))
        .collect::<Result<Vec<_>>>()?;
    join(pieces)
}
