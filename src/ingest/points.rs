//! A clip's points in metres, Z up: FK over the kept frames, the unit and up axis, the
//! hips' facing direction and the toe tips (spec com-from-bvh §2–§4). Shared by the ingest
//! ([`super::clip`]) and the frozen body model ([`super::body`]).
//!
//! # Model
//! ```text
//! L_leg(file) = mean over sides of |HJC−KJC| + |KJC−AJC| (rest pose)
//! unit        = override, or detect_unit(L_leg(file))
//! up          = override, or detect_up(mean over frames of head − mid-ankle, rest pose)
//! point       = unit · up(FK(q))                         metres, internal Z up
//! facing      = normalize((HJC_L − HJC_R) × e_z)         zero when the hips are vertical
//! toe tip     = first valid candidate (rest pose or median cosine ≥ 0.5 with facing),
//!               else AJC + 0.2217·L_leg·facing − 0.0833·L_leg·e_z
//! ```

use super::{ClipSummary, IngestOptions};
use crate::bvh::Bvh;
use crate::error::{echo, Error, Result};
use crate::math::stats::median;
use crate::math::v3::{dot, norm, sub, V3};
use crate::skeleton::com::SidePoints;
use crate::skeleton::landmarks::{leg_length, Landmarks, Limb, ToeTipRule};
use crate::skeleton::names::Side;
use crate::skeleton::units::{detect_unit, detect_up, UpAxis};
use crate::skeleton::{fk, Skeleton};

/// Toe-tip fallback: distance ahead of the ankle per metre of leg (0.7·0.152·1.75/0.84).
pub const TTIP_FALLBACK_AHEAD: f64 = 0.2217;
/// Toe-tip fallback: distance below the ankle per metre of leg (0.07/0.84).
pub const TTIP_FALLBACK_BELOW: f64 = 0.0833;
/// A toe candidate is valid when its direction from the ankle has at least this cosine
/// with the facing direction (rest pose, or median over the motion).
pub const TTIP_MIN_FORWARD_COS: f64 = 0.5;

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

/// FK over the kept frames into one flat array (frames × points), file units and axes
/// ([`fk::forward_frames`]: several frames per SIMD batch).
pub(super) fn fk_frames(skel: &Skeleton, bvh: &Bvh, skip: usize) -> Vec<V3> {
    let np = skel.n_points();
    let n = bvh.motion.n_frames() - skip;
    let mut out = vec![[0.0; 3]; n * np];
    let mut ws = fk::FkWorkspace::new(skel);
    let nc = bvh.motion.n_channels;
    fk::forward_frames(skel, &mut ws, &bvh.motion.values[skip * nc..], &mut out);
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

/// One parsed clip as the ingest stages see it: skeleton, landmarks, rest pose (file units
/// and axes), the kept frames (from row `skip`) and the options.
pub(super) struct ClipSource<'a> {
    pub skel: &'a Skeleton,
    pub lm: &'a Landmarks,
    pub rest_file: &'a [V3],
    pub bvh: &'a Bvh,
    pub skip: usize,
    pub opts: &'a IngestOptions,
}

/// A clip's kept frames in metres, internal Z-up frame, and what scaled them.
pub(super) struct ClipPoints {
    /// Frames × points, m.
    pub pts: Vec<V3>,
    /// Points per frame.
    pub np: usize,
    /// Rest pose, m.
    pub rest: Vec<V3>,
    /// Leg length, m.
    pub leg_m: f64,
    /// Metres per file unit.
    pub scale: f64,
    /// Unit name, or `override`.
    pub unit: String,
    /// The file's up axis.
    pub up: UpAxis,
}

impl ClipPoints {
    /// One slice of points per kept frame.
    pub fn frames(&self) -> Vec<&[V3]> {
        self.pts.chunks_exact(self.np).collect()
    }
}

