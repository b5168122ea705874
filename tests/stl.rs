//! STL meshes (ASCII and binary) give exactly the trajectories of the same triangles in OFF.

use std::path::Path;
use std::process::Command;

/// An open box of edge 1/16 m and height 1/8 m as triangles (coordinates exact in f32).
fn triangles() -> Vec<[[f32; 3]; 3]> {
    let (a, h) = (0.03125f32, 0.125f32);
    let c = [
        [-a, -a, 0.0],
        [a, -a, 0.0],
        [a, a, 0.0],
        [-a, a, 0.0],
        [-a, -a, h],
        [a, -a, h],
        [a, a, h],
        [-a, a, h],
    ];
    let quads = [
        [0, 1, 2, 3],
        [0, 1, 5, 4],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 0, 4, 7],
    ];
    quads
        .iter()
        .flat_map(|q| [[c[q[0]], c[q[1]], c[q[2]]], [c[q[0]], c[q[2]], c[q[3]]]])
        .collect()
}

fn off(t: &[[[f32; 3]; 3]]) -> String {
    let mut s = format!("OFF\n{} {} 0\n", 3 * t.len(), t.len());
    for tri in t {
        for v in tri {
            s += &format!("{} {} {}\n", v[0], v[1], v[2]);
        }
    }
    for k in 0..t.len() {
        s += &format!("3 {} {} {}\n", 3 * k, 3 * k + 1, 3 * k + 2);
    }
    s
}

fn stl_ascii(t: &[[[f32; 3]; 3]]) -> String {
    let mut s = String::from("solid box\n");
    for tri in t {
        s += "  facet normal 0 0 0\n    outer loop\n";
        for v in tri {
            s += &format!("      vertex {:e} {:e} {:e}\n", v[0], v[1], v[2]);
        }
        s += "    endloop\n  endfacet\n";
    }
    s + "endsolid box\n"
}

fn stl_binary(t: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b[..5].copy_from_slice(b"solid"); // binary files may start with "solid" too
    b.extend_from_slice(&(t.len() as u32).to_le_bytes());
    for tri in t {
        b.extend_from_slice(&[0u8; 12]);
        for v in tri {
            for x in v {
                b.extend_from_slice(&x.to_le_bytes());
            }
        }
        b.extend_from_slice(&[0u8; 2]);
    }
    b
}

fn run(dir: &Path, mesh: &str) -> Vec<Vec<u8>> {
    let out = format!("out_{}", mesh.replace('.', "_"));
    std::fs::write(
        dir.join(format!("{mesh}.toml")),
        format!(
            "[geometry]\nradius_min = 0.003\nradius_max = 0.005\nmesh = \"{mesh}\"\nmesh_radii = [0.0005]\n\
             spawn_min = [-0.025, -0.025, 0.02]\nspawn_max = [0.025, 0.025, 0.1]\n\
             [simulation]\nmax_particles = 120\nspawn_attempts = 4\nframes = 4\nsteps_per_frame = 500\n\
             [output]\ndir = \"{out}\"\n"
        ),
    )
    .unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_tinydem"))
        .args(["run", &format!("{mesh}.toml"), "-q"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{mesh}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    (0..=4)
        .map(|k| std::fs::read(dir.join(format!("{out}/particles{k:06}.csv"))).unwrap())
        .collect()
}

#[test]
fn stl_and_off_versions_of_a_geometry_give_identical_trajectories() {
    let t = tempfile::tempdir().unwrap();
    let tri = triangles();
    std::fs::write(t.path().join("box.off"), off(&tri)).unwrap();
    std::fs::write(t.path().join("box_ascii.stl"), stl_ascii(&tri)).unwrap();
    std::fs::write(t.path().join("box_binary.stl"), stl_binary(&tri)).unwrap();
    let reference = run(t.path(), "box.off");
    assert!(reference[4].len() > 100 * 50, "particles were spawned");
    // The particles reached the floor: some z below 0.01.
    let text = String::from_utf8(reference[4].clone()).unwrap();
    assert!(
        text.lines()
            .skip(1)
            .any(|l| l.split(',').nth(2).unwrap().parse::<f64>().unwrap() < 0.01)
    );
    for mesh in ["box_ascii.stl", "box_binary.stl"] {
        assert!(
            run(t.path(), mesh) == reference,
            "{mesh} differs from box.off"
        );
    }
}
