//! Checkpoints in parts: each process of a split run writes its own piece of the state at
//! once, with no gather, so that a stop asked by the batch system is on disk within the
//! second or two a launcher grants before SIGKILL. The first process then joins the parts
//! into the one-file checkpoint; if it is killed first, reading the checkpoint joins them.
//!
//! Part `k` of `n` of the checkpoint of step `s` at `out/checkpoint.bin` is
//! `out/checkpoint.bin.s.part-k-of-n` (the step in the name, so that the parts of two stops
//! never mix: the set of a stop killed while writing is incomplete, and ignored): the magic
//! `TINYDEM PART`, `k` and `n` (u32 each), then a checkpoint (format as in
//! `engine::records::bytes`, with its own checksum) of that process's particles (with their anchors), the
//! springs of every contact it holds one of, and the state all processes share. Joined,
//! the parts give the very snapshot the gathered checkpoint holds (`Simulation::snapshot`
//! of a split run is made the same way), so resuming from parts or from the joined file
//! is the same.

use std::io::Read;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail, ensure};

use super::{decode, encode_into, join, shared_part};
use crate::engine::records::Snapshot;

const MAGIC: &[u8; 12] = b"TINYDEM PART";
/// The bytes before a part's checkpoint.
const HEADER: usize = 12 + 4 + 4;
/// Where the step is in a checkpoint: after its magic, version and fingerprint.
const STEP_AT: usize = 12 + 4 + 8;

/// The path of part `k` of `n` of the checkpoint of step `step` at `path`.
pub fn part_path(path: &Path, step: u64, k: usize, n: usize) -> PathBuf {
    path.with_file_name(format!("{}.{step}.part-{k}-of-{n}", file_name(path)))
}

/// Which part a file is: of the checkpoint of a step, part `k` of `n`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Part {
    step: u64,
    n: usize,
    k: usize,
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map_or_else(|| "checkpoint".into(), |n| n.to_string_lossy().into_owned())
}

/// Which part `name` is, if it is a part of the checkpoint named `of`.
fn part_of(name: &str, of: &str) -> Option<Part> {
    let rest = name.strip_prefix(of)?.strip_prefix('.')?;
    let (step, rest) = rest.split_once(".part-")?;
    let (k, n) = rest.split_once("-of-")?;
    let digits = |t: &str| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit());
    if !(digits(step) && digits(k) && digits(n)) {
        return None;
    }
    let part = Part {
        step: step.parse().ok()?,
        n: n.parse().ok()?,
        k: k.parse().ok()?,
    };
    (part.k < part.n).then_some(part)
}

/// Whether `name` is a part of some checkpoint (output of a run, for `--overwrite`).
pub fn is_part(name: &str) -> bool {
    let Some(at) = name.find(".part-") else {
        return false;
    };
    name[..at]
        .rfind('.')
        .is_some_and(|dot| part_of(name, &name[..dot]).is_some())
}

/// Writes `piece` as part `k` of `n` of the checkpoint at `path` (atomically), named by
/// its step.
pub fn save_part(
    path: &Path,
    k: usize,
    n: usize,
    piece: &Snapshot,
    fingerprint: u64,
) -> Result<()> {
    let mut bytes = Vec::new();
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&(k as u32).to_le_bytes());
    bytes.extend_from_slice(&(n as u32).to_le_bytes());
    encode_into(&mut bytes, piece, fingerprint);
    let part = part_path(path, piece.steps, k, n);
    crate::io::files::write_bytes_atomically(&part, &bytes)
        .with_context(|| format!("cannot write checkpoint part {}", part.display()))
}

/// Removes the parts of the checkpoint at `path` of other steps than `keep` (all of them if
/// none: once the whole file holds the newest state).
pub fn remove_parts(path: &Path, keep: Option<u64>) {
    for (part, which) in parts_beside(path, &file_name(path)) {
        if Some(which.step) != keep {
            let _ = std::fs::remove_file(part);
        }
    }
}

/// The parts of the checkpoint named `of` in the directory of `path`, in order.
fn parts_beside(path: &Path, of: &str) -> Vec<(PathBuf, Part)> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut parts: Vec<_> = entries
        .flatten()
        .filter_map(|e| {
            let part = part_of(&e.file_name().to_string_lossy(), of)?;
            Some((e.path(), part))
        })
        .collect();
    parts.sort_by_key(|p| p.1);
    parts
}

/// The step the checkpoint file at `path` is of, if its head can be read.
fn step_of(path: &Path) -> Option<u64> {
    let mut head = [0; STEP_AT + 8];
    crate::io::files::open(path)
        .ok()?
        .read_exact(&mut head)
        .ok()?;
    Some(u64::from_le_bytes(head[STEP_AT..].try_into().ok()?))
}

