//! Materials and the coefficients of a contact between two of them: what the contact law
//! is made from (the scenario's `[[materials]]`, `[[interactions]]` and `[simulation]
//! friction_springs` become these).

pub use crate::model::heat::Thermal;
pub use crate::model::registry::ContactModels;

/// The properties of a material (Table 2 of the paper).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// ρ [M/L³]
    pub density: f64,
    /// E [M/LT²]
    pub youngs_modulus: f64,
    /// ν [-]
    pub poisson_ratio: f64,
    /// e_n [-]
    pub restitution: f64,
    /// μ_s, μ_r, μ_t [-]
    pub friction_sliding: f64,
    pub friction_rolling: f64,
    pub friction_twisting: f64,
    /// η [M/LT]
    pub viscosity: f64,
    /// k_c [M/LT²] = [J/m³]: the simplified JKR cohesion, a pull k_c A over the contact
    /// area A.
    pub cohesion: f64,
    /// γ [J/m²], the work of adhesion of DMT (`adhesion_model = "dmt"`; 0 otherwise).
    pub surface_energy: f64,
    /// k_n [M/T²] of Hooke's normal sub-model (`normal_model = "hooke"`; 0 otherwise).
    pub hooke_stiffness: f64,
    /// k_s / k_n of Hooke's normal sub-model (2/7 by default).
    pub hooke_stiffness_ratio: f64,
    /// The contact law's sub-models for this material's contacts.
    pub models: ContactModels,
    /// k, c, T_0, q_V, h: heat transfer (conducts where k > 0).
    pub thermal: Thermal,
}

/// When a friction spring is advanced by Δt v relative to the force taken from it
/// (`[simulation] friction_springs`; the derivation is at `coulomb_spring` in `contact/friction.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FrictionSprings {
    /// Advance the spring, then take its force: symplectic, creates no energy (the default).
    #[default]
    AdvanceFirst,
    /// The paper's Eqs. (53)-(55): the force of the previous step's spring, then advance.
    /// It creates energy at Eq. (50)'s time step; the original program's order.
    Paper,
}

impl FrictionSprings {
    /// The value of the scenario key.
    pub fn key(self) -> &'static str {
        match self {
            FrictionSprings::AdvanceFirst => "advance_first",
            FrictionSprings::Paper => "paper",
        }
    }
}

/// The coefficients of the contact between two materials: e_n, μ_s, μ_r, μ_t, k_c.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairCoefficients {
    pub restitution: f64,
    pub friction_sliding: f64,
    pub friction_rolling: f64,
    pub friction_twisting: f64,
    pub cohesion: f64,
    /// γ of DMT [J/m²] (0 unless the pair's adhesion is DMT).
    pub surface_energy: f64,
    /// Hooke's k_n and k_s / k_n (`normal_model = "hooke"`).
    pub hooke_stiffness: f64,
    pub hooke_stiffness_ratio: f64,
    pub models: ContactModels,
    /// Whether `[[interactions]]` set any of them (otherwise the means).
    pub given: bool,
}
