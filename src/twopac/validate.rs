//! Dynamic validation of a COM trajectory: the paper's Table 3 protocol (two-pac §7).
//!
//! # Model
//!
//! ```text
//! samples  t_i = t_0 + i Δ  (Δ = 0.01 s) and t_end;  active contacts: phase containing t_i
//! s*(t_i)  = min s  s.t.  G V β = w(c(t_i), c̈(t_i)),  β + s·1 ≥ 0,  s ≥ 0      (N, L̇ = 0)
//!          = max(0, −b0*)  (the margin LP of equilibrium.rs), 0 under force closure,
//!            +∞ when G V β = w has no solution (a point contact off its vertical)
//! valid    ⇔  s* ≤ 1e-6 · m g
//! ```
//!
//! Per trajectory: `point_valid_rate`, `trajectory_valid`, `max s*` and its time; per
//! scenario the mean `point_valid_rate` and the fraction of valid trajectories (the paper
//! does not say which of the two Table 3 shows, so both are reported).
//!
//! # Frames and units
//!
//! World frame, Z up; s, m, N.
//!
//! # References
//!
//! Tonneau et al., 2PAC, §6 and Table 3; spec two-pac §7.

use super::equilibrium::{EqualityForm, GRAVITY};
use super::trajectory::ComTrajectory;
use super::TwopacError;

/// Sampling step `Δ`, s.
pub const DEFAULT_STEP_S: f64 = 0.01;
/// Most samples of one validated trajectory (count): its span ÷ the step, plus one.
/// Each sample is one LP, solved five times by `twopac` (2PAC and quasi-static curves,
/// three timed repeats): 100,000 samples are 1,000 s of motion at [`DEFAULT_STEP_S`].
pub const MAX_SAMPLES: usize = 100_000;
/// A sample is valid when `s* ≤ VALID_SLACK_REL · m g`.
pub const VALID_SLACK_REL: f64 = 1e-6;

/// One validated sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time, s.
    pub t_s: f64,
    /// Active phase.
    pub phase: usize,
    /// `s*`, N (`+∞` when infeasible).
    pub slack_n: f64,
    /// `s* ≤ 1e-6 m g`.
    pub valid: bool,
}

/// Validation of one trajectory (§7 step 3).
#[derive(Debug, Clone, PartialEq)]
pub struct Validation {
    /// Every sample.
    pub samples: Vec<Sample>,
    /// Fraction of valid samples.
    pub point_valid_rate: f64,
    /// All samples valid.
    pub trajectory_valid: bool,
    /// Largest `s*`, N.
    pub max_slack_n: f64,
    /// Time of the largest `s*`, s.
    pub worst_t_s: f64,
}

/// The number of §7 samples of a span `[t0, t1]` at `step_s` (a float: it may be huge;
/// `+∞` for a span or step that is not a number).
pub fn sample_count(t0: f64, t1: f64, step_s: f64) -> f64 {
    let steps = (t1 - t0) / step_s;
    if steps.is_nan() {
        f64::INFINITY
    } else {
        steps.max(0.0).ceil() + 1.0
    }
}

/// Checks the samples of a span `[t0, t1]` at `step_s` against [`MAX_SAMPLES`].
///
/// # Errors
/// [`TwopacError::Cap`] (a span that is not finite counts as too long).
pub fn check_span(t0: f64, t1: f64, step_s: f64) -> Result<(), TwopacError> {
    let n = sample_count(t0, t1, step_s);
    if n > MAX_SAMPLES as f64 {
        let found = if n.is_finite() && n < 1e15 {
            format!("{n:.0}")
        } else {
            format!("{n:.3e}")
        };
        return Err(TwopacError::Cap {
            what: "validation samples",
            found: format!("{found} (span {:.6e} s at {step_s} s)", t1 - t0),
            max: MAX_SAMPLES,
            cap: "MAX_SAMPLES",
        });
    }
    Ok(())
}

/// The sample times of §7: every `step_s` from the start, plus the end point.
pub fn sample_times(t0: f64, t1: f64, step_s: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut k = 0usize;
    loop {
        let t = t0 + k as f64 * step_s;
        if t >= t1 - 1e-12 {
            break;
        }
        out.push(t);
        k += 1;
    }
    out.push(t1);
    out
}

/// Validate `traj` with the equality form of each phase (`forms[phase]`).
///
/// # Panics
///
/// If the trajectory reports a phase with no form (a programmer error).
pub fn validate(traj: &dyn ComTrajectory, forms: &[EqualityForm], step_s: f64) -> Validation {
    let (t0, t1) = traj.span_s();
    let mut samples = Vec::new();
    for t in sample_times(t0, t1, step_s) {
        let (state, phase) = traj.sample(t);
        let form = &forms[phase];
        let slack_n = form.validation_slack(state.pos, state.acc);
        let valid = slack_n <= VALID_SLACK_REL * form.mass_kg * GRAVITY;
        samples.push(Sample {
            t_s: t,
            phase,
            slack_n,
            valid,
        });
    }
    let n_valid = samples.iter().filter(|s| s.valid).count();
    let worst = samples
        .iter()
        .max_by(|a, b| a.slack_n.total_cmp(&b.slack_n))
        .copied();
    Validation {
        point_valid_rate: n_valid as f64 / samples.len().max(1) as f64,
        trajectory_valid: n_valid == samples.len(),
        max_slack_n: worst.map_or(0.0, |s| s.slack_n),
        worst_t_s: worst.map_or(t0, |s| s.t_s),
        samples,
    }
}

/// Scenario summary: `(mean point_valid_rate, fraction of valid trajectories)`.
pub fn summarise(runs: &[Validation]) -> (f64, f64) {
    if runs.is_empty() {
        return (0.0, 0.0);
    }
    let n = runs.len() as f64;
    (
        runs.iter().map(|r| r.point_valid_rate).sum::<f64>() / n,
        runs.iter().filter(|r| r.trajectory_valid).count() as f64 / n,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    // See: issue 11 item 6 — the samples of a span are counted before any is made.
    #[test]
    fn spans_beyond_max_samples_are_refused() {
        let step = DEFAULT_STEP_S;
        // [0, 1] s at 0.01 s: 100 steps and the end point.
        assert_eq!(
            sample_count(0.0, 1.0, step),
            sample_times(0.0, 1.0, step).len() as f64
        );
        let max_span = (MAX_SAMPLES - 1) as f64 * step;
        assert!(check_span(0.0, max_span * (1.0 - 1e-12), step).is_ok());
        assert!(check_span(0.0, 1.01 * max_span, step).is_err());
        for t1 in [1e9, f64::INFINITY, f64::NAN] {
            let e = check_span(0.0, t1, step).unwrap_err();
            assert!(e.to_string().contains("MAX_SAMPLES"), "{e}");
        }
    }
}
