//! Fuzzing the readers with proptest: arbitrary bytes and mutations of valid files must
//! give a result or an error, never a panic (nor a huge allocation). The number of cases
//! per target comes from `TINYDEM_FUZZ_CASES` (default 256); `.ci/run` runs many more.

use std::path::Path;

use proptest::prelude::*;
use tinydem::geometry::mesh::Mesh;
use tinydem::io::checkpoint;
use tinydem::io::csv::read_particles;
use tinydem::scenario::Scenario;

fn config() -> ProptestConfig {
    let cases = std::env::var("TINYDEM_FUZZ_CASES")
        .ok()
        .and_then(|c| c.parse().ok())
        .unwrap_or(256);
    ProptestConfig {
        cases,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

const OFF: &str = "OFF\n# box\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n\
                   4 0 1 2 3 0\n3 4 5 6 1\n2 0 4\n1 7 1\n4 0 1 5 4\n3 2 3 7\n";
const STL: &str = "solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid t\n";
const CSV: &str = "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n0,0,0.1,0.005,0,0,-1,1,0,0,0,0,0,0\n\
                   1e-3,-2.5e-2,3,0.004,1,2,3,0.5,0.5,0.5,0.5,-1,0,1e2\n";
const TOML: &str = "[geometry]\nradius_min = 0.004\nradius_max = 0.006\nmesh_radii = [0.0, 0.001]\n\
                    spawn_min = [-0.02, -0.02, 0.02]\nspawn_max = [0.02, 0.02, 0.05]\n\
                    [material]\ndensity = 2500.0\npoisson_ratio = 0.25\nrestitution = 0.7\n\
                    [simulation]\nframes = 2\nseed = 42\n[output]\ncheckpoint_every = 1\n";

/// Mutations of a valid text: replaced, inserted or deleted bytes, and a truncation.
fn mutate(base: &'static str) -> impl Strategy<Value = Vec<u8>> {
    let n = base.len();
    (
        prop::collection::vec((0..n, any::<u8>(), 0u8..3), 0..8),
        0..=n,
    )
        .prop_map(move |(edits, cut)| {
            let mut b = base.as_bytes().to_vec();
            for (at, byte, kind) in edits {
                let at = at.min(b.len().saturating_sub(1));
                match kind {
                    0 if !b.is_empty() => b[at] = byte,
                    1 => b.insert(at, byte),
                    _ if !b.is_empty() => {
                        b.remove(at);
                    }
                    _ => {}
                }
            }
            b.truncate(cut.max(b.len() / 2));
            b
        })
}

/// Mutations that swap in tokens which are numbers, huge numbers or special values.
fn tokens(base: &'static str) -> impl Strategy<Value = String> {
    let specials = prop::sample::select(vec![
        "0",
        "-1",
        "1e308",
        "-1e308",
        "nan",
        "inf",
        "18446744073709551616",
        "99999999999",
        "",
        "4 0 1 2 3",
        "#",
        "\n",
        ",",
        "x",
        "1.5",
        "-0",
        "5",
        "2147483648",
    ]);
    prop::collection::vec((any::<prop::sample::Index>(), specials), 1..5).prop_map(move |subs| {
        let mut words: Vec<String> = base.split(' ').map(str::to_string).collect();
        for (idx, s) in subs {
            let k = idx.index(words.len());
            words[k] = s.to_string();
        }
        words.join(" ")
    })
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn off_reader_never_panics(bytes in prop::collection::vec(any::<u8>(), 0..200)) {
        let _ = Mesh::parse_off(&text(&bytes), "fuzz.off", &[0.0, 0.1]);
    }

    #[test]
    fn off_reader_survives_mutations(bytes in mutate(OFF), t in tokens(OFF)) {
        let _ = Mesh::parse_off(&text(&bytes), "fuzz.off", &[0.0, 0.1]);
        let _ = Mesh::parse_off(&t, "fuzz.off", &[0.0, 0.1]);
    }

    #[test]
    fn stl_reader_never_panics(bytes in prop::collection::vec(any::<u8>(), 0..400), ascii in mutate(STL)) {
        let _ = Mesh::parse_stl(&bytes, "fuzz.stl", 0.0);
        let _ = Mesh::parse_stl(&ascii, "fuzz.stl", 0.0);
        // Binary: a valid file with flipped bytes.
        let mut b = vec![0u8; 80];
        b.extend_from_slice(&2u32.to_le_bytes());
        for k in 0..100u8 {
            b.push(k.wrapping_mul(37));
        }
        for (i, x) in bytes.iter().take(8).enumerate() {
            let at = (*x as usize * 7 + i) % b.len();
            b[at] ^= x;
        }
        let _ = Mesh::parse_stl(&b, "fuzz.stl", 0.0);
    }

    #[test]
    fn csv_reader_never_panics(bytes in prop::collection::vec(any::<u8>(), 0..200)) {
        let _ = read_particles(&bytes[..], "fuzz.csv");
    }

    #[test]
    fn csv_reader_survives_mutations(bytes in mutate(CSV), t in tokens(CSV)) {
        let _ = read_particles(&bytes[..], "fuzz.csv");
        let _ = read_particles(t.as_bytes(), "fuzz.csv");
    }

    #[test]
    fn scenario_parser_survives_mutations(bytes in mutate(TOML), t in tokens(TOML)) {
        let _ = Scenario::parse(&text(&bytes), Path::new("fuzz.toml"));
        let _ = Scenario::parse(&t, Path::new("fuzz.toml"));
    }

    #[test]
    fn checkpoint_reader_never_panics(bytes in prop::collection::vec(any::<u8>(), 0..300), flips in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..4)) {
        let _ = checkpoint::decode(&bytes, Some(1));
        let mut valid = checkpoint::encode(&sample_snapshot(), 1);
        for (idx, b) in flips {
            let k = idx.index(valid.len());
            valid[k] ^= b;
        }
        let _ = checkpoint::decode(&valid, Some(1));
    }
}

fn sample_snapshot() -> tinydem::engine::Snapshot {
    let sim = tinydem::engine::Simulation::from_parts(
        Scenario::parse("[simulation]\nframes = 1\n", Path::new("s.toml")).unwrap(),
        Mesh::default(),
        read_particles(CSV.as_bytes(), "fuzz.csv").unwrap(),
    )
    .unwrap();
    sim.snapshot().unwrap()
}
