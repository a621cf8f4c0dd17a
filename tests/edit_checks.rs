//! Issue 14, the checks that were still missed: a jump higher than recorded keeps its
//! contact times and converges on every frame (the foot turns about its toe tip when the
//! planned COM is beyond the leg's reach), and a real run's support foot holds still (the
//! capture's slide of a resting foot point is removed). Issue 37 item 5: an edited run has
//! the query's contact time and cadence and the recording's posture, a higher jump keeps
//! bent knees in flight and no root spike; issue 38 item 1: every edit prints its verdict
//! and exits by it.

use super::edit_motion::{
    assert_bounds_except, cycle_of, edit, edit_cycle, edit_with_output, first_cycle_against_source,
    first_jump, fixture, library, measure, read_plan, recorded_jump_against_source,
};
use super::util::{ok, refused, s, shared_or_skip};
use stancelib::library::codec::table::read_parquet;
use std::path::{Path, PathBuf};

// See: issue 14 item 3 — "iterate root correction and leg IK until the COM error is below
// 1 mm; report frames that do not converge": at 1.2 × the recorded apex 11 frames at the
// end of the push and the start of the landing did not converge (exit 1) and the contacts
// were re-detected 4.7 frames off the plan; with the toe pivot the edit exits 0 (every
// frame converged) and the events are within 1 frame.
#[test]
fn jump_higher_than_recorded_pivots_on_the_toes_and_converges() {
    let dir = tempfile::tempdir().unwrap();
    let lib = library(dir.path(), &[fixture("jump_120hz_cmu_yup")]);
    let out = dir.path().join("jump_120pct.bvh");
    // Exit 0: no frame reported as not converged (the request itself fails the force
    // limit, so it is written with --allow-infeasible).
    ok(&[
        "edit",
        "jump",
        "--lib",
        lib.to_str().unwrap(),
        "--height-scale",
        "1.2",
        "--allow-infeasible",
        "--out",
        out.to_str().unwrap(),
    ]);
    let f = measure(&out);
    assert_eq!(f.unconverged, 0, "{f:?}");
    assert_bounds_except(&f, &[]);
}

// See: issue 14 checks — "the support foot's contact point slides ≤ 1 cm during each
// stance; contacts are detected within 1 frame": on the CMU run the support foot slid
// 17 mm (the capture's own marker slide, reproduced), contacts were 1.6 and 4.5 frames
// off and 28 / 48 frames did not converge (feet out of reach at push-off). Now: slide
// 5.4 mm at both speeds, events 0.84 frames at the recorded speed; at 1.1 × the left
// push-off ended 2.0 frames early and 10 frames did not converge (1 at 1.0 ×): the plan
// puts the COM 1.127 m from the contact at liftoff, 3 % beyond the recorded 1.094 m, with
// the foot already upright on its toe. With the posture for reach (pelvis and trunk turn
// so the stance hip comes nearer the foot, `edit::posture`): events 0.84 / 0.91 frames at
// 1.0 × / 1.1 ×, every frame converged (measured 2026-12-02). After the leaned cycle and
// the −g stance edges: events 0.86 / 0.85 frames, slide 5.3 mm, every frame converged
// (2026-12-03).
#[test]
fn real_run_edit_support_foot_holds_still_and_lifts_on_time() {
    let Some(data) = shared_or_skip("real_run_edit_support_foot_holds_still_and_lifts_on_time")
    else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let src = data.join("bvh/run/cmu_09_01_run_mb.bvh");
    let lib = library(dir.path(), std::slice::from_ref(&src));
    let (id, v0) = cycle_of(&lib, "cmu_09_01_run_mb");
    for (scale, misses, most_unconverged) in [(1.0, &[][..], 0), (1.1, &[][..], 0)] {
        let v = scale * v0;
        let out = dir.path().join(format!("cmu_{scale}.bvh"));
        edit_cycle(&lib, &id, v, &out);
        let f = measure(&out);
        assert_bounds_except(&f, misses);
        assert!(
            f.unconverged <= most_unconverged,
            "{scale} × v0: {} frames did not converge (measured {} or fewer)",
            f.unconverged,
            most_unconverged
        );
        if scale == 1.0 {
            // The recorded speed should reproduce the recording (issue 14: joint-angle RMS
            // ≤ 3°, root path ≤ 2 cm). Over the first cycle: 4.58° and 11.6 cm on
            // 2026-12-02; 4.52° and 4.06 cm with the periodic cycle leaned, not rescaled
            // (`edit::lean`); 1.80° and 3.02 cm with stance edges on −g flight parabolas
            // (`stances::assemble`, 2026-12-03); 1.80° and 1.61 cm with the recording's COM
            // detail added to each planned stance (`edit::detail`) and the cycle's height
            // change split between its start and end (`edit::plan::run_requests`),
            // 2026-12-06 (2.12 cm with a cubic-shaped detail alone, 2.79 cm with the split
            // alone). This restores the recording's own path on top of the force model, so
            // it checks the editor's round trip, not the force model's reproduction.
            let (rms, root) = first_cycle_against_source(&out, &src, &lib);
            eprintln!(
                "CMU identity cycle: joint-angle RMS {rms:.3}° (bound 3), root path \
                 {root:.4} m (bound 0.02)"
            );
            assert!(rms <= 3.0, "joint-angle RMS {rms}° > 3°");
            assert!(root <= 0.02, "root path {root} m > 0.02 m");
        }
    }
}

// See: issue 14 checks — "a request for the recorded speed (or the recorded jump)
// reproduces the recorded motion: joint-angle RMS ≤ 3° and root path ≤ 2 cm", on the shared
// real clips. Only the 120 Hz fixture jump was checked until 2026-12-06. Measured then over
// the whole edit (root path before → after the recording's COM detail, `edit::detail`):
// cmu_01_01 1.33 → 1.25 cm; cmu_13_32 8.8 → 5.3 cm and cmu_02_04 (a vertical jump with
// long rest stances) 30 → 30 cm; then 12.9 cm for the vertical jump with its landing
// chained in the liftoff's heading (it was chained along its apex velocity, about 50° off:
// 0.08 m/s forward, 0.10 m/s of kept sideways drift) and the detail measured at the played
// β_p; then (2026-12-06, second session) 0.96 / 1.42 / 2.36 cm with a jump's outer edges
// left free (its first touchdown and last liftoff join no planned flight), its travel
// offsets kept instead of balanced, the landing chained in its own recorded heading (3.5°
// off the liftoff's on the vertical jump, which turned the whole landing pose) and the edge
// corrections over at most 0.2 s (`edit::detail::EDGE_WINDOW_S`); the vertical jump's
// 2.36 cm was its left foot shuffling 15 cm inside its recorded landing stance, held in
// place as a slide: kept as a step (`edit::FOOT_STEP_M`), 1.97 cm and 2.1°.
#[test]
fn recorded_real_jumps_against_their_recordings() {
    let Some(data) = shared_or_skip("recorded_real_jumps_against_their_recordings") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    for clip in [
        "cmu_01_01_forward_jumps_mb",
        "cmu_13_32_forward_jump_daz",
        "cmu_02_04_vertical_jump_mb",
    ] {
        let src = data.join(format!("bvh/jump/{clip}.bvh"));
        let sub = dir.path().join(clip);
        let lib = library(&sub, std::slice::from_ref(&src));
        let out = sub.join("jump.bvh");
        let (rms, root) = recorded_jump_against_source(&lib, &src, &out);
        eprintln!("{clip}: recorded jump, joint-angle RMS {rms:.3}°, root path {root:.4} m");
        // And the round trip's bounds, every one of them (the issue asks them of every
        // written BVH; the real jumps were first measured on 2026-12-06).
        assert_bounds_except(&measure(&out), &[]);
        assert!(rms <= 3.0, "{clip}: joint-angle RMS {rms}° > 3°");
        assert!(root <= 0.02, "{clip}: root path {root} m > 0.02 m");
    }
}

