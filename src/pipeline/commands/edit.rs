//! The edit stage (`stancelib edit run|jump`): open the library, choose and solve the
//! request (`edit::select`), take poses from the source clip, and write `FILE.bvh`,
//! `FILE.plan.parquet` and `FILE.png`. Nothing is written unless the whole motion is
//! computed, and an infeasible request is refused unless it is allowed.

use std::path::{Path, PathBuf};

use anyhow::Context;

use super::edit_outputs::{plan_table, plot_of, sidecars, EditOutputs};
use super::queries::{load_pool, query_kv, write_table, LimitOptions};
use crate::bvh::{parse_file, write_file, Bvh};
use crate::edit::fidelity::{check, recorded_knee_range, FidelityOptions};
use crate::edit::footing::{impulse_change, pose_reaching, Footing};
use crate::edit::plan::{place, EditStance, PlanKind, StanceTiming};
use crate::edit::pose::{pose_motion, Reference};
use crate::edit::select::{
    choose_jump, choose_run, jump_stances, ChosenRun, EditLimits, JumpTarget, RunTarget,
};
use crate::edit::swing::{fold_change_deg, fold_swing_knees, swings, FoldReport, Swing};
use crate::edit::{
    EditOptions, DEFAULT_JUMP_SWING_HOLD_S, MAX_CYCLES, MAX_EDIT_FRAME_JOINTS, MAX_FPS, MIN_FPS,
    RUN_KNEE_SLACK_DEG,
};
use crate::ingest::body::BodyModel;
use crate::library::codec::provenance::library_body;
use crate::library::codec::schema::{CLIPS_FILE, STANCES_FILE};
use crate::library::readers::read::{read_clip_sources, read_stance_timing};
use crate::pipeline::engine::inputs::file_sha256;
use crate::plot::edit::edit_png;
use crate::plot::write_png;
use crate::query::feasibility::LimitForm;
use crate::query::jump::recorded_jump;
use crate::query::limits::{left_out_line, LeftOut};
use crate::query::run::{check_scale, check_speed};
use crate::skeleton::units::UpAxis;

/// What every edit shares: the library, the source of the poses, the output and limits.
#[derive(Debug, Clone)]
pub struct EditTarget {
    /// Library folder.
    pub lib: PathBuf,
    /// Output BVH (`.bvh`); the plan and the plot are written beside it.
    pub out: PathBuf,
    /// Output frame rate, Hz (`None`: the source clip's).
    pub fps: Option<f64>,
    /// Source BVH instead of the path recorded in `clips.parquet`.
    pub source: Option<PathBuf>,
    /// Write the motion even when the request breaks a constraint.
    pub allow_infeasible: bool,
    /// Limit form, μ and active set (§7.5).
    pub limits: LimitOptions,
}

/// `edit run`: `cycles` steady cycles of the best run cycle at a speed.
#[derive(Debug, Clone)]
pub struct RunEdit {
    /// Library, output and limits.
    pub target: EditTarget,
    /// Speed and character.
    pub run: RunTarget,
    /// Steady cycles written, `1..=MAX_CYCLES`.
    pub cycles: usize,
}

/// `edit jump`: a liftoff → flight → landing at an apex height and distance.
#[derive(Debug, Clone)]
pub struct JumpEdit {
    /// Library, output and limits.
    pub target: EditTarget,
    /// Height, distance and pair.
    pub jump: JumpTarget,
}

