use super::*;

/// Independent re-read of the text: FK of every row in file axes, mapped back to
/// internal metres.
fn reread(bvh: &str, up: SynthUp, unit: f64) -> Vec<Kin> {
    let (head, motion) = bvh.split_once("MOTION").unwrap();
    let toks: Vec<&str> = head.split_whitespace().collect();
    let num = |s: &str| s.parse::<f64>().unwrap();
    let at = |i: usize| V3::new(num(toks[i + 1]), num(toks[i + 2]), num(toks[i + 3]));
    let mut seq = (0..toks.len()).filter(|&i| toks[i] == "OFFSET").map(at);
    let (mut offs, mut ends) = ([V3::zeros(); N], [V3::zeros(); N]);
    for j in 0..N {
        offs[j] = seq.next().unwrap();
        if SKELETON[j].3.is_some() {
            ends[j] = seq.next().unwrap();
        }
    }
    let back = file_from_internal(up).transpose() * unit;
    let rows = motion
        .lines()
        .skip(3)
        .map(|l| l.split_whitespace().map(num).collect());
    let kin = |r: Vec<f64>| {
        let local = std::array::from_fn(|j| rot_zyx(r[3 * j + 3], r[3 * j + 4], r[3 * j + 5]));
        let k = forward(&offs, &ends, V3::new(r[0], r[1], r[2]), &local);
        Kin {
            pos: k.pos.map(|p| back * p),
            end: k.end.map(|p| back * p),
        }
    };
    rows.map(kin).collect()
}

fn cases() -> Vec<SynthOptions> {
    let mut v = vec![];
    for motion in [SynthMotion::Run, SynthMotion::Jump] {
        for (frame_rate_hz, up, unit_m, seed) in [
            (120.0, SynthUp::Y, 1.0, 1),
            (60.0, SynthUp::Z, 0.01, 7),
            (100.0, SynthUp::Y, 0.0254, 3),
            (30.0, SynthUp::Y, 0.056444, 11),
            (240.0, SynthUp::Z, 1.0, 42),
        ] {
            v.push(SynthOptions {
                motion,
                frame_rate_hz,
                duration_s: 2.5,
                unit_m,
                up,
                seed,
                platform_m: 0.0,
            });
        }
    }
    v
}

#[test]
fn rows_have_one_value_per_channel() {
    for o in cases() {
        let clip = generate(&o);
        let n = clip.com.len();
        assert_eq!(clip.bvh.matches("CHANNELS 3 ").count(), N - 1);
        assert!(clip.bvh.contains(&format!("Frames: {n}\n")));
        let rows: Vec<_> = clip
            .bvh
            .lines()
            .skip_while(|l| !l.starts_with("Frame Time"))
            .collect();
        assert_eq!(rows.len(), n + 1);
        assert!(rows[1..]
            .iter()
            .all(|r| r.split_whitespace().count() == 6 + 3 * (N - 1)));
        let lens = [
            clip.contact_left.len(),
            clip.contact_right.len(),
            clip.force_n_per_kg.len(),
        ];
        assert_eq!(lens, [n; 3]);
    }
}

#[test]
fn com_of_the_written_file_is_the_truth() {
    for o in cases() {
        let (clip, [ratio, residual]) = build(&o);
        // Solved to 1e-12 m; 1e-9 leaves room for round-off.
        assert!(residual < 1e-9, "{o:?}: residual {residual}");
        // IK reaches every target below 1.0; 1 % margin keeps the knee well defined.
        assert!(ratio < 0.99, "{o:?}: leg extension {ratio}");
        // Nine printed decimals (file units, degrees) move points by < 1e-8 m.
        for (k, kin) in reread(&clip.bvh, o.up, o.unit_m).iter().enumerate() {
            let err = (de_leva_com(kin) - V3::from(clip.com[k])).norm();
            assert!(err < 1e-7, "{o:?} frame {k}: {err}");
        }
    }
}

