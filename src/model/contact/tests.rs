//! The contact law against Section 2.2: its limits, its symmetries and its friction springs.

use super::friction::{coulomb_spring, project_onto_tangent_plane};
use super::*;
use crate::model::motion::RigidVelocity;
use crate::model::registry::AdhesionModel;
use glam::DVec3;

#[test]
fn beta_limits() {
    assert_eq!(damping_factor(1.0), 0.0);
    assert_eq!(damping_factor(0.0), 1.0);
    let b = damping_factor(0.5);
    assert!((b - 0.215_453_8).abs() < 1e-6, "{b}");
}

#[test]
fn projection_keeps_length_and_removes_normal_part() {
    let n = DVec3::Z;
    let u = project_onto_tangent_plane::<f64>(DVec3::new(3.0, 0.0, 4.0), n);
    assert!((u - DVec3::new(5.0, 0.0, 0.0)).length() < 1e-15);
    assert_eq!(project_onto_tangent_plane::<f64>(DVec3::Z, n), DVec3::ZERO);
    assert_eq!(
        project_onto_tangent_plane::<f64>(DVec3::ZERO, n),
        DVec3::ZERO
    );
}

#[test]
fn static_spring_accumulates_and_kinetic_spring_matches_coulomb() {
    // The paper's order: the force of the old spring, then the spring grows.
    let mut u = 0.0;
    let f = coulomb_spring(&mut u, 2.0, 10.0, 1.0, 100.0, (0.5, false), false);
    assert_eq!((f, u), (-2.0, 1.0));
    // Advancing first: the spring grows, then gives the force.
    let mut u = 0.0;
    let f = coulomb_spring(&mut u, 2.0, 10.0, 1.0, 100.0, (0.5, true), false);
    assert_eq!((f, u), (-12.0, 1.0));
    // Kinetic: |f| is clipped to the limit and the spring reproduces it (Eq. 55).
    for first in [false, true] {
        let mut u = 1.0;
        let f = coulomb_spring(&mut u, 2.0, 10.0, 1.0, 3.0, (0.5, first), false);
        assert_eq!(f, -3.0);
        assert!((-10.0 * u - 2.0 - f).abs() < 1e-15);
    }
}

/// The update matrices of `coulomb_spring`'s comment, stepped: the paper's order gains
/// energy by 1 + (ωΔt)² a step undamped; advancing first keeps it bounded.
#[test]
fn sticking_oscillator_gains_energy_only_in_the_papers_order() {
    let (m, k, dt) = (1.0, 1.0, 0.3);
    let energy_after = |first: bool, steps: usize| {
        let (mut u, mut v) = (0.0, 1.0);
        let mut most: f64 = 0.0;
        for _ in 0..steps {
            // The contact sees the velocity of the body, which moves with it.
            let f = coulomb_spring(&mut u, v, k, 0.0, f64::INFINITY, (dt, first), false);
            v += dt * f / m;
            most = most.max(0.5 * m * v * v + 0.5 * k * u * u);
        }
        most
    };
    let gain = 1.0 + (dt * dt * k / m);
    let paper = energy_after(false, 100);
    assert!(paper > 0.5 * gain.powi(90), "{paper}");
    let first = energy_after(true, 10_000);
    assert!(first < 0.5 * 1.5, "{first}");
}

mod lanes {
    use super::*;
    use crate::model::lanes::Gather;
    use proptest::prelude::*;
    use wide::{f64x4, f64x8};

