//! Stage 5a of the step: the rigid bodies (clumps). Each body sums the loads of its
//! spheres about its centre of mass, moves as one rigid body, and puts its spheres where
//! its motion takes them; stage 5 then leaves those spheres alone.

use super::*;
use crate::model::bodies::Body;
use crate::model::rigid;
use crate::neighbours::Periodic;

/// Stage 5a: advance every body of `p` by `dt` under gravity `g` and the loads of its
/// spheres (which stage 5 zeroes with the others), and set its spheres' states. The sum
/// over a body's spheres runs in their id order, and each sphere's load is an exact sum,
/// so a body's motion does not depend on the thread count or the storage order. Returns
/// whether some body's new state is not finite.
///
/// Translation is the spheres' semi-implicit Euler (v += Δt (F/M + g), x += Δt v); rotation
/// is `rigid::step` (the torque kicks the angular momentum, then the splitting of Dullweber,
/// Leimkuhler & McLachlan turns the body freely, gyroscopic term included). Drag acts on
/// each sphere as on a free one (Eqs. 3-4, at the sphere's velocity).
///
/// A fixed body (its spheres fixed: by a `[[fixed]]` box that holds its centre of mass, the
/// `fixed` column, Python's `freeze`) stays where it is, at rest.
///
/// In a split run, only the bodies whose spheres are `owned` move: the others are ghosts,
/// whose spheres' states their owners send (stage 5c).
#[inline(never)] // a stage of its own in profiles
pub(super) fn run(
    model: &Model,
    (dt, g): (f64, DVec3),
    (periodic, owned): (Option<Periodic>, Option<&[bool]>),
    p: &mut Particles,
    loads: &[Load],
) -> bool {
    if p.bodies.is_empty() {
        return false;
    }
    let Particles {
        bodies,
        x,
        v,
        q,
        w,
        radius,
        material,
        fixed,
        ..
    } = p;
    let (list, members) = bodies.parts_mut();
    let own = |b: usize| owned.is_none_or(|o| o[members.of(b)[0] as usize]);
    let spheres = Spheres {
        v,
        w,
        radius,
        material,
    };
    list.par_iter_mut()
        .enumerate()
        .with_min_len(64)
        .filter(|(b, _)| own(*b))
        .for_each(|(b, body)| {
            if fixed[members.of(b)[0] as usize] {
                // Held where it is, at rest.
                (body.v, body.w) = (DVec3::ZERO, DVec3::ZERO);
                return;
            }
            let (f, tau) = wrench(model, &spheres, body, members.of(b), loads);
            body.v += (f / body.mass + g) * dt;
            body.x += body.v * dt;
            (body.q, body.w) = rigid::step(body.q, body.w, tau, body.inertia, dt);
        });
    let mut non_finite = false;
    for (b, body) in list.iter().enumerate().filter(|(b, _)| own(*b)) {
        non_finite |= !(body.x.is_finite() && body.v.is_finite() && body.w.is_finite());
        for (k, &i) in members.of(b).iter().enumerate() {
            let i = i as usize;
            let (at, velocity) = body.sphere_state(k);
            (x[i], v[i]) = image_of(periodic, at, velocity, x[i]);
            (q[i], w[i]) = (body.q, body.w);
        }
    }
    non_finite
}

/// A sphere of a body at `at` with `velocity`, as the image of that place nearest `now`,
/// where the sphere is: a rebuild wraps each sphere into the box on its own, and the sphere
/// keeps that image when its body places it anew. Across the gradient sides of a sheared
/// (Lees-Edwards) box the image is offset along the shear axis as it is now and moves with
/// the shear velocity.
fn image_of(periodic: Option<Periodic>, at: DVec3, velocity: DVec3, now: DVec3) -> (DVec3, DVec3) {
    let Some(p) = periodic else {
        return (at, velocity);
    };
    let (shift, crossings) = p.image_towards(at, now);
    let mut velocity = velocity;
    if let Some(sh) = p.shear {
        velocity[sh.axis] += crossings as f64 * sh.velocity;
    }
    (at + shift, velocity)
}

/// What the wrench of a body reads of its spheres.
struct Spheres<'a> {
    v: &'a [DVec3],
    w: &'a [DVec3],
    radius: &'a [f64],
    material: &'a [u16],
}

/// The force and the torque about the centre of mass on `body` (its spheres stored at
/// `members`): its spheres' loads and drag, in their id order.
fn wrench(
    model: &Model,
    p: &Spheres,
    body: &Body,
    members: &[u32],
    loads: &[Load],
) -> (DVec3, DVec3) {
    let (mut f, mut tau) = (DVec3::ZERO, DVec3::ZERO);
    for (k, &i) in members.iter().enumerate() {
        let i = i as usize;
        let load = loads[i].value(&model.scales.lanes);
        let d = model.densities[p.material[i] as usize];
        let r = p.radius[i];
        // Eqs. (3)-(4) for the sphere alone: m c = (4/3 π ρ R³) drag / R², and I γ.
        let m_c = d.mass_per_r3 * d.drag * r;
        let f_k = DVec3::new(load[0], load[1], load[2]) - p.v[i] * m_c;
        let tau_k = DVec3::new(load[3], load[4], load[5]) - p.w[i] * (4.0 / 3.0 * m_c * r * r);
        f += f_k;
        tau += tau_k + (body.q * body.offsets[k]).cross(f_k);
    }
    (f, tau)
}
