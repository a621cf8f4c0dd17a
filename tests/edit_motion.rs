//! Issue 14: `edit run` and `edit jump` write full-body BVH that goes back into the crate's
//! own ingest and build; every bound of the issue is checked on the re-ingested motion.

use std::path::{Path, PathBuf};

use stancelib::bvh::parse_file;
use stancelib::edit::rotation::{angle_deg, from_euler, slerp, Quat};
use stancelib::ingest::{ingest, ClipFrames, ClipOutcome, ClipSummary, ContactRun, IngestOptions};
use stancelib::library::read::{open_library, read_parquet};
use stancelib::query::run::run_cycles;
use stancelib::skeleton::Skeleton;

use super::util::{ok, root, shared_or_skip, stancelib};

const G: f64 = 9.81;

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

/// A library of the given BVH files in `dir/lib`.
fn library(dir: &Path, files: &[PathBuf]) -> PathBuf {
    let lib = dir.join("lib");
    let mut args: Vec<String> = vec!["build".into()];
    args.extend(files.iter().map(|f| f.display().to_string()));
    args.extend(["--out".into(), lib.display().to_string()]);
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&a);
    lib
}

fn fixture(name: &str) -> PathBuf {
    root().join("fixtures/bvh").join(format!("{name}.bvh"))
}

/// The first run cycle of `clip` in a library: (first stance id, recorded speed).
fn cycle_of(lib: &Path, clip: &str) -> (String, f64) {
    let l = open_library(lib).unwrap();
    let c = run_cycles(&l.stances)
        .into_iter()
        .find(|c| l.stances[c.stances[0]].clip == clip)
        .expect("a run cycle");
    (l.stances[c.stances[0]].stance_id.clone(), c.v_orig)
}

/// The plan sidecar, by column.
struct Plan {
    time: Vec<f64>,
    phase: Vec<String>,
    com: Vec<[f64; 3]>,
    pose_com: Vec<[f64; 3]>,
    window: Vec<Option<(f64, f64)>>,
    stance: Vec<Option<String>>,
    converged: Vec<bool>,
}

fn read_plan(out: &Path) -> Plan {
    let df = read_parquet(&out.with_extension("plan.parquet")).unwrap();
    let f = |n: &str| -> Vec<Option<f64>> { df.column(n).unwrap().f64().unwrap().iter().collect() };
    let v3 = |p: &str| -> Vec<[f64; 3]> {
        let (x, y, z) = (f(&format!("{p}_x")), f(&format!("{p}_y")), f(&format!("{p}_z")));
        (0..x.len()).map(|i| [x[i].unwrap(), y[i].unwrap(), z[i].unwrap()]).collect()
    };
    let s = |n: &str| -> Vec<Option<String>> {
        df.column(n).unwrap().str().unwrap().iter().map(|v| v.map(String::from)).collect()
    };
    let (td, lo) = (f("stance_td_s"), f("stance_lo_s"));
    Plan {
        time: f("time_s").into_iter().map(Option::unwrap).collect(),
        phase: s("phase").into_iter().map(Option::unwrap).collect(),
        com: v3("com"),
        pose_com: v3("pose_com"),
        window: td.iter().zip(&lo).map(|(a, b)| a.zip(*b)).collect(),
        stance: s("stance_id"),
        converged: df.column("converged").unwrap().bool().unwrap().iter().map(Option::unwrap).collect(),
    }
}

