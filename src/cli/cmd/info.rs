//! `stancelib info LIB`: what a library holds and how it was built (see
//! [`library_info`]), as text or, with `--json`, one JSON object.

use anyhow::Context;

use super::super::args::InfoArgs;
use super::super::Outcome;
use crate::library::readers::info::library_info;

/// Run `info`.
///
/// # Errors
/// A missing or malformed library (the error names the file).
pub fn run(a: InfoArgs) -> anyhow::Result<Outcome> {
    let info = library_info(&a.lib).with_context(|| format!("library {}", a.lib.display()))?;
    if crate::cli::json() {
        crate::cli::summary_json(&serde_json::to_value(&info)?);
    } else {
        crate::say!("{info}");
    }
    Ok(Outcome::Clean)
}
