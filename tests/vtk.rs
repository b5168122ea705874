//! ParaView output: a real VTK reader (meshio, from PyPI) loads the `.vtu` frames and finds
//! exactly the values of the CSV frame; the `.pvd` lists the frames with their times.
//! Without meshio the test reports that it was skipped, except under CI, where `.ci/run`
//! installs meshio and the test must run.

mod common;

use std::path::Path;
use std::process::Command;

#[test]
fn vtk_frames_match_csv_frames_in_a_real_reader() {
    if !common::has_meshio() {
        return;
    }
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
    let check = Command::new("python3")
        .arg(root.join("tests/vtk_check.py"))
        .args([t.path().join("output").to_str().unwrap(), "3"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&check.stdout).into_owned()
        + &String::from_utf8_lossy(&check.stderr);
    assert!(check.status.success(), "{text}");
    assert!(text.contains("identical to the CSV"), "{text}");
}