// See: issue 14, `edit jump --pair LIFTOFF_ID:LANDING_ID`. A liftoff and a landing of two
// different recorded jumps of CMU 01_01, recorded 180° apart (the subject turns around
// between them): chained in the landing's own recorded heading, its braking force pushed
// along the travel and the edit ended at 2.1 m/s with 14 frames not converged (found by
// review, 2026-12-06); turned onto the liftoff's heading it comes to rest and every frame
// converges.
#[test]
fn a_paired_jump_lands_in_the_liftoffs_heading() {
    let Some(data) = shared_or_skip("a_paired_jump_lands_in_the_liftoffs_heading") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let src = data.join("bvh/jump/cmu_01_01_forward_jumps_mb.bvh");
    let lib = library(dir.path(), std::slice::from_ref(&src));
    let l = stancelib::library::readers::read::open_library(&lib).unwrap();
    let timing =
        stancelib::library::readers::read::read_stance_timing(&lib.join("stances.parquet"))
            .unwrap();
    let id = |frame: &str| {
        let i = l
            .stances
            .iter()
            .position(|s| s.stance_id.ends_with(frame))
            .unwrap_or_else(|| panic!("stance {frame}"));
        (l.stances[i].stance_id.clone(), timing[i].heading)
    };
    let ((up, h_up), (down, h_down)) = (id(":LR:150"), id(":LR:1335"));
    let dot = h_up[0] * h_down[0] + h_up[1] * h_down[1];
    assert!(
        dot < -0.9,
        "recorded headings {h_up:?} and {h_down:?} are opposite"
    );
    let out = dir.path().join("paired.bvh");
    // Exit 0: every frame converged (the request fails friction, so it is allowed).
    ok(&[
        "edit",
        "jump",
        "--lib",
        lib.to_str().unwrap(),
        "--pair",
        &format!("{up}:{down}"),
        "--allow-infeasible",
        "--out",
        out.to_str().unwrap(),
    ]);
    let plan = read_plan(&out);
    let (t, c, n) = (&plan.time, &plan.com, plan.time.len());
    let speed =
        (c[n - 1][0] - c[n - 2][0]).hypot(c[n - 1][1] - c[n - 2][1]) / (t[n - 1] - t[n - 2]);
    assert!(speed < 0.3, "the landing ends at {speed} m/s");
    assert_bounds_except(&measure(&out), &[]);
}

// See: issue 14 — `--pair` names a liftoff and a landing; the edit poses both from one
// source clip, so stances of two clips are refused, naming both.
#[test]
fn a_pair_of_two_clips_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let lib = library(
        dir.path(),
        &[fixture("jump_120hz_cmu_yup"), fixture("jump_100hz_m_zup")],
    );
    let l = stancelib::library::readers::read::open_library(&lib).unwrap();
    let s = &l.stances;
    let up = s
        .iter()
        .find(|x| x.clip == "jump_120hz_cmu_yup" && stancelib::query::jump::is_liftoff(x))
        .expect("a liftoff");
    let down = s
        .iter()
        .find(|x| x.clip == "jump_100hz_m_zup" && stancelib::query::jump::is_landing(x))
        .expect("a landing");
    let out = dir.path().join("cross.bvh");
    refused(
        &[
            "edit",
            "jump",
            "--lib",
            lib.to_str().unwrap(),
            "--pair",
            &format!("{}:{}", up.stance_id, down.stance_id),
            "--out",
            out.to_str().unwrap(),
        ],
        &["different clips", &up.stance_id, &down.stance_id],
    );
    assert!(!out.exists(), "nothing written");
}

// See: issue 14 checks — "the rebuilt stances reproduce the request: apex height and
// distance within 2 cm (jumps)", on the real forward jumps asked a new distance, and a new
// height and distance (the fixture jump is vertical: its distance is fixed). First measured
// 2026-12-06 on `cmu_13_32`: at the recorded height, 0.9 / 1.0 / 1.1 × the recorded
// distance rebuilt 1.8 / 1.5 / 1.2 cm short; 3 cm higher, 4.3 / 3.9 / 3.6 cm short. Both
// edges of the rebuilt jump were cut where the edit began and ended, not where the
// recording's were: with the recording's rest written before the liftoff
// (`edit::LEAD_IN_S`) and a quiet stretch at the clip's end cutting a stance however
// short (`stances::segment`, `settled_end`), they rebuild within −0.05 … +0.59 cm, and
// three of `cmu_01_01`'s four jumps within 1.4 cm. The fourth, `LR:1003`, starts with
// 2.4 s of shifting weight before its push: its model distance was ill-conditioned (its
// identity edit rebuilt 2.2 cm long, 6.8 cm when started half a frame later, while the
// travel was the recording's to 0.4 cm), 2.96 cm at +3 cm and 1.1 ×; with the force fit's
// travel targets (`force_model::ratio`, "Travel targets") every jump rebuilds within
// 1.05 cm (cmu_13_32's four within +0.23 … +0.51 cm). The change of the travel measured is checked too. KNOWN MISS found by this
// test: a foot of `LR:1697`'s pair slides 1.16 cm at +3 cm and 1.1 × (bound 1 cm): the
// recorded right ankle swivels 1.19 cm about its toe tip (which stays within 1.2 mm) in
// that stance, and the check measures the ankle (docs/edited-motion.md, "A new height and
// distance").
#[test]
fn real_forward_jumps_at_a_new_height_and_distance_round_trip() {
    let Some(data) = shared_or_skip("real_forward_jumps_at_a_new_height_and_distance_round_trip")
    else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let mut cases = 0;
    for clip in ["cmu_13_32_forward_jump_daz", "cmu_01_01_forward_jumps_mb"] {
        let src = data.join(format!("bvh/jump/{clip}.bvh"));
        let lib = library(&dir.path().join(clip), std::slice::from_ref(&src));
        let l = stancelib::library::readers::read::open_library(&lib).unwrap();
        let travel = measured_travel(&lib);
        let pairs: Vec<(usize, usize)> = (1..l.stances.len())
            .filter(|&i| {
                stancelib::query::jump::is_liftoff(&l.stances[i - 1])
                    && stancelib::query::jump::is_landing(&l.stances[i])
            })
            .map(|i| (i - 1, i))
            .collect();
        assert!(!pairs.is_empty(), "{clip}: a recorded jump");
        for (i, j) in pairs {
            let (s1, s2) = (&l.stances[i], &l.stances[j]);
            let (h0, d0) = stancelib::query::jump::recorded_jump(s1, s2);
            let t0 = travel[&s1.stance_id] + travel[&s2.stance_id];
            let pair = format!("{}:{}", s1.stance_id, s2.stance_id);
            let requests: &[(f64, f64)] = if clip.starts_with("cmu_13") {
                &[(0.0, 0.9), (0.0, 1.1), (0.03, 0.9), (0.03, 1.1)]
            } else {
                &[(0.03, 1.1)]
            };
            for &(dh, k) in requests {
                let (h, d) = (h0 + dh, k * d0);
                cases += 1;
                let out = dir.path().join(format!("jump{cases}.bvh"));
                edit(&[
                    "edit",
                    "jump",
                    "--lib",
                    lib.to_str().unwrap(),
                    "--pair",
                    &pair,
                    "--height",
                    &h.to_string(),
                    "--distance",
                    &d.to_string(),
                    "--allow-infeasible",
                    "--out",
                    out.to_str().unwrap(),
                ]);
                // KNOWN MISS: the landing after `LR:1697` slides 1.16 cm at +3 cm, 1.1 ×.
                let misses: &[(&str, f64)] = if s1.stance_id.ends_with(":LR:1697") {
                    &[("slide_m", 0.0125)]
                } else {
                    &[]
                };
                assert_bounds_except(&measure(&out), misses);
                let rl = library(&dir.path().join(format!("rebuilt{cases}")), &[out]);
                let r = stancelib::library::readers::read::open_library(&rl).unwrap();
                let (a, b) = first_jump(&r.stances).expect("the rebuilt clip has a jump");
                let (hr, dr) = stancelib::query::jump::recorded_jump(&r.stances[a], &r.stances[b]);
                let rt = measured_travel(&rl);
                let moved = rt[&r.stances[a].stance_id] + rt[&r.stances[b].stance_id] - t0;
                eprintln!(
                    "{pair} +{dh} m, {k} ×: apex {:+.4} m, model distance {:+.4} m, travel \
                     change {:+.4} m against {:+.4} m asked",
                    hr - h,
                    dr - d,
                    moved,
                    d - d0
                );
                assert!((hr - h).abs() <= 0.02, "{pair}: apex {hr} vs {h}");
                assert!((dr - d).abs() <= 0.02, "{pair}: distance {dr} vs {d}");
                assert!(
                    (moved - (d - d0)).abs() <= 0.02,
                    "{pair}: travel change {moved}"
                );
            }
        }
    }
    assert_eq!(
        cases, 8,
        "four requests of cmu_13_32, one of each cmu_01_01 jump"
    );
}

