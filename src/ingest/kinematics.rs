//! The numerical body of `ingest`: FK over the kept frames, unit and up axis, toe tips,
//! COM and its derivatives, floors, contacts and flights.

use super::contact_runs::{self, ContactRun};
use super::{ClipFrames, ClipSummary, IngestOptions};
use crate::bvh::Bvh;
use crate::contacts::detect::{clean, hysteresis, static_hysteresis, PointTrack};
use crate::contacts::flight::{clip_summary, curvature_inside, fit_run, Flight};
use crate::contacts::options::{STATIC_MIN_GAP_S, STATIC_MIN_ON_S};
use crate::contacts::support::{is_missed_support, speed_led, SpeedLedRule};
use crate::contacts::{floor, raw_speed, runs, EFFECTORS};
use crate::error::{echo, Error, Result};
use crate::math::savgol::{SavGol, DEFAULT_ORDER};
use crate::math::stats::median;
use crate::skeleton::com::{com, BodyPoints, SidePoints};
use crate::skeleton::landmarks::{leg_length, Landmarks, Limb, ToeTipRule};
use crate::skeleton::names::Side;
use crate::skeleton::units::{detect_unit, detect_up, NOMINAL_LEG_M};
use crate::skeleton::{fk, Skeleton};

/// Toe-tip fallback: distance ahead of the ankle per metre of leg (0.7·0.152·1.75/0.84).
pub const TTIP_FALLBACK_AHEAD: f64 = 0.2217;
/// Toe-tip fallback: distance below the ankle per metre of leg (0.07/0.84).
pub const TTIP_FALLBACK_BELOW: f64 = 0.0833;
/// A toe candidate is valid when its direction from the ankle has at least this cosine
/// with the facing direction (rest pose, or median over the motion).
pub const TTIP_MIN_FORWARD_COS: f64 = 0.5;

type V3 = [f64; 3];

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

/// Horizontal facing direction from the hips: normalize((HJC_L − HJC_R) × e_z); the zero
/// vector when the hips are vertically aligned.
pub fn facing(hip_l: V3, hip_r: V3) -> V3 {
    let d = sub(hip_l, hip_r);
    let f = [d[1], -d[0], 0.0];
    let n = norm(f);
    if n > 0.0 {
        f.map(|v| v / n)
    } else {
        [0.0; 3] // hips vertical: no facing (callers fall back, stance-model §2)
    }
}

/// FK over the kept frames into one flat array (frames × points), file units and axes.
pub(super) fn fk_frames(skel: &Skeleton, bvh: &Bvh, skip: usize) -> Vec<V3> {
    let np = skel.n_points();
    let n = bvh.motion.n_frames() - skip;
    let mut out = vec![[0.0; 3]; n * np];
    let mut ws = fk::FkWorkspace::new(skel);
    for (f, chunk) in out.chunks_exact_mut(np).enumerate() {
        fk::forward(skel, &mut ws, bvh.motion.row(skip + f), chunk);
    }
    out
}

/// The toe tip of one frame: the chosen point, or the fallback ahead of and below the
/// ankle (`fwd`: the hips' facing direction of the frame).
pub(super) fn toe_tip(p: Option<usize>, fp: &[V3], ankle: usize, fwd: V3, leg_m: f64) -> V3 {
    match p {
        Some(p) => fp[p],
        None => std::array::from_fn(|i| {
            fp[ankle][i] + TTIP_FALLBACK_AHEAD * leg_m * fwd[i]
                - if i == 2 {
                    TTIP_FALLBACK_BELOW * leg_m
                } else {
                    0.0
                }
        }),
    }
}

pub(super) fn choose_toe(
    lm: &Landmarks,
    s: Side,
    rest: &[V3],
    frames: &[&[V3]],
    fwd: &[V3],
) -> (ToeTipRule, Option<usize>) {
    let ankle = lm.limb(s).ankle;
    let rest_fwd = facing(rest[lm.left.hip], rest[lm.right.hip]);
    for (rule, p) in lm.toe_candidates(s) {
        let w = sub(rest[p], rest[ankle]);
        let rest_ok = norm(w) > 0.0 && dot(w, rest_fwd) >= TTIP_MIN_FORWARD_COS * norm(w);
        let cosines: Vec<f64> = frames
            .iter()
            .zip(fwd)
            .map(|(fp, fw)| {
                let w = sub(fp[p], fp[ankle]);
                let n = norm(w);
                if n > 0.0 {
                    dot(w, *fw) / n
                } else {
                    0.0
                }
            })
            .collect();
        if rest_ok || median(&cosines).is_some_and(|m| m >= TTIP_MIN_FORWARD_COS) {
            return (rule, Some(p));
        }
    }
    (ToeTipRule::Fallback, None)
}

