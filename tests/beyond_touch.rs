//! Contacts that outlast touch: JKR's pull-off force and separation, its sticking speed,
//! and liquid bridges (Willett's force against the gap, rupture, no force after it until
//! the bodies touch again); their bits on 1 and 2 threads; their bad keys.

use crate::common;

use glam::DVec3;
use std::f64::consts::PI;
use tinydem::engine::Simulation;
use tinydem::model::integrate::Inertia;
use tinydem::model::particles::Particle;

const R: f64 = 0.005;
const RHO: f64 = 2500.0;
/// Young's modulus and Poisson's ratio of the tests' material, and E* against a rigid wall.
const E: f64 = 1e7;
const NU: f64 = 0.3;
const E_WALL: f64 = E / (1.0 - NU * NU);
/// A floor and a ceiling (rectangles facing up and down at z = 0).
const FLOOR: &str = "OFF\n4 1 0\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n4 0 1 2 3\n";
const CEILING: &str = "OFF\n4 1 0\n-1 -1 0\n-1 1 0\n1 1 0\n1 -1 0\n4 0 1 2 3\n";

/// A simulation of `particles` with the `[material]` lines `material` (E, ν and no damping
/// before them), gravity `g` along -z, the mesh `off` (none if empty) and time step `dt`.
fn sim(material: &str, g: f64, off: &str, dt: f64, particles: Vec<Particle>) -> Simulation {
    let material = format!(
        "density = {RHO}\nyoungs_modulus = {E:e}\npoisson_ratio = {NU}\nrestitution = 1.0\n{material}"
    );
    common::single_grains(R, &material, (g, off), dt, particles)
}

fn grain(x: DVec3, v: DVec3) -> Particle {
    common::sphere(R, x, v, DVec3::ZERO)
}

/// JKR's pull-off force 3/2 π γ R* and the overlap -(3/4) (π² γ² R* / E*²)^(1/3) at which
/// the contact ends under a prescribed separation.
fn jkr_pull_off(gamma: f64, e_star: f64, r_star: f64) -> (f64, f64) {
    let f_c = 1.5 * PI * gamma * r_star;
    let delta_c = 0.75 * (PI * PI * gamma * gamma * r_star / (e_star * e_star)).cbrt();
    (f_c, -delta_c)
}

/// A grain pulled off its partner (a ceiling, or a fixed grain above it) by a weight of
/// 1.2 F_c from touch: the strongest pull its contact gave, and its last overlap.
fn pulled_off(gamma: f64, wall: bool, model: &str) -> (f64, f64) {
    let r_star = if wall { R } else { 0.5 * R };
    let (f_c, _) = jkr_pull_off(gamma, if wall { E_WALL } else { 0.5 * E_WALL }, r_star);
    let m = Inertia::mass(R, RHO);
    let material = format!("adhesion_model = \"{model}\"\nsurface_energy = {gamma}");
    let below = DVec3::new(0.0, 0.0, -(R - 1e-9));
    let (particles, off) = if wall {
        (vec![grain(below, DVec3::ZERO)], CEILING)
    } else {
        let mut above = grain(DVec3::new(0.0, 0.0, R), DVec3::ZERO);
        above.fixed = true;
        let hanging = grain(below, DVec3::ZERO);
        (vec![above, hanging], "")
    };
    let mut s = sim(&material, 1.2 * f_c / m, off, 2e-8, particles);
    let (mut strongest, mut last) = (0.0f64, f64::NAN);
    for _ in 0..2_000_000 {
        s.step().unwrap();
        let contacts = s.held_contacts();
        let Some(c) = contacts.first() else {
            return (strongest, last);
        };
        // The force on the lower grain along +z pulls it up: attraction.
        let f = if wall { c.f_n.z } else { -c.f_n.z };
        strongest = strongest.max(f);
        last = c.overlap;
    }
    panic!("the grain did not come off");
}

