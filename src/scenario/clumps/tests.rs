use std::f64::consts::PI;
use std::path::Path;

use super::MOST_SPHERES_COMPUTED;
use crate::scenario::{MassSource, Scenario};

const HEAD: &str = "[geometry]\nradius_min = 0.002\nradius_max = 0.005\n\
                    [material]\ndensity = 2000.0\n";

fn parse(text: &str) -> anyhow::Result<Scenario> {
    Scenario::parse(&format!("{HEAD}{text}"), Path::new("s.toml"))
}

fn error(text: &str) -> String {
    format!("{:#}", parse(text).unwrap_err())
}

#[test]
fn a_dimer_gets_the_mass_of_its_union_and_a_principal_frame() {
    let (r, d) = (0.004, 0.004);
    let s = parse(&format!(
        "[[clumps]]\nname = \"dimer\"\nspheres = [[0.0, 0.0, 0.0, {r}], [0.0, {d}, 0.0, {r}]]\n"
    ))
    .unwrap();
    let c = &s.clumps[0];
    let lens = PI * (4.0 * r + d) * (2.0 * r - d).powi(2) / 12.0;
    let mass = 2000.0 * (2.0 * 4.0 / 3.0 * PI * r.powi(3) - lens);
    assert!((c.mass / mass - 1.0).abs() < 1e-3, "{} vs {mass}", c.mass);
    // In the body frame the dimer lies along the first (smallest) principal axis, centred.
    assert!(c.inertia.x < c.inertia.y && (c.inertia.y / c.inertia.z - 1.0).abs() < 1e-3);
    for (s, sign) in c.spheres.iter().zip([-1.0, 1.0]) {
        assert!((s.centre.x.abs() - d / 2.0).abs() < 1e-7, "{}", s.centre);
        assert!(s.centre.y.abs() < 1e-7 && s.centre.z.abs() < 1e-7, "{sign}");
    }
    assert!((c.bounding_radius - (d / 2.0 + r)).abs() < 1e-7);
    assert!(matches!(c.source, MassSource::Computed { error } if error < 1e-3));
    // run.toml gives the same scenario back.
    let again = Scenario::parse(&s.to_toml(), Path::new("s.toml")).unwrap();
    assert_eq!(again.clumps, s.clumps);
}

#[test]
fn given_mass_and_inertia_are_kept() {
    let s = parse(
        "[[clumps]]\nname = \"pill\"\nspheres = [[-0.002, 0.0, 0.0, 0.003], [0.002, 0.0, 0.0, 0.003]]\n\
         mass = 1e-3\ninertia = [1e-9, 2e-9, 2e-9]\n",
    )
    .unwrap();
    let c = &s.clumps[0];
    assert_eq!(
        (c.mass, c.inertia.y, c.source),
        (1e-3, 2e-9, MassSource::Given)
    );
    assert_eq!(c.spheres, c.given);
    let again = Scenario::parse(&s.to_toml(), Path::new("s.toml")).unwrap();
    assert_eq!(again.clumps, s.clumps);
}

#[test]
fn templates_from_a_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("t.csv"),
        "x,y,z,r\n0,0,0,0.003\n0,0,0.005,0.003\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("bad.csv"), "x,y,z,r\n0,0,0\n").unwrap();
    let scenario = |file: &str| format!("{HEAD}[[clumps]]\nname = \"t\"\nfile = \"{file}\"\n");
    let s = Scenario::parse(&scenario("t.csv"), &dir.path().join("s.toml")).unwrap();
    assert_eq!(s.clumps[0].spheres.len(), 2);
    let e = Scenario::parse(&scenario("bad.csv"), &dir.path().join("s.toml")).unwrap_err();
    assert!(
        format!("{e:#}").contains("bad.csv:2: expected four numbers x,y,z,r"),
        "{e:#}"
    );
}

#[test]
fn bad_templates_are_refused_with_the_reason() {
    let e = error(
        "[[clumps]]\nname = \"apart\"\nspheres = [[0.0, 0.0, 0.0, 0.003], [0.0, 0.005, 0.0, 0.003], [0.02, 0.0, 0.0, 0.003]]\n",
    );
    assert!(
        e.contains("\"apart\": sphere 3 (at [0.02, 0, 0], radius 0.003) is not joined to sphere 1"),
        "{e}"
    );
    let e = error("[[clumps]]\nname = \"big\"\nspheres = [[0.0, 0.0, 0.0, 0.01]]\n");
    assert!(
        e.contains("sphere 1 has radius 0.01, outside [geometry] radius_min..radius_max"),
        "{e}"
    );
    let e = error("[[clumps]]\nname = \"none\"\nspheres = []\n");
    assert!(e.contains("at least one sphere"), "{e}");
    let e = error(
        "[[clumps]]\nname = \"both\"\nspheres = [[0.0, 0.0, 0.0, 0.003]]\nfile = \"t.csv\"\n",
    );
    assert!(e.contains("give either spheres"), "{e}");
    let e = error("[[clumps]]\nname = \"half\"\nspheres = [[0.0, 0.0, 0.0, 0.003]]\nmass = 1.0\n");
    assert!(e.contains("give both mass and inertia"), "{e}");
    let e = error(
        "[[clumps]]\nname = \"odd\"\nspheres = [[0.0, 0.0, 0.0, 0.003]]\nmass = 1.0\ninertia = [1.0, 1.0, 3.0]\n",
    );
    assert!(e.contains("at most the sum of the other two"), "{e}");
    let twice = "[[clumps]]\nname = \"a\"\nspheres = [[0.0, 0.0, 0.0, 0.003]]\n";
    assert!(error(&format!("{twice}{twice}")).contains("the name is taken"));
    let e = error(
        "[[clumps]]\nname = \"m\"\nspheres = [[0.0, 0.0, 0.0, 0.003]]\nmaterial = \"steel\"\n",
    );
    assert!(e.contains("material = \"steel\" is not a material"), "{e}");
}

#[test]
fn a_template_of_more_spheres_than_its_mass_properties_can_take_is_refused_at_once() {
    let chain = |n: usize| -> String {
        let spheres: Vec<String> = (0..n)
            .map(|k| format!("[{}, 0.0, 0.0, 0.002]", k as f64 * 0.003))
            .collect();
        format!(
            "[geometry]\nradius_min = 0.002\nradius_max = 0.003\n\
             [[clumps]]\nname = \"chain\"\nspheres = [{}]\n",
            spheres.join(", ")
        )
    };
    let start = std::time::Instant::now();
    let err = format!(
        "{:#}",
        Scenario::parse(&chain(MOST_SPHERES_COMPUTED + 1), Path::new("s.toml"))
            .err()
            .unwrap()
    );
    assert!(
        err.contains("1001 spheres: the mass properties of more than 1000"),
        "{err}"
    );
    // Refused before any quadrature.
    assert!(start.elapsed().as_secs_f64() < 5.0);
}
