//! The `twopac` stage (spec two-pac §1.1, §4–§8) at the I/O edge: phases from a recorded
//! clip (`--clip`: ingest, contact runs, phases), the library's kinematic polytopes for
//! named effectors, the trajectory samples and plot data of a plan, and the solve-time
//! report `timings.json` (each target repeated a fixed number of times, [`REPEATS_BUILD`],
//! …; never in Parquet, §8).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use rayon::prelude::*;

use super::twopac_tables::{form_name, TrajectoryRow};
use crate::plot::trajectory::{CurveSample, PhaseSpan, TrajectoryPlot};
use crate::twopac::bezier::ComState;
use crate::twopac::clip::{phases_from_runs, RecordedRun, Recording};
use crate::twopac::diagnose::Failure;
use crate::twopac::phases::{KinematicsRef, PhasesFile};
use crate::twopac::polytope::Polytope;
use crate::twopac::region::{static_region, RegionStatus};
use crate::twopac::trajectory::{plan, ComTrajectory, Phase, Plan, PlanOptions, QuasiStatic};
use crate::twopac::transition::{transition_eq13, transition_eq6};
use crate::twopac::validate::{sample_times, validate, Validation, DEFAULT_STEP_S};

/// Where the named kinematic polytopes of a phases file come from.
#[derive(Debug, Clone, Copy, Default)]
pub struct PolytopeSource<'a> {
    /// The library folder (`--lib`) with `kinematics.parquet`.
    pub lib: Option<&'a Path>,
    /// The character of its polytopes (`--character`; default: the only one).
    pub character: Option<&'a str>,
    /// The recorded clip the phases came from (`--clip`), whose character is the default.
    pub clip: Option<&'a Path>,
}

/// Repetitions of each phase's H-representation build (§8.1 target 1).
pub const REPEATS_BUILD: usize = 100;
/// Repetitions of each transition QP, eq 6 and eq 13 (§8.1 target 2).
pub const REPEATS_QP: usize = 1000;
/// Repetitions of the whole trajectory, without validation (§8.1 target 3).
pub const REPEATS_PLAN: usize = 30;
/// Repetitions of the dynamic validation (§7), reported on its own.
pub const REPEATS_VALIDATION: usize = 3;

/// The kinematic polytopes of a library by (`character_id`, `effector`), in the contact
/// frame (metres); rows renormalised to exactly unit length (stored values carry rounding).
///
/// # Errors
/// `kinematics.parquet` missing or malformed (the error names the file, column and row).
pub fn read_polytopes(
    lib_dir: &Path,
) -> crate::error::Result<BTreeMap<(String, String), Polytope>> {
    Ok(crate::library::codec::kinematics::read_facets(lib_dir)?
        .into_iter()
        .map(|(k, (a, b))| (k, Polytope::new(a, b)))
        .collect())
}

/// The library's kinematic polytopes keyed by `(character_id, effector)` (two-pac §3).
pub fn read_library_polytopes(lib: &Path) -> anyhow::Result<BTreeMap<(String, String), Polytope>> {
    Ok(read_polytopes(lib)?)
}

/// The polytopes of one character: `character`, or the only one in the library.
///
/// # Errors
/// No polytope at all, an unknown character, or several characters without `--character`.
pub(crate) fn character_polytopes(
    all: &BTreeMap<(String, String), Polytope>,
    character: Option<&str>,
    lib: &Path,
) -> anyhow::Result<BTreeMap<String, Polytope>> {
    let ids: BTreeSet<&str> = all.keys().map(|(c, _)| c.as_str()).collect();
    let list = || ids.iter().copied().collect::<Vec<_>>().join(", ");
    let id = match (character, ids.len()) {
        (_, 0) => anyhow::bail!("{}: kinematics.parquet has no polytope", lib.display()),
        (Some(c), _) if ids.contains(c) => c,
        (Some(c), _) => anyhow::bail!(
            "--character {c}: not in {} (characters: {})",
            lib.display(),
            list()
        ),
        (None, 1) => ids.iter().next().copied().unwrap_or_default(),
        (None, _) => anyhow::bail!(
            "{}: several characters ({}): choose one with --character ID",
            lib.display(),
            list()
        ),
    };
    Ok(all
        .iter()
        .filter(|((c, _), _)| c == id)
        .map(|((_, e), p)| (e.clone(), p.clone()))
        .collect())
}

