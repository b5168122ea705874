//! Contact history: the states of touching contacts keyed by particle (id or storage
//! index) and partner, to carry them across rebuilds and into checkpoints.

use super::*;

/// A contact history: the states of particle pairs keyed by (lower, higher) and of
/// particle-face contacts by (particle, face), where particles are named by id (in
/// checkpoints) or by their storage index after a rebuild's re-sort (to carry the states
/// into the new lists). Compressed by the first key, each run ordered by the second.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct History {
    /// The entries of `a` are `start[a]..start[a+1]`, ordered by the other key.
    pub(crate) start: Vec<u32>,
    pub(crate) other: Vec<u32>,
    pub(crate) state: Vec<ContactState>,
}

impl History {
    /// The history of `(a, other, state)` entries, `a` below `keys`: a counting sort by
    /// `a`, then each run by `other`. `visit` hands every entry to its argument, the same
    /// entries in the same order each time it is called (twice: to count, then to place).
    pub(crate) fn from_visits(
        keys: usize,
        visit: impl Fn(&mut dyn FnMut(u32, u32, ContactState)),
    ) -> History {
        let mut start = vec![0u32; keys + 1];
        visit(&mut |a, _, _| start[a as usize + 1] += 1);
        for k in 0..keys {
            start[k + 1] += start[k];
        }
        let total = start[keys] as usize;
        let mut fill = start.clone();
        let mut other = vec![0u32; total];
        let mut state = vec![ContactState::default(); total];
        visit(&mut |a, o, s| {
            let k = fill[a as usize] as usize;
            (other[k], state[k]) = (o, s);
            fill[a as usize] += 1;
        });
        drop(fill);
        // Runs are short: insertion sort, in place.
        for a in 0..keys {
            let run = start[a] as usize..start[a + 1] as usize;
            for k in run.start + 1..run.end {
                let mut m = k;
                while m > run.start && other[m - 1] > other[m] {
                    other.swap(m - 1, m);
                    state.swap(m - 1, m);
                    m -= 1;
                }
            }
        }
        History {
            start,
            other,
            state,
        }
    }

    /// The history of saved `(id, other, state)` entries (a checkpoint's) for `particles`
    /// (in storage order): keyed by storage index, `pairs` or not. An entry naming a
    /// particle that `particles` lacks is an error.
    pub fn in_storage(
        particles: &Particles,
        entries: &[Entry],
        pairs: bool,
    ) -> Result<History, String> {
        Self::keyed(
            &IdIndex::of(particles),
            particles.len(),
            entries,
            pairs,
            false,
        )
    }

    /// [`History::in_storage`] for `n` particles, whose storage indices by id are `index`
    /// ([`IdIndex::of`]), of the entries that name only them; the others are left out.
    pub(crate) fn of_present(index: &IdIndex, n: usize, entries: &[Entry], pairs: bool) -> History {
        Self::keyed(index, n, entries, pairs, true).expect("entries of absent particles left out")
    }

    pub(crate) fn keyed(
        index: &IdIndex,
        n: usize,
        entries: &[Entry],
        pairs: bool,
        skip_absent: bool,
    ) -> Result<History, String> {
        let at = |id: Id| index.get(id);
        if !skip_absent {
            let named = |e: &Entry| [Some(e.0), pairs.then_some(e.1)];
            if let Some(id) = entries
                .iter()
                .flat_map(named)
                .flatten()
                .find(|&id| at(id).is_none())
            {
                return Err(format!(
                    "contact of particle id {id}, which the checkpoint lacks"
                ));
            }
        }
        Ok(History::from_visits(n, |f| {
            for &(a, b, s) in entries {
                let Some(a) = at(a) else { continue };
                if pairs {
                    let Some(b) = at(b) else { continue };
                    f(a.min(b), a.max(b), s);
                } else {
                    f(a, u32::try_from(b).expect("a face index"), s);
                }
            }
        }))
    }

    /// Every entry, ordered by the first key and then by the other.
    #[cfg(test)]
    pub(crate) fn entries(&self) -> Vec<(u32, u32, ContactState)> {
        (0..self.start.len().saturating_sub(1))
            .flat_map(|a| {
                (self.start[a] as usize..self.start[a + 1] as usize)
                    .map(move |k| (a as u32, self.other[k], self.state[k]))
            })
            .collect()
    }

    pub fn len(&self) -> usize {
        self.other.len()
    }

    pub fn is_empty(&self) -> bool {
        self.other.is_empty()
    }

    /// The entries of `a`: the other keys (ascending) and their states.
    #[inline]
    pub(crate) fn run(&self, a: usize) -> (&[u32], &[ContactState]) {
        if a + 1 >= self.start.len() {
            return (&[], &[]);
        }
        let run = self.start[a] as usize..self.start[a + 1] as usize;
        (&self.other[run.clone()], &self.state[run])
    }
}

/// A saved contact's state by id: of a particle pair (lower id, higher id, state), or of a
/// particle-face contact (id, face index, state).
pub type Entry = (Id, Id, ContactState);

/// Contact histories as lists of entries: particle pairs and particle-face contacts.
pub type Entries = (Vec<Entry>, Vec<Entry>);

/// The contact histories of both lists.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Histories {
    pub pairs: History,
    pub faces: History,
}

/// Where each particle of a set is stored, by id: a table over all ids when the set holds
/// most of them (a run in one process), a sorted list of its own otherwise (a process of a
/// split run holds a few of many ids, and its memory follows what it holds, not the total).
pub(crate) enum IdIndex {
    /// The storage index at each id ([`NONE`] for ids the set lacks).
    Table(Vec<u32>),
    /// (id, storage index), by id.
    Sorted(Vec<(Id, u32)>),
}

impl IdIndex {
    /// A table while it takes at most about twice the memory of the sorted list.
    fn table_pays(held: usize, ids: usize) -> bool {
        ids <= 2 * held + 4096
    }

    /// The index of the ids of `particles`.
    pub(crate) fn of(particles: &Particles) -> IdIndex {
        if Self::table_pays(particles.len(), particles.next_id as usize) {
            let mut index = vec![NONE; particles.next_id as usize];
            for (k, &id) in particles.id.iter().enumerate() {
                index[id as usize] = k as u32;
            }
            return IdIndex::Table(index);
        }
        let mut index: Vec<(Id, u32)> = (0..particles.len() as u32)
            .map(|k| (particles.id[k as usize], k))
            .collect();
        index.sort_unstable();
        IdIndex::Sorted(index)
    }

    /// Where the particle of id `id` is stored, if the set holds it.
    #[inline]
    pub(crate) fn get(&self, id: Id) -> Option<u32> {
        match self {
            IdIndex::Table(index) => usize::try_from(id)
                .ok()
                .and_then(|id| index.get(id))
                .copied()
                .filter(|&k| k != NONE),
            IdIndex::Sorted(index) => index
                .binary_search_by_key(&id, |e| e.0)
                .ok()
                .map(|at| index[at].1),
        }
    }
}
