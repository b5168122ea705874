//! Particle frames in the original program's CSV format:
//! header `x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz`, one particle per line, full round-trip
//! precision, files `particlesNNNNNN.csv`. Runs that tag particles add a last column `tag`.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use glam::{DQuat, DVec3};

use crate::particles::{Particle, Particles};

pub const COLUMNS: [&str; 14] = [
    "x", "y", "z", "R", "vx", "vy", "vz", "q0", "q1", "q2", "q3", "wx", "wy", "wz",
];

/// The file name of frame `k`.
pub fn frame_name(k: u64) -> String {
    format!("particles{k:06}.csv")
}

/// Writes all particles as CSV text in id order, with the `tag` column if `tags`.
pub fn write_particles(out: &mut impl Write, p: &Particles, tags: bool) -> std::io::Result<()> {
    let mut line = String::with_capacity(512);
    out.write_all(COLUMNS.join(",").as_bytes())?;
    out.write_all(if tags { b",tag\n" } else { b"\n" })?;
    let mut buf = ryu::Buffer::new();
    for (_, q) in p.iter_by_id() {
        line.clear();
        let values = [
            q.x.x, q.x.y, q.x.z, q.radius, q.v.x, q.v.y, q.v.z, q.q.w, q.q.x, q.q.y, q.q.z, q.w.x,
            q.w.y, q.w.z,
        ];
        for (k, value) in values.iter().enumerate() {
            if k > 0 {
                line.push(',');
            }
            line.push_str(buf.format(*value));
        }
        if tags {
            line.push(',');
            line.push_str(itoa::Buffer::new().format(q.tag));
        }
        line.push('\n');
        out.write_all(line.as_bytes())?;
    }
    Ok(())
}

/// Writes a frame file atomically: to a temporary name first, then renamed, so a crash
/// never leaves a half-written frame behind.
pub fn write_frame(dir: &Path, k: u64, p: &Particles, tags: bool) -> Result<PathBuf> {
    write_frame_as(dir, &frame_name(k), p, tags)
}

/// Writes particles atomically to `dir/name`.
pub fn write_frame_as(dir: &Path, name: &str, p: &Particles, tags: bool) -> Result<PathBuf> {
    let path = dir.join(name);
    let tmp = dir.join(format!(".{name}.tmp"));
    let write = || -> std::io::Result<()> {
        let mut w = std::io::BufWriter::with_capacity(1 << 20, std::fs::File::create(&tmp)?);
        write_particles(&mut w, p, tags)?;
        w.into_inner().map_err(|e| e.into_error())?.sync_data()?;
        std::fs::rename(&tmp, &path)
    };
    write().with_context(|| format!("cannot write frame {}", path.display()))?;
    Ok(path)
}