/// What an edit wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct EditReport {
    /// Frames written.
    pub n_frames: usize,
    /// Their rate, Hz.
    pub fps_hz: f64,
    /// The BVH, `FILE.plan.parquet` and `FILE.png`.
    pub bvh: PathBuf,
    /// The plan table.
    pub plan: PathBuf,
    /// The plot.
    pub png: PathBuf,
    /// The recorded cycle (`A + B`) or jump pair (`A → B`) the edit plays.
    pub used: String,
    /// What the plan achieves: a run's mean speed with its gait law, contact times and
    /// step periods; a jump's apex height and distance.
    pub achieved: String,
    /// Every stance passes the exact check (§7.4).
    pub feasible: bool,
    /// Infeasible: each failing stance's deciding constraint, value, limit and margin
    /// (`query::tables::violation_detail`, written anyway with `--allow-infeasible`);
    /// feasible: the constraint nearest to breaking (`tightest_detail`).
    pub deciding: Vec<String>,
    /// Frames whose COM or foot stayed off by more than the tolerance.
    pub unconverged: usize,
    /// The support foot farthest from its planned place: (frame, distance m), when one is
    /// off by more than the tolerance (out of reach: knee straight, heel up to its bound,
    /// pelvis turned to its bound).
    pub foot_off: Option<(usize, f64)>,
    /// The posture and smoothness figures against the source ([`crate::edit::fidelity`]).
    pub fidelity: String,
    /// One line per posture or smoothness check that fails.
    pub unfaithful: Vec<String>,
}

impl EditTarget {
    /// Checks the output name and the frame rate before any work.
    ///
    /// # Errors
    /// An output not ending in `.bvh`, a rate outside `MIN_FPS..=MAX_FPS`.
    fn check(&self) -> anyhow::Result<()> {
        let ok = self
            .out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("bvh"));
        anyhow::ensure!(ok, "--out {}: must end in .bvh", self.out.display());
        if let Some(f) = self.fps {
            anyhow::ensure!(
                f.is_finite() && (MIN_FPS..=MAX_FPS).contains(&f),
                "--fps: must be from {MIN_FPS} to {MAX_FPS} Hz (MIN_FPS, MAX_FPS), found {f}"
            );
        }
        Ok(())
    }

    /// The limits with the form defaulting to `default`.
    fn edit_limits(&self, default: LimitForm) -> anyhow::Result<EditLimits> {
        let (form, mu) = self.limits.form(default)?;
        let active = self.limits.active_fraction()?;
        Ok(EditLimits { form, mu, active })
    }
}

/// Runs `edit run`.
///
/// # Errors
/// Bad options, an unreadable library or source, no solvable cycle, an infeasible request
/// (unless allowed), an unwritable output.
pub fn edit_run(e: &RunEdit) -> anyhow::Result<EditReport> {
    let t = &e.target;
    t.check()?;
    check_speed("--speed", e.run.speed_mps)?;
    check_scale("--length-scale", e.run.length_scale)?;
    check_scale("--mass-scale", e.run.mass_scale)?;
    anyhow::ensure!(
        (1..=MAX_CYCLES).contains(&e.cycles),
        "--cycles: must be from 1 to {MAX_CYCLES} (MAX_CYCLES), found {}",
        e.cycles
    );
    let limits = t.edit_limits(LimitForm::Absolute)?;
    let (lib, pool) = load_pool(&t.lib, limits.active)?;
    let times = timing(&t.lib)?;
    let chosen = choose_run(&lib, &pool, &times, &e.run, limits)
        .with_context(|| format!("library {}", t.lib.display()))?;
    report_left_out("edit run", "cycle(s)", &chosen.left_out);
    let first = chosen.stances[0].source.stance_id.clone();
    let used = format!("{first} + {}", chosen.stances[1].source.stance_id);
    let fold = swing_plan(&lib, &times, &chosen, e.run.length_scale);
    let achieved = run_achieved(&chosen, e.run.speed_mps);
    let order: Vec<usize> = (0..e.cycles).flat_map(|_| [0, 1]).collect();
    let stances = chosen.stances.clone();
    let edit = compute(t, e.run.length_scale, stances, order, PlanKind::Run, &fold)?;
    let mut achieved = format!("{achieved}; {}", swing_text(&edit.swing));
    if let Some(moved) = footing_text(&edit) {
        achieved = format!("{achieved}; {moved}");
    }
    let tm = &chosen.timing;
    let kv = query_kv(
        &t.lib,
        serde_json::json!({
            "edit": "run", "lib": t.lib, "speed_mps": e.run.speed_mps, "cycles": e.cycles,
            "stance": first, "k": chosen.k, "length_scale": e.run.length_scale,
            "mass_scale": e.run.mass_scale, "limits": limits.form.name(), "mu": limits.mu,
            "active_set": limits.active, "gait_law": tm.law.source.name(),
            "sigma_contact": tm.sigma_c, "sigma_step": tm.sigma_t, "kappa": tm.kappa,
            "speed_achieved_mps": chosen.speed_mps, "keep_left_out": e.run.keep_left_out,
            "swing_fold_deg": edit.swing.asked_deg, "contact_shift_m": edit.footing.shift_m,
        }),
    )?;
    let title = format!(
        "Can cycle {first} run at {:.2} m/s? The edited run ({} cycles)",
        e.run.speed_mps, e.cycles
    );
    finish(t, edit, kv, title, (used, achieved))
}