#[test]
fn jkr_pulls_off_at_its_force_and_separation() {
    let gamma = 0.5;
    for (wall, e_star, r_star) in [(true, E_WALL, R), (false, 0.5 * E_WALL, 0.5 * R)] {
        let (f_c, delta_c) = jkr_pull_off(gamma, e_star, r_star);
        let (strongest, last) = pulled_off(gamma, wall, "jkr");
        eprintln!(
            "JKR wall {wall}: pull-off force {:+.2e}, separation {:+.2e}",
            strongest / f_c - 1.0,
            last / delta_c - 1.0
        );
        assert!(
            (strongest / f_c - 1.0).abs() < 1e-2,
            "wall {wall}: the strongest pull {strongest} N, JKR's 3/2 pi gamma R* = {f_c} N"
        );
        assert!(
            (last / delta_c - 1.0).abs() < 1e-2,
            "wall {wall}: the contact ended at overlap {last} m, JKR's at {delta_c} m"
        );
    }
}

/// The speed below which an elastic sphere sticks to a JKR plane: its kinetic energy
/// against the work of separating the contact from δ = 0 to -δ_c (the hysteresis of
/// Thornton & Ning 1998). With a = l x², l = (c R)^(2/3), c² = 2 π γ / E*: δ = (l²/R)
/// (x⁴ - x) and F = 2 π γ R (4x⁶/3 - 2x³), so the work is 2 π γ l² ∫ from x_c = 4^(-1/3)
/// to 1 of -(4x⁶/3 - 2x³)(4x³ - 1) dx.
fn sticking_speed(gamma: f64, e_star: f64, r: f64, m: f64) -> f64 {
    let l2 = ((2.0 * PI * gamma / e_star).sqrt() * r).powf(4.0 / 3.0);
    let antiderivative = |x: f64| 8.0 / 15.0 * x.powi(10) - 4.0 / 3.0 * x.powi(7) + 0.5 * x.powi(4);
    let integral = antiderivative(1.0) - antiderivative(0.25f64.cbrt());
    let work = -2.0 * PI * gamma * l2 * integral;
    (2.0 * work / m).sqrt()
}

#[test]
fn an_elastic_jkr_grain_sticks_below_the_sticking_speed_and_rebounds_above() {
    let gamma = 0.5;
    let m = Inertia::mass(R, RHO);
    let v_s = sticking_speed(gamma, E_WALL, R, m);
    let material = format!("adhesion_model = \"jkr\"\nsurface_energy = {gamma}");
    for (share, sticks) in [(0.95, true), (1.05, false)] {
        let v0 = share * v_s;
        let start = grain(DVec3::new(0.0, 0.0, R + 1e-9), DVec3::new(0.0, 0.0, -v0));
        let mut s = sim(&material, 0.0, FLOOR, 2e-8, vec![start]);
        for _ in 0..400_000 {
            s.step().unwrap();
        }
        let (z, v) = (s.particles.x[0].z, s.particles.v[0].z);
        eprintln!(
            "JKR at {share} v_s ({v_s:.4e} m/s): gap {:.3e} m, v {v:.4e} m/s",
            z - R
        );
        if sticks {
            assert!(
                z - R < 1e-5 && !s.held_contacts().is_empty(),
                "at {share} of {v_s} m/s it should stick: gap {}, v {v}",
                z - R
            );
        } else {
            let escaping = (share * share - 1.0).sqrt() * v_s;
            assert!(
                s.held_contacts().is_empty() && (v / escaping - 1.0).abs() < 0.1,
                "at {share} of {v_s} m/s it should leave at {escaping} m/s: v {v}"
            );
        }
    }
}

/// Willett et al. 2000's force of a bridge of volume `v` between spheres of effective
/// radius `r_star` at the gap `s` (Derjaguin's R = 2 R*).
fn willett(gamma_l: f64, theta_deg: f64, v: f64, r_star: f64, s: f64) -> f64 {
    let r = 2.0 * r_star;
    let s_plus = 0.5 * s * (r / v).sqrt();
    2.0 * PI * r * gamma_l * theta_deg.to_radians().cos()
        / (1.0 + 2.1 * s_plus + 10.0 * s_plus * s_plus)
}

const WET: &str = "liquid_volume = 2e-10\nsurface_tension = 0.07\ncontact_angle = 20.0";

