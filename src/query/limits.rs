//! Which limits a query checks a stance against (spec stance-model §7.5): each character's
//! absolute limits, recomputed from the library's own tables with the function the build
//! used, or the stance's own relative ones, with a given μ under either form.
//!
//! # References
//! spec stance-model §7.5 (limit forms), §9 (the scaled character's limits).

use std::collections::BTreeMap;

use super::feasibility::{relative_limits, LimitForm, Limits};
use super::pool::Prepared;
use crate::library::readers::read::{same_content, ClipInfo, StanceLibrary};
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

/// A jump stance's limits: [`stance_limits`], with the absolute `χ_max` no farther than
/// the body's reach (`ingest::reach`, `clips.parquet` `reach_m`) unless the stance itself
/// reached farther when it was recorded (what the person did is possible):
///
/// ```text
/// absolute: χ_max = min(χ_max of stance_limits, max(R, ext_max))
/// ```
/// A jump pushes and lands along the leg, so the straight leg on its toe bounds how far
/// the COM gets from the contact; the edited jumps beyond `R` leave their plan
/// (`docs/edited-motion.md`). Runs keep [`stance_limits`]: their touchdown is bounded by
/// how far ahead the foot lands, which `R` does not measure. A clip without a reach (a
/// library built before it existed) keeps [`stance_limits`].
pub fn jump_limits(
    p: &Prepared,
    form: LimitForm,
    absolute: &BTreeMap<String, Limits>,
    mu: Option<f64>,
    clips: &BTreeMap<String, ClipInfo>,
) -> Limits {
    let l = stance_limits(p, form, absolute, mu);
    let reach = clips.get(&p.stance.clip).and_then(|c| c.reach_m);
    match (form, reach) {
        (LimitForm::Absolute, Some(r)) if r.is_finite() => Limits {
            chi_max: l.chi_max.min(r.max(p.stance.coef.ext_max)),
            ..l
        },
        _ => l,
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

/// Why a clip's stances are left out of the queries (`--keep-left-out` keeps them).
#[derive(Debug, Clone, PartialEq)]
pub enum LeftOut {
    /// Its flights say its time base is wrong: `s_eff` outside [`S_EFF_RANGE`].
    TimeBase(f64),
    /// The same file content (SHA-256) as the named clip, first by name, which answers for
    /// both: a copy would enter every answer twice.
    Duplicate(String),
}

impl std::fmt::Display for LeftOut {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LeftOut::TimeBase(s) => write!(
                f,
                "time base wrong (s_eff {s:.3} outside [{}, {}])",
                S_EFF_RANGE.0, S_EFF_RANGE.1
            ),
            LeftOut::Duplicate(of) => write!(f, "same content as {}", crate::error::echo(of)),
        }
    }
}

/// The clips whose stances the queries leave out, and why ([`LeftOut`]); a clip both
/// copied and mistimed is named for its copy.
pub fn left_out_clips(lib: &StanceLibrary) -> BTreeMap<String, LeftOut> {
    let copies = same_content(
        lib.clips
            .iter()
            .map(|(n, c)| (n.as_str(), c.content_sha256.as_str())),
    );
    let mut out: BTreeMap<String, LeftOut> = copies
        .into_iter()
        .map(|(c, of)| (c, LeftOut::Duplicate(of)))
        .collect();
    for name in lib.clips.keys() {
        if !out.contains_key(name) && time_scaled(lib, name) {
            let s = lib.clips[name].s_eff.unwrap_or(f64::NAN);
            out.insert(name.clone(), LeftOut::TimeBase(s));
        }
    }
    out
}

/// Most clips one "left out" line names; the rest are counted.
pub const LEFT_OUT_NAMED: usize = 10;

/// The line that names the left-out clips of a query (`what`: "cycle(s)", …, with their
/// count), or `None` when nothing is left out.
pub fn left_out_line(
    command: &str,
    count: usize,
    what: &str,
    clips: &[(&String, &LeftOut)],
) -> Option<String> {
    if clips.is_empty() {
        return None;
    }
    let mut named: Vec<String> = clips
        .iter()
        .take(LEFT_OUT_NAMED)
        .map(|(c, why)| format!("{} ({why})", crate::error::echo(c)))
        .collect();
    if clips.len() > LEFT_OUT_NAMED {
        named.push(format!("and {} more", clips.len() - LEFT_OUT_NAMED));
    }
    Some(format!(
        "{command}: {count} {what} of {} clip(s) left out: {}; --keep-left-out keeps them",
        clips.len(),
        named.join(", ")
    ))
}
