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
    /// Whether the slots read as constants of the run (the rolling model, the Coulomb test)
    /// are read (`Dynamic`), or are the paper's (`Papers`), so that a run of the paper's law
    /// is compiled without their branches.
    const DYNAMIC: bool;
    /// Whether contacts outlast touch (see [`Adhesion::BEYOND_TOUCH`]).
    const BEYOND_TOUCH: bool;
}

/// The rolling model and Coulomb test are the paper's: compiled in.
pub struct Papers;
/// The rolling model and Coulomb test are read from the run's [`Choice`].
pub struct Dynamic;

/// Whether a composition reads the run's constants (see [`Models::DYNAMIC`]).
pub trait Constants {
    const DYNAMIC: bool;
}

impl Constants for Papers {
    const DYNAMIC: bool = false;
}

impl Constants for Dynamic {
    const DYNAMIC: bool = true;
}

/// The composition of adhesion `A`, spring order `O` and the run's constants `D` with the
/// paper's other sub-models.
pub struct Composition<A, O, D = Papers>(PhantomData<(A, O, D)>);

impl<A: Adhesion, O: Order, D: Constants> Models for Composition<A, O, D> {
    type Adhesion = A;
    type Order = O;
    const DYNAMIC: bool = D::DYNAMIC;
    const BEYOND_TOUCH: bool = A::BEYOND_TOUCH;
}

/// Which composition a run uses, found once from its pairs of materials.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Choice {
    /// Not `None` if any pair pulls (k_c > 0 or γ > 0).
    pub adhesion: AdhesionModel,
    /// Whether any pair makes liquid bridges.
    pub bridges: bool,
    pub springs: FrictionSprings,
    /// The rolling sub-model and what the tangential Coulomb limit clips: one each per run,
    /// read by the law as constants (a branch that always goes the same way), not types.
    pub rolling: RollingModel,
    pub tangential: TangentialCoulomb,
}

impl Choice {
    /// Whether the run's constants are the paper's (its loops compiled without their
    /// branches).
    pub fn papers_constants(self) -> bool {
        self.rolling == RollingModel::Spring && self.tangential == TangentialCoulomb::Total
    }
}

/// `$body` with the type `$M` set to the composition of `$choice` (a [`Choice`]): the one
/// place where the scenario's names become types.
macro_rules! with_models {
    ($choice:expr, $M:ident => $body:expr) => {{
        let choice: $crate::model::contact::composition::Choice = $choice;
        if choice.papers_constants() {
            $crate::model::contact::composition::with_models!(
                @order choice, $crate::model::contact::composition::Papers, $M => $body
            )
        } else {
            $crate::model::contact::composition::with_models!(
                @order choice, $crate::model::contact::composition::Dynamic, $M => $body
            )
        }
    }};
    (@order $choice:ident, $D:ty, $M:ident => $body:expr) => {{
        use $crate::model::contact::adhesion::{Bridge, Jkr, NoAdhesion, Pull};
        use $crate::model::contact::friction::{AdvanceFirst, PaperOrder};
        use $crate::model::materials::FrictionSprings;
        use $crate::model::registry::AdhesionModel;
        match ($choice.adhesion, $choice.bridges) {
            (AdhesionModel::None, false) => {
                $crate::model::contact::composition::with_models!(@springs $choice, NoAdhesion, $D, $M => $body)
            }
            // A run with JKR makes no bridges (the scenario refuses both).
            (AdhesionModel::Jkr | AdhesionModel::JkrForce, _) => {
                $crate::model::contact::composition::with_models!(@springs $choice, Jkr, $D, $M => $body)
            }
            (_, true) => {
                $crate::model::contact::composition::with_models!(@springs $choice, Bridge, $D, $M => $body)
            }
            (_, false) => {
                $crate::model::contact::composition::with_models!(@springs $choice, Pull, $D, $M => $body)
            }
        }
    }};
    (@springs $choice:ident, $A:ty, $D:ty, $M:ident => $body:expr) => {{
        use $crate::model::contact::composition::Composition;
        match $choice.springs {
            FrictionSprings::AdvanceFirst => {
                type $M = Composition<$A, AdvanceFirst, $D>;
                $body
            }
            FrictionSprings::Paper => {
                type $M = Composition<$A, PaperOrder, $D>;
                $body
            }
        }
    }};
}
pub(crate) use with_models;
