//! The bytes of a snapshot: the checkpoint format (written to files by `io::checkpoint`, and
//! sent between processes to gather a split run's snapshot), versioned, with a checksum, so
//! that a resumed run is bitwise identical to an uninterrupted one.
//!
//! Layout (little endian): magic `TINYDEM CKPT`, format version (u32), scenario fingerprint
//! (u64), step (u64), step of the last neighbour-list rebuild (u64), spawner word position
//! (u128), pending radius flag (u8) and value (f64), the next particle id (u64; u32 before
//! format 7, as every id below), particle
//! count (u64) and per particle, in storage order: its id (u64), 14 f64 (x, y, z, R, vx, vy,
//! vz, q0..q3, wx, wy, wz), its tag (u32), material (u16) and, from format 5, whether it is fixed (u8); whether the lists were built (u8) and if so
//! each particle's position at the last rebuild (3 f64); the lonely particles of the last
//! rebuild: count (u64) and per entry storage index (u32) and allowance (f64); then the particle-pair and particle-face histories: count (u64) and per
//! entry the ids (lower, higher) or the id and face (u64, u64) and the springs u_s, u_r (3 f64
//! each), u_t (f64); from format 3 the removed particles, wall sums, scenario, mesh files and
//! spawn regions (`Cursor::rest`); from format 4 whether the spawn box is off (u8) and the servos' states (count, and per servo its
//! mesh file (u32), position, speed, position at the last rebuild and last load (4 f64)); from
//! format 6 the rigid bodies (clumps): count (u64) and per body the id of its first sphere
//! (u64; its spheres are the particles of the next ids), template (u16), scale, x, v,
//! q0..q3, w, mass, principal moments, bounding radius (19 f64) and its spheres' offsets
//! (count u32, 3 f64 each); from format 8 (written when the particles hold optional fields,
//! `model/fields.rs`; without them, format 7) the optional fields: count (u32) and per field
//! its name (length u8, bytes) and its values in storage order; from format 9 (written with
//! heat transfer) the heat into each mesh file since the last frame (count u64, i128 each);
//! from format 10 (written with the energy ledger) the ledger: its sums' 24 integers (i64),
//! whether it has started (u8), its starting energy and each mode's stored energy then (6
//! f64); last a CRC-32 of everything
//! before it. A particle's record is the table's (`model/particles.rs`, the core fields with
//! a checkpoint format, from that format on, in the table's order).
//!
//! The storage order and the positions of the last rebuild let a resumed run rebuild the
//! very lists the interrupted one had; its results depend on them (the order in which
//! forces are summed), so that is what makes it bitwise identical.

use anyhow::{Result, bail};
use glam::{DQuat, DVec3};

use super::{Outflow, Removed, Snapshot, Wrench};
use crate::engine::spawn::{RegionState, SpawnerState};
use crate::model::bodies::{Body, BodyId};
use crate::model::contact_state::{ActiveState, ContactState, OPTIONAL_STATE};
use crate::model::particles::{Id, OPTIONAL, Particle, Particles};
use crate::model::servo::State;
use crate::neighbours::Entry;

const MAGIC: &[u8; 12] = b"TINYDEM CKPT";
const VERSION: u32 = 10;
/// The format of a checkpoint without optional particle fields: 7, whose bytes format 8
/// adds the section of the optional fields to.
const WITHOUT_OPTIONAL: u32 = 7;
/// The format of a checkpoint with optional fields and no heat transfer: 8, whose bytes
/// format 9 adds the heat into the walls to.
const WITHOUT_HEAT: u32 = 8;
/// The format of a checkpoint without the energy ledger: 9, whose bytes format 10 adds the
/// ledger to.
const WITHOUT_LEDGER: u32 = 9;
/// The oldest version this program reads.
const OLDEST: u32 = 2;

fn put_f64s(out: &mut Vec<u8>, values: &[f64]) {
    for v in values {
        out.extend_from_slice(&v.to_le_bytes());
    }
}

