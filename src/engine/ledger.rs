//! The energy ledger's stage (`[output] energy_ledger`, `model/ledger.rs`): once the
//! particles have moved, the work of each contact's modes at the mean velocities of the
//! step, of gravity and of the fluid's drag; the kinetic energy spawned and removed; and,
//! at a frame, the energy the contacts hold.

use super::*;
use crate::model::ledger::{Balance, CHUNK, Entry, Kept, Ledger, Mean, WALL};
use wide::f64x8;

/// The ledger of a run and the stage's scratch.
pub(crate) struct Books {
    ledger: Ledger,
    /// Each particle's velocities before this step moved it.
    before: Vec<(DVec3, DVec3)>,
    /// The contact stages' entries of the step (kept for their room).
    entries: Vec<Entry>,
}

impl Books {
    /// The books of a run whose contact forces are at most `scales.force` and radii at
    /// most `r_max`: a term is the work of a step, which no contact can make larger than
    /// its force over a radius; the sums hold 2^41 times that.
    pub(super) fn new(scales: &LoadScales, r_max: f64) -> Books {
        Books {
            ledger: Ledger::new(scales.force.largest() * r_max * 2f64.powi(30)),
            before: Vec::new(),
            entries: Vec::new(),
        }
    }

    /// The entries' buffer, empty, for the contact stages to fill.
    pub(super) fn take_entries(&mut self) -> Vec<Entry> {
        let mut e = std::mem::take(&mut self.entries);
        e.clear();
        e
    }

    /// What a checkpoint keeps of the ledger.
    pub(super) fn kept(&self) -> Kept {
        self.ledger.kept()
    }

    /// The ledger continued from a checkpoint's.
    pub(super) fn resume(&mut self, kept: &Kept) {
        self.ledger = self.ledger.with_kept(kept);
    }
}

impl Simulation {
    /// Before stage 5: the velocities the particles move from (with the ledger).
    pub(super) fn remember_velocities(&mut self) {
        if let Some(books) = &mut self.books {
            let p = &self.particles;
            books.before.clear();
            books
                .before
                .extend(p.v.iter().copied().zip(p.w.iter().copied()));
        }
    }

    /// The ledger's stage, after stages 5-5c: the step's work of the modes of the
    /// contacts `entries` (those of own particles, of a pair the lower id's) and of the
    /// walls; of gravity and drag on own particles. Whether every term was in range.
    pub(super) fn keep_books(&mut self, entries: Vec<Entry>) -> bool {
        let Some(mut books) = self.books.take() else {
            return true;
        };
        let fine = self.book_step(&mut books, &entries);
        books.entries = entries;
        self.books = Some(books);
        fine
    }

