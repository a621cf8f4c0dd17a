//! One module per subcommand.

pub mod build;
pub mod edit;
pub mod equilibrium;
pub mod forces;
pub mod frames;
pub mod info;
pub mod map;
pub mod plot;
pub mod query;
pub mod run;
pub mod synth;
pub mod twopac;

use std::path::Path;

use anyhow::Context;

use crate::plot::PlotError;

/// Draws a PNG with `draw` under a temporary name beside `path`, then renames it into
/// place, so a failed draw leaves no file and an earlier one survives.
///
/// # Errors
/// The drawing fails or the rename does.
pub fn write_png(
    path: &Path,
    draw: impl FnOnce(&Path) -> Result<(), PlotError>,
) -> anyhow::Result<()> {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .with_context(|| format!("{}: not a file name", path.display()))?;
    // The backend picks the image format from the extension: keep `.png` last.
    let tmp = path.with_file_name(format!(".{name}.tmp-{}.png", std::process::id()));
    let drawn = draw(&tmp).map_err(anyhow::Error::from).and_then(|()| {
        std::fs::rename(&tmp, path).with_context(|| format!("cannot rename {name}"))
    });
    if drawn.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    drawn
}
