//! `stancelib forces`: every (or the named) stance's model force on its evaluation grid,
//! in stance and world axes, as one Parquet table; with `--per-contact`, one clip's (or
//! one stance's) total force split between its feet and hands with their centres of
//! pressure, as Parquet, CSV or OpenSim `.mot`.

use anyhow::Context;

use super::super::args::{ForcesArgs, ForcesFormat};
use super::super::Outcome;
use crate::force_model::per_contact::SplitOptions;
use crate::library::codec::schema::STANCES_FILE;
use crate::library::readers::forces::{forces_table, read_force_stances, select_stances};
use crate::library::readers::per_contact::{
    contact_rows, per_contact_csv, per_contact_mot, per_contact_table, read_contact_clip,
};
use crate::library::storage::atomic::write_text_atomic;
use crate::pipeline::commands::queries::{query_kv, write_table};

/// The output format: `--format`, else the `--out` extension, else Parquet.
///
/// # Errors
/// `--format` disagrees with a known `--out` extension; CSV or `.mot` without
/// `--per-contact`; `--clip` without `--per-contact`.
fn format_of(a: &ForcesArgs) -> anyhow::Result<ForcesFormat> {
    let from_ext = ForcesFormat::from_extension(&a.out);
    let format = match (a.format, from_ext) {
        (Some(f), Some(e)) if f != e => anyhow::bail!(
            "--format {} but --out {} names a .{} file",
            f.as_str(),
            a.out.display(),
            e.as_str()
        ),
        (Some(f), _) | (None, Some(f)) => f,
        (None, None) => ForcesFormat::Parquet,
    };
    if !a.per_contact {
        if let Some(c) = &a.clip {
            anyhow::bail!("--clip {c} needs --per-contact (the stance models are per stance)");
        }
        if format != ForcesFormat::Parquet {
            // Name what the user gave: the option, or only the extension.
            let what = match a.format {
                Some(f) => format!("--format {}", f.as_str()),
                None => format!("a .{} output", format.as_str()),
            };
            anyhow::bail!("{what} needs --per-contact (the stance models are written as Parquet)");
        }
    }
    Ok(format)
}

/// Run `forces`.
///
/// # Errors
/// Bad options (each named), an unreadable library, an unknown `--stance` id or clip
/// (nothing is written), an unwritable output.
pub fn run(a: ForcesArgs) -> anyhow::Result<Outcome> {
    crate::library::storage::layout::check_output_outside(&a.lib, &a.out)?;
    let format = format_of(&a)?;
    // Once for both paths (`read_contact_clip` leaves it to its caller).
    crate::library::codec::provenance::check_layout(&a.lib)?;
    if a.per_contact {
        return run_per_contact(&a, format);
    }
    let table = a.lib.join(STANCES_FILE);
    let stances =
        read_force_stances(&table).with_context(|| format!("library {}", a.lib.display()))?;
    let chosen = select_stances(&table, &stances, &a.stances)?;
    let mut df = forces_table(&chosen)?;
    let kv = query_kv(
        &a.lib,
        serde_json::json!({
            "query": "forces", "lib": a.lib, "stances": a.stances,
        }),
    )?;
    write_table(&a.out, &mut df, &kv)?;
    crate::say!(
        "forces: {} stance(s), {} sample(s) → {}",
        chosen.len(),
        df.height(),
        a.out.display()
    );
    Ok(Outcome::Clean)
}

/// `forces --per-contact`.
fn run_per_contact(a: &ForcesArgs, format: ForcesFormat) -> anyhow::Result<Outcome> {
    let (clip, range) = match (&a.clip, a.stances.as_slice()) {
        (Some(c), []) => (c.clone(), None),
        (None, [id]) => {
            let table = a.lib.join(STANCES_FILE);
            let stances = read_force_stances(&table)
                .with_context(|| format!("library {}", a.lib.display()))?;
            let s = select_stances(&table, &stances, std::slice::from_ref(id))?[0];
            let range = (s.stance.first_frame, s.last_frame);
            (s.stance.clip.clone(), Some(range))
        }
        (None, []) => anyhow::bail!("--per-contact needs --clip NAME or one --stance ID"),
        (_, ids) => anyhow::bail!(
            "--per-contact writes one clip or one stance, but {} --stance ids were given",
            ids.len()
        ),
    };
    let c =
        read_contact_clip(&a.lib, &clip).with_context(|| format!("library {}", a.lib.display()))?;
    let rows = contact_rows(&c, range, &SplitOptions::default());
    // `write_table` creates the output's folder; the text formats do it here.
    let write_text = |text: String| -> anyhow::Result<()> {
        if let Some(dir) = a.out.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create {}", dir.display()))?;
        }
        Ok(write_text_atomic(&a.out, &text)?)
    };
    match format {
        ForcesFormat::Parquet => {
            let mut df = per_contact_table(&rows)?;
            let kv = query_kv(
                &a.lib,
                serde_json::json!({
                    "query": "forces", "per_contact": true, "lib": a.lib,
                    "clip": clip, "stances": a.stances,
                }),
            )?;
            write_table(&a.out, &mut df, &kv)?;
        }
        ForcesFormat::Csv => write_text(per_contact_csv(&rows))?,
        ForcesFormat::Mot => {
            let name = a
                .out
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("ground_reactions");
            write_text(per_contact_mot(&rows, name))?;
        }
    }
    let count = |rule: &str| rows.split.iter().filter(|s| **s == rule).count();
    crate::say!(
        "forces --per-contact: clip {}, {} frame(s), {} handing over, {} by the lever rule, {} even → {} ({})",
        clip,
        rows.frame.len(),
        count("transition"),
        count("lever"),
        count("even"),
        a.out.display(),
        format.as_str()
    );
    Ok(Outcome::Clean)
}
