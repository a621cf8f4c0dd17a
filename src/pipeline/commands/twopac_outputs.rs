//! The `twopac` stage after the phases are resolved: plan the trajectory and its
//! quasi-static baseline, validate and sample both (spec two-pac §7), and write the output
//! folder (§8): the six tables, `timings.json`, `trajectory.png` and, for a recorded clip,
//! `recorded.json`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;

use super::twopac::{clip_phases, plot_data, resolve, rows, timings, PolytopeSource, Recorded};
use super::twopac_tables::{
    form_name, phases_table, trajectory_table, transitions_table, validation_table, windows_table,
    TrajectoryRow,
};
use crate::library::codec::write::write_atomic;
use crate::library::storage::atomic::write_text_atomic;
use crate::pipeline::engine::inputs::{read_side_text, SideInput};
use crate::plot::trajectory::trajectory_png;
use crate::plot::trajectory::{curve_verdict, CurveSample};
use crate::plot::write_png;
use crate::plot::Verdict;
use crate::twopac::clip::{rms_to_recording, Recording};
use crate::twopac::diagnose::{explain, failures, Cause, Failure};
use crate::twopac::phases::{parse_phases, PhasesFile};
use crate::twopac::trajectory::{
    phase_diagnostics, plan, ComTrajectory, Phase, PhaseDiagnostic, Plan, PlanOptions, QuasiStatic,
};
use crate::twopac::transition::QpForm;
use crate::twopac::validate::{check_span, validate, Validation, DEFAULT_STEP_S};

/// A `twopac` job: where the phases and polytopes come from, the QP form, the output.
#[derive(Debug, Clone)]
pub struct TwopacJob {
    /// Phases file (JSON, `stancelib.twopac.phases/1`); else `clip`.
    pub phases: Option<PathBuf>,
    /// Phases from a recorded clip (needs `lib`).
    pub clip: Option<PathBuf>,
    /// Library folder of the named kinematic polytopes.
    pub lib: Option<PathBuf>,
    /// Character of the library's polytopes (default: the clip's, or the only one).
    pub character: Option<String>,
    /// Transition QP form.
    pub form: QpForm,
    /// Output folder.
    pub out: PathBuf,
}

/// What a `twopac` job planned and wrote.
pub struct TwopacReport {
    /// The resolved phases.
    pub phases: Vec<Phase>,
    /// The plan, its baseline and their validation.
    pub planned: Planned,
    /// RMS distance of the recorded COM to the planned one, m (`--clip` only).
    pub rms_to_recorded_m: Option<f64>,
    /// The phases came from a recorded clip.
    pub recorded: bool,
}

/// Runs a `twopac` job: load and resolve the phases, plan, validate, write.
///
/// # Errors
/// Bad options (a clip without a library, neither phases nor clip), an unreadable or
/// invalid phases file, a phase sequence the core rejects, an unwritable output.
pub fn run_twopac(job: &TwopacJob) -> anyhow::Result<TwopacReport> {
    if let Some(clip) = &job.clip {
        anyhow::ensure!(
            job.lib.is_some(),
            "--clip {}: the effectors' kinematic polytopes come from the library: give --lib LIB",
            clip.display()
        );
    }
    let (file, path, recorded) = load(job)?;
    let clip_id = recorded.as_ref().and_then(|r| r.character_id.as_deref());
    let src = PolytopeSource {
        lib: job.lib.as_deref(),
        character: job.character.as_deref(),
        clip: job.clip.as_deref(),
    };
    let phases = resolve(&file, &path, &src, clip_id)?;
    let planned = plan_phases(&phases, &file, job.form, &path)?;
    let rms = write_outputs(
        &job.out,
        &phases,
        &file,
        job.form,
        &planned,
        recorded.as_ref(),
        &path,
    )?;
    Ok(TwopacReport {
        phases,
        planned,
        rms_to_recorded_m: rms,
        recorded: recorded.is_some(),
    })
}

/// The phases file or the phases of a recorded clip, its path, and the clip's recorded
/// motion.
fn load(job: &TwopacJob) -> anyhow::Result<(PhasesFile, PathBuf, Option<Recorded>)> {
    Ok(match &job.clip {
        Some(clip) => {
            let (file, rec) = clip_phases(clip)?;
            (file, clip.clone(), Some(rec))
        }
        None => {
            let path = job
                .phases
                .clone()
                .context("give --phases FILE or --clip CLIP.bvh")?;
            let text = read_side_text(&path, SideInput::Phases)?;
            let file = parse_phases(&text).with_context(|| path.display().to_string())?;
            (file, path, None)
        }
    })
}

/// A planned phase sequence with everything the outputs need.
pub struct Planned {
    /// The 2PAC plan (§4–§6).
    pub p: Plan,
    /// The quasi-static baseline through the same transition points.
    pub qs: QuasiStatic,
    /// Per-phase diagnostics.
    pub diags: Vec<PhaseDiagnostic>,
    /// §7 validation of the 2PAC curve.
    pub v_curve: Validation,
    /// §7 validation of the baseline.
    pub v_qs: Validation,
    /// The 2PAC curve's invalid samples with their causes.
    pub fail_curve: Vec<Failure>,
    /// The baseline's invalid samples with their causes.
    pub fail_qs: Vec<Failure>,
    /// The effectors of each phase (`left_foot+right_foot`), to name phases in words.
    pub phase_names: Vec<String>,
    /// Body mass, kg.
    pub mass_kg: f64,
    /// Samples of the 2PAC curve.
    pub curve_rows: Vec<TrajectoryRow>,
    /// Samples of the baseline.
    pub qs_rows: Vec<TrajectoryRow>,
    /// Solve times (`timings.json`).
    pub timings: serde_json::Value,
    /// Wall time of the plan, s.
    pub plan_s: f64,
}

