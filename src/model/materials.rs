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
    /// γ [J/m²], the work of adhesion of DMT and JKR (`adhesion_model = "dmt" | "jkr"`;
    /// 0 otherwise).
    pub surface_energy: f64,
    /// The liquid of its bridges (none: volume 0).
    pub liquid: Liquid,
    /// k_n [M/T²] of Hooke's normal sub-model (`normal_model = "hooke"`; 0 otherwise).
    pub hooke_stiffness: f64,
    /// k_s / k_n of Hooke's normal sub-model (2/7 by default).
    pub hooke_stiffness_ratio: f64,
    /// The contact law's sub-models for this material's contacts.
    pub models: ContactModels,
    /// k, c, T_0, q_V, h: heat transfer (conducts where k > 0).
    pub thermal: Thermal,
}

/// The liquid that wets a material's contacts: each contact, once touched, holds a bridge of
/// `volume` (Willett et al. 2000's capillary force) until its gap passes the rupture
/// distance (Lian et al. 1993). Volume 0: dry.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Liquid {
    /// V \[L³\], the liquid of one bridge (`liquid_volume`).
    pub volume: f64,
    /// γ_l [M/T²] = [N/m] (`surface_tension`).
    pub surface_tension: f64,
    /// θ in degrees (`contact_angle`), from 0 to 90.
    pub contact_angle: f64,
}

impl Liquid {
    /// Whether it makes bridges.
    pub fn wet(&self) -> bool {
        self.volume > 0.0
    }

    /// The gap at which a bridge breaks, (1 + θ/2) V^(1/3) (Lian et al. 1993, θ in radians).
    pub fn rupture_distance(&self) -> f64 {
        (1.0 + 0.5 * self.contact_angle.to_radians()) * self.volume.cbrt()
    }
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
    /// γ of DMT and JKR [J/m²] (0 unless the pair's adhesion is one of them).
    pub surface_energy: f64,
    /// The liquid of the pair's bridges (none: volume 0).
    pub liquid: Liquid,
    /// Hooke's k_n and k_s / k_n (`normal_model = "hooke"`).
    pub hooke_stiffness: f64,
    pub hooke_stiffness_ratio: f64,
    pub models: ContactModels,
    /// Whether `[[interactions]]` set any of them (otherwise the means).
    pub given: bool,
}
