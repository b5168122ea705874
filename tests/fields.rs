//! Coarse-grained fields (`tinydem analyze --fields`) against theory: the stress of a settled
//! column carries its weight, the kinetic stress of a gas is its momentum flux; and the
//! files the command writes.
//! (Kernels, and integrals of single particles and contacts: `src/tools/fields/tests.rs`.)

use crate::common;

use glam::{DQuat, DVec3};
use tinydem::engine::Simulation;
use tinydem::model::integrate::Inertia;
use tinydem::model::particles::{Particle, Particles};
use tinydem::tools::fields::{Grid, Kernel, Sums};

const RHO: f64 = 2500.0;
const G: f64 = 9.81;

/// 1,200 grains poured into a cell periodic in x and y (4 x 4 cm) onto a floor, at rest.
fn settled_column() -> Simulation {
    let text = format!(
        "[geometry]\nradius_min = 0.002\nradius_max = 0.0025\n\
         spawn_min = [-0.02, -0.02, 0.003]\nspawn_max = [0.02, 0.02, 0.1]\n\
         [material]\ndensity = {RHO}\nyoungs_modulus = 1e7\nrestitution = 0.3\nfriction_sliding = 0.5\n\
         [simulation]\nmax_particles = 1200\n\
         [domain]\nmin = [-0.02, -0.02, -0.01]\nmax = [0.02, 0.02, 0.2]\nperiodic = [true, true, false]\n\
         [[meshes]]\nshape = {{ type = \"plane\", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 0.4 }}\n"
    );
    let mut sim = Simulation::new(common::scenario(&text)).unwrap();
    for _ in 0..40_000 {
        sim.step().unwrap();
    }
    sim
}

#[test]
fn the_stress_of_a_settled_column_carries_its_weight() {
    let sim = settled_column();
    assert!(sim.thermo().kinetic_energy < 1e-7, "{:?}", sim.thermo());
    let p = sim.particles_in_domain();
    let top = (0..p.len()).map(|k| p.x[k].z).fold(0.0, f64::max);
    // Slices 1 mm thick along z across the cell (which they wrap in x and y).
    let grid = Grid::over(
        DVec3::new(-0.02, -0.02, 0.0),
        DVec3::new(0.02, 0.02, top + 0.005),
        0.001,
        Some(2),
        [true, true, false],
    );
    let mut sums = Sums::new(grid.clone(), Kernel::Gaussian { width: 0.002 });
    let mass = |k: usize| Inertia::mass(p.radius[k], RHO);
    sums.add(&p, mass, Some(&sim.contact_network()));
    let f = sums.fields();
    // The weight of what lies above each slice, from the density field itself.
    let h = grid.spacing.z;
    let mut sum = 0.0;
    let mut above: Vec<f64> = (f.density.iter().rev())
        .map(|rho| {
            sum += rho * G * h;
            sum
        })
        .collect();
    above.reverse();
    // Away from the floor and the free surface (5 diameters each), sigma_zz = rho g h to 5 %.
    let (mut checked, mut worst) = (0, 0.0f64);
    for (k, (rho, above)) in f.density.iter().zip(&above).enumerate() {
        let z = grid.point(k).z;
        if z < 0.0225 || z > top - 0.0225 {
            continue;
        }
        let weight = above - 0.5 * rho * G * h;
        let szz = f.stress(k).col(2).z;
        worst = worst.max((szz / weight - 1.0).abs());
        assert!(
            (szz - weight).abs() < 0.05 * weight,
            "z = {z}: sigma_zz {szz} Pa, the weight above {weight} Pa"
        );
        // The grains push sideways too (compression positive), less than downwards.
        let sxx = f.stress(k).col(0).x;
        assert!(
            sxx > 0.1 * szz && sxx < szz,
            "z = {z}: sigma_xx {sxx}, sigma_zz {szz}"
        );
        checked += 1;
    }
    assert!(checked > 10, "{checked} slices checked, top at {top}");
    eprintln!("{checked} slices, sigma_zz / weight above: worst {worst:.4}");
    // At rest: no kinetic stress to speak of.
    let most = f
        .kinetic
        .iter()
        .map(|m| m.col(2).z.abs())
        .fold(0.0, f64::max);
    assert!(most < 1e-6 * above[0], "{most}");
}

