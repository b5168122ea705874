//! Particle frames in the original program's CSV format:
//! header `x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz`, one particle per line, full round-trip
//! precision, files `particlesNNNNNN.csv`. Runs that tag particles add a column `tag`; runs
//! that can remove particles (or have several materials) add `id` and `material` after it;
//! runs with fixed particles `fixed` (1 for a fixed particle, 0 for one that moves) last.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use glam::{DQuat, DVec3};

use crate::engine::records::{ContactRecord, Partner};
use crate::model::fields::Optional;
use crate::model::particles::{Id, MAX_ID, OPTIONAL, Particle, Particles};

pub const COLUMNS: [&str; 14] = [
    "x", "y", "z", "R", "vx", "vy", "vz", "q0", "q1", "q2", "q3", "wx", "wy", "wz",
];

/// Whole-number columns a frame may carry beyond the fourteen.
/// The optional whole-number columns; `clump` (a clump's template index, -1 for a plain
/// sphere) is read as its value + 1.
pub const INT_COLUMNS: [&str; 5] = ["tag", "id", "material", "fixed", "clump"];

/// The file name of frame `k`.
pub fn frame_name(k: u64) -> String {
    format!("particles{k:06}.csv")
}

/// The columns of the contact force and torque on each row (`[output] forces`): written by
/// a run, and passed over when a frame is read.
pub const FORCE_COLUMNS: [&str; 6] = ["fx", "fy", "fz", "tx", "ty", "tz"];

/// The columns of a frame beyond the original fourteen.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Extra<'a> {
    /// `tag`
    pub tag: bool,
    /// `id` and `material`
    pub ids: bool,
    /// `fixed` (also written whenever a particle is fixed)
    pub fixed: bool,
    /// `clump` (the scenario has clumps): a row per rigid body, `R` its bounding radius
    pub clump: bool,
    /// [`FORCE_COLUMNS`]: each row's contact force and torque, by its id (a row without
    /// one has none)
    pub loads: Option<&'a crate::engine::records::Loads>,
}

/// The header line of a frame of `p` with the `extra` columns; and whether it has the
/// `fixed` and `clump` columns.
fn header(p: &Particles, extra: &Extra) -> (String, bool, bool) {
    let mut line = COLUMNS.join(",");
    if extra.tag {
        line.push_str(",tag");
    }
    if extra.ids {
        line.push_str(",id,material");
    }
    let fixed = extra.fixed || p.fixed.contains(&true);
    if fixed {
        line.push_str(",fixed");
    }
    let clump = extra.clump || !p.bodies.is_empty();
    if clump {
        line.push_str(",clump");
    }
    for f in p.active.framed() {
        line.push_str(&format!(",{}", f.columns().join(",")));
    }
    if extra.loads.is_some() {
        line.push_str(&format!(",{}", FORCE_COLUMNS.join(",")));
    }
    line.push('\n');
    (line, fixed, clump)
}

/// Writes all particles as CSV text in id order, with the `extra` columns.
pub fn write_particles(out: &mut impl Write, p: &Particles, extra: Extra) -> std::io::Result<()> {
    let mut line = String::with_capacity(512);
    let (header, fixed, clump) = header(p, &extra);
    out.write_all(header.as_bytes())?;
    let optional = p.active.framed();
    let mut numbers = Vec::new();
    let mut buf = ryu::Buffer::new();
    for i in p.id_order() {
        let (id, mut q) = (p.id[i], p.get(i));
        // A rigid body: one row, by its first sphere, with the body's motion.
        let mut template = -1;
        if let Some(b) = q.body {
            if id != b.first() {
                continue;
            }
            let body = &p.bodies.list[p.bodies.index_of(b).expect("a listed body")];
            (q.x, q.radius, q.v, q.q, q.w) = (body.x, body.bounding_radius, body.v, body.q, body.w);
            template = body.template as i64;
        }
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
        if extra.tag {
            line.push(',');
            line.push_str(itoa::Buffer::new().format(q.tag));
        }
        if extra.ids {
            line.push(',');
            line.push_str(itoa::Buffer::new().format(id));
            line.push(',');
            line.push_str(itoa::Buffer::new().format(q.material));
        }
        if fixed {
            line.push_str(if q.fixed { ",1" } else { ",0" });
        }
        if clump {
            line.push(',');
            line.push_str(itoa::Buffer::new().format(template));
        }
        numbers.clear();
        optional
            .iter()
            .for_each(|f| p.numbers(f.name, i, &mut numbers));
        for value in &numbers {
            line.push(',');
            line.push_str(buf.format(*value));
        }
        if let Some(loads) = extra.loads {
            let (f, t) = loads.get(&id).copied().unwrap_or_default();
            for value in [f.x, f.y, f.z, t.x, t.y, t.z] {
                line.push(',');
                line.push_str(buf.format(value));
            }
        }
        line.push('\n');
        out.write_all(line.as_bytes())?;
    }
    Ok(())
}

