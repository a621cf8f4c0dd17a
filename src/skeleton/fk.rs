//! Forward kinematics: every joint and End Site position of one frame, in file units and
//! file axes.
//!
//! # Model
//! ```text
//! R_j = R_p(j) · R_j^local,   P_j = P_p(j) + R_p(j) · t_j^local     (root: R_p = I, P_p = 0)
//! End Site of j:  P_j + R_j · OFFSET_end
//! Elementary rotations (right-handed, degrees in the file):
//! R_x(θ) = [[1,0,0],[0,c,−s],[0,s,c]],  R_y(θ) = [[c,0,s],[0,1,0],[−s,0,c]],
//! R_z(θ) = [[c,−s,0],[s,c,0],[0,0,1]]
//! ```
//! Right-multiplying by an elementary rotation mixes two columns of the running matrix,
//! so a joint costs one `sin_cos` and four multiply-adds per column pair and channel.
//!
//! # References
//! spec com-from-bvh §2 [verified]; pinocchio `kinematics.hxx` (parents before children).
//!
//! # Examples
//! ```
//! use stancelib::{bvh, skeleton::{Skeleton, fk}};
//! let text = "HIERARCHY\nROOT A\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n JOINT B\n {\n  OFFSET 1 0 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  End Site\n  {\n   OFFSET 1 0 0\n  }\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 90 0 0 0 0 0\n";
//! let b = bvh::parse_reader(text.as_bytes()).unwrap();
//! let skel = Skeleton::from_bvh(&b);
//! let mut ws = fk::FkWorkspace::new(&skel);
//! let mut pts = vec![[0.0; 3]; skel.n_points()];
//! fk::forward(&skel, &mut ws, b.motion.row(0), &mut pts);
//! assert!((pts[2][1] - 2.0).abs() < 1e-12); // End Site rotated by 90° about Z: (0, 2, 0)
//! ```

use super::model::{Skeleton, TranslationMode};

/// A 3×3 rotation stored by columns: `m[c][r]`.
pub type Mat3 = [[f64; 3]; 3];

/// The identity rotation.
pub const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// Per-thread scratch: the world rotation of every joint.
#[derive(Debug, Clone)]
pub struct FkWorkspace {
    /// World rotation per joint.
    pub rot: Vec<Mat3>,
}

impl FkWorkspace {
    /// Scratch sized for `skel`.
    pub fn new(skel: &Skeleton) -> FkWorkspace {
        FkWorkspace {
            rot: vec![IDENTITY; skel.n_joints()],
        }
    }
}