/// `x_measured_m` of every stance of a library, by stance id (the COM's travel along the
/// heading from its touchdown apex to its liftoff apex, measured, not the model's).
fn measured_travel(lib: &std::path::Path) -> std::collections::HashMap<String, f64> {
    let df = read_parquet(&lib.join("stances.parquet")).unwrap();
    let id = df.column("stance_id").unwrap().str().unwrap().clone();
    let x = df.column("x_measured_m").unwrap().f64().unwrap().clone();
    id.iter()
        .zip(x.iter())
        .map(|(i, x)| (i.unwrap().to_string(), x.unwrap()))
        .collect()
}

// ---------------------------------------------------------------------------------------
// Issue 37 item 5, "Edited motion follows", and the edits' part of issue 38 item 1.

/// A column of an edit's plan table (f64).
fn plan_f64(out: &Path, name: &str) -> Vec<f64> {
    let df = read_parquet(&out.with_extension("plan.parquet")).unwrap();
    let c = df.column(name).unwrap().f64().unwrap().clone();
    c.iter().map(|v| v.unwrap_or(f64::NAN)).collect()
}

/// A string column of an edit's plan table.
fn plan_str(out: &Path, name: &str) -> Vec<Option<String>> {
    let df = read_parquet(&out.with_extension("plan.parquet")).unwrap();
    let c = df.column(name).unwrap().str().unwrap().clone();
    c.iter().map(|v| v.map(String::from)).collect()
}

/// Per frame of `bvh`, measured from its joint positions as `frames --joints` writes them
/// (independent of `edit::fidelity`): trunk lean (mid-hip → `Neck` against vertical, in
/// the hips' sagittal plane, deg), knee flexion left and right (180° − ∠(UpLeg, Leg,
/// Foot), deg) and the `Hips` position (m, Z up); DAZ skeletons by their own names.
struct Gauged {
    lean: Vec<f64>,
    knees: Vec<[f64; 2]>,
    hips: Vec<[f64; 3]>,
    dt: f64,
}

fn gauged(bvh: &Path, dir: &Path) -> Gauged {
    let out = dir.join(format!(
        "joints_{}",
        bvh.file_stem().unwrap().to_string_lossy()
    ));
    ok(&[
        "frames",
        s(bvh).as_str(),
        "--out",
        s(&out).as_str(),
        "--joints",
        "--quiet",
    ]);
    let df = read_parquet(&out.join("joints.parquet")).unwrap();
    let names: Vec<String> = df
        .column("joint")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .map(|v| v.unwrap().to_string())
        .collect();
    let frame: Vec<i64> = df
        .column("frame")
        .unwrap()
        .i64()
        .unwrap()
        .iter()
        .map(Option::unwrap)
        .collect();
    let axis = |n: &str| -> Vec<f64> {
        df.column(n)
            .unwrap()
            .f64()
            .unwrap()
            .iter()
            .map(Option::unwrap)
            .collect()
    };
    let (x, y, z) = (axis("x_m"), axis("y_m"), axis("z_m"));
    let n = (*frame.iter().max().unwrap() + 1) as usize;
    let mut at: std::collections::HashMap<&str, Vec<[f64; 3]>> = Default::default();
    for i in 0..names.len() {
        at.entry(names[i].as_str())
            .or_insert_with(|| vec![[0.0; 3]; n])[frame[i] as usize] = [x[i], y[i], z[i]];
    }
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    // The CMU/MotionBuilder names, or the DAZ ones (`cmu_13_32_…_daz`).
    let daz = at.contains_key("lThigh");
    let name = |side: usize, j: usize| -> String {
        let (cmu, d) = (["UpLeg", "Leg", "Foot"], ["Thigh", "Shin", "Foot"]);
        if daz {
            format!("{}{}", ["l", "r"][side], d[j])
        } else {
            format!("{}{}", ["Left", "Right"][side], cmu[j])
        }
    };
    let (neck_name, hips_name) = if daz {
        ("neck", "hip")
    } else {
        ("Neck", "Hips")
    };
    let knee = |side: usize, f: usize| {
        let p = |j: usize| at[name(side, j).as_str()][f];
        let (u, v) = (sub(p(0), p(1)), sub(p(2), p(1)));
        180.0
            - (dot(u, v) / (dot(u, u) * dot(v, v)).sqrt())
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees()
    };
    let lean = |f: usize| {
        let at_name = |n: &str| at[n][f];
        let (hl, hr, neck) = (
            at_name(&name(0, 0)),
            at_name(&name(1, 0)),
            at_name(neck_name),
        );
        let lat = [hl[0] - hr[0], hl[1] - hr[1], 0.0];
        let fwd = [-lat[1], lat[0], 0.0]; // lat × z
        let mid = [
            0.5 * (hl[0] + hr[0]),
            0.5 * (hl[1] + hr[1]),
            0.5 * (hl[2] + hr[2]),
        ];
        let t = sub(neck, mid);
        (dot(t, fwd) / dot(fwd, fwd).sqrt())
            .atan2(t[2])
            .to_degrees()
    };
    let dt = stancelib::bvh::parse_file(bvh).unwrap().motion.frame_time_s;
    Gauged {
        lean: (0..n).map(lean).collect(),
        knees: (0..n).map(|f| [knee(0, f), knee(1, f)]).collect(),
        hips: at[hips_name].clone(),
        dt,
    }
}

/// `[min, max]` of the values.
fn range(v: impl Iterator<Item = f64>) -> [f64; 2] {
    v.fold([f64::INFINITY, f64::NEG_INFINITY], |[a, b], x| {
        [a.min(x), b.max(x)]
    })
}

/// Posture tolerances of the issue's "within the recorded range", deg: the same as
/// `edit::fidelity`'s defaults (a runner's own spread between trials at one speed).
const LEAN_TOL_DEG: f64 = 5.0;
const KNEE_TOL_DEG: f64 = 10.0;

/// The written run's trunk lean and knee flexion against the whole source clip's range
/// (± the tolerances): `(frames outside, edited lean range, edited knee range, recorded
/// lean range, recorded knee range)`.
fn run_posture(
    out: &Path,
    src: &Path,
    dir: &Path,
    swing_fold_deg: f64,
) -> (usize, [f64; 2], [f64; 2], [f64; 2], [f64; 2]) {
    let (e, r) = (gauged(out, dir), gauged(src, dir));
    let (lean_r, knee) = (
        range(r.lean.iter().copied()),
        range(r.knees.iter().flatten().copied()),
    );
    let knee_r = [knee[0], knee[1] + swing_fold_deg];
    let outside = (0..e.lean.len())
        .filter(|&f| {
            let l = e.lean[f];
            l < lean_r[0] - LEAN_TOL_DEG
                || l > lean_r[1] + LEAN_TOL_DEG
                || e.knees[f]
                    .iter()
                    .any(|&k| k < knee_r[0] - KNEE_TOL_DEG || k > knee_r[1] + KNEE_TOL_DEG)
        })
        .count();
    let lean_e = range(e.lean.iter().copied());
    let knee_e = range(e.knees.iter().flatten().copied());
    (outside, lean_e, knee_e, lean_r, knee_r)
}

