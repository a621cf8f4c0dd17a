//! Issue 14: `edit run` and `edit jump` write full-body BVH that goes back into the crate's
//! own ingest and build; every bound of the issue is checked on the re-ingested motion.

use std::path::{Path, PathBuf};

use stancelib::bvh::parse_file;
use stancelib::edit::rotation::{angle_deg, from_euler, Quat};
use stancelib::ingest::{ClipFrames, ClipSummary, ContactRun, IngestOptions};
use stancelib::library::codec::table::read_parquet;
use stancelib::library::readers::read::open_library;
use stancelib::query::run::run_cycles;
use stancelib::skeleton::Skeleton;
use stancelib::stances::segment::Boundary;

use super::util::{ingest_body, ok, root, shared_or_skip, stancelib};

const G: f64 = 9.81;

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

/// A library of the given BVH files in `dir/lib`.
pub(super) fn library(dir: &Path, files: &[PathBuf]) -> PathBuf {
    let lib = dir.join("lib");
    let mut args: Vec<String> = vec!["build".into()];
    args.extend(files.iter().map(|f| f.display().to_string()));
    args.extend(["--out".into(), lib.display().to_string()]);
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&a);
    lib
}

pub(super) fn fixture(name: &str) -> PathBuf {
    root().join("fixtures/bvh").join(format!("{name}.bvh"))
}

/// The first run cycle of `clip` in a library: (first stance id, recorded speed).
pub(super) fn cycle_of(lib: &Path, clip: &str) -> (String, f64) {
    let l = open_library(lib).unwrap();
    let c = run_cycles(&l.stances)
        .into_iter()
        .find(|c| l.stances[c.stances[0]].clip == clip)
        .expect("a run cycle");
    (l.stances[c.stances[0]].stance_id.clone(), c.v_orig)
}

/// The 120 Hz fixture run in a library under `dir`: (source clip, library, first stance
/// of its run cycle, recorded speed).
fn fixture_run_cycle(dir: &Path) -> (PathBuf, PathBuf, String, f64) {
    let src = fixture("run_120hz_m_yup");
    let lib = library(dir, std::slice::from_ref(&src));
    let (id, v0) = cycle_of(&lib, "run_120hz_m_yup");
    (src, lib, id, v0)
}

/// The plan sidecar, by column.
pub(super) struct Plan {
    pub(super) time: Vec<f64>,
    pub(super) com: Vec<[f64; 3]>,
    pose_com: Vec<[f64; 3]>,
    window: Vec<Option<(f64, f64)>>,
    stance: Vec<Option<String>>,
    phase: Vec<String>,
    converged: Vec<bool>,
}

pub(super) fn read_plan(out: &Path) -> Plan {
    let df = read_parquet(&out.with_extension("plan.parquet")).unwrap();
    let f = |n: &str| -> Vec<Option<f64>> { df.column(n).unwrap().f64().unwrap().iter().collect() };
    let v3 = |p: &str| -> Vec<[f64; 3]> {
        let (x, y, z) = (
            f(&format!("{p}_x_m")),
            f(&format!("{p}_y_m")),
            f(&format!("{p}_z_m")),
        );
        (0..x.len())
            .map(|i| [x[i].unwrap(), y[i].unwrap(), z[i].unwrap()])
            .collect()
    };
    let s = |n: &str| -> Vec<Option<String>> {
        df.column(n)
            .unwrap()
            .str()
            .unwrap()
            .iter()
            .map(|v| v.map(String::from))
            .collect()
    };
    let (td, lo) = (f("stance_td_clip_s"), f("stance_lo_clip_s"));
    Plan {
        time: f("time_clip_s").into_iter().map(Option::unwrap).collect(),
        com: v3("com"),
        pose_com: v3("pose_com"),
        window: td.iter().zip(&lo).map(|(a, b)| a.zip(*b)).collect(),
        stance: s("stance_id"),
        phase: s("phase").into_iter().map(Option::unwrap).collect(),
        converged: df
            .column("converged")
            .unwrap()
            .bool()
            .unwrap()
            .iter()
            .map(Option::unwrap)
            .collect(),
    }
}

