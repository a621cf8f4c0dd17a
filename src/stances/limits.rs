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
    /// Stances these facts stand for: 1 for one stance; [`group_facts`] folds a clip's
    /// stances of one mass and support into one entry (largest `f_peak` and `ext_max`,
    /// smallest `ext_min`).
    pub count: usize,
}

/// `facts` with the stances of one clip, character, mass and support folded into one
/// entry each, in the order of their first stance: the limits of [`limits`] are the same,
/// bit for bit (each is a largest or smallest value times a factor that depends only on
/// the clip and the mass, and rounding keeps the order of products by one positive
/// factor), and a build keeps one entry a clip instead of one a stance. That needs a
/// positive mass and leg length, as the ingest gives them; a stance whose mass is not
/// finite and positive keeps an entry of its own.
pub fn group_facts(facts: Vec<StanceFacts>) -> Vec<StanceFacts> {
    let mut out: Vec<StanceFacts> = Vec::new();
    let mut at: std::collections::HashMap<(String, String, u64, bool), usize> =
        std::collections::HashMap::new();
    for f in facts {
        if !(f.mass_kg.is_finite() && f.mass_kg > 0.0) {
            out.push(f);
            continue;
        }
        let key = (
            f.clip.clone(),
            f.character_id.clone(),
            f.mass_kg.to_bits(),
            f.unsupported,
        );
        match at.get(&key) {
            Some(&i) => {
                let g = &mut out[i];
                g.f_peak = g.f_peak.max(f.f_peak);
                g.ext_max = g.ext_max.max(f.ext_max);
                g.ext_min = g.ext_min.min(f.ext_min);
                g.count += f.count;
            }
            None => {
                at.insert(key, out.len());
                out.push(f);
            }
        }
    }
    out
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
            count: 1,
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
            let n_own: usize = own.iter().map(|s| s.count).sum();
            let (pool, scale, source) = if n_own >= MIN_CHARACTER_STANCES {
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
                n_stances: n_own,
                source: source.to_string(),
            };
            (id, lim)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::Rng;

    /// Stances of `clips` clips of three characters (one with fewer than 20 stances), some
    /// unsupported, masses per clip, values in any order.
    fn facts(rng: &mut Rng, clips: usize) -> (Vec<StanceFacts>, BTreeMap<String, ClipFacts>) {
        let mut f = Vec::new();
        let mut c = BTreeMap::new();
        for k in 0..clips {
            let clip = format!("clip_{k}");
            let character = ["a", "b", "c"][k % 3].to_string();
            let mass = rng.uniform(50.0, 90.0);
            let n = if character == "c" {
                2
            } else {
                rng.int(3, 12) as usize
            };
            for _ in 0..n {
                f.push(StanceFacts {
                    clip: clip.clone(),
                    character_id: character.clone(),
                    mass_kg: mass,
                    f_peak: rng.uniform(600.0, 2500.0),
                    ext_min: rng.uniform(0.6, 0.9),
                    ext_max: rng.uniform(0.9, 1.2),
                    unsupported: rng.next_f64() < 0.2,
                    count: 1,
                });
            }
            let s_eff = [None, Some(1.0), Some(1.3)][rng.int(0, 2) as usize];
            let leg_m = rng.uniform(0.8, 1.0);
            c.insert(clip, ClipFacts { s_eff, leg_m });
        }
        (f, c)
    }

    #[test]
    fn limits_of_grouped_facts_are_those_of_every_stance_bit_for_bit() {
        let mut rng = Rng::new(0x0001_157a);
        for clips in [1, 4, 9, 30] {
            let (f, c) = facts(&mut rng, clips);
            let n = f.len();
            let grouped = group_facts(f.clone());
            assert!(
                grouped.len() <= 2 * clips && grouped.len() < n,
                "{clips} clips"
            );
            assert_eq!(grouped.iter().map(|g| g.count).sum::<usize>(), n);
            let (a, b) = (limits(&f, &c), limits(&grouped, &c));
            assert_eq!(a.len(), b.len());
            for ((ka, la), (kb, lb)) in a.iter().zip(&b) {
                assert_eq!(ka, kb);
                assert_eq!(la.n_stances, lb.n_stances);
                assert_eq!(la.source, lb.source);
                for (x, y) in [
                    (la.f_max_n, lb.f_max_n),
                    (la.chi_min_m, lb.chi_min_m),
                    (la.chi_max_m, lb.chi_max_m),
                ] {
                    assert_eq!(x.to_bits(), y.to_bits(), "{ka}: {la:?} vs {lb:?}");
                }
            }
        }
    }
}