/// `m · v` for a column-stored matrix.
#[inline(always)]
pub fn mul_vec(m: &Mat3, v: &[f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}

/// Right-multiply `m` by the elementary rotation about `axis` by `deg` degrees, in place.
#[inline(always)]
pub fn rotate_right(m: &mut Mat3, axis: usize, deg: f64) {
    let (s, c) = deg.to_radians().sin_cos();
    // Constant column indices per arm keep the matrix in registers (a run-time index pair
    // spilled it to the stack: +26 % FK throughput, tests/bench/stages.rs).
    match axis {
        0 => mix::<1, 2>(m, s, c), // M·R_x: col1' = c·col1 + s·col2, col2' = −s·col1 + c·col2
        1 => mix::<2, 0>(m, s, c), // M·R_y: col2' = c·col2 + s·col0, col0' = −s·col2 + c·col0
        _ => mix::<0, 1>(m, s, c), // M·R_z: col0' = c·col0 + s·col1, col1' = −s·col0 + c·col1
    }
}

/// `col_A' = c·col_A + s·col_B`, `col_B' = −s·col_A + c·col_B`.
#[inline(always)]
fn mix<const A: usize, const B: usize>(m: &mut Mat3, s: f64, c: f64) {
    let (ca, cb) = (m[A], m[B]);
    m[A] = [
        c * ca[0] + s * cb[0],
        c * ca[1] + s * cb[1],
        c * ca[2] + s * cb[2],
    ];
    m[B] = [
        -s * ca[0] + c * cb[0],
        -s * ca[1] + c * cb[1],
        -s * ca[2] + c * cb[2],
    ];
}

/// The local translation of joint `j` for a motion row.
#[inline(always)]
pub fn local_translation(skel: &Skeleton, j: usize, row: &[f64]) -> [f64; 3] {
    let ch = &skel.channels[j];
    let off = skel.offsets[j];
    match ch.mode {
        TranslationMode::Offset => off,
        TranslationMode::Replace => {
            std::array::from_fn(|a| ch.translations[a].map_or(off[a], |i| row[i]))
        }
        TranslationMode::Delta => {
            std::array::from_fn(|a| off[a] + ch.translations[a].map_or(0.0, |i| row[i]))
        }
    }
}

/// Local rotation of joint `j` for a motion row (rotation channels in the order listed).
pub fn local_rotation(skel: &Skeleton, j: usize, row: &[f64]) -> Mat3 {
    let mut m = IDENTITY;
    for &(axis, idx) in &skel.channels[j].rotations {
        rotate_right(&mut m, axis, row[idx]);
    }
    m
}

/// Forward kinematics of one frame: `points` (len = `skel.n_points()`) receives every
/// joint then every End Site, file units and axes.
///
/// # Panics
/// If `row.len() < skel.n_channels` or `points.len() < skel.n_points()` (programmer error;
/// the clip pipeline sizes both from the skeleton).
pub fn forward(skel: &Skeleton, ws: &mut FkWorkspace, row: &[f64], points: &mut [[f64; 3]]) {
    assert!(row.len() >= skel.n_channels && points.len() >= skel.n_points());
    for j in 0..skel.n_joints() {
        let t = local_translation(skel, j, row);
        let (mut r, p) = match skel.parents[j] {
            None => (IDENTITY, t),
            Some(pj) => {
                let rp = ws.rot[pj];
                let d = mul_vec(&rp, &t);
                let pp = points[pj];
                (rp, [pp[0] + d[0], pp[1] + d[1], pp[2] + d[2]])
            }
        };
        for &(axis, idx) in &skel.channels[j].rotations {
            rotate_right(&mut r, axis, row[idx]);
        }
        ws.rot[j] = r;
        points[j] = p;
    }
    let nj = skel.n_joints();
    for (e, (j, off)) in skel.end_sites.iter().enumerate() {
        let d = mul_vec(&ws.rot[*j], off);
        let p = points[*j];
        points[nj + e] = [p[0] + d[0], p[1] + d[1], p[2] + d[2]];
    }
}

/// The rest pose: every joint at its OFFSET, every rotation the identity (spec §2).
pub fn rest_pose(skel: &Skeleton) -> Vec<[f64; 3]> {
    let mut pts = vec![[0.0; 3]; skel.n_points()];
    for j in 0..skel.n_joints() {
        let o = skel.offsets[j];
        pts[j] = match skel.parents[j] {
            None => o,
            Some(p) => [pts[p][0] + o[0], pts[p][1] + o[1], pts[p][2] + o[2]],
        };
    }
    let nj = skel.n_joints();
    for (e, (j, o)) in skel.end_sites.iter().enumerate() {
        pts[nj + e] = [pts[*j][0] + o[0], pts[*j][1] + o[1], pts[*j][2] + o[2]];
    }
    pts
}

/// Geodesic angle (degrees) between two rotations: `acos((tr(A Bᵀ) − 1)/2)`.
pub fn geodesic_deg(a: &Mat3, b: &Mat3) -> f64 {
    // tr(A Bᵀ) = Σ_c Σ_r a[c][r] b[c][r]
    let tr: f64 = (0..3)
        .map(|c| (0..3).map(|r| a[c][r] * b[c][r]).sum::<f64>())
        .sum();
    ((tr - 1.0) / 2.0).clamp(-1.0, 1.0).acos().to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Vector3};

    fn na(axis: usize, deg: f64) -> Rotation3<f64> {
        let ax = [Vector3::x_axis(), Vector3::y_axis(), Vector3::z_axis()][axis];
        Rotation3::from_axis_angle(&ax, deg.to_radians())
    }

    #[test]
    fn composition_matches_nalgebra_intrinsic_product() {
        // R = R_a1 · R_a2 · R_a3 for every order, checked against nalgebra's rotations.
        for order in [[2, 0, 1], [2, 1, 0], [0, 2, 1], [1, 2, 0], [0, 1, 2]] {
            let ang = [37.0, -71.5, 128.25];
            let mut m = IDENTITY;
            let mut r = Rotation3::identity();
            for k in 0..3 {
                rotate_right(&mut m, order[k], ang[k]);
                r *= na(order[k], ang[k]);
            }
            for c in 0..3 {
                for rr in 0..3 {
                    assert!((m[c][rr] - r[(rr, c)]).abs() < 1e-14);
                }
            }
        }
    }

    #[test]
    fn geodesic_angle_of_a_known_rotation() {
        let mut m = IDENTITY;
        rotate_right(&mut m, 1, 33.0);
        assert!((geodesic_deg(&m, &IDENTITY) - 33.0).abs() < 1e-9);
    }
}
