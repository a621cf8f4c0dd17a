//! Default constraint limits per character (spec stance-model §7.5, with the bounds of a
//! person's legs: a departure, `docs/stance-model.md` §7.5).
//!
//! # Model
//! ```text
//! μ = 0.7
//! F_max = min(max(1.05 · max F_peak, 3.5 m g), 6 m g)    over the eligible stances
//! χ_max = 1.5 L_leg,   χ_min = 0.5 L_leg                  (what a leg reaches; a jump's
//!                                                         χ_max stops at the body's reach,
//!                                                         `query::limits::jump_limits`)
//! source: `character` when its own stances set F_max, `size` when the floor did
//! eligible: locomotion on the feet (no hand in the label, no `unsupported` boundary), and
//! the clip's s_eff is null or within [0.9, 1.1]
//! ```
//! A query checks a stance against `max(character limit, the stance's own recorded
//! extreme)` (`query::limits`): what the person did is possible for the person, so every
//! recorded stance is feasible as recorded, and a stance that did less than its character
//! can do has room to do more.

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
    /// A hand supports the stance (label with `LH`/`RH`): not locomotion on the feet.
    pub hands: bool,
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
    let mut at: std::collections::HashMap<(String, String, u64, (bool, bool)), usize> =
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
            (f.unsupported, f.hands),
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
            hands: s.label.contains('H'),
            count: 1,
        }
    }
}

/// Absolute friction limit (the crate-wide default μ).
pub use crate::math::constants::DEFAULT_MU;
/// Margin on the extremes of the example stances.
pub const MARGIN: f64 = 1.05;
/// No character's force limit exceeds this many body weights (a stance above it is named
/// by `info`, [`beyond_bounds`]).
pub const F_MAX_CAP_BW: f64 = 6.0;
/// `χ_max` of every character, leg lengths: what a leg reaches (the locomotion stances'
/// median is 1.16, their 95th percentile 1.64 with climbing and hanging; a runner's stance
/// at 4 m/s reaches 1.33 on the force plates, and the same runner asked to run faster
/// needs more).
pub const CHI_MAX_CAP_LEG: f64 = 1.5;
/// `χ_min` of every character, leg lengths (the locomotion stances' 1st percentile is
/// 0.64).
pub const CHI_MIN_FLOOR_LEG: f64 = 0.5;
/// The force limit's floor, body weights: the capacity a person has beyond what a short
/// recording shows (about the 99th percentile of the locomotion stances' peak force in the
/// shared and bulk sets, 3.4; running stances on the plates reach 2.2–2.8). A runner
/// recorded at 4 m/s (1.05 × its own peak: 2.7 body weights) could otherwise not be asked
/// for 5 m/s.
pub const POPULATION_F_MAX_BW: f64 = 3.5;
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
    /// `character` when its own stances set `F_max`, `size` when the floor of
    /// [`POPULATION_F_MAX_BW`] body weights did.
    pub source: String,
}

/// Per-stance facts the limits need: the clip's `s_eff` and leg length.
pub struct ClipFacts {
    /// Effective time scale of the clip.
    pub s_eff: Option<f64>,
    /// Leg length, m.
    pub leg_m: f64,
}

/// Why a foot stance lies beyond what a person's legs do (peak force above
/// [`F_MAX_CAP_BW`] body weights, COM–contact distance above [`CHI_MAX_CAP_LEG`] leg
/// lengths), or `None`. `f_peak` N, `mass` kg, `ext_max` and `leg` m.
pub fn beyond_bounds(f_peak: f64, mass: f64, ext_max: f64, leg: f64) -> Option<String> {
    let bw = f_peak / (mass * crate::math::constants::GRAVITY);
    let ext = ext_max / leg;
    let mut why = Vec::new();
    if bw > F_MAX_CAP_BW {
        why.push(format!("peak force {bw:.1} body weights > {F_MAX_CAP_BW}"));
    }
    if ext > CHI_MAX_CAP_LEG {
        why.push(format!(
            "COM–contact {ext:.2} leg lengths > {CHI_MAX_CAP_LEG}"
        ));
    }
    (!why.is_empty()).then(|| why.join(", "))
}

fn eligible(s: &StanceFacts, clip: Option<&ClipFacts>) -> bool {
    let s_eff_ok = clip
        .and_then(|c| c.s_eff)
        .is_none_or(|v| (S_EFF_RANGE.0..=S_EFF_RANGE.1).contains(&v));
    !s.unsupported && !s.hands && s_eff_ok
}