/// An id: 8 bytes, or 4 in the formats before 7 (`wide` false; for the tests that make
/// files of older formats).
fn put_id(out: &mut Vec<u8>, id: Id, wide: bool) {
    match wide {
        true => out.extend_from_slice(&id.to_le_bytes()),
        false => out.extend_from_slice(&u32::try_from(id).expect("a 32-bit id").to_le_bytes()),
    }
}

fn put_history(out: &mut Vec<u8>, h: &[Entry], wide: bool) {
    out.extend_from_slice(&(h.len() as u64).to_le_bytes());
    for &(i, j, s) in h {
        put_id(out, i, wide);
        put_id(out, j, wide);
        s.put_checkpoint(out);
    }
}

/// Encodes a snapshot in format 6 (ids of 4 bytes), for the tests of the older formats.
#[cfg(test)]
pub(crate) fn encode_v6(snapshot: &Snapshot, fingerprint: u64) -> Vec<u8> {
    let mut out = Vec::new();
    encode_as(&mut out, snapshot, fingerprint, 6);
    out
}

/// Encodes a snapshot.
pub fn encode(snapshot: &Snapshot, fingerprint: u64) -> Vec<u8> {
    let mut out = Vec::new();
    encode_into(&mut out, snapshot, fingerprint);
    out
}

/// The bytes a checkpoint of `snapshot` takes (a bound).
fn encoded_size(s: &Snapshot) -> usize {
    let records = s.particles.len() * (8 + Particle::checkpoint_size(VERSION) + 24)
        + s.lonely.len() * 12
        + (s.pair_history.len() + s.face_history.len()) * 72;
    256 + records
        + s.scenario.len()
        + 16 * s.mesh_files.len()
        + 48 * s.wall_sums.len()
        + 16 * s.wall_heat.len()
        + 16 * s.removed.outlets.len()
        + 17 * s.spawner.regions.len()
        + 1
        + 36 * s.servos.len()
}

/// Appends the checkpoint of `snapshot` to `out` (its checksum covers what it appends).
pub fn encode_into(out: &mut Vec<u8>, snapshot: &Snapshot, fingerprint: u64) {
    let optional = !snapshot.particles.active.fields().is_empty()
        || !snapshot.contact_state.fields().is_empty();
    let version = match (optional, snapshot.wall_heat.is_empty()) {
        _ if snapshot.ledger.is_some() => VERSION,
        (_, false) => WITHOUT_LEDGER,
        (true, true) => WITHOUT_HEAT,
        (false, true) => WITHOUT_OPTIONAL,
    };
    encode_as(out, snapshot, fingerprint, version);
}

