//! The corpus of bad input files in `tests/bad_inputs/{off,stl,csv}`: each `NAME.ext` must make
//! `tinydem run` exit non-zero, without panicking, with a message naming the file and
//! containing the text in `NAME.expected`. (Bad scenario files are in `tests/scenarios/bad`.)

use std::path::{Path, PathBuf};
use std::process::Command;

fn corpus(kind: &str) -> Vec<(PathBuf, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/bad_inputs")
        .join(kind);
    let mut v: Vec<(PathBuf, String)> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == kind))
        .map(|p| {
            let expected = std::fs::read_to_string(p.with_extension("expected"))
                .unwrap_or_else(|_| panic!("{} has no .expected file", p.display()));
            (p, expected.trim_end().to_string())
        })
        .collect();
    v.sort();
    v
}

fn check(kind: &str, scenario: impl Fn(&Path) -> String) {
    let cases = corpus(kind);
    assert!(cases.len() >= 10);
    for (file, expected) in cases {
        let t = tempfile::tempdir().unwrap();
        std::fs::write(t.path().join("s.toml"), scenario(&file)).unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_tinydem"))
            .args(["run", "s.toml", "-q"])
            .current_dir(t.path())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        let name = file.file_name().unwrap().to_string_lossy();
        assert!(!o.status.success(), "{name} was accepted");
        assert!(!err.contains("panicked"), "{name}: {err}");
        assert!(
            err.contains(&*name),
            "{name}: message does not name the file: {err}"
        );
        assert!(
            err.contains(&expected),
            "{name}: message\n  {err}\nlacks\n  {expected}"
        );
        assert_eq!(
            err.trim_end().lines().count(),
            1,
            "{name}: one-line message expected: {err}"
        );
    }
}

#[test]
fn bad_meshes() {
    check("off", |f| {
        format!(
            "[geometry]\nmesh = \"{}\"\nmesh_radii = [0.0]\n",
            f.display()
        )
    });
}

#[test]
fn bad_stl_meshes() {
    check("stl", |f| {
        format!(
            "[geometry]\nmesh = \"{}\"\nmesh_radii = [0.0]\n",
            f.display()
        )
    });
}

#[test]
fn bad_particle_files() {
    check("csv", |f| {
        format!("[input]\nparticles = \"{}\"\n", f.display())
    });
}
