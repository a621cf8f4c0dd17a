//! A full-body pose per output frame: the time-warped reference, the new heading, the
//! support feet planted by analytic two-bone IK and the root placed so the COM is the
//! planned one.
//!
//! # Model
//! Per output time `t` ([`pose_frame`]; every frame of a plan: [`pose_motion`]):
//! ```text
//! 1. reference pose  the source's pose at the time-warped clip time, turned by the
//!                    heading change Δψ                                         [frame]
//! 2. foot goals      each foot anchored to its planned stance, or on its way between
//!                    two, and how strongly it is held there                    [goals]
//! 3. root and IK     feet by two-bone IK (about the toe beyond the leg's reach), the
//!                    root shifted so the COM is the planned one, the pelvis turned
//!                    where a support leg falls short; repeated        [frame, reach]
//! 4. written row     the joints' Euler angles nearest the previous frame's    [joints]
//! ```
//! The files, one concern each; each uses only the types below and the files listed before
//! it (no import circle), and its docs state its equations:
//! - `reference`: the source recording ([`Reference`], [`StanceSource`]): its pose, COM
//!   and feet at a clip time, the feet's resting slide, the heading change.
//! - `joints`: forward kinematics of a quaternion pose, a joint turned in the world frame,
//!   Euler angles written back; the per-thread scratch [`PoseWorkspace`].
//! - `goals`: where each foot goes at a time and how strongly it is pulled there.
//! - `reach`: the reach IK: two-bone legs, the toe pivot, the posture's reach step.
//! - `frame`: one frame solved (reference pose, root/IK iteration, lead-in), and the
//!   whole motion.
//!
//! # Frames and units
//! FK and IK in file units and axes (rotations as unit quaternions); COM, targets and
//! reports in metres, internal Z-up frame.

mod frame;
mod goals;
mod joints;
mod reach;
mod reference;

pub use frame::{frame_count_f64, pose_frame, pose_motion};
pub use joints::PoseWorkspace;
pub(crate) use reference::{local_quat, world_quats};
pub use reference::{Reference, StanceSource};

use super::path::Phase;
use super::posture::Posture;
use super::rotation::Quat;
use crate::bvh::Motion;
use crate::math::v3::V3;

/// A pose being built: local rotations and the row of every channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// Local rotation per joint.
    pub q: Vec<Quat>,
    /// Every channel (translations used; rotation values are rewritten from `q`).
    pub row: Vec<f64>,
    /// Nearest source frame (Euler branch reference for the first output frame).
    pub ref_frame: usize,
}

/// One output frame's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct FramePose {
    /// Output time (s from the first output frame; [`pose_frame`] gives the plan time).
    pub time_s: f64,
    /// The phase.
    pub phase: Phase,
    /// Planned COM (m).
    pub com_plan: V3,
    /// COM of the written pose (m).
    pub com_pose: V3,
    /// Planned contact point, in stance (m).
    pub contact: Option<V3>,
    /// Planned touchdown and liftoff of the stance, in stance (s, output time;
    /// [`pose_frame`] gives plan times).
    pub window: Option<(f64, f64)>,
    /// Support ankle (left when both), in stance (m).
    pub foot: Option<V3>,
    /// Largest distance of a support ankle from its target (m).
    pub foot_error_m: f64,
    /// Root/IK iterations used.
    pub iterations: usize,
    /// COM within tolerance and feet on their targets.
    pub converged: bool,
    /// The posture change that let the support legs reach ([`super::posture`]; zero
    /// where they reach with the reference's posture).
    pub posture: Posture,
    /// Clip time of the source pose the frame is taken from, s (in a flight between two
    /// stances, that of the edge weighing more in the blend).
    pub source_time_s: f64,
}

/// The whole edited motion.
#[derive(Debug, Clone, PartialEq)]
pub struct EditedMotion {
    /// Rows in the source's channel layout.
    pub motion: Motion,
    /// Per frame: plan, pose COM and convergence.
    pub frames: Vec<FramePose>,
}