/// The swings of the chosen cycle's clip and the fold change the speed law asks of them
/// ([`crate::edit::swing`]): from the recorded speed to the planned one, on a character
/// `length_scale` times the source's size.
fn swing_plan(
    lib: &crate::library::readers::read::StanceLibrary,
    times: &[StanceTiming],
    chosen: &ChosenRun,
    length_scale: f64,
) -> (Vec<Swing>, f64) {
    let clip = &chosen.stances[0].source.clip;
    let own = lib
        .stances
        .iter()
        .zip(times)
        .filter(|(s, _)| &s.clip == clip)
        .map(|(s, t)| (s.label.as_str(), t.td_clip_s, t.lo_clip_s));
    // `v_orig` is the recorded speed on the character (times √L): its legs are L times.
    let leg = lib
        .clips
        .get(clip)
        .and_then(|c| c.leg_m)
        .unwrap_or(f64::NAN)
        * length_scale;
    let delta = fold_change_deg(chosen.v_orig, chosen.speed_mps, leg);
    (swings(own), delta)
}

/// The swing fold in one phrase, for the verdict.
fn swing_text(r: &FoldReport) -> String {
    if r.folded == 0 {
        return format!(
            "swing knee as recorded (speed law {:+.1}°; {} of {} swings folded)",
            r.asked_deg, r.folded, r.swings
        );
    }
    format!(
        "swing knee {:+.1}° at its fold (speed law {:+.1}°, {} of {} swings)",
        r.applied_deg, r.asked_deg, r.folded, r.swings
    )
}

/// The contacts a run moved for its legs to reach, in one phrase (`None`: none moved):
/// per moved stance the shift, the support frames off the plan before and after, and the
/// change of its angular impulse ([`crate::edit::footing`]).
fn footing_text(e: &EditOutputs) -> Option<String> {
    let f = &e.footing;
    let each: Vec<String> = e
        .stances
        .iter()
        .enumerate()
        .filter(|&(i, _)| f.shift_m[i] != 0.0)
        .map(|(i, s)| {
            let d = f.shift_m[i];
            format!(
                "{} {:.1} cm {} (off the plan for {:.0} → {:.0} ms of the stance, pitch angular \
                 impulse {:+.1} N·m·s)",
                s.source.stance_id,
                d.abs() * 100.0,
                if d > 0.0 { "forward" } else { "back" },
                f.before[i].total() as f64 * f.miss_s[i] * 1e3,
                f.after[i].total() as f64 * f.miss_s[i] * 1e3,
                impulse_change(s, d)
            )
        })
        .collect();
    (!each.is_empty()).then(|| {
        format!(
            "contact moved where the legs do not reach the plan's: {}",
            each.join(", ")
        )
    })
}

/// A run's plan in one phrase: its mean speed, the gait law and each stance's contact time
/// and step period (the query's, `query run`'s `contact_time_s`, `step_period_s`).
fn run_achieved(c: &ChosenRun, asked: f64) -> String {
    let each = |f: &dyn Fn(&crate::query::solve::Solution) -> f64| {
        let v: Vec<String> = c
            .stances
            .iter()
            .map(|e| format!("{:.3}", f(&e.scaled.solution)))
            .collect();
        v.join(" / ")
    };
    format!(
        "speed {:.3} m/s (asked {asked}, recorded {:.3}), gait law {}: contact {} s, \
         step period {} s",
        c.speed_mps,
        c.v_orig,
        c.timing.law.source.name(),
        each(&|s| s.t_lo - s.t_td),
        each(&|s| s.t_e),
    )
}