// See: issue 37 item 5 — "edit run changes cadence and contact time with speed as the
// query predicts" and issue 37's κ law: `edit run` used `(vs, ve, x)·k`, now the query's
// `u + κ(v − v₀)` with timing σ (`edit::plan::law_run_requests`). The planned stances'
// contact times and the cycle's period (touchdown to touchdown two stances later) equal
// `query run`'s `contact_time_s` and `step_period_s` at the same speed within a frame
// (measured: identical to 1e-9 s), and the terminal says the speed achieved.
#[test]
fn issue37_item5_edit_run_contact_time_and_cadence_are_the_querys() {
    let dir = tempfile::tempdir().unwrap();
    let lib = library(dir.path(), &[fixture("run_120hz_m_yup")]);
    let (id, _) = cycle_of(&lib, "run_120hz_m_yup");
    let frame_s = 1.0 / 120.0;
    for v in [2.0, 3.0, 4.0, 5.0] {
        let out = dir.path().join(format!("run_{v}.bvh"));
        let args = [
            "edit",
            "run",
            "--lib",
            &s(&lib),
            "--speed",
            &v.to_string(),
            "--stance",
            &id,
            "--allow-infeasible",
            "--out",
            &s(&out),
        ];
        let (code, stdout, err) = super::util::stancelib(&args);
        assert!(matches!(code, 0 | 1 | 3), "{stdout}\n{err}");
        assert!(stdout.contains(&format!("speed {v:.3} m/s")), "{stdout}");
        let q = dir.path().join(format!("q_{v}.parquet"));
        ok(&[
            "query",
            "run",
            "--lib",
            &s(&lib),
            "--speed",
            &v.to_string(),
            "--out",
            &s(&q),
            "--quiet",
        ]);
        let t = stancelib::library::codec::table::Table::open(&q).unwrap();
        let row = super::util::first_stance_ids(&t)
            .iter()
            .position(|x| *x == id)
            .unwrap();
        let want_c = t.f64_lists("contact_time_s", Some(2)).unwrap()[row].clone();
        let want_t = t.f64_lists("step_period_s", Some(2)).unwrap()[row].clone();
        // The plan: each stance's window, in play order (S1, S2, S1, …).
        let (td, lo) = (
            plan_f64(&out, "stance_td_clip_s"),
            plan_f64(&out, "stance_lo_clip_s"),
        );
        let mut windows: Vec<(f64, f64)> = Vec::new();
        for i in 0..td.len() {
            if td[i].is_finite() && windows.last() != Some(&(td[i], lo[i])) {
                windows.push((td[i], lo[i]));
            }
        }
        assert!(windows.len() >= 4, "{windows:?}");
        let mut worst = 0.0f64;
        for (k, w) in windows.iter().enumerate() {
            let contact = w.1 - w.0;
            worst = worst.max((contact - want_c[k % 2]).abs());
            if let Some(next) = windows.get(k + 2) {
                worst = worst.max((next.0 - w.0 - (want_t[0] + want_t[1])).abs());
            }
        }
        eprintln!(
            "edit run {v} m/s: contact {:.4} / {:.4} s, cycle {:.4} s; query {:.4} / {:.4} s, \
             {:.4} s; largest difference {worst:.2e} s",
            windows[0].1 - windows[0].0,
            windows[1].1 - windows[1].0,
            windows[2].0 - windows[0].0,
            want_c[0],
            want_c[1],
            want_t[0] + want_t[1]
        );
        assert!(worst <= frame_s, "{worst} s > one frame");
    }
}

// See: issue 37 item 5 — "posture stays within the recorded range (trunk lean, knee
// angles)". Before: the posture solver leaned the trunk (15° DOF) and the CMU run edited to
// 4–5 m/s leaned 35–39°; the fixture run at 5 m/s landed with its knee at 5° (recorded ≥
// 32.5°). Now the trunk keeps its recorded orientation and a run's knee reaches no
// straighter than the source less 5° (`edit::RUN_KNEE_SLACK_DEG`), the heel rising about
// the toe instead. Measured from the written joints (not the editor's own gauge) against
// the whole source clip ± 5° lean, ± 10° knee. The swing knee may fold beyond the
// recording by the speed law the edit prints (`edit::swing`), and its upper bound moves
// by that much. At 5 m/s (1.66 × the plate run's speed) the lifted foot was held near its
// contact while the body moved on faster than recorded, and the knee locked through the
// flight (52 frames outside); a swinging ankle is now kept within the reference knee's
// flexion less 5° of its hip (`edit::pose::reach::swing_reach`): 0. The fixture at 5 m/s
// (1.43 ×, 70 frames before) landed with its knee 16° straighter than recorded, the planned
// contact 0.56 m ahead of the COM against 0.44 m at its own speed, and the 2 m/s jog at
// 5 m/s (2.5 ×) pushed off as straight; the pelvis now turns (up to 10°) for a support knee
// about to straighten 2.5° beyond the toe pivot's bound
// (`edit::pose::reach::POSTURE_KNEE_SLACK_DEG`): 0 on both. The other runner on plates
// (4 m/s) and the jog were not looked at when either change was made.
#[test]
fn issue37_item5_edit_run_posture_stays_within_the_recorded_range() {
    let dir = tempfile::tempdir().unwrap();
    let mut cases: Vec<(PathBuf, Vec<(f64, usize)>)> = vec![(
        fixture("run_120hz_m_yup"),
        // (speed, frames allowed outside): 0 at 2–4 m/s; the 5 m/s known miss as measured.
        vec![(2.0, 0), (3.0, 0), (4.0, 0), (5.0, 0), (6.0, 0)],
    )];
    if let Some(data) =
        shared_or_skip("issue37_item5_edit_run_posture_stays_within_the_recorded_range")
    {
        cases.push((
            data.join("forceplate/hamner_multi_run_3ms/clip.bvh"),
            vec![(2.0, 0), (3.0, 0), (4.0, 0), (5.0, 0)],
        ));
        cases.push((
            data.join("forceplate/hamner_s02_run_4ms/clip.bvh"),
            vec![(2.0, 0), (3.0, 0), (5.0, 0)],
        ));
        cases.push((
            data.join("forceplate/hamner_multi_run_2ms/clip.bvh"),
            vec![(3.0, 0), (4.0, 0), (5.0, 0)],
        ));
        cases.push((
            data.join("bvh/run/cmu_09_01_run_mb.bvh"),
            vec![(3.0, 0), (4.0, 0), (4.5, 0), (5.0, 0)],
        ));
    }
    for (n, (src, speeds)) in cases.iter().enumerate() {
        let sub = dir.path().join(format!("c{n}"));
        let lib = library(&sub, std::slice::from_ref(src));
        for &(v, allowed) in speeds {
            let out = sub.join(format!("run_{v}.bvh"));
            let (code, said) = edit_run_at(&lib, v, &out);
            // The swing knee may fold beyond the recording by the speed law it names.
            let fold = swing_law_deg(&said);
            let (outside, lean_e, knee_e, lean_r, knee_r) =
                run_posture(&out, src, &sub, fold.max(0.0));
            eprintln!(
                "{} at {v} m/s (exit {code}): lean {:.1}…{:.1}° (recorded {:.1}…{:.1}°), knee \
                 {:.1}…{:.1}° (recorded {:.1}…{:.1}°), {outside} frame(s) outside",
                src.display(),
                lean_e[0],
                lean_e[1],
                lean_r[0],
                lean_r[1],
                knee_e[0],
                knee_e[1],
                knee_r[0],
                knee_r[1]
            );
            if allowed > 0 {
                eprintln!("KNOWN MISS: {outside} frame(s) outside at {v} m/s (ceiling {allowed})");
            } else {
                // The editor's own check agrees: no posture line on stderr (exit 0 or 3).
                assert_ne!(code, 1, "{} at {v} m/s", src.display());
            }
            assert!(
                outside <= allowed,
                "{}: {outside} frames outside at {v} m/s",
                src.display()
            );
        }
    }
}

