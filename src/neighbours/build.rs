//! Building the lists: a rebuild (the particles re-sorted into cell order, their springs
//! carried), without removed particles, from a history by id (a split run), and restored from
//! a checkpoint.

use rayon::prelude::*;

use super::*;

impl Neighbours {
    /// Rebuilds both lists for `particles`, re-sorting them into spatial order first.
    ///
    /// Particles are stored in the order of their cells (cell key, then id), so that
    /// neighbours in space are neighbours in memory; the springs of touching pairs are
    /// carried to their slots in the new lists (keyed by the particles' new storage
    /// indices, so that carrying them runs in spatial order too), and the lists are built
    /// from the positions (see `Neighbours::build`).
    pub fn rebuild(&mut self, particles: &mut Particles, faces: &[Face], face_grid: &FaceGrid) {
        self.rebuild_without(particles, &[], faces, face_grid);
    }

    /// Rebuilds the lists as [`Neighbours::rebuild`] does, removing first the particles
    /// (storage indices, ascending) in `gone` and the history of their contacts.
    pub fn rebuild_without(
        &mut self,
        particles: &mut Particles,
        gone: &[u32],
        faces: &[Face],
        face_grid: &FaceGrid,
    ) {
        if let Some(periodic) = self.periodic {
            // Between rebuilds particles move freely across periodic sides; here they are
            // put back into the box.
            particles
                .x
                .par_iter_mut()
                .zip(particles.v.par_iter_mut())
                .with_min_len(4 * MIN_PARALLEL_LEN)
                .for_each(|(x, v)| (*x, *v) = periodic.wrap_state(*x, *v));
        }
        let layout = Layout::of(&particles.radius, self.skin);
        let keys = layout.keys(&particles.x, &particles.id);
        let order: Option<Vec<u32>> = (!gone.is_empty() || !keys.is_sorted()).then(|| {
            let mut gone = gone.iter().peekable();
            let mut order: Vec<u32> = (0..particles.len() as u32)
                .filter(|&i| gone.next_if_eq(&&i).is_none())
                .collect();
            order.par_sort_unstable_by_key(|&i| keys[i as usize]);
            order
        });
        drop(keys);
        let n = order.as_ref().map_or(particles.len(), Vec::len);
        // Where each particle goes (NONE: removed), and the springs by the new places.
        let mut new = vec![NONE; self.pairs.owners()];
        match &order {
            Some(order) => {
                for (k, &old) in order.iter().enumerate() {
                    if (old as usize) < new.len() {
                        new[old as usize] = k as u32;
                    }
                }
            }
            None => new.iter_mut().enumerate().for_each(|(k, v)| *v = k as u32),
        }
        // The anchors go before the history is made, the old lists after.
        self.x_at_build = Vec::new();
        let kept = |a: u32| (a != NONE).then_some(a);
        let history = Histories {
            pairs: ContactList::history_of(&[&self.pairs, &self.wrapped], n, |i, j| {
                let (a, b) = (kept(new[i])?, kept(new[j as usize])?);
                Some((a.min(b), a.max(b)))
            }),
            faces: self.faces.history(n, |i, f| kept(new[i]).map(|a| (a, f))),
        };
        drop(new);
        // The old lists go before the new ones are made.
        self.pairs = ContactList::default();
        self.faces = ContactList::default();
        self.wrapped = ContactList::default();
        if let Some(order) = order {
            particles.permute(&order);
        }
        self.build(&particles.x, particles, faces, face_grid, layout, &history);
        drop(history);
        self.find_lonely(&particles.x, &particles.radius, faces);
        self.x_at_build = particles.x.clone();
        self.rebuilds += 1;
    }