    /// [`Simulation::keep_books`] into `books`.
    fn book_step(&self, books: &mut Books, entries: &[Entry]) -> bool {
        let (p, model) = (&self.particles, &self.model);
        let (dt, g) = (
            self.scenario.simulation.timestep,
            self.scenario.kinetics.gravity,
        );
        let own = |k: usize| self.own(k);
        let Books { ledger, before, .. } = books;
        let ledger = &*ledger;
        let merge = |(mut a, fa): (Sum6, bool), (b, fb): (Sum6, bool)| {
            a.merge(&b);
            (a, fa & fb)
        };
        // Gravity's work and the drag's (at the velocities it was taken at, Eqs. 42-44); the
        // velocities before the step become the means of the step in their place.
        let work = |k: usize, motion: &mut (DVec3, DVec3)| {
            let (v, w) = *motion;
            let (v_mid, w_mid) = (0.5 * (v + p.v[k]), 0.5 * (w + p.w[k]));
            *motion = (v_mid, w_mid);
            let m = model.mass(p, k);
            let r = p.radius[k];
            let c = model.densities[p.material[k] as usize].drag / (r * r); // Eq. (3)
            let gravity = m * g.dot(v_mid) * dt;
            let inertia = 0.4 * m * r * r;
            let drag = -(m * c * v.dot(v_mid) + inertia * (10.0 / 3.0) * c * w.dot(w_mid)) * dt;
            f64x8::from([gravity, drag, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
        };
        let (particles, fine_p) = before
            .par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(c, chunk)| {
                let each = chunk
                    .iter_mut()
                    .enumerate()
                    .map(|(l, b)| (c * CHUNK + l, b));
                let terms = each.map(|(k, b)| (k, work(k, b))).filter(|&(k, _)| own(k));
                ledger.sum(terms.map(|t| t.1))
            })
            .reduce(|| (Sum6::default(), true), merge);
        let mean = |k: usize| {
            let (v, w) = before[k];
            Mean { v, w }
        };
        let (contacts, fine) = entries
            .par_chunks(CHUNK)
            .map(|chunk| {
                let own = chunk.iter().filter(|e| own(e.i as usize));
                ledger.sum(own.map(|e| {
                    let j = match e.j {
                        WALL => Mean::default(),
                        j => mean(j as usize),
                    };
                    e.work(mean(e.i as usize), j, dt)
                }))
            })
            .reduce(|| (Sum6::default(), true), merge);
        // Every process holds the sums of all (as the walls' heat): a checkpoint's parts agree.
        let [contacts, particles] = self.over_processes([contacts, particles]);
        books.ledger.add_contacts(&contacts);
        books.ledger.add_particles(&particles);
        fine & fine_p
    }

    /// The kinetic energy of the own particles `ks` brought in (spawned) or taken out
    /// (removed), to the ledger.
    pub(super) fn book_kinetic(&mut self, ks: impl Iterator<Item = usize>, spawned: bool) {
        let Some(books) = &self.books else {
            return;
        };
        let p = &self.particles;
        let energy = |k: usize| {
            let m = self.model.mass(p, k);
            let r = p.radius[k];
            0.5 * m * (p.v[k].length_squared() + 0.4 * r * r * p.w[k].length_squared())
        };
        let terms: Vec<f64> = ks.filter(|&k| self.own(k)).map(energy).collect();
        let slot = if spawned { 2 } else { 3 };
        let mut sum = Sum6::default();
        for chunk in terms.chunks(CHUNK) {
            sum.merge(
                &books
                    .ledger
                    .sum(chunk.iter().map(|&e| {
                        let mut t = [0.0; 8];
                        t[slot] = e;
                        f64x8::from(t)
                    }))
                    .0,
            );
        }
        // Over all processes (collective: each spawns and removes in step with the others).
        let [sum] = self.over_processes([sum]);
        let books = self.books.as_mut().expect("kept");
        books.ledger.add_particles(&sum);
    }

    /// At the first step: the energy the ledger starts from.
    pub(super) fn open_books(&mut self) {
        if self
            .books
            .as_ref()
            .is_some_and(|b| b.ledger.start.is_none())
        {
            let (kinetic, stored) = (self.thermo_kinetic(), self.stored_energy());
            let books = self.books.as_mut().expect("kept");
            books.ledger.start = Some(kinetic + stored.iter().sum::<f64>());
            books.ledger.stored_start = stored;
        }
    }

    /// The kinetic energy of all grains (collective in a split run).
    fn thermo_kinetic(&self) -> f64 {
        let e = self.grain_energies();
        e.iter().map(|e| e.1 + e.2).sum()
    }

    /// The energy the contacts of own particles hold now, by mode (over all processes,
    /// collective in a split run; exact sums, so the same for any split).
    pub(super) fn stored_energy(&self) -> [f64; 5] {
        let Some(books) = &self.books else {
            return [0.0; 5];
        };
        let p = &self.particles;
        let mut terms = Vec::new();
        self.each_held_contact(|i, other, kin, coef, springs, _| {
            if self.own(i) {
                let body = (p.radius[i], self.mass_of(i));
                let e = self.model.law.stored(coef, body, other, kin, &springs);
                terms.push(f64x8::from([e[0], e[1], e[2], e[3], e[4], 0.0, 0.0, 0.0]));
            }
        });
        let mut sum = Sum6::default();
        for chunk in terms.chunks(CHUNK) {
            sum.merge(&books.ledger.sum(chunk.iter().copied()).0);
        }
        let [sum] = self.over_processes([sum]);
        let stored = books.ledger.value(&sum.words());
        std::array::from_fn(|m| stored[m])
    }

    /// `sums` added over all processes (collective in a split run, one message).
    fn over_processes<const N: usize>(&self, sums: [Sum6; N]) -> [Sum6; N] {
        let Some(d) = &self.share else {
            return sums;
        };
        let words: Vec<i64> = sums.iter().flat_map(|s| s.words()).collect();
        let all = d.comm.sum_i64(&words);
        std::array::from_fn(|k| {
            let mut sum = Sum6::from_words(all[12 * k..12 * k + 12].try_into().expect("12"));
            sum.carry();
            sum
        })
    }

    /// The ledger's columns of `log.csv` now (collective in a split run), with the
    /// kinetic energy `kinetic`; `None` without the ledger.
    pub(super) fn balance(&self, kinetic: f64) -> Option<Balance> {
        let books = self.books.as_ref()?;
        let stored = self.stored_energy();
        // Each process holds the sums of all.
        let mut ledger = books.ledger;
        if ledger.start.is_none() {
            ledger.start = Some(kinetic + stored.iter().sum::<f64>());
            ledger.stored_start = stored;
        }
        Some(Balance::of(&ledger, kinetic, stored))
    }
}