/// The checkpoint of `snapshot` in format `version`: the newest, or 6 (ids of 4 bytes;
/// for the tests of older formats, which cut the rest).
fn encode_as(out: &mut Vec<u8>, snapshot: &Snapshot, fingerprint: u64, version: u32) {
    let wide = version >= 7;
    let start = out.len();
    out.reserve(encoded_size(snapshot));
    let p = &snapshot.particles;
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&version.to_le_bytes());
    out.extend_from_slice(&fingerprint.to_le_bytes());
    out.extend_from_slice(&snapshot.steps.to_le_bytes());
    out.extend_from_slice(&snapshot.built_at.to_le_bytes());
    out.extend_from_slice(&snapshot.spawner.word_pos.to_le_bytes());
    out.push(snapshot.spawner.pending_radius.is_some() as u8);
    put_f64s(out, &[snapshot.spawner.pending_radius.unwrap_or(0.0)]);
    put_id(out, p.next_id, wide);
    out.extend_from_slice(&(p.len() as u64).to_le_bytes());
    for (k, q) in p.iter().enumerate() {
        put_id(out, p.id[k], wide);
        q.put_checkpoint(out);
    }
    let built = snapshot.anchors.len() == p.len() && !p.is_empty();
    out.push(built as u8);
    if built {
        for a in &snapshot.anchors {
            put_f64s(out, &[a.x, a.y, a.z]);
        }
    }
    out.extend_from_slice(&(snapshot.lonely.len() as u64).to_le_bytes());
    for &(i, allowance) in &snapshot.lonely {
        out.extend_from_slice(&i.to_le_bytes());
        put_f64s(out, &[allowance]);
    }
    put_history(out, &snapshot.pair_history, wide);
    put_history(out, &snapshot.face_history, wide);
    let removed = &snapshot.removed;
    let put_outflow = |out: &mut Vec<u8>, o: &Outflow| {
        out.extend_from_slice(&o.count.to_le_bytes());
        put_f64s(out, &[o.mass]);
    };
    put_outflow(out, &removed.domain);
    out.extend_from_slice(&(removed.outlets.len() as u64).to_le_bytes());
    for o in &removed.outlets {
        put_outflow(out, o);
    }
    out.extend_from_slice(&(snapshot.wall_sums.len() as u64).to_le_bytes());
    for w in &snapshot.wall_sums {
        put_f64s(out, &[w.f.x, w.f.y, w.f.z, w.tau.x, w.tau.y, w.tau.z]);
    }
    out.extend_from_slice(&(snapshot.scenario.len() as u64).to_le_bytes());
    out.extend_from_slice(snapshot.scenario.as_bytes());
    out.extend_from_slice(&(snapshot.mesh_files.len() as u64).to_le_bytes());
    for &(faces, hash) in &snapshot.mesh_files {
        out.extend_from_slice(&faces.to_le_bytes());
        out.extend_from_slice(&hash.to_le_bytes());
    }
    let regions = &snapshot.spawner.regions;
    out.extend_from_slice(&(regions.len() as u64).to_le_bytes());
    for r in regions {
        out.extend_from_slice(&r.inserted.to_le_bytes());
        out.push(r.pending_radius.is_some() as u8);
        put_f64s(out, &[r.pending_radius.unwrap_or(0.0)]);
    }
    out.push(snapshot.spawner.box_off as u8);
    out.extend_from_slice(&(snapshot.servos.len() as u64).to_le_bytes());
    for (file, s) in &snapshot.servos {
        out.extend_from_slice(&file.to_le_bytes());
        put_f64s(out, &[s.position, s.speed, s.built, s.load]);
    }
    put_bodies(out, &p.bodies.list, wide);
    if version >= 8 {
        put_optional(out, p);
        put_optional_state(out, snapshot);
    }
    put_heat_and_ledger(out, snapshot, version);
    let crc = crc32fast::hash(&out[start..]);
    out.extend_from_slice(&crc.to_le_bytes());
}

/// The heat into the walls (format 9) and the energy ledger (format 10).
fn put_heat_and_ledger(out: &mut Vec<u8>, snapshot: &Snapshot, version: u32) {
    if version >= 9 {
        out.extend_from_slice(&(snapshot.wall_heat.len() as u64).to_le_bytes());
        for q in &snapshot.wall_heat {
            out.extend_from_slice(&q.to_le_bytes());
        }
    }
    if version >= 10 {
        let kept = snapshot.ledger.unwrap_or_default();
        for w in kept.words {
            out.extend_from_slice(&w.to_le_bytes());
        }
        out.push(kept.start.is_some() as u8);
        put_f64s(out, &[kept.start.unwrap_or(0.0)]);
        put_f64s(out, &kept.stored_start);
    }
}

/// A field's name: its length (u8) and bytes.
fn put_name(out: &mut Vec<u8>, name: &str) {
    out.push(name.len() as u8);
    out.extend_from_slice(name.as_bytes());
}

/// The optional fields the particles hold: their count (u32), and per field its name
/// (length u8, bytes) and its values in storage order.
fn put_optional(out: &mut Vec<u8>, p: &Particles) {
    let fields = p.active.fields();
    out.extend_from_slice(&(fields.len() as u32).to_le_bytes());
    for f in fields {
        put_name(out, f.name);
        p.put_field(f.name, out);
    }
}