    /// Rebuilds the lists for `particles` (re-sorted into spatial order first) where they
    /// are, or at the positions `at` (one per particle: the anchors of an earlier rebuild,
    /// which become the anchors again), with the springs of `pairs` and `faces`,
    /// entries by id ((lower id, higher id) and (id, face); those naming a particle that
    /// `particles` lacks are left out). For a process of a split run (`parallel/decomposition.rs`), which
    /// gathers its history from other processes: it finds no lonely particles, whose
    /// clearances would need the particles it does not hold. Returns the permutation
    /// applied (`Particles::permute`).
    pub fn rebuild_from(
        &mut self,
        particles: &mut Particles,
        at: Option<Vec<DVec3>>,
        pairs: &[Entry],
        faces_history: &[Entry],
        faces: &[Face],
        face_grid: &FaceGrid,
    ) -> Vec<u32> {
        let layout = Layout::of(&particles.radius, self.skin);
        let keys = layout.keys(at.as_deref().unwrap_or(&particles.x), &particles.id);
        let mut order: Vec<u32> = (0..particles.len() as u32).collect();
        order.par_sort_unstable_by_key(|&i| keys[i as usize]);
        drop(keys);
        self.pairs = ContactList::default();
        self.faces = ContactList::default();
        self.wrapped = ContactList::default();
        particles.permute(&order);
        let at = at.map(|at| {
            order
                .iter()
                .map(|&o| at[o as usize])
                .collect::<Vec<DVec3>>()
        });
        let index = IdIndex::of(particles);
        let history = Histories {
            pairs: History::of_present(&index, particles.len(), pairs, true),
            faces: History::of_present(&index, particles.len(), faces_history, false),
        };
        drop(index);
        let x = at.unwrap_or_else(|| particles.x.clone());
        self.build(&x, particles, faces, face_grid, layout, &history);
        self.lonely = Vec::new();
        self.x_at_build = x;
        self.rebuilds += 1;
        order
    }

    /// Forgets the anchors of the last rebuild, so that the lists count as stale at the
    /// next step (as those of a simulation never stepped).
    pub fn forget_anchors(&mut self) {
        self.x_at_build = Vec::new();
        self.lonely = Vec::new();
    }

    /// Builds again the lists of a checkpoint: the particles in their saved storage order,
    /// the positions of the last rebuild (`anchors`) and its lonely particles, and the
    /// contact histories (keyed by storage index, [`History::in_storage`]). The lists are
    /// those the run had, slot for slot.
    pub fn restore(
        &mut self,
        particles: &Particles,
        anchors: Vec<DVec3>,
        lonely: Vec<(u32, f64)>,
        faces: &[Face],
        face_grid: &FaceGrid,
        history: &Histories,
    ) {
        let layout = Layout::of(&particles.radius, self.skin);
        self.build(&anchors, particles, faces, face_grid, layout, history);
        self.x_at_build = anchors;
        self.lonely = lonely;
        self.rebuilds += 1;
    }

    /// Both lists for particles at `x` (radii and ids from `particles`, in storage order),
    /// with the springs of `history`, and the slabs.
    ///
    /// Each pair is listed once, under its lower storage index, with its partners in
    /// ascending order. Cells sized for every radius (`uniform`): each particle looks for
    /// its partners of higher index in the 27 cells around its own. Otherwise each pair is
    /// found by its larger particle (ties: the lower index), which searches as many cells
    /// as its own reach needs, and the pairs are sorted afterwards.
    fn build(
        &mut self,
        x: &[DVec3],
        particles: &Particles,
        faces: &[Face],
        face_grid: &FaceGrid,
        layout: Layout,
        history: &Histories,
    ) {
        let radius = &particles.radius;
        let n = x.len();
        let skin = self.skin;
        let grid = CellGrid::of_points(x, layout.h);
        let body = &particles.body;
        let clumps = !particles.bodies.is_empty();
        // The spheres of one rigid body are no pair.
        let close = |i: u32, j: u32| {
            let reach = radius[i as usize] + radius[j as usize] + skin;
            (x[i as usize] - x[j as usize]).length_squared() < reach * reach
                && !(clumps && one_body(body, i, j))
        };
        let in_cell_order = layout.uniform && {
            let inv_h = 1.0 / layout.h;
            x.windows(2)
                .all(|w| key(cell_of(w[0], inv_h)) <= key(cell_of(w[1], inv_h)))
        };
        let (start, partner) = if in_cell_order {
            pairs_forward(&grid, n, &close)
        } else if layout.uniform {
            pairs_around(&grid, x, &close)
        } else {
            pairs_by_larger(&grid, x, radius, (skin, layout), &close)
        };
        let slabs = slabs_of(&start, &partner);
        self.pairs = ContactList::with_states(start, partner, slabs, &history.pairs, self.state);
        if let Some(periodic) = self.periodic {
            self.build_wrapped(periodic, x, particles, (&grid, layout), history);
        }
        drop(grid);
        let (start, partner) = face_pairs(x, radius, skin, faces, face_grid);
        let blocks = blocks_of(&start, FACE_BLOCK);
        self.faces = ContactList::with_states(start, partner, blocks, &history.faces, self.state);
    }