#[test]
fn the_kinetic_stress_of_a_gas_is_its_momentum_flux() {
    // 4,000 grains scattered in a periodic box with random velocities (seeded), a drift
    // along x and more spread along z than across: the fields of that one state.
    let mut seed = 12345u64;
    let mut uniform = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let (l, n, r) = (0.2, 4000, 0.001);
    let p: Particles = (0..n)
        .map(|_| {
            let x = DVec3::new(uniform(), uniform(), uniform()) * l;
            let v = DVec3::new(
                0.3 + uniform() - 0.5,
                uniform() - 0.5,
                2.0 * (uniform() - 0.5),
            );
            Particle {
                x,
                radius: r,
                v,
                q: DQuat::IDENTITY,
                w: DVec3::ZERO,
                tag: 0,
                material: 0,
                fixed: false,
                body: None,
                ..Particle::default()
            }
        })
        .collect();
    let m = Inertia::mass(r, RHO);
    // The momentum flux of the gas about its mean velocity, per volume.
    let mean = (0..n).map(|k| p.v[k]).sum::<DVec3>() / n as f64;
    let mut flux = glam::DMat3::ZERO;
    for k in 0..n {
        let u = p.v[k] - mean;
        flux += glam::DMat3::from_cols(u * u.x, u * u.y, u * u.z) * (m / l.powi(3));
    }
    let grid = Grid::over(DVec3::ZERO, DVec3::splat(l), 0.02, None, [true; 3]);
    let mut sums = Sums::new(grid.clone(), Kernel::Gaussian { width: 0.03 });
    sums.add(&p, |_| m, Some(&[]));
    let f = sums.fields();
    let average =
        f.kinetic.iter().fold(glam::DMat3::ZERO, |s, k| s + *k) * (1.0 / grid.len() as f64);
    for c in 0..3 {
        for rr in 0..3 {
            let (got, want) = (average.col(c)[rr], flux.col(c)[rr]);
            let scale = flux.col(2).z;
            assert!(
                (got - want).abs() < 0.03 * scale,
                "({rr}, {c}): {got} against n m <v v> = {want}"
            );
        }
    }
    // The density and the drift, on average.
    let density = f.density.iter().sum::<f64>() / grid.len() as f64;
    // (The cells sample each grain's kernel: 1e-5 of its mass is lost to that.)
    let expected = n as f64 * m / l.powi(3);
    assert!(
        (density - expected).abs() < 1e-4 * expected,
        "{density} vs {expected}"
    );
    let drift = f.velocity.iter().map(|v| v.x).sum::<f64>() / grid.len() as f64;
    assert!((drift - mean.x).abs() < 0.01, "{drift} against {}", mean.x);
}

