//! The edit stage (`stancelib edit run|jump`): open the library, choose and solve the
//! request (`edit::select`), take poses from the source clip, and write `FILE.bvh`,
//! `FILE.plan.parquet` and `FILE.png`. Nothing is written unless the whole motion is
//! computed, and an infeasible request is refused unless it is allowed.

use std::path::{Path, PathBuf};

use anyhow::Context;

use super::edit_outputs::{plan_table, plot_of, sidecars, EditOutputs};
use super::queries::{load_pool, query_kv, write_table, LimitOptions};
use crate::bvh::{parse_file, write_file, Bvh};
use crate::edit::plan::{place, EditStance, PlanKind, StanceTiming};
use crate::edit::pose::{pose_motion, Reference};
use crate::edit::select::{
    choose_jump, choose_run, jump_stances, EditLimits, JumpTarget, RunTarget,
};
use crate::edit::{EditOptions, MAX_CYCLES, MAX_EDIT_FRAME_JOINTS, MAX_FPS, MIN_FPS};
use crate::ingest::body::BodyModel;
use crate::library::provenance::library_body;
use crate::library::read::{read_clip_sources, read_stance_timing};
use crate::library::schema::{CLIPS_FILE, STANCES_FILE};
use crate::pipeline::batch::file_sha256;
use crate::plot::edit::edit_png;
use crate::plot::write_png;
use crate::query::feasibility::LimitForm;
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
    /// `<stance_id>: <constraint>` of every stance that breaks one (written anyway).
    pub violated: Vec<String>,
    /// Frames whose COM or foot stayed off by more than the tolerance.
    pub unconverged: usize,
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
    let first = chosen.stances[0].source.stance_id.clone();
    let order: Vec<usize> = (0..e.cycles).flat_map(|_| [0, 1]).collect();
    let edit = compute(t, e.run.length_scale, chosen.stances, order, PlanKind::Run)?;
    let kv = query_kv(
        &t.lib,
        serde_json::json!({
            "edit": "run", "lib": t.lib, "speed_mps": e.run.speed_mps, "cycles": e.cycles,
            "stance": first, "k": chosen.k, "length_scale": e.run.length_scale,
            "mass_scale": e.run.mass_scale, "limits": limits.form.name(), "mu": limits.mu,
            "active_set": limits.active,
        }),
    )?;
    let title = format!(
        "Can cycle {first} run at {:.2} m/s? The edited run ({} cycles)",
        e.run.speed_mps, e.cycles
    );
    finish(t, edit, kv, title)
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
    let edit = compute(t, 1.0, stances, vec![0, 1], kind)?;
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
    finish(t, edit, kv, title)
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
        return Err(crate::error::Error::limit(
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

/// Builds the reference, places the plan and poses every frame.
fn compute(
    t: &EditTarget,
    length: f64,
    stances: Vec<EditStance>,
    order: Vec<usize>,
    kind: PlanKind,
) -> anyhow::Result<EditOutputs> {
    let clip = stances[0].source.clip.clone();
    let (bvh, unit, up) = source_clip(&t.lib, &clip, t.source.as_deref())?;
    let bvh = bvh.scaled(length);
    let (sex, landmarks) = library_body(&t.lib)?;
    let body =
        BodyModel::new(&bvh, unit, up, sex, &landmarks).with_context(|| format!("clip {clip}"))?;
    let frame_time_s = t.fps.map_or(bvh.motion.frame_time_s, |f| 1.0 / f);
    let reference = Reference::new(body, bvh.motion.clone())
        .with_context(|| format!("clip {clip}"))?
        .with_length_scale(length);
    let (path, sources) = place(&stances, &order, &reference, kind);
    check_frames(&path, frame_time_s, bvh.hierarchy.joints.len())?;
    let edited = pose_motion(
        &reference,
        &path,
        &sources,
        &EditOptions::default(),
        frame_time_s,
    );
    let footprints = path.stances.iter().map(|s| s.contact_point()).collect();
    let violated = stances.iter().filter_map(EditStance::violated).collect();
    Ok(EditOutputs {
        bvh,
        edited,
        reference,
        stances,
        order,
        footprints,
        violated,
    })
}

/// Refuses an infeasible edit (unless allowed), then writes the BVH and its sidecars.
fn finish(
    t: &EditTarget,
    e: EditOutputs,
    kv: Vec<(String, String)>,
    title: String,
) -> anyhow::Result<EditReport> {
    if !e.violated.is_empty() && !t.allow_infeasible {
        anyhow::bail!(
            "infeasible request: {} (nothing written; --allow-infeasible writes it anyway)",
            e.violated.join("; ")
        );
    }
    if let Some(dir) = t.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let mut df = plan_table(&e)?;
    let plot = plot_of(&e, title);
    let out = Bvh {
        hierarchy: e.bvh.hierarchy.clone(),
        motion: e.edited.motion.clone(),
        warnings: Vec::new(),
    };
    // The BVH writer is below the library's; the read's generation is checked here.
    crate::library::generation::before_output()?;
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
        violated: e.violated,
        unconverged: e.edited.frames.iter().filter(|f| !f.converged).count(),
    })
}