/// Writes particles atomically to `dir/name` (a frame, or a piece of one): to a temporary
/// name first, then renamed, so a crash never leaves a half-written frame behind.
pub fn write_frame_as(dir: &Path, name: &str, p: &Particles, extra: Extra) -> Result<PathBuf> {
    let path = dir.join(name);
    crate::io::files::write_atomically(&path, |w| write_particles(w, p, extra))
        .with_context(|| format!("cannot write frame {}", path.display()))?;
    Ok(path)
}

/// The header of a contact network file.
pub const CONTACT_COLUMNS: &str = "id_i,id_j,face,x,y,z,fn_x,fn_y,fn_z,ft_x,ft_y,ft_z,overlap,\
ti_x,ti_y,ti_z,tj_x,tj_y,tj_z";

/// The header of the contact networks of earlier versions, without the torques.
const CONTACT_COLUMNS_V1: &str = "id_i,id_j,face,x,y,z,fn_x,fn_y,fn_z,ft_x,ft_y,ft_z,overlap";

/// Writes the contact network atomically to `dir/name`: a line per contact, `id_j` or
/// `face` -1 where it does not apply.
pub fn write_contacts(dir: &Path, name: &str, contacts: &[ContactRecord]) -> Result<PathBuf> {
    let path = dir.join(name);
    let write = |w: &mut std::io::BufWriter<std::fs::File>| -> std::io::Result<()> {
        writeln!(w, "{CONTACT_COLUMNS}")?;
        let mut buf = ryu::Buffer::new();
        let mut line = String::with_capacity(256);
        for c in contacts {
            line.clear();
            let (j, f) = match c.with {
                Partner::Particle(j) => (j as i64, -1),
                Partner::Face(f) => (-1, f as i64),
            };
            line.push_str(itoa::Buffer::new().format(c.id));
            for k in [j, f] {
                line.push(',');
                line.push_str(itoa::Buffer::new().format(k));
            }
            for x in [
                c.point.x, c.point.y, c.point.z, c.f_n.x, c.f_n.y, c.f_n.z, c.f_t.x, c.f_t.y,
                c.f_t.z, c.overlap, c.tau_i.x, c.tau_i.y, c.tau_i.z, c.tau_j.x, c.tau_j.y,
                c.tau_j.z,
            ] {
                line.push(',');
                line.push_str(buf.format(x));
            }
            line.push('\n');
            w.write_all(line.as_bytes())?;
        }
        Ok(())
    };
    crate::io::files::write_atomically(&path, write)
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(path)
}

/// Reads a contact network written by [`write_contacts`] (`contactsNNNNNN.csv`).
pub fn load_contacts(path: &Path) -> Result<Vec<ContactRecord>> {
    let file = path.display().to_string();
    let text = std::io::read_to_string(
        crate::io::files::open(path).with_context(|| format!("cannot read contact file {file}"))?,
    )
    .with_context(|| format!("cannot read contact file {file}"))?;
    let mut lines = text.lines();
    let values = match lines.next().map(str::trim) {
        Some(CONTACT_COLUMNS) => 19,
        Some(CONTACT_COLUMNS_V1) => 13,
        _ => bail!("{file}:1: expected the header '{CONTACT_COLUMNS}'"),
    };
    lines
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(k, line)| contact(line, &file, k + 2, values))
        .collect()
}

