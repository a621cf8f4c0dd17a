//! The swing knee at a new running speed: how far a runner folds the swinging leg changes
//! with speed, so an edited run folds it by a speed law instead of replaying the
//! recording's fold (a departure from the paper, whose edit keeps the recorded swing;
//! `docs/edited-motion.md`).
//!
//! # Model
//! ```text
//! Fr = v / √(g · L_leg)                                 (Froude speed, dimensionless)
//! Δθ = k · (Fr_target − Fr_source),   k = SWING_FOLD_PER_FROUDE_DEG
//! per swing [lo, td'] of one foot in the source (its liftoff to its next touchdown),
//! θ(f) the knee flexion of frame f (deg):
//!   θ_e = max(θ(lo), θ(td')),   θ_p = max θ over the swing
//!   w(f) = clamp((θ(f) − θ_e) / (θ_p − θ_e), 0, 1)
//!   Δ = clamp(Δθ, −FOLD_KEPT · (θ_p − θ_e), MAX_KNEE_FLEXION_DEG − θ_p)
//!   q_knee(f) ← R(n, −Δ · w(f)) · q_knee(f)
//!   n = (H − K) × (A − K) / |…|   (hip, knee, ankle; in the knee's parent frame)
//! ```
//! The fold is added where the knee is folded beyond its liftoff and touchdown flexion, in
//! proportion, so the stance frames and the swing's edges are the recording's and the peak
//! moves by `Δ`; rotating the shank about the normal of the hip–knee–ankle plane keeps the
//! leg in its plane. The law is dimensionless (dynamic similarity): a character `L` times
//! the source's size at `√L` times its speed folds as the source does.
//!
//! # Where `k` comes from
//! The peak swing knee flexion (median over a clip's swings) of every run in the shared
//! data, five runners: one runner at 1.96 and 2.96 m/s (88.2°, 102.6°), a CMU runjog at
//! 2.63 m/s (95.5°), nine CMU runs of one subject at 3.42–3.62 m/s (105–120°), a plate run
//! at 3.94 m/s (101.6°) and a fast run at 5.37 m/s (118°). The form, a common slope with
//! each runner's own level (the edit starts from the source's fold), was chosen by leaving
//! one runner out: the slope fitted on the other four is 22.1–27.4°; fitted on all five,
//! 23.6°. Left out, the one runner recorded at two speeds is predicted to fold 7.3° more at
//! 2.96 than at 1.96 m/s, where it folds 14.4° more (the edit replaying the recording: 0°).
//! Levels differ between runners by up to 9°, which the law does not model: it moves the
//! source's own fold.

use crate::bvh::Motion;
use crate::ingest::body::BodyModel;
use crate::math::constants::GRAVITY;
use crate::math::v3::{cross, norm, sub, V3};
use crate::skeleton::fk::FkWorkspace;

use super::fidelity::gauge;
use super::pose::{local_quat, world_quats};
use super::rotation::{axis_angle, conj, is_tait_bryan, mul, rotate, to_euler, Quat};

/// Degrees of swing knee fold per unit of Froude speed `v/√(g L_leg)` (module docs).
pub const SWING_FOLD_PER_FROUDE_DEG: f64 = 23.6;
/// No swing knee is folded beyond this flexion, degrees (the heel near the buttock; the
/// runs of the shared data peak at 88–123°).
pub const MAX_KNEE_FLEXION_DEG: f64 = 140.0;
/// A slower edit unfolds a swing by at most this share of its fold above its edges, so a
/// swing stays a swing.
pub const FOLD_KEPT: f64 = 0.5;
/// A swing folding less than this above its edges, degrees, is not a running swing (a
/// shuffle, a stance split in two) and is left as recorded.
pub const MIN_SWING_FOLD_DEG: f64 = 10.0;
/// Longest liftoff-to-touchdown interval of one foot read as a swing, s (a run's swing
/// lasts 0.3–0.6 s).
pub const MAX_SWING_S: f64 = 1.0;

/// Froude speed `v / √(g L)`: speed `v` (m/s) of a body of leg length `L` (m).
pub fn froude_speed(v_mps: f64, leg_m: f64) -> f64 {
    v_mps / (GRAVITY * leg_m).sqrt()
}