#[test]
fn a_liquid_bridge_pulls_by_willetts_force_until_its_rupture_distance() {
    let (gamma_l, theta, v) = (0.07, 20.0, 2e-10);
    let rupture = (1.0 + 0.5 * f64::to_radians(theta)) * f64::cbrt(v);
    // Two grains touch, then the free one flies off fast enough to break the bridge.
    let mut fixed = grain(DVec3::ZERO, DVec3::ZERO);
    fixed.fixed = true;
    let free = grain(
        DVec3::new(2.0 * R - 1e-7, 0.0, 0.0),
        DVec3::new(0.05, 0.0, 0.0),
    );
    let mut s = sim(WET, 0.0, "", 1e-6, vec![fixed, free]);
    let (mut seen, mut last_gap, mut worst) = (0, 0.0, 0.0f64);
    for _ in 0..100_000 {
        s.step().unwrap();
        let gap = s.particles.x[1].x - 2.0 * R;
        let Some(c) = s.held_contacts().first().copied() else {
            assert!(gap >= rupture, "the bridge broke at gap {gap} < {rupture}");
            break;
        };
        if gap > 0.0 {
            // The force on the lower id (the fixed grain at x = 0) pulls it towards +x.
            let expected = willett(gamma_l, theta, v, 0.5 * R, gap);
            worst = worst.max((c.f_n.x / expected - 1.0).abs());
            let f_t = c.f_t.length();
            assert!(f_t < 1e-12 * expected, "apart, no friction: {f_t}");
            seen += 1;
            last_gap = gap;
        }
    }
    eprintln!(
        "bridge: {seen} steps apart, worst {worst:.1e}, last gap {last_gap:e} of {rupture:e}"
    );
    assert!(seen > 100, "the bridge was seen apart {seen} times");
    assert!(worst < 1e-9, "the force strays from Willett's by {worst}");
    let step = s.particles.v[1].x * 1e-6;
    assert!(
        last_gap < rupture && last_gap > rupture - 2.0 * step,
        "the bridge lasted to gap {last_gap}, its rupture distance is {rupture}"
    );
}

#[test]
fn a_broken_bridge_pulls_not_until_the_grain_touches_again() {
    let (v, theta) = (2e-10, 20.0);
    let rupture = (1.0 + 0.5 * f64::to_radians(theta)) * f64::cbrt(v);
    // Off the floor at a speed that rises past the rupture distance, not much further.
    let g = 9.81;
    let bridge = 4.0 * PI * 0.07 * f64::to_radians(theta).cos() * R;
    let m = Inertia::mass(R, RHO);
    let v0 = (2.0 * (g + bridge / m) * 1.5 * rupture).sqrt();
    let start = grain(DVec3::new(0.0, 0.0, R - 1e-9), DVec3::new(0.0, 0.0, v0));
    let dt = 1e-6;
    let mut s = sim(WET, g, FLOOR, dt, vec![start]);
    let (mut broke, mut returned, mut touched) = (false, false, false);
    for _ in 0..200_000 {
        let v_before = s.particles.v[0].z;
        s.step().unwrap();
        let gap = s.particles.x[0].z - R;
        let open = !s.held_contacts().is_empty();
        if !broke {
            broke = !open && gap > 0.0;
            continue;
        }
        if gap < 0.0 {
            // The contact opens at the next step's contact stage.
            s.step().unwrap();
            touched = !s.held_contacts().is_empty();
            break;
        }
        // Broken: gravity alone, also back within the rupture distance.
        assert!(!open, "a bridge came back at gap {gap} without touch");
        let dv = s.particles.v[0].z - v_before;
        assert!((dv + g * dt).abs() < 1e-12, "dv {dv} at gap {gap}");
        returned |= gap < 0.5 * rupture;
    }
    assert!(
        broke && returned && touched,
        "broke {broke}, returned {returned}, touched {touched}"
    );
}

/// A pour of 200 grains into the silo with JKR and with liquid bridges: the same bits on 1
/// and 2 threads, and with another skin (the lists rebuilt at other steps carry the open
/// contacts, bridges apart too).
#[test]
fn jkr_and_bridges_give_the_same_bits_on_one_and_two_threads_and_any_skin() {
    for models in [
        "adhesion_model = \"jkr\"\nsurface_energy = 0.05",
        "liquid_volume = 1e-10\nsurface_tension = 0.07\ncontact_angle = 20.0",
    ] {
        let run = |threads, skin| common::silo_pour(models, threads, skin);
        let ((one, contacts), (two, _)) = (run(1, 0.5), run(2, 0.5));
        assert!(
            one.len() > 100 && contacts > 50,
            "{models}: {contacts} contacts"
        );
        assert!(one == two, "{models}: 1 and 2 threads differ");
        let (wide, _) = run(1, 1.3);
        assert!(one == wide, "{models}: skin 1.3 differs");
    }
}

