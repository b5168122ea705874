use super::*;
use crate::model::particles::Particle;

fn kernels() -> [Kernel; 2] {
    [
        Kernel::Gaussian { width: 0.01 },
        Kernel::Lucy { width: 0.02 },
    ]
}

#[test]
fn kernels_and_their_marginals_integrate_to_one() {
    for k in kernels() {
        let c = k.cutoff();
        // Shells of the sphere, and the marginal over its line.
        let n = 20_000;
        let dr = c / n as f64;
        let volume: f64 = (0..n)
            .map(|i| {
                let r = (i as f64 + 0.5) * dr;
                4.0 * std::f64::consts::PI * r * r * k.value(r * r) * dr
            })
            .sum();
        let line: f64 = (0..2 * n)
            .map(|i| k.marginal(-c + (i as f64 + 0.5) * dr) * dr)
            .sum();
        assert!((volume - 1.0).abs() < 1e-6, "{k:?}: {volume}");
        assert!((line - 1.0).abs() < 1e-6, "{k:?}: {line}");
        // The marginal is the kernel summed over a plane (at z = c / 3, over a fine square).
        let z = c / 3.0;
        let h = c / 400.0;
        let plane: f64 = (-400..400)
            .flat_map(|i| (-400..400).map(move |j| (i, j)))
            .map(|(i, j)| {
                let (x, y) = ((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
                k.value(x * x + y * y + z * z) * h * h
            })
            .sum();
        assert!(
            (plane - k.marginal(z)).abs() < 1e-4 * k.marginal(0.0),
            "{k:?}"
        );
        assert_eq!(k.value(c * c * 1.0001), 0.0);
    }
}

fn particle(x: DVec3, v: DVec3, radius: f64) -> Particle {
    Particle {
        x,
        radius,
        v,
        ..Default::default()
    }
}

#[test]
fn a_particles_mass_and_momentum_are_the_integrals_of_its_fields() {
    let grid = Grid::over(DVec3::ZERO, DVec3::splat(0.1), 0.002, None, [false; 3]);
    let cell = grid.spacing.x * grid.spacing.y * grid.spacing.z;
    for kernel in kernels() {
        let p: Particles = [particle(
            DVec3::new(0.05, 0.041, 0.063),
            DVec3::new(1.0, -2.0, 0.5),
            0.005,
        )]
        .into_iter()
        .collect();
        let mut sums = Sums::new(grid.clone(), kernel);
        sums.add(&p, |_| 3e-3, None);
        let f = sums.fields();
        let mass: f64 = f.density.iter().sum::<f64>() * cell;
        assert!((mass - 3e-3).abs() < 1e-3 * 3e-3, "{kernel:?}: {mass}");
        // Where it is: the velocity; its own motion is no fluctuation.
        let k = (0..grid.len())
            .max_by(|&a, &b| f.density[a].total_cmp(&f.density[b]))
            .unwrap();
        assert!((f.velocity[k] - DVec3::new(1.0, -2.0, 0.5)).length() < 1e-12);
        assert!(
            f.kinetic[k]
                .abs()
                .to_cols_array()
                .iter()
                .all(|&x| x < 1e-9 * f.density[k])
        );
    }
}

#[test]
fn a_contacts_stress_integrates_to_its_force_times_its_branch() {
    // Two spheres pressed together along a tilted line, and one on a wall.
    let (r, delta) = (0.005, 1e-4);
    let n = DVec3::new(1.0, 2.0, 2.0) / 3.0;
    let (a, b) = (
        DVec3::splat(0.05),
        DVec3::splat(0.05) - n * (2.0 * r - delta),
    );
    let mut p: Particles = [particle(a, DVec3::ZERO, r), particle(b, DVec3::ZERO, r)]
        .into_iter()
        .collect();
    p.id = vec![4, 9];
    let f = n * 2.0 + DVec3::new(0.2, -0.1, 0.0);
    let contacts = [
        ContactRecord {
            id: 4,
            with: Partner::Particle(9),
            point: a - n * (r - delta / 2.0),
            f_n: n * 2.0,
            f_t: DVec3::new(0.2, -0.1, 0.0),
            overlap: delta,
            tau_i: DVec3::ZERO,
            tau_j: DVec3::ZERO,
        },
        ContactRecord {
            id: 9,
            with: Partner::Face(0),
            point: b - DVec3::Z * r,
            f_n: DVec3::Z,
            f_t: DVec3::ZERO,
            overlap: 0.0,
            tau_i: DVec3::ZERO,
            tau_j: DVec3::ZERO,
        },
    ];
    let grid = Grid::over(DVec3::ZERO, DVec3::splat(0.1), 0.0025, None, [false; 3]);
    let cell = grid.spacing.x * grid.spacing.y * grid.spacing.z;
    let expected = DMat3::from_cols(
        f * (n.x * (2.0 * r - delta)),
        f * (n.y * (2.0 * r - delta)),
        f * (n.z * (2.0 * r - delta)),
    ) + DMat3::from_cols(DVec3::ZERO, DVec3::ZERO, DVec3::Z * r);
    for kernel in kernels() {
        let mut sums = Sums::new(grid.clone(), kernel);
        sums.add(&p, |_| 1e-3, Some(&contacts));
        let fields = sums.fields();
        let total = fields.contact.iter().fold(DMat3::ZERO, |s, c| s + *c) * cell;
        let error = (total - expected)
            .abs()
            .to_cols_array()
            .into_iter()
            .fold(0.0, f64::max);
        assert!(error < 1e-3 * 2.0 * r, "{kernel:?}: {total} vs {expected}");
    }
}

#[test]
fn slices_integrate_to_what_the_box_holds() {
    // Particles across a periodic box: the slices along z hold their mass (the box's
    // cross-section times the integral over z), and wrap at the sides.
    let grid = Grid::over(
        DVec3::ZERO,
        DVec3::new(0.02, 0.03, 0.04),
        0.004,
        Some(2),
        [false, false, true],
    );
    assert_eq!(grid.counts, [1, 1, 10]);
    let p: Particles = [0.001, 0.02, 0.039]
        .iter()
        .map(|&z| particle(DVec3::new(0.01, 0.01, z), DVec3::ZERO, 0.002))
        .collect();
    // (Sums over the cells: kernels resolved by 3 to 6 cells across their width.)
    for kernel in [
        Kernel::Gaussian { width: 0.003 },
        Kernel::Lucy { width: 0.012 },
    ] {
        let mut sums = Sums::new(grid.clone(), kernel);
        sums.add(&p, |_| 1e-3, None);
        let f = sums.fields();
        let mass: f64 = f.density.iter().sum::<f64>() * 0.02 * 0.03 * 0.004;
        assert!((mass - 3e-3).abs() < 1e-3 * 3e-3, "{kernel:?}: {mass}");
        // The grains at z = 0.001 and 0.039 are neighbours across the side.
        assert!((f.density[0] - f.density[9]).abs() < 1e-9 * f.density[0]);
    }
}
