//! ParaView-ready output: VTK XML unstructured grids (`.vtu`) with binary (raw appended)
//! data, and a `.pvd` collection that lists the frames with their times.
//!
//! Particles are points with one vertex cell each and the point arrays `radius`,
//! `velocity`, `angular_velocity`, `orientation` (the quaternion q0, q1, q2, q3), `tag`,
//! `id`, `material` (its index in the scenario's materials) and `fixed` (1 if it is held,
//! 0 if it moves); the mesh is its faces
//! (vertex, line, triangle and quad cells) with the cell array `radius`.

use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};

use crate::engine::records::{ContactRecord, Loads, Partner};
use crate::geometry::mesh::{Mesh, Primitive};
use crate::model::particles::{Active, Id, Particles};

/// Where an array goes in the file.
#[derive(Clone, Copy, PartialEq)]
enum Section {
    PointData,
    CellData,
    Points,
    Cells,
}

/// A `.vtu` file under construction: XML header text and the appended binary block; and
/// the arrays it has, as the parallel file that lists pieces of its kind declares them.
struct Vtu {
    point_data: String,
    cell_data: String,
    points: String,
    cells: String,
    appended: Vec<u8>,
    declared: Vec<(Section, String)>,
}

/// An array's element type as VTK names it.
trait VtkType: Copy {
    const NAME: &'static str;
    fn put(self, out: &mut Vec<u8>);
}

