//! The keys that choose the contact law's sub-models (`normal_model`, `adhesion_model`,
//! `rolling_model`, `tangential_coulomb`) in `[material]`, `[[materials]]` and
//! `[[interactions]]`, checked against the registry (`model/registry.rs`).

use anyhow::{Result, anyhow, bail};

use super::Scenario;
use super::validate::Range;
use crate::model::materials::{Liquid, Material, PairCoefficients};
use crate::model::registry::{
    AdhesionModel, ContactModels, Named, NormalModel, RollingModel, TangentialCoulomb,
};

/// The sub-models a table names, each or not.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GivenModels {
    pub normal: Option<NormalModel>,
    pub adhesion: Option<AdhesionModel>,
    pub rolling: Option<RollingModel>,
    pub tangential: Option<TangentialCoulomb>,
}

/// One key's value, checked against its slot of the registry.
fn named<M: Named>(table: &str, value: Option<String>) -> Result<Option<M>> {
    (value.map(|v| M::parse(&v).map_err(|e| anyhow!("{table} {e}")))).transpose()
}

impl GivenModels {
    /// The four keys of table `table`, checked.
    pub(super) fn read(
        table: &str,
        [normal, adhesion, rolling, tangential]: [Option<String>; 4],
    ) -> Result<GivenModels> {
        Ok(GivenModels {
            normal: named(table, normal)?,
            adhesion: named(table, adhesion)?,
            rolling: named(table, rolling)?,
            tangential: named(table, tangential)?,
        })
    }

    /// A material's sub-models: those named, or the defaults (the paper's; adhesion "sjkr"
    /// where `cohesion` > 0, "none" otherwise; "dmt" is named, with `surface_energy`).
    pub(super) fn of_material(
        self,
        table: &str,
        cohesion: f64,
        surface_energy: f64,
    ) -> Result<ContactModels> {
        let adhesion = match self.adhesion {
            Some(m) if m != AdhesionModel::Sjkr && cohesion > 0.0 => {
                bail!(
                    "{table} adhesion_model = \"{}\" contradicts cohesion = {cohesion}: drop one of them",
                    self.adhesion.unwrap_or_default().name()
                )
            }
            Some(model) if model.has_surface_energy() && surface_energy <= 0.0 => {
                bail!(
                    "{table} adhesion_model = \"{}\" needs surface_energy > 0 (the work of \
                     adhesion gamma, J/m^2)",
                    model.name()
                )
            }
            Some(AdhesionModel::None | AdhesionModel::Sjkr) | None if surface_energy > 0.0 => {
                bail!(
                    "{table} surface_energy = {surface_energy} needs adhesion_model = \"dmt\", \
                     \"jkr\" or \"jkr_force\""
                )
            }
            Some(model) if model.is_jkr() && self.normal == Some(NormalModel::Hooke) => bail!(
                "{table} adhesion_model = \"{}\" needs Hertz's normal model: JKR's contact \
                 area is Hertz's with adhesion",
                model.name()
            ),
            Some(model) => model,
            None if cohesion > 0.0 => AdhesionModel::Sjkr,
            None => AdhesionModel::None,
        };
        Ok(ContactModels {
            normal: self.normal.unwrap_or_default(),
            adhesion,
            rolling: self.rolling.unwrap_or_default(),
            tangential: self.tangential.unwrap_or_default(),
        })
    }

    /// `mixed` with what this names put over it.
    pub fn over(self, mixed: ContactModels) -> ContactModels {
        ContactModels {
            normal: self.normal.unwrap_or(mixed.normal),
            adhesion: self.adhesion.unwrap_or(mixed.adhesion),
            rolling: self.rolling.unwrap_or(mixed.rolling),
            tangential: self.tangential.unwrap_or(mixed.tangential),
        }
    }

    /// Each key named, with its value (for `run.toml`).
    pub fn named(self) -> Vec<(&'static str, &'static str)> {
        let mut out = Vec::new();
        if let Some(m) = self.normal {
            out.push((NormalModel::KEY, m.name()));
        }
        if let Some(m) = self.adhesion {
            out.push((AdhesionModel::KEY, m.name()));
        }
        if let Some(m) = self.rolling {
            out.push((RollingModel::KEY, m.name()));
        }
        if let Some(m) = self.tangential {
            out.push((TangentialCoulomb::KEY, m.name()));
        }
        out
    }
}

/// Hooke's k_s / k_n unless given: 2/7, at which a sphere's tangential oscillation on a
/// plane has the period of its normal one (LIGGGHTS's `ktToKnUser`, LAMMPS's examples).
pub const HOOKE_RATIO: f64 = 2.0 / 7.0;

