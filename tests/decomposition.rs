//! The same bits however the particles are laid out: each particle's forces are summed in
//! the order of its partners' ids, so the storage order, the slabs of the pair stage and
//! the times of the neighbour-list rebuilds (which re-sort the particles) change nothing.
//! It is what a run split over processes rests on: each process holds its own particles in
//! its own order.

mod common;

use tinydem::simulation::Simulation;

/// Each particle's id with the bits of its state, in id order.
fn state_by_id(sim: &Simulation) -> Vec<(u32, Vec<u64>)> {
    sim.particles
        .iter_by_id()
        .map(|(id, p)| {
            let mut bits: Vec<u64> = [p.x, p.v, p.w]
                .iter()
                .flat_map(|v| v.to_array())
                .chain(p.q.to_array())
                .map(f64::to_bits)
                .collect();
            bits.push(p.radius.to_bits());
            (id, bits)
        })
        .collect()
}

/// The silo of `tests/data/stages` filling through its plug-less outlet: spawning, two
/// radii, friction of every kind, a mesh, outlets and the loads on the walls.
fn silo(skin: f64) -> String {
    format!(
        "[geometry]\nradius_min = 0.003\nradius_max = 0.004\nmesh = \"stages/silo.off\"\nmesh_radii = [0.0]\n\
         spawn_min = [-0.05, -0.05, 0.06]\nspawn_max = [0.05, 0.05, 0.14]\n\
         [material]\nrestitution = 0.3\nfriction_sliding = 0.5\nfriction_rolling = 0.1\nfriction_twisting = 0.1\n\
         [simulation]\nmax_particles = 300\nskin = {skin}\n\
         [domain]\nmin = [-0.1, -0.1, -0.2]\nmax = [0.1, 0.1, 0.2]\n\
         [[outlets]]\nmin = [-0.1, -0.1, -0.2]\nmax = [0.1, 0.1, -0.05]\n\
         [output]\nwall_forces = true\n"
    )
}

#[test]
fn the_skin_changes_how_often_the_lists_are_rebuilt_not_the_bits() {
    let steps = 2500;
    let runs: Vec<Simulation> = [0.5, 0.1, 2.0]
        .iter()
        .map(|&skin| common::simulate(&silo(skin), steps))
        .collect();
    let rebuilds: Vec<u64> = runs.iter().map(Simulation::rebuilds).collect();
    assert!(
        rebuilds[1] > 2 * rebuilds[0] && rebuilds[0] > 2 * rebuilds[2],
        "the skins should rebuild at very different times: {rebuilds:?}"
    );
    let reference = state_by_id(&runs[0]);
    assert!(reference.len() > 200, "{} particles", reference.len());
    assert!(
        runs[0].contact_count() > 100,
        "{} contacts: the grains should be packed",
        runs[0].contact_count()
    );
    for (sim, skin) in runs.iter().zip([0.5, 0.1, 2.0]).skip(1) {
        assert!(
            state_by_id(sim) == reference,
            "skin {skin}: the state differs from skin 0.5's"
        );
    }
}