/// Little-endian numbers of the named VTK type.
macro_rules! vtk_number {
    ($($t:ty => $name:literal),*) => {$(
        impl VtkType for $t {
            const NAME: &'static str = $name;
            fn put(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
        }
    )*};
}

vtk_number!(f64 => "Float64", i64 => "Int64", u32 => "UInt32");

impl VtkType for u8 {
    const NAME: &'static str = "UInt8";
    fn put(self, out: &mut Vec<u8>) {
        out.push(self);
    }
}

impl Vtu {
    fn new() -> Vtu {
        Vtu {
            point_data: String::new(),
            cell_data: String::new(),
            points: String::new(),
            cells: String::new(),
            appended: Vec::new(),
            declared: Vec::new(),
        }
    }

    /// Appends one array of `count` values (UInt64 byte count, then the values) and adds its
    /// XML element to `section`.
    fn array<T: VtkType>(
        &mut self,
        section: Section,
        name: &str,
        components: usize,
        count: usize,
        values: impl Iterator<Item = T>,
    ) {
        let offset = self.appended.len();
        let bytes = count * std::mem::size_of::<T>();
        self.appended
            .extend_from_slice(&(bytes as u64).to_le_bytes());
        self.appended.reserve(bytes);
        let mut written = 0;
        for v in values {
            v.put(&mut self.appended);
            written += 1;
        }
        debug_assert_eq!(written, count);
        let element = format!(
            "        <DataArray type=\"{}\" Name=\"{name}\" NumberOfComponents=\"{components}\" format=\"appended\" offset=\"{offset}\"/>\n",
            T::NAME
        );
        self.declared.push((
            section,
            format!(
                "      <PDataArray type=\"{}\" Name=\"{name}\" NumberOfComponents=\"{components}\"/>\n",
                T::NAME
            ),
        ));
        match section {
            Section::PointData => self.point_data += &element,
            Section::CellData => self.cell_data += &element,
            Section::Points => self.points += &element,
            Section::Cells => self.cells += &element,
        }
    }

    fn write(&self, path: &Path, points: usize, cells: usize) -> Result<()> {
        self.write_as(
            path,
            points,
            cells,
            "UnstructuredGrid",
            "Cells",
            "NumberOfCells",
        )
    }

    /// Writes the file as a `kind` (`UnstructuredGrid`, or `PolyData` whose cells are
    /// `Lines`).
    fn write_as(
        &self,
        path: &Path,
        points: usize,
        cells: usize,
        kind: &str,
        cells_tag: &str,
        count_attribute: &str,
    ) -> Result<()> {
        let mut text = String::new();
        text.push_str("<?xml version=\"1.0\"?>\n");
        text.push_str(&format!(
            "<VTKFile type=\"{kind}\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
        ));
        text.push_str(&format!("  <{kind}>\n"));
        text.push_str(&format!(
            "    <Piece NumberOfPoints=\"{points}\" {count_attribute}=\"{cells}\">\n"
        ));
        text.push_str(&format!(
            "      <PointData>\n{}      </PointData>\n",
            self.point_data
        ));
        text.push_str(&format!(
            "      <CellData>\n{}      </CellData>\n",
            self.cell_data
        ));
        text.push_str(&format!("      <Points>\n{}      </Points>\n", self.points));
        text.push_str(&format!(
            "      <{cells_tag}>\n{}      </{cells_tag}>\n",
            self.cells
        ));
        text.push_str(&format!(
            "    </Piece>\n  </{kind}>\n  <AppendedData encoding=\"raw\">\n   _"
        ));
        let tail = "\n  </AppendedData>\n</VTKFile>\n";
        atomic_write(path, &[text.as_bytes(), &self.appended, tail.as_bytes()])
    }

    /// Writes the parallel file (`kind` `PUnstructuredGrid` or `PPolyData`) that lists the
    /// pieces `sources` (file names beside it), each with the arrays of this one.
    fn write_list(&self, path: &Path, kind: &str, sources: &[String]) -> Result<()> {
        let declared = |section: Section| -> String {
            let of = self.declared.iter().filter(|d| d.0 == section);
            of.map(|d| d.1.as_str()).collect()
        };
        let mut text = String::from("<?xml version=\"1.0\"?>\n");
        text += &format!(
            "<VTKFile type=\"{kind}\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
        );
        text += &format!("  <{kind} GhostLevel=\"0\">\n");
        text += &format!(
            "    <PPointData>\n{}    </PPointData>\n",
            declared(Section::PointData)
        );
        text += &format!(
            "    <PCellData>\n{}    </PCellData>\n",
            declared(Section::CellData)
        );
        text += &format!(
            "    <PPoints>\n{}    </PPoints>\n",
            declared(Section::Points)
        );
        for s in sources {
            text += &format!("    <Piece Source=\"{s}\"/>\n");
        }
        text += &format!("  </{kind}>\n</VTKFile>\n");
        atomic_write(path, &[text.as_bytes()])
    }

    /// A named array of `n` 3-vectors.
    fn vectors(
        &mut self,
        section: Section,
        name: &str,
        n: usize,
        values: impl Iterator<Item = glam::DVec3>,
    ) {
        self.array(section, name, 3, 3 * n, values.flat_map(|a| a.to_array()));
    }
}

/// A regular grid of points as VTK image data (`.vti`), for fields: `counts` points along
/// x, y, z (x the fastest), the first at `origin`, `spacing` apart.
pub struct Image {
    pub origin: glam::DVec3,
    pub spacing: glam::DVec3,
    pub counts: [usize; 3],
}

impl Image {
    /// Writes the point arrays `arrays` (a name, its number of components, and the values,
    /// point by point) to `path`.
    pub fn write(&self, path: &Path, arrays: &[(&str, usize, &[f64])]) -> Result<()> {
        let mut v = Vtu::new();
        for &(name, components, values) in arrays {
            v.array(
                Section::PointData,
                name,
                components,
                values.len(),
                values.iter().copied(),
            );
        }
        let [nx, ny, nz] = self.counts.map(|n| n.max(1) - 1);
        let extent = format!("0 {nx} 0 {ny} 0 {nz}");
        let (o, h) = (self.origin, self.spacing);
        let mut text = String::from("<?xml version=\"1.0\"?>\n");
        text += "<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n";
        text += &format!(
            "  <ImageData WholeExtent=\"{extent}\" Origin=\"{} {} {}\" Spacing=\"{} {} {}\">\n",
            o.x, o.y, o.z, h.x, h.y, h.z
        );
        text += &format!("    <Piece Extent=\"{extent}\">\n");
        text += &format!("      <PointData>\n{}      </PointData>\n", v.point_data);
        text += "      <CellData>\n      </CellData>\n";
        text += "    </Piece>\n  </ImageData>\n  <AppendedData encoding=\"raw\">\n   _";
        let tail = "\n  </AppendedData>\n</VTKFile>\n";
        atomic_write(path, &[text.as_bytes(), &v.appended, tail.as_bytes()])
    }
}

/// Writes `parts` to a temporary file and renames it to `path`.
fn atomic_write(path: &Path, parts: &[&[u8]]) -> Result<()> {
    crate::io::files::write_atomically(path, |w| parts.iter().try_for_each(|p| w.write_all(p)))
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Writes the particles as a `.vtu` file, in id order; with the arrays `force` and `torque`
/// of each particle's contacts if `loads` are given (by id).
pub fn write_particles(path: &Path, p: &Particles, loads: Option<&Loads>) -> Result<()> {
    particles_vtu(p, !p.bodies.is_empty(), loads).write(path, p.len(), p.len())
}

/// Writes one process's piece of the particles of a frame (as [`write_particles`]; with
/// the `body` array if `bodies`, so that all pieces have the same arrays).
pub fn write_particle_piece(
    path: &Path,
    p: &Particles,
    bodies: bool,
    loads: Option<&Loads>,
) -> Result<()> {
    particles_vtu(p, bodies, loads).write(path, p.len(), p.len())
}

/// Writes the `.pvtu` file that makes the pieces `sources` (of [`write_particle_piece`])
/// one data set for ParaView; `forces`: they hold `force` and `torque`; `active`: the
/// optional fields they hold.
pub fn write_particle_list(
    path: &Path,
    sources: &[String],
    (bodies, forces): (bool, bool),
    active: Active,
) -> Result<()> {
    let none = Loads::default();
    let loads = forces.then_some(&none);
    let p = Particles {
        active,
        ..Particles::default()
    };
    particles_vtu(&p, bodies, loads).write_list(path, "PUnstructuredGrid", sources)
}

/// The particles' file, in id order; with the `body` array if `bodies`, and `force` and
/// `torque` from `loads`.
fn particles_vtu(p: &Particles, bodies: bool, loads: Option<&Loads>) -> Vtu {
    use Section::*;
    let n = p.len();
    let order = p.id_order();
    let by_id = || order.iter().copied();
    let mut v = Vtu::new();
    // (Int64, VTK's own id type: ids stay below 2^62.)
    v.array(PointData, "id", 1, n, by_id().map(|i| p.id[i] as i64));
    v.array(PointData, "radius", 1, n, by_id().map(|i| p.radius[i]));
    v.vectors(PointData, "velocity", n, by_id().map(|i| p.v[i]));
    v.vectors(PointData, "angular_velocity", n, by_id().map(|i| p.w[i]));
    v.array(
        PointData,
        "orientation",
        4,
        4 * n,
        by_id().flat_map(|i| [p.q[i].w, p.q[i].x, p.q[i].y, p.q[i].z]),
    );
    v.array(PointData, "tag", 1, n, by_id().map(|i| p.tag[i]));
    v.array(
        PointData,
        "material",
        1,
        n,
        by_id().map(|i| p.material[i] as u32),
    );
    v.array(PointData, "fixed", 1, n, by_id().map(|i| p.fixed[i] as u8));
    if bodies {
        // Every sphere of a clump is a point, with its body's id (its first sphere's): -1
        // for a plain sphere.
        let body = |i: usize| p.body[i].map_or(-1, |b| b.first() as i64);
        v.array(PointData, "body", 1, n, by_id().map(body));
    }
    if let Some(loads) = loads {
        let load = |i: usize| loads.get(&p.id[i]).copied().unwrap_or_default();
        v.vectors(PointData, "force", n, by_id().map(|i| load(i).0));
        v.vectors(PointData, "torque", n, by_id().map(|i| load(i).1));
    }
    for f in p.active.framed() {
        let k = f.suffixes.len();
        let mut numbers = Vec::with_capacity(k * n);
        by_id().for_each(|i| p.numbers(f.name, i, &mut numbers));
        v.array(PointData, f.name, k, k * n, numbers.into_iter());
    }
    v.vectors(Points, "points", n, by_id().map(|i| p.x[i]));
    v.array(Cells, "connectivity", 1, n, 0..n as i64);
    v.array(Cells, "offsets", 1, n, 1..=n as i64);
    v.array(Cells, "types", 1, n, std::iter::repeat_n(1u8, n)); // VTK_VERTEX
    v
}

/// Writes the mesh faces as a `.vtu` file: one cell per face, with its radius.
pub fn write_mesh(path: &Path, mesh: &Mesh) -> Result<()> {
    write_mesh_with(path, mesh, &[])
}

/// Writes the mesh faces as [`write_mesh`] does, with further cell arrays: each its name, its
/// number of components and a value per face and component.
pub fn write_mesh_with(path: &Path, mesh: &Mesh, cells: &[(&str, usize, &[f64])]) -> Result<()> {
    use Section::*;
    let mut points = Vec::new();
    let mut connectivity = Vec::new();
    let mut offsets = Vec::new();
    let mut types = Vec::new();
    for face in &mesh.faces {
        let (corners, vtk_type): (Vec<glam::DVec3>, u8) = match face.shape {
            Primitive::Point(a) => (vec![a], 1),         // VTK_VERTEX
            Primitive::Segment(a, b) => (vec![a, b], 3), // VTK_LINE
            Primitive::Triangle { a, b, c, .. } => (vec![a, b, c], 5), // VTK_TRIANGLE
            Primitive::Rectangle { o, e1, e2, .. } => (vec![o, o + e1, o + e1 + e2, o + e2], 9), // VTK_QUAD
        };
        for c in corners {
            connectivity.push(points.len() as i64);
            points.push(c);
        }
        offsets.push(connectivity.len() as i64);
        types.push(vtk_type);
    }
    let (np, nc) = (points.len(), mesh.faces.len());
    let mut v = Vtu::new();
    v.array(
        CellData,
        "radius",
        1,
        nc,
        mesh.faces.iter().map(|f| f.radius),
    );
    for (name, components, values) in cells {
        v.array(CellData, name, *components, nc, values.iter().copied());
    }
    v.vectors(Points, "points", points.len(), points.iter().copied());
    v.array(
        Cells,
        "connectivity",
        1,
        connectivity.len(),
        connectivity.into_iter(),
    );
    v.array(Cells, "offsets", 1, nc, offsets.into_iter());
    v.array(Cells, "types", 1, nc, types.into_iter());
    v.write(path, np, nc)
}

/// Writes the contact network as `.vtp` lines: particle centre to particle centre for a
/// pair, centre to contact point for a face, with the cell arrays `normal_force` and
/// `tangential_force` (magnitudes \[N\]), `overlap` \[m\] and `face` (-1 for pairs).
/// `p` holds the particles of the contacts (of a piece: own and ghosts).
pub fn write_contacts(path: &Path, p: &Particles, contacts: &[ContactRecord]) -> Result<()> {
    let n = contacts.len();
    let v = contacts_vtp(p, contacts);
    v.write_as(path, 2 * n, n, "PolyData", "Lines", "NumberOfLines")
}

/// Writes the `.pvtp` file that makes the pieces `sources` (of [`write_contacts`]) one
/// data set for ParaView.
pub fn write_contact_list(path: &Path, sources: &[String]) -> Result<()> {
    contacts_vtp(&Particles::default(), &[]).write_list(path, "PPolyData", sources)
}

/// The contact network's file.
fn contacts_vtp(p: &Particles, contacts: &[ContactRecord]) -> Vtu {
    use Section::*;
    let at: rustc_hash::FxHashMap<Id, usize> =
        p.id.iter().enumerate().map(|(k, &id)| (id, k)).collect();
    let mut points = Vec::with_capacity(2 * contacts.len());
    for c in contacts {
        let xi = p.x[at[&c.id]];
        points.push(xi);
        points.push(match c.with {
            // A pair across a periodic side: to the contact point rather than across the box.
            Partner::Particle(j)
                if (p.x[at[&(j as Id)]] - xi).length() <= 4.0 * (c.point - xi).length() =>
            {
                p.x[at[&(j as Id)]]
            }
            _ => c.point,
        });
    }
    let n = contacts.len();
    let mut v = Vtu::new();
    v.array(
        CellData,
        "normal_force",
        1,
        n,
        contacts.iter().map(|c| c.f_n.length()),
    );
    v.array(
        CellData,
        "tangential_force",
        1,
        n,
        contacts.iter().map(|c| c.f_t.length()),
    );
    v.array(
        CellData,
        "overlap",
        1,
        n,
        contacts.iter().map(|c| c.overlap),
    );
    v.array(
        CellData,
        "face",
        1,
        n,
        contacts.iter().map(|c| match c.with {
            Partner::Particle(_) => -1i64,
            Partner::Face(f) => f as i64,
        }),
    );
    v.vectors(Points, "points", 2 * n, points.into_iter());
    v.array(Cells, "connectivity", 1, 2 * n, 0..2 * n as i64);
    v.array(Cells, "offsets", 1, n, (1..=n as i64).map(|k| 2 * k));
    v
}

/// Writes a `.pvd` collection of `(time, file name)` entries.
pub fn write_collection(path: &Path, entries: &[(f64, String)]) -> Result<()> {
    let mut text = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (time, file) in entries {
        text.push_str(&format!(
            "    <DataSet timestep=\"{time:e}\" part=\"0\" file=\"{file}\"/>\n"
        ));
    }
    text.push_str("  </Collection>\n</VTKFile>\n");
    atomic_write(path, &[text.as_bytes()])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::particles::Particle;

    /// An optional field the particles hold is an array of their file and of the listing of
    /// a split run's pieces.
    #[test]
    fn an_optional_field_is_an_array() {
        let dir = tempfile::tempdir().unwrap();
        let mut p: Particles = [Particle {
            radius: 0.01,
            ..Default::default()
        }]
        .into_iter()
        .collect();
        let (file, list) = (dir.path().join("p.vtu"), dir.path().join("p.pvtu"));
        write_particles(&file, &p, None).unwrap();
        let array = "Name=\"probe\" NumberOfComponents=\"1\"";
        let text =
            |path: &Path| String::from_utf8_lossy(&std::fs::read(path).unwrap()).into_owned();
        assert!(!text(&file).contains(array));
        p.activate("probe");
        write_particles(&file, &p, None).unwrap();
        assert!(text(&file).contains(array));
        write_particle_list(&list, &["p.vtu".into()], (false, false), p.active).unwrap();
        assert!(text(&list).contains(array));
    }
}