/// Hooke's keys of a table, `hooke_stiffness` (k_n) and `hooke_stiffness_ratio` (k_s / k_n).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Hooke {
    pub stiffness: Option<f64>,
    pub ratio: Option<f64>,
}

impl Hooke {
    /// The keys of table `table`, checked.
    pub(super) fn read(table: &str, [stiffness, ratio]: [Option<f64>; 2]) -> Result<Hooke> {
        let positive = |key: &str, x: Option<f64>| {
            x.map(|x| super::validate::check(&format!("{table} {key}"), x, Range::Positive))
                .transpose()
        };
        Ok(Hooke {
            stiffness: positive("hooke_stiffness", stiffness)?,
            ratio: positive("hooke_stiffness_ratio", ratio)?,
        })
    }

    /// The normal sub-model of a table that names `normal` (or not) with these keys: a
    /// stiffness alone chooses Hooke; Hooke named needs it (in a material; an interaction
    /// may take the mean of its materials'), and Hertz takes neither key.
    pub(super) fn choose(self, table: &str, normal: &mut Option<NormalModel>) -> Result<()> {
        match *normal {
            None if self.stiffness.is_some() => *normal = Some(NormalModel::Hooke),
            Some(NormalModel::Hertz) if self.stiffness.is_some() || self.ratio.is_some() => bail!(
                "{table} normal_model = \"hertz\" takes no hooke_stiffness or \
                 hooke_stiffness_ratio: drop them, or choose normal_model = \"hooke\""
            ),
            None if self.ratio.is_some() => bail!(
                "{table} hooke_stiffness_ratio needs Hooke's normal model: give hooke_stiffness \
                 (k_n, N/m) too"
            ),
            Some(NormalModel::Hooke)
                if self.stiffness.is_none() && table.starts_with("[material") =>
            {
                bail!(
                    "{table} normal_model = \"hooke\" needs hooke_stiffness, the normal \
                     stiffness k_n in N/m"
                )
            }
            _ => {}
        }
        Ok(())
    }
}

/// Whether a material's contacts follow Hooke.
pub fn is_hooke(m: &Material) -> bool {
    m.models.normal == NormalModel::Hooke
}

/// Whether a material adheres by a surface energy (DMT or JKR).
pub fn has_surface_energy(m: &Material) -> bool {
    m.models.adhesion.has_surface_energy()
}

/// Whether a material's contacts make liquid bridges.
pub fn is_wet(m: &Material) -> bool {
    m.liquid.wet()
}

/// The liquid keys of a table, `liquid_volume` (V, m³ per bridge), `surface_tension`
/// (N/m) and `contact_angle` (deg, in [0, 90]), checked; those of a material need each
/// other (a volume with a surface tension, a tension or angle with a volume).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GivenLiquid {
    pub volume: Option<f64>,
    pub surface_tension: Option<f64>,
    pub contact_angle: Option<f64>,
}

impl GivenLiquid {
    /// The keys of table `table`, checked.
    pub(super) fn read(table: &str, [volume, tension, angle]: [Option<f64>; 3]) -> Result<Self> {
        let check = |key: &str, x: Option<f64>, range: Range| {
            x.map(|x| super::validate::check(&format!("{table} {key}"), x, range))
                .transpose()
        };
        Ok(GivenLiquid {
            volume: check("liquid_volume", volume, Range::NonNegative)?,
            surface_tension: check("surface_tension", tension, Range::NonNegative)?,
            contact_angle: check("contact_angle", angle, Range::Closed(0.0, 90.0))?,
        })
    }

    /// A material's liquid: dry unless a volume is given, which needs a surface tension.
    pub(super) fn of_material(self, table: &str) -> Result<Liquid> {
        let liquid = Liquid {
            volume: self.volume.unwrap_or(0.0),
            surface_tension: self.surface_tension.unwrap_or(0.0),
            contact_angle: self.contact_angle.unwrap_or(0.0),
        };
        if liquid.wet() && liquid.surface_tension <= 0.0 {
            bail!(
                "{table} liquid_volume = {} needs surface_tension > 0 (N/m) for its bridges",
                liquid.volume
            );
        }
        if !liquid.wet() && (self.surface_tension.is_some() || self.contact_angle.is_some()) {
            bail!(
                "{table} surface_tension and contact_angle describe liquid bridges: give \
                 liquid_volume > 0 (m^3 per bridge) too"
            );
        }
        Ok(liquid)
    }

    /// The liquid of a pair of materials `m`, `n` with these keys given for it: each key
    /// given, or the mean over the wet ones.
    pub fn over(self, [m, n]: [&Material; 2]) -> Liquid {
        let mean = |f: fn(&Liquid) -> f64| mean_of([m, n], is_wet, |m| f(&m.liquid));
        Liquid {
            volume: self.volume.unwrap_or_else(|| mean(|l| l.volume)),
            surface_tension: (self.surface_tension).unwrap_or_else(|| mean(|l| l.surface_tension)),
            contact_angle: self
                .contact_angle
                .unwrap_or_else(|| mean(|l| l.contact_angle)),
        }
    }
}

