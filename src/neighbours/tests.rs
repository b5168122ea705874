//! The neighbour lists against brute force, the springs through a re-sort, the lonely
//! particles' clearances and the nearest periodic image.

use super::*;

/// The face lists rely on it: every cell lists its boxes in ascending order, however
/// they were added.
#[test]
fn a_cell_lists_its_boxes_in_ascending_order() {
    let boxes: Vec<(DVec3, DVec3)> = (0..50)
        .map(|k| {
            let lo = DVec3::new((k * 37 % 11) as f64, (k * 13 % 7) as f64, 0.0) * 0.1;
            (lo, lo + DVec3::splat(0.05 + (k % 5) as f64 * 0.2))
        })
        .rev()
        .collect();
    let grid = CellGrid::of_boxes(&boxes, 0.1);
    let mut seen = 0;
    for x in 0..20 {
        for y in 0..20 {
            let items = grid.at(DVec3::new(
                x as f64 * 0.1 + 0.05,
                y as f64 * 0.1 + 0.05,
                0.01,
            ));
            assert!(items.windows(2).all(|w| w[0] < w[1]), "{items:?}");
            seen += items.len();
        }
    }
    assert!(seen > 100, "{seen}");
}

/// Particles at `x` with radii `radius` (ids in that order).
fn particles(x: &[DVec3], radius: &[f64]) -> Particles {
    x.iter()
        .zip(radius)
        .map(|(&x, &radius)| crate::model::particles::Particle {
            x,
            radius,
            ..Default::default()
        })
        .collect()
}

