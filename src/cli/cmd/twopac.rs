//! `stancelib twopac`: the 2PAC COM trajectory of a contact phase sequence (spec two-pac
//! §1.1, §4–§8): `trajectory.parquet`, `quasi_static.parquet`, `phases.parquet`,
//! `transitions.parquet`, `windows.parquet`, `validation.parquet`, `timings.json` and
//! `trajectory.png` in the output folder.
//!
//! The stage itself (clip ingest, polytopes, samples, solve times) is in
//! [`crate::pipeline::twopac`]; this command checks its options, delegates and prints.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;

use super::super::args::TwopacArgs;
use super::super::Outcome;
use super::equilibrium::read_text;
use crate::library::atomic::write_text_atomic;
use crate::library::write::write_atomic;
use crate::pipeline::twopac::{
    clip_phases, plot_data, resolve, rows, timings, PolytopeSource, Recorded,
};
use crate::pipeline::twopac_tables::{
    form_name, phases_table, trajectory_table, transitions_table, validation_table, windows_table,
    TrajectoryRow,
};
use crate::plot::trajectory::trajectory_png;
use crate::twopac::clip::{rms_to_recording, Recording};
use crate::twopac::phases::{parse_phases, PhasesFile};
use crate::twopac::trajectory::{
    phase_diagnostics, plan, ComTrajectory, Phase, PhaseDiagnostic, Plan, PlanOptions, QuasiStatic,
};
use crate::twopac::transition::QpForm;
use crate::twopac::validate::{check_span, validate, Validation, DEFAULT_STEP_S};

/// A planned phase sequence with everything the outputs need.
struct Planned {
    p: Plan,
    qs: QuasiStatic,
    diags: Vec<PhaseDiagnostic>,
    v_curve: Validation,
    v_qs: Validation,
    curve_rows: Vec<TrajectoryRow>,
    qs_rows: Vec<TrajectoryRow>,
    timings: serde_json::Value,
    plan_s: f64,
}

/// Run `twopac`.
///
/// # Errors
/// A bad option, an unreadable or invalid phases file (exit 2, nothing written), a phase
/// sequence the core rejects (empty kinematics of a transition), an unwritable output.
pub fn run(a: TwopacArgs) -> anyhow::Result<Outcome> {
    let form = QpForm::from(a.form);
    if let Some(clip) = &a.clip {
        anyhow::ensure!(
            a.lib.is_some(),
            "--clip {}: the effectors' kinematic polytopes come from the library: give --lib LIB",
            clip.display()
        );
    }
    let (file, path, recorded) = load(&a)?;
    let clip_id = recorded.as_ref().and_then(|r| r.character_id.as_deref());
    let src = PolytopeSource {
        lib: a.lib.as_deref(),
        character: a.character.as_deref(),
        clip: a.clip.as_deref(),
    };
    let phases = resolve(&file, &path, &src, clip_id)?;
    let planned = plan_phases(&phases, &file, form, &path)?;
    write_outputs(
        &a.out,
        &phases,
        &file,
        form,
        &planned,
        recorded.as_ref(),
        &path,
    )?;
    print_summary(&phases, &planned, &a.out);
    Ok(Outcome::Clean)
}