#[test]
fn liquid_and_jkr_keys_are_checked() {
    let refused = |text: &str| {
        let e = tinydem::scenario::Scenario::parse(text, std::path::Path::new("s.toml"));
        format!("{:#}", e.expect_err(text))
    };
    let e = refused("[material]\nliquid_volume = 1e-9\n");
    assert!(
        e.contains("liquid_volume = 0.000000001 needs surface_tension > 0")
            || e.contains("needs surface_tension > 0"),
        "{e}"
    );
    let e =
        refused("[material]\nliquid_volume = 1e-9\nsurface_tension = 0.07\ncontact_angle = 95.0\n");
    assert!(e.contains("contact_angle = 95 is not allowed"), "{e}");
    let e =
        refused("[material]\nliquid_volume = 1e-9\nsurface_tension = 0.07\ncontact_angle = -1.0\n");
    assert!(e.contains("contact_angle = -1 is not allowed"), "{e}");
    let e = refused("[material]\nsurface_tension = 0.07\n");
    assert!(e.contains("give liquid_volume > 0"), "{e}");
    let e = refused("[material]\nliquid_volume = -1e-9\nsurface_tension = 0.07\n");
    assert!(
        e.contains("liquid_volume = -0.000000001 is not allowed")
            || e.contains("liquid_volume = -1e-9 is not allowed"),
        "{e}"
    );
    let e = refused("[material]\nadhesion_model = \"jkr\"\n");
    assert!(
        e.contains("adhesion_model = \"jkr\" needs surface_energy > 0"),
        "{e}"
    );
    let e = refused("[material]\nadhesion_model = \"jkr\"\nsurface_energy = -0.1\n");
    assert!(e.contains("surface_energy = -0.1 is not allowed"), "{e}");
    let e = refused(
        "[material]\nadhesion_model = \"jkr\"\nsurface_energy = 0.1\nhooke_stiffness = 100.0\n",
    );
    assert!(e.contains("JKR's contact area is Hertz's"), "{e}");
    let e = refused(
        "[[materials]]\nname = \"a\"\nadhesion_model = \"jkr\"\nsurface_energy = 0.1\n\
         [[materials]]\nname = \"b\"\nliquid_volume = 1e-9\nsurface_tension = 0.07\n",
    );
    assert!(e.contains("JKR and liquid bridges in one run"), "{e}");
    let e = refused(
        "[[materials]]\nname = \"a\"\n[[materials]]\nname = \"b\"\n\
         [[interactions]]\nmaterials = [\"a\", \"b\"]\nliquid_volume = 1e-9\n",
    );
    assert!(e.contains("have no surface tension"), "{e}");
    let e = refused("[material]\nadhesion_model = \"capillary\"\n");
    assert!(e.contains("\"jkr\" (JKR's elastic adhesion"), "{e}");
}

/// `check` names the adhesion in force and each wet pair's bridge, and `run.toml` keeps
/// the liquid.
#[test]
fn check_names_the_bridges_and_run_toml_keeps_them() {
    let text = format!("[material]\n{WET}\n");
    let s = tinydem::scenario::Scenario::parse(&text, std::path::Path::new("s.toml")).unwrap();
    let written = s.to_toml();
    assert!(
        written.contains("liquid_volume = 2e-10")
            || written.contains("liquid_volume = 0.0000000002"),
        "{written}"
    );
    let again =
        tinydem::scenario::Scenario::parse(&written, std::path::Path::new("run.toml")).unwrap();
    assert_eq!(again, s);
    let rupture = (1.0 + 0.5 * f64::to_radians(20.0)) * f64::cbrt(2e-10);
    let dir = tempfile::tempdir().unwrap();
    let lines = tinydem::driver::check::describe(&s, dir.path()).unwrap();
    assert!(!lines.contains("lists' skin"), "{lines}");
    // A bridge that reaches past the skin raises it, and check says so.
    let big = text.replace("2e-10", "1e-7");
    let s = tinydem::scenario::Scenario::parse(&big, std::path::Path::new("s.toml")).unwrap();
    let raised = tinydem::driver::check::describe(&s, dir.path()).unwrap();
    let rupture_big = (1.0 + 0.5 * f64::to_radians(20.0)) * f64::cbrt(1e-7);
    assert!(
        raised.contains(&format!(
            "lists' skin            {rupture_big:.4e} m, raised from"
        )),
        "{raised}"
    );
    assert!(
        lines.contains("liquid bridges") && lines.contains(&format!("rupture at {rupture:.4e} m")),
        "{lines}"
    );
}