/// The arrays of a `.vti` file written with raw appended data: name and values.
fn vti_arrays(bytes: &[u8]) -> Vec<(String, Vec<f64>)> {
    let text = String::from_utf8_lossy(bytes);
    let start = text.find("<AppendedData encoding=\"raw\">").unwrap();
    let data = bytes[start..].iter().position(|&b| b == b'_').unwrap() + start + 1;
    text.match_indices("<DataArray ")
        .map(|(at, _)| {
            let tag = &text[at..at + text[at..].find("/>").unwrap()];
            let attr = |name: &str| {
                let from = tag.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
                tag[from..from + tag[from..].find('"').unwrap()].to_string()
            };
            let offset: usize = attr("offset").parse().unwrap();
            let at = data + offset;
            let len = u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
            let values = bytes[at + 8..at + 8 + len]
                .chunks(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                .collect();
            (attr("Name"), values)
        })
        .collect()
}

/// Grains resting in a box, with their contact networks; the command `tinydem` in the
/// directory `t`, its standard output.
fn bed(t: &std::path::Path) -> impl Fn(&[&str]) -> String + '_ {
    std::fs::write(
        t.join("s.toml"),
        "[geometry]\nradius_min = 0.004\nradius_max = 0.005\n\
         spawn_min = [-0.02, -0.02, 0.01]\nspawn_max = [0.02, 0.02, 0.06]\n\
         [simulation]\nmax_particles = 60\nframes = 3\nsteps_per_frame = 400\n\
         [output]\ncontacts = true\n\
         [[meshes]]\nshape = { type = \"box\", min = [-0.03, -0.03, 0.0], max = [0.03, 0.03, 0.1], open = [\"+z\"] }\n",
    )
    .unwrap();
    let run = move |args: &[&str]| {
        let o = common::tinydem(args, t);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    run(&["run", "s.toml", "-o", "out", "-q"]);
    run
}

const BOX: &str = "-0.03,-0.03,0,0.03,0.03,0.1";

#[test]
fn analyze_fields_writes_image_data_and_csv_of_the_same_numbers() {
    let t = tempfile::tempdir().unwrap();
    let run = bed(t.path());
    let said = run(&[
        "analyze",
        "out",
        "--fields",
        "--spacing",
        "0.01",
        "--bounds",
        BOX,
    ]);
    assert!(
        said.contains("fields000003.vti") && said.contains("6 x 6 x 10 points, 1 frame(s)"),
        "{said}"
    );
    let csv = std::fs::read_to_string(t.path().join("out/fields000003.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 35);
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 360);
    let arrays = vti_arrays(&std::fs::read(t.path().join("out/fields000003.vti")).unwrap());
    let names: Vec<&str> = arrays.iter().map(|a| a.0.as_str()).collect();
    assert_eq!(
        names,
        [
            "density",
            "volume_fraction",
            "velocity",
            "stress",
            "contact_stress",
            "kinetic_stress"
        ]
    );
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(arrays[0].1[k], row[column("density")]);
        assert_eq!(arrays[3].1[9 * k + 5], row[column("stress_yz")]);
    }
    // The grains rest on the floor: the floor's cells hold them, under compression.
    assert!(
        rows.iter()
            .any(|r| r[column("density")] > 100.0 && r[column("stress_zz")] > 0.0)
    );
}

#[test]
fn analyze_fields_averages_slices_and_needs_the_contact_networks() {
    let t = tempfile::tempdir().unwrap();
    let run = bed(t.path());
    // Averaged over the frames, in slices along z (a mean diameter apart: about 9 mm), with
    // Lucy's kernel.
    let said = run(&[
        "analyze",
        "out",
        "--fields",
        "--slices",
        "z",
        "--frames",
        "1,3",
        "--average",
        "--kernel",
        "lucy",
        "--bounds",
        BOX,
    ]);
    assert!(
        said.contains("slices_z_mean.vti") && said.contains("1 x 1 x 11 points, 3 frame(s)"),
        "{said}"
    );
    // Without contact networks, the contact stress cannot be had: a clear error.
    std::fs::remove_file(t.path().join("out/contacts000003.csv")).unwrap();
    let o = common::tinydem(&["analyze", "out", "--fields"], t.path());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("[output] contacts = true"),
        "{err}"
    );
}

/// The `name` column of a CSV file's rows.
fn csv_column(path: &std::path::Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let at = (lines.next().unwrap().split(','))
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("{name} in {}", path.display()));
    lines
        .map(|l| l.split(',').nth(at).unwrap().parse().unwrap())
        .collect()
}

