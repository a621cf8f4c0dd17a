//! `stancelib edit run` and `stancelib edit jump`: the options as typed requests, the edit
//! stage ([`crate::pipeline::commands::edit`]), the verdict in the terminal. Exit codes
//! ([`crate::cli::args::EDIT_EXIT_HELP`], the same for runs and jumps): 0 feasible, converged
//! and faithful; 1 written, but some frames did not converge (flagged in the plan table) or
//! the posture leaves the recorded range, a knee locks through a flight or the root jerks
//! (`edit::fidelity`); 3 infeasible, written with `--allow-infeasible`; 2 fatal. Each
//! failure is named on stderr.

use super::super::args::{EditCommon, EditJumpArgs, EditRunArgs};
use super::super::Outcome;
use crate::edit::select::{JumpTarget, RunTarget};
use crate::pipeline::commands::edit::{
    edit_jump, edit_run, EditReport, EditTarget, JumpEdit, RunEdit,
};

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
    crate::library::storage::layout::check_output_outside(&a.common.lib, &a.common.out)?;
    let e = RunEdit {
        target: target(&a.common),
        run: RunTarget {
            speed_mps: a.speed,
            length_scale: a.length_scale,
            mass_scale: a.mass_scale,
            stance: a.stance,
            gait_law: crate::query::gait::LawChoice::parse(&a.gait_law).unwrap_or_default(),
            keep_left_out: a.common.keep_left_out,
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
    crate::library::storage::layout::check_output_outside(&a.common.lib, &a.common.out)?;
    let e = JumpEdit {
        target: target(&a.common),
        jump: JumpTarget {
            height_m: a.height,
            height_scale: a.height_scale,
            distance_m: a.distance,
            pair: a.pair,
            keep_left_out: a.common.keep_left_out,
        },
    };
    Ok(report(&edit_jump(&e)?))
}

/// Prints what was written and the verdict (stdout; failures on stderr) and decides the
/// exit code (module docs).
fn report(r: &EditReport) -> Outcome {
    crate::say!(
        "edit: {} frame(s) at {:.1} Hz → {} (+ {}, {})",
        r.n_frames,
        r.fps_hz,
        r.bvh.display(),
        r.plan.display(),
        r.png.display()
    );
    crate::say!("edit: used {}; {}", r.used, r.achieved);
    if r.feasible {
        let tight = r
            .deciding
            .first()
            .map_or(String::new(), |d| format!("; tightest {d}"));
        crate::say!("edit: feasible{tight}");
    } else {
        for d in &r.deciding {
            eprintln!("edit: infeasible, written anyway (--allow-infeasible): {d}");
        }
    }
    crate::say!("edit: {}", r.fidelity);
    for u in &r.unfaithful {
        eprintln!("edit: {u}");
    }
    if r.unconverged > 0 {
        let why = r.foot_off.map_or(String::new(), |(f, d)| {
            format!(
                "; a support foot up to {:.1} mm off, frame {f}: out of reach with the knee \
                 straight, the heel up to {}° and the pelvis turned up to {}° (the plan puts \
                 the COM farther from the contact than this body reaches)",
                d * 1e3,
                crate::edit::DEFAULT_MAX_TOE_PIVOT_DEG,
                crate::edit::DEFAULT_MAX_PELVIS_TURN_DEG
            )
        });
        eprintln!(
            "edit: {} of {} frame(s) did not converge (COM or foot more than {} m off; column \
             `{}`){why}",
            r.unconverged,
            r.n_frames,
            crate::edit::DEFAULT_COM_TOL_M,
            crate::library::codec::schema::edit_plan::CONVERGED
        );
    }
    if !r.feasible {
        Outcome::Infeasible
    } else if r.unconverged == 0 && r.unfaithful.is_empty() {
        Outcome::Clean
    } else {
        Outcome::SomeFailed
    }
}
