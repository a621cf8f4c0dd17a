//! `stancelib list LIB`: a catalogue of what a library holds (see
//! [`crate::pipeline::commands::catalogue`]): characters, recorded run cycles, recorded jumps, as
//! text or, with `--json`, one JSON object.
//!
//! A command of its own rather than sections of `info`: `info` reads a few columns and
//! counts them, while the catalogue opens every stance and runs the run query on each
//! cycle; and `info --json`'s keys stay as they are.

use anyhow::Context;

use super::super::args::ListArgs;
use super::super::Outcome;
use crate::pipeline::commands::catalogue::{read_catalogue, Catalogue};

/// Clip names shown per character in the text (`--json` lists all).
pub const CLIPS_SHOWN: usize = 3;

/// Run `list`.
///
/// # Errors
/// A missing or malformed library (the error names the file).
pub fn run(a: ListArgs) -> anyhow::Result<Outcome> {
    let cat = read_catalogue(&a.lib).with_context(|| format!("library {}", a.lib.display()))?;
    if crate::cli::json() {
        crate::cli::summary_json(&serde_json::to_value(&cat)?);
    } else {
        print_catalogue(&cat);
    }
    Ok(Outcome::Clean)
}

/// `v` with `digits` decimals, or `-`.
fn or_dash(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.digits$}"))
}

/// The catalogue as text on stdout.
pub fn print_catalogue(cat: &Catalogue) {
    crate::say!("library {}", cat.library.display());
    crate::say!("characters ({}):", cat.characters.len());
    for c in &cat.characters {
        let mut names = c
            .clips
            .iter()
            .take(CLIPS_SHOWN)
            .cloned()
            .collect::<Vec<_>>()
            .join(", ");
        if c.clips.len() > CLIPS_SHOWN {
            names.push_str(&format!(", … {} more", c.clips.len() - CLIPS_SHOWN));
        }
        crate::say!(
            "  {}: {} clip(s) ({names}), leg {} m, mass {} kg, {} stance(s)",
            c.character_id,
            c.n_clips,
            or_dash(c.leg_length_m, 3),
            or_dash(c.mass_kg, 1),
            c.n_stances
        );
    }
    crate::say!(
        "run cycles ({}; feasible: at its own speed under the default `query run`):",
        cat.run_cycles.len()
    );
    let pair = |a: &str, b: &str| format!("{a} → {b}");
    let clip_w = (cat.run_cycles.iter().map(|c| c.clip.chars().count()))
        .chain(cat.jumps.iter().map(|j| j.clip.chars().count()))
        .fold(4, usize::max);
    let pair_w = (cat.run_cycles.iter())
        .map(|c| pair(&c.stance_ids[0], &c.stance_ids[1]).chars().count())
        .chain(
            cat.jumps
                .iter()
                .map(|j| pair(&j.liftoff, &j.landing).chars().count()),
        )
        .fold(17, usize::max);
    if !cat.run_cycles.is_empty() {
        crate::say!(
            "  {:<clip_w$} {:<pair_w$} {:>10}  feasible",
            "clip",
            "stances",
            "v_orig_mps"
        );
    }
    for c in &cat.run_cycles {
        let verdict = match c.feasible_at_own_speed {
            Some(true) => "yes".to_string(),
            Some(false) => "no".to_string(),
            None => format!(
                "left out: {}",
                c.left_out.as_deref().unwrap_or("by query run")
            ),
        };
        crate::say!(
            "  {:<clip_w$} {:<pair_w$} {:>10.3}  {verdict}",
            c.clip,
            pair(&c.stance_ids[0], &c.stance_ids[1]),
            c.v_orig_mps
        );
    }
    crate::say!("jumps ({}):", cat.jumps.len());
    if !cat.jumps.is_empty() {
        crate::say!(
            "  {:<clip_w$} {:<pair_w$} {:>8} {:>10}",
            "clip",
            "liftoff → landing",
            "height_m",
            "distance_m"
        );
    }
    for j in &cat.jumps {
        crate::say!(
            "  {:<clip_w$} {:<pair_w$} {:>8.3} {:>10.3}",
            j.clip,
            pair(&j.liftoff, &j.landing),
            j.height_m,
            j.distance_m
        );
    }
}