pub(super) fn side_points(limb: &Limb, fp: &[V3], ttip: V3) -> SidePoints {
    SidePoints {
        hjc: fp[limb.hip],
        kjc: fp[limb.knee],
        ajc: fp[limb.ankle],
        ttip,
        arm: limb
            .arm
            .as_ref()
            .map(|a| [fp[a.shoulder], fp[a.elbow], fp[a.wrist], a.met3.at(fp)]),
    }
}

/// Run the numerical stages; fills the per-clip fields of `summary`.
pub(super) fn run(
    skel: &Skeleton,
    lm: &Landmarks,
    rest_file: &[V3],
    bvh: &Bvh,
    skip: usize,
    opts: &IngestOptions,
    summary: &mut ClipSummary,
) -> Result<(ClipFrames, Vec<ContactRun>)> {
    let dt = bvh.motion.frame_time_s;
    let legs = [
        [lm.left.hip, lm.left.knee, lm.left.ankle],
        [lm.right.hip, lm.right.knee, lm.right.ankle],
    ];
    for leg in legs {
        if !leg_length(rest_file, [leg, leg]).is_finite() {
            let names = leg.map(|p| echo(&skel.point_name(p)));
            return Err(Error::non_finite(
                "rest-pose leg length",
                None,
                Some(names.join("–")),
            ));
        }
    }
    let leg_file = leg_length(rest_file, legs);
    let (scale, unit_name) = match opts.unit_m {
        Some(u) => (u, "override".to_string()),
        None => {
            let (u, w) = detect_unit(leg_file);
            summary.warnings.extend(w);
            (u.scale, u.name)
        }
    };
    let mut pts = fk_frames(skel, bvh, skip);
    let np = skel.n_points();
    let n = pts.len() / np;
    let up = match opts.up_axis {
        Some(a) => a,
        None => {
            let head_above = |fp: &[V3]| {
                let mid: V3 =
                    std::array::from_fn(|i| 0.5 * (fp[lm.left.ankle][i] + fp[lm.right.ankle][i]));
                sub(fp[lm.head], mid)
            };
            let mut mean = [0.0; 3];
            for fp in pts.chunks_exact(np) {
                let v = head_above(fp);
                (0..3).for_each(|i| mean[i] += v[i] / n as f64);
            }
            let (a, w) = detect_up(mean, head_above(rest_file));
            summary.warnings.extend(w);
            a
        }
    };
    let to_int = |p: V3| up.to_internal(p).map(|v| v * scale);
    pts.iter_mut().for_each(|p| *p = to_int(*p));
    if let Some(k) = first_non_finite(&pts) {
        let (f, p) = (skip + k / np, k % np);
        return Err(Error::non_finite(
            "position",
            Some(f),
            Some(echo(&skel.point_name(p))),
        ));
    }
    let rest: Vec<V3> = rest_file.iter().map(|p| to_int(*p)).collect();
    let leg_m = leg_file * scale;
    if !leg_m.is_finite() {
        return Err(Error::non_finite(
            "rest-pose leg length in metres",
            None,
            None,
        ));
    }
    summary.unit_scale = Some(scale);
    summary.unit = Some(unit_name);
    summary.up_axis = Some(up.as_str().to_string());
    summary.leg_length_m = Some(leg_m);
    summary.character_id = Some(match &opts.character_id {
        Some(id) => id.clone(),
        None => character_id(skel, leg_m),
    });
    let frames: Vec<&[V3]> = pts.chunks_exact(np).collect();

    let fwd: Vec<V3> = frames
        .iter()
        .map(|fp| facing(fp[lm.left.hip], fp[lm.right.hip]))
        .collect();
    let mut toe: [Vec<V3>; 2] = Default::default();
    for (k, s) in [Side::L, Side::R].into_iter().enumerate() {
        let (rule, p) = choose_toe(lm, s, &rest, &frames, &fwd);
        summary.toe_tip_rule[k] = Some(rule.as_str().to_string());
        let ankle = lm.limb(s).ankle;
        toe[k] = (0..n)
            .map(|f| toe_tip(p, frames[f], ankle, fwd[f], leg_m))
            .collect();
    }
    if let Some(s) = summary.skeleton.as_mut() {
        s.push_str(&format!(
            ";TTIP_L={};TTIP_R={}",
            summary.toe_tip_rule[0].as_deref().unwrap_or("?"),
            summary.toe_tip_rule[1].as_deref().unwrap_or("?")
        ));
    }
    if lm.head_from_neck {
        summary.warnings.push(format!(
            "no head joint: head segment from the neck chain, {} towards {}, {:.4} × the leg length long (de Leva)",
            skel.point_name(lm.cerv),
            skel.point_name(lm.head),
            crate::skeleton::landmarks::HEAD_PER_LEG_LENGTH
        ));
    }
    for (tag, limb) in [("left", &lm.left), ("right", &lm.right)] {
        if limb.arm.is_none() {
            summary
                .warnings
                .push(format!("no {tag} arm: arm mass added to the trunk"));
        }
    }
    let com_pos: Vec<V3> = (0..n)
        .map(|f| {
            let fp = frames[f];
            let b = BodyPoints {
                vert: lm.vert.at(fp),
                cerv: fp[lm.cerv],
                left: side_points(&lm.left, fp, toe[0][f]),
                right: side_points(&lm.right, fp, toe[1][f]),
            };
            com(&b, opts.sex)
        })
        .collect();
    // With fallback toe tips on both feet "forward" comes from the hips, so the check
    // could not fail: it is not made (null).
    let fallback = |r: &Option<String>| r.as_deref() == Some(ToeTipRule::Fallback.as_str());
    summary.handedness_ok =
        (!summary.toe_tip_rule.iter().all(fallback)).then(|| handedness(&frames, lm, &toe));
    if summary.handedness_ok == Some(false) {
        summary.warnings.push(
            "handedness check failed: left/right labels swapped or the file is mirrored".into(),
        );
    }

    if let Some(f) = first_non_finite(&com_pos) {
        // Name the fallback toe tip when it is the culprit (it scales with the leg length).
        let joint = (0..2)
            .find(|&k| !toe[k][f].iter().all(|v| v.is_finite()))
            .map(|k| ["TTIP_L", "TTIP_R"][k].to_string());
        return Err(Error::non_finite("COM", Some(skip + f), joint));
    }
    let sg = SavGol::for_frame_time(dt, DEFAULT_ORDER)?;
    let deriv = |d: usize| -> Vec<V3> {
        let cols: [Vec<f64>; 3] = std::array::from_fn(|i| {
            sg.apply(&com_pos.iter().map(|c| c[i]).collect::<Vec<_>>(), d, dt)
        });
        (0..n)
            .map(|f| [cols[0][f], cols[1][f], cols[2][f]])
            .collect()
    };
    let com_v = deriv(1);
    let com_a = deriv(2);
    for (what, d) in [("COM velocity", &com_v), ("COM acceleration", &com_a)] {
        if let Some(f) = first_non_finite(d) {
            return Err(Error::non_finite(what, Some(skip + f), None));
        }
    }
    let frame: Vec<i64> = (0..n).map(|f| (skip + f) as i64).collect();
    let time_s: Vec<f64> = frame.iter().map(|&f| f as f64 * dt).collect();

    // Contacts (§7).
    let c = &opts.contacts;
    let half = floor::half_window(dt, c.floor_window_s);
    let zs = |v: &[V3]| v.iter().map(|p| p[2]).collect::<Vec<f64>>();
    let ground_z = floor::ground(&zs(&toe[0]), &zs(&toe[1]), half);
    let sc = leg_m / NOMINAL_LEG_M;
    let track_of = |p: &[V3], h: Vec<f64>| PointTrack {
        h,
        v: raw_speed(p, dt),
    };
    let ankle_pos = |s: Side| -> Vec<V3> { (0..n).map(|f| frames[f][lm.limb(s).ankle]).collect() };
    let mut effector_pos: [Option<Vec<V3>>; 4] = Default::default();
    let mut tracks: [Vec<PointTrack>; 4] = Default::default();
    let mut points: [Vec<Vec<V3>>; 4] = Default::default();
    for (k, s) in [Side::L, Side::R].into_iter().enumerate() {
        let a = ankle_pos(s);
        tracks[k] = vec![
            track_of(
                &a,
                floor::foot_heights(&zs(&a), &ground_z, half, floor::CLEARANCE_ANKLE, sc),
            ),
            track_of(
                &toe[k],
                floor::foot_heights(&zs(&toe[k]), &ground_z, half, floor::CLEARANCE_TTIP, sc),
            ),
        ];
        points[k] = vec![a.clone(), toe[k].clone()];
        effector_pos[k] = Some(a);
        if let Some(arm) = &lm.limb(s).arm {
            let wr: Vec<V3> = (0..n).map(|f| frames[f][arm.wrist]).collect();
            let m3: Vec<V3> = (0..n).map(|f| arm.met3.at(frames[f])).collect();
            if c.hands {
                tracks[2 + k] = vec![
                    track_of(
                        &wr,
                        floor::hand_heights(&zs(&wr), &ground_z, floor::CLEARANCE_WRIST, sc),
                    ),
                    track_of(
                        &m3,
                        floor::hand_heights(&zs(&m3), &ground_z, floor::CLEARANCE_MET3, sc),
                    ),
                ];
                points[2 + k] = vec![wr.clone(), m3];
            }
            effector_pos[2 + k] = Some(wr);
        }
    }
    let rate = 1.0 / dt;
    let mut contact: [Vec<bool>; 4] = Default::default();
    let mut stat: [Vec<bool>; 4] = Default::default();
    let mut surf: [Vec<Option<f64>>; 4] = Default::default();
    for e in 0..4 {
        if tracks[e].is_empty() {
            contact[e] = vec![false; n];
            stat[e] = vec![false; n];
            surf[e] = vec![None; n];
            continue;
        }
        let th = if e < 2 { &c.foot } else { &c.hand };
        let mut flags = hysteresis(&tracks[e], th);
        clean(&mut flags, rate, c.min_gap_s, c.min_on_s);
        if c.static_mode {
            let (mut sflags, trig) = static_hysteresis(&tracks[e]);
            clean(&mut sflags, rate, STATIC_MIN_GAP_S, STATIC_MIN_ON_S);
            surf[e] = vec![None; n];
            for (a, b) in runs(&sflags) {
                let p = trig[a].unwrap_or(0);
                let z: Vec<f64> = (a..=b).map(|f| points[e][p][f][2]).collect();
                let m = median(&z);
                surf[e][a..=b].iter_mut().for_each(|s| *s = m);
            }
            flags.iter_mut().zip(&sflags).for_each(|(f, s)| *f |= *s);
            clean(&mut flags, rate, c.min_gap_s, c.min_on_s);
            stat[e] = sflags;
        }
        contact[e] = flags;
    }

    // Physics cross-check (contacts::support): a non-ballistic no-contact interval is a
    // missed support, re-detected by the speed-led rule inside it.
    let vz: Vec<f64> = com_v.iter().map(|v| v[2]).collect();
    let mut speed_led_flags: [Vec<bool>; 4] = std::array::from_fn(|_| vec![false; n]);
    let collect_runs = |contact: &[Vec<bool>; 4], speed_led_flags: &[Vec<bool>; 4]| {
        let det = contact_runs::Detector {
            tracks: &tracks,
            speed_led: speed_led_flags,
        };
        contact_runs::collect(
            &det,
            contact,
            &stat,
            &surf,
            &points,
            &ground_z,
            &fwd,
            &frame,
            &time_s,
            dt,
            c.static_mode,
        )
    };
    // Flights (§7.7) of the no-contact runs, with the cross-check's curvature between the
    // sub-frame events that bound each run.
    let flights_of = |contact: &[Vec<bool>; 4], runs_out: &[ContactRun]| -> Vec<Flight> {
        let none: Vec<bool> = (0..n).map(|f| !contact.iter().any(|c| c[f])).collect();
        runs(&none)
            .into_iter()
            .filter(|&(a, b)| a > 0 && b + 1 < n)
            .map(|(a, b)| {
                let mut f = fit_run(&com_pos, &time_s, &vz, a, b, dt, skip as i64);
                let lo = runs_out
                    .iter()
                    .filter(|r| r.last_frame == frame[a - 1])
                    .filter_map(|r| r.lo_time_s)
                    .reduce(f64::max);
                let td = runs_out
                    .iter()
                    .filter(|r| r.first_frame == frame[b + 1])
                    .filter_map(|r| r.td_time_s)
                    .reduce(f64::min);
                if let (Some(lo), Some(td)) = (lo, td) {
                    f.a_z_all =
                        curvature_inside(&com_pos, &time_s, a, b, Some((lo, td))).or(f.a_z_all);
                    f.events_duration_s = Some(td - lo);
                    f.events_s = Some((lo, td));
                }
                f
            })
            .collect()
    };
    let mut runs_out = collect_runs(&contact, &speed_led_flags);
    if c.support_check {
        let rule = SpeedLedRule::default();
        let mut changed = false;
        for f in flights_of(&contact, &runs_out) {
            if !is_missed_support(&f) {
                continue;
            }
            let (a, b) = (
                (f.first_frame - skip as i64) as usize,
                (f.last_frame - skip as i64) as usize,
            );
            let mut found = Vec::new();
            for e in 0..4 {
                if tracks[e].is_empty() {
                    continue;
                }
                let sl = speed_led(&tracks[e], a, b, &rule, rate, c.min_gap_s);
                for (x, y) in runs(&sl) {
                    contact[e][a + x..=a + y].iter_mut().for_each(|v| *v = true);
                    speed_led_flags[e][a + x..=a + y]
                        .iter_mut()
                        .for_each(|v| *v = true);
                    found.push(format!(
                        "{} {}-{}",
                        EFFECTORS[e],
                        skip + a + x,
                        skip + a + y
                    ));
                    changed = true;
                }
            }
            if !found.is_empty() {
                summary.warnings.push(missed_support_warning(
                    &f,
                    &format!("speed-led contacts: {}", found.join(", ")),
                ));
            }
        }
        if changed {
            for flags in contact.iter_mut() {
                clean(flags, rate, c.min_gap_s, c.min_on_s);
            }
            runs_out = collect_runs(&contact, &speed_led_flags);
        }
    }
    summary.flights = flights_of(&contact, &runs_out);
    if c.support_check {
        for f in summary.flights.iter().filter(|f| is_missed_support(f)) {
            summary.warnings.push(missed_support_warning(
                f,
                "no support found (no foot or hand slow enough)",
            ));
        }
    }
    let (s_eff, az) = clip_summary(&summary.flights);
    summary.s_eff = s_eff;
    summary.flight_az_median = az;

    let joints = opts
        .joints
        .then(|| ((0..np).map(|p| skel.point_name(p)).collect(), pts.clone()));
    let frames = ClipFrames {
        frame,
        time_s,
        com: com_pos,
        com_v,
        com_a,
        ground_z,
        contact,
        static_contact: c.static_mode.then_some(stat),
        surface_z: c.static_mode.then_some(surf),
        effector_pos,
        toe,
        facing: fwd,
        joints,
    };
    Ok((frames, runs_out))
}