/// The optional members of the contacts' states: their count (u32), and per member its
/// name (length u8, bytes) and its values, of the pair entries, then of the face entries.
fn put_optional_state(out: &mut Vec<u8>, s: &Snapshot) {
    let members = s.contact_state.fields();
    out.extend_from_slice(&(members.len() as u32).to_le_bytes());
    for m in members {
        put_name(out, m.name);
        for e in s.pair_history.iter().chain(&s.face_history) {
            e.2.put_member(m.name, out);
        }
    }
}

fn put_bodies(out: &mut Vec<u8>, bodies: &[Body], wide: bool) {
    out.extend_from_slice(&(bodies.len() as u64).to_le_bytes());
    for b in bodies {
        put_id(out, b.id.first(), wide);
        out.extend_from_slice(&b.template.to_le_bytes());
        let (x, v, q, w, i) = (b.x, b.v, b.q, b.w, b.inertia);
        put_f64s(
            out,
            &[
                b.scale,
                x.x,
                x.y,
                x.z,
                v.x,
                v.y,
                v.z,
                q.w,
                q.x,
                q.y,
                q.z,
                w.x,
                w.y,
                w.z,
                b.mass,
                i.x,
                i.y,
                i.z,
                b.bounding_radius,
            ],
        );
        out.extend_from_slice(&(b.offsets.len() as u32).to_le_bytes());
        for o in &b.offsets {
            put_f64s(out, &[o.x, o.y, o.z]);
        }
    }
}

/// A cursor over the checkpoint bytes that reports truncation clearly.
struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
    /// Whether ids take 8 bytes (format 7 on) or 4.
    wide: bool,
}

impl Cursor<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8]> {
        if self.bytes.len() - self.at < n {
            bail!(
                "truncated: ends at byte {} while reading {n} more bytes",
                self.bytes.len()
            );
        }
        self.at += n;
        Ok(&self.bytes[self.at - n..self.at])
    }
    fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }
    fn u16(&mut self) -> Result<u16> {
        Ok(u16::from_le_bytes(self.take(2)?.try_into()?))
    }
    fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into()?))
    }
    fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into()?))
    }
    /// A particle id: 8 bytes from format 7 on, 4 before.
    fn id(&mut self) -> Result<Id> {
        match self.wide {
            true => self.u64(),
            false => self.u32().map(Id::from),
        }
    }
    /// The bytes of an id in this format.
    fn id_size(&self) -> usize {
        if self.wide { 8 } else { 4 }
    }
    fn u128(&mut self) -> Result<u128> {
        Ok(u128::from_le_bytes(self.take(16)?.try_into()?))
    }
    fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_le_bytes(self.take(8)?.try_into()?))
    }
    fn vec3(&mut self) -> Result<DVec3> {
        Ok(DVec3::new(self.f64()?, self.f64()?, self.f64()?))
    }
    /// A field's name ([`put_name`]).
    fn name(&mut self) -> Result<String> {
        let length = self.u8()? as usize;
        Ok(String::from_utf8_lossy(self.take(length)?).into_owned())
    }
    /// A count of records of `size` bytes each, checked against the bytes left.
    fn count(&mut self, size: usize) -> Result<usize> {
        let n = self.u64()?;
        if n > ((self.bytes.len() - self.at) / size) as u64 {
            bail!("corrupt: announces {n} records, more than the file holds");
        }
        Ok(n as usize)
    }
    fn history(&mut self) -> Result<Vec<Entry>> {
        let size = ContactState::CHECKPOINT_SIZE;
        let n = self.count(2 * self.id_size() + size)?;
        (0..n)
            .map(|_| {
                let (i, j) = (self.id()?, self.id()?);
                let state = ContactState::take_checkpoint(&mut self.take(size)?);
                let s = state.springs;
                if !(bounded(s.u_s) && bounded(s.u_r) && bounded(DVec3::splat(s.u_t))) {
                    bail!(
                        "corrupt checkpoint: the friction springs of contact ({i}, {j}) are {s:?}"
                    );
                }
                Ok((i, j, state))
            })
            .collect()
    }
}