/// A bed in a ring of radius 35 mm, run into `t/out`; the top of the box to measure (5 x 5
/// cm across, inside the ring, from below the floor to above the bed) and the mass of the
/// grains whose centres lie in it.
fn ring_bed(t: &std::path::Path) -> (f64, f64) {
    std::fs::write(
        t.join("s.toml"),
        "[geometry]\nradius_min = 0.003\nradius_max = 0.004\n\
         spawn_min = [-0.03, -0.03, 0.01]\nspawn_max = [0.03, 0.03, 0.08]\n\
         [material]\ndensity = 2500.0\nyoungs_modulus = 1e7\n\
         [simulation]\nmax_particles = 400\nframes = 1\nsteps_per_frame = 6000\n\
         [output]\ncontacts = true\n\
         [[meshes]]\nshape = { type = \"cylinder\", center = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 1.0], radius = 0.035, height = 0.1, open = [\"top\"] }\n",
    )
    .unwrap();
    let o = common::tinydem(&["run", "s.toml", "-o", "out", "-q"], t);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let frame = t.join("out/particles000001.csv");
    let (x, y, z, r) = (
        csv_column(&frame, "x"),
        csv_column(&frame, "y"),
        csv_column(&frame, "z"),
        csv_column(&frame, "R"),
    );
    let inside = |k: usize| x[k].abs() < 0.025 && y[k].abs() < 0.025;
    let counted: f64 = (0..x.len())
        .filter(|&k| inside(k))
        .map(|k| Inertia::mass(r[k], 2500.0))
        .sum();
    let outside = (0..x.len()).filter(|&k| !inside(k)).count();
    assert!(
        outside > 50,
        "the ring holds grains outside the box: {outside}"
    );
    (z.iter().fold(0.0f64, |m, &z| m.max(z)) + 0.02, counted)
}

/// `tinydem analyze out --fields` in slices along z over the box up to `top`, with `extra`
/// arguments; the slices' density and volume fraction, and their thickness.
fn slices(t: &std::path::Path, top: f64, extra: &[&str]) -> (Vec<f64>, Vec<f64>, f64) {
    let bounds = format!("-0.025,-0.025,-0.02,0.025,0.025,{top}");
    let mut args = vec![
        "analyze", "out", "--fields", "--slices", "z", "--bounds", &bounds,
    ];
    args.extend(extra);
    let o = common::tinydem(&args, t);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let file = t.join("out/slices_z000001.csv");
    let (density, fraction) = (
        csv_column(&file, "density"),
        csv_column(&file, "volume_fraction"),
    );
    let dz = (top + 0.02) / density.len() as f64;
    (density, fraction, dz)
}