/// The parts to read for the checkpoint at `path`: the newest complete set (every part of
/// one step and count), if it is of a later step than the file at `path` (a stop whose
/// joining did not finish). Parts of an unfinished set are left alone: the stop that wrote
/// them did not complete, and the file at `path` (or an older set) is the last complete
/// checkpoint.
pub fn newer_parts(path: &Path) -> Option<Vec<PathBuf>> {
    let parts = parts_beside(path, &file_name(path));
    let newest = parts
        .chunk_by(|a, b| (a.1.step, a.1.n) == (b.1.step, b.1.n))
        .filter(|set| set.len() == set[0].1.n)
        .max_by_key(|set| set[0].1.step)?;
    let step = newest[0].1.step;
    step_of(path)
        .is_none_or(|whole| step > whole)
        .then(|| newest.iter().map(|p| p.0.clone()).collect())
}

/// What the newest incomplete set of parts of the checkpoint at `path` lacks, as words
/// ("checkpoint.bin.40.part-1-of-2"), if there is such a set: for the error of a
/// checkpoint that is neither a file nor a complete set.
pub fn missing_parts(path: &Path) -> Option<String> {
    let of = file_name(path);
    let parts = parts_beside(path, &of);
    let set = parts
        .chunk_by(|a, b| (a.1.step, a.1.n) == (b.1.step, b.1.n))
        .filter(|set| set.len() < set[0].1.n)
        .max_by_key(|set| set[0].1.step)?;
    let Part { step, n, .. } = set[0].1;
    let missing: Vec<String> = (0..n)
        .filter(|&k| set.iter().all(|p| p.1.k != k))
        .map(|k| format!("{of}.{step}.part-{k}-of-{n}"))
        .collect();
    Some(missing.join(", "))
}

/// Reads and joins the parts `paths` (part 0 to n-1 of one checkpoint).
pub fn load_parts(paths: &[PathBuf], fingerprint: Option<u64>) -> Result<Snapshot> {
    join_parts(paths, 0..paths.len(), fingerprint)
}

/// Reads part `k` of the parts `paths` of one checkpoint.
fn read_nth(paths: &[PathBuf], k: usize, fingerprint: Option<u64>) -> Result<Snapshot> {
    let bytes = crate::io::files::read(&paths[k])?;
    read_part(&bytes, k, paths.len(), fingerprint)
        .and_then(|piece| of_its_step(&paths[k], &piece).map(|()| piece))
        .with_context(|| format!("cannot resume from {}", paths[k].display()))
}

/// Reads and joins the parts `which` (not empty) of the parts `paths` of one checkpoint.
fn join_parts(
    paths: &[PathBuf],
    which: std::ops::Range<usize>,
    fingerprint: Option<u64>,
) -> Result<Snapshot> {
    let (first, last) = (which.start, which.end - 1);
    let pieces = which
        .map(|k| read_nth(paths, k, fingerprint))
        .collect::<Result<Vec<_>>>()?;
    join(pieces).with_context(|| {
        format!(
            "cannot join the parts {} to {}",
            paths[first].display(),
            paths[last].display()
        )
    })
}

/// Joins the newest complete set of parts of the checkpoint at `path` into the one file a
/// run in one process writes (with the parts' fingerprint), removing the parts; returns how
/// many it joined.
pub fn merge(path: &Path) -> Result<usize> {
    let Some(paths) = newer_parts(path) else {
        let lacking = missing_parts(path).map_or(String::new(), |m| format!(" ({m} missing)"));
        bail!(
            "{}: no complete set of parts newer than the file to join{lacking}",
            path.display()
        );
    };
    let mut head = [0; HEADER + STEP_AT];
    crate::io::files::open(&paths[0])?
        .read_exact(&mut head)
        .with_context(|| format!("cannot read {}", paths[0].display()))?;
    let fingerprint = u64::from_le_bytes(head[HEADER + STEP_AT - 8..].try_into()?);
    let joined = load_parts(&paths, Some(fingerprint))?;
    super::save(path, &joined, fingerprint)?;
    Ok(paths.len())
}

/// Process `j` of `count`'s share of the checkpoint at `path` when it is a set of parts
/// ([`newer_parts`]; `None` when it is one file): the parts `j n / count .. (j+1) n / count`
/// of the n, joined, so that no process reads all. A share of no part holds no particles
/// and the state all processes share (from the first part). Its springs name particles of
/// other shares too: a split run's redistribution sends them to their owners.
pub fn load_share(
    path: &Path,
    fingerprint: Option<u64>,
    (j, count): (usize, usize),
) -> Result<Option<Snapshot>> {
    let Some(paths) = newer_parts(path) else {
        return Ok(None);
    };
    let n = paths.len();
    let share = j * n / count..(j + 1) * n / count;
    if !share.is_empty() {
        return join_parts(&paths, share, fingerprint).map(Some);
    }
    let first = read_nth(&paths, 0, fingerprint)?;
    Ok(Some(shared_part(&first)))
}

