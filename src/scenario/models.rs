//! The keys that choose the contact law's sub-models (`normal_model`, `adhesion_model`,
//! `rolling_model`, `tangential_coulomb`) in `[material]`, `[[materials]]` and
//! `[[interactions]]`, checked against the registry (`model/registry.rs`).

use anyhow::{Result, anyhow, bail};

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
    /// where `cohesion` > 0, "none" otherwise).
    pub(super) fn of_material(self, table: &str, cohesion: f64) -> Result<ContactModels> {
        let adhesion = match self.adhesion {
            Some(AdhesionModel::None) if cohesion > 0.0 => bail!(
                "{table} adhesion_model = \"none\" contradicts cohesion = {cohesion}: drop one of them"
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

/// A material's sub-models that differ from what its keys' defaults give (for `run.toml`,
/// which names only those, so that a scenario without the keys writes none).
pub fn beyond_defaults(models: ContactModels, cohesion: f64) -> GivenModels {
    let default = GivenModels::default()
        .of_material("", cohesion)
        .expect("the defaults agree with any cohesion");
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
