//! Which limits a query checks a stance against (spec stance-model §7.5): each character's
//! absolute limits, recomputed from the library's own tables with the function the build
//! used, or the stance's own relative ones, with a given μ under either form.
//!
//! # References
//! spec stance-model §7.5 (limit forms), §9 (the scaled character's limits).

use std::collections::BTreeMap;

use super::feasibility::{relative_limits, LimitForm, Limits};
use super::pool::Prepared;
use crate::library::read::StanceLibrary;
use crate::stances::limits::{limits, ClipFacts, StanceFacts, S_EFF_RANGE};
use crate::stances::segment::Boundary;

impl From<&crate::stances::limits::CharacterLimits> for Limits {
    /// The checked part of a character's build-time limits (μ, `F_max`, `χ_min`, `χ_max`).
    fn from(l: &crate::stances::limits::CharacterLimits) -> Self {
        Limits {
            mu: l.mu,
            f_max: l.f_max_n,
            chi_min: l.chi_min_m,
            chi_max: l.chi_max_m,
        }
    }
}

/// Per-character absolute limits (§7.5), recomputed from the library's own tables with
/// the function the build used.
pub fn absolute_limits(lib: &StanceLibrary) -> BTreeMap<String, Limits> {
    let facts: Vec<StanceFacts> = lib
        .stances
        .iter()
        .map(|s| StanceFacts {
            clip: s.clip.clone(),
            character_id: s.character_id.clone(),
            mass_kg: s.model.mass_kg,
            f_peak: s.coef.f_peak,
            ext_min: s.coef.ext_min,
            ext_max: s.coef.ext_max,
            unsupported: [s.boundary_start, s.boundary_end].contains(&Boundary::Unsupported),
            hands: s.label.contains('H'),
            count: 1,
        })
        .collect();
    let clips: BTreeMap<String, ClipFacts> = lib
        .clips
        .iter()
        .map(|(k, c)| {
            let f = ClipFacts {
                s_eff: c.s_eff,
                leg_m: c.leg_m.unwrap_or(1.0),
            };
            (k.clone(), f)
        })
        .collect();
    limits(&facts, &clips)
        .iter()
        .map(|(k, l)| (k.clone(), Limits::from(l)))
        .collect()
}

/// A stance's limits under `form`: its character's absolute ones, widened to the stance's
/// own recorded extremes (what the person did is possible for the person, so the
/// recorded stance is feasible as recorded), or its own relative ones (±5 %); μ replaced
/// by `mu` when given (`--mu` acts under both forms, §7.5: "each limit takes either form").
///
/// ```text
/// absolute: μ = max(μ_char, μ_req),  F_max = max(F_char, F_peak),
///           χ_max = max(χ_char, ext_max),  χ_min = min(χ_char, ext_min)
/// ```
pub fn stance_limits(
    p: &Prepared,
    form: LimitForm,
    absolute: &BTreeMap<String, Limits>,
    mu: Option<f64>,
) -> Limits {
    let c = &p.stance.coef;
    let l = match form {
        LimitForm::Relative => relative_limits(c),
        LimitForm::Absolute => match absolute.get(&p.stance.character_id) {
            Some(a) => Limits {
                mu: a.mu.max(c.mu_req),
                f_max: a.f_max.max(c.f_peak),
                chi_min: a.chi_min.min(c.ext_min),
                chi_max: a.chi_max.max(c.ext_max),
            },
            None => relative_limits(c),
        },
    };
    Limits {
        mu: mu.unwrap_or(l.mu),
        ..l
    }
}

/// Whether a clip's flights say its time base is wrong (`s_eff` outside
/// [`S_EFF_RANGE`]): its cycles are left out of the run queries.
pub fn time_scaled(lib: &StanceLibrary, clip: &str) -> bool {
    lib.clips
        .get(clip)
        .and_then(|c| c.s_eff)
        .is_some_and(|s| !(S_EFF_RANGE.0..=S_EFF_RANGE.1).contains(&s))
}