/// The core's phases with every kinematic polytope resolved (inline, or from `--lib`).
///
/// With `--clip` and no `--character`, the clip's own character is used (see
/// [`clip_character`]).
pub fn resolve(
    file: &PhasesFile,
    path: &Path,
    src: &PolytopeSource<'_>,
    clip_id: Option<&str>,
) -> anyhow::Result<Vec<Phase>> {
    let named = file.named_kinematics();
    let library = if named.is_empty() {
        if let Some(lib) = src.lib {
            anyhow::bail!(
                "--lib {}: {} uses no library polytope (every effector's kinematics is inline): \
                 drop --lib, or name a polytope (\"kinematics\": \"left_foot\")",
                lib.display(),
                path.display()
            );
        }
        BTreeMap::new()
    } else {
        let lib = src.lib.with_context(|| {
            format!(
                "{}: effectors use the library polytopes {}: give --lib LIB (with kinematics.parquet) or inline {{\"A\", \"b\"}} polytopes",
                path.display(),
                named.join(", ")
            )
        })?;
        let all = read_library_polytopes(lib)?;
        let character = match (src.character, src.clip) {
            (Some(c), _) => Some(c.to_string()),
            (None, Some(clip)) => clip_character(clip, clip_id, lib, &all),
            (None, None) => None,
        };
        character_polytopes(&all, character.as_deref(), lib)?
    };
    let lookup = |name: &str| library.get(name).cloned();
    file.to_phases(&lookup)
        .with_context(|| path.display().to_string())
}

/// Median and 95th percentile of repeated timings, s.
fn stats(mut v: Vec<f64>) -> serde_json::Value {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    serde_json::json!({
        "median": v[n / 2],
        "p95": v[((n * 95) / 100).min(n - 1)],
        "n": n,
    })
}

fn time_n(n: usize, mut f: impl FnMut()) -> serde_json::Value {
    let v = (0..n)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .collect();
    stats(v)
}

/// `timings.json` (§8.1, CORRECTIONS Issue 5 item 5), each target repeated a fixed number
/// of times: the solve times of one run, reported beside its (deterministic) tables.
pub fn timings(
    phases: &[Phase],
    p: &Plan,
    mass_kg: f64,
    start: &ComState,
    opts: &PlanOptions,
) -> serde_json::Value {
    let regions: Vec<_> = p
        .forms
        .iter()
        .map(|f| static_region(&f.points, &opts.region).ok())
        .collect();
    let phase_rows: Vec<serde_json::Value> = p
        .forms
        .iter()
        .enumerate()
        .map(|(j, f)| {
            let build = if regions[j].is_some() {
                time_n(REPEATS_BUILD, || {
                    std::hint::black_box(static_region(&f.points, &opts.region).ok());
                })
            } else {
                serde_json::Value::Null
            };
            serde_json::json!({
                "phase": j,
                "n_contacts": phases[j].contacts.len(),
                "n_contact_points": f.points.len(),
                "constraint_build_s": build,
            })
        })
        .collect();
    let o = &opts.transition;
    let transition_rows: Vec<serde_json::Value> = p
        .transitions
        .iter()
        .map(|t| {
            let kin = phases[t.kinematics_phase].polytope();
            let c_prev = if t.index == 0 {
                p.phase_states[0].com
            } else {
                p.transitions[t.index - 1].point.com
            };
            let form = &p.forms[t.statics_phase];
            let eq6 = match &regions[t.statics_phase] {
                Some(r) if r.status != RegionStatus::Empty => time_n(REPEATS_QP, || {
                    std::hint::black_box(transition_eq6(r, form.degenerate, &kin, c_prev, o).ok());
                }),
                _ => serde_json::Value::Null,
            };
            let eq13 = time_n(REPEATS_QP, || {
                std::hint::black_box(transition_eq13(form, &kin, c_prev, o).ok());
            });
            serde_json::json!({
                "transition": t.index,
                "statics_phase": t.statics_phase,
                "n_kinematic_rows": kin.len(),
                "qp_eq6_s": eq6,
                "qp_eq13_s": eq13,
            })
        })
        .collect();
    let trajectory = time_n(REPEATS_PLAN, || {
        std::hint::black_box(plan(phases, mass_kg, start, opts).ok());
    });
    let validation = time_n(REPEATS_VALIDATION, || {
        std::hint::black_box(validate(p, &p.forms, DEFAULT_STEP_S));
    });
    serde_json::json!({
        "phases": phase_rows,
        "transitions": transition_rows,
        "trajectory_s": trajectory,
        "validation_s": validation,
        "form": form_name(opts.form),
        "n_phases": phases.len(),
        "profile": if cfg!(debug_assertions) { "debug" } else { "release" },
        "repeats": {
            "constraint_build": REPEATS_BUILD, "qp": REPEATS_QP,
            "trajectory": REPEATS_PLAN, "validation": REPEATS_VALIDATION,
        },
        "targets_s": {
            "constraint_build_6_rectangles": 5e-4, "qp_eq6_median": 5e-6,
            "trajectory_10_phases": 2e-3,
        },
    })
}