fn reingest(out: &Path) -> (ClipSummary, ClipFrames, Vec<ContactRun>) {
    let bvh = parse_file(out).unwrap();
    super::util::ingest_body(&bvh, &IngestOptions::default(), &out.display().to_string())
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// What the round trip measured (printed, then asserted by the callers).
#[derive(Debug, Default)]
pub(super) struct Figures {
    pub(super) com_rms_m: f64,
    pub(super) com_max_m: f64,
    pub(super) event_err_frames: f64,
    pub(super) slide_max_m: f64,
    pub(super) joint_step_max_deg: f64,
    pub(super) flight_az_err: f64,
    pub(super) unconverged: usize,
}

/// Re-ingests `out` and measures it against its plan.
pub(super) fn measure(out: &Path) -> Figures {
    let plan = read_plan(out);
    let (summary, frames, contacts) = reingest(out);
    let dt = summary.frame_time_s;
    let mut fig = Figures::default();
    assert_eq!(
        frames.frame.len(),
        plan.time.len(),
        "every written frame is kept"
    );
    // COM: re-measured against the plan.
    let errs: Vec<f64> = (0..plan.com.len())
        .map(|i| dist(frames.com[i], plan.com[i]))
        .collect();
    fig.com_rms_m = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len() as f64).sqrt();
    fig.com_max_m = errs.iter().fold(0.0, |a, &b| a.max(b));
    fig.unconverged = plan.converged.iter().filter(|c| !**c).count();
    for i in 0..plan.com.len() {
        assert!(
            dist(plan.pose_com[i], frames.com[i]) < 1e-6,
            "pose COM column = re-ingested COM: frame {i}, {} m",
            dist(plan.pose_com[i], frames.com[i])
        );
    }
    // Planned stances: windows and feet.
    let mut windows: Vec<(f64, f64, String)> = Vec::new();
    for i in 0..plan.time.len() {
        if let (Some(w), Some(id)) = (plan.window[i], &plan.stance[i]) {
            if windows.last().is_none_or(|l| (l.0 - w.0).abs() > 1e-9) {
                windows.push((w.0, w.1, id.clone()));
            }
        }
    }
    assert!(!windows.is_empty());
    let t_end = *plan.time.last().unwrap();
    for (td, lo, id) in &windows {
        let label = id.split(':').nth(1).unwrap();
        let feet: Vec<&str> = [("L", "left_foot"), ("R", "right_foot")]
            .iter()
            .filter(|(c, _)| label.split('+').next().unwrap().contains(c))
            .map(|(_, e)| *e)
            .collect();
        // A stance begins when its first foot touches down and ends when its last foot
        // lifts off (as the stances are cut): those are its planned events. The feet of a
        // two-foot stance keep the recording's own spread between them (the CMU forward
        // jumps' right foot leaves 1.3–1.4 frames before the left, in the source and in
        // the edit).
        let (mut first_td, mut last_lo) = (f64::INFINITY, f64::NEG_INFINITY);
        for e in feet {
            let k = ["left_foot", "right_foot"]
                .iter()
                .position(|x| *x == e)
                .unwrap();
            let run = contacts
                .iter()
                .filter(|c| c.effector == e)
                .find(|c| {
                    (c.first_frame as f64) * dt <= lo + dt && (c.last_frame as f64) * dt >= td - dt
                })
                .unwrap_or_else(|| {
                    panic!(
                        "{}: no {e} contact for stance {id} [{td:.3}, {lo:.3}]",
                        out.display()
                    )
                });
            if let Some(t) = run.td_time_s {
                first_td = first_td.min(t);
            }
            if let Some(t) = run.lo_time_s {
                last_lo = last_lo.max(t);
            }
            // Slide: a foot point (ankle = heel, or toe tip) resting on the floor (within
            // 5 mm of its lowest height in the stance) must not move; a point still landing
            // or already rolling off is not a contact point. Horizontal distance from the
            // point's median position over its resting frames; the better-resting point.
            // A point that lifts and rests again more than `edit::FOOT_STEP_M` away has
            // stepped inside the stance (as `cmu_01_01_forward_jumps_mb:LR:1003`'s foot does
            // in the recording): each of its rests is measured on its own.
            let ankle = frames.effector_pos[k].as_ref().unwrap();
            let idx: Vec<usize> = (0..plan.time.len())
                .filter(|&i| plan.time[i] >= *td && plan.time[i] <= *lo)
                .collect();
            let rest = |p: &[[f64; 3]]| {
                let zmin = idx.iter().map(|&i| p[i][2]).fold(f64::INFINITY, f64::min);
                let on: Vec<usize> = idx
                    .iter()
                    .copied()
                    .filter(|&i| p[i][2] <= zmin + 0.005)
                    .collect();
                let med = |set: &[usize]| {
                    let m = |a: usize| {
                        let mut v: Vec<f64> = set.iter().map(|&i| p[i][a]).collect();
                        v.sort_by(f64::total_cmp);
                        v[v.len() / 2]
                    };
                    (m(0), m(1))
                };
                let mut rests: Vec<Vec<usize>> = Vec::new();
                let mut run: Vec<usize> = Vec::new();
                for (n, &i) in on.iter().enumerate() {
                    run.push(i);
                    if on.get(n + 1) != Some(&(i + 1)) {
                        let (rx, ry) = med(&run);
                        match rests.last_mut() {
                            Some(last)
                                if {
                                    let (lx, ly) = med(last);
                                    (rx - lx).hypot(ry - ly) <= stancelib::edit::FOOT_STEP_M
                                } =>
                            {
                                last.append(&mut run)
                            }
                            _ => rests.push(std::mem::take(&mut run)),
                        }
                    }
                }
                let slide = rests
                    .iter()
                    .map(|set| {
                        let (mx, my) = med(set);
                        set.iter()
                            .map(|&i| (p[i][0] - mx).hypot(p[i][1] - my))
                            .fold(0.0, f64::max)
                    })
                    .fold(0.0, f64::max);
                (on.len(), slide)
            };
            let (na, sa) = rest(ankle);
            let (nt, st) = rest(&frames.toe[k]);
            assert!(na.max(nt) >= 1, "{id}: no foot point rests on the floor");
            let slide = if na >= nt { sa } else { st };
            fig.slide_max_m = fig.slide_max_m.max(slide);
        }
        // A stance that begins at rest (after a jump's lead-in, the recording's own frames)
        // has no planned touchdown: its feet were already down.
        let after_rest = (0..plan.time.len())
            .any(|i| plan.phase[i] == "rest" && (plan.time[i] - td).abs() <= 1.5 * dt);
        if *td > dt && first_td.is_finite() && !after_rest {
            fig.event_err_frames = fig.event_err_frames.max((first_td - td).abs() / dt);
        }
        if *lo < t_end - dt && last_lo.is_finite() {
            fig.event_err_frames = fig.event_err_frames.max((last_lo - lo).abs() / dt);
        }
    }
    // Flights: curvature of the re-measured COM.
    for f in &summary.flights {
        if let Some(az) = f.a_z {
            fig.flight_az_err = fig.flight_az_err.max((az + G).abs());
        }
    }
    // Joints: no NaN, rotation between consecutive frames (scaled to 120 Hz).
    let b = parse_file(out).unwrap();
    assert!(
        b.motion.values.iter().all(|v| v.is_finite()),
        "no NaN in {}",
        out.display()
    );
    let q = local_quats(&b);
    let nj = b.hierarchy.joints.len();
    let per_120 = (1.0 / dt) / 120.0;
    for f in 1..b.motion.n_frames() {
        for j in 0..nj {
            let a = angle_deg(q[(f - 1) * nj + j], q[f * nj + j]) * per_120;
            fig.joint_step_max_deg = fig.joint_step_max_deg.max(a);
        }
    }
    eprintln!("{}: {fig:?}", out.display());
    fig
}