/// One character's limits from its eligible stances `own` (see the module docs); `mass`
/// in kg, `leg` in m.
fn character_limits(own: &[&StanceFacts], mass: f64, leg: f64) -> CharacterLimits {
    let n_own: usize = own.iter().map(|s| s.count).sum();
    let bw = mass * crate::math::constants::GRAVITY;
    let f_own = MARGIN * own.iter().map(|s| s.f_peak).fold(0.0, f64::max);
    let f_floor = POPULATION_F_MAX_BW * bw;
    CharacterLimits {
        mu: DEFAULT_MU,
        f_max_n: f_own.max(f_floor).min(F_MAX_CAP_BW * bw),
        chi_min_m: CHI_MIN_FLOOR_LEG * leg,
        chi_max_m: CHI_MAX_CAP_LEG * leg,
        n_stances: n_own,
        source: if f_own > f_floor { "character" } else { "size" }.to_string(),
    }
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
            let lim = character_limits(&own, mass, leg_c);
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
                    hands: rng.next_f64() < 0.1,
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
                grouped.len() <= 4 * clips && grouped.len() < n,
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

    fn fact(character: &str, mass: f64, f_peak: f64, ext: (f64, f64), hands: bool) -> StanceFacts {
        StanceFacts {
            clip: format!("{character}_clip"),
            character_id: character.into(),
            mass_kg: mass,
            f_peak,
            ext_min: ext.0,
            ext_max: ext.1,
            unsupported: false,
            hands,
            count: 1,
        }
    }

    // Issue 37 item 4: a person's limits: outliers capped by body weight and leg length,
    // hand-supported stances left out, a character with few stances limited by its own
    // size whatever the other characters did.
    #[test]
    fn limits_are_a_persons() {
        let (m, leg) = (70.0, 0.9);
        let bw = m * crate::math::constants::GRAVITY;
        let mut f: Vec<StanceFacts> = (0..30)
            .map(|i| fact("a", m, (1.5 + 0.02 * i as f64) * bw, (0.8, 1.1), false))
            .collect();
        f.push(fact("a", m, 8.0 * bw, (0.8, 1.2), false)); // a clip-edge artefact
        f.extend((0..30).map(|i| fact("c", m, (3.6 + 0.01 * i as f64) * bw, (0.8, 1.1), false)));
        f.extend((0..25).map(|_| fact("d", m, 2.0 * bw, (0.8, 1.1), false)));
        f.push(fact("d", m, 5.5 * bw, (0.1, 4.0), true)); // hanging from a bar
        f.push(fact("b", 50.0, 2.0 * 50.0 * 9.81, (0.7, 1.0), false));
        let clips: BTreeMap<String, ClipFacts> = ["a_clip", "b_clip", "c_clip", "d_clip"]
            .iter()
            .map(|c| {
                (
                    c.to_string(),
                    ClipFacts {
                        s_eff: None,
                        leg_m: leg,
                    },
                )
            })
            .collect();
        let l = limits(&f, &clips);
        let close = |x: f64, y: f64| (x - y).abs() < 1e-9 * y.abs().max(1.0);
        // An artefact beyond 6 body weights caps its character there.
        let a = &l["a"];
        assert_eq!((a.source.as_str(), a.n_stances), ("character", 31));
        assert!(close(a.f_max_n, F_MAX_CAP_BW * bw), "capped at 6 BW: {a:?}");
        // A strong character's own stances set its force limit.
        let c = &l["c"];
        assert_eq!(c.source, "character");
        assert!(close(c.f_max_n, MARGIN * 3.89 * bw), "{c:?}");
        // A hand-supported stance does not count; the floor of a person's capacity does.
        let d = &l["d"];
        assert_eq!((d.source.as_str(), d.n_stances), ("size", 25));
        assert!(close(d.f_max_n, POPULATION_F_MAX_BW * bw), "{d:?}");
        // Extension limits are the leg's bounds, whatever the stances (the bar's 4 m too).
        for x in [a, c, d] {
            assert!(
                close(x.chi_max_m, CHI_MAX_CAP_LEG * leg)
                    && close(x.chi_min_m, CHI_MIN_FLOOR_LEG * leg)
            );
        }
        let b = l["b"].clone();
        assert_eq!((b.source.as_str(), b.n_stances), ("size", 1));
        let bw_b = 50.0 * crate::math::constants::GRAVITY;
        assert!(close(b.f_max_n, POPULATION_F_MAX_BW * bw_b), "{b:?}");
        // Another character's extremes never reach b.
        f.push(fact("a", m, 5.9 * bw, (0.3, 1.45), false));
        assert_eq!(limits(&f, &clips)["b"], b);
        assert!(beyond_bounds(8.0 * bw, m, 1.0, leg).is_some());
        assert!(beyond_bounds(2.0 * bw, m, 1.0, leg).is_none());
    }
}