/// The swing fold change `Δθ = k (Fr_target − Fr_source)` in degrees, for a run at
/// `v_source` (m/s) edited to `v_target` on one body with legs `leg_m` long (both speeds
/// on the same character: a new character's recorded speed is the source's times `√L`, its
/// legs `L` times as long); 0 when an input is not finite and positive.
pub fn fold_change_deg(v_source: f64, v_target: f64, leg_m: f64) -> f64 {
    let ok = |x: f64| x.is_finite() && x > 0.0;
    if !(ok(v_source) && ok(v_target) && ok(leg_m)) {
        return 0.0;
    }
    SWING_FOLD_PER_FROUDE_DEG * (froude_speed(v_target, leg_m) - froude_speed(v_source, leg_m))
}

/// One foot's swing in the source clip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Swing {
    /// 0 left, 1 right.
    pub side: usize,
    /// Liftoff, clip time (s).
    pub lo_s: f64,
    /// The same foot's next touchdown, clip time (s).
    pub td_s: f64,
}

/// The swings between one-foot stances of the same foot: `stances` as (label, touchdown,
/// liftoff) in clip seconds, labels `L` or `R` (other labels are not one foot and are
/// skipped); a gap longer than [`MAX_SWING_S`] or not positive is not a swing.
pub fn swings<'a>(stances: impl IntoIterator<Item = (&'a str, f64, f64)>) -> Vec<Swing> {
    let mut by_side: [Vec<(f64, f64)>; 2] = [Vec::new(), Vec::new()];
    for (label, td, lo) in stances {
        let side = match label {
            "L" => 0,
            "R" => 1,
            _ => continue,
        };
        if td.is_finite() && lo.is_finite() {
            by_side[side].push((td, lo));
        }
    }
    let mut out = Vec::new();
    for (side, list) in by_side.iter_mut().enumerate() {
        list.sort_by(|a, b| a.0.total_cmp(&b.0));
        for w in list.windows(2) {
            let (lo_s, td_s) = (w[0].1, w[1].0);
            if td_s > lo_s && td_s - lo_s <= MAX_SWING_S {
                out.push(Swing { side, lo_s, td_s });
            }
        }
    }
    out
}

/// The fold of one swing: its knee flexion `theta` (deg, the swing's frames from liftoff
/// to touchdown) and the wanted change `delta` (deg) give the added flexion per frame,
/// `Δ · w(f)` of the module docs (0 at both edges; all 0 when the swing folds less than
/// [`MIN_SWING_FOLD_DEG`] above its edges).
pub fn swing_fold(theta: &[f64], delta: f64) -> Vec<f64> {
    let (Some(&first), Some(&last)) = (theta.first(), theta.last()) else {
        return Vec::new();
    };
    let edge = first.max(last);
    let peak = theta.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let fold = peak - edge;
    if !(fold >= MIN_SWING_FOLD_DEG && delta.is_finite()) {
        return vec![0.0; theta.len()];
    }
    let d = delta.clamp(-FOLD_KEPT * fold, (MAX_KNEE_FLEXION_DEG - peak).max(0.0));
    theta
        .iter()
        .map(|&t| d * ((t - edge) / fold).clamp(0.0, 1.0))
        .collect()
}

/// What [`fold_swing_knees`] did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FoldReport {
    /// The fold change asked for, degrees.
    pub asked_deg: f64,
    /// Swings folded (of the ones inside the clip).
    pub folded: usize,
    /// Swings inside the clip.
    pub swings: usize,
    /// The largest change added at a swing's peak, degrees (signed; after the limits).
    pub applied_deg: f64,
}

