//! `stancelib plot stance` and `stancelib plot clip`: delegate to
//! [`crate::pipeline::commands::plots`] and print what was drawn.

use super::super::args::{PlotClipArgs, PlotStanceArgs};
use super::super::Outcome;
use crate::pipeline::commands::plots::{plot_clip, plot_stance, StancePlotJob};

/// Run `plot stance`.
///
/// # Errors
/// An `--active-set` outside [0, 1], an unreadable library or plate file, an unknown
/// stance id (nothing is written), an unwritable output.
pub fn run_stance(a: PlotStanceArgs) -> anyhow::Result<Outcome> {
    crate::library::storage::layout::check_output_outside(&a.lib, &a.out)?;
    let job = StancePlotJob {
        lib: a.lib,
        stance: a.stance,
        plates: a.plates,
        active_set: a.active_set,
        out: a.out,
    };
    let r = plot_stance(&job)?;
    for w in &r.warnings {
        eprintln!("plot stance: {w}");
    }
    crate::say!("plot stance: {} → {}", r.stance_id, job.out.display());
    Ok(Outcome::Clean)
}

/// Run `plot clip`.
///
/// # Errors
/// An unreadable library, a clip it does not hold (nothing is written), an unwritable
/// output.
pub fn run_clip(a: PlotClipArgs) -> anyhow::Result<Outcome> {
    crate::library::storage::layout::check_output_outside(&a.lib, &a.out)?;
    let view = plot_clip(&a.lib, &a.clip, &a.out)?;
    crate::say!(
        "plot clip: {} ({} frames, {} flights) → {}",
        view.clip,
        view.time_s.len(),
        view.flights.len(),
        a.out.display()
    );
    Ok(Outcome::Clean)
}