#[test]
fn slices_hold_the_mass_of_the_grains_within_their_box_and_no_more() {
    // Before, a slice summed its whole plane and divided by the box's area: a bed in a ring
    // gave 0.88 packing fraction.
    let t = tempfile::tempdir().unwrap();
    let (top, counted) = ring_bed(t.path());
    let (density, _, dz) = slices(t.path(), top, &["--spacing", "0.002"]);
    // A grid of the same frame goes to a file of its own (it replaced the slices' before).
    let o = common::tinydem(
        &["analyze", "out", "--fields", "--spacing", "0.01"],
        t.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let grid = csv_column(&t.path().join("out/fields000001.csv"), "density");
    assert!(grid.len() > density.len());
    assert_eq!(
        csv_column(&t.path().join("out/slices_z000001.csv"), "density"),
        density
    );
    let field_mass: f64 = density.iter().map(|rho| rho * dz * 0.05 * 0.05).sum();
    assert!(
        (field_mass / counted - 1.0).abs() < 1e-3,
        "the slices hold {field_mass} kg, the grains in the box {counted} kg"
    );
    // Bins (LIGGGHTS's ave/euler) hold it to the last digits, and their solid fraction is
    // the grains' volume (the same count) over theirs.
    let (density, fraction, dz) =
        slices(t.path(), top, &["--kernel", "cell", "--spacing", "0.004"]);
    let binned: f64 = density.iter().map(|rho| rho * dz * 0.05 * 0.05).sum();
    assert!(
        (binned / counted - 1.0).abs() < 1e-9,
        "{binned} against {counted}"
    );
    let solid: f64 = fraction.iter().map(|f| f * dz * 0.05 * 0.05).sum();
    assert!((solid * 2500.0 / counted - 1.0).abs() < 1e-9, "{solid}");
    // In the bulk of the bed (its bins but the two at the floor and the two at the surface,
    // where a bin of centres layered by the floor holds whole grains), a random packing's.
    let filled: Vec<f64> = fraction.iter().copied().filter(|&f| f > 0.0).collect();
    let inner = &filled[2..filled.len() - 2];
    let bulk = inner.iter().sum::<f64>() / inner.len() as f64;
    assert!((0.5..0.7).contains(&bulk), "{fraction:?}");
}

#[test]
fn fields_refuse_kernels_wider_than_the_box_and_frames_the_run_lacks() {
    let t = tempfile::tempdir().unwrap();
    let _ = bed(t.path());
    for (args, expected) in [
        (
            vec!["--width", "inf"],
            "--width inf: it must be a finite length > 0",
        ),
        (vec!["--width", "1e9"], "beyond the box's largest side"),
        (
            vec!["--frames", "1,99"],
            "asks for frames it does not hold: 4, 5, 6, 7, 8 and 91 more",
        ),
    ] {
        let mut all = vec!["analyze", "out", "--fields", "--bounds", BOX];
        all.extend(args);
        let o = common::tinydem(&all, t.path());
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(expected), "{err}");
    }
    // A frame cut short at the end of a line reads as a valid smaller frame: the run's log
    // tells it apart.
    let frame = t.path().join("out/particles000003.csv");
    let text = std::fs::read_to_string(&frame).unwrap();
    let cut: Vec<&str> = text.lines().take(20).collect();
    std::fs::write(&frame, cut.join("\n") + "\n").unwrap();
    let o = common::tinydem(&["analyze", "out"], t.path());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success()
            && err.contains(
                "particles000003.csv: 19 particles, but the run's log.csv says frame 3 had 60"
            ),
        "{err}"
    );
    std::fs::write(&frame, text).unwrap();
    // An average over a frame deleted since.
    std::fs::remove_file(t.path().join("out/particles000002.csv")).unwrap();
    let o = common::tinydem(
        &["analyze", "out", "--fields", "--frames", "1,3", "--average"],
        t.path(),
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success()
            && err.contains("frames it does not hold: 2 (it has frames 0 to 3, with gaps)"),
        "{err}"
    );
}