    /// The pairs across periodic sides: each image x_j + s of a particle near a side
    /// against the particles i < j near it; one shift per pair, since a period is longer
    /// than twice any reach (checked by the scenario).
    fn build_wrapped(
        &mut self,
        periodic: Periodic,
        x: &[DVec3],
        particles: &Particles,
        (grid, layout): (&CellGrid, Layout),
        history: &Histories,
    ) {
        let (radius, n, skin) = (&particles.radius, x.len(), self.skin);
        let max_radius = radius.iter().copied().fold(0.0, f64::max);
        let reach_max = 2.0 * max_radius + skin;
        let m = (reach_max / layout.h).ceil().max(1.0) as i32;
        type Found = (u32, u32, DVec3, i8);
        let mut found: Vec<Found> = (0..n as u32)
            .into_par_iter()
            .with_min_len(4 * MIN_PARALLEL_LEN)
            .fold(
                || (Vec::new(), Vec::new()),
                |(mut out, mut shifts): (Vec<Found>, Vec<(DVec3, i8)>), j| {
                    periodic.image_shifts(x[j as usize], reach_max, &mut shifts);
                    for &(s, crossing) in &shifts {
                        let image = x[j as usize] + s;
                        let c = cell_of(image, 1.0 / layout.h);
                        for dz in -m..=m {
                            for dy in -m..=m {
                                for dx in -m..=m {
                                    for &i in grid.in_cell(c + IVec3::new(dx, dy, dz)) {
                                        let reach = radius[i as usize] + radius[j as usize] + skin;
                                        if i < j
                                            && (x[i as usize] - image).length_squared()
                                                < reach * reach
                                            && !one_body(&particles.body, i, j)
                                        {
                                            out.push((i, j, s, crossing));
                                        }
                                    }
                                }
                            }
                        }
                    }
                    (out, shifts)
                },
            )
            .map(|(out, _)| out)
            .flatten()
            .collect();
        found.sort_unstable_by_key(|&(i, j, _, _)| (i, j));
        // Each pair as the law sees it: the particle of the higher id at its image
        // nearest the other.
        let ids = &particles.id;
        for f in &mut found {
            let (lo, hi) = if ids[f.0 as usize] < ids[f.1 as usize] {
                (f.0, f.1)
            } else {
                (f.1, f.0)
            };
            (f.2, f.3) = periodic.image_towards(x[hi as usize], x[lo as usize]);
        }
        let (start, partner) = compress(n, found.iter().map(|&(i, j, _, _)| (i, j)));
        self.shift = found.iter().map(|f| f.2).collect();
        self.crossings = found.iter().map(|f| f.3).collect();
        self.offset_at_build = periodic.shear.map_or(0.0, |sh| sh.offset);
        let blocks = blocks_of(&start, FACE_BLOCK);
        self.wrapped = ContactList::with_states(start, partner, blocks, &history.pairs, self.state);
    }
}

/// Whether particles `i` and `j` are spheres of one rigid body.
#[inline(always)]
fn one_body(body: &[Option<crate::model::bodies::BodyId>], i: u32, j: u32) -> bool {
    let a = body[i as usize];
    a.is_some() && a == body[j as usize]
}

/// The pair list of particles stored in cell order: per cell, each particle's partners are
/// the later ones of its cell and those of the 13 cells after it in key order, whose
/// indices all come after its own; so each run comes out sorted.
fn pairs_forward(
    grid: &CellGrid,
    n: usize,
    close: &(impl Fn(u32, u32) -> bool + Sync),
) -> (Vec<u32>, Vec<u32>) {
    let cells = grid.occupied();
    let runs: Vec<Vec<u32>> = cells
        .par_iter()
        .with_min_len(MIN_PARALLEL_LEN / 4)
        .fold(Vec::new, |mut out: Vec<u32>, &(c, a, b)| {
            let forward = FORWARD.map(|d| grid.range(c + d));
            for i in a..b {
                let at = out.len();
                out.push(0); // the run's length, filled below
                for j in (i + 1..b).chain(forward.iter().flat_map(|r| r.clone())) {
                    if close(i, j) {
                        out.push(j);
                    }
                }
                out[at] = (out.len() - at - 1) as u32;
            }
            out
        })
        .collect();
    runs_to_csr(n, runs)
}