// See: issue 37 item 5 — a run edited faster than recorded keeps the recording's bent
// knees and no root spike the recording does not have (the issue asks it of jumps; a
// run's lifted foot is the same question). Before: the lifted foot was held near its
// contact while the body moved on faster than recorded, and the knee locked through the
// flight where the recording bends it to 51° (3 → 5 m/s), and the 2 m/s jog, whose apex
// lies inside its stance, played its stance backwards in the flights of its edits (a
// landing knee bent from 20° to 81° and back in three frames, the root at 35 g at
// 5 m/s, 6 g at 4 m/s). Now a swinging ankle stays within the reference knee's flexion
// less 5° of its hip (`edit::pose::reach::swing_reach`) and a flight edge whose source
// apex lies inside its stance holds the edge's pose (`edit::pose::frame`). Measured from
// the written joints and the plan (`jump_flight_and_spikes`), not the editor's gauge; the
// 4 m/s runner and the jog were not used to build either change.
#[test]
fn issue37_item5_edit_run_faster_keeps_the_lifted_knee_bent_and_no_root_spike() {
    let Some(data) = shared_or_skip(
        "issue37_item5_edit_run_faster_keeps_the_lifted_knee_bent_and_no_root_spike",
    ) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let fp = data.join("forceplate");
    // (source, speed, spike frames allowed): none, but for two known misses where the
    // landing leg reaches its knee bound around a touchdown 1.66 × and 2.5 × faster than
    // recorded: one frame at 3 → 5 (7.1 g, recorded ≤ 4.2 g) and two at 2 → 5 (5.7 and
    // 6.2 g, recorded ≤ 2.1 g; one until the hip of a swinging leg kept its world
    // rotation under a pelvis turn, `edit::posture`).
    let cases = [
        ("hamner_multi_run_3ms", 5.0, 1),
        ("hamner_s02_run_4ms", 5.0, 0),
        ("hamner_multi_run_2ms", 4.0, 0),
        ("hamner_multi_run_2ms", 5.0, 2),
    ];
    for (n, (clip, v, allowed)) in cases.into_iter().enumerate() {
        let src = fp.join(clip).join("clip.bvh");
        let sub = dir.path().join(format!("c{n}"));
        let lib = library(&sub, std::slice::from_ref(&src));
        let out = sub.join(format!("run_{v}.bvh"));
        let (code, said) = edit_run_at(&lib, v, &out);
        let (flights, locked, spikes, max_e, max_r) = jump_flight_and_spikes(&out, &src, &sub);
        eprintln!(
            "{clip} → {v} m/s (exit {code}): {} flights, {locked} knee(s) locked, spike frames \
             {spikes:?}, root ≤ {:.1} g (recorded {:.1} g)",
            flights.len(),
            max_e / G,
            max_r / G
        );
        assert!(!flights.is_empty(), "{clip} → {v}: no flight in {said}");
        assert_eq!(locked, 0, "{clip} → {v} m/s: {said}");
        assert_spikes_within(&spikes, allowed, &format!("{clip} → {v} m/s"));
    }
}

// See: issue 37 item 5 — an edited run's support foot meets the plan. The paper's contact
// point keeps the recording's split of the contact ahead of and behind the body, and CMU
// `09_01` (3.6 m/s) asked for 4.5 or 5 m/s pushed off farther behind than its legs reach:
// its last push-off frames 5.6 / 15.5 mm off the floor point with the knee straight, the
// heel up 50° and the pelvis turned 10° (exit 1). The fixture at 6 m/s landed with its
// knee straighter than its range (exit 1). The contact now moves, only where the legs do
// not reach, by the least step that lets them (`edit::footing`). Measured from
// the written plan: every frame converges, the moved contact is forward at a push-off,
// back at a landing, and the share of the contact ahead of the COM moves the way the
// plate runner's does from 2 to 3 m/s (0.39 → 0.46); runs that reach keep the paper's
// contact.
#[test]
fn issue37_item5_edit_run_moves_a_contact_only_where_the_legs_do_not_reach() {
    let dir = tempfile::tempdir().unwrap();
    let fixture_lib = library(&dir.path().join("fx"), &[fixture("run_120hz_m_yup")]);
    let out = dir.path().join("fx_6.bvh");
    let (code, said) = edit_run_at(&fixture_lib, 6.0, &out);
    eprintln!("fixture → 6 m/s (exit {code}): {said}");
    assert_eq!(code, 0, "{said}");
    assert!(
        said.contains("contact moved") && said.contains(" back ("),
        "{said}"
    );
    assert_all_converged(&out);
    let Some(data) =
        shared_or_skip("issue37_item5_edit_run_moves_a_contact_only_where_the_legs_do_not_reach")
    else {
        return;
    };
    let src = data.join("bvh/run/cmu_09_01_run_mb.bvh");
    let lib = library(&dir.path().join("c09"), std::slice::from_ref(&src));
    let own = dir.path().join("c09_own.bvh");
    let (code, said) = edit_run_at(&lib, 3.6, &own);
    assert_eq!(code, 0, "{said}");
    assert!(!said.contains("contact moved"), "{said}");
    let split_own = share_ahead(&own);
    for v in [4.5, 5.0] {
        let out = dir.path().join(format!("c09_{v}.bvh"));
        let (code, said) = edit_run_at(&lib, v, &out);
        let split = share_ahead(&out);
        eprintln!(
            "cmu_09_01 → {v} m/s (exit {code}): share of the contact ahead of the COM \
             {split:.3} (at its own speed {split_own:.3}); {said}"
        );
        assert_eq!(code, 0, "{said}");
        assert!(
            said.contains("contact moved") && said.contains(" forward ("),
            "{said}"
        );
        assert_all_converged(&out);
        if v == 5.0 {
            // The paper's contact keeps the recorded share (0.421 at 5 m/s); the moved one
            // goes the way the plate runner's does with speed.
            assert!(
                split > split_own + 0.02,
                "{v} m/s: {split} against {split_own}"
            );
        }
    }
    // Runs whose written frames follow the plan keep the paper's contact (the second
    // exited 0 before the contact could move, and its oversampled trial alone would move
    // one).
    for (clip, v) in [("hamner_multi_run_3ms", 4.0), ("hamner_multi_run_2ms", 5.0)] {
        let lib = library(
            &dir.path().join(clip),
            &[data.join(format!("forceplate/{clip}/clip.bvh"))],
        );
        let out = dir.path().join(format!("{clip}_{v}.bvh"));
        let (code, said) = edit_run_at(&lib, v, &out);
        assert_eq!(code, 0, "{said}");
        assert!(!said.contains("contact moved"), "{clip} → {v} m/s: {said}");
    }
}

/// Every frame of an edit's plan table converged (COM and feet on their goals).
fn assert_all_converged(out: &Path) {
    let plan = read_parquet(&out.with_extension("plan.parquet")).unwrap();
    let converged = plan.column("converged").unwrap().bool().unwrap().clone();
    assert!(
        converged.iter().all(|c| c == Some(true)),
        "{}: a frame off the plan",
        out.display()
    );
}

/// The median share of a stance's contact length that lies ahead of the COM at touchdown,
/// from an edit's plan table: `x_TD / (x_TD + x_LO)` along each stance's travel, `x_TD`
/// the contact's distance ahead of the COM at its first stance frame and `x_LO` the COM's
/// beyond the contact at its last.
fn share_ahead(out: &Path) -> f64 {
    let phase = plan_str(out, "phase");
    let td = plan_f64(out, "stance_td_clip_s");
    let col = |n: &str| plan_f64(out, n);
    let (cx, cy, px, py) = (
        col("com_x_m"),
        col("com_y_m"),
        col("contact_x_m"),
        col("contact_y_m"),
    );
    let mut shares = Vec::new();
    let mut i = 0;
    while i < phase.len() {
        if phase[i].as_deref() != Some("stance") {
            i += 1;
            continue;
        }
        let mut j = i;
        while j + 1 < phase.len() && phase[j + 1].as_deref() == Some("stance") && td[j + 1] == td[i]
        {
            j += 1;
        }
        let h = [cx[j] - cx[i], cy[j] - cy[i]];
        let n = h[0].hypot(h[1]);
        let ahead = ((px[i] - cx[i]) * h[0] + (py[i] - cy[i]) * h[1]) / n;
        let behind = ((cx[j] - px[i]) * h[0] + (cy[j] - py[i]) * h[1]) / n;
        shares.push(ahead / (ahead + behind));
        i = j + 1;
    }
    assert!(!shares.is_empty(), "no stance in {}", out.display());
    shares.sort_by(f64::total_cmp);
    shares[shares.len() / 2]
}

/// `edit run --speed v --allow-infeasible` of `lib` into `out`: the exit code and stderr
/// ([`edit_with_output`]).
fn edit_run_at(lib: &Path, v: f64, out: &Path) -> (i32, String) {
    edit_with_output(&[
        "edit",
        "run",
        "--lib",
        &s(lib),
        "--speed",
        &v.to_string(),
        "--allow-infeasible",
        "--out",
        &s(out),
    ])
}

