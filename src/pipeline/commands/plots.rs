//! The plot stages: `plot stance` (one stance's model force against the kinematic force
//! m(a + g) and, with plates, the measured plate force) and `plot clip` (a clip's COM,
//! flights, contacts and warnings), each read from a library and written as a PNG.

use std::path::{Path, PathBuf};

use anyhow::Context;

use crate::force_model::export::{kinematic_force, sample_forces};
use crate::ingest::plates::{parse_plates, PlateFoot, PlateSample};
use crate::library::codec::schema::{CLIPS_FILE, FRAMES_FILE, STANCES_FILE};
use crate::library::readers::clip_view::{read_clip_view, ClipView};
use crate::library::readers::forces::{
    read_clip_accelerations, read_force_stances, read_up_axis, select_stances,
};
use crate::pipeline::engine::inputs::{read_side_text, SideInput};
use crate::plot::stance::{stance_png, time_window, StancePlot, WorldForces};
use crate::plot::write_png;
use crate::skeleton::units::UpAxis;

/// A `plot stance` job.
#[derive(Debug, Clone)]
pub struct StancePlotJob {
    /// Library folder.
    pub lib: PathBuf,
    /// The stance id.
    pub stance: String,
    /// Force-plate file of the stance's clip.
    pub plates: Option<PathBuf>,
    /// Active fraction of the friction check drawn, in `[0, 1]`.
    pub active_set: f64,
    /// Output PNG.
    pub out: PathBuf,
}

/// What `plot stance` drew: the stance id and warnings (a plate file without samples in
/// the window).
#[derive(Debug, Clone, PartialEq)]
pub struct StancePlotReport {
    /// The stance drawn.
    pub stance_id: String,
    /// Warnings about the inputs.
    pub warnings: Vec<String>,
}

/// Runs `plot stance`.
///
/// # Errors
/// An `active_set` outside [0, 1], an unreadable library or plate file, an unknown stance
/// Reads a force-plate CSV file (`--plates`) as a side input ([`SideInput::Plates`]: a
/// regular file within `MAX_PLATES_BYTES`), then parses it ([`parse_plates`]).
///
/// # Errors
/// As [`read_side_text`]; as [`parse_plates`], with the path.
pub fn read_plates(
    path: &Path,
    foot: PlateFoot,
    up: UpAxis,
) -> crate::error::Result<Vec<PlateSample>> {
    parse_plates(&read_side_text(path, SideInput::Plates)?, foot, up).map_err(|e| e.with_path(path))
}

/// id (nothing is written), an unwritable output.
pub fn plot_stance(job: &StancePlotJob) -> anyhow::Result<StancePlotReport> {
    anyhow::ensure!(
        (0.0..=1.0).contains(&job.active_set),
        "--active-set must lie in [0, 1], found {}",
        job.active_set
    );
    let (data, warnings) = stance_plot(job)?;
    create_parent(&job.out)?;
    write_png(&job.out, |p| stance_png(p, &data))?;
    Ok(StancePlotReport {
        stance_id: data.stance_id,
        warnings,
    })
}

/// The data of a stance plot, with warnings.
fn stance_plot(job: &StancePlotJob) -> anyhow::Result<(StancePlot, Vec<String>)> {
    crate::library::codec::provenance::check_layout(&job.lib)?;
    let lib = |name: &str| job.lib.join(name);
    let stances = read_force_stances(&lib(STANCES_FILE))
        .with_context(|| format!("library {}", job.lib.display()))?;
    let s = select_stances(
        &lib(STANCES_FILE),
        &stances,
        std::slice::from_ref(&job.stance),
    )?[0];
    let (td, lo) = (s.times.td_clip_s, s.lo_clip_s);
    let (t0, t1) = time_window(td, lo);
    let clip = &s.stance.clip;
    let mass = s.stance.model.mass_kg;
    let acc = read_clip_accelerations(&lib(FRAMES_FILE), clip, t0, t1)?;
    let kinematic = WorldForces {
        label: "kinematic m(a + g)".into(),
        samples: acc
            .time_s
            .iter()
            .zip(&acc.com_a)
            .map(|(t, a)| (*t, kinematic_force(mass, *a)))
            .collect(),
    };
    let mut warnings = Vec::new();
    let plate = match &job.plates {
        None => None,
        Some(file) => {
            let up = read_up_axis(&lib(CLIPS_FILE), clip)?;
            let foot = PlateFoot::from_label(&s.stance.label);
            let samples: Vec<(f64, [f64; 3])> = read_plates(file, foot, up)?
                .into_iter()
                .filter(|p| (t0..=t1).contains(&p.time_s))
                .map(|p| (p.time_s, p.f_world))
                .collect();
            if samples.is_empty() {
                warnings.push(format!(
                    "{} has no sample in [{t0:.3}, {t1:.3}] s",
                    file.display()
                ));
            }
            let which = match foot {
                PlateFoot::Left => "left foot",
                PlateFoot::Right => "right foot",
                PlateFoot::Total => "total",
            };
            Some(WorldForces {
                label: format!("plate ({which})"),
                samples,
            })
        }
    };
    Ok((
        StancePlot {
            stance_id: s.stance.stance_id.clone(),
            mu_req: s.stance.coef.mu_req,
            mu_req_robust: s.stance.coef.mu_req_robust,
            td_lo_s: (td, lo),
            heading: s.heading,
            model: sample_forces(&s.stance.model, s.times, &s.heading),
            kinematic,
            plate,
            active_fraction: job.active_set,
        },
        warnings,
    ))
}

/// Runs `plot clip`: the clip's view from `lib`, drawn to `out`.
///
/// # Errors
/// An unreadable library, a clip it does not hold (nothing is written), an unwritable
/// output.
pub fn plot_clip(lib: &Path, clip: &str, out: &Path) -> anyhow::Result<ClipView> {
    let view = read_clip_view(lib, clip).with_context(|| format!("library {}", lib.display()))?;
    create_parent(out)?;
    write_png(out, |p| crate::plot::clip::clip_png(p, &view))?;
    Ok(view)
}

/// Creates the folder of an output file.
fn create_parent(out: &Path) -> anyhow::Result<()> {
    if let Some(dir) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    Ok(())
}