/// The largest magnitude a coordinate of a checkpoint's state may have (SI units): far
/// beyond any run, and small enough that its squares and products stay finite.
const STATE_BOUND: f64 = 1e30;

/// Whether every component of `x` is finite and within [`STATE_BOUND`].
fn bounded(x: DVec3) -> bool {
    x.is_finite() && x.abs().max_element() <= STATE_BOUND
}

/// Checks the particles of a checkpoint as any input is checked: finite states within
/// [`STATE_BOUND`], radii > 0, unit quaternions. A checksum only says the bytes are those
/// written, not that what was written is a state.
fn check_states(ids: &[Id], p: &Particles) -> Result<()> {
    for (k, &id) in ids.iter().enumerate() {
        let fields = [
            ("position", p.x[k]),
            ("velocity", p.v[k]),
            ("angular velocity", p.w[k]),
        ];
        for (what, x) in fields {
            if !bounded(x) {
                bail!("corrupt checkpoint: particle {id} has the {what} {x}");
            }
        }
        let r = p.radius[k];
        if !(r > 0.0 && r < STATE_BOUND) {
            bail!("corrupt checkpoint: particle {id} has the radius {r}");
        }
        let q = p.q[k];
        if !q.is_finite() || (q.length() - 1.0).abs() > 1e-9 {
            bail!(
                "corrupt checkpoint: particle {id} has the orientation {q}, not a unit quaternion"
            );
        }
    }
    Ok(())
}

/// Decodes a checkpoint, checking magic, version, checksum and, if given, the fingerprint
/// (a resume needs the scenario it was written with; a staged run does not).
pub fn decode(bytes: &[u8], expected_fingerprint: Option<u64>) -> Result<Snapshot> {
    let (version, mut r) = checked_body(bytes, expected_fingerprint)?;
    let steps = r.u64()?;
    let built_at = r.u64()?;
    if built_at > steps {
        bail!("corrupt checkpoint: last rebuild at step {built_at}, after step {steps}");
    }
    let word_pos = r.u128()?;
    let has_pending = r.u8()? != 0;
    let pending = r.f64()?;
    let next_id = r.id()?;
    let v3 = version >= 3;
    let (particles, anchors) = r.particles(version, next_id)?;
    let lonely = r.lonely(particles.len())?;
    let pair_history = r.history()?;
    let face_history = r.history()?;
    let mut rest = if v3 { r.rest()? } else { Rest::default() };
    let mut box_off = false;
    if version >= 4 {
        box_off = r.u8()? != 0;
        rest.servos = r.servos(rest.mesh_files.len())?;
    }
    let mut particles = particles;
    if version >= 6 {
        let bodies = r.bodies()?;
        join_bodies(&mut particles, bodies)?;
    }
    let mut contact_state = ActiveState::default();
    let (mut pair_history, mut face_history) = (pair_history, face_history);
    if version >= 8 {
        r.optional(&mut particles)?;
        let histories = (&mut pair_history[..], &mut face_history[..]);
        contact_state = r.optional_state(histories)?;
    }
    let mut wall_heat = Vec::new();
    if version >= 9 {
        let files = r.count(16)?;
        // None without heat transfer (format 10 has the section either way).
        if files != 0 && files != rest.mesh_files.len() {
            bail!(
                "corrupt checkpoint: the heat of {files} mesh files, for {} files",
                rest.mesh_files.len()
            );
        }
        for _ in 0..files {
            wall_heat.push(i128::from_le_bytes(r.take(16)?.try_into()?));
        }
    }
    let ledger = match version >= 10 {
        true => Some(r.ledger()?),
        false => None,
    };
    if r.at != r.bytes.len() {
        bail!(
            "corrupt checkpoint: {} unexpected bytes at the end",
            r.bytes.len() - r.at
        );
    }
    Ok(Snapshot {
        contact_state,
        steps,
        built_at,
        particles,
        spawner: SpawnerState {
            word_pos,
            pending_radius: has_pending.then_some(pending),
            regions: rest.regions,
            box_off,
        },
        anchors,
        lonely,
        pair_history,
        face_history,
        removed: rest.removed,
        wall_sums: rest.wall_sums,
        wall_heat,
        scenario: rest.scenario,
        mesh_files: rest.mesh_files,
        servos: rest.servos,
        ledger,
    })
}

