//! The lines of `tinydem check` that describe the materials, the coefficients of each pair
//! of them and the contact sub-models in force.

use super::check::num;
use crate::model::registry::{AdhesionModel, Named, NormalModel, RollingModel, TangentialCoulomb};
use crate::scenario::Scenario;

/// The contact sub-models in force (where any differs from the paper's) and, with Hooke,
/// the contact time of two grains of mass `m_min` in time steps.
pub(super) fn model_lines(s: &Scenario, m_min: f64) -> String {
    let n = s.materials.len() as u16;
    let pairs: Vec<_> = (0..n).flat_map(|a| (a..n).map(move |b| (a, b))).collect();
    let mut normal: Vec<&str> = pairs
        .iter()
        .map(|&(a, b)| s.pair(a, b).models.normal.name())
        .collect();
    normal.dedup();
    let first = s.pair(0, 0).models;
    let papers = normal == ["hertz"]
        && first.rolling == RollingModel::Spring
        && first.tangential == TangentialCoulomb::Total;
    let default = if papers { " (the paper's)" } else { "" };
    let mut out = format!(
        "contact models         normal {}, rolling \"{}\", tangential_coulomb \"{}\"{default}\n",
        normal
            .iter()
            .map(|m| format!("\"{m}\""))
            .collect::<Vec<_>>()
            .join(" and "),
        first.rolling.name(),
        first.tangential.name(),
    );
    out += &adhesion_lines(s, &pairs);
    let stiffest = (pairs.iter())
        .map(|&(a, b)| s.pair(a, b))
        .filter(|p| p.models.normal == NormalModel::Hooke)
        .map(|p| p.hooke_stiffness)
        .fold(0.0, f64::max);
    if stiffest > 0.0 {
        let t_c = crate::scenario::hooke_contact_time(0.5 * m_min, stiffest);
        out += &format!(
            "Hooke contact time     {t_c:.6e} s = {:.1} time steps (two lightest grains, k_n {}, undamped)\n",
            t_c / s.simulation.timestep,
            num(stiffest)
        );
    }
    out
}

/// The adhesion models in force, and each wet pair's liquid bridges.
fn adhesion_lines(s: &Scenario, pairs: &[(u16, u16)]) -> String {
    let mut out = String::new();
    let mut adhesion: Vec<&str> = (pairs.iter())
        .map(|&(a, b)| s.pair(a, b).models.adhesion)
        .filter(|&m| m != AdhesionModel::None)
        .map(|m| m.name())
        .collect();
    adhesion.sort();
    adhesion.dedup();
    if !adhesion.is_empty() {
        let names: Vec<String> = adhesion.iter().map(|m| format!("\"{m}\"")).collect();
        out += &format!("adhesion               {}\n", names.join(" and "));
    }
    let mut first = true;
    for &(a, b) in pairs {
        let l = s.pair(a, b).liquid;
        if l.wet() {
            out += &format!(
                "{:<23}\"{}\" - \"{}\": volume {:e} m^3, surface tension {} N/m, contact angle {} deg, rupture at {:.4e} m\n",
                if first { "liquid bridges" } else { "" },
                s.materials[a as usize].name,
                s.materials[b as usize].name,
                l.volume,
                num(l.surface_tension),
                num(l.contact_angle),
                l.rupture_distance()
            );
            first = false;
        }
    }
    out
}

/// The lists' skin, where the setup raised it to the reach of contacts beyond touch (JKR,
/// liquid bridges).
pub(super) fn skin_line(s: &Scenario, skin: f64) -> String {
    let asked = s.simulation.skin * s.geometry.radius_max;
    if skin > asked {
        format!(
            "lists' skin            {skin:.4e} m, raised from {asked:.4e} m to the largest gap a contact holds across\n"
        )
    } else {
        String::new()
    }
}

/// The materials and the coefficients of each pair of them (where named).
pub(super) fn material_lines(s: &Scenario) -> String {
    let mut materials = String::new();
    if s.materials.len() > 1 || s.materials[0].name != "default" {
        for (k, m) in s.materials.iter().enumerate() {
            let p = &m.properties;
            materials += &format!(
                "{:<23}{k} \"{}\": density {}, E {:e}, nu {}, e_n {}, mu_s {}, mu_r {}, mu_t {}{}\n",
                if k == 0 { "materials" } else { "" },
                m.name,
                num(p.density),
                p.youngs_modulus,
                num(p.poisson_ratio),
                num(p.restitution),
                num(p.friction_sliding),
                num(p.friction_rolling),
                num(p.friction_twisting),
                if p.cohesion > 0.0 {
                    format!(", cohesion {} J/m^3", num(p.cohesion))
                } else {
                    String::new()
                }
            );
        }
        let n = s.materials.len() as u16;
        let mut first = true;
        for a in 0..n {
            for b in a..n {
                let c = s.pair(a, b);
                let how = pair_origin(s, a, b);
                materials += &format!(
                    "{:<23}{} - {}: e_n {}, mu_s {}, mu_r {}, mu_t {}, k_c {} ({how})\n",
                    if first { "pairs" } else { "" },
                    s.materials[a as usize].name,
                    s.materials[b as usize].name,
                    num(c.restitution),
                    num(c.friction_sliding),
                    num(c.friction_rolling),
                    num(c.friction_twisting),
                    num(c.cohesion)
                );
                first = false;
            }
        }
    }
    materials
}

/// Where the coefficients of the pair of materials `a`, `b` come from: its own material's,
/// the means of the two, or (some of them, and the sub-models it names) `[[interactions]]`.
fn pair_origin(s: &Scenario, a: u16, b: u16) -> String {
    let interaction = (s.interactions.iter()).find(|i| i.materials == (a.min(b), a.max(b)));
    let Some(i) = interaction else {
        return if a == b {
            "its own"
        } else {
            "means of the two"
        }
        .to_string();
    };
    let coefficients = i.coefficients();
    let given: Vec<&str> = (coefficients.iter().filter(|c| c.2.is_some()).map(|c| c.1))
        .chain(i.models.named().into_iter().map(|(key, _)| key))
        .collect();
    if coefficients.iter().all(|c| c.2.is_some()) {
        "[[interactions]]".to_string()
    } else {
        let rest = if a == b { "its own" } else { "means" };
        format!(
            "{} from [[interactions]], the rest {rest}",
            given.join(", ")
        )
    }
}
