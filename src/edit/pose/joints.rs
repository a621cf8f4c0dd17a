//! The pose's joints: forward kinematics of a quaternion pose, a joint turned in the world
//! frame, the Euler angles written back into the channel row, and the per-thread scratch
//! of the pose stage ([`PoseWorkspace`]).
//!
//! # Model
//! ```text
//! FK       R_j = R_p·q_j,  x_j = x_p + R_p·t_j   (p: the parent of j, parents first;
//!          root: R = q, x = t; t_j: the joint's offset or translation channels)
//! turn     q_j ← R_p⁻¹·Δ·R_j: joint j's world rotation turned by Δ, its parent kept
//! angles   per joint, the Euler angles of q_j nearest the previous frame's
//! ```
//!
//! # Frames and units
//! File units and axes; FK also gives the points in metres, internal Z-up frame.

use super::reference::Reference;
use super::Pose;
use crate::edit::rotation::{self as rot, Quat};
use crate::ingest::body::BodyModel;
use crate::math::v3::{add, norm, V3};
use crate::skeleton::fk::local_translation;

/// Per-thread scratch of the pose stage.
#[derive(Debug, Clone)]
pub struct PoseWorkspace {
    pub(super) pose: Pose,
    pub(super) other: Pose,
    pub(super) world_q: Vec<Quat>,
    pub(super) file: Vec<V3>,
    pub(super) pts: Vec<V3>,
    pub(super) knee_axis: [Option<V3>; 2],
    pub(super) prev_angles: Option<Vec<f64>>,
    pub(super) free_q: Vec<Quat>,
}

impl PoseWorkspace {
    /// Scratch for a reference's skeleton.
    pub fn new(r: &Reference) -> PoseWorkspace {
        let sk = &r.body.skeleton;
        let pose = Pose {
            q: vec![rot::QUAT_IDENTITY; sk.n_joints()],
            row: vec![0.0; sk.n_channels],
            ref_frame: 0,
        };
        PoseWorkspace {
            other: pose.clone(),
            pose,
            world_q: vec![rot::QUAT_IDENTITY; sk.n_joints()],
            file: vec![[0.0; 3]; sk.n_points()],
            pts: vec![[0.0; 3]; sk.n_points()],
            knee_axis: [None; 2],
            prev_angles: None,
            free_q: vec![rot::QUAT_IDENTITY; sk.n_joints()],
        }
    }
}

/// FK of a quaternion pose: world rotations and file-frame points, then metres Z up.
pub(super) fn forward(
    r: &Reference,
    pose: &Pose,
    wq: &mut [Quat],
    file: &mut [V3],
    pts: &mut [V3],
) {
    let sk = &r.body.skeleton;
    for j in 0..sk.n_joints() {
        let t = local_translation(sk, j, &pose.row);
        match sk.parents[j] {
            None => {
                wq[j] = pose.q[j];
                file[j] = t;
            }
            Some(p) => {
                wq[j] = rot::mul(wq[p], pose.q[j]);
                file[j] = add(file[p], rot::rotate(wq[p], t));
            }
        }
    }
    let nj = sk.n_joints();
    for (e, (j, off)) in sk.end_sites.iter().enumerate() {
        file[nj + e] = add(file[*j], rot::rotate(wq[*j], *off));
    }
    for (o, p) in pts.iter_mut().zip(file.iter()) {
        *o = r.body.to_internal(*p);
    }
}

/// Sets joint `j`'s world rotation to `delta · world` (its parent unchanged).
pub(super) fn turn_world(r: &Reference, pose: &mut Pose, wq: &[Quat], j: usize, delta: Quat) {
    let parent = r.body.skeleton.parents[j].map_or(rot::QUAT_IDENTITY, |p| wq[p]);
    let world = rot::mul(delta, wq[j]);
    pose.q[j] = rot::normalize(rot::mul(rot::conj(parent), world));
}

pub(super) fn up_file(body: &BodyModel) -> V3 {
    let u = body.to_file([0.0, 0.0, 1.0]);
    let n = norm(u);
    u.map(|v| v / n)
}

/// Writes the rotation channels of `ws.pose` into its row (Euler angles nearest the
/// previous frame's, or the reference frame's for the first).
pub(super) fn write_angles(r: &Reference, ws: &mut PoseWorkspace) {
    let sk = &r.body.skeleton;
    let prev = ws
        .prev_angles
        .get_or_insert_with(|| r.motion.row(ws.pose.ref_frame).to_vec());
    for j in 0..sk.n_joints() {
        let ch = &sk.channels[j].rotations;
        if ch.len() == 3 && rot::is_tait_bryan(&r.axes[j]) {
            let axes = [r.axes[j][0], r.axes[j][1], r.axes[j][2]];
            let reference = [prev[ch[0].1], prev[ch[1].1], prev[ch[2].1]];
            let e = rot::to_euler(ws.pose.q[j], axes, reference);
            for n in 0..3 {
                ws.pose.row[ch[n].1] = e[n];
            }
        }
    }
    prev.copy_from_slice(&ws.pose.row);
}