fn local_quats(b: &stancelib::bvh::Bvh) -> Vec<Quat> {
    let sk = Skeleton::from_bvh(b);
    let mut out = Vec::new();
    for f in 0..b.motion.n_frames() {
        let row = b.motion.row(f);
        for c in &sk.channels {
            let axes: Vec<usize> = c.rotations.iter().map(|r| r.0).collect();
            let deg: Vec<f64> = c.rotations.iter().map(|r| row[r.1]).collect();
            out.push(from_euler(&axes, &deg));
        }
    }
    out
}

/// The issue's bounds on one written motion, except `misses`: bounds this edit is known
/// not to meet, each with the figure measured when it was written (asserted as a ceiling,
/// printed as a miss; the report of issue 14 lists them with their cause).
pub(super) fn assert_bounds_except(f: &Figures, misses: &[(&str, f64)]) {
    let bound = |name: &str, value: f64, issue: f64| {
        let ceiling = misses.iter().find(|m| m.0 == name).map(|m| m.1);
        match ceiling {
            Some(c) => {
                eprintln!(
                    "KNOWN MISS {name}: measured {value:.4}, issue bound {issue}, ceiling {c}"
                );
                assert!(value <= c, "{name}: {value} above the recorded miss {c}");
            }
            None => assert!(value <= issue, "{name}: {value} > {issue} (issue 14 bound)"),
        }
    };
    bound("com_rms_m", f.com_rms_m, 0.01);
    bound("com_max_m", f.com_max_m, 0.02);
    bound("event_frames", f.event_err_frames, 1.0);
    bound("slide_m", f.slide_max_m, 0.01);
    bound("flight_az", f.flight_az_err, 0.5);
    bound("joint_step_deg", f.joint_step_max_deg, 30.0);
}

/// Runs an edit that may finish with frames reported as not converged or a posture check
/// failed (exit 1) or as infeasible and written anyway (exit 3, `--allow-infeasible`);
/// any other outcome fails. Returns the exit code.
pub(super) fn edit(args: &[&str]) -> i32 {
    edit_with_output(args).0
}

/// [`edit`], with what it printed on stdout.
pub(super) fn edit_with_output(args: &[&str]) -> (i32, String) {
    let (code, out, err) = stancelib(args);
    assert!(
        matches!(code, 0 | 1 | 3),
        "stancelib {args:?}: exit {code}\n{out}\n{err}"
    );
    if code != 0 {
        eprintln!("reported (exit {code}): {err}");
    }
    match code {
        1 => assert!(
            err.contains("did not converge")
                || err.contains("outside")
                || err.contains("locked")
                || err.contains("root acceleration"),
            "{err}"
        ),
        3 => assert!(err.contains("infeasible"), "{err}"),
        _ => {}
    }
    (code, out)
}

/// Mean speed of the run cycles rebuilt from a written BVH.
fn rebuilt_speed(dir: &Path, out: &Path) -> f64 {
    let lib = library(&dir.join("rebuilt"), &[out.to_path_buf()]);
    let l = open_library(&lib).unwrap();
    let c = run_cycles(&l.stances);
    assert!(!c.is_empty(), "the rebuilt clip has run cycles");
    c.iter().map(|c| c.v_orig).sum::<f64>() / c.len() as f64
}

