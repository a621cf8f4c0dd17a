//! How a runner's timing changes with speed: the gait law of `query run` and `edit run`.
//!
//! # Model
//! The paper keeps every time of a recorded run cycle and scales its horizontal forces
//! only (spec stance-model §6.8), so contact time, cadence and vertical force never change
//! with speed. Real runners shorten contact and step period as they speed up, and the
//! vertical force rises to carry the body through the shorter stance. The law anchors at
//! the recorded cycle (speed `v₀`, contact time `Δt₀`, apex-to-apex step period `T₀`) and
//! moves along power laws of speed:
//!
//! ```text
//! Δt(v) = Δt₀ (v/v₀)^(−a)        σ_c = Δt(v)/Δt₀   contact-time scale (stance lasts σ_c Δt₀)
//! T(v)  = T₀  (v/v₀)^(−b)        σ_T = T(v)/T₀     step-period scale
//! β_v   = g T(v) / (σ_c J_v)     (A3 with J̃_v = σ_c J_v: the vertical force follows)
//! ```
//!
//! `a` and `b` come from the character's own run cycles when its library holds cycles at
//! speeds at least [`MIN_SPEED_RATIO`] apart ([`LawSource::Character`], least squares of
//! `ln Δt` and `ln T` on `ln v` per clip, [`fit`]); otherwise from the population
//! exponents [`POPULATION_CONTACT_EXPONENT`] and [`POPULATION_STEP_EXPONENT`]
//! ([`LawSource::Population`]). Fitted exponents are clamped to
//! [`CONTACT_EXPONENT_RANGE`] and [`STEP_EXPONENT_RANGE`], the span seen in people
//! (a clip pair of noisy kinematic contacts can otherwise give any value).
//!
//! `a = b = 0` is the paper's policy (every time kept).
//!
//! # Units
//! Speeds m/s, times s; exponents and scales dimensionless.
//!
//! # References
//! `docs/stance-model.md` §6.8a (the law, how the population exponents were chosen and
//! their held-out errors against the force plates); Cavagna, Heglund & Willems (2005, J
//! Exp Biol 208:2333), Weyand et al. (2000, J Appl Physiol 89:1991) and Nilsson &
//! Thorstensson (1989, Acta Physiol Scand 136:217) for the trends.

/// Population exponent `a` of the contact time, `Δt ∝ v^(−a)` (2–5 m/s running).
pub const POPULATION_CONTACT_EXPONENT: f64 = 0.42;
/// Population exponent `b` of the step period, `T ∝ v^(−b)` (2–5 m/s running).
pub const POPULATION_STEP_EXPONENT: f64 = 0.19;
/// The range a character's fitted `a` is clamped to.
pub const CONTACT_EXPONENT_RANGE: (f64, f64) = (0.2, 1.0);
/// The range a character's fitted `b` is clamped to.
pub const STEP_EXPONENT_RANGE: (f64, f64) = (0.0, 0.5);
/// Smallest ratio between a character's slowest and fastest clip speed for a fit of its
/// own (below it the speeds say nothing about the exponents).
pub const MIN_SPEED_RATIO: f64 = 1.2;

/// Where a law's exponents come from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LawSource {
    /// The population exponents (the character has one speed).
    Population,
    /// Fitted on the character's own cycles: how many clips, their speed range (m/s).
    Character {
        /// Clips (speeds) in the fit.
        clips: usize,
        /// Slowest clip speed, m/s.
        v_min: f64,
        /// Fastest clip speed, m/s.
        v_max: f64,
    },
    /// Every time kept (the paper's §6.8 policy, `--gait-law paper`).
    Paper,
}

impl LawSource {
    /// `population`, `character` or `paper`: the value of the tables' `gait_law` column.
    pub fn name(&self) -> &'static str {
        match self {
            LawSource::Population => "population",
            LawSource::Character { .. } => "character",
            LawSource::Paper => "paper",
        }
    }
}

/// The exponents of one character's gait law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaitLaw {
    /// `a` in `Δt ∝ v^(−a)`.
    pub contact_exponent: f64,
    /// `b` in `T ∝ v^(−b)`.
    pub step_exponent: f64,
    /// Where they come from.
    pub source: LawSource,
}

impl GaitLaw {
    /// The population law.
    pub const POPULATION: GaitLaw = GaitLaw {
        contact_exponent: POPULATION_CONTACT_EXPONENT,
        step_exponent: POPULATION_STEP_EXPONENT,
        source: LawSource::Population,
    };

    /// The paper's policy: every time kept.
    pub const PAPER: GaitLaw = GaitLaw {
        contact_exponent: 0.0,
        step_exponent: 0.0,
        source: LawSource::Paper,
    };

    /// `(σ_c, σ_T)`: the contact-time and step-period scales from a cycle recorded at `v0`
    /// to speed `v` (both m/s, `v0 > 0`). `v = 0` gives `(+∞, +∞)` under a non-paper law:
    /// a run at rest has no cycle (the caller reports it).
    pub fn time_scales(&self, v0: f64, v: f64) -> (f64, f64) {
        let r = v / v0;
        (r.powf(-self.contact_exponent), r.powf(-self.step_exponent))
    }
}