/// A periodic period must hold the widest pair once with the skin raised to a bridge's reach.
#[test]
fn a_raised_skin_lengthens_the_shortest_period() {
    // R 5 mm, skin 0.5 R: the shortest period is 6 R = 30 mm dry; a bridge of V 1e-7 m³
    // reaches 5.4 mm, raising the skin by 2.9 mm and the shortest period by twice that.
    let text = |liquid: &str| {
        format!(
            "[geometry]\nradius_min = {R}\nradius_max = {R}\nmesh_radii = [0.0]\n\
             [domain]\nmin = [-0.016, -0.05, -0.05]\nmax = [0.016, 0.05, 0.05]\nperiodic = [true, false, false]\n\
             [material]\n{liquid}\n[simulation]\nmax_particles = 0\nspawn_attempts = 0\n"
        )
    };
    let dry = common::scenario(&text(""));
    assert!(Simulation::new(dry).is_ok());
    let wet = common::scenario(&text(
        "liquid_volume = 1e-7\nsurface_tension = 0.07\ncontact_angle = 20.0",
    ));
    let e = format!(
        "{:#}",
        Simulation::new(wet).err().expect("too short a period")
    );
    assert!(
        e.contains("is shorter than 6 times the largest radius and twice the skin's rise"),
        "{e}"
    );
}

/// `jkr_force` parts a contact at the pull-off force, as LAMMPS's `jkr`: at the overlap
/// 3^(-2/3) δ_c, and an impact loses the work of parting from δ = 0 to there (x³ = 3/4).
#[test]
fn jkr_force_parts_at_the_pull_off_force() {
    let gamma = 0.5;
    let (f_c, delta_c) = jkr_pull_off(gamma, E_WALL, R);
    let (strongest, last) = pulled_off(gamma, true, "jkr_force");
    let parting = 3f64.powf(-2.0 / 3.0) * delta_c;
    assert!((strongest / f_c - 1.0).abs() < 1e-2, "{strongest} vs {f_c}");
    assert!(
        (last / parting - 1.0).abs() < 1e-2,
        "parted at {last}, not {parting}"
    );
    // The work lost is that share of the full hysteresis.
    let a = |x: f64| 8.0 / 15.0 * x.powi(10) - 4.0 / 3.0 * x.powi(7) + 0.5 * x.powi(4);
    let share = (a(1.0) - a(0.75f64.cbrt())) / (a(1.0) - a(0.25f64.cbrt()));
    let v_s = sticking_speed(gamma, E_WALL, R, Inertia::mass(R, RHO));
    let material = format!("adhesion_model = \"jkr_force\"\nsurface_energy = {gamma}");
    let start = grain(
        DVec3::new(0.0, 0.0, R + 1e-9),
        DVec3::new(0.0, 0.0, -1.2 * v_s),
    );
    let mut s = sim(&material, 0.0, FLOOR, 2e-8, vec![start]);
    for _ in 0..400_000 {
        s.step().unwrap();
    }
    let leaving = (1.44 - share).sqrt() * v_s;
    let v = s.particles.v[0].z;
    eprintln!(
        "jkr_force: parted at {:+.2e}, leaves {:+.2e}",
        last / parting - 1.0,
        v / leaving - 1.0
    );
    assert!(
        s.held_contacts().is_empty() && (v / leaving - 1.0).abs() < 1e-3,
        "{v} vs {leaving}"
    );
}
