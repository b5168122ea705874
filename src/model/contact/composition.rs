//! The composition of the contact law a run uses, as types: the loops over contacts are
//! generic over it, chosen once per run from the names of `model/registry.rs`.

use std::marker::PhantomData;

use super::adhesion::Adhesion;
use super::friction::Order;
use crate::model::materials::FrictionSprings;
use crate::model::registry::{AdhesionModel, RollingModel, TangentialCoulomb};

/// The sub-models a run's law is composed of, as types: the loops over contacts are
/// generic over it, so that no contact asks which model is in force.
pub trait Models {
    type Adhesion: Adhesion;
    type Order: Order;
}

/// The composition of adhesion `A` and spring order `O` with the paper's other sub-models.
pub struct Composition<A, O>(PhantomData<(A, O)>);

impl<A: Adhesion, O: Order> Models for Composition<A, O> {
    type Adhesion = A;
    type Order = O;
}

/// Which composition a run uses, found once from its pairs of materials.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Choice {
    /// Not `None` if any pair pulls (k_c > 0 or γ > 0).
    pub adhesion: AdhesionModel,
    pub springs: FrictionSprings,
    /// The rolling sub-model and what the tangential Coulomb limit clips: one each per run,
    /// read by the law as constants (a branch that always goes the same way), not types.
    pub rolling: RollingModel,
    pub tangential: TangentialCoulomb,
}

/// `$body` with the type `$M` set to the composition of `$choice` (a [`Choice`]): the one
/// place where the scenario's names become types.
macro_rules! with_models {
    ($choice:expr, $M:ident => $body:expr) => {{
        use $crate::model::contact::adhesion::{NoAdhesion, Pull};
        use $crate::model::contact::composition::Composition;
        use $crate::model::contact::friction::{AdvanceFirst, PaperOrder};
        use $crate::model::materials::FrictionSprings;
        use $crate::model::registry::AdhesionModel;
        let choice: $crate::model::contact::composition::Choice = $choice;
        match (choice.adhesion, choice.springs) {
            (AdhesionModel::None, FrictionSprings::AdvanceFirst) => {
                type $M = Composition<NoAdhesion, AdvanceFirst>;
                $body
            }
            (AdhesionModel::None, FrictionSprings::Paper) => {
                type $M = Composition<NoAdhesion, PaperOrder>;
                $body
            }
            (_, FrictionSprings::AdvanceFirst) => {
                type $M = Composition<Pull, AdvanceFirst>;
                $body
            }
            (_, FrictionSprings::Paper) => {
                type $M = Composition<Pull, PaperOrder>;
                $body
            }
        }
    }};
}
pub(crate) use with_models;
