//! The scenario reference of the user guide (`docs/book/src/scenario/`) and the README stay
//! true: every TOML snippet on their pages is a valid scenario, every page has one, and the
//! snippets that show a table's defaults show the defaults the parser gives; the verification
//! page shows this build's report.

use std::path::{Path, PathBuf};

use tinydem::scenario::Scenario;

fn pages() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/book/src/scenario");
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    v.sort();
    v
}

/// The ```toml blocks of a page, with the line each starts on.
fn snippets(page: &Path) -> Vec<(usize, String)> {
    let text = std::fs::read_to_string(page).unwrap();
    let mut out = Vec::new();
    let mut open: Option<(usize, String)> = None;
    for (n, line) in text.lines().enumerate() {
        match (&mut open, line.trim_start()) {
            (None, l) if l.starts_with("```toml") => open = Some((n + 1, String::new())),
            (Some(_), l) if l.starts_with("```") => out.push(open.take().unwrap()),
            (Some((_, s)), _) => {
                s.push_str(line);
                s.push('\n');
            }
            _ => {}
        }
    }
    assert!(
        open.is_none(),
        "{}: a ```toml block is not closed",
        page.display()
    );
    out
}

fn parse(page: &Path, line: usize, text: &str) -> Scenario {
    let name = format!("{}:{line}", page.display());
    Scenario::parse(text, &page.with_file_name("scenario.toml"))
        .unwrap_or_else(|e| panic!("{name}: the snippet is no valid scenario: {e:#}"))
}

#[test]
fn every_snippet_of_the_scenario_reference_parses() {
    let pages = pages();
    assert!(pages.len() >= 10, "the reference has a page per table");
    let mut count = 0;
    for page in &pages {
        let found = snippets(page);
        assert!(!found.is_empty(), "{}: no ```toml snippet", page.display());
        for (line, text) in found {
            parse(page, line, &text);
            count += 1;
        }
    }
    assert!(count >= 13, "{count} snippets");
}

#[test]
fn the_readmes_scenario_parses() {
    let readme = Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md");
    let found = snippets(&readme);
    assert_eq!(found.len(), 1, "the README shows one scenario");
    let s = parse(&readme, found[0].0, &found[0].1);
    assert_eq!(s.simulation.max_particles, 2000);
    // As a newcomer saves it: it runs, with no file the repository lacks, and pours.
    let t = tempfile::tempdir().unwrap();
    let path = t.path().join("pour.toml");
    std::fs::write(&path, &found[0].1).unwrap();
    let mut sim = tinydem::engine::Simulation::new(Scenario::load(&path).unwrap()).unwrap();
    for _ in 0..2000 {
        sim.step().unwrap();
    }
    assert!(sim.particles.len() > 100, "{} grains", sim.particles.len());
}

#[test]
fn the_snippets_that_show_defaults_show_the_parsers_defaults() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/book/src/scenario");
    let first = |name: &str| {
        let page = dir.join(name);
        let (line, text) = snippets(&page).remove(0);
        parse(&page, line, &text)
    };
    let default = Scenario::default();
    let g = first("geometry.md").geometry;
    assert_eq!(
        (g.radius_min, g.radius_max, g.mesh_radii.clone()),
        (
            default.geometry.radius_min,
            default.geometry.radius_max,
            default.geometry.mesh_radii.clone()
        )
    );
    assert_eq!(
        (g.spawn_min, g.spawn_max, g.mesh_contacts),
        (
            default.geometry.spawn_min,
            default.geometry.spawn_max,
            default.geometry.mesh_contacts
        )
    );
    // mu_t's default is 2/3 mu_s (Eq. 41), 0.19999999999999998; the page says 0.2.
    let mut m = first("material.md").material;
    assert!((m.friction_twisting - default.material.friction_twisting).abs() < 1e-15);
    m.friction_twisting = default.material.friction_twisting;
    assert_eq!(m, default.material);
    assert_eq!(first("kinetics.md").kinetics, default.kinetics);
    let s = first("simulation.md").simulation;
    // The page rounds Eq. 50's time step to three digits.
    let dt = default.simulation.timestep;
    assert!(
        (s.timestep - dt).abs() < 1e-3 * dt,
        "{} against {dt}",
        s.timestep
    );
    let mut same = s.clone();
    same.timestep = dt;
    assert_eq!(same, default.simulation);
}

/// The guide's verification page shows the report this build writes (`tinydem verify
/// --report`): regenerate the page's tables when a case or its numbers change.
#[test]
fn the_verification_page_is_the_report_of_this_build() {
    let checks = tinydem::tools::verify::run(&[], false).unwrap();
    let report = tinydem::tools::verify::report(&checks);
    let tables = &report[report.find("| case | what |").unwrap()..];
    let page = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/book/src/verification.md");
    let text = std::fs::read_to_string(page).unwrap();
    assert!(
        text.ends_with(tables),
        "the page's tables are not this build's report:\n{tables}"
    );
}
