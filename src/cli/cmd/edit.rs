//! `stancelib edit run` and `stancelib edit jump`: choose and solve the request with the
//! query code, take poses from the source clip, write `FILE.bvh`, `FILE.plan.parquet` and
//! `FILE.png`. Nothing is written unless the whole motion is computed.

use std::path::{Path, PathBuf};

use anyhow::Context;
use polars::prelude::{Column, DataFrame};

use super::super::args::{EditCommon, EditJumpArgs, EditRunArgs};
use super::super::Outcome;
use super::write_png;
use crate::bvh::{parse_file, write_file, Bvh};
use crate::edit::path::Phase;
use crate::edit::plan::{
    place, refine_run_k, run_requests, solve_stance, EditStance, StanceTiming,
};
use crate::edit::pose::{pose_motion, EditedMotion, Reference};
use crate::edit::{EditOptions, MAX_CYCLES, MAX_FPS, MIN_FPS};
use crate::ingest::body::BodyModel;
use crate::library::provenance::library_body;
use crate::library::read::{read_clip_sources, read_stance_timing, StanceLibrary};
use crate::library::schema::{CLIPS_FILE, STANCES_FILE};
use crate::pipeline::batch::file_sha256;
use crate::pipeline::queries::{load_pool, query_kv, write_table};
use crate::plot::edit::{edit_png, EditPlot};
use crate::query::feasibility::LimitForm;
use crate::query::jump::{is_landing, is_liftoff, jump, recorded_jump};
use crate::query::limits::{absolute_limits, stance_limits, time_scaled};
use crate::query::pairs::jump_rank;
use crate::query::pool::Prepared;
use crate::query::run::{check_scale, check_speed, run_cycles};
use crate::skeleton::units::UpAxis;

/// Stick figures in the plot, s apart.
const PLOT_STICK_EVERY_S: f64 = 0.1;

/// The sidecar paths of `FILE.bvh`: `FILE.plan.parquet`, `FILE.png`.
pub fn sidecars(out: &Path) -> (PathBuf, PathBuf) {
    (
        out.with_extension("plan.parquet"),
        out.with_extension("png"),
    )
}

fn check_out(c: &EditCommon) -> anyhow::Result<()> {
    let ok = c
        .out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("bvh"));
    anyhow::ensure!(ok, "--out {}: must end in .bvh", c.out.display());
    if let Some(f) = c.fps {
        anyhow::ensure!(
            f.is_finite() && (MIN_FPS..=MAX_FPS).contains(&f),
            "--fps: must be from {MIN_FPS} to {MAX_FPS} Hz (MIN_FPS, MAX_FPS), found {f}"
        );
    }
    Ok(())
}

