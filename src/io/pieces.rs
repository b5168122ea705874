//! Frames a split run wrote in pieces (`[output] gather`): each process's particles in
//! `particlesNNNNNN_K.csv` (with ids) and its contacts in `contactsNNNNNN_K.csv`, K the
//! process. Read here as the one frame a gathered run writes, so that `analyze`, `render`
//! and `fields` take either.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

use crate::engine::records::ContactRecord;
use crate::io::csv::{ClumpColumn, load_contacts, load_grains};
use crate::model::particles::{Active, Id, Particle, Particles};

/// The number of the frame a file of an output directory names: `particlesNNNNNN.csv`, or
/// the first piece `particlesNNNNNN_0.csv` of a frame written in pieces (the other pieces
/// name none, so that a frame counts once).
pub fn frame_number(name: &str) -> Option<u64> {
    let stem = name.strip_prefix("particles")?.strip_suffix(".csv")?;
    let number = match stem.split_once('_') {
        None => stem,
        Some((k, "0")) => k,
        Some(_) => return None,
    };
    if number.len() < 6 || !number.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    number.parse().ok()
}

/// A frame (or its pieces) with each clump's row made into its spheres and body, from the
/// templates of `scenario` (the run's): what the analysis tools measure and draw.
pub fn load_frame_as_grains(
    path: &Path,
    scenario: &crate::scenario::Scenario,
) -> Result<Particles> {
    let (p, clumps) = load_frame(path)?;
    check_against_log(path, p.len())?;
    match clumps {
        Some(c) if c.templates.iter().any(Option::is_some) => {
            if scenario.clumps.is_empty() {
                bail!(
                    "{}: the frame has clumps, but the scenario read has no [[clumps]]: give the \
                     run's scenario (its run.toml)",
                    path.display()
                );
            }
            anyhow::Context::with_context(crate::io::inputs::with_clumps(scenario, p, &c), || {
                format!("frame {}", path.display())
            })
        }
        _ => Ok(p),
    }
}

/// A frame of `rows` particles (plain spheres and clumps) read from `path` holds as many as
/// its run's `log.csv` beside it says it had: a frame cut short at the end of a line reads
/// as a valid smaller one, which this tells apart. (No log, or no row for the frame: no
/// check.)
fn check_against_log(path: &Path, rows: usize) -> Result<()> {
    let (Some(dir), Some(k)) = (
        path.parent(),
        path.file_name().and_then(|n| frame_number(n.to_str()?)),
    ) else {
        return Ok(());
    };
    let Ok(log) = std::fs::read_to_string(dir.join(crate::io::output::LOG)) else {
        return Ok(());
    };
    let mut lines = log.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let (Some(f), Some(n)) = (
        header.iter().position(|&c| c == "frame"),
        header.iter().position(|&c| c == "particles"),
    ) else {
        return Ok(());
    };
    // The last row of the frame (a resumed run may have logged it twice).
    let logged = lines
        .rev()
        .filter_map(|l| {
            let v: Vec<&str> = l.split(',').collect();
            Some((
                v.get(f)?.parse::<u64>().ok()?,
                v.get(n)?.parse::<usize>().ok()?,
            ))
        })
        .find(|&(frame, _)| frame == k);
    match logged {
        Some((_, n)) if n != rows => bail!(
            "{}: {rows} particles, but the run's log.csv says frame {k} had {n}: the file is \
             cut short or from another run",
            path.display()
        ),
        _ => Ok(()),
    }
}

/// The pieces `stem_0.ext`, `stem_1.ext`, ... of the file `path` (`stem.ext`), in order:
/// `None` if there are none, an error if one is missing.
fn pieces_of(path: &Path) -> Option<Result<Vec<PathBuf>>> {
    let stem = path.file_stem()?.to_str()?;
    let ext = path.extension()?.to_str()?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut numbers: Vec<usize> = std::fs::read_dir(dir)
        .ok()?
        .filter_map(|e| {
            let name = e.ok()?.file_name().into_string().ok()?;
            name.strip_prefix(stem)?
                .strip_prefix('_')?
                .strip_suffix(ext)?
                .strip_suffix('.')?
                .parse()
                .ok()
        })
        .collect();
    numbers.sort_unstable();
    let last = *numbers.last()?;
    if let Some(k) = (0..numbers.len()).find(|&k| numbers[k] != k) {
        return Some(Err(anyhow::anyhow!(
            "{}: the pieces of a split run lack {stem}_{k}.{ext} (found {} pieces up to {stem}_{last}.{ext})",
            dir.display(),
            numbers.len(),
        )));
    }
    let name = |k: &usize| dir.join(format!("{stem}_{k}.{ext}"));
    Some(Ok(numbers.iter().map(name).collect()))
}

