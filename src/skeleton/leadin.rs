//! Lead-in frames that are not captured motion: the synthetic T-pose frame 0 of the CMU
//! conversions, the all-zero dropout rows after it, and the DAZ blend frames.
//!
//! # Model
//! ```text
//! 1. frame 0 synthetic ⇔ every root rotation channel of frame 0 = 0
//!                       ∧ every rotation channel of frame 0 has |θ| ≤ 25°
//!                       ∧ ∃ joint: geodesic(R_local(1) R_local(0)ᵀ) > 10°
//! 2. after a dropped frame 0: drop following rows whose channels are all exactly 0
//! 3. only after 1: k = first kept frame, d_i = max_j geodesic(R_j(i), R_j(0));
//!    d_k < ½·d_{k+4}  ⇒  drop k … k+4
//! ```
//! Dropped frames are always a prefix; frame indices keep the file's numbering.
//!
//! # References
//! spec com-from-bvh §2.1 [verified on the shared files].

use super::fk::{geodesic_deg, local_rotation};
use super::model::Skeleton;
use crate::bvh::Motion;

/// Rule 1 (b): largest rotation of a synthetic frame 0, degrees.
pub const TPOSE_MAX_DEG: f64 = 25.0;
/// Rule 1 (c): a joint must change by more than this between frames 0 and 1, degrees.
pub const TPOSE_SNAP_DEG: f64 = 10.0;
/// Rule 3: number of DAZ blend frames after frame 0.
pub const DAZ_BLEND_FRAMES: usize = 5;

fn max_joint_angle(skel: &Skeleton, a: &[f64], b: &[f64]) -> f64 {
    (0..skel.n_joints())
        .map(|j| geodesic_deg(&local_rotation(skel, j, a), &local_rotation(skel, j, b)))
        .fold(0.0, f64::max)
}

fn rotation_channels(skel: &Skeleton, j: Option<usize>) -> impl Iterator<Item = usize> + '_ {
    skel.channels
        .iter()
        .enumerate()
        .filter(move |(k, _)| j.is_none_or(|j| *k == j))
        .flat_map(|(_, c)| c.rotations.iter().map(|r| r.1))
}

fn frame0_is_synthetic(skel: &Skeleton, m: &Motion) -> bool {
    if m.n_frames() < 2 {
        return false;
    }
    let f0 = m.row(0);
    let root_zero = rotation_channels(skel, Some(0)).all(|i| f0[i] == 0.0);
    let small = rotation_channels(skel, None).all(|i| f0[i].abs() <= TPOSE_MAX_DEG);
    root_zero && small && max_joint_angle(skel, f0, m.row(1)) > TPOSE_SNAP_DEG
}

/// Number of leading frames to drop (rows `0..n` are dropped).
pub fn leadin_frames(skel: &Skeleton, m: &Motion) -> usize {
    if !frame0_is_synthetic(skel, m) {
        return 0;
    }
    let mut k = 1;
    while k < m.n_frames() && m.row(k).iter().all(|v| *v == 0.0) {
        k += 1;
    }
    if k + 4 < m.n_frames() {
        let f0 = m.row(0);
        let dk = max_joint_angle(skel, m.row(k), f0);
        let dk4 = max_joint_angle(skel, m.row(k + 4), f0);
        if dk < 0.5 * dk4 {
            k += DAZ_BLEND_FRAMES;
        }
    }
    k.min(m.n_frames())
}