/// The source clip of `clip`: the recorded path (or `--source`), checked against the
/// recorded content hash, parsed, with its unit and up axis.
fn source_clip(lib: &Path, clip: &str, over: Option<&Path>) -> anyhow::Result<(Bvh, f64, UpAxis)> {
    let clips = read_clip_sources(&lib.join(CLIPS_FILE))?;
    let c = clips
        .get(clip)
        .with_context(|| format!("clip {clip}: not in {}", lib.join(CLIPS_FILE).display()))?;
    let path = match over {
        Some(p) => p.to_path_buf(),
        None => {
            let p = PathBuf::from(&c.path);
            let beside = lib.parent().map(|d| d.join(&p));
            match beside {
                Some(b) if !p.exists() && p.is_relative() && b.exists() => b,
                _ => p,
            }
        }
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

/// The source scaled to a character `length` times as long (offsets, End Sites and
/// position channels × L).
fn scale_source(mut bvh: Bvh, length: f64) -> Bvh {
    if length == 1.0 {
        return bvh;
    }
    let mut pos = Vec::new();
    for j in &mut bvh.hierarchy.joints {
        j.offset = j.offset.map(|v| v * length);
        j.end_site = j.end_site.map(|e| e.map(|v| v * length));
        for (k, c) in j.channels.iter().enumerate() {
            if !c.is_rotation() {
                pos.push(j.first_channel + k);
            }
        }
    }
    let nc = bvh.motion.n_channels;
    for (i, v) in bvh.motion.values.iter_mut().enumerate() {
        if pos.contains(&(i % nc)) {
            *v *= length;
        }
    }
    bvh
}

/// Everything an edit computes before anything is written.
struct Edit {
    bvh: Bvh,
    edited: EditedMotion,
    reference: Reference,
    stances: Vec<EditStance>,
    order: Vec<usize>,
    footprints: Vec<[f64; 3]>,
    violated: Vec<String>,
}

fn timing(lib: &Path) -> anyhow::Result<Vec<StanceTiming>> {
    Ok(read_stance_timing(&lib.join(STANCES_FILE))?)
}

/// Builds the reference, places the plan and poses every frame.
fn compute(
    c: &EditCommon,
    clip: &str,
    length: f64,
    stances: Vec<EditStance>,
    order: Vec<usize>,
    jump: bool,
) -> anyhow::Result<Edit> {
    let (bvh, unit, up) = source_clip(&c.lib, clip, c.source.as_deref())?;
    let bvh = scale_source(bvh, length);
    let (sex, landmarks) = library_body(&c.lib)?;
    let body =
        BodyModel::new(&bvh, unit, up, sex, &landmarks).with_context(|| format!("clip {clip}"))?;
    let frame_time_s = c.fps.map_or(bvh.motion.frame_time_s, |f| 1.0 / f);
    let reference =
        Reference::new(body, bvh.motion.clone()).with_context(|| format!("clip {clip}"))?;
    let (path, sources) = place(&stances, &order, &reference, jump, jump);
    let edited = pose_motion(
        &reference,
        &path,
        &sources,
        &EditOptions::default(),
        frame_time_s,
    );
    let footprints = path.stances.iter().map(|s| s.contact_point()).collect();
    let violated = stances.iter().filter_map(EditStance::violated).collect();
    Ok(Edit {
        bvh,
        edited,
        reference,
        stances,
        order,
        footprints,
        violated,
    })
}

fn plan_table(e: &Edit) -> anyhow::Result<DataFrame> {
    let f = &e.edited.frames;
    let id = |p: &Phase| match p {
        Phase::Stance(k) => Some(e.stances[e.order[*k]].source.stance_id.clone()),
        Phase::Flight { .. } => None,
    };
    let bad = |p: &Phase| match p {
        Phase::Stance(k) => e.stances[e.order[*k]].violated(),
        Phase::Flight { .. } => None,
    };
    let v3 = |name: &str, g: &dyn Fn(usize) -> Option<[f64; 3]>| -> Vec<Column> {
        (0..3)
            .map(|a| {
                let v: Vec<Option<f64>> = (0..f.len()).map(|i| g(i).map(|p| p[a])).collect();
                Column::new(format!("{name}_{}_m", ["x", "y", "z"][a]).into(), v)
            })
            .collect()
    };
    let dt = e.edited.motion.frame_time_s;
    let mut cols = vec![
        Column::new(
            "time_clip_s".into(),
            (0..f.len()).map(|i| i as f64 * dt).collect::<Vec<_>>(),
        ),
        Column::new(
            "phase".into(),
            f.iter()
                .map(|x| match x.phase {
                    Phase::Stance(_) => "stance",
                    Phase::Flight { .. } => "flight",
                })
                .collect::<Vec<_>>(),
        ),
        Column::new(
            "stance_id".into(),
            f.iter().map(|x| id(&x.phase)).collect::<Vec<_>>(),
        ),
    ];
    cols.extend(v3("com", &|i| Some(f[i].com_plan)));
    cols.extend(v3("pose_com", &|i| Some(f[i].com_pose)));
    cols.extend(v3("contact", &|i| f[i].contact));
    cols.extend(v3("foot", &|i| f[i].foot));
    for (n, name) in ["stance_td_clip_s", "stance_lo_clip_s"].iter().enumerate() {
        let v: Vec<Option<f64>> = f
            .iter()
            .map(|x| x.window.map(|w| if n == 0 { w.0 } else { w.1 }))
            .collect();
        cols.push(Column::new((*name).into(), v));
    }
    cols.push(Column::new(
        "converged".into(),
        f.iter().map(|x| x.converged).collect::<Vec<_>>(),
    ));
    cols.push(Column::new(
        "iterations".into(),
        f.iter().map(|x| x.iterations as i64).collect::<Vec<_>>(),
    ));
    cols.push(Column::new(
        "violated".into(),
        f.iter().map(|x| bad(&x.phase)).collect::<Vec<_>>(),
    ));
    Ok(DataFrame::new_infer_height(cols)?)
}

fn plot_of(e: &Edit, title: String) -> EditPlot {
    let body = &e.reference.body;
    let sk = &body.skeleton;
    let m = &e.edited.motion;
    let every = ((PLOT_STICK_EVERY_S / m.frame_time_s).round() as usize).max(1);
    let mut ws = crate::skeleton::fk::FkWorkspace::new(sk);
    let (mut file, mut pts) = (vec![[0.0; 3]; sk.n_points()], vec![[0.0; 3]; sk.n_points()]);
    let mut bones = Vec::new();
    for fr in (0..m.n_frames()).step_by(every) {
        body.points(&mut ws, m.row(fr), &mut file, &mut pts);
        for j in 0..sk.n_joints() {
            if let Some(p) = sk.parents[j] {
                bones.push([pts[p], pts[j]]);
            }
        }
        for (e_i, (j, _)) in sk.end_sites.iter().enumerate() {
            bones.push([pts[*j], pts[sk.n_joints() + e_i]]);
        }
    }
    EditPlot {
        title,
        com: e.edited.frames.iter().map(|f| f.com_plan).collect(),
        footprints: e.footprints.clone(),
        bones,
    }
}

/// Refuses an infeasible edit (unless allowed), then writes the BVH and its sidecars.
fn finish(
    c: &EditCommon,
    e: Edit,
    kv: Vec<(String, String)>,
    title: String,
) -> anyhow::Result<Outcome> {
    if !e.violated.is_empty() && !c.allow_infeasible {
        anyhow::bail!(
            "infeasible request: {} (nothing written; --allow-infeasible writes it anyway)",
            e.violated.join("; ")
        );
    }
    if let Some(dir) = c.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let mut df = plan_table(&e)?;
    let plot = plot_of(&e, title);
    let out = Bvh {
        hierarchy: e.bvh.hierarchy.clone(),
        motion: e.edited.motion.clone(),
        warnings: Vec::new(),
    };
    write_file(&c.out, &out)?;
    let (plan, png) = sidecars(&c.out);
    write_table(&plan, &mut df, &kv)?;
    write_png(&png, |p| edit_png(p, &plot))?;
    let bad = e.edited.frames.iter().filter(|f| !f.converged).count();
    let n = e.edited.frames.len();
    println!(
        "edit: {n} frame(s) at {:.1} Hz → {} (+ {}, {})",
        1.0 / e.edited.motion.frame_time_s,
        c.out.display(),
        plan.display(),
        png.display()
    );
    for v in &e.violated {
        println!("edit: infeasible, written anyway: {v}");
    }
    if bad > 0 {
        eprintln!(
            "edit: {bad} of {n} frame(s) did not converge (COM or foot more than {} m off; column `converged`)",
            crate::edit::DEFAULT_COM_TOL_M
        );
        return Ok(Outcome::SomeFailed);
    }
    Ok(Outcome::Clean)
}

/// Run `edit run`.
///
/// # Errors
/// Bad options, an unreadable library or source, no solvable cycle, an infeasible request
/// (without `--allow-infeasible`), an unwritable output.
pub fn run(a: EditRunArgs) -> anyhow::Result<Outcome> {
    let c = &a.common;
    check_out(c)?;
    check_speed("--speed", a.speed)?;
    let (length, mass) = (a.length_scale, a.mass_scale);
    check_scale("--length-scale", length)?;
    check_scale("--mass-scale", mass)?;
    anyhow::ensure!(
        (1..=MAX_CYCLES).contains(&a.cycles),
        "--cycles: must be from 1 to {MAX_CYCLES} (MAX_CYCLES), found {}",
        a.cycles
    );
    let (form, mu) = c.lim.form(LimitForm::Absolute)?;
    let active = c.lim.active_fraction()?;
    let (lib, pool) = load_pool(&c.lib, active)?;
    let times = timing(&c.lib)?;
    let limits: std::collections::BTreeMap<_, _> = absolute_limits(&lib)
        .into_iter()
        .map(|(k, l)| (k, crate::query::run::scale_limits(&l, length, mass)))
        .collect();
    let cycles: Vec<_> = run_cycles(&lib.stances)
        .into_iter()
        .filter(|cy| !time_scaled(&lib, &lib.stances[cy.stances[0]].clip))
        .filter(|cy| {
            a.stance
                .as_ref()
                .is_none_or(|id| &lib.stances[cy.stances[0]].stance_id == id)
        })
        .collect();
    if cycles.is_empty() {
        match &a.stance {
            Some(id) => anyhow::bail!(
                "--stance {id}: not the first stance of a run cycle in {}",
                c.lib.display()
            ),
            None => anyhow::bail!(
                "{}: no run cycle (two chained single-foot stances between flights)",
                c.lib.display()
            ),
        }
    }
    let solved: Vec<(f64, Result<Vec<EditStance>, String>)> = cycles
        .iter()
        .map(|cy| {
            let prep = cy.stances.map(|i| {
                Prepared::with_active_fraction(pool[i].stance.scaled(length, mass), active)
            });
            let k0 = a.speed / (cy.v_orig * length.sqrt());
            refine_run_k(a.speed, k0, |k| {
                let req = run_requests([&prep[0].stance, &prep[1].stance], k);
                (0..2)
                    .map(|n| {
                        let lim = stance_limits(&prep[n], form, &limits, mu);
                        let i = cy.stances[n];
                        solve_stance(&lib.stances[i], times[i], &prep[n], req[n], &lim)
                    })
                    .collect::<Result<Vec<_>, _>>()
            })
        })
        .collect();
    // Feasible first, then the least change of the recorded speed; ties by stance id.
    let rank = |(k, r): &(f64, Result<Vec<EditStance>, String>)| match r {
        Ok(v) => (v.iter().any(|e| e.violated().is_some()), (k - 1.0).abs()),
        Err(_) => (true, f64::INFINITY),
    };
    let best = (0..solved.len())
        .min_by(|&x, &y| {
            let (a1, b1) = rank(&solved[x]);
            let (a2, b2) = rank(&solved[y]);
            a1.cmp(&a2).then(b1.total_cmp(&b2))
        })
        .unwrap_or(0);
    let (k, stances) = match &solved[best] {
        (k, Ok(v)) => (*k, v.clone()),
        (_, Err(e)) => anyhow::bail!("no solution at {} m/s: {e}", a.speed),
    };
    let clip = stances[0].source.clip.clone();
    let order: Vec<usize> = (0..a.cycles).flat_map(|_| [0, 1]).collect();
    let first = stances[0].source.stance_id.clone();
    let e = compute(c, &clip, length, stances, order, false)?;
    let kv = query_kv(
        &c.lib,
        serde_json::json!({
            "edit": "run", "lib": c.lib, "speed_mps": a.speed, "cycles": a.cycles,
            "stance": first, "k": k, "length_scale": length, "mass_scale": mass,
            "limits": form.name(), "mu": mu, "active_set": active,
        }),
    )?;
    let title = format!(
        "edit run: {:.2} m/s, cycle {first}, {} cycles",
        a.speed, a.cycles
    );
    finish(c, e, kv, title)
}

/// A jump candidate: (liftoff, landing) pool indices, apex height, distance, outcome.
type Solved = (
    (usize, usize),
    f64,
    f64,
    Result<crate::query::jump::Jump, String>,
);

/// The first recorded jump of a library: a liftoff followed by a landing in its clip.
fn recorded_pair(lib: &StanceLibrary) -> Option<(usize, usize)> {
    let s = &lib.stances;
    (1..s.len()).find_map(|i| {
        (s[i - 1].clip == s[i].clip && is_liftoff(&s[i - 1]) && is_landing(&s[i]))
            .then_some((i - 1, i))
    })
}

/// The (liftoff, landing) stance indices of `--pair LIFTOFF_ID:LANDING_ID`.
fn given_pair(lib: &StanceLibrary, p: &str) -> anyhow::Result<(usize, usize)> {
    let index = |id: &str| {
        lib.stances
            .iter()
            .position(|s| s.stance_id == id)
            .with_context(|| format!("--pair: unknown stance {id}"))
    };
    // Stance ids hold ':' themselves: split at the middle ':' of the 5 parts.
    let parts: Vec<&str> = p.split(':').collect();
    anyhow::ensure!(
        parts.len() == 6,
        "--pair: expected LIFTOFF_ID:LANDING_ID (each <clip>:<label>:<frame>), found {p}"
    );
    let (i, j) = (index(&parts[..3].join(":"))?, index(&parts[3..].join(":"))?);
    anyhow::ensure!(
        is_liftoff(&lib.stances[i]),
        "--pair: {} is not a liftoff stance (rest or clip edge, then flight)",
        lib.stances[i].stance_id
    );
    anyhow::ensure!(
        is_landing(&lib.stances[j]),
        "--pair: {} is not a landing stance (flight, then rest or clip edge)",
        lib.stances[j].stance_id
    );
    Ok((i, j))
}

/// The (liftoff, landing) pairs an edit may use: the `--pair`; else, without both a
/// height and a distance, the library's first recorded jump; else every liftoff and
/// landing of one clip.
fn jump_candidates(
    lib: &StanceLibrary,
    pair: Option<&str>,
    height_and_distance: bool,
) -> anyhow::Result<Vec<(usize, usize)>> {
    let given = match pair {
        Some(p) => Some(given_pair(lib, p)?),
        None if !height_and_distance => Some(recorded_pair(lib).context(
            "no recorded jump (liftoff then landing in one clip) in the library: give --pair",
        )?),
        None => None,
    };
    let n = lib.stances.len();
    Ok(match given {
        Some(p) => vec![p],
        None => {
            let ups = (0..n).filter(|&i| is_liftoff(&lib.stances[i]));
            ups.flat_map(|i| {
                (0..n)
                    .filter(|&j| is_landing(&lib.stances[j]))
                    .map(move |j| (i, j))
            })
            .filter(|&(i, j)| lib.stances[i].clip == lib.stances[j].clip)
            .collect()
        }
    })
}

/// The two stances of a solved jump, as the editor places them.
fn jump_stances(
    lib: &StanceLibrary,
    pool: &[Prepared],
    times: &[StanceTiming],
    pair: [usize; 2],
    jmp: &crate::query::jump::Jump,
) -> Vec<EditStance> {
    pair.iter()
        .enumerate()
        .map(|(n, &s)| {
            let (req, scaled) = jmp.sides[n];
            EditStance {
                source: lib.stances[s].clone(),
                timing: times[s],
                prepared: pool[s].clone(),
                request: req,
                scaled,
            }
        })
        .collect()
}

/// Run `edit jump`.
///
/// # Errors
/// Bad options, an unreadable library or source, no solvable pair, an infeasible request
/// (without `--allow-infeasible`), an unwritable output.
pub fn run_jump(a: EditJumpArgs) -> anyhow::Result<Outcome> {
    let c = &a.common;
    check_out(c)?;
    for (n, v) in [
        ("--height", a.height),
        ("--distance", a.distance),
        ("--height-scale", a.height_scale),
    ] {
        if let Some(v) = v {
            anyhow::ensure!(v.is_finite(), "{n} must be a number, found {v}");
        }
    }
    let (form, mu) = c.lim.form(LimitForm::Relative)?;
    let active = c.lim.active_fraction()?;
    let (lib, pool) = load_pool(&c.lib, active)?;
    let times = timing(&c.lib)?;
    let absolute = absolute_limits(&lib);
    let candidates = jump_candidates(&lib, a.pair.as_deref(), a.height.zip(a.distance).is_some())?;
    let request = |(i, j): (usize, usize)| {
        let (h0, d0) = recorded_jump(&lib.stances[i], &lib.stances[j]);
        let h = a.height.unwrap_or(h0 * a.height_scale.unwrap_or(1.0));
        (h, a.distance.unwrap_or(d0))
    };
    let solved: Vec<Solved> = candidates
        .iter()
        .map(|&(i, j)| {
            let (h, d) = request((i, j));
            let lim = [
                stance_limits(&pool[i], form, &absolute, mu),
                stance_limits(&pool[j], form, &absolute, mu),
            ];
            (
                (i, j),
                h,
                d,
                jump(&pool[i], &pool[j], h, d, Some(lim)).map_err(|e| e.to_string()),
            )
        })
        .collect();
    anyhow::ensure!(
        !solved.is_empty(),
        "{}: no liftoff and landing stance of one clip",
        c.lib.display()
    );
    let best = (0..solved.len())
        .min_by(|&x, &y| {
            let (a1, b1) = jump_rank(&solved[x].3);
            let (a2, b2) = jump_rank(&solved[y].3);
            a1.cmp(&a2).then(b1.total_cmp(&b2))
        })
        .unwrap_or(0);
    let ((i, j), h, d, result) = &solved[best];
    let jmp = match result {
        Ok(j) => *j,
        Err(e) => anyhow::bail!(
            "no solution for height {h} m, distance {d} m ({} → {}): {e}",
            lib.stances[*i].stance_id,
            lib.stances[*j].stance_id
        ),
    };
    let stances = jump_stances(&lib, &pool, &times, [*i, *j], &jmp);
    let clip = lib.stances[*i].clip.clone();
    let ids = format!(
        "{} → {}",
        lib.stances[*i].stance_id, lib.stances[*j].stance_id
    );
    let e = compute(c, &clip, 1.0, stances, vec![0, 1], true)?;
    let kv = query_kv(
        &c.lib,
        serde_json::json!({
            "edit": "jump", "lib": c.lib, "height_m": h, "distance_m": d, "pair": ids,
            "limits": form.name(), "mu": mu, "active_set": active,
        }),
    )?;
    let title = format!("edit jump: apex {h:.2} m, distance {d:.2} m, {ids}");
    finish(c, e, kv, title)
}