/// Plans the trajectory, checks both spans, validates and samples both curves, and times
/// the solves.
///
/// # Errors
/// The core cannot plan the phases, or a planned span is too long to sample.
pub fn plan_phases(
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
    let fail_curve = failures(&p, &p.forms, &v_curve);
    let fail_qs = failures(&qs, &p.forms, &v_qs);
    let curve_rows = rows(&p, &p, &v_curve);
    let qs_rows = rows(&qs, &p, &v_qs);
    let timings = timings(phases, &p, file.mass_kg, &file.start, &opts);
    Ok(Planned {
        p,
        qs,
        diags,
        v_curve,
        v_qs,
        fail_curve,
        fail_qs,
        phase_names: phase_names(phases),
        mass_kg: file.mass_kg,
        curve_rows,
        qs_rows,
        timings,
        plan_s,
    })
}

/// The effectors of each phase, joined by `+` (`left_foot+right_foot`).
pub fn phase_names(phases: &[Phase]) -> Vec<String> {
    phases
        .iter()
        .map(|p| {
            let e: Vec<&str> = p.contacts.iter().map(|c| c.effector.as_str()).collect();
            e.join("+")
        })
        .collect()
}

impl Planned {
    /// Why the 2PAC curve fails its validation, in words (`None` when valid).
    pub fn why_curve(&self) -> Option<String> {
        explain(&self.v_curve, &self.fail_curve, &self.phase_names)
    }

    /// The verdict line of `trajectory.png`: the 2PAC curve's, then the baseline's.
    pub fn plot_verdict(&self, samples: &[CurveSample]) -> Verdict {
        let v = curve_verdict(samples);
        let n = self.v_qs.samples.len();
        let qs = if self.v_qs.trajectory_valid {
            "the quasi-static baseline too".to_string()
        } else {
            let main = Cause::ALL
                .into_iter()
                .max_by_key(|c| self.fail_qs.iter().filter(|f| f.cause == *c).count())
                .map_or(String::new(), |c| c.as_str().replace('_', " "));
            format!(
                "quasi-static baseline not ({} of {n} samples fail, mostly {main})",
                self.fail_qs.len()
            )
        };
        Verdict::new(format!("{}; {qs}", v.text), v.ok)
    }

    /// The 2PAC curve's smallest robustness margin (N, §8.2, with each sample's own
    /// acceleration), its time (s) and phase: how far the COM stays from the edge of
    /// what the contacts can hold (≈ 0: it runs along the edge of the support). `None`
    /// without a finite margin (force closure, infeasible samples).
    pub fn smallest_margin(&self) -> Option<(f64, f64, usize)> {
        self.curve_rows
            .iter()
            .filter_map(|r| r.verdict.margin_n.map(|m| (m, r.t_s, r.phase)))
            .filter(|(m, _, _)| m.is_finite())
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// Why the quasi-static baseline fails its validation, in words (`None` when valid).
    pub fn why_qs(&self) -> Option<String> {
        explain(&self.v_qs, &self.fail_qs, &self.phase_names)
    }
}

/// Writes the tables, `timings.json`, `trajectory.png` and (with a recording)
/// `recorded.json` into `out`; returns the RMS distance of the recorded COM to the planned
/// one over the planned span, m (with a recording that overlaps it).
///
/// # Errors
/// A table cannot be built, an unwritable folder or file.
pub fn write_outputs(
    out: &Path,
    phases: &[Phase],
    file: &PhasesFile,
    form: QpForm,
    r: &Planned,
    recorded: Option<&Recorded>,
    path: &Path,
) -> anyhow::Result<Option<f64>> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let options = serde_json::json!({
        "phases_file_schema": crate::twopac::phases::PHASES_SCHEMA,
        "mass_kg": file.mass_kg,
        "n_phases": phases.len(),
        "form": form_name(form),
        "step_s": DEFAULT_STEP_S,
    });
    let kv = crate::library::codec::schema::command_kv(
        crate::library::codec::schema::TWOPAC_KEY,
        &options,
    );
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
    let mut data = plot_data(phases, p, &r.curve_rows, &r.qs, &r.fail_curve);
    data.verdict = Some(r.plot_verdict(&data.samples));
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
    write_png(&out.join("trajectory.png"), |path| {
        trajectory_png(path, &data)
    })?;
    let Some(rec) = recorded else {
        return Ok(None);
    };
    let planned: Vec<(f64, [f64; 3])> = r.curve_rows.iter().map(|r| (r.t_s, r.state.pos)).collect();
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
    Ok(rms)
}

/// Writes `v` as pretty JSON with a final newline, atomically.
fn write_json(path: &Path, v: &serde_json::Value) -> anyhow::Result<()> {
    Ok(write_text_atomic(
        path,
        &(serde_json::to_string_pretty(v)? + "\n"),
    )?)
}
