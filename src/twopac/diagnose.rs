//! Why a trajectory fails its dynamic validation (§7), in words: each invalid sample is
//! given a cause, and the causes are summed up per trajectory.
//!
//! # Model
//!
//! ```text
//! invalid sample (c, c̈) of phase j (s* > 1e-6 m g, validate.rs):
//!   no force     s* = ∞: no force distribution of the contacts makes w(c, c̈) at all
//!                (a point or line contact with the COM off its vertical or plane)
//!   off support  c is not in static equilibrium on phase j's contacts (c̈ = 0 fails too):
//!                the COM is outside the region where they hold it at rest; detail: the
//!                distance to the nearest statically held COM (eq 13 without kinematics), m
//!   too fast     c is held at rest, but not with its acceleration; detail: |c̈|, m/s²
//! ```
//!
//! `s*` (N) reads as a pull: the contacts make the wrench only if a friction-cone edge
//! may carry a force down to `−s*`, i.e. a contact pulls on the ground (or wall) with up
//! to `s*` newtons.
//!
//! # Frames and units
//!
//! World frame, Z up; s, m, m/s², N.
//!
//! # References
//!
//! Spec two-pac §4 (eq 13), §7 (Table 3 protocol).

use super::equilibrium::EqualityForm;
use super::polytope::Polytope;
use super::trajectory::ComTrajectory;
use super::transition::{transition_eq13, TransitionOptions};
use super::v3::{norm, sub};
use super::validate::Validation;
use crate::math::constants::STATIC_TOL;

/// Why one sample fails the dynamic validation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Cause {
    /// No force distribution of the active contacts makes the wrench at all.
    NoForce,
    /// The COM is outside the region where the active contacts hold it at rest.
    OffSupport,
    /// The contacts hold the COM at rest there, but not with its acceleration.
    TooFast,
}

impl Cause {
    /// Every cause, in the order the summaries list them.
    pub const ALL: [Cause; 3] = [Cause::OffSupport, Cause::TooFast, Cause::NoForce];

    /// What the cause means, in words.
    pub fn describe(self) -> &'static str {
        match self {
            Cause::NoForce => "no contact force can make the needed wrench (a point or line contact with the COM off its vertical)",
            Cause::OffSupport => "the COM is outside the region where the active contacts hold it at rest",
            Cause::TooFast => "the contacts hold the COM at rest there but not with its acceleration",
        }
    }

    /// A short name (tables, legends).
    pub fn as_str(self) -> &'static str {
        match self {
            Cause::NoForce => "no_force",
            Cause::OffSupport => "off_support",
            Cause::TooFast => "too_fast",
        }
    }
}

/// One invalid sample and its cause.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Failure {
    /// Sample time, s.
    pub t_s: f64,
    /// Active phase.
    pub phase: usize,
    /// Why it fails.
    pub cause: Cause,
    /// Off support: distance to the nearest statically held COM, m (`NaN` when there is
    /// none); too fast: `|c̈|`, m/s²; no force: `NaN`.
    pub detail: f64,
}

/// The cause of an invalid sample at COM `c`, acceleration `acc`, on `form`, with its
/// detail (see [`Failure::detail`]).
pub fn cause_of(form: &EqualityForm, c: [f64; 3], acc: [f64; 3], slack_n: f64) -> (Cause, f64) {
    if !slack_n.is_finite() {
        return (Cause::NoForce, f64::NAN);
    }
    if form.verdict(c, [0.0; 3]).in_equilibrium {
        return (Cause::TooFast, norm(acc));
    }
    let nearest = transition_eq13(form, &Polytope::default(), c, &TransitionOptions::default());
    let distance = match nearest {
        Ok(p) if p.is_static(STATIC_TOL) => norm(sub(p.com, c)),
        _ => f64::NAN,
    };
    (Cause::OffSupport, distance)
}

/// Every invalid sample of `v` (a validation of `traj` with `forms`) with its cause.
pub fn failures(traj: &dyn ComTrajectory, forms: &[EqualityForm], v: &Validation) -> Vec<Failure> {
    v.samples
        .iter()
        .filter(|s| !s.valid)
        .map(|s| {
            let (state, _) = traj.sample(s.t_s);
            let (cause, detail) = cause_of(&forms[s.phase], state.pos, state.acc, s.slack_n);
            Failure {
                t_s: s.t_s,
                phase: s.phase,
                cause,
                detail,
            }
        })
        .collect()
}