/// At most `allowed` root spike frames in `spikes` (a known miss, printed, when `allowed`
/// is above 0); `what` names the edit.
fn assert_spikes_within(spikes: &[usize], allowed: usize, what: &str) {
    if allowed > 0 {
        eprintln!(
            "KNOWN MISS: {what}: {} spike frame(s) (ceiling {allowed})",
            spikes.len()
        );
    }
    assert!(spikes.len() <= allowed, "{what}: root spikes at {spikes:?}");
}

/// The swing fold of the speed law an edit run printed ("speed law +4.2°"), degrees.
fn swing_law_deg(said: &str) -> f64 {
    let at = said
        .find("speed law ")
        .expect("the edit names its swing law")
        + "speed law ".len();
    let num: String = said[at..]
        .chars()
        .take_while(|c| c.is_ascii_digit() || matches!(c, '+' | '-' | '.'))
        .collect();
    num.parse()
        .unwrap_or_else(|_| panic!("swing law in {said}"))
}

/// Standard gravity, m/s² (the unit of the spike bound).
const G: f64 = 9.81;
/// The issue's spike bound: 5 g between frames.
const SPIKE_MPS2: f64 = 5.0 * G;

/// Second difference of a point path at frame `i`, m/s².
fn accel(p: &[[f64; 3]], i: usize, dt: f64) -> f64 {
    let d: Vec<f64> = (0..3)
        .map(|a| p[i + 1][a] - 2.0 * p[i][a] + p[i - 1][a])
        .collect();
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() / (dt * dt)
}

/// Per whole flight and leg `[largest edited flexion, largest source flexion]` (deg), the
/// legs locked, the spike frames, and the largest root acceleration edited and recorded
/// (m/s²).
type JumpFigures = (Vec<[[f64; 2]; 2]>, usize, Vec<usize>, f64, f64);

/// A jump edit against its source, from the written joints and the plan: per whole flight
/// and leg `(largest edited flexion, largest source flexion at the frames' source times)`,
/// the legs locked (under 10° on every flight frame where the source bends past 10°), and
/// the frames whose root accelerates above 5 g, relative to the pose's COM too (the COM's
/// own acceleration is the planned force), where the source has no such frame within two
/// frames of the frame's source time.
fn jump_flight_and_spikes(out: &Path, src: &Path, dir: &Path) -> JumpFigures {
    let (e, r) = (gauged(out, dir), gauged(src, dir));
    let phase = plan_str(out, "phase");
    let t_src = plan_f64(out, "source_clip_s");
    let com: Vec<[f64; 3]> = {
        let (x, y, z) = (
            plan_f64(out, "pose_com_x_m"),
            plan_f64(out, "pose_com_y_m"),
            plan_f64(out, "pose_com_z_m"),
        );
        (0..x.len()).map(|i| [x[i], y[i], z[i]]).collect()
    };
    let src_frame = |t: f64| ((t / r.dt).round().max(0.0) as usize).min(r.knees.len() - 1);
    // Whole flights: between two stance frames.
    let mut flights: Vec<(usize, usize)> = Vec::new();
    let mut start = None;
    for i in 0..phase.len() {
        match (phase[i].as_deref(), start) {
            (Some("flight"), None) if i > 0 && phase[i - 1].as_deref() == Some("stance") => {
                start = Some(i)
            }
            (Some("stance"), Some(a)) => {
                flights.push((a, i));
                start = None;
            }
            (Some("flight"), _) => {}
            _ => start = None,
        }
    }
    let mut figures = Vec::new();
    let mut locked = 0;
    for &(a, b) in &flights {
        let leg = |s: usize| {
            let edited = (a..b)
                .map(|i| e.knees[i][s])
                .fold(f64::NEG_INFINITY, f64::max);
            let source = (a..b)
                .map(|i| r.knees[src_frame(t_src[i])][s])
                .fold(f64::NEG_INFINITY, f64::max);
            [edited, source]
        };
        let legs = [leg(0), leg(1)];
        locked += legs.iter().filter(|l| l[0] < 10.0 && l[1] >= 10.0).count();
        figures.push(legs);
    }
    let n = e.hips.len();
    let rel: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            [
                e.hips[i][0] - com[i][0],
                e.hips[i][1] - com[i][1],
                e.hips[i][2] - com[i][2],
            ]
        })
        .collect();
    let src_spike = |i: usize| {
        let f = src_frame(t_src[i]);
        (f.saturating_sub(2).max(1)..=(f + 2).min(r.hips.len() - 2))
            .any(|k| accel(&r.hips, k, r.dt) > SPIKE_MPS2)
    };
    let spikes: Vec<usize> = (1..n - 1)
        .filter(|&i| accel(&e.hips, i, e.dt) > SPIKE_MPS2 && accel(&rel, i, e.dt) > SPIKE_MPS2)
        .filter(|&i| !src_spike(i))
        .collect();
    let max_e = (1..n - 1)
        .map(|i| accel(&e.hips, i, e.dt))
        .fold(0.0, f64::max);
    let max_r = (1..r.hips.len() - 1)
        .map(|i| accel(&r.hips, i, r.dt))
        .fold(0.0, f64::max);
    (figures, locked, spikes, max_e, max_r)
}

// See: issue 37 item 5 — "edit jump above the recorded height keeps bent knees in flight (no
// knee locked near 180° for the whole flight where the source bends it) and no root
// acceleration spike (none above 5 g between frames that the source does not have)".
// Before: a jump 1.2 × higher held both knees locked through its flight (the swing feet
// held at the recorded height above the floor while the body rose higher), and 1.1 ×
// straightened the knee from 27° to locked in one frame at the end of the push (17 g at
// the root). Now the feet follow the body in flight and the knee shares the last of the
// push with the heel (`edit::DEFAULT_JUMP_SWING_HOLD_S`, `DEFAULT_SOFT_REACH`). Measured
// from the written joints and the plan, not the editor's gauge. The fixture regenerated
// with issue 39's feet folded its knees from 6° to 70° in the first 0.1 s of the 1.2 ×
// flight (5.5 g at the root) with the run's 0.1 s hold; the jump's 0.2 s hold removes it.
#[test]
fn issue37_item5_edit_jump_higher_keeps_bent_knees_in_flight_and_no_root_spike() {
    let dir = tempfile::tempdir().unwrap();
    // (height scale, spike frames allowed): none, but for one known miss.
    let mut cases: Vec<(PathBuf, Vec<(f64, usize)>)> =
        vec![(fixture("jump_120hz_cmu_yup"), vec![(1.1, 0), (1.2, 0)])];
    if let Some(data) = shared_or_skip(
        "issue37_item5_edit_jump_higher_keeps_bent_knees_in_flight_and_no_root_spike",
    ) {
        // Known misses, both plans that put the COM farther from the contact than this body
        // reaches on its toe (exit 1, "out of reach"; the query's extension limit of 1.5 leg
        // lengths allows them): `cmu_01_01` 1.2 × higher, liftoff COM 1.142 m from the
        // contact, 5 push-off frames up to 5.7 cm off, 6 spike frames ≤ 12.2 g where the
        // pose meets its bounds; the vertical `cmu_02_04` 1.1 × higher (apex 1.45 m), the
        // landing's first 2 frames up to 2.0 cm off, 6 spike frames ≤ 11.9 g at the
        // liftoff and the landing (5 with the 0.1 s swing hold that the fixture jump's
        // higher flights did not bear).
        cases.push((
            data.join("bvh/jump/cmu_01_01_forward_jumps_mb.bvh"),
            vec![(1.1, 0), (1.2, 6)],
        ));
        cases.push((
            data.join("bvh/jump/cmu_13_32_forward_jump_daz.bvh"),
            vec![(1.1, 0)],
        ));
        cases.push((
            data.join("bvh/jump/cmu_02_04_vertical_jump_mb.bvh"),
            vec![(1.1, 6)],
        ));
    }
    for (n, (src, scales)) in cases.iter().enumerate() {
        let sub = dir.path().join(format!("j{n}"));
        let lib = library(&sub, std::slice::from_ref(src));
        for &(scale, allowed) in scales {
            let out = sub.join(format!("jump_{scale}.bvh"));
            let code = edit(&[
                "edit",
                "jump",
                "--lib",
                &s(&lib),
                "--height-scale",
                &scale.to_string(),
                "--allow-infeasible",
                "--out",
                &s(&out),
            ]);
            let (flights, locked, spikes, max_e, max_r) = jump_flight_and_spikes(&out, src, &sub);
            for f in &flights {
                eprintln!(
                    "{} × {scale} (exit {code}): flight knees left {:.1}° (source {:.1}°), right {:.1}° (source {:.1}°)",
                    src.display(), f[0][0], f[0][1], f[1][0], f[1][1]
                );
            }
            eprintln!(
                "{} × {scale}: root acceleration ≤ {:.1} g (source {:.1} g), {} spike frame(s) {spikes:?}, {locked} leg(s) locked",
                src.display(), max_e / G, max_r / G, spikes.len()
            );
            assert!(!flights.is_empty(), "a jump has a flight");
            assert_eq!(
                locked,
                0,
                "{}: a knee locked through the flight",
                src.display()
            );
            assert_spikes_within(&spikes, allowed, &format!("{} × {scale}", src.display()));
        }
    }
}