/// Which law a query uses (`--gait-law`, pipeline `[queries] gait_law`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LawChoice {
    /// The character's own law when its cycles span speeds, else the population law.
    #[default]
    Auto,
    /// The population law for every character.
    Population,
    /// The paper's policy (every time kept, `β_v = 1`).
    Paper,
}

impl LawChoice {
    /// The accepted names, for messages.
    pub const NAMES: &'static str = "auto, population or paper";

    /// `auto`, `population` or `paper`; `None` otherwise.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "auto" => Some(LawChoice::Auto),
            "population" => Some(LawChoice::Population),
            "paper" => Some(LawChoice::Paper),
            _ => None,
        }
    }

    /// The name `parse` reads.
    pub fn name(self) -> &'static str {
        match self {
            LawChoice::Auto => "auto",
            LawChoice::Population => "population",
            LawChoice::Paper => "paper",
        }
    }

    /// The law of a character whose clips are `clips`.
    pub fn law(self, clips: &[ClipGait]) -> GaitLaw {
        match self {
            LawChoice::Auto => fit(clips),
            LawChoice::Population => GaitLaw::POPULATION,
            LawChoice::Paper => GaitLaw::PAPER,
        }
    }
}

/// One clip's run cycles summarised for the fit: its mean speed, contact time and step
/// period (medians over its cycles' stances).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClipGait {
    /// Mean speed, m/s.
    pub speed: f64,
    /// Contact time, s.
    pub contact_s: f64,
    /// Apex-to-apex step period, s.
    pub step_s: f64,
}

/// The least-squares slope of `y` on `x` (`None` without spread in `x`).
fn slope(x: &[f64], y: &[f64]) -> Option<f64> {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// A character's own law from its clips (one [`ClipGait`] each), or the population law
/// when they do not span [`MIN_SPEED_RATIO`]:
///
/// ```text
/// a = −slope(ln Δt_i, ln v_i),  b = −slope(ln T_i, ln v_i),  clamped to the ranges
/// ```
pub fn fit(clips: &[ClipGait]) -> GaitLaw {
    let ok: Vec<&ClipGait> = clips
        .iter()
        .filter(|c| {
            [c.speed, c.contact_s, c.step_s]
                .iter()
                .all(|v| v.is_finite() && *v > 0.0)
        })
        .collect();
    let v_min = ok.iter().map(|c| c.speed).fold(f64::INFINITY, f64::min);
    let v_max = ok.iter().map(|c| c.speed).fold(0.0, f64::max);
    if ok.len() < 2 || v_max < MIN_SPEED_RATIO * v_min {
        return GaitLaw::POPULATION;
    }
    let lv: Vec<f64> = ok.iter().map(|c| c.speed.ln()).collect();
    let lc: Vec<f64> = ok.iter().map(|c| c.contact_s.ln()).collect();
    let lt: Vec<f64> = ok.iter().map(|c| c.step_s.ln()).collect();
    let clamp = |v: Option<f64>, r: (f64, f64), d: f64| v.map_or(d, |v| v.clamp(r.0, r.1));
    GaitLaw {
        contact_exponent: clamp(
            slope(&lv, &lc).map(|s| -s),
            CONTACT_EXPONENT_RANGE,
            POPULATION_CONTACT_EXPONENT,
        ),
        step_exponent: clamp(
            slope(&lv, &lt).map(|s| -s),
            STEP_EXPONENT_RANGE,
            POPULATION_STEP_EXPONENT,
        ),
        source: LawSource::Character {
            clips: ok.len(),
            v_min,
            v_max,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fit_recovers_the_exponents_of_a_power_law() {
        let clips: Vec<ClipGait> = [2.0, 3.0, 4.0, 5.0]
            .iter()
            .map(|&v: &f64| ClipGait {
                speed: v,
                contact_s: 0.6 * v.powf(-0.7),
                step_s: 0.45 * v.powf(-0.15),
            })
            .collect();
        let law = fit(&clips);
        assert!((law.contact_exponent - 0.7).abs() < 1e-12);
        assert!((law.step_exponent - 0.15).abs() < 1e-12);
        assert_eq!(law.source.name(), "character");
        let (sc, st) = law.time_scales(2.0, 4.0);
        assert!((sc - 2f64.powf(-0.7)).abs() < 1e-12 && (st - 2f64.powf(-0.15)).abs() < 1e-12);
    }

    #[test]
    fn one_speed_or_a_narrow_span_gives_the_population_law() {
        let c = |v: f64| ClipGait {
            speed: v,
            contact_s: 0.3,
            step_s: 0.35,
        };
        assert_eq!(fit(&[c(3.0)]), GaitLaw::POPULATION);
        assert_eq!(fit(&[c(3.0), c(3.3)]), GaitLaw::POPULATION);
        assert_eq!(fit(&[c(3.0), c(f64::NAN)]), GaitLaw::POPULATION);
        // Equal contact times at 3 and 4 m/s: a = 0, clamped up to the range's floor.
        let law = fit(&[c(3.0), c(4.0)]);
        assert_eq!(law.contact_exponent, CONTACT_EXPONENT_RANGE.0);
    }

    #[test]
    fn the_paper_law_keeps_every_time() {
        assert_eq!(GaitLaw::PAPER.time_scales(3.0, 6.0), (1.0, 1.0));
    }
}
