//! ParaView output: the `.vtu` frames hold exactly the values of the CSV frames, read by this
//! test's own reader of VTK's raw appended XML (always) and by a real VTK reader (meshio, from
//! PyPI) where python3 has it; `.ci/run` installs meshio, and under CI its check must run.

use crate::common;

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

/// The arrays of a VTK XML file with raw appended data, by name, as f64 (VTK's Float64,
/// Int64, UInt32 and UInt8), read from the XML headers and the blocks they point to.
fn read_raw_appended(path: &Path) -> BTreeMap<String, Vec<f64>> {
    let bytes = std::fs::read(path).unwrap();
    let marker = b"<AppendedData encoding=\"raw\">";
    let at = (bytes.windows(marker.len()).position(|w| w == marker)).expect("appended data");
    let head = std::str::from_utf8(&bytes[..at]).unwrap();
    let blob = &bytes[at + marker.len()..];
    let blob = &blob[blob.iter().position(|&b| b == b'_').unwrap() + 1..];
    assert!(head.contains("header_type=\"UInt64\""), "{head}");
    let attribute = |tag: &str, name: &str| -> String {
        let start = tag.find(&format!(" {name}=\"")).expect(name) + name.len() + 3;
        tag[start..start + tag[start..].find('"').unwrap()].to_string()
    };
    let mut arrays = BTreeMap::new();
    for tag in head.split("<DataArray").skip(1) {
        let offset: usize = attribute(tag, "offset").parse().unwrap();
        let size = u64::from_le_bytes(blob[offset..offset + 8].try_into().unwrap()) as usize;
        let data = &blob[offset + 8..offset + 8 + size];
        let values: Vec<f64> = match attribute(tag, "type").as_str() {
            "Float64" => data
                .chunks(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                .collect(),
            "Int64" => data
                .chunks(8)
                .map(|c| i64::from_le_bytes(c.try_into().unwrap()) as f64)
                .collect(),
            "UInt32" => data
                .chunks(4)
                .map(|c| u32::from_le_bytes(c.try_into().unwrap()) as f64)
                .collect(),
            "UInt8" => data.iter().map(|&b| b as f64).collect(),
            other => panic!("type {other}"),
        };
        arrays.insert(attribute(tag, "Name"), values);
    }
    arrays
}

/// The columns of a CSV frame by name (numbers as f64; rows in order).
fn read_csv_columns(path: &Path) -> BTreeMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let names: Vec<&str> = lines.next().unwrap().split(',').collect();
    let mut columns: BTreeMap<String, Vec<f64>> =
        names.iter().map(|c| (c.to_string(), Vec::new())).collect();
    for line in lines {
        for (name, value) in names.iter().zip(line.split(',')) {
            let column = columns.entry(name.to_string()).or_default();
            column.push(value.parse().unwrap());
        }
    }
    columns
}

/// Each particle array of the `.vtu` frame equals the CSV frame's columns bit for bit.
fn assert_frame_matches_csv(out: &Path, frame: usize) {
    let vtu = read_raw_appended(&out.join(format!("particles{frame:06}.vtu")));
    let csv = read_csv_columns(&out.join(format!("particles{frame:06}.csv")));
    let n = csv["x"].len();
    let rows = |names: &[&str]| -> Vec<f64> {
        let columns: Vec<&Vec<f64>> = names.iter().map(|c| &csv[*c]).collect();
        let mut v = Vec::with_capacity(n * names.len());
        for k in 0..n {
            v.extend(columns.iter().map(|c| c[k]));
        }
        v
    };
    let expected = [
        ("points", rows(&["x", "y", "z"])),
        ("radius", rows(&["R"])),
        ("velocity", rows(&["vx", "vy", "vz"])),
        ("angular_velocity", rows(&["wx", "wy", "wz"])),
        ("orientation", rows(&["q0", "q1", "q2", "q3"])),
    ];
    for (name, values) in expected {
        assert_eq!(vtu[name], values, "{name} of frame {frame}");
    }
    for name in ["tag", "id", "material", "fixed"] {
        if let Some(column) = csv.get(name) {
            assert_eq!(&vtu[name], column, "{name} of frame {frame}");
        }
    }
    assert_eq!(vtu["types"], vec![1.0; n], "one vertex cell per particle");
    assert_eq!(
        vtu["connectivity"],
        (0..n).map(|k| k as f64).collect::<Vec<_>>()
    );
}

#[test]
fn vtk_frames_match_csv_frames_in_a_real_reader() {
    let t = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::write(
        t.path().join("s.toml"),
        format!(
            "[geometry]\nradius_min = 0.003\nradius_max = 0.005\nmesh = \"{}\"\nmesh_radii = [0.0, 0.001]\n\
             spawn_min = [-0.02, -0.02, 0.05]\nspawn_max = [0.02, 0.02, 0.1]\n\
             [kinetics]\ninitial_angular_velocity = [1.0, 2.0, 3.0]\n\
             [simulation]\nmax_particles = 150\nspawn_attempts = 5\nframes = 3\nsteps_per_frame = 500\n\
             [output]\nformats = [\"csv\", \"vtk\"]\ncontacts = true\n",
            root.join("tests/scenarios/good/box.off").display()
        ),
    )
    .unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_tinydem"))
        .args(["run", "s.toml", "-q"])
        .current_dir(t.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = t.path().join("output");
    for frame in 0..=3 {
        assert_frame_matches_csv(&out, frame);
    }
    assert!(read_csv_columns(&out.join("particles000003.csv"))["x"].len() > 100);
    if !common::has_meshio() {
        return;
    }
    let check = Command::new("python3")
        .arg(root.join("tests/vtk_check.py"))
        .args([out.to_str().unwrap(), "3"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&check.stdout).into_owned()
        + &String::from_utf8_lossy(&check.stderr);
    assert!(check.status.success(), "{text}");
    assert!(text.contains("identical to the CSV"), "{text}");
}