/// The listed particle pairs by id, (lower, higher), sorted; and a check that every
/// owner's partners follow it, in order, within the next slab.
fn listed(nb: &Neighbours, p: &Particles) -> Vec<(Id, Id)> {
    let list = &nb.pairs;
    let mut pairs = Vec::new();
    let slabs = &nb.pairs.blocks;
    for s in 0..slabs.len() - 1 {
        let limit = slabs.get(s + 2).copied().unwrap_or(slabs[slabs.len() - 1]);
        for i in slabs[s] as usize..slabs[s + 1] as usize {
            let run = &list.partner[list.run(i)];
            assert!(run.windows(2).all(|w| w[0] < w[1]), "{run:?}");
            for &j in run {
                assert!(j as usize > i && j < limit, "{i} {j} slabs {slabs:?}");
                let (a, b) = (p.id[i], p.id[j as usize]);
                pairs.push((a.min(b), a.max(b)));
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

/// Brute-force pairs within reach, as (i, j) with i < j.
fn brute(x: &[DVec3], radius: &[f64], skin: f64) -> Vec<(Id, Id)> {
    let mut v = Vec::new();
    for i in 0..x.len() {
        for j in i + 1..x.len() {
            if x[i].distance(x[j]) < radius[i] + radius[j] + skin {
                v.push((i as Id, j as Id));
            }
        }
    }
    v
}

#[test]
fn polydisperse_lists_match_brute_force() {
    // 600 small particles and 6 ten times larger among them.
    let mut s = 11u64;
    let mut rnd = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let x: Vec<DVec3> = (0..606)
        .map(|_| DVec3::new(rnd(), rnd(), rnd()) * 0.15)
        .collect();
    let radius: Vec<f64> = (0..606)
        .map(|i| if i % 101 == 0 { 0.02 } else { 0.002 })
        .collect();
    let mut nb = Neighbours::new(0.001);
    let mut p = particles(&x, &radius);
    nb.rebuild(&mut p, &[], &FaceGrid::default());
    assert_eq!(listed(&nb, &p), brute(&x, &radius, 0.001));
}

#[test]
fn lists_every_pair_within_reach_once_in_spatial_order() {
    // A small lattice with jitter; compare with brute force.
    let mut x = Vec::new();
    let mut s = 7u64;
    let mut rnd = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..400 {
        x.push(DVec3::new(rnd(), rnd(), rnd()) * 0.2 - 0.1);
    }
    let radius: Vec<f64> = (0..x.len())
        .map(|i| 0.005 + 0.001 * (i % 3) as f64)
        .collect();
    let mut nb = Neighbours::new(0.002);
    let mut p = particles(&x, &radius);
    nb.rebuild(&mut p, &[], &FaceGrid::default());
    assert_eq!(listed(&nb, &p), brute(&x, &radius, 0.002));
    // The particles are stored in the order of their cells, each one unchanged.
    let h = 2.0 * 0.007 + 0.002;
    let keys: Vec<u64> = p.x.iter().map(|&x| key(cell_of(x, 1.0 / h))).collect();
    assert!(keys.is_sorted());
    for k in 0..p.len() {
        assert_eq!(p.x[k], x[p.id[k] as usize]);
    }
    assert!(nb.pairs.blocks.len() > 3, "{:?}", nb.pairs.blocks);
}

/// A checkpoint's springs naming a particle it lacks are refused with the id; a split
/// run's history leaves out the springs of particles another process holds.
#[test]
fn histories_by_id_name_or_skip_the_particles_absent() {
    let x = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
    let p = particles(&x, &[0.1; 3]);
    let s = |u_t: f64| {
        let springs = crate::model::springs::Springs {
            u_t,
            ..Default::default()
        };
        ContactState {
            springs,
            ..ContactState::default()
        }
    };
    let entries = [(0, 2, s(1.0)), (1, 7, s(2.0)), (2, 1, s(3.0))];
    let err = History::in_storage(&p, &entries, true).unwrap_err();
    assert!(err.contains("id 7"), "{err}");
    let index = IdIndex::of(&p);
    let h = History::of_present(&index, p.len(), &entries, true);
    assert_eq!(
        h.entries(),
        vec![(0, 2, s(1.0)), (1, 2, s(3.0))],
        "the pair with 7 left out, the others keyed low to high"
    );
}

#[test]
fn an_index_of_few_of_many_ids_is_a_sorted_list_that_finds_what_a_table_finds() {
    let x = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    let mut p = particles(&x, &[0.1; 4]);
    (p.id, p.next_id) = (vec![900_000, 5, 12_345, 17], 1_000_000);
    let sorted = IdIndex::of(&p);
    assert!(
        matches!(sorted, IdIndex::Sorted(_)),
        "4 of 10^6 ids: no table"
    );
    p.next_id = 900_001;
    let index = IdIndex::of(&p);
    let table = match &index {
        IdIndex::Sorted(list) => {
            let mut t = vec![NONE; 900_001];
            list.iter().for_each(|&(id, k)| t[id as usize] = k);
            IdIndex::Table(t)
        }
        IdIndex::Table(_) => unreachable!("4 of 900,001 ids"),
    };
    for id in [0, 5, 17, 18, 12_345, 899_999, 900_000, 900_001, u64::MAX] {
        assert_eq!(sorted.get(id), table.get(id), "id {id}");
    }
    assert_eq!(sorted.get(12_345), Some(2));
    (p.id, p.next_id) = (vec![0, 1, 2, 3], 4);
    assert!(
        matches!(IdIndex::of(&p), IdIndex::Table(_)),
        "all ids: a table"
    );
}

#[test]
fn springs_follow_their_pairs_through_a_re_sort() {
    let x = vec![
        DVec3::new(0.5, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(0.009, 0.0, 0.0),
        DVec3::new(0.509, 0.0, 0.0),
    ];
    let radius = vec![0.005; 4];
    let mut p = particles(&x, &radius);
    let mut nb = Neighbours::new(0.002);
    nb.rebuild(&mut p, &[], &FaceGrid::default());
    assert_eq!(listed(&nb, &p), vec![(0, 3), (1, 2)]);
    // Give each pair springs that name it, then move the pairs past each other.
    let list = &mut nb.pairs;
    for i in 0..p.len() {
        let block = list.blocks.partition_point(|&b| b as usize <= i) - 1;
        for k in list.start[i] as usize..list.start[i + 1] as usize {
            let id = p.id[i].min(p.id[list.partner[k] as usize]);
            let e = list.stores[block].open();
            list.stores[block].state.springs[e as usize].u_t = id as f64 + 1.0;
            list.contact[k] = e;
        }
    }
    for x in &mut p.x {
        x.x = 1.0 - x.x;
    }
    nb.rebuild(&mut p, &[], &FaceGrid::default());
    assert_eq!(p.id, vec![3, 0, 2, 1]);
    let (mut pairs, _) = nb.entries_by_id(&p.id);
    pairs.sort_unstable_by_key(|e| (e.0, e.1));
    assert_eq!(
        pairs
            .iter()
            .map(|e| (e.0, e.1, e.2.springs.u_t))
            .collect::<Vec<_>>(),
        vec![(0, 3, 1.0), (1, 2, 2.0)]
    );
}

/// The storage index of the particle with id `id`.
fn at(p: &Particles, id: Id) -> usize {
    p.id.iter().position(|&i| i == id).expect("present")
}

#[test]
fn a_lonely_particle_may_move_half_its_clearance() {
    // A particle 0.5 m from a small cluster falls towards it in 1 mm steps.
    let radius = vec![0.01; 4];
    let x = vec![
        DVec3::new(0.0, 0.0, 0.5),
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(0.02, 0.0, 0.0),
        DVec3::new(-0.02, 0.0, 0.0),
    ];
    let skin = 0.005;
    let mut nb = Neighbours::new(skin);
    let mut p = particles(&x, &radius);
    nb.rebuild(&mut p, &[], &FaceGrid::default());
    assert_eq!(nb.lonely.len(), 1, "{:?}", nb.lonely);
    let mut rebuilds = 0;
    while p.x[at(&p, 0)].z > 0.015 {
        let k = at(&p, 0);
        p.x[k].z -= 0.001;
        if nb.stale(&p.x, &p.radius, &[], 0.0) {
            nb.rebuild(&mut p, &[], &FaceGrid::default());
            rebuilds += 1;
        }
        // Whatever touches is listed.
        let (a, b) = (at(&p, 0), at(&p, 1));
        if p.x[a].distance(p.x[b]) < 0.02 {
            assert!(
                listed(&nb, &p).contains(&(0, 1)),
                "contact missed at z = {}",
                p.x[a].z
            );
        }
    }
    // Skin / 2 alone would rebuild every 3 steps (160 times).
    assert!(rebuilds < 20, "{rebuilds} rebuilds");
    // An ordinary particle still triggers a rebuild after skin / 2.
    let mut nb = Neighbours::new(skin);
    nb.rebuild(&mut p, &[], &FaceGrid::default());
    let k = at(&p, 2);
    p.x[k].x += 0.6 * skin;
    assert!(nb.stale(&p.x, &p.radius, &[], 0.0));
}

#[test]
fn lonely_clearances_are_skipped_while_listed_grains_set_the_pace() {
    let radius = vec![0.01; 3];
    let x = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(0.0199, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 0.5),
    ];
    let skin = 0.005;
    let mut nb = Neighbours::new(skin);
    let mut p = particles(&x, &radius);
    nb.rebuild(&mut p, &[], &FaceGrid::default());
    assert_eq!(nb.lonely.len(), 1, "the grain far from the pair");
    // The touching pair moves on together past skin / 2: a rebuild no allowance puts off.
    for id in [0, 1] {
        let k = at(&p, id);
        p.x[k].y += 0.6 * skin;
    }
    assert!(nb.stale(&p.x, &p.radius, &[], 0.0));
    nb.rebuild(&mut p, &[], &FaceGrid::default());
    assert!(
        nb.lonely.is_empty(),
        "no clearances while listed grains set the pace"
    );
    // The lone grain alone moves past skin / 2: an allowance would have put that off.
    let k = at(&p, 2);
    p.x[k].z -= 0.6 * skin;
    assert!(nb.stale(&p.x, &p.radius, &[], 0.0));
    nb.rebuild(&mut p, &[], &FaceGrid::default());
    assert_eq!(nb.lonely.len(), 1, "found again");
    // And then it does: the grain moves on within its allowance, no rebuild.
    let k = at(&p, 2);
    p.x[k].z -= 0.6 * skin;
    assert!(!nb.stale(&p.x, &p.radius, &[], 0.0));
}

#[test]
fn two_lonely_particles_meeting_head_on_are_listed_before_they_touch() {
    let radius = vec![0.01; 2];
    let x = vec![DVec3::new(-0.5, 0.0, 0.0), DVec3::new(0.5, 0.0, 0.0)];
    let mut nb = Neighbours::new(0.005);
    let mut p = particles(&x, &radius);
    nb.rebuild(&mut p, &[], &FaceGrid::default());
    assert_eq!(nb.lonely.len(), 2);
    let mut rebuilds = 0;
    for _ in 0..600 {
        let (a, b) = (at(&p, 0), at(&p, 1));
        p.x[a].x += 0.001;
        p.x[b].x -= 0.0013;
        if nb.stale(&p.x, &p.radius, &[], 0.0) {
            nb.rebuild(&mut p, &[], &FaceGrid::default());
            rebuilds += 1;
        }
        let (a, b) = (at(&p, 0), at(&p, 1));
        if p.x[a].distance(p.x[b]) < 0.02 {
            assert_eq!(listed(&nb, &p), vec![(0, 1)], "contact missed at {:?}", p.x);
        }
    }
    let (a, b) = (at(&p, 0), at(&p, 1));
    assert!(
        p.x[a].x > p.x[b].x,
        "they passed through each other's place"
    );
    assert!(rebuilds < 150, "{rebuilds} rebuilds");
}

/// The image a wrapped pair is seen with is the one `image_shifts` finds, and the same
/// whichever particle is the one listed: its shift depends on the two points alone.
#[test]
fn the_image_towards_a_point_is_the_nearest_one_found() {
    let sheared = Periodic {
        min: DVec3::splat(-0.05),
        length: DVec3::new(0.1, 0.08, 0.1),
        axes: [true, true, true],
        shear: Some(Shear {
            velocity: 0.3,
            axis: 0,
            gradient: 2,
            offset: 0.1234,
        }),
    };
    let plain = Periodic {
        shear: None,
        ..sheared
    };
    let mut shifts = Vec::new();
    for periodic in [plain, sheared] {
        let mut checked = 0;
        for k in 0..4000u64 {
            let h = |m: u64| {
                let z = (k * 8 + m).wrapping_mul(0x9E37_79B9_7F4A_7C15);
                ((z ^ (z >> 29)).wrapping_mul(0xBF58_476D_1CE4_E5B9) >> 40) as f64
                    / (1u64 << 24) as f64
            };
            let x = periodic.min + DVec3::new(h(1), h(2), h(3)) * periodic.length;
            let to = periodic.min + DVec3::new(h(4), h(5), h(6)) * periodic.length;
            let reach = 0.02;
            periodic.image_shifts(x, reach, &mut shifts);
            for &(s, n) in &shifts {
                if (x + s).distance(to) < reach {
                    let (e, m) = periodic.image_towards(x, to);
                    assert!((e - s).length() < 1e-12 && m == n, "{x} {to}: {e} {s}");
                    checked += 1;
                }
            }
        }
        assert!(checked > 20, "{checked} pairs across the sides");
    }
}
