//! `stancelib plot stance`: one stance's model force against the kinematic force m(a + g)
//! and, with `--plates`, the measured plate force, as a PNG.

use anyhow::Context;

use super::super::args::{PlotClipArgs, PlotStanceArgs};
use super::super::Outcome;
use super::write_png;
use crate::force_model::export::{kinematic_force, sample_forces};
use crate::library::forces::{
    read_clip_accelerations, read_force_stances, read_up_axis, select_stances,
};
use crate::library::plates::{read_plates, PlateFoot};
use crate::library::schema::{CLIPS_FILE, FRAMES_FILE, STANCES_FILE};
use crate::plot::stance::{stance_png, time_window, StancePlot, WorldForces};

/// Run `plot stance`.
///
/// # Errors
/// An `--active-set` outside [0, 1], an unreadable library or plate file, an unknown
/// stance id (nothing is written), an unwritable output.
pub fn run_stance(a: PlotStanceArgs) -> anyhow::Result<Outcome> {
    anyhow::ensure!(
        (0.0..=1.0).contains(&a.active_set),
        "--active-set must lie in [0, 1], found {}",
        a.active_set
    );
    let lib = |name: &str| a.lib.join(name);
    let stances = read_force_stances(&lib(STANCES_FILE))
        .with_context(|| format!("library {}", a.lib.display()))?;
    let s = select_stances(
        &lib(STANCES_FILE),
        &stances,
        std::slice::from_ref(&a.stance),
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
    let plate = match &a.plates {
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
                eprintln!(
                    "plot stance: {} has no sample in [{t0:.3}, {t1:.3}] s",
                    file.display()
                );
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
    let data = StancePlot {
        stance_id: s.stance.stance_id.clone(),
        mu_req: s.stance.coef.mu_req,
        td_lo_s: (td, lo),
        heading: s.heading,
        model: sample_forces(&s.stance.model, s.times, &s.heading),
        kinematic,
        plate,
        active_fraction: a.active_set,
    };
    if let Some(dir) = a.out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    write_png(&a.out, |p| stance_png(p, &data))?;
    crate::say!("plot stance: {} → {}", data.stance_id, a.out.display());
    Ok(Outcome::Clean)
}

/// Run `plot clip`.
///
/// # Errors
/// An unreadable library, a clip it does not hold (nothing is written), an unwritable
/// output.
pub fn run_clip(a: PlotClipArgs) -> anyhow::Result<Outcome> {
    let view = crate::library::clip_view::read_clip_view(&a.lib, &a.clip)
        .with_context(|| format!("library {}", a.lib.display()))?;
    if let Some(dir) = a.out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    write_png(&a.out, |p| crate::plot::clip::clip_png(p, &view))?;
    crate::say!(
        "plot clip: {} ({} frames, {} flights) → {}",
        view.clip,
        view.time_s.len(),
        view.flights.len(),
        a.out.display()
    );
    Ok(Outcome::Clean)
}