/// The mean of `f` over those of `materials` that have a sub-model (`has`; of both if
/// neither has it): a pair's coefficients of that model unless `[[interactions]]` gives them.
pub fn mean_of(
    materials: [&Material; 2],
    has: impl Fn(&Material) -> bool,
    f: impl Fn(&Material) -> f64,
) -> f64 {
    let having: Vec<f64> = (materials.iter())
        .filter(|m| has(m))
        .map(|m| f(m))
        .collect();
    match having[..] {
        [x] => x,
        [x, y] => 0.5 * (x + y),
        _ => 0.5 * (f(materials[0]) + f(materials[1])),
    }
}

impl Scenario {
    /// What must hold between the pairs of materials: one normal sub-model per pair (an
    /// `[[interactions]]` entry names it for two materials that differ), a Hooke stiffness
    /// for each Hooke pair, and one rolling sub-model and one tangential Coulomb test in the
    /// whole run.
    pub(super) fn consistent_models(&self) -> Result<()> {
        let n = self.materials.len() as u16;
        let name = |a: u16| &self.materials[a as usize].name;
        let (mut rolling, mut tangential) = (Vec::new(), Vec::new());
        let (mut jkr, mut wet) = (false, false);
        for a in 0..n {
            for b in a..n {
                let (m, o) = (
                    &self.materials[a as usize].properties,
                    &self.materials[b as usize].properties,
                );
                let given = (self.interactions.iter()).find(|i| i.materials == (a, b));
                let adhere = [m.models.adhesion, o.models.adhesion];
                if adhere[0] != adhere[1]
                    && !adhere.contains(&AdhesionModel::None)
                    && given.and_then(|i| i.models.adhesion).is_none()
                {
                    bail!(
                        "materials \"{}\" and \"{}\" adhere by different models (\"{}\", \"{}\"): \
                         name the pair's adhesion_model in [[interactions]]",
                        name(a),
                        name(b),
                        adhere[0].name(),
                        adhere[1].name()
                    );
                }
                if m.models.normal != o.models.normal
                    && given.and_then(|i| i.models.normal).is_none()
                {
                    bail!(
                        "materials \"{}\" (normal_model = \"{}\") and \"{}\" (\"{}\") differ in \
                         their normal model: name the pair's in [[interactions]] (normal_model, \
                         and hooke_stiffness for \"hooke\")",
                        name(a),
                        m.models.normal.name(),
                        name(b),
                        o.models.normal.name()
                    );
                }
                let pair = self.pair(a, b);
                if pair.models.normal == NormalModel::Hooke && pair.hooke_stiffness <= 0.0 {
                    bail!(
                        "the contacts of \"{}\" and \"{}\" follow Hooke without a stiffness: give \
                         hooke_stiffness in their [[interactions]]",
                        name(a),
                        name(b)
                    );
                }
                self.pair_models_hold(&pair, (name(a), name(b)))?;
                jkr |= pair.models.adhesion.is_jkr();
                wet |= pair.liquid.wet();
                rolling.push((pair.models.rolling, (a, b)));
                tangential.push((pair.models.tangential, (a, b)));
            }
        }
        if jkr && wet {
            bail!(
                "JKR and liquid bridges in one run: the law keeps one kind of contact beyond \
                 touch per run; choose one"
            );
        }
        one_per_run(&rolling, &name)?;
        one_per_run(&tangential, &name)
    }

    /// What a pair's coefficients need for its sub-models (`names`: the materials').
    fn pair_models_hold(&self, pair: &PairCoefficients, names: (&String, &String)) -> Result<()> {
        let (a, b) = names;
        let adhesion = pair.models.adhesion;
        if adhesion.has_surface_energy() && pair.surface_energy <= 0.0 {
            bail!(
                "the contacts of \"{a}\" and \"{b}\" follow {} without a surface energy: \
                 give surface_energy in their [[interactions]]",
                adhesion.name().to_uppercase()
            );
        }
        if adhesion.is_jkr() && pair.models.normal == NormalModel::Hooke {
            bail!(
                "the contacts of \"{a}\" and \"{b}\" follow JKR and Hooke: JKR needs Hertz's \
                 normal model (name normal_model = \"hertz\" in their [[interactions]])"
            );
        }
        if pair.liquid.wet() && pair.liquid.surface_tension <= 0.0 {
            bail!(
                "the liquid bridges of \"{a}\" and \"{b}\" have no surface tension: give \
                 surface_tension (N/m) in their [[interactions]]"
            );
        }
        Ok(())
    }
}