/// Index of the first point with a NaN or infinite coordinate.
fn first_non_finite(pts: &[V3]) -> Option<usize> {
    pts.iter().position(|p| !p.iter().all(|v| v.is_finite()))
}

/// `sk-` + the first 12 hex digits of SHA-256 over one `<name>\t<parent index>\n` line per
/// joint (file order, End Sites excluded, root parent −1) and `leg_mm=<round(1000·L_leg)>\n`
/// (spec stance-model §11).
pub fn character_id(skel: &Skeleton, leg_m: f64) -> String {
    use sha2::{Digest, Sha256};
    let mut text = String::new();
    for (name, parent) in skel.names.iter().zip(&skel.parents) {
        let p = parent.map_or(-1, |p| p as i64);
        text.push_str(&format!("{name}\t{p}\n"));
    }
    text.push_str(&format!("leg_mm={}\n", (1000.0 * leg_m).round() as i64));
    let digest = Sha256::digest(text.as_bytes());
    let hex: String = digest.iter().take(6).map(|b| format!("{b:02x}")).collect();
    format!("sk-{hex}")
}

/// `(hip_L − hip_R) · (e_z × forward) > 0`, forward = mean horizontal ankle→toe direction.
fn handedness(frames: &[&[V3]], lm: &Landmarks, toe: &[Vec<V3>; 2]) -> bool {
    let mut fw = [0.0; 3];
    let mut hip = [0.0; 3];
    for (f, fp) in frames.iter().enumerate() {
        for (k, limb) in [&lm.left, &lm.right].into_iter().enumerate() {
            let d = sub(toe[k][f], fp[limb.ankle]);
            fw[0] += d[0];
            fw[1] += d[1];
        }
        let h = sub(fp[lm.left.hip], fp[lm.right.hip]);
        (0..3).for_each(|i| hip[i] += h[i]);
    }
    let side = [-fw[1], fw[0], 0.0]; // e_z × forward
    dot(hip, side) > 0.0
}

/// The clip warning for a no-contact interval whose COM is not ballistic; `outcome` says
/// what the speed-led rule found.
fn missed_support_warning(f: &crate::contacts::flight::Flight, outcome: &str) -> String {
    format!(
        "missed support: no contact over frames {}-{} ({:.3} s) but the COM curves at {:+.2} m/s², not -g; {outcome}",
        f.first_frame,
        f.last_frame,
        f.events_duration_s.unwrap_or(f.duration_s),
        f.a_z_all.unwrap_or(f64::NAN),
    )
}