/// The format version of a checkpoint and a reader of its body after the fingerprint,
/// once its magic, version, checksum and fingerprint (if `expected_fingerprint`) are
/// checked.
fn checked_body(bytes: &[u8], expected_fingerprint: Option<u64>) -> Result<(u32, Cursor<'_>)> {
    if bytes.len() < MAGIC.len() + 4 || &bytes[..MAGIC.len()] != MAGIC {
        bail!("not a tinydem checkpoint (no 'TINYDEM CKPT' header)");
    }
    let (body, crc) = bytes.split_at(bytes.len() - 4);
    let version = u32::from_le_bytes(bytes[12..16].try_into()?);
    if !(OLDEST..=VERSION).contains(&version) {
        bail!(
            "checkpoint format version {version}; this tinydem reads versions {OLDEST} to {VERSION}"
        );
    }
    if crc32fast::hash(body).to_le_bytes() != crc {
        bail!("corrupt checkpoint: the checksum does not match (truncated or damaged file)");
    }
    let mut r = Cursor {
        bytes: body,
        at: 16,
        wide: version >= 7,
    };
    let fingerprint = r.u64()?;
    if expected_fingerprint.is_some_and(|f| f != fingerprint) {
        bail!(
            "the checkpoint was written for a different scenario or mesh (material, time step, \
             spawning, geometry): resume it with the scenario it was written with"
        );
    }
    Ok((version, r))
}

/// What format 3 added after the histories.
#[derive(Default)]
struct Rest {
    removed: Removed,
    wall_sums: Vec<Wrench>,
    scenario: String,
    mesh_files: Vec<(u64, u64)>,
    regions: Vec<RegionState>,
    servos: Vec<(u32, State)>,
}

