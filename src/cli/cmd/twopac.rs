//! `stancelib twopac`: the 2PAC COM trajectory of a contact phase sequence (spec two-pac
//! §1.1, §4–§8): `trajectory.parquet`, `quasi_static.parquet`, `phases.parquet`,
//! `transitions.parquet`, `windows.parquet`, `validation.parquet`, `timings.json` and
//! `trajectory.png` in the output folder.
//!
//! The stage itself (clip ingest, polytopes, plan, samples, solve times, outputs) is in
//! [`crate::pipeline::commands::twopac`] and [`crate::pipeline::commands::twopac_outputs`]; this command
//! turns its options into a job, delegates and prints.

use super::super::args::TwopacArgs;
use super::super::Outcome;
use crate::math::constants::STATIC_TOL;
use crate::pipeline::commands::twopac_outputs::{run_twopac, TwopacJob, TwopacReport};
use crate::twopac::transition::QpForm;
use crate::twopac::validate::{Validation, DEFAULT_STEP_S};

/// Run `twopac`.
///
/// # Errors
/// A bad option, an unreadable or invalid phases file (exit 2, nothing written), a phase
/// sequence the core rejects (empty kinematics of a transition), an unwritable output.
pub fn run(a: TwopacArgs) -> anyhow::Result<Outcome> {
    let job = TwopacJob {
        phases: a.phases,
        clip: a.clip,
        lib: a.lib,
        character: a.character,
        form: QpForm::from(a.form),
        out: a.out,
    };
    let report = run_twopac(&job)?;
    print_summary(&report, &job);
    Ok(Outcome::Clean)
}

/// A validation's verdict in words: `2PAC curve: dynamically valid at all 591 samples …`
/// or `NOT dynamically valid (256 of 591 samples valid)`; the reasons follow on a `why:`
/// line ([`crate::twopac::diagnose::explain`]).
pub fn validation_line(name: &str, v: &Validation) -> String {
    let n = v.samples.len();
    let n_valid = v.samples.iter().filter(|s| s.valid).count();
    if v.trajectory_valid {
        format!(
            "{name}: dynamically valid at all {n} samples (every {} s, the contacts can make the force and moment its COM needs)",
            DEFAULT_STEP_S
        )
    } else {
        format!(
            "{name}: NOT dynamically valid ({n_valid} of {n} samples valid, point_valid_rate {:.3})",
            v.point_valid_rate
        )
    }
}

/// The name of the 2PAC curve in the summary.
const CURVE: &str = "2PAC curve";

/// A margin below this fraction of the body weight `m g` is reported as "on the edge of
/// the support" (0.1 %: 0.7 N for 70 kg).
pub const EDGE_MARGIN_REL: f64 = 1e-3;

/// The 2PAC curve's smallest robustness margin in words, flagged when the COM runs along
/// the edge of the support (a valid curve with no room to spare; printed for a valid
/// curve, an invalid one has its `why:` line).
fn margin_line(r: &TwopacReport) -> Option<String> {
    let (m, t, j) = r.planned.smallest_margin()?;
    let name = r.planned.phase_names.get(j).map_or("", String::as_str);
    let weight_n = r.planned.mass_kg * crate::math::constants::GRAVITY;
    let edge = if m.abs() <= EDGE_MARGIN_REL * weight_n {
        ": the COM runs along the edge of the support there (valid, no room to spare)"
    } else {
        ""
    };
    let m_shown = if m.abs() < 0.05 { 0.0 } else { m };
    Some(format!(
        "smallest robustness margin {m_shown:.1} N at {t:.2} s (phase {j} [{name}]){edge}"
    ))
}

/// The summary lines on stdout.
fn print_summary(r: &TwopacReport, job: &TwopacJob) {
    let p = &r.planned.p;
    if r.recorded {
        crate::say!(
            "  recorded COM vs 2PAC COM over the planned span: RMS {} m",
            r.rms_to_recorded_m
                .map_or("-".into(), |v| format!("{v:.4}"))
        );
    }
    let n_static = p
        .transitions
        .iter()
        .filter(|t| t.point.is_static(STATIC_TOL))
        .count();
    let n_viol: usize = p.windows.iter().map(|w| w.violations.len()).sum();
    crate::say!(
        "twopac: {} phase(s), {} transition(s) ({n_static} statically feasible), {} window(s), \
         {n_viol} kinematic guarantee violation(s); planned in {:.3} ms",
        r.phases.len(),
        p.transitions.len(),
        p.windows.len(),
        r.planned.plan_s * 1e3
    );
    for (name, v, why) in [
        (CURVE, &r.planned.v_curve, r.planned.why_curve()),
        (
            "quasi-static baseline (for comparison: it stops at every phase state and transition point)",
            &r.planned.v_qs,
            r.planned.why_qs(),
        ),
    ] {
        crate::say!("  {}", validation_line(name, v));
        if let Some(why) = why {
            crate::say!("    why: {why}");
        }
        let shown = name == CURVE && v.trajectory_valid;
        if let (true, Some(line)) = (shown, margin_line(r)) {
            crate::say!("    {line}");
        }
    }
    crate::say!("  → {}", job.out.display());
}
