//! The registry of the contact law's sub-models (`model/contact/`): the names the
//! scenario chooses them by, one line each. `contact/composition.rs` turns the names a
//! run uses into the types its loops are generic over.

/// The sub-models of one slot of the law, by their names in the scenario.
pub trait Named: Copy + Eq + Sized + 'static {
    /// The scenario key that chooses it.
    const KEY: &'static str;
    /// Every sub-model of the slot: its name and what it is.
    const KNOWN: &'static [(&'static str, Self, &'static str)];

    /// Its name in the scenario.
    fn name(self) -> &'static str {
        let known = Self::KNOWN.iter().find(|(_, m, _)| *m == self);
        known.expect("every sub-model is registered").0
    }

    /// The sub-model named `value`; the error lists the known ones.
    fn parse(value: &str) -> Result<Self, String> {
        match Self::KNOWN.iter().find(|(name, _, _)| *name == value) {
            Some((_, model, _)) => Ok(*model),
            None => {
                let known: Vec<String> = (Self::KNOWN.iter())
                    .map(|(name, _, what)| format!("\"{name}\" ({what})"))
                    .collect();
                Err(format!(
                    "{} = \"{value}\" is not a known model: it must be {}",
                    Self::KEY,
                    known.join(" or ")
                ))
            }
        }
    }
}

/// A slot of the law and its sub-models: `Slot "key" { Variant = "name": "what it is", }`.
macro_rules! registry {
    ($(#[$m:meta])* $slot:ident $key:literal { $($(#[$vm:meta])* $variant:ident = $name:literal: $what:literal,)* }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        pub enum $slot {
            #[default]
            $($(#[$vm])* $variant,)*
        }

        impl Named for $slot {
            const KEY: &'static str = $key;
            const KNOWN: &'static [(&'static str, Self, &'static str)] =
                &[$(($name, $slot::$variant, $what)),*];
        }
    };
}

registry! {
    /// The normal sub-model: the elastic stiffnesses (`contact/normal.rs`).
    NormalModel "normal_model" {
        Hertz = "hertz": "Hertz-Mindlin, the paper's Eqs. 12-14",
        Hooke = "hooke": "the linear spring-dashpot, k_n = hooke_stiffness",
    }
}

registry! {
    /// The adhesion sub-model (`contact/adhesion.rs`).
    AdhesionModel "adhesion_model" {
        None = "none": "no adhesion",
        Sjkr = "sjkr": "the simplified JKR cohesion, a pull cohesion x area",
        Dmt = "dmt": "the DMT pull 2 pi surface_energy R* while in contact",
        Jkr = "jkr": "JKR's elastic adhesion, the contact kept until the pull-off separation",
        JkrForce = "jkr_force": "JKR parting at the pull-off force, as LAMMPS's jkr",
    }
}

impl AdhesionModel {
    /// Whether it is JKR's (either way of parting).
    pub fn is_jkr(self) -> bool {
        matches!(self, AdhesionModel::Jkr | AdhesionModel::JkrForce)
    }

    /// Whether its pull comes from `surface_energy` (DMT, JKR).
    pub fn has_surface_energy(self) -> bool {
        self == AdhesionModel::Dmt || self.is_jkr()
    }
}

registry! {
    /// The rolling sub-model (`contact/rolling.rs`).
    RollingModel "rolling_model" {
        Spring = "spring": "the paper's rolling spring, Eqs. 34, 39",
        Cdt = "cdt": "a constant torque against the rolling, Ai et al. 2011's model A",
        Epsd2 = "epsd2": "an elastic-plastic spring torque, Ai et al. 2011's model C without its damper",
    }
}

registry! {
    /// What the tangential Coulomb limit clips (`contact/friction.rs`).
    TangentialCoulomb "tangential_coulomb" {
        Total = "total": "the spring and damper force together, the paper's Eq. 55",
        Spring = "spring": "the spring force alone, no damper while sliding, as LIGGGHTS and LAMMPS",
    }
}

/// The sub-models of the contacts between two materials.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ContactModels {
    pub normal: NormalModel,
    pub adhesion: AdhesionModel,
    pub rolling: RollingModel,
    pub tangential: TangentialCoulomb,
}

impl ContactModels {
    /// The sub-models of the contacts between a material with `self` and one with `other`:
    /// adhesion if either adheres (one without has k_c = 0, which mixes as the other
    /// coefficients do), the others as both have them (each slot has one sub-model today;
    /// a second one decides its mixing here).
    pub fn mix(self, other: ContactModels) -> ContactModels {
        let adhesion = if other.adhesion != AdhesionModel::None {
            other.adhesion
        } else {
            self.adhesion
        };
        ContactModels { adhesion, ..self }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_sub_model_reads_back_by_its_name() {
        fn each<M: Named + std::fmt::Debug>() {
            for &(name, model, _) in M::KNOWN {
                assert_eq!(M::parse(name), Ok(model));
                assert_eq!(model.name(), name);
            }
        }
        each::<NormalModel>();
        each::<AdhesionModel>();
        each::<RollingModel>();
        each::<TangentialCoulomb>();
    }

    #[test]
    fn an_unknown_name_is_refused_with_the_known_ones() {
        let e = AdhesionModel::parse("capillary").unwrap_err();
        assert_eq!(
            e,
            "adhesion_model = \"capillary\" is not a known model: it must be \"none\" (no adhesion) \
             or \"sjkr\" (the simplified JKR cohesion, a pull cohesion x area) or \"dmt\" (the DMT \
             pull 2 pi surface_energy R* while in contact) or \"jkr\" (JKR's elastic adhesion, the \
             contact kept until the pull-off separation) or \"jkr_force\" (JKR parting at the \
             pull-off force, as LAMMPS's jkr)"
        );
        assert!(NormalModel::parse("Hertz").is_err(), "names are exact");
    }

    #[test]
    fn adhesion_mixes_as_either_material_has_it() {
        let dry = ContactModels::default();
        let wet = ContactModels {
            adhesion: AdhesionModel::Sjkr,
            ..dry
        };
        assert_eq!(dry.mix(wet), wet);
        assert_eq!(wet.mix(dry), wet);
        assert_eq!(dry.mix(dry), dry);
    }
}