#[test]
fn edited_runs_round_trip_within_the_issue_bounds() {
    let dir = tmp();
    let (_, lib, id, v0) = fixture_run_cycle(dir.path());
    // See: issue 14 checks — at 2 m/s the rebuilt cycle ran at 1.89 m/s while k = v/v_orig
    // was taken as is (the periodic requests move the solved times); `refine_run_k` now
    // solves k for the speed. The flights' curvature (0.95 m/s² from −g at 4 m/s before)
    // holds since the pose iteration stops at 10 µm (`edit::DEFAULT_COM_SOLVE_TOL_M`).
    for v in [2.0, 3.0, 4.0] {
        let out = dir.path().join(format!("run_{v}.bvh"));
        edit_cycle(&lib, &id, v, &out);
        assert!(out.with_extension("png").is_file());
        let f = measure(&out);
        let sub = tempfile::tempdir_in(dir.path()).unwrap();
        let speed = rebuilt_speed(sub.path(), &out);
        eprintln!("run at {v} m/s (recorded {v0:.3}): rebuilt {speed:.4} m/s");
        assert!(
            (speed - v).abs() <= 0.02 * v,
            "rebuilt speed {speed} vs {v}"
        );
        assert_bounds_except(&f, &[]);
    }
}

/// `edit run` of the cycle starting at stance `id` at `v` m/s into `out`, infeasible
/// requests written anyway (see [`edit`]).
pub(super) fn edit_cycle(lib: &Path, id: &str, v: f64, out: &Path) {
    edit(&[
        "edit",
        "run",
        "--lib",
        lib.to_str().unwrap(),
        "--speed",
        &v.to_string(),
        "--stance",
        id,
        "--out",
        out.to_str().unwrap(),
        "--allow-infeasible",
    ]);
}

/// Index of a stance id in a library's file order.
fn stance_index(lib: &Path, id: &str) -> usize {
    open_library(lib)
        .unwrap()
        .stances
        .iter()
        .position(|s| s.stance_id == id)
        .unwrap()
}

/// Joint-angle RMS (degrees) and largest root distance (m) of the first `span_s` of an
/// edited clip against the source clip from `src_t0` on (identity requests).
fn against_source(
    out: &Path,
    source: &Path,
    unit_m: f64,
    t_out0: f64,
    src_t0: f64,
    span_s: f64,
) -> (f64, f64) {
    let (o, s) = (parse_file(out).unwrap(), parse_file(source).unwrap());
    let (qo, qs) = (local_quats(&o), local_quats(&s));
    let nj = o.hierarchy.joints.len();
    let sk = Skeleton::from_bvh(&s);
    let root_t = |b: &stancelib::bvh::Bvh, f: usize| -> [f64; 3] {
        let row = b.motion.row(f);
        sk.channels[0]
            .translations
            .map(|c| row[c.unwrap()] * unit_m)
    };
    let (dt_o, dt_s) = (o.motion.frame_time_s, s.motion.frame_time_s);
    let (mut sum, mut n, mut root_max) = (0.0, 0usize, 0.0f64);
    for f in 0..o.motion.n_frames() {
        let t = f as f64 * dt_o;
        if t < t_out0 || t > t_out0 + span_s {
            continue;
        }
        let x = (src_t0 + t - t_out0) / dt_s;
        let (f0, w) = (x.floor() as usize, x - x.floor());
        if f0 + 1 >= s.motion.n_frames() {
            continue;
        }
        for j in 0..nj {
            let q = stancelib::edit::rotation::slerp(qs[f0 * nj + j], qs[(f0 + 1) * nj + j], w);
            let a = angle_deg(qo[f * nj + j], q);
            sum += a * a;
            n += 1;
        }
        let (r0, r1, ro) = (root_t(&s, f0), root_t(&s, f0 + 1), root_t(&o, f));
        let rs: [f64; 3] = std::array::from_fn(|i| r0[i] + w * (r1[i] - r0[i]));
        root_max = root_max.max(dist(ro, rs));
    }
    assert!(n > 0, "frames compared");
    ((sum / n as f64).sqrt(), root_max)
}

/// The first planned stance window of an edit (output time).
fn first_window(out: &Path) -> (f64, f64, String) {
    let plan = read_plan(out);
    let i = plan.window.iter().position(Option::is_some).unwrap();
    let w = plan.window[i].unwrap();
    (w.0, w.1, plan.stance[i].clone().unwrap())
}