/// Leg length of the rest pose, file units; each leg must have a finite length.
fn rest_leg_length(skel: &Skeleton, lm: &Landmarks, rest_file: &[V3]) -> Result<f64> {
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
    Ok(leg_length(rest_file, legs))
}

/// The file's up axis: the override, or from the mean head-above-ankles direction over the
/// frames (`pts`, file units and axes) and in the rest pose.
fn up_axis(
    lm: &Landmarks,
    pts: &[V3],
    np: usize,
    rest_file: &[V3],
    opts: &IngestOptions,
    warnings: &mut Vec<String>,
) -> UpAxis {
    if let Some(a) = opts.up_axis {
        return a;
    }
    let n = pts.len() / np;
    let head_above = |fp: &[V3]| {
        let mid: V3 = std::array::from_fn(|i| 0.5 * (fp[lm.left.ankle][i] + fp[lm.right.ankle][i]));
        sub(fp[lm.head], mid)
    };
    let mut mean = [0.0; 3];
    for fp in pts.chunks_exact(np) {
        let v = head_above(fp);
        (0..3).for_each(|i| mean[i] += v[i] / n as f64);
    }
    let (a, w) = detect_up(mean, head_above(rest_file));
    warnings.extend(w);
    a
}

/// FK over the kept frames (from row `src.skip`), in metres and the internal Z-up frame, with
/// the unit and up axis (overrides, or detected; detection warnings go to `warnings`).
///
/// # Errors
/// A non-finite rest-pose leg length, position or leg length in metres
/// (`ErrorKind::NonFinite`, naming the first bad frame and joint).
pub(super) fn clip_points(src: &ClipSource, warnings: &mut Vec<String>) -> Result<ClipPoints> {
    let ClipSource {
        skel,
        lm,
        rest_file,
        bvh,
        skip,
        opts,
    } = *src;
    let leg_file = rest_leg_length(skel, lm, rest_file)?;
    let (scale, unit) = match opts.unit_m {
        Some(u) => (u, "override".to_string()),
        None => {
            let (u, w) = detect_unit(leg_file);
            warnings.extend(w);
            (u.scale, u.name)
        }
    };
    let mut pts = fk_frames(skel, bvh, skip);
    let np = skel.n_points();
    let up = up_axis(lm, &pts, np, rest_file, opts, warnings);
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
    Ok(ClipPoints {
        pts,
        np,
        rest,
        leg_m,
        scale,
        unit,
        up,
    })
}

/// The toe tip of both feet on every frame; records each side's rule in `summary`
/// (`toe_tip_rule`, and `;TTIP_L=…;TTIP_R=…` after the skeleton mapping).
pub(super) fn toe_tips(
    lm: &Landmarks,
    body: &ClipPoints,
    frames: &[&[V3]],
    fwd: &[V3],
    summary: &mut ClipSummary,
) -> [Vec<V3>; 2] {
    let mut toe: [Vec<V3>; 2] = Default::default();
    for (k, s) in [Side::L, Side::R].into_iter().enumerate() {
        let (rule, p) = choose_toe(lm, s, &body.rest, frames, fwd);
        summary.toe_tip_rule[k] = Some(rule.as_str().to_string());
        let ankle = lm.limb(s).ankle;
        toe[k] = (0..frames.len())
            .map(|f| toe_tip(p, frames[f], ankle, fwd[f], body.leg_m))
            .collect();
    }
    if let Some(s) = summary.skeleton.as_mut() {
        s.push_str(&format!(
            ";TTIP_L={};TTIP_R={}",
            summary.toe_tip_rule[0].as_deref().unwrap_or("?"),
            summary.toe_tip_rule[1].as_deref().unwrap_or("?")
        ));
    }
    toe
}

/// Index of the first point with a NaN or infinite coordinate.
pub(super) fn first_non_finite(pts: &[V3]) -> Option<usize> {
    pts.iter().position(|p| !p.iter().all(|v| v.is_finite()))
}