#[test]
fn wall_stresses_carry_a_resting_bed_on_its_floor() {
    // Grains at rest in a box: the faces' forces add up to the bed's weight, pressing down
    // on the floor (its pressure over its area the same), and the side walls carry little.
    let t = tempfile::tempdir().unwrap();
    std::fs::write(
        t.path().join("s.toml"),
        "[geometry]\nradius_min = 0.004\nradius_max = 0.005\n\
         spawn_min = [-0.02, -0.02, 0.01]\nspawn_max = [0.02, 0.02, 0.06]\n\
         [material]\nrestitution = 0.3\nfriction_sliding = 0.5\n\
         [simulation]\nmax_particles = 60\nframes = 2\nsteps_per_frame = 6000\n\
         [output]\ncontacts = true\n\
         [[meshes]]\nshape = { type = \"box\", min = [-0.03, -0.03, 0.0], max = [0.03, 0.03, 0.1], open = [\"+z\"] }\n",
    )
    .unwrap();
    let o = common::tinydem(&["run", "s.toml", "-o", "out", "-q"], t.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = common::tinydem(&["analyze", "out", "--wall-stress"], t.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(said.contains("wall_stress000002.vtu"), "{said}");
    let frame = t.path().join("out/particles000002.csv");
    let weight: f64 = (csv_column(&frame, "R").iter())
        .map(|&r| Inertia::mass(r, 1000.0) * G)
        .sum();
    let table = t.path().join("out/wall_stress000002.csv");
    let (fz, pressure, area, mesh) = (
        csv_column(&table, "fz"),
        csv_column(&table, "pressure"),
        csv_column(&table, "area"),
        csv_column(&table, "mesh"),
    );
    assert!(mesh.iter().all(|&m| m == 1.0), "the box is [[meshes]] #1");
    let down: f64 = -fz.iter().sum::<f64>();
    assert!(
        (down / weight - 1.0).abs() < 0.01,
        "{down} N on the walls, {weight} N of grains"
    );
    // The box's faces: -x, +x, -y, +y, -z (the floor); +z open.
    let floor = 4;
    assert!(
        (pressure[floor] * area[floor] / weight - 1.0).abs() < 0.02,
        "{pressure:?}"
    );
    assert!(
        pressure[..4].iter().all(|&p| p * 0.06 * 0.1 < 0.2 * weight),
        "{pressure:?}"
    );
    let vtu = std::fs::read(t.path().join("out/wall_stress000002.vtu")).unwrap();
    assert!(String::from_utf8_lossy(&vtu).contains("Name=\"pressure\""));
}

#[test]
fn frames_carry_each_grains_contact_force_and_torque() {
    // `[output] forces = true`: a bed at rest in a box; each grain's contact force and torque
    // in the frame (its fx, ..., tz) is that of its contacts in the network, the forces add
    // up to the bed's weight (the contacts between grains cancel), the frame reads back, and
    // the VTK file holds them too.
    let t = tempfile::tempdir().unwrap();
    std::fs::write(
        t.path().join("s.toml"),
        "[geometry]\nradius_min = 0.004\nradius_max = 0.005\n\
         spawn_min = [-0.02, -0.02, 0.01]\nspawn_max = [0.02, 0.02, 0.06]\n\
         [material]\nrestitution = 0.3\nfriction_sliding = 0.5\nfriction_rolling = 0.2\n\
         [simulation]\nmax_particles = 60\nframes = 2\nsteps_per_frame = 6000\n\
         [output]\ncontacts = true\nforces = true\nformats = [\"csv\", \"vtk\"]\n\
         [[meshes]]\nshape = { type = \"box\", min = [-0.03, -0.03, 0.0], max = [0.03, 0.03, 0.1], open = [\"+z\"] }\n",
    )
    .unwrap();
    let o = common::tinydem(&["run", "s.toml", "-o", "out", "-q"], t.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let frame = t.path().join("out/particles000002.csv");
    let (fz, r) = (csv_column(&frame, "fz"), csv_column(&frame, "R"));
    let weight: f64 = r.iter().map(|&r| Inertia::mass(r, 1000.0) * G).sum();
    let up: f64 = fz.iter().sum();
    assert!(
        (up / weight - 1.0).abs() < 0.01,
        "{up} N up, {weight} N of grains"
    );
    // Each grain's: from its contacts in the network (the force on id_i, minus it on id_j).
    let network = t.path().join("out/contacts000002.csv");
    let (i, j) = (csv_column(&network, "id_i"), csv_column(&network, "id_j"));
    let (fn_z, ft_z) = (csv_column(&network, "fn_z"), csv_column(&network, "ft_z"));
    let mut by_id = vec![0.0; fz.len()];
    for c in 0..i.len() {
        by_id[i[c] as usize] += fn_z[c] + ft_z[c];
        if j[c] >= 0.0 {
            by_id[j[c] as usize] -= fn_z[c] + ft_z[c];
        }
    }
    for (k, (a, b)) in fz.iter().zip(&by_id).enumerate() {
        assert!(
            (a - b).abs() <= 1e-12 * weight,
            "grain {k}: {a} against {b}"
        );
    }
    // At rest, each grain's contact force holds its weight, and its torques balance.
    let tx = csv_column(&frame, "tx");
    for k in 0..fz.len() {
        let w = Inertia::mass(r[k], 1000.0) * G;
        assert!(
            (fz[k] / w - 1.0).abs() < 0.05,
            "grain {k}: {} of its weight",
            fz[k] / w
        );
        assert!(tx[k].abs() < 1e-3 * w * r[k], "grain {k}: torque {}", tx[k]);
    }
    // Read back by the tools, and in the VTK frame.
    let o = common::tinydem(&["analyze", "out"], t.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let vtu = std::fs::read(t.path().join("out/particles000002.vtu")).unwrap();
    let text = String::from_utf8_lossy(&vtu);
    assert!(text.contains("Name=\"force\"") && text.contains("Name=\"torque\""));
}