#[test]
fn identity_run_reproduces_the_recorded_motion() {
    let dir = tmp();
    let (src, lib, id, v0) = fixture_run_cycle(dir.path());
    let out = dir.path().join("identity.bvh");
    ok(&[
        "edit",
        "run",
        "--lib",
        lib.to_str().unwrap(),
        "--speed",
        &v0.to_string(),
        "--stance",
        &id,
        "--cycles",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    // See: issue 14 checks — the identity cycle's flights re-measured 0.90 m/s² from −g
    // while the pose iteration stopped at the 1 mm COM tolerance (8e/T² over a 0.11 s
    // flight); it now stops at 10 µm and every bound holds.
    assert_bounds_except(&measure(&out), &[]);
    let (td, _, first) = first_window(&out);
    let t = stancelib::library::readers::read::read_stance_timing(&lib.join("stances.parquet"))
        .unwrap();
    let td_clip = t[stance_index(&lib, &first)].td_clip_s;
    let (rms, root) = against_source(&out, &src, 1.0, 0.0, td_clip - td, 10.0);
    eprintln!("identity run: joint-angle RMS {rms:.3}°, root path {root:.4} m");
    assert!(rms <= 3.0, "joint-angle RMS {rms}° > 3°");
    assert!(root <= 0.02, "root path {root} m > 2 cm");
}

#[test]
fn infeasible_run_is_refused_naming_the_constraint_and_writes_nothing() {
    let dir = tmp();
    let lib = library(dir.path(), &[fixture("run_120hz_m_yup")]);
    let out = dir.path().join("fast.bvh");
    let (code, _, err) = stancelib(&[
        "edit",
        "run",
        "--lib",
        lib.to_str().unwrap(),
        "--speed",
        "9",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("infeasible request")
            && (err.contains("force") || err.contains("friction") || err.contains("extension")),
        "{err}"
    );
    for p in [
        out.clone(),
        out.with_extension("plan.parquet"),
        out.with_extension("png"),
    ] {
        assert!(!p.exists(), "{} written", p.display());
    }
    // --allow-infeasible writes it (exit 3), and the sidecar names the constraint per
    // stance frame.
    let code = edit(&[
        "edit",
        "run",
        "--lib",
        lib.to_str().unwrap(),
        "--speed",
        "9",
        "--out",
        out.to_str().unwrap(),
        "--allow-infeasible",
    ]);
    assert_eq!(code, 3, "an infeasible edit written anyway exits 3");
    let df = read_parquet(&out.with_extension("plan.parquet")).unwrap();
    let v = df
        .column("violated")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .flatten()
        .count();
    assert!(v > 0, "violated column names the failing constraint");
}

// See: issue 14, review of the jump lead-in (2026-12-06) — a jump edit writes up to
// `edit::LEAD_IN_S` of its recording before the first touchdown (so that re-ingested, the
// liftoff begins at rest as its source did). Written with the recording's feet, the feet
// jumped at the touchdown by as much as the solved contact point moved (1.04 cm on this
// fixture at 0.7 × its apex, 5.4 cm on `cmu_13_32` at 0.4 ×); they now stand on the
// planned footprints from the first frame.
#[test]
fn a_jump_edit_starts_with_its_recorded_rest_on_the_planned_footprints() {
    let dir = tmp();
    let src = fixture("jump_120hz_cmu_yup");
    let lib = library(dir.path(), std::slice::from_ref(&src));
    let clips =
        stancelib::library::readers::read::read_clip_sources(&lib.join("clips.parquet")).unwrap();
    let clip = &clips["jump_120hz_cmu_yup"];
    let source = parse_file(&src).unwrap();
    let dropped =
        stancelib::skeleton::leadin::leadin_frames(&Skeleton::from_bvh(&source), &source.motion);
    let first_kept_s = dropped as f64 * source.motion.frame_time_s;
    let timing =
        stancelib::library::readers::read::read_stance_timing(&lib.join("stances.parquet"))
            .unwrap();
    for (scale, fps) in [("1.0", None), ("0.7", None), ("0.7", Some("60"))] {
        let out = dir
            .path()
            .join(format!("rest_{scale}_{}.bvh", fps.unwrap_or("src")));
        let mut args = vec![
            "edit",
            "jump",
            "--lib",
            lib.to_str().unwrap(),
            "--height-scale",
            scale,
            "--allow-infeasible",
            "--out",
            out.to_str().unwrap(),
        ];
        if let Some(f) = fps {
            args.extend(["--fps", f]);
        }
        edit(&args);
        let plan = read_plan(&out);
        let dt = plan.time[1] - plan.time[0];
        let n_rest = plan.phase.iter().take_while(|p| *p == "rest").count();
        assert!(
            plan.phase[n_rest..].iter().all(|p| p != "rest"),
            "rest rows only before the first touchdown"
        );
        let (td, _, first) = first_window(&out);
        let td_clip = timing[stance_index(&lib, &first)].td_clip_s;
        let lead = (td_clip - first_kept_s).min(stancelib::edit::LEAD_IN_S);
        assert!(lead > 0.1, "the fixture's liftoff starts after some rest");
        assert_eq!(n_rest, (lead / dt + 1e-9).floor() as usize, "×{scale}");
        assert!(
            (td - n_rest as f64 * dt).abs() < 1e-9,
            "the touchdown follows the lead-in"
        );
        if scale == "1.0" {
            // The recorded jump's lead-in is its recording.
            let unit = clip.unit_scale.unwrap();
            let (rms, root) = against_source(&out, &src, unit, 0.0, td_clip - td, td - dt / 2.0);
            assert!(
                rms < 0.01 && root < 1e-4,
                "rest frames: {rms}° RMS, root {root} m"
            );
        }
        // The ankles do not jump at the touchdown: the step onto the first stance frame is
        // no larger than the steps of the standing lead-in (plus 1 mm).
        let (_, frames, _) = reingest(&out);
        for k in 0..2 {
            let a = frames.effector_pos[k].as_ref().unwrap();
            let step = |i: usize| (a[i][0] - a[i - 1][0]).hypot(a[i][1] - a[i - 1][1]);
            let standing = (1..n_rest).map(step).fold(0.0, f64::max);
            eprintln!(
                "×{scale} {fps:?} foot {k}: step at the touchdown {:.5} m, lead-in steps ≤ {standing:.5} m",
                step(n_rest)
            );
            assert!(step(n_rest) <= standing + 1e-3, "×{scale} foot {k}");
        }
    }
}

/// The first liftoff stance followed by a landing stance: their indices.
pub(super) fn first_jump(s: &[stancelib::query::pool::PoolStance]) -> Option<(usize, usize)> {
    (1..s.len()).find_map(|i| {
        (stancelib::query::jump::is_liftoff(&s[i - 1]) && stancelib::query::jump::is_landing(&s[i]))
            .then_some((i - 1, i))
    })
}

#[test]
fn edited_jumps_reach_the_requested_apex_and_round_trip() {
    let dir = tmp();
    let src = fixture("jump_120hz_cmu_yup");
    let lib = library(dir.path(), std::slice::from_ref(&src));
    let l = open_library(&lib).unwrap();
    let s = &l.stances;
    let (i, j) = first_jump(s).expect("a recorded jump");
    let (h0, d0) = stancelib::query::jump::recorded_jump(&s[i], &s[j]);
    // See: issue 14 checks — at 1.2 × the recorded apex the plan puts the COM up to 1.10 m
    // from the contact point (the recorded push reaches 0.97 m with the foot flat): the
    // legs could not reach, the feet left 4.7 frames early and landed 4.4 late. The foot
    // now turns about its toe tip (`edit::DEFAULT_MAX_TOE_PIVOT_DEG`): every bound holds.
    for (scale, misses) in [(1.0, &[][..]), (1.2, &[][..])] {
        let out = dir.path().join(format!("jump_{scale}.bvh"));
        edit(&[
            "edit",
            "jump",
            "--lib",
            lib.to_str().unwrap(),
            "--height-scale",
            &scale.to_string(),
            "--out",
            out.to_str().unwrap(),
            "--allow-infeasible",
        ]);
        let f = measure(&out);
        assert_bounds_except(&f, misses);
        let sub = tempfile::tempdir_in(dir.path()).unwrap();
        let rl = library(sub.path(), std::slice::from_ref(&out));
        let r = open_library(&rl).unwrap();
        let rs = &r.stances;
        let (a, b) = first_jump(rs).expect("the rebuilt clip has a jump");
        let (h, d) = stancelib::query::jump::recorded_jump(&rs[a], &rs[b]);
        eprintln!(
            "jump ×{scale}: apex {h:.4} m (asked {:.4}), distance {d:.4} m (asked {d0:.4})",
            h0 * scale
        );
        assert!((h - h0 * scale).abs() <= 0.02, "apex {h} vs {}", h0 * scale);
        assert!((d - d0).abs() <= 0.02, "distance {d} vs {d0}");
        if scale == 1.0 {
            let (td, _, _) = first_window(&out);
            let tm =
                stancelib::library::readers::read::read_stance_timing(&lib.join("stances.parquet"))
                    .unwrap();
            let (rms, root) = against_source(&out, &src, 0.056444, 0.0, tm[i].td_clip_s - td, 10.0);
            eprintln!("identity jump: joint-angle RMS {rms:.3}°, root path {root:.4} m");
            assert!(
                rms <= 3.0 && root <= 0.02,
                "identity jump: RMS {rms}°, root {root} m"
            );
        }
    }
}

#[test]
fn edited_run_of_a_real_cmu_clip_round_trips() {
    let Some(data) = shared_or_skip("edited_run_of_a_real_cmu_clip_round_trips") else {
        return;
    };
    let dir = tmp();
    let src = data.join("bvh/run/cmu_09_01_run_mb.bvh");
    let lib = library(dir.path(), &[src]);
    let (id, v0) = cycle_of(&lib, "cmu_09_01_run_mb");
    for v in [v0, 1.1 * v0] {
        let out = dir.path().join(format!("cmu_{v:.2}.bvh"));
        edit_cycle(&lib, &id, v, &out);
        let f = measure(&out);
        // The COM, flight curvature, joint-step and NaN bounds; slide and contact timing
        // are asserted in `edit_checks`.
        assert!(f.com_rms_m <= 0.01 && f.com_max_m <= 0.02, "{f:?}");
        assert!(f.flight_az_err <= 0.5, "{f:?}");
        assert!(f.joint_step_max_deg <= 30.0, "{f:?}");
    }
}

#[test]
fn edited_run_of_a_longer_heavier_character_scales_by_dynamic_similarity() {
    // See: issue 14 "What a user gets" — `--length-scale L --mass-scale M`: a new character
    // by dynamic similarity (§9). At V = √L · v_orig the request is the recorded cycle at the
    // same Froude number: lengths scale by L, times by √L, and every round-trip bound holds.
    let dir = tmp();
    let (src, lib, id, v0) = fixture_run_cycle(dir.path());
    let (length, mass) = (1.25f64, 1.8f64);
    let v = v0 * length.sqrt();
    let out = dir.path().join("tall.bvh");
    ok(&[
        "edit",
        "run",
        "--lib",
        lib.to_str().unwrap(),
        "--speed",
        &v.to_string(),
        "--stance",
        &id,
        "--cycles",
        "2",
        "--length-scale",
        &length.to_string(),
        "--mass-scale",
        &mass.to_string(),
        "--out",
        out.to_str().unwrap(),
    ]);
    // KNOWN MISS (issue 39 item 5): the fixture's feet bear force 3 cm above their resting
    // height, the sub-frame event height, so the source's events fall on its force edges;
    // scaled by L = 1.25 that give is 3.75 cm while the event height stays 3 cm, so the
    // re-detected touchdown comes about 10 ms after the planned one (and the liftoff as much
    // before it): 1.17 frames measured.
    const EDGE_MISS_FRAMES: f64 = 1.2;
    assert_bounds_except(&measure(&out), &[("event_frames", EDGE_MISS_FRAMES)]);
    let (src_summary, _, _) = ingest_body(
        &parse_file(&src).unwrap(),
        &IngestOptions::default(),
        "source",
    );
    let (summary, _, _) = reingest(&out);
    let leg_ratio = summary.leg_length_m.unwrap() / src_summary.leg_length_m.unwrap();
    assert!(
        (leg_ratio - length).abs() < 1e-3 * length,
        "leg length ratio {leg_ratio}, want {length}"
    );
    assert_eq!(summary.frame_time_s, src_summary.frame_time_s);
    let sub = tempfile::tempdir_in(dir.path()).unwrap();
    let speed = rebuilt_speed(sub.path(), &out);
    eprintln!("L = {length}: rebuilt {speed:.4} m/s for {v:.4} (recorded {v0:.4})");
    assert!(
        (speed - v).abs() <= 0.02 * v,
        "rebuilt speed {speed} vs {v}"
    );
    // Stance durations scale by √L; the contact thresholds are absolute, so each re-detected
    // edge of the taller character's stances may move by the known miss above.
    let durations = |l: &Path| -> Vec<f64> {
        let t = stancelib::library::readers::read::read_stance_timing(&l.join("stances.parquet"))
            .unwrap();
        t.iter().map(|s| s.lo_clip_s - s.td_clip_s).collect()
    };
    let d0 = durations(&lib);
    let rebuilt = sub.path().join("rebuilt/lib");
    let d1 = durations(&rebuilt);
    let mean = |d: &[f64]| d.iter().sum::<f64>() / d.len() as f64;
    let ratio = mean(&d1) / mean(&d0);
    eprintln!(
        "stance duration ratio {ratio:.4} (√L = {:.4})",
        length.sqrt()
    );
    let dt = src_summary.frame_time_s;
    assert!(
        (mean(&d1) - length.sqrt() * mean(&d0)).abs() <= 2.0 * EDGE_MISS_FRAMES * dt,
        "stance durations scale by {ratio}, want √L = {}",
        length.sqrt()
    );
}

#[test]
fn edit_of_a_female_library_poses_with_the_female_segment_model() {
    // See: issue 14 item 3 — the root carries the COM of the library's own body model: a
    // library built with a female body (de Leva's female column) is edited with it, so the
    // written motion re-ingested with that body follows the plan; with the male column the
    // same frames sit millimetres off (the check can fail).
    let dir = tmp();
    let body = dir.path().join("female.toml");
    std::fs::write(&body, "mass_kg = 58.0\nsex = \"female\"\n").unwrap();
    let lib = dir.path().join("lib");
    let src = fixture("run_120hz_m_yup");
    ok(&[
        "build",
        src.to_str().unwrap(),
        "--body",
        body.to_str().unwrap(),
        "--out",
        lib.to_str().unwrap(),
    ]);
    let out = dir.path().join("female.bvh");
    ok(&[
        "edit",
        "run",
        "--lib",
        lib.to_str().unwrap(),
        "--speed",
        "3",
        "--cycles",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    let plan = read_plan(&out);
    let bvh = parse_file(&out).unwrap();
    let com_err = |sex: stancelib::skeleton::com::Sex| -> f64 {
        let opts = IngestOptions {
            sex,
            ..IngestOptions::default()
        };
        let (_, frames, _) = ingest_body(&bvh, &opts, &out.display().to_string());
        (0..plan.com.len())
            .map(|i| dist(frames.com[i], plan.com[i]))
            .fold(0.0, f64::max)
    };
    let (female, male) = (
        com_err(stancelib::skeleton::com::Sex::Female),
        com_err(stancelib::skeleton::com::Sex::Male),
    );
    eprintln!("female library edit: COM off the plan by {female:.2e} m (female model), {male:.2e} m (male)");
    assert!(female <= 1e-4, "female model: COM {female} m off the plan");
    assert!(
        male > 1e-3,
        "the two segment models differ by {male} m only"
    );
}

/// Joint-angle RMS (degrees) and largest root distance (m) of an edit's first cycle (from
/// the start to the liftoff of its second planned stance) against its source clip, for a
/// request at the recorded speed: output time 0 is source time `td_clip − td_out` of the
/// first stance.
pub(super) fn first_cycle_against_source(out: &Path, source: &Path, lib: &Path) -> (f64, f64) {
    let plan = read_plan(out);
    let mut windows: Vec<(f64, f64, String)> = Vec::new();
    for (w, s) in plan.window.iter().zip(&plan.stance) {
        if let (Some(w), Some(s)) = (w, s) {
            if windows.last().is_none_or(|l| l.0 != w.0) {
                windows.push((w.0, w.1, s.clone()));
            }
        }
    }
    assert!(windows.len() >= 2, "two planned stances: {windows:?}");
    let (td, _, first) = &windows[0];
    against_source_from(out, source, lib, (first, *td), windows[1].1)
}

/// [`against_source`] of an edit whose first planned stance `first` touches down at output
/// time `td`, aligned with that stance's touchdown in its source clip, over `span_s`.
fn against_source_from(
    out: &Path,
    source: &Path,
    lib: &Path,
    (first, td): (&str, f64),
    span_s: f64,
) -> (f64, f64) {
    let t = stancelib::library::readers::read::read_stance_timing(&lib.join("stances.parquet"))
        .unwrap();
    let td_clip = t[stance_index(lib, first)].td_clip_s;
    let clips =
        stancelib::library::readers::read::read_clip_sources(&lib.join("clips.parquet")).unwrap();
    let clip = first.split(':').next().unwrap();
    let unit_m = clips[clip].unit_scale.expect("unit scale");
    // After a jump's lead-in (its `rest` rows, the recording's own frames, which would only
    // dilute the figures); a run has none.
    let plan = read_plan(out);
    let t0 = plan
        .phase
        .iter()
        .zip(&plan.time)
        .find(|(p, _)| *p != "rest")
        .map_or(0.0, |(_, t)| *t);
    against_source(out, source, unit_m, t0, td_clip - td + t0, span_s)
}

/// Joint-angle RMS (degrees) and largest root distance (m) of the edit of a library's
/// recorded jump (its own height and distance) against its source clip, over the edit.
pub(super) fn recorded_jump_against_source(lib: &Path, source: &Path, out: &Path) -> (f64, f64) {
    edit(&[
        "edit",
        "jump",
        "--lib",
        lib.to_str().unwrap(),
        "--source",
        source.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--allow-infeasible",
    ]);
    let (td, _, first) = first_window(out);
    against_source_from(out, source, lib, (&first, td), 10.0)
}

// See: issue 37 item 5 — an edited run changes its cadence and contact time with speed
// as `query run` predicts: the edit of the fixture run at 2 and 4 m/s, re-ingested and
// built again, has the contact time and step period of the query's answer for that
// cycle (within 5 %: the rebuilt contacts are detected from the edited feet), and the
// paper's law keeps the recorded ones.
#[test]
fn edited_runs_follow_the_gait_law_of_the_query() {
    let dir = tmp();
    let (_, lib, id, _) = fixture_run_cycle(dir.path());
    let rebuilt = |out: &Path, sub: &str| -> (f64, f64) {
        let lib = library(&dir.path().join(sub), &[out.to_path_buf()]);
        let l = open_library(&lib).unwrap();
        let single: Vec<_> = l
            .stances
            .iter()
            .filter(|s| s.label == "L" || s.label == "R")
            .filter(|s| s.boundary_start == Boundary::Flight && s.boundary_end == Boundary::Flight)
            .collect();
        assert!(single.len() >= 4, "{sub}: {} running stances", single.len());
        let mut dt: Vec<f64> = single.iter().map(|s| s.model.dt_s).collect();
        let mut t: Vec<f64> = single.iter().map(|s| s.params.t_e).collect();
        (median(&mut dt), median(&mut t))
    };
    let mut contact = Vec::new();
    for v in [2.0, 4.0] {
        let out = dir.path().join(format!("law_{v}.bvh"));
        edit_cycle(&lib, &id, v, &out);
        let q = dir.path().join(format!("q_{v}.parquet"));
        ok(&[
            "query",
            "run",
            "--lib",
            lib.to_str().unwrap(),
            "--speed",
            &v.to_string(),
            "--out",
            q.to_str().unwrap(),
            "--quiet",
        ]);
        let t = stancelib::library::codec::table::Table::open(&q).unwrap();
        let row = super::util::first_stance_ids(&t)
            .iter()
            .position(|x| *x == id)
            .expect("the cycle is answered");
        let want_c = t.f64_lists("contact_time_s", Some(2)).unwrap()[row][0];
        let want_t = t.f64_lists("step_period_s", Some(2)).unwrap()[row][0];
        let (got_c, got_t) = rebuilt(&out, &format!("rebuilt_{v}"));
        eprintln!(
            "edit at {v} m/s: contact {got_c:.3} s (query {want_c:.3}), step {got_t:.3} s (query {want_t:.3})"
        );
        assert!(
            (got_c / want_c - 1.0).abs() <= 0.05,
            "contact {got_c} vs {want_c}"
        );
        assert!(
            (got_t / want_t - 1.0).abs() <= 0.05,
            "step {got_t} vs {want_t}"
        );
        contact.push(got_c);
    }
    assert!(
        contact[1] < 0.85 * contact[0],
        "faster is shorter contact: {contact:?}"
    );
    // The paper's law: the recorded cadence at both speeds.
    let mut steps = Vec::new();
    for v in [2.0, 4.0] {
        let out = dir.path().join(format!("paper_{v}.bvh"));
        edit(&[
            "edit",
            "run",
            "--lib",
            lib.to_str().unwrap(),
            "--speed",
            &v.to_string(),
            "--stance",
            &id,
            "--gait-law",
            "paper",
            "--out",
            out.to_str().unwrap(),
            "--allow-infeasible",
        ]);
        steps.push(rebuilt(&out, &format!("paper_rebuilt_{v}")).1);
    }
    assert!(
        (steps[0] / steps[1] - 1.0).abs() <= 0.03,
        "paper law keeps the period: {steps:?}"
    );
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