/// The frame at `path` (`particlesNNNNNN.csv`) with its `clump` column: the file, or the
/// pieces of a split run joined in id order.
pub fn load_frame(path: &Path) -> Result<(Particles, Option<ClumpColumn>)> {
    let Some(pieces) = pieces_of(path).filter(|_| !path.exists()) else {
        return load_grains(path);
    };
    let mut rows: Vec<(Id, Particle, Option<u16>)> = Vec::new();
    let (mut clumps, mut active) = (false, Active::default());
    for piece in pieces? {
        let (p, c) = load_grains(&piece)?;
        clumps |= c.is_some();
        active = p.active; // (every piece has the same columns)
        let template = |i: usize| c.as_ref().and_then(|c| c.templates[i]);
        rows.extend((0..p.len()).map(|i| (p.id[i], p.get(i), template(i))));
    }
    rows.sort_unstable_by_key(|r| r.0);
    if let Some(w) = rows.windows(2).find(|w| w[0].0 == w[1].0) {
        // (Pieces are written with ids: without, each would count from 0.)
        bail!("{}: particle {} is in two pieces", path.display(), w[0].0);
    }
    let mut particles = Particles {
        next_id: rows.last().map_or(0, |r| r.0 + 1),
        active,
        ..Particles::default()
    };
    let mut templates = Vec::with_capacity(rows.len());
    for (id, particle, template) in rows {
        particles.insert(id, particle);
        templates.push(template);
    }
    let clumps = clumps.then_some(ClumpColumn {
        templates,
        ids: true,
    });
    Ok((particles, clumps))
}

/// The contact network at `path` (`contactsNNNNNN.csv`): the file, or the pieces of a
/// split run joined in the order of the gathered file.
pub fn load_network(path: &Path) -> Result<Vec<ContactRecord>> {
    let Some(pieces) = pieces_of(path).filter(|_| !path.exists()) else {
        return load_contacts(path);
    };
    let mut all = Vec::new();
    for piece in pieces? {
        all.extend(load_contacts(&piece)?);
    }
    all.sort_by_key(ContactRecord::network_order);
    Ok(all)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_named_once_whole_or_in_pieces() {
        assert_eq!(frame_number("particles000012.csv"), Some(12));
        assert_eq!(frame_number("particles000012_0.csv"), Some(12));
        assert_eq!(frame_number("particles000012_1.csv"), None);
        assert_eq!(frame_number("particles000012.vtu"), None);
        assert_eq!(frame_number("particles.csv"), None);
        assert_eq!(frame_number("particles_a.csv"), None);
    }

    #[test]
    fn pieces_join_in_id_order_and_a_gap_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let header = "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,id,material\n";
        let row = |id: u32| format!("{id}.0,0,0,0.5,0,0,0,1,0,0,0,0,0,0,{id},0\n");
        for (k, ids) in [(0, vec![4, 1]), (1, vec![0, 3, 2])] {
            let text: String = std::iter::once(header.to_string())
                .chain(ids.into_iter().map(row))
                .collect();
            std::fs::write(dir.path().join(format!("particles000003_{k}.csv")), text).unwrap();
        }
        let path = dir.path().join("particles000003.csv");
        let (p, clumps) = load_frame(&path).unwrap();
        assert_eq!(p.id, [0, 1, 2, 3, 4]);
        assert_eq!(p.x[4].x, 4.0);
        assert_eq!(p.next_id, 5);
        assert!(clumps.is_none());
        std::fs::rename(
            dir.path().join("particles000003_1.csv"),
            dir.path().join("particles000003_2.csv"),
        )
        .unwrap();
        let err = format!("{:#}", load_frame(&path).unwrap_err());
        assert!(err.contains("lack particles000003_1.csv"), "{err}");
        let err = format!(
            "{:#}",
            load_frame(&dir.path().join("particles000009.csv")).unwrap_err()
        );
        assert!(err.contains("cannot read particle file"), "{err}");
    }
}