/// Prints (stderr) the clips an edit left out ([`left_out_line`]).
fn report_left_out(command: &str, what: &str, left: &[(String, LeftOut)]) {
    let clips: std::collections::BTreeMap<&String, &LeftOut> =
        left.iter().map(|(c, w)| (c, w)).collect();
    let named: Vec<(&String, &LeftOut)> = clips.into_iter().collect();
    if let Some(line) = left_out_line(command, left.len(), what, &named) {
        eprintln!("{line}");
    }
}

/// Runs `edit jump`.
///
/// # Errors
/// Bad options, an unreadable library or source, no solvable pair, an infeasible request
/// (unless allowed), an unwritable output.
pub fn edit_jump(e: &JumpEdit) -> anyhow::Result<EditReport> {
    let t = &e.target;
    t.check()?;
    for (n, v) in [
        ("--height", e.jump.height_m),
        ("--distance", e.jump.distance_m),
        ("--height-scale", e.jump.height_scale),
    ] {
        if let Some(v) = v {
            anyhow::ensure!(v.is_finite(), "{n} must be a number, found {v}");
        }
    }
    let limits = t.edit_limits(LimitForm::Absolute)?;
    let (lib, pool) = load_pool(&t.lib, limits.active)?;
    let times = timing(&t.lib)?;
    let chosen = choose_jump(&lib, &pool, &e.jump, limits)
        .with_context(|| format!("library {}", t.lib.display()))?;
    report_left_out("edit jump", "pair(s)", &chosen.left_out);
    let [i, j] = chosen.pair;
    let ids = format!(
        "{} → {}",
        lib.stances[i].stance_id, lib.stances[j].stance_id
    );
    let stances = jump_stances(&lib, &pool, &times, &chosen);
    // The landing right after the liftoff in their clip keeps its recorded turn.
    let kind = if j == i + 1 && lib.stances[i].clip == lib.stances[j].clip {
        PlanKind::Jump
    } else {
        PlanKind::PairedJump
    };
    let edit = compute(t, 1.0, stances, vec![0, 1], kind, &(Vec::new(), 0.0))?;
    let (h, d) = (chosen.height_m, chosen.distance_m);
    let kv = query_kv(
        &t.lib,
        serde_json::json!({
            "edit": "jump", "lib": t.lib, "height_m": h, "distance_m": d, "pair": ids,
            "limits": limits.form.name(), "mu": limits.mu, "active_set": limits.active,
        }),
    )?;
    // A jump in place printed "distance -0.00 m", which read as backwards.
    let d_shown = if d.abs() < 0.005 { 0.0 } else { d };
    let title = format!("Can {ids} jump {h:.2} m high, {d_shown:.2} m far? The edited jump");
    let (h0, d0) = recorded_jump(&lib.stances[i], &lib.stances[j]);
    let achieved = format!(
        "apex {h:.3} m, distance {d_shown:.3} m (recorded {h0:.3} m, {d0:.3} m: × {:.3} in height)",
        h / h0
    );
    finish(t, edit, kv, title, (ids, achieved))
}

fn timing(lib: &Path) -> anyhow::Result<Vec<StanceTiming>> {
    Ok(read_stance_timing(&lib.join(STANCES_FILE))?)
}

