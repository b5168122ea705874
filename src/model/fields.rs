//! The machinery of per-particle fields: from one table of fields (`particle_fields!`, whose
//! one use is in `model/particles.rs`) it makes the storage ([`Particles`], a vector per
//! field), the one-particle record ([`Particle`]), `insert`, `get` and `permute`, the
//! records of the split run's messages, the state sent to ghosts each step, the checkpoint
//! record, and, for the optional fields, their names, columns and bytes by name (which the
//! frames, checkpoints and Python find them by).
//!
//! Two kinds of rows:
//! - **core** fields, held for every particle of every run:
//!   `name: type, ghost: bool, checkpoint: Option<format>` (the checkpoint record holds the
//!   field from that format on, in the table's order; `None`: not in the record);
//! - **optional** fields, held only when a run asks for them ([`Particles::activate`]; e.g.
//!   a temperature when heat is conducted), so that a run without them stores, sends and
//!   writes no byte more: `name: type, ghost: bool, unit: "…"`. An active optional field is
//!   in the messages, in checkpoints (a section by name, format 8) and in frames (CSV
//!   columns and VTK arrays named after it), and Python reads and sets it by name.
//!
//! A field's type is a [`Value`] (its bytes) and, for optional fields, [`Components`] (its
//! numbers in a frame); its `Default` is the value of a particle that does not say. A row
//! may be `#[cfg(test)]` (a field only the tests have).
//!
//! [`Particles`]: crate::model::particles::Particles
//! [`Particle`]: crate::model::particles::Particle
//! [`Particles::activate`]: crate::model::particles::Particles::activate

use glam::DVec3;

pub use crate::model::value::Value;

/// The numbers of a value of an optional field, as a frame writes and reads them.
pub trait Components: Value {
    /// The suffixes of its columns after the field's name (`[""]`: one column named after
    /// the field).
    const SUFFIXES: &'static [&'static str];
    /// Appends its numbers.
    fn numbers(&self, out: &mut Vec<f64>);
    /// The value of `numbers` (as many as [`Self::SUFFIXES`]), if they make one.
    fn from_numbers(numbers: &[f64]) -> Option<Self>;
}

impl Components for f64 {
    const SUFFIXES: &'static [&'static str] = &[""];
    fn numbers(&self, out: &mut Vec<f64>) {
        out.push(*self);
    }
    fn from_numbers(numbers: &[f64]) -> Option<Self> {
        numbers[0].is_finite().then_some(numbers[0])
    }
}

impl Components for u32 {
    const SUFFIXES: &'static [&'static str] = &[""];
    fn numbers(&self, out: &mut Vec<f64>) {
        out.push(*self as f64);
    }
    fn from_numbers(numbers: &[f64]) -> Option<Self> {
        let n = numbers[0];
        (n >= 0.0 && n <= u32::MAX as f64 && n.fract() == 0.0).then_some(n as u32)
    }
}

impl Components for DVec3 {
    const SUFFIXES: &'static [&'static str] = &["_x", "_y", "_z"];
    fn numbers(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(&self.to_array());
    }
    fn from_numbers(numbers: &[f64]) -> Option<Self> {
        let v = DVec3::from_slice(numbers);
        v.is_finite().then_some(v)
    }
}

/// A whole number the engine keeps exactly (a heat content in its quantum): carried by
/// messages and checkpoints, in no frame (no columns).
impl Components for i128 {
    const SUFFIXES: &'static [&'static str] = &[];
    fn numbers(&self, _: &mut Vec<f64>) {}
    fn from_numbers(_: &[f64]) -> Option<Self> {
        None
    }
}

/// What the frames, checkpoints and Python know of an optional field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Optional {
    pub name: &'static str,
    /// Its unit, in the dimensions of the paper (`[L]`, `[T]`, ...) or a name (`K`).
    pub unit: &'static str,
    /// The suffixes of its columns ([`Components::SUFFIXES`]).
    pub suffixes: &'static [&'static str],
    /// The bytes of one value.
    pub size: usize,
    /// Whether ghosts receive its value each step.
    pub ghost: bool,
}

impl Optional {
    /// The names of its columns in a frame.
    pub fn columns(&self) -> Vec<String> {
        self.suffixes
            .iter()
            .map(|s| format!("{}{s}", self.name))
            .collect()
    }
}

