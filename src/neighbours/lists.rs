//! The contact lists in compressed form, cut into blocks, each with a store of the states
//! of its touching contacts.

use rayon::prelude::*;

use super::*;

/// A slot without a contact.
pub const NONE: u32 = u32::MAX;

/// The states of the touching contacts of one block of a list (`ContactState`: the
/// friction springs, and what other parts of the law keep), and its free entries. A
/// contact stage runs a block in one task, which opens and closes entries in the block's
/// own store.
#[derive(Clone, Debug, Default)]
pub struct Store {
    pub state: States,
    pub(crate) free: Vec<u32>,
}

impl Store {
    /// A new entry, in the state of a first touch (zero springs; open, in a run whose
    /// contacts outlast touch).
    #[inline]
    pub fn open(&mut self) -> u32 {
        let first = ContactState {
            beyond: self.state.active.beyond,
            ..ContactState::default()
        };
        match self.free.pop() {
            Some(k) => {
                self.state.set(k as usize, first);
                k
            }
            None => {
                if self.state.full() {
                    // A little room at a time: contacts come and go, the count changes slowly.
                    self.state.reserve_exact(self.state.len() / 8 + 8);
                }
                self.state.push(first);
                (self.state.len() - 1) as u32
            }
        }
    }

    /// Frees entry `k` (its state is forgotten).
    #[inline]
    pub fn close(&mut self, k: u32) {
        self.free.push(k);
    }