// See: issue 38 item 1 — "edit run does not say which cycle, the speed achieved, or whether
// it was feasible. With --allow-infeasible an infeasible edit exits 0 while one with frames
// that did not converge exits 1, so a script cannot tell an infeasible edit from a good
// one." Now every edit prints the cycle or pair used, what it achieves and its verdict with
// the deciding (or tightest) constraint's value, limit and margin; exit 0 feasible and
// faithful, 1 frames off the plan or posture outside the recording, 2 refused, 3 infeasible
// written anyway — the same for runs and jumps, and in `--help`.
#[test]
fn issue38_item1_edits_print_their_verdict_and_exit_by_it() {
    let dir = tempfile::tempdir().unwrap();
    let run = library(&dir.path().join("run"), &[fixture("run_120hz_m_yup")]);
    let jump = library(&dir.path().join("jump"), &[fixture("jump_120hz_cmu_yup")]);
    let out = |n: &str| s(&dir.path().join(n));
    let edit_run = |v: &str, extra: &[&str], name: &str| {
        let mut a = vec![
            "edit",
            "run",
            "--lib",
            run.to_str().unwrap(),
            "--speed",
            v,
            "--out",
        ];
        let o = out(name);
        a.push(&o);
        a.extend_from_slice(extra);
        super::util::stancelib(&a)
    };
    // 0: feasible, converged, posture as recorded.
    let (code, stdout, err) = edit_run("3", &[], "r3.bvh");
    eprintln!("edit run 3 m/s:\n{stdout}{err}");
    assert_eq!(code, 0, "{stdout}{err}");
    for needle in [
        "used run_120hz_m_yup:R:51 + run_120hz_m_yup:L:95",
        "speed 3.000 m/s",
        "contact ",
        "feasible; tightest ",
        "(margin ",
    ] {
        assert!(stdout.contains(needle), "{needle:?} in {stdout}");
    }
    // 2: infeasible, refused, with the deciding constraint's value, limit and margin.
    let (code, stdout, err) = edit_run("9", &[], "r9.bvh");
    eprintln!("edit run 9 m/s:\n{stdout}{err}");
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("infeasible request (run_120hz_m_yup:R:51") && err.contains("(by "),
        "{err}"
    );
    // 3: the same written with --allow-infeasible.
    let (code, _, err) = edit_run("9", &["--allow-infeasible"], "r9.bvh");
    assert_eq!(code, 3, "{err}");
    assert!(
        err.contains("infeasible, written anyway") && err.contains("(by "),
        "{err}"
    );
    // 1: feasible, but its posture leaves the recorded range (7.25 m/s, 2.1 × the recorded
    // speed: with its contacts moved back, the landing leg still straightens beyond the
    // source's least flexion less 10° on 2 frames; at 8 m/s the friction limit refuses it).
    let (code, _, err) = edit_run("7.25", &[], "r7.bvh");
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("knee flexion") && err.contains("outside"),
        "{err}"
    );
    // Jumps the same: 0 feasible, 3 infeasible written (relative limits: ±5 % of the
    // recorded stance), 2 refused.
    let edit_jump = |extra: &[&str], name: &str| {
        let o = out(name);
        let mut a = vec![
            "edit",
            "jump",
            "--lib",
            jump.to_str().unwrap(),
            "--height-scale",
            "1.2",
            "--out",
            &o,
        ];
        a.extend_from_slice(extra);
        super::util::stancelib(&a)
    };
    let (code, stdout, err) = edit_jump(&[], "j.bvh");
    eprintln!("edit jump × 1.2:\n{stdout}{err}");
    assert_eq!(code, 0, "{stdout}{err}");
    for needle in [
        "used jump_120hz_cmu_yup:LR:42 → jump_120hz_cmu_yup:LR:150",
        "apex 1.344 m",
        "feasible; tightest ",
    ] {
        assert!(stdout.contains(needle), "{needle:?} in {stdout}");
    }
    let (code, _, err) = edit_jump(&["--limits", "relative"], "jr.bvh");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("(by "), "{err}");
    let (code, _, err) = edit_jump(&["--limits", "relative", "--allow-infeasible"], "jr.bvh");
    assert_eq!(code, 3, "{err}");
    // Documented in --help.
    for cmd in [
        &["edit", "--help"][..],
        &["edit", "run", "--help"],
        &["edit", "jump", "--help"],
    ] {
        let help = ok(cmd);
        assert!(
            help.contains("Exit codes")
                && help.contains("3  infeasible, written with --allow-infeasible"),
            "{cmd:?}: {help}"
        );
    }
}

// See: the known bug "edit jump --height 1.35 / --height 1.4 on the demo jump leaves frames
// off the plan". Both now on the plan (the soft reach and the swing-foot hold,
// `edit::DEFAULT_SOFT_REACH`, `DEFAULT_JUMP_SWING_HOLD_S`, on the fixture regenerated with
// issue 39's feet; 1.42 m too). 1.5 m put push-off and landing frames up to 27.6 mm off with
// the knees straight, the heel up 50° and the pelvis at its 10° bound: the plan puts the
// COM farther from the contact than this body reaches. Now the jump limits stop at the
// body's reach (`query::limits::jump_limits`, `clips.parquet` `reach_m`), so the edit is
// refused up front (exit 2, nothing written) naming the extension and the reach; with
// `--allow-infeasible` it is written and says both (exit 3).
#[test]
fn demo_jump_at_1_4_m_converges_and_at_1_5_m_is_refused_beyond_its_reach() {
    let dir = tempfile::tempdir().unwrap();
    let lib = library(dir.path(), &[fixture("jump_120hz_cmu_yup")]);
    let reach = read_parquet(&lib.join("clips.parquet"))
        .unwrap()
        .column("reach_m")
        .unwrap()
        .f64()
        .unwrap()
        .get(0)
        .unwrap();
    let run = |h: &str, allow: bool| {
        let out = dir.path().join(format!("jump_{h}_{allow}.bvh"));
        let mut args = vec!["edit", "jump", "--lib", s(&lib).leak(), "--height", h];
        if allow {
            args.push("--allow-infeasible");
        }
        args.extend(["--out", s(&out).leak()]);
        let (code, _, err) = super::util::stancelib(&args);
        eprintln!("--height {h} (allow {allow}): exit {code}\n{err}");
        (code, err, out)
    };
    let (code, err, out) = run("1.4", false);
    assert_eq!(code, 0, "{err}");
    let off = plan_f64(&out, "foot_error_m")
        .into_iter()
        .fold(0.0, f64::max);
    assert!(off <= 1e-3, "{off} m");
    let (code, err, out) = run("1.5", false);
    assert_eq!(code, 2, "{err}");
    assert!(!out.exists(), "a refused edit writes nothing");
    let limit = format!("{reach:.3} m");
    assert!(
        err.contains("extension_max") && err.contains(&limit),
        "{limit}: {err}"
    );
    let (code, err, out) = run("1.5", true);
    assert_eq!(code, 3, "{err}");
    assert!(out.exists() && err.contains("extension_max"), "{err}");
}