    fn vec3(range: f64) -> impl Strategy<Value = DVec3> {
        (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    type Contact = (Body, Body, Springs);

    /// One contact: bodies i and j overlapping by up to half the smaller radius, and
    /// springs that are zero, small (sticking) or large (sliding). Not coincident
    /// centres: there r_i + r_j = 0 and the law gives NaN, alone and in lanes (with
    /// NaNs of either sign); such an overlap, deeper than either radius, stops the run
    /// as unstable in any case.
    fn contact() -> impl Strategy<Value = Contact> {
        let spring = prop_oneof![Just(DVec3::ZERO), vec3(1e-6), vec3(1e-2)];
        (
            (1e-3..1e-2f64, 1e-3..1e-2f64, 0.5..0.999f64, vec3(1.0)),
            (vec3(1.0), vec3(1.0), vec3(100.0), vec3(100.0)),
            (spring.clone(), spring, -1e-2..1e-2f64, any::<bool>()),
        )
            .prop_map(
                |((r_i, r_j, reach, dir), (v_i, v_j, w_i, w_j), (u_s, u_r, u_t, twist))| {
                    let dir = dir.try_normalize().unwrap_or(DVec3::X);
                    let x_j = DVec3::new(0.3, -0.2, 0.1);
                    let i = Body {
                        x: x_j + dir * (r_i + r_j) * reach,
                        radius: r_i,
                        v: v_i,
                        w: w_i,
                    };
                    let j = Body {
                        x: x_j,
                        radius: r_j,
                        v: v_j,
                        w: w_j,
                    };
                    let springs = Springs {
                        u_s,
                        u_r,
                        u_t: if twist { u_t } else { 0.0 },
                    };
                    (i, j, springs)
                },
            )
    }

    /// The law of one material with restitution `e_n` and cohesion `k_c`, its springs in
    /// the paper's order or advanced first: each of the four compositions.
    fn law(e_n: f64, k_c: f64, paper: bool) -> ContactLaw {
        let models = crate::model::registry::ContactModels {
            adhesion: if k_c > 0.0 {
                AdhesionModel::Sjkr
            } else {
                AdhesionModel::None
            },
            ..Default::default()
        };
        let material = Material {
            density: 2500.0,
            youngs_modulus: 1e7,
            poisson_ratio: 0.25,
            restitution: e_n,
            friction_sliding: 0.4,
            friction_rolling: 0.05,
            friction_twisting: 0.02,
            viscosity: 1e-5,
            cohesion: k_c,
            surface_energy: 0.0,
            liquid: Default::default(),
            hooke_stiffness: 0.0,
            hooke_stiffness_ratio: 2.0 / 7.0,
            models,
            thermal: Default::default(),
        };
        let springs = if paper {
            FrictionSprings::Paper
        } else {
            FrictionSprings::AdvanceFirst
        };
        ContactLaw::new(&material, 1e-5, springs)
    }

    fn cohesion() -> impl Strategy<Value = f64> {
        prop_oneof![Just(0.0), 1.0..1e5f64]
    }

    fn mass(r: f64) -> f64 {
        4.0 / 3.0 * std::f64::consts::PI * 2500.0 * r.powi(3)
    }

    /// Fails unless the lanes of `force` and `springs` have the bits of the contacts
    /// evaluated one by one.
    fn same_bits<T: Gather<N>, const N: usize>(
        single: &[(ContactForce, Springs); N],
        force: ContactForce<T>,
        springs: Springs<T>,
    ) -> Result<(), TestCaseError> {
        let (f, tau_i, tau_j) = (
            T::scatter_vec(force.f),
            T::scatter_vec(force.tau_i),
            T::scatter_vec(force.tau_j),
        );
        let (u_s, u_r, u_t) = (
            T::scatter_vec(springs.u_s),
            T::scatter_vec(springs.u_r),
            springs.u_t.scatter(),
        );
        let bits = |v: DVec3| v.to_array().map(f64::to_bits);
        for (l, (alone, springs_alone)) in single.iter().enumerate() {
            prop_assert_eq!(bits(f[l]), bits(alone.f), "f, lane {}", l);
            prop_assert_eq!(bits(tau_i[l]), bits(alone.tau_i), "tau_i, lane {}", l);
            prop_assert_eq!(bits(tau_j[l]), bits(alone.tau_j), "tau_j, lane {}", l);
            prop_assert_eq!(bits(u_s[l]), bits(springs_alone.u_s), "u_s, lane {}", l);
            prop_assert_eq!(bits(u_r[l]), bits(springs_alone.u_r), "u_r, lane {}", l);
            prop_assert_eq!(
                u_t[l].to_bits(),
                springs_alone.u_t.to_bits(),
                "u_t, lane {}",
                l
            );
        }
        Ok(())
    }

    /// Evaluates `N` contacts in the lanes of `T` and each alone; fails unless every
    /// force, torque and spring has the same bits.
    fn lanes_match_single_contacts<T, const N: usize>(
        contacts: [Contact; N],
        law: ContactLaw,
    ) -> Result<(), TestCaseError>
    where
        T: Gather<N> + Displacement<T>,
        T::Vec: Displacement<T>,
    {
        let single = contacts.map(|(i, j, mut springs)| {
            let kin = Kinematics::between_particles(&i, &j).expect("overlapping");
            let other = Other::Particle {
                r: j.radius,
                m: mass(j.radius),
            };
            let coef = law.pair(0, 0);
            let force = law.evaluate(coef, i.radius, mass(i.radius), other, &kin, &mut springs);
            (force, springs)
        });

        let lanes = |body: fn(&Contact) -> &Body| Body::<T> {
            x: T::gather_vec(contacts.each_ref().map(|c| body(c).x)),
            radius: T::gather(contacts.each_ref().map(|c| body(c).radius)),
            v: T::gather_vec(contacts.each_ref().map(|c| body(c).v)),
            w: T::gather_vec(contacts.each_ref().map(|c| body(c).w)),
        };
        let (i, j) = (lanes(|c| &c.0), lanes(|c| &c.1));
        let d = i.x - j.x;
        let kin = Kinematics::of_touching_particles(&i, &j, d, T::dot(d, d));
        let mut springs = Springs::<T> {
            u_s: T::gather_vec(contacts.map(|c| c.2.u_s)),
            u_r: T::gather_vec(contacts.map(|c| c.2.u_r)),
            u_t: T::gather(contacts.map(|c| c.2.u_t)),
        };
        let m = |body: &Body<T>| T::gather(body.radius.scatter().map(mass));
        let other = Other::Particle {
            r: j.radius,
            m: m(&j),
        };
        let force = law.evaluate(
            &law.pair(0, 0).splat(),
            i.radius,
            m(&i),
            other,
            &kin,
            &mut springs,
        );
        same_bits(&single, force, springs)
    }

    /// A particle touching a static wall whose closest point is at `d` from its centre.
    fn wall_contact() -> impl Strategy<Value = (Body, DVec3, Springs)> {
        let spring = prop_oneof![Just(DVec3::ZERO), vec3(1e-6), vec3(1e-2)];
        (
            (1e-3..1e-2f64, 0.5..0.999f64, vec3(1.0)),
            (vec3(1.0), vec3(100.0)),
            (spring.clone(), spring, -1e-2..1e-2f64),
        )
            .prop_map(|((r, reach, dir), (v, w), (u_s, u_r, u_t))| {
                let d = dir.try_normalize().unwrap_or(DVec3::Z) * r * reach;
                let body = Body {
                    x: DVec3::new(0.1, 0.2, 0.3),
                    radius: r,
                    v,
                    w,
                };
                (body, d, Springs { u_s, u_r, u_t })
            })
    }

    fn walls_in_lanes_match_single_contacts<T, const N: usize>(
        contacts: [(Body, DVec3, Springs); N],
        law: ContactLaw,
    ) -> Result<(), TestCaseError>
    where
        T: Gather<N> + Displacement<T>,
        T::Vec: Displacement<T>,
    {
        let still = RigidVelocity::default();
        let kin = contacts
            .map(|(body, d, _)| Kinematics::with_wall(&body, d, 0.0, &still).expect("overlapping"));
        let single: [_; N] = std::array::from_fn(|l| {
            let (body, _, mut springs) = contacts[l];
            let force = law.evaluate(
                law.with_wall(0, 0),
                body.radius,
                mass(body.radius),
                Other::Wall,
                &kin[l],
                &mut springs,
            );
            (force, springs)
        });
        let lanes = Kinematics::<T> {
            n: T::gather_vec(kin.map(|k| k.n)),
            delta: T::gather(kin.map(|k| k.delta)),
            r_i: T::gather(kin.map(|k| k.r_i)),
            r_j: T::gather(kin.map(|k| k.r_j)),
            v: T::gather_vec(kin.map(|k| k.v)),
            omega: T::gather_vec(kin.map(|k| k.omega)),
        };
        let mut springs = Springs::<T> {
            u_s: T::gather_vec(contacts.map(|c| c.2.u_s)),
            u_r: T::gather_vec(contacts.map(|c| c.2.u_r)),
            u_t: T::gather(contacts.map(|c| c.2.u_t)),
        };
        let radius = T::gather(contacts.map(|c| c.0.radius));
        let m = T::gather(contacts.map(|c| mass(c.0.radius)));
        let force = law.evaluate(
            &law.with_wall(0, 0).splat(),
            radius,
            m,
            Other::Wall,
            &lanes,
            &mut springs,
        );
        same_bits(&single, force, springs)
    }

    proptest! {
        /// The mesh stage evaluates the law for several wall contacts at once.
        #[test]
        fn wall_contacts_in_eight_lanes_give_their_single_bits(
            contacts in proptest::array::uniform8(wall_contact()),
            e_n in 0.1..0.9f64,
            k_c in cohesion(),
            paper: bool,
        ) {
            walls_in_lanes_match_single_contacts::<f64x8, 8>(contacts, law(e_n, k_c, paper))?;
        }

        /// The particle-pair stage evaluates several contacts at once; each lane must
        /// give the bits of the contact evaluated alone.
        #[test]
        fn four_lanes_give_the_bits_of_four_single_contacts(
            contacts in proptest::array::uniform4(contact()),
            e_n in 0.1..0.9f64,
            k_c in cohesion(),
            paper: bool,
        ) {
            lanes_match_single_contacts::<f64x4, 4>(contacts, law(e_n, k_c, paper))?;
        }

        #[test]
        fn eight_lanes_give_the_bits_of_eight_single_contacts(
            contacts in proptest::array::uniform8(contact()),
            e_n in 0.1..0.9f64,
            k_c in cohesion(),
            paper: bool,
        ) {
            lanes_match_single_contacts::<f64x8, 8>(contacts, law(e_n, k_c, paper))?;
        }
    }
}

/// A run where some pair adheres composes every contact with SJKR; a pair with k_c = 0
/// must then give the bits it has without adhesion, in either spring order.
#[test]
fn sjkr_without_cohesion_gives_the_bits_of_no_adhesion() {
    use adhesion::{NoAdhesion, Pull};
    use composition::Composition;
    use friction::{AdvanceFirst, PaperOrder};
    let material = Material {
        density: 2500.0,
        youngs_modulus: 1e7,
        poisson_ratio: 0.25,
        restitution: 0.5,
        friction_sliding: 0.4,
        friction_rolling: 0.05,
        friction_twisting: 0.02,
        viscosity: 1e-5,
        cohesion: 0.0,
        surface_energy: 0.0,
        liquid: Default::default(),
        hooke_stiffness: 0.0,
        hooke_stiffness_ratio: 2.0 / 7.0,
        models: Default::default(),
        thermal: Default::default(),
    };
    let law = ContactLaw::new(&material, 1e-5, FrictionSprings::AdvanceFirst);
    let i = Body {
        x: DVec3::new(0.0, 0.0, 0.0),
        radius: 1e-3,
        v: DVec3::new(0.1, -0.2, 0.3),
        w: DVec3::new(5.0, 1.0, -2.0),
    };
    let j = Body {
        x: DVec3::new(1.9e-3, 1e-4, -2e-4),
        radius: 1.1e-3,
        v: DVec3::new(-0.3, 0.0, 0.1),
        w: DVec3::new(0.0, 7.0, 3.0),
    };
    let kin = Kinematics::between_particles(&i, &j).expect("overlapping");
    let other = Other::Particle { r: 1.1e-3, m: 1e-5 };
    let springs = Springs {
        u_s: DVec3::new(1e-6, 2e-6, 0.0),
        u_r: DVec3::new(0.0, 1e-6, 1e-6),
        u_t: 1e-6,
    };
    let coef = law.pair(0, 0);
    let run = |compose: &dyn Fn(&mut Springs) -> ContactForce| {
        let mut s = springs;
        (compose(&mut s), s)
    };
    type Dry<O> = Composition<NoAdhesion, O>;
    type Wet<O> = Composition<Pull, O>;
    assert_eq!(
        run(&|s| law.compose::<Dry<AdvanceFirst>, f64>(coef, 1e-3, 1e-5, other, &kin, s)),
        run(&|s| law.compose::<Wet<AdvanceFirst>, f64>(coef, 1e-3, 1e-5, other, &kin, s)),
    );
    assert_eq!(
        run(&|s| law.compose::<Dry<PaperOrder>, f64>(coef, 1e-3, 1e-5, other, &kin, s)),
        run(&|s| law.compose::<Wet<PaperOrder>, f64>(coef, 1e-3, 1e-5, other, &kin, s)),
    );
}