/// `motion` with each swing's knee folded by `delta_deg` at its peak ([`swing_fold`]):
/// only the knee rotation channels of swing frames change.
pub fn fold_swing_knees(
    body: &BodyModel,
    motion: &Motion,
    swings: &[Swing],
    delta_deg: f64,
) -> (Motion, FoldReport) {
    let mut out = motion.clone();
    let mut report = FoldReport {
        asked_deg: delta_deg,
        ..FoldReport::default()
    };
    let n = motion.n_frames();
    if n < 3 || delta_deg == 0.0 || !delta_deg.is_finite() {
        return (out, report);
    }
    let knees = gauge(body, motion);
    let mut folder = KneeFolder::new(body);
    let dt = motion.frame_time_s;
    let first = body.leadin.min(n - 1);
    let frame = |t: f64| (t / dt).round();
    for s in swings {
        let (a, b) = (frame(s.lo_s), frame(s.td_s));
        if !(a >= first as f64 && b <= (n - 1) as f64 && b > a + 1.0) {
            continue;
        }
        report.swings += 1;
        let (a, b) = (a as usize, b as usize);
        let theta: Vec<f64> = (a..=b).map(|f| knees[f].knee_deg[s.side]).collect();
        let add = swing_fold(&theta, delta_deg);
        let peak = add
            .iter()
            .copied()
            .fold(0.0_f64, |m, v| if v.abs() > m.abs() { v } else { m });
        if peak == 0.0 {
            continue;
        }
        report.folded += 1;
        if peak.abs() > report.applied_deg.abs() {
            report.applied_deg = peak;
        }
        for (f, d) in (a..=b).zip(add) {
            if d != 0.0 {
                folder.fold(&mut out, f, s.side, d);
            }
        }
    }
    (out, report)
}

/// What folding a knee needs of a skeleton: its rotation axes per joint and the FK
/// buffers, made once per motion.
struct KneeFolder<'a> {
    body: &'a BodyModel,
    axes: Vec<Vec<usize>>,
    ws: FkWorkspace,
    file: Vec<V3>,
    pts: Vec<V3>,
}

impl<'a> KneeFolder<'a> {
    fn new(body: &'a BodyModel) -> Self {
        let sk = &body.skeleton;
        let axes = sk
            .channels
            .iter()
            .map(|c| c.rotations.iter().map(|&(a, _)| a).collect())
            .collect();
        let np = sk.n_points();
        KneeFolder {
            body,
            axes,
            ws: FkWorkspace::new(sk),
            file: vec![[0.0; 3]; np],
            pts: vec![[0.0; 3]; np],
        }
    }

    /// Adds `deg` of flexion to the knee of `side` in row `f` of `motion`: the knee's
    /// local rotation turned about the normal of the hip–knee–ankle plane (its parent's
    /// frame).
    fn fold(&mut self, motion: &mut Motion, f: usize, side: usize, deg: f64) {
        let (body, sk) = (self.body, &self.body.skeleton);
        let leg = [&body.landmarks.left, &body.landmarks.right][side];
        let Some(parent) = sk.parents.get(leg.knee).copied().flatten() else {
            return;
        };
        let axes = &self.axes[leg.knee];
        if !is_tait_bryan(axes) {
            return;
        }
        let row = motion.row(f).to_vec();
        body.points(&mut self.ws, &row, &mut self.file, &mut self.pts);
        let (h, k, a) = (
            self.file[leg.hip],
            self.file[leg.knee],
            self.file[leg.ankle],
        );
        let n_file = cross(sub(h, k), sub(a, k));
        let len = norm(n_file);
        if len.is_nan() || len <= 1e-9 {
            return;
        }
        let local: Vec<Quat> = (0..sk.n_joints())
            .map(|j| local_quat(sk, &self.axes[j], j, &row))
            .collect();
        let parent_world = world_quats(sk, &local)[parent];
        let n_local = rotate(conj(parent_world), n_file.map(|v| v / len));
        let q = mul(axis_angle(n_local, -deg.to_radians()), local[leg.knee]);
        let ch = &sk.channels[leg.knee];
        let now: Vec<f64> = ch.rotations.iter().map(|&(_, i)| row[i]).collect();
        let new = to_euler(q, [axes[0], axes[1], axes[2]], [now[0], now[1], now[2]]);
        let nc = motion.n_channels;
        for (&(_, i), v) in ch.rotations.iter().zip(new) {
            motion.values[f * nc + i] = v;
        }
    }
}

#[cfg(test)]
mod tests;