/// That every pair of materials has the same sub-model of one slot (the law reads it as a
/// constant of the run).
fn one_per_run<'a, M: Named>(
    pairs: &[(M, (u16, u16))],
    name: &dyn Fn(u16) -> &'a String,
) -> Result<()> {
    let (first, (a, b)) = pairs[0];
    if let Some((other, (c, d))) = pairs.iter().find(|(m, _)| *m != first) {
        bail!(
            "one {} for a whole run: \"{}\"-\"{}\" have \"{}\", \"{}\"-\"{}\" \"{}\" (give \
             every material, or [[interactions]], the same)",
            M::KEY,
            name(a),
            name(b),
            first.name(),
            name(*c),
            name(*d),
            other.name()
        );
    }
    Ok(())
}

/// A material's sub-models that differ from what its keys' defaults give (for `run.toml`,
/// which names only those, so that a scenario without the keys writes none; Hooke follows
/// from `hooke_stiffness`).
pub fn beyond_defaults(m: &Material) -> GivenModels {
    let (models, cohesion) = (m.models, m.cohesion);
    let mut default = GivenModels::default()
        .of_material("", cohesion, 0.0)
        .expect("the defaults agree with any cohesion");
    if m.hooke_stiffness > 0.0 {
        default.normal = NormalModel::Hooke;
    }
    GivenModels {
        normal: (models.normal != default.normal).then_some(models.normal),
        adhesion: (models.adhesion != default.adhesion).then_some(models.adhesion),
        rolling: (models.rolling != default.rolling).then_some(models.rolling),
        tangential: (models.tangential != default.tangential).then_some(models.tangential),
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use crate::model::registry::AdhesionModel;
    use crate::scenario::Scenario;

    const TWO_COHESIVE: &str = "[[materials]]\nname = \"a\"\ncohesion = 200.0\n\
        [[materials]]\nname = \"b\"\ncohesion = 100.0\nadhesion_model = \"sjkr\"\n\
        [[materials]]\nname = \"dry\"\nadhesion_model = \"sjkr\"\n";

    /// An interaction may switch adhesion off between two cohesive materials, and a
    /// cohesion given for a pair alone adheres; `run.toml` keeps both.
    #[test]
    fn an_interaction_chooses_the_adhesion_of_its_pair() {
        let toml = format!(
            "{TWO_COHESIVE}[[interactions]]\nmaterials = [\"a\", \"b\"]\nadhesion_model = \"none\"\n\
             [[interactions]]\nmaterials = [\"dry\", \"dry\"]\ncohesion = 30.0\n"
        );
        let s = Scenario::parse(&toml, Path::new("s.toml")).unwrap();
        let (ab, aa, a_dry, dry) = (s.pair(0, 1), s.pair(0, 0), s.pair(0, 2), s.pair(2, 2));
        assert_eq!(
            (ab.models.adhesion, ab.cohesion),
            (AdhesionModel::None, 0.0)
        );
        assert_eq!(
            (aa.models.adhesion, aa.cohesion),
            (AdhesionModel::Sjkr, 200.0)
        );
        assert_eq!(
            (a_dry.models.adhesion, a_dry.cohesion),
            (AdhesionModel::Sjkr, 100.0)
        );
        assert_eq!(
            (dry.models.adhesion, dry.cohesion),
            (AdhesionModel::Sjkr, 30.0)
        );
        let written = s.to_toml();
        assert!(written.contains("adhesion_model = \"none\""), "{written}");
        // "sjkr" where the cohesion gives it anyway is not repeated; on a dry material it is.
        assert_eq!(
            written.matches("adhesion_model = \"sjkr\"").count(),
            1,
            "{written}"
        );
        let again = Scenario::parse(&written, Path::new("run.toml")).unwrap();
        assert_eq!(again, s, "{written}");
        for (a, b) in [(0, 1), (0, 0), (0, 2), (2, 2), (1, 2)] {
            assert_eq!(again.pair(a, b), s.pair(a, b));
        }
    }

    /// Without the keys a scenario is the paper's model, with cohesion where given, and
    /// `run.toml` names no model.
    #[test]
    fn without_the_keys_the_models_are_the_papers() {
        let s = Scenario::parse("[material]\ncohesion = 5.0\n", Path::new("s.toml")).unwrap();
        assert_eq!(s.material.models.adhesion, AdhesionModel::Sjkr);
        assert!(!s.to_toml().contains("_model"), "{}", s.to_toml());
        let dry = Scenario::parse("", Path::new("s.toml")).unwrap();
        assert_eq!(dry.material.models, Default::default());
        assert!(!dry.to_toml().contains("_model"));
    }
}