fn reingest(out: &Path) -> (ClipSummary, ClipFrames, Vec<ContactRun>) {
    let bvh = parse_file(out).unwrap();
    match ingest(&bvh, &IngestOptions::default()).unwrap() {
        ClipOutcome::Body { summary, frames, contacts } => (summary, frames, contacts),
        ClipOutcome::Skipped { reason, .. } => panic!("{} skipped: {reason}", out.display()),
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// What the round trip measured (printed, then asserted by the callers).
#[derive(Debug, Default)]
struct Figures {
    com_rms_m: f64,
    com_max_m: f64,
    event_err_frames: f64,
    slide_max_m: f64,
    joint_step_max_deg: f64,
    flight_az_err: f64,
    unconverged: usize,
}

/// Re-ingests `out` and measures it against its plan.
fn measure(out: &Path) -> Figures {
    let plan = read_plan(out);
    let (summary, frames, contacts) = reingest(out);
    let dt = summary.frame_time_s;
    let mut fig = Figures::default();
    assert_eq!(frames.frame.len(), plan.time.len(), "every written frame is kept");
    // COM: re-measured against the plan.
    let errs: Vec<f64> = (0..plan.com.len()).map(|i| dist(frames.com[i], plan.com[i])).collect();
    fig.com_rms_m = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len() as f64).sqrt();
    fig.com_max_m = errs.iter().fold(0.0, |a, &b| a.max(b));
    fig.unconverged = plan.converged.iter().filter(|c| !**c).count();
    for i in 0..plan.com.len() {
        assert!(dist(plan.pose_com[i], frames.com[i]) < 1e-6, "pose COM column = re-ingested COM");
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
        for e in feet {
            let k = ["left_foot", "right_foot"].iter().position(|x| *x == e).unwrap();
            let run = contacts
                .iter()
                .filter(|c| c.effector == e)
                .find(|c| (c.first_frame as f64) * dt <= lo + dt && (c.last_frame as f64) * dt >= td - dt)
                .unwrap_or_else(|| panic!("{}: no {e} contact for stance {id} [{td:.3}, {lo:.3}]", out.display()));
            if *td > dt {
                if let Some(t) = run.td_time_s {
                    fig.event_err_frames = fig.event_err_frames.max((t - td).abs() / dt);
                }
            }
            if *lo < t_end - dt {
                if let Some(t) = run.lo_time_s {
                    fig.event_err_frames = fig.event_err_frames.max((t - lo).abs() / dt);
                }
            }
            // Slide: the foot point that stays put (heel = ankle, or toe tip) during the
            // planned stance, horizontal distance from its position at mid-stance.
            let ankle = frames.effector_pos[k].as_ref().unwrap();
            let idx: Vec<usize> = (0..plan.time.len())
                .filter(|&i| plan.time[i] >= *td && plan.time[i] <= *lo)
                .collect();
            let mid = idx[idx.len() / 2];
            let hor = |p: &[[f64; 3]]| {
                idx.iter()
                    .map(|&i| (p[i][0] - p[mid][0]).hypot(p[i][1] - p[mid][1]))
                    .fold(0.0, f64::max)
            };
            let slide = hor(ankle).min(hor(&frames.toe[k]));
            fig.slide_max_m = fig.slide_max_m.max(slide);
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
    assert!(b.motion.values.iter().all(|v| v.is_finite()), "no NaN in {}", out.display());
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

/// The issue's bounds on one written motion.
fn assert_bounds(f: &Figures) {
    assert!(f.com_rms_m <= 0.01, "COM RMS {} m > 1 cm", f.com_rms_m);
    assert!(f.com_max_m <= 0.02, "COM max {} m > 2 cm", f.com_max_m);
    assert!(f.event_err_frames <= 1.0, "contact event {} frames from the plan", f.event_err_frames);
    assert!(f.slide_max_m <= 0.01, "support foot slides {} m", f.slide_max_m);
    assert!(f.flight_az_err <= 0.5, "flight curvature {} m/s² from −g", f.flight_az_err);
    assert!(f.joint_step_max_deg <= 30.0, "a joint turns {}° in one 120 Hz frame", f.joint_step_max_deg);
    assert_eq!(f.unconverged, 0, "frames whose COM or feet missed the 1 mm tolerance");
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
    let lib = library(dir.path(), &[fixture("run_120hz_m_yup")]);
    let (id, v0) = cycle_of(&lib, "run_120hz_m_yup");
    for v in [2.0, 3.0, 4.0] {
        let out = dir.path().join(format!("run_{v}.bvh"));
        let o = out.display().to_string();
        ok(&["edit", "run", "--lib", lib.to_str().unwrap(), "--speed", &v.to_string(), "--stance", &id, "--out", &o, "--allow-infeasible"]);
        assert!(out.with_extension("png").is_file());
        let f = measure(&out);
        assert_bounds(&f);
        let sub = tempfile::tempdir_in(dir.path()).unwrap();
        let speed = rebuilt_speed(sub.path(), &out);
        eprintln!("run at {v} m/s (recorded {v0:.3}): rebuilt {speed:.4} m/s");
        assert!((speed - v).abs() <= 0.02 * v, "rebuilt speed {speed} vs {v}");
    }
}