impl Cursor<'_> {
    /// The particles of a checkpoint of format `version` (material indices from format 3
    /// on, fixed from 5), checked, with their ids below `next_id`; and their anchors, if the
    /// lists were built.
    fn particles(&mut self, version: u32, next_id: Id) -> Result<(Particles, Vec<DVec3>)> {
        let r = self;
        let size = Particle::checkpoint_size(version);
        let n = r.count(r.id_size() + size)?;
        let mut particles = Particles::default();
        let mut ids = Vec::with_capacity(n);
        for _ in 0..n {
            ids.push(r.id()?);
            particles.push(Particle::take_checkpoint(&mut r.take(size)?, version));
        }
        let anchors = match r.u8()? {
            0 => Vec::new(),
            _ => (0..n).map(|_| r.vec3()).collect::<Result<_>>()?,
        };
        check_states(&ids, &particles)?;
        let mut sorted = ids.clone();
        sorted.sort_unstable();
        if sorted.windows(2).any(|w| w[0] == w[1]) || sorted.last().is_some_and(|&m| m >= next_id) {
            bail!("corrupt checkpoint: particle ids repeat or reach the next id {next_id}");
        }
        (particles.id, particles.next_id) = (ids, next_id);
        Ok((particles, anchors))
    }

    /// The optional fields of `particles` (format 8): each known to this program, once,
    /// with a value for every particle.
    fn optional(&mut self, particles: &mut Particles) -> Result<()> {
        let r = self;
        for _ in 0..r.u32()? {
            let name = r.name()?;
            let Some(field) = OPTIONAL.iter().find(|f| f.name == name) else {
                bail!(
                    "the checkpoint holds the particle field '{name}', which this tinydem does not know"
                );
            };
            if particles.active.fields().contains(&field) {
                bail!("corrupt checkpoint: the particle field '{name}' twice");
            }
            let bytes = r.take(field.size * particles.len())?;
            particles.take_field(&name, &mut &bytes[..]);
        }
        Ok(())
    }

    /// The optional members of the contacts' states (format 8), each known to this
    /// program, once, with a value for every entry of `histories` (pairs, then faces).
    fn optional_state(
        &mut self,
        (pairs, faces): (&mut [Entry], &mut [Entry]),
    ) -> Result<ActiveState> {
        let r = self;
        let mut active = ActiveState::default();
        for _ in 0..r.u32()? {
            let name = r.name()?;
            let Some(member) = OPTIONAL_STATE.iter().find(|f| f.name == name) else {
                bail!(
                    "the checkpoint holds the contact state '{name}', which this tinydem does not know"
                );
            };
            if active.fields().contains(&member) {
                bail!("corrupt checkpoint: the contact state '{name}' twice");
            }
            active.activate(&name);
            let mut bytes = r.take(member.size * (pairs.len() + faces.len()))?;
            for e in pairs.iter_mut().chain(faces.iter_mut()) {
                e.2.take_member(&name, &mut bytes);
            }
        }
        Ok(active)
    }

    /// The rigid bodies (format 6), finite, ascending by id.
    fn bodies(&mut self) -> Result<Vec<Body>> {
        let r = self;
        let count = r.count(r.id_size() + 2 + 19 * 8 + 4)?;
        let mut bodies = Vec::with_capacity(count);
        for _ in 0..count {
            let id = r.id()?;
            let template = r.u16()?;
            let f: Vec<f64> = (0..19).map(|_| r.f64()).collect::<Result<_>>()?;
            let n = r.u32()? as usize;
            if n > (r.bytes.len() - r.at) / 24 || n < 2 || id.checked_add(n as Id).is_none() {
                bail!("corrupt checkpoint: a body of {n} spheres");
            }
            let offsets = (0..n).map(|_| r.vec3()).collect::<Result<Vec<_>>>()?;
            let v3 = |k: usize| DVec3::new(f[k], f[k + 1], f[k + 2]);
            let body = Body {
                id: BodyId::new(id),
                template,
                scale: f[0],
                x: v3(1),
                v: v3(4),
                q: DQuat::from_xyzw(f[8], f[9], f[10], f[7]),
                w: v3(11),
                mass: f[14],
                inertia: v3(15),
                offsets,
                bounding_radius: f[18],
            };
            let finite =
                f.iter().all(|x| x.is_finite()) && body.offsets.iter().all(|o| o.is_finite());
            if !finite || body.mass <= 0.0 || bodies.last().is_some_and(|b: &Body| b.id >= body.id)
            {
                bail!("corrupt checkpoint: body {id} not finite, massless or out of order");
            }
            bodies.push(body);
        }
        Ok(bodies)
    }

    /// The lonely particles of the last rebuild (storage indices below `n`, ascending) with
    /// their allowances.
    fn lonely(&mut self, n: usize) -> Result<Vec<(u32, f64)>> {
        let r = self;
        let lonely_count = r.count(4 + 8)?;
        let lonely = (0..lonely_count)
            .map(|_| Ok((r.u32()?, r.f64()?)))
            .collect::<Result<Vec<(u32, f64)>>>()?;
        if lonely.iter().any(|&(i, _)| i as usize >= n) || !lonely.is_sorted_by_key(|l| l.0) {
            bail!("corrupt checkpoint: lonely particles out of order or range");
        }
        Ok(lonely)
    }

    /// The energy ledger (format 10): its sums' integers, its start.
    fn ledger(&mut self) -> Result<crate::model::ledger::Kept> {
        let mut words = [0i64; 24];
        for w in &mut words {
            *w = self.u64()? as i64;
        }
        let started = self.u8()? != 0;
        let start = self.f64()?;
        let mut stored_start = [0.0; 5];
        for e in &mut stored_start {
            *e = self.f64()?;
        }
        Ok(crate::model::ledger::Kept {
            words,
            start: started.then_some(start),
            stored_start,
        })
    }

    /// The servos' states with their mesh files (below `files`, ascending), finite (format
    /// 4).
    fn servos(&mut self, files: usize) -> Result<Vec<(u32, State)>> {
        let r = self;
        let count = r.count(4 + 32)?;
        let servos = (0..count)
            .map(|_| {
                let file = r.u32()?;
                let (position, speed) = (r.f64()?, r.f64()?);
                let (built, load) = (r.f64()?, r.f64()?);
                let state = State {
                    position,
                    speed,
                    built,
                    load,
                };
                Ok((file, state))
            })
            .collect::<Result<Vec<_>>>()?;
        let finite = |s: &State| {
            [s.position, s.speed, s.built, s.load]
                .iter()
                .all(|x| x.abs() < 1e30)
        };
        if servos
            .iter()
            .any(|(f, s)| *f as usize >= files || !finite(s))
            || !servos.is_sorted_by_key(|s| s.0)
        {
            bail!("corrupt checkpoint: a servo's mesh file or state is out of range");
        }
        Ok(servos)
    }

    /// The removed particles, wall sums, scenario, mesh files and spawn regions (format 3).
    fn rest(&mut self) -> Result<Rest> {
        let r = self;
        let mut rest = Rest::default();
        let outflow = |r: &mut Cursor| -> Result<Outflow> {
            Ok(Outflow {
                count: r.u64()?,
                mass: r.f64()?,
            })
        };
        rest.removed.domain = outflow(r)?;
        let outlets = r.count(16)?;
        rest.removed.outlets = (0..outlets).map(|_| outflow(r)).collect::<Result<_>>()?;
        let files = r.count(48)?;
        rest.wall_sums = (0..files)
            .map(|_| {
                Ok(Wrench {
                    f: r.vec3()?,
                    tau: r.vec3()?,
                })
            })
            .collect::<Result<_>>()?;
        let len = r.count(1)?;
        rest.scenario = String::from_utf8(r.take(len)?.to_vec())
            .map_err(|_| anyhow::anyhow!("corrupt checkpoint: its scenario is not UTF-8"))?;
        let files = r.count(16)?;
        rest.mesh_files = (0..files)
            .map(|_| Ok((r.u64()?, r.u64()?)))
            .collect::<Result<_>>()?;
        let count = r.count(17)?;
        rest.regions = (0..count)
            .map(|_| {
                let inserted = r.u64()?;
                let has = r.u8()? != 0;
                let radius = r.f64()?;
                Ok(RegionState {
                    inserted,
                    pending_radius: has.then_some(radius),
                })
            })
            .collect::<Result<_>>()?;
        Ok(rest)
    }
}

/// Gives `particles` their `bodies`: body b's spheres are the particles of ids b, b + 1, ...;
/// each must be present.
fn join_bodies(particles: &mut Particles, bodies: Vec<Body>) -> Result<()> {
    let mut at = rustc_hash::FxHashMap::default();
    for (k, &id) in particles.id.iter().enumerate() {
        at.insert(id, k);
    }
    for b in &bodies {
        for id in b.id.first()..b.id.first() + b.offsets.len() as Id {
            let Some(&k) = at.get(&id) else {
                bail!(
                    "corrupt checkpoint: sphere {id} of body {} is missing",
                    b.id.first()
                );
            };
            if particles.body[k].is_some() {
                bail!("corrupt checkpoint: particle {id} is in two bodies");
            }
            particles.body[k] = Some(b.id);
        }
    }
    particles.bodies.list = bodies;
    let (id, body) = (particles.id.clone(), particles.body.clone());
    particles.bodies.locate(&id, &body);
    Ok(())
}