/// The pair list of particles in any storage order (a restored checkpoint may hold a
/// re-anchored particle out of its cell): per owner, its partners of higher index from the
/// 27 cells around its cell, sorted.
fn pairs_around(
    grid: &CellGrid,
    x: &[DVec3],
    close: &(impl Fn(u32, u32) -> bool + Sync),
) -> (Vec<u32>, Vec<u32>) {
    let n = x.len();
    let runs: Vec<Vec<u32>> = (0..n as u32)
        .into_par_iter()
        .with_min_len(4 * MIN_PARALLEL_LEN)
        .fold(Vec::new, |mut out: Vec<u32>, i| {
            let at = out.len();
            out.push(0); // the run's length, filled below
            grid.for_each_near(x[i as usize], |j| {
                if j > i && close(i, j) {
                    out.push(j);
                }
            });
            out[at + 1..].sort_unstable();
            out[at] = (out.len() - at - 1) as u32;
            out
        })
        .collect();
    runs_to_csr(n, runs)
}

/// The pair list with cells smaller than the largest reach: each pair found by its larger
/// particle (ties: the lower index), which searches as many cells as its own reach needs,
/// and the pairs sorted afterwards.
fn pairs_by_larger(
    grid: &CellGrid,
    x: &[DVec3],
    radius: &[f64],
    (skin, layout): (f64, Layout),
    close: &(impl Fn(u32, u32) -> bool + Sync),
) -> (Vec<u32>, Vec<u32>) {
    let n = x.len();
    let finds = |i: u32, j: u32| {
        let (ri, rj) = (radius[i as usize], radius[j as usize]);
        rj < ri || (rj == ri && j > i)
    };
    let cells_needed = |i: u32| {
        ((2.0 * radius[i as usize] + skin) / layout.h)
            .ceil()
            .max(1.0) as i32
    };
    let mut pairs: Vec<u64> = (0..n as u32)
        .into_par_iter()
        .with_min_len(4 * MIN_PARALLEL_LEN)
        .fold(Vec::new, |mut out: Vec<u64>, i| {
            let c = cell_of(x[i as usize], 1.0 / layout.h);
            let m = cells_needed(i);
            for dz in -m..=m {
                for dy in -m..=m {
                    for dx in -m..=m {
                        for &j in grid.in_cell(c + IVec3::new(dx, dy, dz)) {
                            if finds(i, j) && close(i, j) {
                                out.push(((i.min(j) as u64) << 32) | i.max(j) as u64);
                            }
                        }
                    }
                }
            }
            out
        })
        .flatten()
        .collect();
    pairs.par_sort_unstable();
    compress(n, pairs.iter().map(|&k| ((k >> 32) as u32, k as u32)))
}

/// The particle-face list: each particle's faces within reach, from the face grid. The
/// items of a grid cell come in ascending order, so each particle's run of faces is sorted.
fn face_pairs(
    x: &[DVec3],
    radius: &[f64],
    skin: f64,
    faces: &[Face],
    face_grid: &FaceGrid,
) -> (Vec<u32>, Vec<u32>) {
    let n = x.len();
    let face_pairs: Vec<(u32, u32)> = (0..n)
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN / 8)
        .flat_map_iter(|i| {
            let (xi, ri) = (x[i], radius[i]);
            let pair = move |&f: &u32| {
                let face = &faces[f as usize];
                let reach = ri + face.radius + skin;
                let near = face.separation(xi).length_squared() < reach * reach;
                near.then_some((i as u32, f))
            };
            // (Borrowed from the grid, unless faces of several levels were merged.)
            match face_grid.at(xi) {
                std::borrow::Cow::Borrowed(listed) => {
                    rayon::iter::Either::Left(listed.iter().filter_map(pair))
                }
                std::borrow::Cow::Owned(listed) => rayon::iter::Either::Right(
                    listed
                        .iter()
                        .filter_map(pair)
                        .collect::<Vec<_>>()
                        .into_iter(),
                ),
            }
        })
        .collect();
    compress(n, face_pairs.iter().copied())
}