fn read_part(bytes: &[u8], k: usize, n: usize, fingerprint: Option<u64>) -> Result<Snapshot> {
    if bytes.len() < HEADER || &bytes[..12] != MAGIC {
        bail!("not a part of a tinydem checkpoint (no 'TINYDEM PART' header)");
    }
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    if (word(12), word(16)) != (k, n) {
        bail!(
            "corrupt: its header says part {} of {}, its name part {k} of {n}",
            word(12),
            word(16)
        );
    }
    decode(&bytes[HEADER..], fingerprint)
}

/// Checks that the part `path`, read as `piece`, is of the step its name says.
fn of_its_step(path: &Path, piece: &Snapshot) -> Result<()> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
    let named = name.and_then(|n| {
        let at = n.find(".part-")?;
        n[..at].rsplit('.').next()?.parse::<u64>().ok()
    });
    ensure!(
        named == Some(piece.steps),
        "corrupt: it holds step {}, its name says another",
        piece.steps
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::particles::Particles;

    /// Two pieces of one state (particles 3 and 4, their contact in both) and their join.
    fn pieces() -> (Vec<Snapshot>, Snapshot) {
        let mut a = super::super::tests::snapshot();
        a.lonely.clear();
        let mut b = a.clone();
        let mut q = b.particles.get(0);
        q.x.x += 0.01;
        b.particles = Particles {
            next_id: a.particles.next_id,
            ..Particles::default()
        };
        b.particles.insert(4, q);
        b.face_history.clear();
        let mut whole = a.clone();
        whole.particles.insert(4, q);
        whole.anchors.push(b.anchors[0]);
        (vec![b, a], whole)
    }

    #[test]
    fn pieces_join_in_id_order_with_each_contact_once() {
        let (pieces, whole) = pieces();
        assert_eq!(join(pieces.clone()).unwrap(), whole);
        let mut other = pieces.clone();
        other[1].steps += 1;
        let e = join(other).unwrap_err().to_string();
        assert!(e.contains("part 1 is not of the state of part 0"), "{e}");
        let twice = vec![pieces[0].clone(), pieces[0].clone()];
        let e = join(twice).unwrap_err().to_string();
        assert!(e.contains("particle 4 is in two parts"), "{e}");
    }

    #[test]
    fn the_newest_complete_set_of_parts_is_read_and_a_checkpoint_removes_them() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("checkpoint.bin");
        let (pieces, whole) = pieces();
        // Part 0 alone (a stop that did not finish): no checkpoint to read, and the error
        // names the missing part.
        save_part(&path, 0, 2, &pieces[0], 7).unwrap();
        assert!(newer_parts(&path).is_none());
        let e = format!("{:#}", super::super::load(&path, Some(7)).unwrap_err());
        let missing = format!("checkpoint.bin.{}.part-1-of-2 missing", pieces[0].steps);
        assert!(e.contains(&missing), "{e}");
        // An older complete set is read while the newer one is unfinished.
        let mut old = pieces.clone();
        old.iter_mut()
            .for_each(|p| (p.steps, p.built_at) = (12000, 11900));
        save_part(&path, 0, 2, &old[0], 7).unwrap();
        save_part(&path, 1, 2, &old[1], 7).unwrap();
        assert_eq!(super::super::load(&path, Some(7)).unwrap().steps, 12000);
        // Both parts: read, joined.
        save_part(&path, 1, 2, &pieces[1], 7).unwrap();
        assert_eq!(super::super::load(&path, Some(7)).unwrap(), whole);
        // An older whole checkpoint beside them: the parts are newer.
        let mut older = whole.clone();
        (older.steps, older.built_at) = (100, 50);
        std::fs::write(&path, super::super::encode(&older, 7)).unwrap();
        assert_eq!(super::super::load(&path, Some(7)).unwrap(), whole);
        // A whole checkpoint of the same step (the join finished): the file is read.
        let mut same = whole.clone();
        same.particles.v[0].x = 9.0;
        std::fs::write(&path, super::super::encode(&same, 7)).unwrap();
        assert_eq!(super::super::load(&path, Some(7)).unwrap(), same);
        // A damaged part of the newest set is an error that names it.
        std::fs::remove_file(&path).unwrap();
        remove_parts(&path, Some(12345));
        let part = part_path(&path, 12345, 1, 2);
        let mut bytes = std::fs::read(&part).unwrap();
        bytes[60] ^= 1;
        std::fs::write(&part, &bytes).unwrap();
        let e = format!("{:#}", super::super::load(&path, Some(7)).unwrap_err());
        assert!(
            e.contains("checkpoint.bin.12345.part-1-of-2") && e.contains("checksum"),
            "{e}"
        );
        // A part renamed to another step is refused.
        std::fs::write(&part, &bytes[..]).unwrap();
        save_part(&path, 1, 2, &pieces[1], 7).unwrap();
        std::fs::rename(part_path(&path, 12345, 0, 2), part_path(&path, 12346, 0, 2)).unwrap();
        std::fs::rename(&part, part_path(&path, 12346, 1, 2)).unwrap();
        let e = format!("{:#}", super::super::load(&path, Some(7)).unwrap_err());
        assert!(e.contains("its name says another"), "{e}");
        // Saving the whole checkpoint removes the parts.
        super::super::save(&path, &whole, 7).unwrap();
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        assert_eq!(names, ["checkpoint.bin"]);
    }

    #[test]
    fn shares_of_the_parts_hold_each_part_once_and_a_damaged_one_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("checkpoint.bin");
        let (pieces, whole) = pieces();
        assert!(load_share(&path, Some(7), (0, 1)).unwrap().is_none());
        super::super::save(&path, &whole, 7).unwrap();
        assert!(
            load_share(&path, Some(7), (0, 2)).unwrap().is_none(),
            "one file"
        );
        save_part(&path, 0, 2, &pieces[0], 7).unwrap();
        save_part(&path, 1, 2, &pieces[1], 7).unwrap();
        std::fs::remove_file(&path).unwrap();
        let share = |j, count| load_share(&path, Some(7), (j, count)).unwrap().unwrap();
        assert_eq!(share(0, 1), whole, "one share: all parts");
        for count in [2, 3] {
            let shares: Vec<Snapshot> = (0..count).map(|j| share(j, count)).collect();
            let ids: Vec<u64> = shares.iter().flat_map(|s| s.particles.id.clone()).collect();
            assert_eq!(ids, [4, 3], "{count} shares: each part once, in order");
            for s in &shares {
                assert_eq!(
                    (s.steps, &s.spawner, &s.removed),
                    (whole.steps, &whole.spawner, &whole.removed)
                );
                assert_eq!(s.anchors.len(), s.particles.len());
            }
        }
        // Of 3 shares of 2 parts the first holds none; the contact of 3 and 4 is in both.
        assert!(share(0, 3).pair_history.is_empty() && share(0, 3).particles.is_empty());
        assert_eq!(share(1, 3).pair_history, share(2, 3).pair_history);
        let part = part_path(&path, whole.steps, 1, 2);
        let mut bytes = std::fs::read(&part).unwrap();
        bytes[60] ^= 1;
        std::fs::write(&part, &bytes).unwrap();
        let e = format!("{:#}", load_share(&path, Some(7), (1, 2)).unwrap_err());
        assert!(e.contains(".part-1-of-2") && e.contains("checksum"), "{e}");
        assert!(
            load_share(&path, Some(7), (0, 2)).is_ok(),
            "the other share reads"
        );
    }

    #[test]
    fn merge_joins_the_parts_into_the_one_file_with_their_fingerprint() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("checkpoint.bin");
        let (pieces, whole) = pieces();
        save_part(&path, 0, 2, &pieces[0], 7).unwrap();
        let e = format!("{:#}", merge(&path).unwrap_err());
        assert!(e.contains("part-1-of-2 missing"), "{e}");
        save_part(&path, 1, 2, &pieces[1], 7).unwrap();
        assert_eq!(merge(&path).unwrap(), 2);
        assert!(newer_parts(&path).is_none() && parts_beside(&path, "checkpoint.bin").is_empty());
        assert_eq!(super::super::load(&path, Some(7)).unwrap(), whole);
        assert!(merge(&path).is_err(), "nothing newer than the file to join");
    }

    #[test]
    fn part_names() {
        let path = Path::new("out/checkpoint.bin");
        assert_eq!(
            part_path(path, 700, 2, 3),
            Path::new("out/checkpoint.bin.700.part-2-of-3")
        );
        assert!(is_part("checkpoint.bin.700.part-2-of-3"));
        assert!(!is_part("checkpoint.bin.700.part-3-of-3"));
        assert!(!is_part("checkpoint.bin.700.part-x-of-3"));
        assert!(!is_part("checkpoint.bin.part-1-of-3"));
        assert!(!is_part("particles000001.csv"));
    }
}
