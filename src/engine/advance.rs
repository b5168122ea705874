//! Stage 5 of the step: semi-implicit Euler and SPIRAL for every particle (`integrate.rs`),
//! in lanes, with gravity, drag and the summed loads.

use super::*;

/// Stage 5 (Section 2.3): advance each particle of `p` by `dt` under gravity `g` and the
/// force and torque its contacts added to its load (Eqs. 1-2), which it uses up (zeroes).
/// A fixed particle keeps its place and orientation, at rest; its load is dropped. A
/// sphere of a rigid body keeps the state stage 5a gave it.
/// Returns whether some particle's new state is not finite (for stage 6, so that it needs
/// no pass of its own).
#[inline(never)] // a stage of its own in profiles
pub(super) fn run(
    model: &Model,
    (dt, g): (f64, DVec3),
    p: &mut Particles,
    loads: &mut [Load],
) -> bool {
    let scales = &model.scales;
    let densities = &model.densities;
    let uniform = densities.len() == 1;
    let (material, fixed, member) = (&p.material, &p.fixed, &p.body);
    (
        p.x.par_chunks_mut(WIDTH),
        p.v.par_chunks_mut(WIDTH),
        p.q.par_chunks_mut(WIDTH),
        p.w.par_chunks_mut(WIDTH),
        p.radius.par_chunks(WIDTH),
        material.par_chunks(WIDTH),
        (fixed.par_chunks(WIDTH), member.par_chunks(WIDTH)),
        loads.par_chunks_mut(WIDTH),
    )
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN.div_ceil(WIDTH))
        .map(|(x, v, q, w, radius, material, (fixed, member), load)| {
            // `WIDTH` particles at a time in lanes; a short last group repeats its last
            // particle in the spare lanes. The loads are used up (zeroed for the next
            // step).
            let n = x.len();
            let lane: [usize; WIDTH] = std::array::from_fn(|l| l.min(n - 1));
            let (mut f, mut tau) = ([DVec3::ZERO; WIDTH], [DVec3::ZERO; WIDTH]);
            for l in 0..WIDTH {
                let v = load[lane[l]].value(&scales.lanes);
                (f[l], tau[l]) = (DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5]));
            }
            load.fill(Load::default());
            let state = State::<Group> {
                x: Group::gather_vec_at(x, &lane),
                v: Group::gather_vec_at(v, &lane),
                q: Group::gather_quat_at(q, &lane),
                w: Group::gather_vec_at(w, &lane),
            };
            let (inv_mass_r3, drag) = if uniform {
                let d = densities[0];
                (Group::splat(d.inv_mass_r3), Group::splat(d.drag))
            } else {
                let d = lane.map(|l| densities[material[l] as usize]);
                (
                    Group::gather(d.map(|d| d.inv_mass_r3)),
                    Group::gather(d.map(|d| d.drag)),
                )
            };
            let body = Response::with(Group::gather_at(radius, &lane), inv_mass_r3, drag);
            let new = advance(
                state,
                &body,
                Group::gather_vec(f),
                Group::gather_vec(tau),
                Group::splat_vec(g),
                Group::splat(dt),
            );
            let (new_x, new_v, new_q, new_w) = (
                Group::scatter_vec(new.x),
                Group::scatter_vec(new.v),
                Group::scatter_quat(new.q),
                Group::scatter_vec(new.w),
            );
            if fixed.contains(&true) || member.iter().any(Option::is_some) {
                let held: [Held; WIDTH] = std::array::from_fn(|l| match (lane[l], l < n) {
                    (_, false) => Held::Free, // a spare lane
                    (k, true) if member[k].is_some() => Held::Member,
                    (k, true) if fixed[k] => Held::Fixed,
                    _ => Held::Free,
                });
                hold(&held[..n], (x, v, q, w), (&new_x, &new_v, &new_q, &new_w));
            } else {
                x.copy_from_slice(&new_x[..n]);
                v.copy_from_slice(&new_v[..n]);
                q.copy_from_slice(&new_q[..n]);
                w.copy_from_slice(&new_w[..n]);
            }
            (0..n).any(|l| !(x[l].is_finite() && v[l].is_finite() && w[l].is_finite()))
        })
        .reduce(|| false, |a, b| a || b)
}

/// What the integration does with a particle.
#[derive(Clone, Copy, PartialEq)]
enum Held {
    Free,
    /// Fixed: stays where it is, at rest.
    Fixed,
    /// A sphere of a rigid body: moved by stage 5a.
    Member,
}

/// The new states of a group with fixed particles or spheres of bodies: fixed ones stay
/// where they are, at rest, the spheres of bodies as they are.
fn hold(
    held: &[Held],
    (x, v, q, w): (&mut [DVec3], &mut [DVec3], &mut [glam::DQuat], &mut [DVec3]),
    new: (
        &[DVec3; WIDTH],
        &[DVec3; WIDTH],
        &[glam::DQuat; WIDTH],
        &[DVec3; WIDTH],
    ),
) {
    for (l, &held) in held.iter().enumerate() {
        match held {
            Held::Fixed => (v[l], w[l]) = (DVec3::ZERO, DVec3::ZERO),
            Held::Member => {}
            Held::Free => (x[l], v[l], q[l], w[l]) = (new.0[l], new.1[l], new.2[l], new.3[l]),
        }
    }
}
