//! The ingest of one clip as a sequence of stage calls: the clip's points (FK, unit, up
//! axis: [`super::points`]), toe tips, COM and its SG derivatives, then the contact stage
//! ([`crate::contacts`]: tracks, timeline, runs, flights).
//!
//! # Model
//! ```text
//! points (m, Z up) → facing, toe tips → COM (de Leva) → SG velocity, acceleration
//!   → contacts::tracks → contacts::detect → contacts::runs_and_flights → clip summary
//! ```
//!
//! # References
//! spec com-from-bvh §2–§8.

use super::knee_branch;
use super::points::{self, facing, first_non_finite, side_points, ClipPoints, ClipSource};
use super::{ClipFrames, ClipSummary, IngestOptions};
use crate::contacts::flight::clip_summary;
use crate::contacts::{self, ClipMotion, ContactRun, EffectorPoints};
use crate::error::{Error, Result};
use crate::math::savgol::{SavGol, DEFAULT_ORDER};
use crate::math::v3::{dot, sub, V3};
use crate::skeleton::com::{com, BodyPoints, Sex};
use crate::skeleton::landmarks::{Landmarks, ToeTipRule};
use crate::skeleton::names::Side;
use crate::skeleton::Skeleton;

/// Run the numerical stages on the kept frames (from row `src.skip`); fills the per-clip
/// fields of `summary`.
pub(super) fn run(
    src: &ClipSource,
    summary: &mut ClipSummary,
) -> Result<(ClipFrames, Vec<ContactRun>)> {
    let ClipSource {
        skel,
        lm,
        bvh,
        skip,
        opts,
        ..
    } = *src;
    let dt = bvh.motion.frame_time_s;
    let body = points::clip_points(src, &mut summary.warnings)?;
    record_body(summary, skel, &body, opts);
    let frames = body.frames();
    let fwd: Vec<V3> = frames
        .iter()
        .map(|fp| facing(fp[lm.left.hip], fp[lm.right.hip]))
        .collect();
    let toe = points::toe_tips(lm, &body, &frames, &fwd, summary);
    body_warnings(skel, lm, &mut summary.warnings);
    let knees = repaired_knees(lm, &frames, &toe, skip, &mut summary.warnings);
    let com_pos = com_track(lm, &frames, &toe, &knees, opts.sex);
    check_handedness(summary, &frames, lm, &toe);
    if let Some(f) = first_non_finite(&com_pos) {
        // Name the fallback toe tip when it is the culprit (it scales with the leg length).
        let joint = (0..2)
            .find(|&k| !toe[k][f].iter().all(|v| v.is_finite()))
            .map(|k| ["TTIP_L", "TTIP_R"][k].to_string());
        return Err(Error::non_finite("COM", Some(skip + f), joint));
    }
    summary.reach_m = clip_reach(lm, &frames, &toe, &com_pos, body.leg_m);
    let (com_v, com_a) = com_derivatives(&com_pos, dt, skip)?;
    let frame: Vec<i64> = (0..frames.len()).map(|f| (skip + f) as i64).collect();
    let time_s: Vec<f64> = frame.iter().map(|&f| f as f64 * dt).collect();

    // Contacts (§7), flights (§7.7) and the physics cross-check.
    let c = &opts.contacts;
    let fallback = |r: &Option<String>| r.as_deref() == Some(ToeTipRule::Fallback.as_str());
    let toe_estimated = [0, 1].map(|k| fallback(&summary.toe_tip_rule[k]));
    let effector = effector_points(lm, &frames, &toe, toe_estimated);
    let effector_pos = effector_positions(&effector);
    let tracks = contacts::tracks(effector, body.leg_m, dt, c);
    let mut timeline = contacts::detect(&tracks, c);
    let vz: Vec<f64> = com_v.iter().map(|v| v[2]).collect();
    let az: Vec<f64> = com_a.iter().map(|a| a[2]).collect();
    let vh: Vec<f64> = com_v.iter().map(|v| v[0].hypot(v[1])).collect();
    let motion = ClipMotion {
        frame: &frame,
        time_s: &time_s,
        dt,
        com: &com_pos,
        com_vz: &vz,
        com_speed_h: &vh,
        com_az: &az,
        facing: &fwd,
    };
    let events = contacts::runs_and_flights(&tracks, &mut timeline, &motion, c);
    summary.warnings.extend(events.warnings);
    summary.flights = events.flights;
    (summary.s_eff, summary.flight_az_median) = clip_summary(&summary.flights);

    let joints = opts.joints.then(|| {
        let names = (0..body.np).map(|p| skel.point_name(p)).collect();
        (names, body.pts.clone())
    });
    let frames = ClipFrames {
        frame,
        time_s,
        com: com_pos,
        com_v,
        com_a,
        ground_z: tracks.ground_z,
        contact: timeline.contact,
        static_contact: c.static_mode.then_some(timeline.static_contact),
        surface_z: c.static_mode.then_some(timeline.surface_z),
        effector_pos,
        toe,
        facing: fwd,
        joints,
    };
    Ok((frames, events.runs))
}

