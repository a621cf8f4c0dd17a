//! `stancelib twopac`: the 2PAC COM trajectory of a contact phase sequence (spec two-pac
//! §1.1, §4–§8): `trajectory.parquet`, `quasi_static.parquet`, `phases.parquet`,
//! `transitions.parquet`, `windows.parquet`, `validation.parquet`, `timings.json` and
//! `trajectory.png` in the output folder.
//!
//! Solve times are measured here, by repeating each solve a fixed number of times
//! ([`REPEATS_BUILD`], …), and go to `timings.json` only (§8: Parquet stays deterministic).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use rayon::prelude::*;

use super::super::args::TwopacArgs;
use super::super::Outcome;
use super::equilibrium::read_text;
use crate::library::twopac::{
    form_name, phases_table, trajectory_table, transitions_table, validation_table, windows_table,
    TrajectoryRow,
};
use crate::library::write::write_atomic;
use crate::plot::trajectory::{trajectory_png, TrajectoryPlot};
use crate::twopac::bezier::ComState;
use crate::twopac::clip::{phases_from_runs, rms_to_recording, RecordedRun, Recording};
use crate::twopac::phases::{parse_phases, KinematicsRef, PhasesFile};
use crate::twopac::polytope::Polytope;
use crate::twopac::region::{static_region, RegionStatus};
use crate::twopac::trajectory::{
    phase_diagnostics, plan, ComTrajectory, Phase, Plan, PlanOptions, QuasiStatic,
};
use crate::twopac::transition::{transition_eq13, transition_eq6, QpForm};
use crate::twopac::validate::{check_span, sample_times, validate, Validation, DEFAULT_STEP_S};

/// Repetitions of each phase's H-representation build (§8.1 target 1).
pub const REPEATS_BUILD: usize = 100;
/// Repetitions of each transition QP, eq 6 and eq 13 (§8.1 target 2).
pub const REPEATS_QP: usize = 1000;
/// Repetitions of the whole trajectory, without validation (§8.1 target 3).
pub const REPEATS_PLAN: usize = 30;
/// Repetitions of the dynamic validation (§7), reported on its own.
pub const REPEATS_VALIDATION: usize = 3;

fn parse_form(s: &str) -> anyhow::Result<QpForm> {
    match s {
        "eq13" => Ok(QpForm::Eq13),
        "eq6" => Ok(QpForm::Eq6),
        other => anyhow::bail!("--form: expected eq13 or eq6, found '{other}'"),
    }
}

