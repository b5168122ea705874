//! The state of a contact, declared once: what each part of the contact law keeps from
//! step to step while the contact touches (the machinery: `contact_fields!` in
//! `model/fields.rs`). The stores of the neighbour lists hold it per entry, rebuilds carry
//! it, messages and checkpoints hold it.

use crate::model::fields::{Value, contact_fields};
use crate::model::springs::Springs;

// A row: its doc (meaning and unit) and `name: type`. Core members are held by every run;
// optional ones when a run asks for them.
contact_fields! {
    core {
        /// The static friction springs (Table 3): sliding, rolling and twisting.
        springs: Springs;
    }
    optional {
        /// Whether the contact is open in a run whose contacts outlast touch (JKR's neck, a
        /// liquid bridge): an open contact there is kept, springs or not, while its gap is
        /// within the adhesion's reach.
        beyond: bool;
        #[cfg(test)]
        /// The steps the contact has touched (the state of the tests' sub-model).
        touches: u32;
    }
}

impl ContactState {
    /// Whether nothing is kept but that the contact is open (a first touch).
    pub fn is_first_touch(&self) -> bool {
        ContactState {
            beyond: false,
            ..*self
        } == ContactState::default()
    }
}