/// One line `n` of a contact network of `values` columns (19, or 13 without the torques).
fn contact(line: &str, file: &str, n: usize, values: usize) -> Result<ContactRecord> {
    let fields: Vec<&str> = line.split(',').map(str::trim).collect();
    if fields.len() != values {
        bail!("{file}:{n}: {} values, expected {values}", fields.len());
    }
    let int = |k: usize| -> Result<i64> {
        (fields[k].parse())
            .map_err(|_| anyhow::anyhow!("{file}:{n}: '{}' is not a whole number", fields[k]))
    };
    let mut x = [0.0; 16];
    for (v, text) in x.iter_mut().zip(&fields[3..]) {
        *v = text
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| anyhow::anyhow!("{file}:{n}: '{text}' is not a finite number"))?;
    }
    let (id, j, face) = (int(0)?, int(1)?, int(2)?);
    let id = Id::try_from(id).map_err(|_| anyhow::anyhow!("{file}:{n}: id_i {id} out of range"))?;
    let with = match (j, face) {
        (j, -1) if j >= 0 => Partner::Particle(j as Id),
        (-1, f) if f >= 0 => Partner::Face(f as usize),
        _ => bail!(
            "{file}:{n}: a contact is with a particle (id_j, face = -1) or a face (id_j = -1, face)"
        ),
    };
    let v = |k: usize| DVec3::new(x[k], x[k + 1], x[k + 2]);
    Ok(ContactRecord {
        id,
        with,
        point: v(0),
        f_n: v(3),
        f_t: v(6),
        overlap: x[9],
        tau_i: v(10),
        tau_j: v(13),
    })
}