#[test]
fn flights_are_exactly_ballistic_and_stances_push() {
    for o in cases() {
        let clip = generate(&o);
        let (dt, mut count) = (1.0 / o.frame_rate_hz, 0);
        assert!(
            clip.force_n_per_kg.iter().all(|f| f[2] >= 0.0),
            "{o:?}: pulling force"
        );
        for k in 1..clip.com.len() - 1 {
            if clip.contact_left[k] || clip.contact_right[k] {
                continue;
            }
            let [a, b, c] = [k - 1, k, k + 1].map(|i| V3::from(clip.com[i]));
            let acc = (a - 2.0 * b + c) / (dt * dt);
            // Closed-form parabola: only round-off (~1e-15 m / dt²) remains.
            assert!(
                (acc + V3::z() * G).norm() < 1e-6,
                "{o:?} frame {k}: {acc:?}"
            );
            assert_eq!(clip.force_n_per_kg[k], [0.0; 3]);
            count += 1;
        }
        assert!(count >= 4, "{o:?}: {count} flight frames");
    }
}

/// (height above its floor, central-difference speed) of ankle and toe tip at `k`.
fn gates(pts: &[Vec<V3>; 2], k: usize, rate: f64) -> [(f64, f64); 2] {
    let (lo, hi) = (k.saturating_sub(1), (k + 1).min(pts[0].len() - 1));
    [(0, ANKLE_Z), (1, 0.0)].map(|(p, floor)| {
        let v = (pts[p][hi] - pts[p][lo]).norm() * rate / (hi - lo) as f64;
        (pts[p][k].z - floor, v)
    })
}

#[test]
fn feet_follow_the_contact_detector_rules() {
    for o in cases() {
        let clip = generate(&o);
        let kins = reread(&clip.bvh, o.up, o.unit_m);
        for (side, truth) in [(0, &clip.contact_left), (1, &clip.contact_right)] {
            let (ajc, toe) = (LEGS[side][2], LEGS[side][3]);
            let pts = [
                kins.iter().map(|k| k.pos[ajc]).collect(),
                kins.iter().map(|k| k.end[toe]).collect(),
            ];
            for k in 0..kins.len() {
                let g = gates(&pts, k, o.frame_rate_hz);
                let msg = format!("{o:?} side {side} frame {k}: {g:?}");
                if !truth[k] {
                    // Swing: every point above 6 cm or faster than 2 m/s (with margin).
                    assert!(g.iter().all(|&(h, v)| h > 0.065 || v > 2.05), "{msg}");
                    continue;
                }
                // Planted: on its footprint, flat, at most the sole's give above the
                // floor, inside the enter gate (with margin).
                let first = (0..=k).rev().take_while(|&i| truth[i]).last().unwrap_or(k);
                let d = pts[0][k] - pts[0][first];
                assert!(d.x.hypot(d.y) < 1e-7, "{msg}");
                assert!((pts[0][k].z - pts[1][k].z - ANKLE_Z).abs() < 1e-7, "{msg}");
                assert!((-1e-7..=SOLE_GIVE_M + 1e-7).contains(&g[1].0), "{msg}");
                assert!(g.iter().any(|&(h, v)| h <= 0.04 && v <= 1.95), "{msg}");
            }
        }
    }
}