/// Reads particles from CSV text. The header names the 14 columns (in any order); every
/// value must be a finite number, every radius positive, every quaternion non-zero (it
/// is normalised).
pub fn read_particles(input: impl Read, file: &str) -> Result<Particles> {
    let mut lines = BufReader::with_capacity(1 << 16, input);
    let mut header = String::new();
    if lines
        .read_line(&mut header)
        .map_err(|_| anyhow::anyhow!("{file}:1: cannot read line (not UTF-8 text?)"))?
        == 0
    {
        bail!(
            "{file}: empty file, expected the header line '{}'",
            COLUMNS.join(",")
        );
    }
    let names: Vec<&str> = header.trim().split(',').map(str::trim).collect();
    let mut slot = [usize::MAX; 14];
    let mut tag_column = None;
    for (col, name) in names.iter().enumerate() {
        if *name == "tag" && tag_column.is_none() {
            tag_column = Some(col);
            continue;
        }
        let Some(k) = COLUMNS.iter().position(|c| c == name) else {
            bail!(
                "{file}:1: unknown column '{name}': expected the header '{}'",
                COLUMNS.join(",")
            );
        };
        if slot[k] != usize::MAX {
            bail!("{file}:1: column '{name}' appears twice");
        }
        slot[k] = col;
    }
    if let Some(k) = slot.iter().position(|&s| s == usize::MAX) {
        bail!(
            "{file}:1: column '{}' is missing: expected the header '{}'",
            COLUMNS[k],
            COLUMNS.join(",")
        );
    }

    // Column of each of the 14 quantities, and which quantity each column holds.
    let mut quantity_of_column = vec![usize::MAX; names.len()];
    for (k, &col) in slot.iter().enumerate() {
        quantity_of_column[col] = k;
    }
    let mut particles = Particles::default();
    let mut values = [0.0f64; 14];
    let mut reader = lines;
    let mut buf = String::new();
    let mut n = 1;
    loop {
        buf.clear();
        n += 1;
        match reader.read_line(&mut buf) {
            Ok(0) => break,
            Ok(_) => {}
            Err(_) => bail!("{file}:{n}: cannot read line (not UTF-8 text?)"),
        }
        let line = buf.trim();
        if line.is_empty() {
            continue;
        }
        let mut count = 0;
        let mut tag = 0u32;
        for (col, text) in line.split(',').enumerate() {
            count += 1;
            if col >= names.len() {
                continue;
            }
            let text = text.trim();
            if Some(col) == tag_column {
                tag = text.parse().map_err(|_| {
                    anyhow::anyhow!("{file}:{n}: column {} ('tag'): expected a whole number >= 0, found '{text}'", col + 1)
                })?;
                continue;
            }
            let k = quantity_of_column[col];
            let x: f64 = text.parse().map_err(|_| {
                anyhow::anyhow!(
                    "{file}:{n}: column {} ('{}'): expected a number, found '{text}'",
                    col + 1,
                    COLUMNS[k]
                )
            })?;
            if !x.is_finite() {
                bail!(
                    "{file}:{n}: column {} ('{}'): expected a finite number, found '{text}'",
                    col + 1,
                    COLUMNS[k]
                );
            }
            values[k] = x;
        }
        if count != names.len() {
            bail!("{file}:{n}: expected {} values, found {count}", names.len());
        }
        let v = values;
        if v[3] <= 0.0 {
            bail!("{file}:{n}: radius R = {} must be > 0", v[3]);
        }
        let q = DQuat::from_xyzw(v[8], v[9], v[10], v[7]);
        let norm = q.length();
        if norm == 0.0 {
            bail!(
                "{file}:{n}: the quaternion (q0, q1, q2, q3) is zero; use 1,0,0,0 for no rotation"
            );
        }
        particles.push(Particle {
            x: DVec3::new(v[0], v[1], v[2]),
            radius: v[3],
            v: DVec3::new(v[4], v[5], v[6]),
            q: if (norm - 1.0).abs() < 1e-12 {
                q
            } else {
                q / norm
            },
            w: DVec3::new(v[11], v[12], v[13]),
            tag,
        });
    }
    Ok(particles)
}

/// Reads a particle CSV file.
pub fn load_particles(path: &Path) -> Result<Particles> {
    let f = std::fs::File::open(path)
        .with_context(|| format!("cannot read particle file {}", path.display()))?;
    read_particles(f, &path.display().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_is_exact() {
        let p: Particles = [Particle {
            x: DVec3::new(0.1, -1e-300, 1.0 / 3.0),
            radius: 0.004,
            v: DVec3::new(1e-7, 2.5, -0.0),
            q: DQuat::from_rotation_x(0.3),
            w: DVec3::new(1.0, 2.0, 3.0),
            tag: 42,
        }]
        .into_iter()
        .collect();
        let mut text = Vec::new();
        write_particles(&mut text, &p, true).unwrap();
        let back = read_particles(&text[..], "t").unwrap();
        assert_eq!(back, p);
    }

    fn err(text: &str) -> String {
        format!(
            "{:#}",
            read_particles(text.as_bytes(), "p.csv").unwrap_err()
        )
    }

    #[test]
    fn bad_lines_are_named() {
        let h = "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n";
        assert!(
            err(&format!("{h}0,0,0,1,0,0,0,1,0,0,0,0,0\n"))
                .contains("p.csv:2: expected 14 values, found 13")
        );
        assert!(err(&format!("{h}0,0,0,1,0,0,0,1,0,0,0,0,0,abc\n")).contains("found 'abc'"));
        assert!(
            err(&format!("{h}0,0,0,-1,0,0,0,1,0,0,0,0,0,0\n"))
                .contains("radius R = -1 must be > 0")
        );
        assert!(err(&format!("{h}0,0,NaN,1,0,0,0,1,0,0,0,0,0,0\n")).contains("finite"));
        assert!(err("x,y,z\n").contains("column 'R' is missing"));
        assert!(err("x,y,z,x\n").contains("appears twice"));
        assert!(err("").contains("empty file"));
    }
}