/// The library's kinematic polytopes keyed by `(character_id, effector)` (two-pac §3).
fn read_library_polytopes(lib: &Path) -> anyhow::Result<BTreeMap<(String, String), Polytope>> {
    Ok(crate::library::kinematics::read_polytopes(lib)?)
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
fn resolve(
    file: &PhasesFile,
    path: &Path,
    a: &TwopacArgs,
    clip_id: Option<&str>,
) -> anyhow::Result<Vec<Phase>> {
    let named = file.named_kinematics();
    let library = if named.is_empty() {
        if let Some(lib) = &a.lib {
            anyhow::bail!(
                "--lib {}: {} uses no library polytope (every effector's kinematics is inline): \
                 drop --lib, or name a polytope (\"kinematics\": \"left_foot\")",
                lib.display(),
                path.display()
            );
        }
        BTreeMap::new()
    } else {
        let lib = a.lib.as_ref().with_context(|| {
            format!(
                "{}: effectors use the library polytopes {}: give --lib LIB (with kinematics.parquet) or inline {{\"A\", \"b\"}} polytopes",
                path.display(),
                named.join(", ")
            )
        })?;
        let all = read_library_polytopes(lib)?;
        let character = match (&a.character, &a.clip) {
            (Some(c), _) => Some(c.clone()),
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
/// of times.
fn timings(
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
fn rows(traj: &(dyn ComTrajectory + Sync), p: &Plan, v: &Validation) -> Vec<TrajectoryRow> {
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

/// Writes a text file under a temporary name, then renames it into place.
fn write_text(dir: &Path, name: &str, text: &str) -> anyhow::Result<()> {
    let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    std::fs::write(&tmp, text).with_context(|| format!("cannot write {}", tmp.display()))?;
    std::fs::rename(&tmp, dir.join(name)).with_context(|| format!("cannot write {name}"))
}

fn plot_data(
    phases: &[Phase],
    p: &Plan,
    curve: &[TrajectoryRow],
    qs: &QuasiStatic,
) -> TrajectoryPlot {
    let mut contacts: Vec<Vec<[f64; 3]>> = Vec::new();
    for c in phases.iter().flat_map(|ph| &ph.contacts) {
        let pts: Vec<[f64; 3]> = c.points().iter().map(|q| q.pos).collect();
        if !contacts.contains(&pts) {
            contacts.push(pts);
        }
    }
    TrajectoryPlot {
        title: format!(
            "2PAC COM trajectory: {} phases, {} transitions, {} windows",
            phases.len(),
            p.transitions.len(),
            p.windows.len()
        ),
        contacts,
        curve: curve.iter().map(|r| r.state.pos).collect(),
        quasi_static: qs.knots.iter().map(|k| k.1).collect(),
        transitions: p.transitions.iter().map(|t| t.point.com).collect(),
        phase_states: p.phase_states.iter().map(|s| s.com).collect(),
        recorded: Vec::new(),
        invalid: curve
            .iter()
            .filter(|r| !r.valid)
            .map(|r| r.state.pos)
            .collect(),
    }
}

/// The recorded motion of a `--clip` run (kept frames), and where its phases start.
struct Recorded {
    frame: Vec<i64>,
    time_s: Vec<f64>,
    com: Vec<[f64; 3]>,
    start_s: f64,
    /// The clip's own `character_id` (skeleton id under default options).
    character_id: Option<String>,
}

/// Phases from a clip (two-pac §1.1 `--clip`): ingest with the static / multi-contact
/// mode on, contact runs → phases of the first stretch of continuous support, library
/// polytopes for every effector.
fn clip_phases(clip: &Path, has_lib: bool) -> anyhow::Result<(PhasesFile, Recorded)> {
    anyhow::ensure!(
        has_lib,
        "--clip {}: the effectors' kinematic polytopes come from the library: give --lib LIB",
        clip.display()
    );
    let bvh = crate::bvh::parse_file(clip).with_context(|| clip.display().to_string())?;
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
fn clip_character(
    clip: &Path,
    own_id: Option<&str>,
    lib: &Path,
    all: &BTreeMap<(String, String), Polytope>,
) -> Option<String> {
    let has = |id: &str| all.keys().any(|(c, _)| c == id);
    let sha = crate::pipeline::batch::file_sha256(clip);
    let clips = crate::library::read::Table::open_columns(
        &lib.join(crate::library::schema::CLIPS_FILE),
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

/// Friction coefficient of contacts taken from a clip (two-pac §1 default).
const DEFAULT_CLIP_MU: f64 = 0.7;

/// Run `twopac`.
///
/// # Errors
/// A bad option, an unreadable or invalid phases file (exit 2, nothing written), a phase
/// sequence the core rejects (empty kinematics of a transition), an unwritable output.
pub fn run(a: TwopacArgs) -> anyhow::Result<Outcome> {
    let form = parse_form(&a.form)?;
    let (file, path, recorded) = match &a.clip {
        Some(clip) => {
            let (file, rec) = clip_phases(clip, a.lib.is_some())?;
            (file, clip.clone(), Some(rec))
        }
        None => {
            let path = a
                .phases
                .clone()
                .context("give --phases FILE or --clip CLIP.bvh")?;
            let text = read_text(&path)?;
            let file = parse_phases(&text).with_context(|| path.display().to_string())?;
            (file, path, None)
        }
    };
    let clip_id = recorded.as_ref().and_then(|r| r.character_id.as_deref());
    let phases = resolve(&file, &path, &a, clip_id)?;
    let opts = PlanOptions {
        form,
        ..PlanOptions::default()
    };
    let t0 = Instant::now();
    let p = plan(&phases, file.mass_kg, &file.start, &opts)
        .with_context(|| format!("{}: cannot plan the trajectory", path.display()))?;
    let plan_s = t0.elapsed().as_secs_f64();
    let qs = QuasiStatic::from_plan(&p);
    for (what, (t0, t1)) in [
        ("2PAC trajectory", p.span_s()),
        ("quasi-static", qs.span_s()),
    ] {
        check_span(t0, t1, DEFAULT_STEP_S).with_context(|| {
            format!(
                "{}: phases: the planned {what} (durations, or COM distances at {} m/s)",
                path.display(),
                crate::twopac::trajectory::POLYLINE_SPEED_MPS
            )
        })?;
    }
    let diags = phase_diagnostics(&p, &phases);
    let v_curve = validate(&p, &p.forms, DEFAULT_STEP_S);
    let v_qs = validate(&qs, &p.forms, DEFAULT_STEP_S);
    let curve_rows = rows(&p, &p, &v_curve);
    let qs_rows = rows(&qs, &p, &v_qs);
    let timings = timings(&phases, &p, file.mass_kg, &file.start, &opts);

    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("cannot create {}", a.out.display()))?;
    let options = serde_json::json!({
        "phases_file_schema": crate::twopac::phases::PHASES_SCHEMA,
        "mass_kg": file.mass_kg,
        "n_phases": phases.len(),
        "form": form_name(form),
        "step_s": DEFAULT_STEP_S,
    });
    let kv = vec![
        (
            "stancelib.tool_version".to_string(),
            env!("CARGO_PKG_VERSION").to_string(),
        ),
        ("stancelib.twopac".to_string(), options.to_string()),
    ];
    write_atomic(
        &a.out,
        "trajectory.parquet",
        &mut trajectory_table(&curve_rows)?,
        &kv,
    )?;
    write_atomic(
        &a.out,
        "quasi_static.parquet",
        &mut trajectory_table(&qs_rows)?,
        &kv,
    )?;
    write_atomic(
        &a.out,
        "phases.parquet",
        &mut phases_table(&p, &phases, &diags)?,
        &kv,
    )?;
    write_atomic(
        &a.out,
        "transitions.parquet",
        &mut transitions_table(&p, &phases)?,
        &kv,
    )?;
    write_atomic(
        &a.out,
        "windows.parquet",
        &mut windows_table(&p, &phases)?,
        &kv,
    )?;
    write_atomic(
        &a.out,
        "validation.parquet",
        &mut validation_table(&[("2pac", &v_curve), ("quasi_static", &v_qs)])?,
        &kv,
    )?;
    write_text(
        &a.out,
        "timings.json",
        &(serde_json::to_string_pretty(&timings)? + "\n"),
    )?;
    let mut data = plot_data(&phases, &p, &curve_rows, &qs);
    if let (Some(rec), Some(first), Some(last)) = (&recorded, curve_rows.first(), curve_rows.last())
    {
        // The recorded COM over the planned span (plan time 0 = clip time start_s).
        let (t0, t1) = (rec.start_s + first.t_s, rec.start_s + last.t_s);
        data.recorded = rec
            .time_s
            .iter()
            .zip(&rec.com)
            .filter(|(t, _)| (t0..=t1).contains(*t))
            .map(|(_, c)| *c)
            .collect();
    }
    super::write_png(&a.out.join("trajectory.png"), |path| {
        trajectory_png(path, &data)
    })?;
    if let Some(rec) = &recorded {
        let planned: Vec<(f64, [f64; 3])> =
            curve_rows.iter().map(|r| (r.t_s, r.state.pos)).collect();
        let recording = Recording {
            frame: &rec.frame,
            time_s: &rec.time_s,
            com: &rec.com,
        };
        let rms = rms_to_recording(&planned, recording, rec.start_s);
        let cmp = serde_json::json!({
            "clip": path.display().to_string(), "start_s": rec.start_s,
            "n_phases": phases.len(), "rms_to_recorded_m": rms,
        });
        write_text(
            &a.out,
            "recorded.json",
            &(serde_json::to_string_pretty(&cmp)? + "\n"),
        )?;
        crate::say!(
            "  recorded COM vs 2PAC COM over the planned span: RMS {} m",
            rms.map_or("-".into(), |v| format!("{v:.4}"))
        );
    }

    let n_static = p
        .transitions
        .iter()
        .filter(|t| t.point.is_static(1e-6))
        .count();
    let n_viol: usize = p.windows.iter().map(|w| w.violations.len()).sum();
    crate::say!(
        "twopac: {} phase(s), {} transition(s) ({n_static} statically feasible), {} window(s), \
         {n_viol} kinematic guarantee violation(s); planned in {:.3} ms",
        phases.len(),
        p.transitions.len(),
        p.windows.len(),
        plan_s * 1e3
    );
    for (name, v) in [("2pac", &v_curve), ("quasi-static", &v_qs)] {
        crate::say!(
            "  {name}: {} samples, point_valid_rate {:.3}, trajectory_valid {}, max s* {:.3} N at {:.2} s",
            v.samples.len(),
            v.point_valid_rate,
            v.trajectory_valid,
            v.max_slack_n,
            v.worst_t_s
        );
    }
    crate::say!("  → {}", a.out.display());
    Ok(Outcome::Clean)
}

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
        let sha = crate::pipeline::batch::file_sha256(&clip).unwrap();
        let mut df = DataFrame::new_infer_height(vec![
            Column::new("content_sha256".into(), vec![sha, "0".repeat(64)]),
            Column::new("character_id".into(), ["sk-b", "sk-c"]),
        ])
        .unwrap();
        crate::library::write::write_atomic(
            dir.path(),
            crate::library::schema::CLIPS_FILE,
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