/// Whether column `col`, `name`, is one of an optional particle field's: then it is noted
/// in `optional` (each field with its columns); a column twice is an error.
fn optional_column(
    optional: &mut Vec<(&'static Optional, Vec<usize>)>,
    name: &str,
    col: usize,
    file: &str,
) -> Result<bool> {
    let Some(f) = OPTIONAL
        .iter()
        .find(|f| f.columns().iter().any(|c| c == name))
    else {
        return Ok(false);
    };
    let at = optional.iter().position(|(g, _)| *g == f);
    let at = at.unwrap_or_else(|| {
        optional.push((f, vec![usize::MAX; f.suffixes.len()]));
        optional.len() - 1
    });
    let k = f
        .columns()
        .iter()
        .position(|c| c == name)
        .expect("its column");
    if optional[at].1[k] != usize::MAX {
        bail!("{file}:1: column '{name}' appears twice");
    }
    optional[at].1[k] = col;
    Ok(true)
}

/// The columns of a particle CSV file, from its header.
struct Header {
    columns: usize,
    /// The columns a run writes that a frame read passes over ([`FORCE_COLUMNS`]).
    passed: Vec<usize>,
    /// The column of each optional whole-number quantity: tag, id, material, fixed.
    int_column: [Option<usize>; 5],
    /// The quantity (of the 14) each column holds.
    quantity_of_column: Vec<usize>,
    /// The optional particle fields the file holds, each with its columns.
    optional: Vec<(&'static Optional, Vec<usize>)>,
    /// Their columns, in that order.
    optional_columns: Vec<usize>,
}

impl Header {
    /// The header line `header` of `file`: the 14 columns in any order, and the optional
    /// ones.
    fn parse(header: &str, file: &str) -> Result<Header> {
        let names: Vec<&str> = header.trim().split(',').map(str::trim).collect();
        let mut slot = [usize::MAX; 14];
        // The optional whole-number columns: tag, id, material, fixed.
        let mut int_column = [None; 5];
        let mut passed = Vec::new();
        let mut optional = Vec::new();
        for (col, name) in names.iter().enumerate() {
            if FORCE_COLUMNS.contains(name) {
                passed.push(col);
                continue;
            }
            if optional_column(&mut optional, name, col, file)? {
                continue;
            }
            if let Some(k) = INT_COLUMNS.iter().position(|c| c == name) {
                if int_column[k].is_some() {
                    bail!("{file}:1: column '{name}' appears twice");
                }
                int_column[k] = Some(col);
                continue;
            }
            let Some(k) = COLUMNS.iter().position(|c| c == name) else {
                bail!(
                    "{file}:1: unknown column '{name}': expected the header '{}' (and optionally {})",
                    COLUMNS.join(","),
                    INT_COLUMNS.join(", ")
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

        for (f, columns) in &optional {
            if let Some(k) = columns.iter().position(|&c| c == usize::MAX) {
                bail!(
                    "{file}:1: column '{}' is missing: the field {} has the columns {}",
                    f.columns()[k],
                    f.name,
                    f.columns().join(",")
                );
            }
        }
        // Column of each of the 14 quantities, and which quantity each column holds.
        let mut quantity_of_column = vec![usize::MAX; names.len()];
        for (k, &col) in slot.iter().enumerate() {
            quantity_of_column[col] = k;
        }
        Ok(Header {
            columns: names.len(),
            passed,
            int_column,
            quantity_of_column,
            optional_columns: optional.iter().flat_map(|o| o.1.clone()).collect(),
            optional,
        })
    }

    /// The values of row `line` (line `n` of `file`): the 14 quantities and the whole
    /// numbers.
    /// The numbers of the optional fields go to `numbers`, in the order of `optional`.
    fn row(
        &self,
        line: &str,
        (n, file): (usize, &str),
        numbers: &mut Vec<f64>,
    ) -> Result<([f64; 14], [u64; 5])> {
        let (names, int_column, quantity_of_column) =
            (self.columns, &self.int_column, &self.quantity_of_column);
        let mut values = [0.0f64; 14];
        let mut count = 0;
        let mut ints = [0u64; 5];
        let fields = &self.optional_columns;
        numbers.clear();
        numbers.resize(fields.len(), 0.0);
        for (col, text) in line.split(',').enumerate() {
            count += 1;
            if col >= names || self.passed.contains(&col) {
                continue;
            }
            let text = text.trim();
            if let Some(k) = fields.iter().position(|&c| c == col) {
                numbers[k] = text.parse().map_err(|_| {
                    anyhow::anyhow!(
                        "{file}:{n}: column {} ('{}'): expected a number, found '{text}'",
                        col + 1,
                        self.name(col)
                    )
                })?;
                continue;
            }
            if let Some(k) = int_column.iter().position(|&c| c == Some(col)) {
                let parsed = if k == 4 {
                    text.parse::<i64>()
                        .ok()
                        .and_then(|c| u64::try_from(c + 1).ok())
                } else {
                    text.parse().ok()
                };
                ints[k] = parsed.ok_or_else(|| {
                    anyhow::anyhow!(
                        "{file}:{n}: column {} ('{}'): expected a whole number >= {}, found '{text}'",
                        col + 1,
                        INT_COLUMNS[k],
                        if k == 4 { -1 } else { 0 }
                    )
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
        if count != names {
            bail!("{file}:{n}: expected {names} values, found {count}");
        }
        Ok((values, ints))
    }

    /// The name of optional column `col`.
    fn name(&self, col: usize) -> String {
        let mut names = self.optional.iter().flat_map(|(f, cols)| {
            let names = f.columns();
            cols.iter()
                .zip(names)
                .map(|(&c, name)| (c, name))
                .collect::<Vec<_>>()
        });
        names
            .find(|&(c, _)| c == col)
            .map(|(_, name)| name)
            .unwrap_or_default()
    }

    /// Sets the optional fields of the particle stored last in `particles` to the row's
    /// `numbers`.
    fn set_optional(
        &self,
        particles: &mut Particles,
        numbers: &[f64],
        (n, file): (usize, &str),
    ) -> Result<()> {
        let (last, mut at) = (particles.len() - 1, 0);
        for (f, cols) in &self.optional {
            let values = &numbers[at..at + cols.len()];
            if !particles.set_numbers(f.name, last, values) {
                let names = f.columns().join(",");
                bail!("{file}:{n}: {names}: {values:?} is not a valid {}", f.name);
            }
            at += cols.len();
        }
        Ok(())
    }
}

/// The particle of a row's values `v` and whole numbers `ints` (line `n` of `file`).
fn particle(v: [f64; 14], ints: [u64; 5], n: usize, file: &str) -> Result<Particle> {
    if v[3] <= 0.0 {
        bail!("{file}:{n}: radius R = {} must be > 0", v[3]);
    }
    if ints[3] > 1 {
        bail!(
            "{file}:{n}: fixed = {}: expected 1 (fixed) or 0 (moving)",
            ints[3]
        );
    }
    let q = DQuat::from_xyzw(v[8], v[9], v[10], v[7]);
    let norm = q.length();
    if norm == 0.0 {
        bail!("{file}:{n}: the quaternion (q0, q1, q2, q3) is zero; use 1,0,0,0 for no rotation");
    }
    Ok(Particle {
        x: DVec3::new(v[0], v[1], v[2]),
        radius: v[3],
        v: DVec3::new(v[4], v[5], v[6]),
        q: if (norm - 1.0).abs() < 1e-12 {
            q
        } else {
            q / norm
        },
        w: DVec3::new(v[11], v[12], v[13]),
        tag: u32::try_from(ints[0])
            .map_err(|_| anyhow::anyhow!("{file}:{n}: tag {} is out of range", ints[0]))?,
        material: u16::try_from(ints[2])
            .map_err(|_| anyhow::anyhow!("{file}:{n}: material {} is out of range", ints[2]))?,
        fixed: ints[3] == 1,
        ..Default::default()
    })
}

/// The ids of a file's particles, which they keep (a frame of a run that removed some).
fn keep_ids(particles: &mut Particles, ids: Vec<Id>, file: &str) -> Result<()> {
    let mut sorted = ids.clone();
    sorted.sort_unstable();
    if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
        bail!("{file}: particle id {} appears twice", w[0]);
    }
    if sorted.last().is_some_and(|&m| m >= MAX_ID) {
        bail!("{file}: particle ids must be below {MAX_ID}");
    }
    particles.next_id = sorted.last().map_or(0, |&m| m + 1);
    particles.id = ids;
    Ok(())
}

/// Reads particles from CSV text. The header names the 14 columns (in any order); every
/// value must be a finite number, every radius positive, every quaternion non-zero (it
/// is normalised).
/// What a scenario allows of the particles of its input file (`[input] particles`): their
/// materials, and radii from half R_min (a shorter contact than Eq. 50's step resolves) to
/// 64 R_max (the most the exact load sums hold).
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    pub materials: usize,
    pub radius_min: f64,
    pub radius_max: f64,
}

impl Limits {
    /// What is wrong with particle `p` on line `n` of `file`, if anything.
    fn check(&self, p: &Particle, n: usize, file: &str) -> Result<()> {
        let (count, m) = (self.materials, p.material as usize);
        if m >= count {
            bail!(
                "{file}:{n}: material {m}, but the scenario has {count} material{} (0 to {})",
                if count == 1 { "" } else { "s" },
                count - 1
            );
        }
        if p.radius > 64.0 * self.radius_max {
            bail!(
                "{file}:{n}: radius R = {} is more than 64 times [geometry] radius_max = {}, the most the load sums hold: raise radius_max",
                p.radius,
                self.radius_max
            );
        }
        if p.radius < 0.5 * self.radius_min {
            bail!(
                "{file}:{n}: radius R = {} is below half [geometry] radius_min = {}: the time step (Eq. 50, of R_min) is too long for it; lower radius_min",
                p.radius,
                self.radius_min
            );
        }
        Ok(())
    }
}

/// Reads particles in the CSV format of the frames, each within `limits` (a scenario's).
pub fn load_particles_within(path: &Path, limits: &Limits) -> Result<Particles> {
    Ok(load_grains_within(path, limits)?.0)
}

/// The `clump` column of a particle file: each row's template index (`None` for a plain
/// sphere), and whether the file gave the ids (an `id` column).
#[derive(Clone, Debug, PartialEq)]
pub struct ClumpColumn {
    pub templates: Vec<Option<u16>>,
    pub ids: bool,
}

/// A particle file (a frame) with its `clump` column if it has one.
pub fn load_grains(path: &Path) -> Result<(Particles, Option<ClumpColumn>)> {
    let f = crate::io::files::open(path)
        .with_context(|| format!("cannot read particle file {}", path.display()))?;
    read_grains(f, &path.display().to_string(), None)
}

/// As [`load_particles_within`], with each row's `clump` column if the file has one (the
/// template's index, or `None` for a plain sphere).
pub fn load_grains_within(
    path: &Path,
    limits: &Limits,
) -> Result<(Particles, Option<ClumpColumn>)> {
    let f = crate::io::files::open(path)
        .with_context(|| format!("cannot read particle file {}", path.display()))?;
    read_grains(f, &path.display().to_string(), Some(limits))
}

/// Share `k` of `n` of a particle file (`[input] particles`), for a run split over `n`
/// processes whose process `k` reads only it: the rows that start in the k-th of n equal
/// byte ranges after the header, each row read by one process; and whether the file gives
/// the ids (an `id` column). Without, its ids count from 0 within the share: the caller
/// adds the rows of the shares before.
pub fn load_grains_share(
    path: &Path,
    limits: &Limits,
    (k, n): (usize, usize),
) -> Result<(Particles, Option<ClumpColumn>, bool)> {
    use std::io::{Seek, SeekFrom};
    let file = path.display().to_string();
    let mut f = crate::io::files::open(path)
        .with_context(|| format!("cannot read particle file {file}"))?;
    let len = f.metadata().map(|m| m.len()).unwrap_or(0);
    let mut header = String::new();
    BufReader::new(&mut f)
        .read_line(&mut header)
        .with_context(|| format!("{file}:1: cannot read line (not UTF-8 text?)"))?;
    let body = header.len() as u64;
    // The first row that starts at or after byte `at`.
    let mut row_at = |at: u64| -> Result<u64> {
        if at <= body || at >= len {
            return Ok(at.clamp(body, len));
        }
        f.seek(SeekFrom::Start(at - 1))?;
        let mut skipped = Vec::new();
        BufReader::new(&mut f).read_until(b'\n', &mut skipped)?;
        Ok(at - 1 + skipped.len() as u64)
    };
    let share = |j: usize| body + (len - body) * j as u64 / n as u64;
    let (from, to) = (row_at(share(k))?, row_at(share(k + 1))?);
    f.seek(SeekFrom::Start(from))?;
    let name = format!("{file} (the share of process {k} of {n}: bytes {from} to {to})");
    let ids = Header::parse(&header, &file)?.int_column[1].is_some();
    let rows = std::io::Cursor::new(header.into_bytes()).chain(f.take(to - from));
    let (particles, clumps) = read_grains(rows, &name, Some(limits))?;
    Ok((particles, clumps, ids))
}

pub fn read_particles(input: impl Read, file: &str) -> Result<Particles> {
    read_particles_within(input, file, None)
}

fn read_particles_within(
    input: impl Read,
    file: &str,
    limits: Option<&Limits>,
) -> Result<Particles> {
    Ok(read_grains(input, file, limits)?.0)
}

/// The particles of CSV text, and the `clump` column's values if it has one.
fn read_grains(
    input: impl Read,
    file: &str,
    limits: Option<&Limits>,
) -> Result<(Particles, Option<ClumpColumn>)> {
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
    let columns = Header::parse(&header, file)?;
    let mut particles = Particles::default();
    for (f, _) in &columns.optional {
        particles.activate(f.name);
    }
    let mut numbers = Vec::new();
    let mut ids = Vec::new();
    let mut clumps = Vec::new();
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
        let (values, ints) = columns.row(line, (n, file), &mut numbers)?;
        let p = particle(values, ints, n, file)?;
        if let Some(limits) = limits {
            limits.check(&p, n, file)?;
        }
        particles.push(p);
        columns.set_optional(&mut particles, &numbers, (n, file))?;
        if columns.int_column[1].is_some() {
            ids.push(ints[1]);
        }
        if columns.int_column[4].is_some() {
            let clump = ints[4].checked_sub(1).map(u16::try_from).transpose();
            clumps.push(clump.map_err(|_| {
                anyhow::anyhow!("{file}:{n}: clump {} is out of range", ints[4] - 1)
            })?);
        }
    }
    if columns.int_column[1].is_some() {
        keep_ids(&mut particles, ids, file)?;
    }
    let clumps = ClumpColumn {
        templates: clumps,
        ids: columns.int_column[1].is_some(),
    };
    Ok((particles, columns.int_column[4].is_some().then_some(clumps)))
}

/// Reads a particle CSV file.
pub fn load_particles(path: &Path) -> Result<Particles> {
    let f = crate::io::files::open(path)
        .with_context(|| format!("cannot read particle file {}", path.display()))?;
    read_particles(f, &path.display().to_string())
}

#[cfg(test)]
mod tests;