/// The source clip of `clip`: the recorded path (or `over`), checked against the recorded
/// content hash, parsed, with its unit and up axis.
fn source_clip(lib: &Path, clip: &str, over: Option<&Path>) -> anyhow::Result<(Bvh, f64, UpAxis)> {
    let clips = read_clip_sources(&lib.join(CLIPS_FILE))?;
    let c = clips
        .get(clip)
        .with_context(|| format!("clip {clip}: not in {}", lib.join(CLIPS_FILE).display()))?;
    let path = match over {
        Some(p) => p.to_path_buf(),
        None => recorded_path(lib, &c.path),
    };
    let sha = file_sha256(&path).with_context(|| {
        format!(
            "clip {clip}: source {} cannot be read (give it with --source)",
            path.display()
        )
    })?;
    anyhow::ensure!(
        sha == c.content_sha256,
        "clip {clip}: source {} is not the file the library was built from (content hash differs)",
        path.display()
    );
    let bvh = parse_file(&path)?;
    let unit = c.unit_scale.context("clips.parquet: unit_scale is null")?;
    let up = c
        .up_axis
        .as_deref()
        .and_then(UpAxis::parse)
        .context("clips.parquet: up_axis is missing or unknown")?;
    Ok((bvh, unit, up))
}

/// A clip's recorded path; a relative one that does not exist is looked for beside the
/// library folder.
fn recorded_path(lib: &Path, recorded: &str) -> PathBuf {
    let p = PathBuf::from(recorded);
    match lib.parent().map(|d| d.join(&p)) {
        Some(b) if !p.exists() && p.is_relative() && b.exists() => b,
        _ => p,
    }
}

/// Checks the frames × joints of the planned output against [`MAX_EDIT_FRAME_JOINTS`]
/// before any frame is posed.
///
/// # Errors
/// Beyond the limit: the frames, rate and joints asked for, and the options that set them.
fn check_frames(
    path: &crate::edit::path::ComPath,
    frame_time_s: f64,
    joints: usize,
) -> anyhow::Result<()> {
    let frames = crate::edit::pose::frame_count_f64(path, frame_time_s);
    let n = frames * joints as f64;
    if n > MAX_EDIT_FRAME_JOINTS as f64 {
        let field = format!(
            "edit output ({} frames at {:.1} Hz × {joints} joints; lower --cycles or --fps)",
            crate::error::count_text(frames),
            1.0 / frame_time_s
        );
        return Err(crate::error::Error::cap(
            field,
            "frame-joints",
            n,
            MAX_EDIT_FRAME_JOINTS,
            "MAX_EDIT_FRAME_JOINTS",
        )
        .into());
    }
    Ok(())
}

/// Builds the reference (its swing knees folded by `fold`'s change, [`fold_swing_knees`]),
/// places the plan and poses every frame.
fn compute(
    t: &EditTarget,
    length: f64,
    stances: Vec<EditStance>,
    order: Vec<usize>,
    kind: PlanKind,
    fold: &(Vec<Swing>, f64),
) -> anyhow::Result<EditOutputs> {
    let clip = stances[0].source.clip.clone();
    let (bvh, unit, up) = source_clip(&t.lib, &clip, t.source.as_deref())?;
    let bvh = bvh.scaled(length);
    let (sex, landmarks) = library_body(&t.lib)?;
    let body =
        BodyModel::new(&bvh, unit, up, sex, &landmarks).with_context(|| format!("clip {clip}"))?;
    let frame_time_s = t.fps.map_or(bvh.motion.frame_time_s, |f| 1.0 / f);
    let (motion, swing) = fold_swing_knees(&body, &bvh.motion, &fold.0, fold.1);
    let reference = Reference::new(body, motion)
        .with_context(|| format!("clip {clip}"))?
        .with_length_scale(length);
    let (path, sources) = place(&stances, &order, &reference, kind);
    check_frames(&path, frame_time_s, bvh.hierarchy.joints.len())?;
    let mut opts = EditOptions::default();
    if kind == PlanKind::Run {
        // The knee stays within the source's range over the cycle (`RUN_KNEE_SLACK_DEG`).
        let t0 = sources
            .iter()
            .map(|s| s.td_clip_s - s.before_s)
            .fold(f64::INFINITY, f64::min);
        let t1 = sources
            .iter()
            .map(|s| s.lo_clip_s + s.after_s)
            .fold(f64::NEG_INFINITY, f64::max);
        let [least, _] = recorded_knee_range(&reference.body, &reference.motion, t0, t1);
        if least.is_finite() {
            opts.min_knee_flexion_deg = (least - RUN_KNEE_SLACK_DEG).max(0.0);
        }
    }
    if kind != PlanKind::Run {
        opts.swing_hold_s = DEFAULT_JUMP_SWING_HOLD_S;
    }
    let fidelity_opts = match kind {
        PlanKind::Run => FidelityOptions::run(),
        PlanKind::Jump | PlanKind::PairedJump => FidelityOptions::jump(),
    };
    let mut stances = stances;
    let (path, edited, footing) = if kind == PlanKind::Run {
        let (path, _, edited, footing) = pose_reaching(
            &mut stances,
            &order,
            &reference,
            &opts,
            fidelity_opts,
            frame_time_s,
        );
        (path, edited, footing)
    } else {
        let edited = pose_motion(&reference, &path, &sources, &opts, frame_time_s);
        (path, edited, Footing::none(stances.len()))
    };
    let footprints = path.stances.iter().map(|s| s.contact_point()).collect();
    let violated = stances
        .iter()
        .filter_map(EditStance::violation_detail)
        .collect();
    let mut fidelity = check(
        &reference.body,
        &reference.motion,
        &edited.motion,
        &edited.frames,
        fidelity_opts,
    );
    fidelity.swing_folded = swing.folded > 0;
    Ok(EditOutputs {
        bvh,
        edited,
        reference,
        stances,
        order,
        footprints,
        violated,
        fidelity,
        swing,
        footing,
    })
}