/// Samples of a trajectory at the §7 times, with the verdict at each (in parallel).
pub fn rows(traj: &(dyn ComTrajectory + Sync), p: &Plan, v: &Validation) -> Vec<TrajectoryRow> {
    let (t0, t1) = traj.span_s();
    let times = sample_times(t0, t1, DEFAULT_STEP_S);
    times
        .par_iter()
        .zip(v.samples.par_iter())
        .map(|(&t, s)| {
            let (state, phase) = traj.sample(t);
            TrajectoryRow {
                t_s: t,
                phase,
                state,
                valid: s.valid,
                slack_n: s.slack_n,
                verdict: p.forms[phase].verdict(state.pos, state.acc),
            }
        })
        .collect()
}

/// What `trajectory.png` draws of a plan: contacts, the 2PAC curve with its validated
/// samples and their causes of failure (`fails`, [`crate::twopac::diagnose::failures`]),
/// the quasi-static polyline, transition points, phase states and the phases on the time
/// axis.
pub fn plot_data(
    phases: &[Phase],
    p: &Plan,
    curve: &[TrajectoryRow],
    qs: &QuasiStatic,
    fails: &[Failure],
) -> TrajectoryPlot {
    let mut contacts: Vec<Vec<[f64; 3]>> = Vec::new();
    for c in phases.iter().flat_map(|ph| &ph.contacts) {
        let pts: Vec<[f64; 3]> = c.points().iter().map(|q| q.pos).collect();
        if !contacts.contains(&pts) {
            contacts.push(pts);
        }
    }
    let cause_at = |t: f64| {
        fails
            .iter()
            .find(|f| (f.t_s - t).abs() < 1e-9)
            .map(|f| f.cause)
    };
    let (t0, t1) = p.span_s();
    let bounds: Vec<f64> = std::iter::once(t0)
        .chain(p.switch_times_s.iter().copied())
        .chain(std::iter::once(t1))
        .collect();
    TrajectoryPlot {
        title: format!(
            "Is the 2PAC COM trajectory dynamically valid? ({} contact phases, {} transitions)",
            phases.len(),
            p.transitions.len(),
        ),
        verdict: None,
        contacts,
        curve: curve.iter().map(|r| r.state.pos).collect(),
        quasi_static: qs.knots.iter().map(|k| k.1).collect(),
        transitions: p.transitions.iter().map(|t| t.point.com).collect(),
        phase_states: p.phase_states.iter().map(|s| s.com).collect(),
        recorded: Vec::new(),
        samples: curve
            .iter()
            .map(|r| CurveSample {
                t_s: r.t_s,
                pos: r.state.pos,
                slack_n: r.slack_n,
                cause: (!r.valid).then(|| cause_at(r.t_s)).flatten(),
            })
            .collect(),
        phases: phases
            .iter()
            .zip(bounds.windows(2))
            .map(|(ph, w)| PhaseSpan {
                start_s: w[0],
                end_s: w[1],
                effectors: ph
                    .contacts
                    .iter()
                    .map(|c| c.effector.as_str())
                    .collect::<Vec<_>>()
                    .join("+"),
            })
            .collect(),
    }
}