/// The phases file (`--phases`) or the phases of a recorded clip (`--clip`), its path,
/// and the clip's recorded motion.
fn load(a: &TwopacArgs) -> anyhow::Result<(PhasesFile, PathBuf, Option<Recorded>)> {
    Ok(match &a.clip {
        Some(clip) => {
            let (file, rec) = clip_phases(clip)?;
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
    })
}

/// Plans the trajectory, checks both spans, validates and samples both curves, and times
/// the solves.
fn plan_phases(
    phases: &[Phase],
    file: &PhasesFile,
    form: QpForm,
    path: &Path,
) -> anyhow::Result<Planned> {
    let opts = PlanOptions {
        form,
        ..PlanOptions::default()
    };
    let t0 = Instant::now();
    let p = plan(phases, file.mass_kg, &file.start, &opts)
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
    let diags = phase_diagnostics(&p, phases);
    let v_curve = validate(&p, &p.forms, DEFAULT_STEP_S);
    let v_qs = validate(&qs, &p.forms, DEFAULT_STEP_S);
    let curve_rows = rows(&p, &p, &v_curve);
    let qs_rows = rows(&qs, &p, &v_qs);
    let timings = timings(phases, &p, file.mass_kg, &file.start, &opts);
    Ok(Planned {
        p,
        qs,
        diags,
        v_curve,
        v_qs,
        curve_rows,
        qs_rows,
        timings,
        plan_s,
    })
}

/// Writes the tables, `timings.json`, `trajectory.png` and (with a recording)
/// `recorded.json` into `out`.
fn write_outputs(
    out: &Path,
    phases: &[Phase],
    file: &PhasesFile,
    form: QpForm,
    r: &Planned,
    recorded: Option<&Recorded>,
    path: &Path,
) -> anyhow::Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let options = serde_json::json!({
        "phases_file_schema": crate::twopac::phases::PHASES_SCHEMA,
        "mass_kg": file.mass_kg,
        "n_phases": phases.len(),
        "form": form_name(form),
        "step_s": DEFAULT_STEP_S,
    });
    let kv = crate::library::schema::command_kv(crate::library::schema::TWOPAC_KEY, &options);
    let p = &r.p;
    let validations = [("2pac", &r.v_curve), ("quasi_static", &r.v_qs)];
    for (name, mut df) in [
        ("trajectory.parquet", trajectory_table(&r.curve_rows)?),
        ("quasi_static.parquet", trajectory_table(&r.qs_rows)?),
        ("phases.parquet", phases_table(p, phases, &r.diags)?),
        ("transitions.parquet", transitions_table(p, phases)?),
        ("windows.parquet", windows_table(p, phases)?),
        ("validation.parquet", validation_table(&validations)?),
    ] {
        write_atomic(out, name, &mut df, &kv)?;
    }
    write_json(&out.join("timings.json"), &r.timings)?;
    let mut data = plot_data(phases, p, &r.curve_rows, &r.qs);
    if let (Some(rec), Some(first), Some(last)) =
        (recorded, r.curve_rows.first(), r.curve_rows.last())
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
    super::write_png(&out.join("trajectory.png"), |path| {
        trajectory_png(path, &data)
    })?;
    if let Some(rec) = recorded {
        let planned: Vec<(f64, [f64; 3])> =
            r.curve_rows.iter().map(|r| (r.t_s, r.state.pos)).collect();
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
        write_json(&out.join("recorded.json"), &cmp)?;
        crate::say!(
            "  recorded COM vs 2PAC COM over the planned span: RMS {} m",
            rms.map_or("-".into(), |v| format!("{v:.4}"))
        );
    }
    Ok(())
}

/// Writes `v` as pretty JSON with a final newline, atomically.
fn write_json(path: &Path, v: &serde_json::Value) -> anyhow::Result<()> {
    Ok(write_text_atomic(
        path,
        &(serde_json::to_string_pretty(v)? + "\n"),
    )?)
}

/// The summary lines on stdout.
fn print_summary(phases: &[Phase], r: &Planned, out: &Path) {
    let p = &r.p;
    let n_static = p
        .transitions
        .iter()
        .filter(|t| t.point.is_static(crate::math::constants::STATIC_TOL))
        .count();
    let n_viol: usize = p.windows.iter().map(|w| w.violations.len()).sum();
    crate::say!(
        "twopac: {} phase(s), {} transition(s) ({n_static} statically feasible), {} window(s), \
         {n_viol} kinematic guarantee violation(s); planned in {:.3} ms",
        phases.len(),
        p.transitions.len(),
        p.windows.len(),
        r.plan_s * 1e3
    );
    for (name, v) in [("2pac", &r.v_curve), ("quasi-static", &r.v_qs)] {
        crate::say!(
            "  {name}: {} samples, point_valid_rate {:.3}, trajectory_valid {}, max s* {:.3} N at {:.2} s",
            v.samples.len(),
            v.point_valid_rate,
            v.trajectory_valid,
            v.max_slack_n,
            v.worst_t_s
        );
    }
    crate::say!("  → {}", out.display());
}