/// A phase list as text: `1 [right_foot], 3 [left_foot]`, at most [`MAX_LISTED`] phases.
fn phase_list(mut phases: Vec<usize>, names: &[String]) -> String {
    phases.sort_unstable();
    phases.dedup();
    let shown: Vec<String> = phases
        .iter()
        .take(MAX_LISTED)
        .map(|&j| match names.get(j) {
            Some(n) => format!("{j} [{n}]"),
            None => j.to_string(),
        })
        .collect();
    let more = phases.len().saturating_sub(MAX_LISTED);
    let tail = if more > 0 {
        format!(" and {more} more")
    } else {
        String::new()
    };
    format!("{}{tail}", shown.join(", "))
}

/// Most phases a summary lists by name.
pub const MAX_LISTED: usize = 4;

/// Why a validated trajectory is not valid, in words (`None` when it is valid):
/// per cause, how many samples, how far or how fast at worst, in which phases (named by
/// `phase_names`, the effectors of each phase); then the worst sample.
pub fn explain(v: &Validation, failures: &[Failure], phase_names: &[String]) -> Option<String> {
    if v.trajectory_valid {
        return None;
    }
    let mut parts = Vec::new();
    for cause in Cause::ALL {
        let mine: Vec<&Failure> = failures.iter().filter(|f| f.cause == cause).collect();
        if mine.is_empty() {
            continue;
        }
        let worst = mine
            .iter()
            .map(|f| f.detail)
            .filter(|d| d.is_finite())
            .fold(f64::NAN, f64::max);
        let how = match cause {
            Cause::OffSupport if worst.is_finite() => {
                format!(", up to {:.1} cm outside", 100.0 * worst)
            }
            Cause::TooFast if worst.is_finite() => format!(", |c̈| up to {worst:.1} m/s²"),
            _ => String::new(),
        };
        parts.push(format!(
            "{} sample(s): {}{how} (phases {})",
            mine.len(),
            cause.describe(),
            phase_list(mine.iter().map(|f| f.phase).collect(), phase_names)
        ));
    }
    let worst = v
        .samples
        .iter()
        .max_by(|a, b| a.slack_n.total_cmp(&b.slack_n));
    let worst = worst.map_or(String::new(), |s| {
        let name = phase_names.get(s.phase).map_or("", String::as_str);
        format!(
            "; worst at {:.2} s (phase {} [{name}]): a contact would have to pull with s* = {:.1} N",
            s.t_s, s.phase, s.slack_n
        )
    });
    Some(format!(
        "{} of {} samples fail: {}{worst}",
        failures.len(),
        v.samples.len(),
        parts.join("; ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::twopac::contact::{Contact, ContactShape};

    fn foot() -> EqualityForm {
        // One 0.2 × 0.1 m flat foot at the origin, μ = 0.7, 70 kg.
        let c = Contact::new(
            "right_foot",
            [0.0; 3],
            [0.0, 0.0, 1.0],
            0.7,
            0.0,
            ContactShape::Rectangle {
                length_m: 0.2,
                width_m: 0.1,
            },
        )
        .unwrap();
        EqualityForm::new(&[c], 70.0).unwrap()
    }

    #[test]
    fn causes_tell_off_support_from_too_fast() {
        let f = foot();
        // 5 cm beside the foot's edge (y = 0.05): off support by 5 cm, whatever c̈.
        let (cause, d) = cause_of(&f, [0.0, 0.1, 0.9], [0.0; 3], 10.0);
        assert_eq!(cause, Cause::OffSupport);
        assert!((d - 0.05).abs() < 1e-4, "{d}");
        // Above the foot's centre but accelerating sideways at 3 m/s²: the centre of
        // pressure y = −z c̈_y/g ≈ −0.28 m is off the foot: too fast.
        let (cause, a) = cause_of(&f, [0.0, 0.0, 0.9], [0.0, 3.0, 0.0], 10.0);
        assert_eq!(cause, Cause::TooFast);
        assert!((a - 3.0).abs() < 1e-12);
        assert_eq!(
            cause_of(&f, [0.0; 3], [0.0; 3], f64::INFINITY).0,
            Cause::NoForce
        );
    }
}