/// The sub-frame event test of spec com-from-bvh §7.3 (`contacts::timing`) of a foot
/// at frame `k`: `min_p max(h_p/H, v_p/V)`.
fn event_test(pts: &[Vec<V3>; 2], k: usize, rate: f64, v_event: f64) -> f64 {
    use crate::contacts::timing::EVENT_H_M;
    gates(pts, k, rate)
        .iter()
        .map(|&(h, v)| (h / EVENT_H_M).max(v / v_event))
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn contact_edges_are_where_the_event_test_is_met() {
    use crate::contacts::timing::{EVENT_LO_V_MPS, EVENT_TD_V_MPS};
    for o in cases() {
        let clip = generate(&o);
        let kins = reread(&clip.bvh, o.up, o.unit_m);
        let n = kins.len();
        for (side, truth) in [(0, &clip.contact_left), (1, &clip.contact_right)] {
            let (ajc, toe) = (LEGS[side][2], LEGS[side][3]);
            let pts = [
                kins.iter().map(|k| k.pos[ajc]).collect(),
                kins.iter().map(|k| k.end[toe]).collect(),
            ];
            let r = |k: usize, v: f64| event_test(&pts, k, o.frame_rate_hz, v);
            for (a, b) in crate::contacts::runs(truth) {
                // The first and last force frames meet the test exactly (the give's
                // 3 cm; 1e-6: the nine printed decimals), the frames outside do not.
                if a > 0 {
                    let (out, at) = (r(a - 1, EVENT_TD_V_MPS), r(a, EVENT_TD_V_MPS));
                    let msg = format!("{o:?} side {side} touchdown {a}: {out} {at}");
                    assert!(out > 1.05 && (at - 1.0).abs() < 1e-6, "{msg}");
                }
                if b + 1 < n {
                    let (at, out) = (r(b, EVENT_LO_V_MPS), r(b + 1, EVENT_LO_V_MPS));
                    let msg = format!("{o:?} side {side} liftoff {b}: {at} {out}");
                    assert!(out > 1.05 && (at - 1.0).abs() < 1e-6, "{msg}");
                }
            }
        }
    }
}

#[test]
fn run_is_periodic_at_the_mean_speed() {
    let tl = run_timeline(1.0 / 120.0, 400);
    let stride = 2 * tl.period;
    let (c0, c1) = (tl.com(0).0, tl.com(stride).0);
    let v = |k: i64| tl.com(k + 1).0 - tl.com(k).0;
    assert!((c1.z - c0.z).abs() < 1e-12 && (c1.y - c0.y).abs() < 1e-12);
    assert!((v(stride) - v(0)).norm() < 1e-12, "velocity not periodic");
    assert!(((c1.x - c0.x) * 120.0 / stride as f64 - RUN_SPEED).abs() < 1e-12);
    // 2.5 s at 120 Hz asks for 300 frames; the nearest apex or mid-stance is k = 308.
    let o = SynthOptions {
        duration_s: 2.5,
        ..Default::default()
    };
    assert_eq!(generate(&o).com.len(), 309);
}

#[test]
fn any_options_give_a_clip() {
    let bad = [
        (f64::NAN, f64::INFINITY, -1.0),
        (0.0, -3.0, 0.0),
        (1e9, 0.05, 1e12),
    ];
    for (frame_rate_hz, duration_s, unit_m) in bad.into_iter().chain([(24.0, 0.19, 0.3048)]) {
        for motion in [SynthMotion::Run, SynthMotion::Jump] {
            let o = SynthOptions {
                motion,
                frame_rate_hz,
                duration_s,
                unit_m,
                ..Default::default()
            };
            let clip = generate(&o);
            assert!(!clip.com.is_empty() && clip.com.iter().flatten().all(|x| x.is_finite()));
            assert!(!clip.bvh.contains("NaN") && !clip.bvh.contains("inf"));
        }
    }
}

#[test]
fn euler_zyx_round_trips() {
    for (z, y, x) in [
        (10.0, 20.0, 30.0),
        (-170.0, 89.9, 5.0),
        (0.0, -90.0, 0.0),
        (120.0, -45.0, 179.0),
    ] {
        let r = rot_zyx(z, y, x);
        let [a, b, c] = zyx_deg(&r);
        assert!((rot_zyx(a, b, c) - r).norm() < 1e-12);
    }
}

#[test]
fn rest_pose_matches_the_brief() {
    let (offs, ends) = skeleton_offsets();
    let k = forward(&offs, &ends, V3::new(0.0, 0.0, 0.99), &[M3::identity(); N]);
    let [hip, knee, ankle, _] = LEGS[0].map(|j| k.pos[j]);
    assert!(((knee - hip).norm() + (ankle - knee).norm() - 0.84).abs() < 1e-12);
    let tip = k.end[LEGS[0][3]] - ankle;
    assert!((tip.x - 0.19).abs() < 1e-12 && (tip.z + ANKLE_Z).abs() < 1e-12);
    assert!((k.end[HEAD].z - 1.75).abs() < 1e-12 && (hip.y - HIP_Y).abs() < 1e-12);
    // de Leva: a standing male's COM is at 0.54–0.59 of stature.
    let c = de_leva_com(&k);
    assert!(
        c.z > 0.54 * 1.75 && c.z < 0.59 * 1.75 && c.y.abs() < 1e-12,
        "{c:?}"
    );
}
