//! Issue 14, the checks that were still missed: a jump higher than recorded keeps its
//! contact times and converges on every frame (the foot turns about its toe tip when the
//! planned COM is beyond the leg's reach), and a real run's support foot holds still (the
//! capture's slide of a resting foot point is removed).

use super::edit_motion::{
    assert_bounds_except, cycle_of, edit, edit_cycle, first_cycle_against_source, first_jump,
    fixture, library, measure, read_plan, recorded_jump_against_source,
};
use super::util::{ok, refused, shared_or_skip};

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
            // (`stances::build`, 2026-12-03); 1.80° and 1.61 cm with the recording's COM
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
    let l = stancelib::library::read::open_library(&lib).unwrap();
    let timing =
        stancelib::library::read::read_stance_timing(&lib.join("stances.parquet")).unwrap();
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
    let l = stancelib::library::read::open_library(&lib).unwrap();
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
// distance within 2 cm (jumps)", on a real forward jump asked a new distance, and a new
// height and distance (the fixture jump is vertical: its distance is fixed). Measured
// 2026-12-06 (first measured then): at the recorded height, 0.9 / 1.0 / 1.1 × the
// recorded distance rebuild 1.8 / 1.5 / 1.2 cm short; 3 cm higher, 4.3 / 3.9 / 3.6 cm
// short (the code before that day's jump changes: 3.3 cm long at 1.1 ×). KNOWN MISS with a
// ceiling: the distance of a jump asked a new height too (issue 14 stays open;
// docs/edited-motion.md, "Known miss: a new height moves the rebuilt distance").
#[test]
fn a_real_forward_jump_at_a_new_height_and_distance_round_trips() {
    let Some(data) = shared_or_skip("a_real_forward_jump_at_a_new_height_and_distance_round_trips")
    else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let src = data.join("bvh/jump/cmu_13_32_forward_jump_daz.bvh");
    let lib = library(dir.path(), std::slice::from_ref(&src));
    let l = stancelib::library::read::open_library(&lib).unwrap();
    let (i, j) = first_jump(&l.stances).expect("a recorded jump");
    let (h0, d0) = stancelib::query::jump::recorded_jump(&l.stances[i], &l.stances[j]);
    let pair = format!("{}:{}", l.stances[i].stance_id, l.stances[j].stance_id);
    for (name, h, d, distance_ceiling) in [
        ("new distance", h0, 1.1 * d0, 0.02),
        ("new height and distance", h0 + 0.03, 1.1 * d0, 0.045),
    ] {
        let out = dir.path().join(format!("{}.bvh", name.replace(' ', "_")));
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
        assert_bounds_except(&measure(&out), &[]);
        let sub = dir.path().join(format!("rebuilt {name}"));
        let rl = library(&sub, std::slice::from_ref(&out));
        let r = stancelib::library::read::open_library(&rl).unwrap();
        let (a, b) = first_jump(&r.stances).expect("the rebuilt clip has a jump");
        let (hr, dr) = stancelib::query::jump::recorded_jump(&r.stances[a], &r.stances[b]);
        let status = if distance_ceiling > 0.02 {
            "KNOWN MISS"
        } else {
            "bound"
        };
        eprintln!(
            "{name}: apex {hr:.4} m (asked {h:.4}), distance {dr:.4} m (asked {d:.4}, {status} \
             {distance_ceiling})"
        );
        assert!((hr - h).abs() <= 0.02, "{name}: apex {hr} vs {h}");
        assert!(
            (dr - d).abs() <= distance_ceiling,
            "{name}: distance {dr} vs {d} ({status} {distance_ceiling})"
        );
    }
}