/// Refuses an infeasible edit (unless allowed), then writes the BVH and its sidecars.
/// `(used, achieved)`: the cycle or pair played and what its plan achieves (for the report).
fn finish(
    t: &EditTarget,
    e: EditOutputs,
    kv: Vec<(String, String)>,
    title: String,
    (used, achieved): (String, String),
) -> anyhow::Result<EditReport> {
    if !e.violated.is_empty() && !t.allow_infeasible {
        anyhow::bail!(
            "infeasible request ({used}; {achieved}): {} (nothing written; --allow-infeasible \
             writes it anyway, exit 3)",
            e.violated.join("; ")
        );
    }
    let feasible = e.violated.is_empty();
    let deciding = if feasible {
        e.stances
            .iter()
            .filter_map(EditStance::tightest_detail)
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, d)| d)
            .into_iter()
            .collect()
    } else {
        e.violated.clone()
    };
    if let Some(dir) = t.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let mut df = plan_table(&e)?;
    let unconverged = e.edited.frames.iter().filter(|f| !f.converged).count();
    let verdict = match (feasible, unconverged) {
        (true, 0) => "feasible".to_string(),
        (true, n) => format!("feasible, {n} frame(s) not converged"),
        (false, 0) => "INFEASIBLE".to_string(),
        (false, n) => format!("INFEASIBLE, {n} frame(s) not converged"),
    };
    let plot = plot_of(&e, format!("{title} ({verdict})"));
    let out = Bvh {
        hierarchy: e.bvh.hierarchy.clone(),
        motion: e.edited.motion.clone(),
        warnings: Vec::new(),
    };
    // The BVH writer is below the library's; the read's generation is checked here.
    crate::library::storage::generation::before_output()?;
    write_file(&t.out, &out)?;
    let (plan, png) = sidecars(&t.out);
    write_table(&plan, &mut df, &kv)?;
    write_png(&png, |p| edit_png(p, &plot))?;
    Ok(EditReport {
        n_frames: e.edited.frames.len(),
        fps_hz: 1.0 / e.edited.motion.frame_time_s,
        bvh: t.out.clone(),
        plan,
        png,
        used,
        achieved,
        feasible,
        deciding,
        unconverged,
        foot_off: e
            .edited
            .frames
            .iter()
            .enumerate()
            .map(|(i, f)| (i, f.foot_error_m))
            .filter(|&(_, d)| d > EditOptions::default().com_tol_m)
            .max_by(|a, b| a.1.total_cmp(&b.1)),
        fidelity: e.fidelity.summary(),
        unfaithful: e.fidelity.failures(),
    })
}
