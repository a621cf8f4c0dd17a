//! Default constraint limits per character (spec stance-model §7.5).
//!
//! # Model
//! ```text
//! μ = 0.7
//! F_max = 1.05 · max F_peak,   χ_max = 1.05 · max ext_max,   χ_min = min ext_min / 1.05
//! over the character's eligible stances; with fewer than 20, over every eligible stance of
//! the library scaled to the character (F_peak by M = m_char/m_s, ext by L = L_char/L_s).
//! eligible: no `unsupported` boundary, and the clip's s_eff is null or within [0.9, 1.1]
//! ```

use std::collections::BTreeMap;

use serde::Serialize;

use super::segment::Boundary;
use super::Stance;

/// What the limits need of one stance (from a `Stance` or a `stances.parquet` row).
#[derive(Debug, Clone, PartialEq)]
pub struct StanceFacts {
    /// Clip name.
    pub clip: String,
    /// Character id.
    pub character_id: String,
    /// Body mass, kg.
    pub mass_kg: f64,
    /// Original peak force, N.
    pub f_peak: f64,
    /// Original smallest COM–contact distance, m.
    pub ext_min: f64,
    /// Original largest COM–contact distance, m.
    pub ext_max: f64,
    /// An `unsupported` boundary on either side.
    pub unsupported: bool,
}

impl From<&Stance> for StanceFacts {
    fn from(s: &Stance) -> Self {
        StanceFacts {
            clip: s.clip.clone(),
            character_id: s.character_id.clone(),
            mass_kg: s.mass_kg,
            f_peak: s.coef.f_peak,
            ext_min: s.coef.ext_min,
            ext_max: s.coef.ext_max,
            unsupported: s.boundary_start == Boundary::Unsupported
                || s.boundary_end == Boundary::Unsupported,
        }
    }
}

/// Absolute friction limit (the crate-wide default μ).
pub use crate::math::constants::DEFAULT_MU;
/// Margin on the extremes of the example stances.
pub const MARGIN: f64 = 1.05;
/// Below this many eligible stances a character uses the library-wide values.
pub const MIN_CHARACTER_STANCES: usize = 20;
/// Clips whose effective time scale lies outside this range do not set limits.
pub const S_EFF_RANGE: (f64, f64) = (0.9, 1.1);

/// The build-time record of one character's limits, as the manifest stores them: the
/// checked values (μ, `F_max`, `χ_min`, `χ_max`; the queries check them as
/// `query::feasibility::Limits`, converted by `From`) and where they came from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CharacterLimits {
    /// Friction coefficient.
    pub mu: f64,
    /// Force limit, N.
    pub f_max_n: f64,
    /// Smallest COM–contact distance, m.
    pub chi_min_m: f64,
    /// Largest COM–contact distance, m.
    pub chi_max_m: f64,
    /// Eligible stances of the character.
    pub n_stances: usize,
    /// `character` or `library` (fewer than 20 stances).
    pub source: String,
}

/// Per-stance facts the limits need: the clip's `s_eff` and leg length.
pub struct ClipFacts {
    /// Effective time scale of the clip.
    pub s_eff: Option<f64>,
    /// Leg length, m.
    pub leg_m: f64,
}

fn eligible(s: &StanceFacts, clip: Option<&ClipFacts>) -> bool {
    let unsupported = s.unsupported;
    let s_eff_ok = clip
        .and_then(|c| c.s_eff)
        .is_none_or(|v| (S_EFF_RANGE.0..=S_EFF_RANGE.1).contains(&v));
    !unsupported && s_eff_ok
}

/// Limits per `character_id` (sorted map, deterministic).
pub fn limits(
    stances: &[StanceFacts],
    clips: &BTreeMap<String, ClipFacts>,
) -> BTreeMap<String, CharacterLimits> {
    let ok: Vec<&StanceFacts> = stances
        .iter()
        .filter(|s| eligible(s, clips.get(&s.clip)))
        .collect();
    let leg = |s: &StanceFacts| clips.get(&s.clip).map_or(1.0, |c| c.leg_m);
    let mut chars: BTreeMap<String, (f64, f64)> = BTreeMap::new(); // character → (mass, leg)
    for s in stances {
        chars
            .entry(s.character_id.clone())
            .or_insert((s.mass_kg, leg(s)));
    }
    chars
        .into_iter()
        .map(|(id, (mass, leg_c))| {
            let own: Vec<&StanceFacts> = ok
                .iter()
                .copied()
                .filter(|s| s.character_id == id)
                .collect();
            // Library-wide values are scaled to the character: force by M, lengths by L.
            let (pool, scale, source) = if own.len() >= MIN_CHARACTER_STANCES {
                (&own, None, "character")
            } else {
                (&ok, Some((mass, leg_c)), "library")
            };
            let m_scale = |s: &StanceFacts| scale.map_or(1.0, |(m, _)| m / s.mass_kg);
            let l_scale = |s: &StanceFacts| scale.map_or(1.0, |(_, l)| l / leg(s));
            let f_peak = pool
                .iter()
                .map(|s| s.f_peak * m_scale(s))
                .fold(0.0, f64::max);
            let ext_max = pool
                .iter()
                .map(|s| s.ext_max * l_scale(s))
                .fold(0.0, f64::max);
            let ext_min = pool
                .iter()
                .map(|s| s.ext_min * l_scale(s))
                .fold(f64::INFINITY, f64::min);
            let lim = CharacterLimits {
                mu: DEFAULT_MU,
                f_max_n: MARGIN * f_peak,
                chi_min_m: if ext_min.is_finite() {
                    ext_min / MARGIN
                } else {
                    0.0
                },
                chi_max_m: MARGIN * ext_max,
                n_stances: own.len(),
                source: source.to_string(),
            };
            (id, lim)
        })
        .collect()
}