/// The body's reach from its COM ([`super::reach::body_reach_m`]), m.
fn clip_reach(
    lm: &Landmarks,
    frames: &[&[V3]],
    toe: &[Vec<V3>; 2],
    com: &[V3],
    leg_m: f64,
) -> Option<f64> {
    let pair =
        |l: usize, r: usize| -> Vec<[V3; 2]> { frames.iter().map(|fp| [fp[l], fp[r]]).collect() };
    let toes: Vec<[V3; 2]> = (0..frames.len()).map(|f| [toe[0][f], toe[1][f]]).collect();
    super::reach::body_reach_m(
        com,
        &pair(lm.left.hip, lm.right.hip),
        &pair(lm.left.ankle, lm.right.ankle),
        &toes,
        leg_m,
    )
}

/// The per-clip fields of the body: unit, up axis, leg length and character id.
fn record_body(
    summary: &mut ClipSummary,
    skel: &Skeleton,
    body: &ClipPoints,
    opts: &IngestOptions,
) {
    summary.unit_scale = Some(body.scale);
    summary.unit = Some(body.unit.clone());
    summary.up_axis = Some(body.up.as_str().to_string());
    summary.leg_length_m = Some(body.leg_m);
    summary.character_id = Some(match &opts.character_id {
        Some(id) => id.clone(),
        None => character_id(skel, body.leg_m),
    });
}

/// Advisories on how the body was modelled: a head from the neck chain, missing arms.
fn body_warnings(skel: &Skeleton, lm: &Landmarks, warnings: &mut Vec<String>) {
    if lm.head_from_neck {
        warnings.push(format!(
            "no head joint: head segment from the neck chain, {} towards {}, {:.4} × the leg length long (de Leva)",
            skel.point_name(lm.cerv),
            skel.point_name(lm.head),
            crate::skeleton::landmarks::HEAD_PER_LEG_LENGTH
        ));
    }
    for (tag, limb) in [("left", &lm.left), ("right", &lm.right)] {
        if limb.arm.is_none() {
            warnings.push(format!("no {tag} arm: arm mass added to the trunk"));
        }
    }
}

/// Each leg's knee per frame with its two-bone branch jumps mirrored back
/// ([`knee_branch::repair`]); a warning names the leg and how many frames moved.
fn repaired_knees(
    lm: &Landmarks,
    frames: &[&[V3]],
    toe: &[Vec<V3>; 2],
    skip: usize,
    warnings: &mut Vec<String>,
) -> [Vec<V3>; 2] {
    let limbs = [&lm.left, &lm.right];
    std::array::from_fn(|k| {
        let at = |j: usize| -> Vec<V3> { frames.iter().map(|fp| fp[j]).collect() };
        let l = limbs[k];
        let (knee, changed) = knee_branch::repair(&at(l.hip), &at(l.knee), &at(l.ankle), &toe[k]);
        if let (Some(first), Some(last)) = (changed.first(), changed.last()) {
            warnings.push(format!(
                "{} knee: {} frame(s) in frames {}-{} mirrored back across the hip-ankle line \
                 for the COM (two-bone IK branch jumps)",
                ["left", "right"][k],
                changed.len(),
                skip + first,
                skip + last
            ));
        }
        knee
    })
}