/// The recorded motion of a `--clip` run (kept frames), and where its phases start.
pub struct Recorded {
    /// Kept frames (file rows).
    pub frame: Vec<i64>,
    /// Clip time of each kept frame, s.
    pub time_s: Vec<f64>,
    /// COM of each kept frame (world, Z up, m).
    pub com: Vec<[f64; 3]>,
    /// Clip time at which the phases start, s.
    pub start_s: f64,
    /// The clip's own `character_id` (skeleton id under default options).
    pub character_id: Option<String>,
}

/// Phases from a clip (two-pac §1.1 `--clip`): ingest with the static / multi-contact
/// mode on, contact runs → phases of the first stretch of continuous support, library
/// polytopes for every effector.
///
/// # Errors
/// The clip cannot be read or ingested, is not a body, or has no contact phase.
pub fn clip_phases(clip: &Path) -> anyhow::Result<(PhasesFile, Recorded)> {
    let bvh = crate::pipeline::engine::inputs::read_side_bvh(clip)?;
    let mut opts = crate::ingest::IngestOptions::default();
    opts.contacts.static_mode = true;
    let outcome = crate::ingest::ingest(&bvh, &opts).with_context(|| clip.display().to_string())?;
    let crate::ingest::ClipOutcome::Body {
        frames,
        contacts,
        summary,
    } = outcome
    else {
        anyhow::bail!("{}: not a body or too short to plan", clip.display());
    };
    let runs: Vec<RecordedRun> = contacts
        .iter()
        .map(|r| RecordedRun {
            effector: r.effector.to_string(),
            frames: (r.first_frame, r.last_frame),
            origin: r.origin,
            yaw_rad: r.yaw_rad,
            normal: r.normal,
        })
        .collect();
    let recording = Recording {
        frame: &frames.frame,
        time_s: &frames.time_s,
        com: &frames.com,
    };
    let (phases, start_s) = phases_from_runs(&runs, recording, DEFAULT_CLIP_MU)
        .with_context(|| clip.display().to_string())?;
    anyhow::ensure!(
        !phases.is_empty(),
        "{}: no contact phase to plan (no support detected)",
        clip.display()
    );
    let effectors = phases
        .iter()
        .flat_map(|p| p.contacts.iter().map(|c| c.effector.clone()))
        .map(|e| (e.clone(), KinematicsRef::Named(e)))
        .collect();
    let file = PhasesFile {
        mass_kg: opts.mass_kg,
        start: ComState::default(),
        effectors,
        phases,
    };
    let rec = Recorded {
        frame: frames.frame,
        time_s: frames.time_s,
        com: frames.com,
        start_s,
        character_id: summary.character_id,
    };
    Ok((file, rec))
}

/// The character of a `--clip` in the library `lib`: that of the library's clip with the
/// same content (SHA-256, `clips.parquet`), else the clip's own skeleton id when the
/// library has polytopes for it; `None` leaves the choice to `--character`.
pub fn clip_character(
    clip: &Path,
    own_id: Option<&str>,
    lib: &Path,
    all: &BTreeMap<(String, String), Polytope>,
) -> Option<String> {
    let has = |id: &str| all.keys().any(|(c, _)| c == id);
    let sha = crate::pipeline::engine::inputs::file_sha256(clip);
    let clips = crate::library::codec::table::Table::open_columns(
        &lib.join(crate::library::codec::schema::CLIPS_FILE),
        &["content_sha256", "character_id"],
    )
    .ok();
    let from_library = sha.zip(clips).and_then(|(sha, t)| {
        let shas = t.strings("content_sha256").ok()?;
        let ids = t.df.column("character_id").ok()?.str().ok()?.clone();
        let row = shas.iter().position(|s| *s == sha)?;
        ids.get(row).map(str::to_string)
    });
    from_library
        .filter(|id| has(id))
        .or_else(|| own_id.filter(|id| has(id)).map(str::to_string))
}