/// The gait of a clip as `frames` re-detects it from the written motion, medians over its
/// foot contacts whose both events lie inside the clip: `[mean speed m/s, contact time s,
/// touchdown-to-touchdown period s, foot ahead of the COM at touchdown m (along the COM's
/// travel), knee flexion at touchdown deg, knee flexion at mid-stance deg, swing knee
/// flexion (98th percentile of both knees) deg, trunk lean deg, COM vertical range m]`.
/// `g` is the clip's [`gauged`], whose `frames` folder is `frames_dir`.
fn gait(g: &Gauged, frames_dir: &Path) -> [f64; 9] {
    let f = read_parquet(&frames_dir.join("frames.parquet")).unwrap();
    let c = read_parquet(&frames_dir.join("contacts.parquet")).unwrap();
    let col = |df: &polars::prelude::DataFrame, n: &str| -> Vec<f64> {
        df.column(n)
            .unwrap()
            .f64()
            .unwrap()
            .iter()
            .map(|v| v.unwrap_or(f64::NAN))
            .collect()
    };
    let t = col(&f, "time_clip_s");
    let com: Vec<[f64; 3]> = (0..t.len())
        .map(|i| {
            [
                col(&f, "com_x_m")[i],
                col(&f, "com_y_m")[i],
                col(&f, "com_z_m")[i],
            ]
        })
        .collect();
    let effector: Vec<String> = c
        .column("effector")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .map(|v| v.unwrap().to_string())
        .collect();
    let (td, lo) = (col(&c, "td_clip_s"), col(&c, "lo_clip_s"));
    let n = t.len();
    let frame = |time: f64| (((time - t[0]) / g.dt).round() as usize).min(n - 1);
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let inside: Vec<usize> = (0..td.len())
        .filter(|&k| {
            // A contact open at the clip's edge has no event there (null).
            effector[k].ends_with("_foot") && td[k] > t[0] + g.dt && lo[k] < t[n - 1] - g.dt
        })
        .collect();
    assert!(
        inside.len() >= 3,
        "{}: too few contacts",
        frames_dir.display()
    );
    let side = |k: usize| usize::from(effector[k].starts_with("right"));
    let ahead = |k: usize| {
        let i = frame(td[k]);
        let (a, b) = (com[i.saturating_sub(1)], com[(i + 1).min(n - 1)]);
        let h = [b[0] - a[0], b[1] - a[1]];
        let len = h[0].hypot(h[1]);
        let foot = col(&f, ["left_foot_x_m", "right_foot_x_m"][side(k)])[i];
        let foot_y = col(&f, ["left_foot_y_m", "right_foot_y_m"][side(k)])[i];
        ((foot - com[i][0]) * h[0] + (foot_y - com[i][1]) * h[1]) / len
    };
    let mut tds: Vec<f64> = inside.iter().map(|&k| td[k]).collect();
    tds.sort_by(f64::total_cmp);
    let mut knees: Vec<f64> = g.knees.iter().flatten().copied().collect();
    knees.sort_by(f64::total_cmp);
    let z = range(com.iter().map(|p| p[2]));
    [
        (com[n - 1][0] - com[0][0]).hypot(com[n - 1][1] - com[0][1]) / (t[n - 1] - t[0]),
        median(inside.iter().map(|&k| lo[k] - td[k]).collect()),
        median(tds.windows(2).map(|w| w[1] - w[0]).collect()),
        median(inside.iter().map(|&k| ahead(k)).collect()),
        median(
            inside
                .iter()
                .map(|&k| g.knees[frame(td[k])][side(k)])
                .collect(),
        ),
        median(
            inside
                .iter()
                .map(|&k| g.knees[frame(0.5 * (td[k] + lo[k]))][side(k)])
                .collect(),
        ),
        knees[(knees.len() as f64 * 0.98) as usize],
        median(g.lean.clone()),
        z[1] - z[0],
    ]
}

// See: the brief — "what it predicts (a run at another speed …, the edited motion) must
// match how the same person moves at that speed". One runner recorded at 2 and 3 m/s
// (`hamner_multi_run_2ms`, `_3ms`): each recording edited to the speed the other measures,
// re-read by `frames` from the written joints, against the other recording read the same
// way. Timing within the issue's 10 %; the touchdown distance within 20 % (the
// recordings' own strides spread 0.142–0.158 and 0.204–0.248 m); knees at touchdown and
// mid-stance within 10° and the trunk within 5° (`edit::fidelity`'s tolerances: one
// runner's spread between trials); the COM's vertical range within 15 %. The swing knee
// (98th percentile of the flexion) within 10° too: the edit folds it by the speed law of
// `edit::swing` (fitted across five runners; with this one left out it predicts +7.3° where
// the runner folds 14.4° more at 3 m/s than at 2). Measured (2 → 3 / 3 → 2 m/s): contact
// +6.4 / −1.3 %, period −5.4 / +4.1 %, touchdown distance +2.9 / +13.6 %, knee at
// touchdown −4.1 / +3.1°, mid-stance −1.6 / +3.8°, swing knee −5.7 / +7.5° (−15.5 / +15.9°
// when the edit replayed the recorded swing), lean −1.1 / +0.2°, COM range −12.2 / +8.2 %.
#[test]
fn edited_run_moves_like_the_same_runner_recorded_at_the_target_speed() {
    let Some(data) =
        shared_or_skip("edited_run_moves_like_the_same_runner_recorded_at_the_target_speed")
    else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let clip = |v: u32| data.join(format!("forceplate/hamner_multi_run_{v}ms/clip.bvh"));
    let names = [
        "speed m/s",
        "contact s",
        "period s",
        "touchdown ahead m",
        "knee at touchdown °",
        "knee mid-stance °",
        "swing knee °",
        "trunk lean °",
        "COM range m",
    ];
    // (relative bound, absolute bound in degrees) per figure.
    let bounds: [(f64, f64); 9] = [
        (0.01, 0.0),
        (0.10, 0.0),
        (0.10, 0.0),
        (0.20, 0.0),
        (0.0, KNEE_TOL_DEG),
        (0.0, KNEE_TOL_DEG),
        (0.0, KNEE_TOL_DEG),
        (0.0, LEAN_TOL_DEG),
        (0.15, 0.0),
    ];
    for (from, to) in [(2u32, 3u32), (3, 2)] {
        let sub = dir.path().join(format!("from{from}"));
        let folder = |p: &Path| {
            let stem = p.file_stem().unwrap().to_string_lossy();
            sub.join(format!("joints_{stem}"))
        };
        // The target recording under its own name, so its `frames` folder is its own; the
        // edit asks for the speed that recording measures (1.966 m/s for "2 m/s").
        let target = sub.join(format!("recorded_{to}.bvh"));
        std::fs::create_dir_all(&sub).unwrap();
        std::fs::copy(clip(to), &target).unwrap();
        let gr = gauged(&target, &sub);
        let r = gait(&gr, &folder(&target));
        let lib = library(&sub, &[clip(from)]);
        let out = sub.join(format!("edit_{from}to{to}.bvh"));
        let code = edit(&[
            "edit",
            "run",
            "--lib",
            &s(&lib),
            "--speed",
            &format!("{:.3}", r[0]),
            "--out",
            &s(&out),
        ]);
        assert_eq!(code, 0, "edit {from} → {:.3} m/s", r[0]);
        let ge = gauged(&out, &sub);
        let e = gait(&ge, &folder(&out));
        for (k, name) in names.iter().enumerate() {
            let (rel, diff) = (e[k] / r[k] - 1.0, e[k] - r[k]);
            eprintln!(
                "{from} → {to} m/s, {name}: edited {:.3}, recorded at {to} m/s {:.3} \
                 ({:+.1} %, {diff:+.2})",
                e[k],
                r[k],
                100.0 * rel,
            );
            match bounds[k] {
                (b, 0.0) => assert!(rel.abs() <= b, "{from} → {to}: {name} {rel:+.3}"),
                (_, deg) => assert!(diff.abs() <= deg, "{from} → {to}: {name} {diff:+.2}°"),
            }
        }
    }
}