/// The whole-body COM per frame (de Leva, spec com-from-bvh §5), with the knees given
/// (the file's, or [`repaired_knees`]).
fn com_track(
    lm: &Landmarks,
    frames: &[&[V3]],
    toe: &[Vec<V3>; 2],
    knees: &[Vec<V3>; 2],
    sex: Sex,
) -> Vec<V3> {
    (0..frames.len())
        .map(|f| {
            let fp = frames[f];
            let mut left = side_points(&lm.left, fp, toe[0][f]);
            let mut right = side_points(&lm.right, fp, toe[1][f]);
            (left.kjc, right.kjc) = (knees[0][f], knees[1][f]);
            let b = BodyPoints {
                vert: lm.vert.at(fp),
                cerv: fp[lm.cerv],
                left,
                right,
            };
            com(&b, sex)
        })
        .collect()
}

/// The handedness check (§4), with a warning when it fails. With fallback toe tips on both
/// feet "forward" comes from the hips, so the check could not fail: it is not made (null).
fn check_handedness(
    summary: &mut ClipSummary,
    frames: &[&[V3]],
    lm: &Landmarks,
    toe: &[Vec<V3>; 2],
) {
    let fallback = |r: &Option<String>| r.as_deref() == Some(ToeTipRule::Fallback.as_str());
    summary.handedness_ok =
        (!summary.toe_tip_rule.iter().all(fallback)).then(|| handedness(frames, lm, toe));
    if summary.handedness_ok == Some(false) {
        summary.warnings.push(
            "handedness check failed: left/right labels swapped or the file is mirrored".into(),
        );
    }
}

/// SG velocity and acceleration of the COM (§6).
///
/// # Errors
/// No SG filter for `dt` (`ErrorKind::Smoothing`); a non-finite derivative
/// (`ErrorKind::NonFinite`, naming the first bad file row).
fn com_derivatives(com_pos: &[V3], dt: f64, skip: usize) -> Result<(Vec<V3>, Vec<V3>)> {
    let sg = SavGol::for_frame_time(dt, DEFAULT_ORDER)?;
    let deriv = |d: usize| -> Vec<V3> {
        let cols: [Vec<f64>; 3] = std::array::from_fn(|i| {
            sg.apply(&com_pos.iter().map(|c| c[i]).collect::<Vec<_>>(), d, dt)
        });
        (0..com_pos.len())
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
    Ok((com_v, com_a))
}

/// The contact points of every effector: ankle and toe tip per foot; wrist and MET3 per
/// hand with an arm.
fn effector_points(
    lm: &Landmarks,
    frames: &[&[V3]],
    toe: &[Vec<V3>; 2],
    toe_estimated: [bool; 2],
) -> EffectorPoints {
    let track = |p: &dyn Fn(&[V3]) -> V3| -> Vec<V3> { frames.iter().map(|fp| p(fp)).collect() };
    let foot = |k: usize, s: Side| [track(&|fp| fp[lm.limb(s).ankle]), toe[k].clone()];
    let hand = |s: Side| {
        lm.limb(s)
            .arm
            .as_ref()
            .map(|arm| [track(&|fp| fp[arm.wrist]), track(&|fp| arm.met3.at(fp))])
    };
    EffectorPoints {
        feet: [foot(0, Side::L), foot(1, Side::R)],
        hands: [hand(Side::L), hand(Side::R)],
        toe_estimated,
    }
}

/// Ankle centre per foot and wrist centre per hand with an arm (`ClipFrames::effector_pos`).
fn effector_positions(p: &EffectorPoints) -> [Option<Vec<V3>>; 4] {
    [
        Some(p.feet[0][0].clone()),
        Some(p.feet[1][0].clone()),
        p.hands[0].as_ref().map(|h| h[0].clone()),
        p.hands[1].as_ref().map(|h| h[0].clone()),
    ]
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