/// Friction coefficient of contacts taken from a clip (two-pac §1 default): the crate's
/// default μ.
const DEFAULT_CLIP_MU: f64 = crate::math::constants::DEFAULT_MU;

#[cfg(test)]
mod tests {
    use super::*;

    fn lib(keys: &[(&str, &str)]) -> BTreeMap<(String, String), Polytope> {
        keys.iter()
            .enumerate()
            .map(|(i, (c, e))| {
                let p = Polytope::aabb([0.0; 3], [1.0, 1.0, i as f64 + 1.0]);
                ((c.to_string(), e.to_string()), p)
            })
            .collect()
    }

    #[test]
    fn the_only_character_is_the_default() {
        let all = lib(&[("c1", "left_foot"), ("c1", "right_foot")]);
        let got = character_polytopes(&all, None, Path::new("L")).unwrap();
        assert_eq!(got.len(), 2);
        assert_eq!(got["right_foot"], all[&("c1".into(), "right_foot".into())]);
    }

    #[test]
    fn several_characters_need_a_choice() {
        let all = lib(&[("a", "left_foot"), ("b", "left_foot"), ("b", "left_hand")]);
        let e = character_polytopes(&all, None, Path::new("L")).unwrap_err();
        assert!(e.to_string().contains("--character"), "{e}");
        let got = character_polytopes(&all, Some("b"), Path::new("L")).unwrap();
        assert_eq!(got.keys().collect::<Vec<_>>(), ["left_foot", "left_hand"]);
        assert_eq!(got["left_foot"], all[&("b".into(), "left_foot".into())]);
        assert!(character_polytopes(&all, Some("z"), Path::new("L")).is_err());
        assert!(character_polytopes(&BTreeMap::new(), None, Path::new("L")).is_err());
    }

    // See: issue 17 item 6 — `twopac --clip` made the user look up the clip's character.
    #[test]
    fn a_clip_finds_its_own_character() {
        use polars::prelude::{Column, DataFrame};
        let dir = tempfile::tempdir().unwrap();
        let clip = dir.path().join("walk.bvh");
        std::fs::write(&clip, "not parsed here: only its bytes are hashed").unwrap();
        let other = dir.path().join("other.bvh");
        std::fs::write(&other, "another clip").unwrap();
        let sha = crate::pipeline::engine::inputs::file_sha256(&clip).unwrap();
        let mut df = DataFrame::new_infer_height(vec![
            Column::new("content_sha256".into(), vec![sha, "0".repeat(64)]),
            Column::new("character_id".into(), ["sk-b", "sk-c"]),
        ])
        .unwrap();
        crate::library::codec::write::write_atomic(
            dir.path(),
            crate::library::codec::schema::CLIPS_FILE,
            &mut df,
            &[],
        )
        .unwrap();
        let all = lib(&[("sk-a", "left_foot"), ("sk-b", "left_foot")]);
        // The library's clip of the same content wins over the clip's own skeleton id.
        let got = clip_character(&clip, Some("sk-a"), dir.path(), &all);
        assert_eq!(got.as_deref(), Some("sk-b"));
        // A clip the library does not hold: its own id, when the library has polytopes for it.
        let got = clip_character(&other, Some("sk-a"), dir.path(), &all);
        assert_eq!(got.as_deref(), Some("sk-a"));
        assert_eq!(clip_character(&other, Some("sk-z"), dir.path(), &all), None);
        assert_eq!(clip_character(&other, None, dir.path(), &all), None);
    }
}
