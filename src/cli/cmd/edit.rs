//! `stancelib edit run` and `stancelib edit jump`: the options as typed requests, the edit
//! stage ([`crate::pipeline::edit`]), a summary on stdout. Exit 1 when some frames did not
//! converge (they are written and flagged in the plan table) or the posture leaves the
//! recorded range, a knee locks through a flight or the root jerks (`edit::fidelity`; each
//! named on stderr).

use super::super::args::{EditCommon, EditJumpArgs, EditRunArgs};
use super::super::Outcome;
use crate::edit::select::{JumpTarget, RunTarget};
use crate::pipeline::edit::{edit_jump, edit_run, EditReport, EditTarget, JumpEdit, RunEdit};

fn target(c: &EditCommon) -> EditTarget {
    EditTarget {
        lib: c.lib.clone(),
        out: c.out.clone(),
        fps: c.fps,
        source: c.source.clone(),
        allow_infeasible: c.allow_infeasible,
        limits: c.lim.options(),
    }
}

/// Run `edit run`.
///
/// # Errors
/// Bad options, an unreadable library or source, no solvable cycle, an infeasible request
/// (without `--allow-infeasible`), an unwritable output.
pub fn run(a: EditRunArgs) -> anyhow::Result<Outcome> {
    let e = RunEdit {
        target: target(&a.common),
        run: RunTarget {
            speed_mps: a.speed,
            length_scale: a.length_scale,
            mass_scale: a.mass_scale,
            stance: a.stance,
            gait_law: crate::query::gait::LawChoice::parse(&a.gait_law).unwrap_or_default(),
        },
        cycles: a.cycles,
    };
    Ok(report(&edit_run(&e)?))
}

/// Run `edit jump`.
///
/// # Errors
/// Bad options, an unreadable library or source, no solvable pair, an infeasible request
/// (without `--allow-infeasible`), an unwritable output.
pub fn run_jump(a: EditJumpArgs) -> anyhow::Result<Outcome> {
    let e = JumpEdit {
        target: target(&a.common),
        jump: JumpTarget {
            height_m: a.height,
            height_scale: a.height_scale,
            distance_m: a.distance,
            pair: a.pair,
        },
    };
    Ok(report(&edit_jump(&e)?))
}

/// Prints what was written; `SomeFailed` when frames did not converge.
fn report(r: &EditReport) -> Outcome {
    crate::cli::print_line(format_args!(
        "edit: {} frame(s) at {:.1} Hz → {} (+ {}, {})",
        r.n_frames,
        r.fps_hz,
        r.bvh.display(),
        r.plan.display(),
        r.png.display()
    ));
    for v in &r.violated {
        crate::cli::print_line(format_args!("edit: infeasible, written anyway: {v}"));
    }
    crate::cli::print_line(format_args!("edit: {}", r.fidelity));
    for u in &r.unfaithful {
        eprintln!("edit: {u}");
    }
    if r.unconverged > 0 {
        eprintln!(
            "edit: {} of {} frame(s) did not converge (COM or foot more than {} m off; column `{}`)",
            r.unconverged,
            r.n_frames,
            crate::edit::DEFAULT_COM_TOL_M,
            crate::library::schema::edit_plan::CONVERGED
        );
    }
    if r.unconverged == 0 && r.unfaithful.is_empty() {
        Outcome::Clean
    } else {
        Outcome::SomeFailed
    }
}