    /// Entries in use.
    pub fn len(&self) -> usize {
        self.state.len() - self.free.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A compressed list: for each owner `i` (a storage index), a run of partners; each slot
/// whose pair touches holds its contact, an entry of the store of the slot's block (the
/// blocks are runs of owners). States are kept only for touching pairs, those of a
/// particle pair as seen from the particle of the lower id (body i of the contact law),
/// whatever the storage order.
#[derive(Clone, Debug, Default)]
pub struct ContactList {
    /// Run of owner `i` is `start[i]..start[i+1]`.
    pub start: Vec<u32>,
    /// Partner of each slot: a particle `j > i` (storage index), or a face index.
    pub partner: Vec<u32>,
    /// The contact of each slot: its entry in its block's store, or [`NONE`]. A pair that
    /// parts closes its contact and is not looked at again while it stays apart.
    pub contact: Vec<u32>,
    /// Owner bounds of the blocks: block `p` is owners `blocks[p]..blocks[p+1]`.
    pub blocks: Vec<u32>,
    /// One store per block.
    pub stores: Vec<Store>,
}

impl ContactList {
    pub fn slots(&self) -> usize {
        self.partner.len()
    }

    /// The slots of owner `i`.
    #[inline]
    pub fn run(&self, i: usize) -> std::ops::Range<usize> {
        self.start[i] as usize..self.start[i + 1] as usize
    }

    /// Number of owners.
    pub fn owners(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    /// Number of contacts (touching pairs).
    pub fn contacts(&self) -> usize {
        self.stores.iter().map(Store::len).sum()
    }

    /// Calls `f` with owner, slot and state of every slot whose contact has a state to
    /// keep (not that of a first touch), in slot order.
    pub(crate) fn for_each_live(&self, mut f: impl FnMut(usize, usize, ContactState)) {
        for p in 0..self.blocks.len().saturating_sub(1) {
            let store = &self.stores[p];
            for i in self.blocks[p] as usize..self.blocks[p + 1] as usize {
                for k in self.run(i) {
                    let c = self.contact[k];
                    if c != NONE {
                        let s = store.state.get(c as usize);
                        if s != ContactState::default() {
                            f(i, k, s);
                        }
                    }
                }
            }
        }
    }

    /// The contact history of the list: for each slot with a state to keep, the key that
    /// `key(owner, partner)` gives it (first keys below `keys`; none: the contact is
    /// dropped) and its state.
    pub(crate) fn history(
        &self,
        keys: usize,
        key: impl Fn(usize, u32) -> Option<(u32, u32)> + Sync,
    ) -> History {
        Self::history_of(&[self], keys, key)
    }

    /// The contact history of several lists of the same kind (particle pairs, within the
    /// box and across periodic sides), as [`ContactList::history`].
    pub(crate) fn history_of(
        lists: &[&ContactList],
        keys: usize,
        key: impl Fn(usize, u32) -> Option<(u32, u32)> + Sync,
    ) -> History {
        History::from_visits(keys, |f| {
            for list in lists {
                list.for_each_live(|i, k, s| {
                    if let Some((a, other)) = key(i, list.partner[k]) {
                        f(a, other, s);
                    }
                });
            }
        })
    }

    /// A list from runs in compressed form cut into blocks at `blocks` (owner bounds), each
    /// slot with the state `history` holds for (owner, partner), found by merging each
    /// run with the owner's history run (both ascending).
    pub(crate) fn with_states(
        start: Vec<u32>,
        partner: Vec<u32>,
        blocks: Vec<u32>,
        history: &History,
        active: ActiveState,
    ) -> ContactList {
        let mut contact = vec![NONE; partner.len()];
        let slots: Vec<usize> = blocks.iter().map(|&o| start[o as usize] as usize).collect();
        let stores: Vec<Store> = (0..blocks.len().saturating_sub(1))
            .zip(cut(&mut contact, &slots))
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(|(p, contact)| {
                let first = slots[p];
                let mut store = Store {
                    state: States::new(active),
                    ..Store::default()
                };
                for i in blocks[p] as usize..blocks[p + 1] as usize {
                    let run = start[i] as usize..start[i + 1] as usize;
                    let (other, carried) = history.run(i);
                    let mut h = 0;
                    for k in run {
                        let j = partner[k];
                        while h < other.len() && other[h] < j {
                            h += 1;
                        }
                        if other.get(h) == Some(&j) && carried[h] != ContactState::default() {
                            contact[k - first] = store.state.len() as u32;
                            store.state.push(carried[h]);
                        }
                    }
                }
                store.state.shrink_to_fit();
                store
            })
            .collect();
        ContactList {
            start,
            partner,
            contact,
            blocks,
            stores,
        }
    }
}

/// Owner bounds of blocks of at least `size` slots of a list with run starts `start` (the
/// last block may be shorter).
pub(crate) fn blocks_of(start: &[u32], size: usize) -> Vec<u32> {
    let mut bounds = vec![0u32];
    let owners = start.len().saturating_sub(1);
    for i in 1..owners {
        if (start[i] - start[bounds[bounds.len() - 1] as usize]) as usize >= size {
            bounds.push(i as u32);
        }
    }
    if owners > 0 {
        bounds.push(owners as u32);
    }
    bounds
}

/// Slots per block of the particle-face list (a task of the mesh stage).
pub const FACE_BLOCK: usize = 256;

/// `slice` cut at `bounds` (ascending, from 0 to its length).
pub(crate) fn cut<'a, T>(mut slice: &'a mut [T], bounds: &[usize]) -> Vec<&'a mut [T]> {
    bounds
        .windows(2)
        .map(|w| {
            let (block, rest) = std::mem::take(&mut slice).split_at_mut(w[1] - w[0]);
            slice = rest;
            block
        })
        .collect()
}

/// Runs collected as `[length, partners...]` blocks, `n` of them in owner order, in
/// compressed form.
pub(crate) fn runs_to_csr(n: usize, runs: Vec<Vec<u32>>) -> (Vec<u32>, Vec<u32>) {
    let total = runs.iter().map(Vec::len).sum::<usize>() - n;
    let mut start = Vec::with_capacity(n + 1);
    let mut partner = Vec::with_capacity(total);
    start.push(0u32);
    for block in runs {
        let mut k = 0;
        while k < block.len() {
            let len = block[k] as usize;
            partner.extend_from_slice(&block[k + 1..k + 1 + len]);
            start.push(partner.len() as u32);
            k += 1 + len;
        }
    }
    debug_assert_eq!(start.len(), n + 1);
    (start, partner)
}

/// Compressed form of `(owner, partner)` pairs: a counting sort by owner that keeps the
/// order of each owner's partners.
pub(crate) fn compress(
    n: usize,
    pairs: impl Iterator<Item = (u32, u32)> + Clone,
) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; n + 1];
    for (i, _) in pairs.clone() {
        start[i as usize + 1] += 1;
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let mut fill = start.clone();
    let mut partner = vec![0u32; start[n] as usize];
    for (i, j) in pairs {
        partner[fill[i as usize] as usize] = j;
        fill[i as usize] += 1;
    }
    (start, partner)
}