/// A set of flags, one per optional member of a table (`held` of `$described`, each
/// described in `$table`): which members are held, listed and set by name.
macro_rules! held_set {
    (
        $(#[doc = $doc:literal])*
        $set:ident,
        $described:ty,
        $table:ident,
        [$($(#[cfg($cfg:meta)])? $oname:ident = $oalias:expr),*]
    ) => {
        $(#[doc = $doc])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        pub struct $set {
            $($(#[cfg($cfg)])? pub $oname: bool,)*
        }

        impl $set {
            /// The members held, as `$table` describes them.
            pub fn fields(&self) -> Vec<&'static $described> {
                #[allow(unused_mut)]
                let mut held = Vec::new();
                $($(#[cfg($cfg)])?
                if self.$oname {
                    held.extend($table.iter().find(|f| f.name == $oalias));
                })*
                held
            }

            /// Holds the member `name` from now on; false if there is none.
            pub fn activate(&mut self, name: &str) -> bool {
                $($(#[cfg($cfg)])?
                if name == $oalias {
                    self.$oname = true;
                    return true;
                })*
                let _ = name;
                false
            }
        }
    };
}

pub(crate) use held_set;

/// The name of an optional field: the one its row gives (`name: "T"`), or its own.
macro_rules! field_name {
    ($name:ident) => {
        stringify!($name)
    };
    ($name:ident, $alias:literal) => {
        $alias
    };
}

pub(crate) use field_name;

/// The bytes of a record (a particle, a contact's state) in the messages of a split run:
/// every core member, then the optional ones that the processes hold (`active`).
macro_rules! message_record {
    (
        $record:ident,
        $active:ident,
        [$($name:ident: $ty:ty),*],
        [$($(#[cfg($cfg:meta)])? $oname:ident: $oty:ty),*]
    ) => {
        impl $record {
            /// The bytes of a record in a message between processes that hold the
            /// optional members `active`.
            pub fn size(active: &$active) -> usize {
                #[allow(unused_mut)]
                let mut n = 0 $(+ <$ty as Value>::SIZE)*;
                $($(#[cfg($cfg)])?
                if active.$oname {
                    n += <$oty as Value>::SIZE;
                })*
                let _ = active;
                n
            }

            /// Appends the record's bytes in a message: every core member, and the
            /// optional ones `active`.
            pub fn put(&self, active: &$active, out: &mut Vec<u8>) {
                $(self.$name.put(out);)*
                $($(#[cfg($cfg)])?
                if active.$oname {
                    self.$oname.put(out);
                })*
                let _ = active;
            }

            /// The record whose bytes (in a message between processes that hold the
            /// optional members `active`) `bytes` begin with.
            pub fn take(active: &$active, bytes: &mut &[u8]) -> $record {
                let mut r = $record::default();
                $(r.$name = Value::take(bytes);)*
                $($(#[cfg($cfg)])?
                if active.$oname {
                    r.$oname = Value::take(bytes);
                })*
                let _ = active;
                r
            }
        }
    };
}

pub(crate) use message_record;

/// Makes the particles' storage and records from the table of fields (see the module's
/// text).
macro_rules! particle_fields {
    (
        core {$(
            $(#[doc = $doc:literal])*
            $name:ident: $ty:ty, ghost: $ghost:literal, checkpoint: $since:expr;
        )*}
        optional {$(
            $(#[cfg($cfg:meta)])?
            $(#[doc = $odoc:literal])*
            $oname:ident: $oty:ty, ghost: $oghost:literal, unit: $unit:literal
            $(, name: $oalias:literal)?;
        )*}
    ) => {
        /// The state of every particle: a vector per field of the table, in storage order.
        #[derive(Clone, Debug, Default, PartialEq)]
        pub struct Particles {
            /// The id of the particle stored at each index.
            pub id: Vec<Id>,
            /// The id the next particle created gets.
            pub next_id: Id,
            $($(#[doc = $doc])* pub $name: Vec<$ty>,)*
            $($(#[cfg($cfg)])? $(#[doc = $odoc])* pub $oname: Vec<$oty>,)*
            /// Which optional fields are held (the others' vectors are empty).
            pub active: Active,
            /// The rigid bodies (clumps) of several particles.
            pub bodies: Bodies,
        }

        $crate::model::fields::held_set!(
            /// Which optional fields the particles hold.
            Active,
            $crate::model::fields::Optional,
            OPTIONAL,
            [$($(#[cfg($cfg)])? $oname = $crate::model::fields::field_name!($oname $(, $oalias)?)),*]
        );

        impl Active {
            /// The fields held that frames write (those with columns), as `OPTIONAL`
            /// describes them.
            pub fn framed(&self) -> Vec<&'static $crate::model::fields::Optional> {
                let mut held = self.fields();
                held.retain(|f| !f.suffixes.is_empty());
                held
            }
        }

        /// One particle's state: a row of [`Particles`] (optional fields not held at their
        /// defaults).
        #[derive(Clone, Copy, Debug, Default, PartialEq)]
        pub struct Particle {
            $($(#[doc = $doc])* pub $name: $ty,)*
            $($(#[cfg($cfg)])? $(#[doc = $odoc])* pub $oname: $oty,)*
        }

        /// The optional fields of the table.
        pub const OPTIONAL: &[$crate::model::fields::Optional] = &[$(
            $(#[cfg($cfg)])?
            $crate::model::fields::Optional {
                name: $crate::model::fields::field_name!($oname $(, $oalias)?),
                unit: $unit,
                suffixes: <$oty as $crate::model::fields::Components>::SUFFIXES,
                size: <$oty as Value>::SIZE,
                ghost: $oghost,
            },
        )*];

        impl Particles {
            /// Adds a particle that has its id already (one made elsewhere: by another
            /// process of a split run); `next_id` stays.
            pub fn insert(&mut self, id: Id, p: Particle) {
                self.id.push(id);
                $(self.$name.push(p.$name);)*
                $($(#[cfg($cfg)])?
                if self.active.$oname {
                    self.$oname.push(p.$oname);
                })*
            }

            /// The particle stored at `i`.
            pub fn get(&self, i: usize) -> Particle {
                Particle {
                    $($name: self.$name[i],)*
                    $($(#[cfg($cfg)])?
                    $oname: if self.active.$oname { self.$oname[i] } else { Default::default() },)*
                }
            }

            /// No particles, with the optional fields of `self` (and its `next_id`).
            pub fn empty_like(&self) -> Particles {
                Particles { next_id: self.next_id, active: self.active, ..Particles::default() }
            }

            /// Holds the optional field `name` from now on (every particle at its default,
            /// if it was not held); false if there is no such field.
            pub fn activate(&mut self, name: &str) -> bool {
                let n = self.len();
                $($(#[cfg($cfg)])?
                if name == $crate::model::fields::field_name!($oname $(, $oalias)?) {
                    if !self.active.$oname {
                        self.active.$oname = true;
                        self.$oname = vec![Default::default(); n];
                    }
                    return true;
                })*
                let _ = (n, name);
                false
            }

            /// Puts the fields of the particle stored at `order[k]` at index `k`.
            fn gather_fields(&mut self, order: &[u32]) {
                gather(&mut self.id, order);
                $(gather(&mut self.$name, order);)*
                $($(#[cfg($cfg)])?
                if self.active.$oname {
                    gather(&mut self.$oname, order);
                })*
            }

            /// The bytes of the state sent to a particle's ghosts each step.
            pub fn ghost_state_size(&self) -> usize {
                #[allow(unused_mut)]
                let mut n = 0 $(+ if $ghost { <$ty as Value>::SIZE } else { 0 })*;
                $($(#[cfg($cfg)])?
                if $oghost && self.active.$oname {
                    n += <$oty as Value>::SIZE;
                })*
                n
            }

            /// Appends the state sent to the ghosts of the particle stored at `i`.
            pub fn put_ghost_state(&self, i: usize, out: &mut Vec<u8>) {
                $(if $ghost { self.$name[i].put(out); })*
                $($(#[cfg($cfg)])?
                if $oghost && self.active.$oname {
                    self.$oname[i].put(out);
                })*
            }

            /// Sets the ghost stored at `i` to the state `bytes` begin with.
            pub fn take_ghost_state(&mut self, i: usize, bytes: &mut &[u8]) {
                $(if $ghost { self.$name[i] = Value::take(bytes); })*
                $($(#[cfg($cfg)])?
                if $oghost && self.active.$oname {
                    self.$oname[i] = Value::take(bytes);
                })*
            }

            /// Appends the numbers of the optional field `name` of the particle stored at
            /// `i` (as many as its columns), if it is held.
            pub fn numbers(&self, name: &str, i: usize, out: &mut Vec<f64>) {
                $($(#[cfg($cfg)])?
                if name == $crate::model::fields::field_name!($oname $(, $oalias)?) && self.active.$oname {
                    <$oty as $crate::model::fields::Components>::numbers(&self.$oname[i], out);
                })*
                let _ = (name, i, out);
            }

            /// Sets the optional field `name` (held) of the particle stored at `i` to the
            /// value of `numbers`; false if they make none.
            pub fn set_numbers(&mut self, name: &str, i: usize, numbers: &[f64]) -> bool {
                $($(#[cfg($cfg)])?
                if name == $crate::model::fields::field_name!($oname $(, $oalias)?) && self.active.$oname {
                    return match <$oty as $crate::model::fields::Components>::from_numbers(numbers) {
                        Some(value) => {
                            self.$oname[i] = value;
                            true
                        }
                        None => false,
                    };
                })*
                let _ = (name, i, numbers);
                false
            }

            /// Appends the values of the optional field `name` (held) in storage order.
            pub fn put_field(&self, name: &str, out: &mut Vec<u8>) {
                $($(#[cfg($cfg)])?
                if name == $crate::model::fields::field_name!($oname $(, $oalias)?) && self.active.$oname {
                    self.$oname.iter().for_each(|v| v.put(out));
                })*
                let _ = (name, out);
            }

            /// Holds the optional field `name` with the values (one per particle, in
            /// storage order) `bytes` begin with; false if there is no such field.
            pub fn take_field(&mut self, name: &str, bytes: &mut &[u8]) -> bool {
                if !self.activate(name) {
                    return false;
                }
                $($(#[cfg($cfg)])?
                if name == $crate::model::fields::field_name!($oname $(, $oalias)?) {
                    self.$oname.iter_mut().for_each(|v| *v = Value::take(bytes));
                })*
                let _ = bytes;
                true
            }
        }

        $crate::model::fields::message_record!(
            Particle,
            Active,
            [$($name: $ty),*],
            [$($(#[cfg($cfg)])? $oname: $oty),*]
        );

        impl Particle {
            /// The bytes of a particle's record in a checkpoint of format `version`.
            pub fn checkpoint_size(version: u32) -> usize {
                0 $(+ match $since { Some(since) if version >= since => <$ty as Value>::SIZE, _ => 0 })*
            }

            /// Appends the particle's record in a checkpoint of the newest format (its core
            /// fields; the optional ones have a section of their own).
            pub fn put_checkpoint(&self, out: &mut Vec<u8>) {
                $(if $since.is_some() { self.$name.put(out); })*
            }

            /// The particle whose record in a checkpoint of format `version` `bytes` begin
            /// with (fields newer than the format at their defaults).
            pub fn take_checkpoint(bytes: &mut &[u8], version: u32) -> Particle {
                let mut p = Particle::default();
                $(if matches!($since, Some(since) if version >= since) {
                    p.$name = Value::take(bytes);
                })*
                p
            }
        }
    };
}

pub(crate) use particle_fields;

/// What checkpoints know of an optional member of a contact's state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OptionalState {
    pub name: &'static str,
    /// The bytes of one value.
    pub size: usize,
}

/// Makes a contact's state and its stores from the table of its members (one use, in
/// `model/contact_state.rs`): each member is the state of a part of the contact law,
/// kept from step to step while the contact touches. Core members are held by every run
/// (their bytes in each entry of a checkpoint's contact history, from format 2); optional
/// members only when a run asks for them (`States::activate`), in messages and in a
/// checkpoint's section by name (format 8). A member's type is a [`Value`].
macro_rules! contact_fields {
    (
        core {$(
            $(#[doc = $doc:literal])*
            $name:ident: $ty:ty;
        )*}
        optional {$(
            $(#[cfg($cfg:meta)])?
            $(#[doc = $odoc:literal])*
            $oname:ident: $oty:ty;
        )*}
    ) => {
        /// The state of one contact: what the parts of the contact law keep from step to
        /// step (optional members not held at their defaults). A contact whose state is
        /// the default one has nothing to keep.
        #[derive(Clone, Copy, Debug, Default, PartialEq)]
        pub struct ContactState {
            $($(#[doc = $doc])* pub $name: $ty,)*
            $($(#[cfg($cfg)])? $(#[doc = $odoc])* pub $oname: $oty,)*
        }

        $crate::model::fields::held_set!(
            /// Which optional members of a contact's state are held.
            ActiveState,
            $crate::model::fields::OptionalState,
            OPTIONAL_STATE,
            [$($(#[cfg($cfg)])? $oname = stringify!($oname)),*]
        );

        /// The optional members of a contact's state.
        pub const OPTIONAL_STATE: &[$crate::model::fields::OptionalState] = &[$(
            $(#[cfg($cfg)])?
            $crate::model::fields::OptionalState {
                name: stringify!($oname),
                size: <$oty as Value>::SIZE,
            },
        )*];

        /// The states of the entries of a store: a vector per member (the optional ones
        /// empty unless held).
        #[derive(Clone, Debug, Default)]
        pub struct States {
            $($(#[doc = $doc])* pub $name: Vec<$ty>,)*
            $($(#[cfg($cfg)])? $(#[doc = $odoc])* pub $oname: Vec<$oty>,)*
            pub active: ActiveState,
        }

        impl States {
            /// No entries, holding the optional members `active`.
            pub fn new(active: ActiveState) -> States {
                States { active, ..States::default() }
            }

            pub fn len(&self) -> usize {
                0 $(.max(self.$name.len()))*
            }

            pub fn is_empty(&self) -> bool {
                self.len() == 0
            }

            /// A new entry of state `s`.
            #[inline]
            pub fn push(&mut self, s: ContactState) {
                $(self.$name.push(s.$name);)*
                $($(#[cfg($cfg)])?
                if self.active.$oname {
                    self.$oname.push(s.$oname);
                })*
            }

            /// Entry `k`'s state.
            #[inline]
            pub fn get(&self, k: usize) -> ContactState {
                let mut s = ContactState::default();
                $(s.$name = self.$name[k];)*
                $($(#[cfg($cfg)])?
                if self.active.$oname {
                    s.$oname = self.$oname[k];
                })*
                s
            }

            /// Sets entry `k`'s state.
            #[inline]
            pub fn set(&mut self, k: usize, s: ContactState) {
                $(self.$name[k] = s.$name;)*
                $($(#[cfg($cfg)])?
                if self.active.$oname {
                    self.$oname[k] = s.$oname;
                })*
            }

            /// Room for `n` more entries, exactly.
            pub fn reserve_exact(&mut self, n: usize) {
                $(self.$name.reserve_exact(n);)*
                $($(#[cfg($cfg)])?
                if self.active.$oname {
                    self.$oname.reserve_exact(n);
                })*
            }

            /// Whether the next entry needs more room.
            #[inline]
            pub fn full(&self) -> bool {
                true $(&& self.$name.len() == self.$name.capacity())*
            }

            pub fn shrink_to_fit(&mut self) {
                $(self.$name.shrink_to_fit();)*
                $($(#[cfg($cfg)])?
                self.$oname.shrink_to_fit();)*
            }
        }

        $crate::model::fields::message_record!(
            ContactState,
            ActiveState,
            [$($name: $ty),*],
            [$($(#[cfg($cfg)])? $oname: $oty),*]
        );

        impl ContactState {
            /// The bytes of the core members in an entry of a checkpoint.
            pub const CHECKPOINT_SIZE: usize = 0 $(+ <$ty as Value>::SIZE)*;

            /// Appends the core members' bytes in an entry of a checkpoint.
            pub fn put_checkpoint(&self, out: &mut Vec<u8>) {
                $(self.$name.put(out);)*
            }

            /// The state whose core members' bytes (in a checkpoint) `bytes` begin with.
            pub fn take_checkpoint(bytes: &mut &[u8]) -> ContactState {
                let mut s = ContactState::default();
                $(s.$name = Value::take(bytes);)*
                s
            }

            /// Appends the bytes of the optional member `name`.
            pub fn put_member(&self, name: &str, out: &mut Vec<u8>) {
                $($(#[cfg($cfg)])?
                if name == stringify!($oname) {
                    self.$oname.put(out);
                })*
                let _ = (name, out);
            }

            /// Sets the optional member `name` to the value `bytes` begin with.
            pub fn take_member(&mut self, name: &str, bytes: &mut &[u8]) {
                $($(#[cfg($cfg)])?
                if name == stringify!($oname) {
                    self.$oname = Value::take(bytes);
                })*
                let _ = (name, bytes);
            }
        }
    };
}

pub(crate) use contact_fields;
