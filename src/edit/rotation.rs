//! Unit quaternions for joint rotations: from and to BVH Euler channels, slerp without
//! flips, and the rotation taking one direction onto another.
//!
//! # Model
//! ```text
//! q = (w, x, y, z), |q| = 1;  R(q₁q₂) = R(q₁)R(q₂)
//! channels a₁a₂a₃ (distinct axes i, j, k), R = R_i(θ₁) R_j(θ₂) R_k(θ₃), s = +1 if (i, j, k)
//! is cyclic in (x, y, z), else −1:
//!   θ₂ = asin(s·R_ik),  θ₁ = atan2(−s·R_jk, R_kk),  θ₃ = atan2(−s·R_ij, R_ii)
//!   second solution (θ₁ + 180°, 180° − θ₂, θ₃ + 180°); each angle ± 360° n
//! slerp(q₀, q₁, w) with q₁ → −q₁ when q₀·q₁ < 0 (the short way: no flip)
//! ```
//! Of the Euler solutions the one nearest (sum of squared degrees) to a reference triple
//! is written, so angles stay continuous from frame to frame.
//!
//! # Frames and units
//! Angles in degrees (as in BVH), rotations right-handed about the file axes.

use crate::skeleton::fk::Mat3;

/// A unit quaternion `(w, x, y, z)`.
pub type Quat = [f64; 4];

/// The identity rotation.
pub const QUAT_IDENTITY: Quat = [1.0, 0.0, 0.0, 0.0];

/// `a · b` (apply `b` first).
#[inline]
pub fn mul(a: Quat, b: Quat) -> Quat {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// The inverse of a unit quaternion.
#[inline]
pub fn conj(q: Quat) -> Quat {
    [q[0], -q[1], -q[2], -q[3]]
}

/// Rotation by `deg` degrees about file axis `axis` (0, 1, 2).
#[inline]
pub fn about_axis(axis: usize, deg: f64) -> Quat {
    let (s, c) = (deg.to_radians() * 0.5).sin_cos();
    let mut q = [c, 0.0, 0.0, 0.0];
    q[1 + axis] = s;
    q
}

/// Rotation by `angle` radians about the unit vector `n`.
pub fn axis_angle(n: [f64; 3], angle: f64) -> Quat {
    let (s, c) = (angle * 0.5).sin_cos();
    [c, s * n[0], s * n[1], s * n[2]]
}

/// `q / |q|` (the identity for a zero quaternion).
pub fn normalize(q: Quat) -> Quat {
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    if n > 0.0 {
        q.map(|v| v / n)
    } else {
        QUAT_IDENTITY
    }
}

/// Spherical interpolation from `a` (w = 0) to `b` (w = 1), the short way.
pub fn slerp(a: Quat, b: Quat, w: f64) -> Quat {
    let mut d: f64 = (0..4).map(|i| a[i] * b[i]).sum();
    let b = if d < 0.0 {
        d = -d;
        b.map(|v| -v)
    } else {
        b
    };
    if d > 0.9995 {
        // Nearly equal: normalised lerp is exact to 1e-7 rad here and avoids 0/0.
        return normalize(std::array::from_fn(|i| a[i] + w * (b[i] - a[i])));
    }
    let th = d.clamp(-1.0, 1.0).acos();
    let (s0, s1) = (((1.0 - w) * th).sin(), (w * th).sin());
    let s = th.sin();
    std::array::from_fn(|i| (s0 * a[i] + s1 * b[i]) / s)
}

/// The column-stored matrix of `q` (`m[c][r]`, as `skeleton::fk`).
pub fn to_mat(q: Quat) -> Mat3 {
    let [w, x, y, z] = q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y + w * z),
            2.0 * (x * z - w * y),
        ],
        [
            2.0 * (x * y - w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z + w * x),
        ],
        [
            2.0 * (x * z + w * y),
            2.0 * (y * z - w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// `q · v`.
pub fn rotate(q: Quat, v: [f64; 3]) -> [f64; 3] {
    crate::skeleton::fk::mul_vec(&to_mat(q), &v)
}

/// The smallest rotation taking direction `a` onto direction `b` (identity when either
/// is zero; a half turn about a perpendicular axis when they are opposite).
pub fn between(a: [f64; 3], b: [f64; 3]) -> Quat {
    let na = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let nb = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
    if na == 0.0 || nb == 0.0 {
        return QUAT_IDENTITY;
    }
    let (a, b) = (a.map(|v| v / na), b.map(|v| v / nb));
    let c = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    if d < -1.0 + 1e-12 {
        let k = if a[0].abs() < 0.9 { 0 } else { 1 };
        let mut e = [0.0; 3];
        e[k] = 1.0;
        let p = [
            a[1] * e[2] - a[2] * e[1],
            a[2] * e[0] - a[0] * e[2],
            a[0] * e[1] - a[1] * e[0],
        ];
        let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        return [0.0, p[0] / n, p[1] / n, p[2] / n];
    }
    normalize([1.0 + d, c[0], c[1], c[2]])
}

/// The rotation of Euler channels: axes `axes` with angles `deg`, in the order listed.
pub fn from_euler(axes: &[usize], deg: &[f64]) -> Quat {
    axes.iter()
        .zip(deg)
        .fold(QUAT_IDENTITY, |q, (&a, &d)| mul(q, about_axis(a, d)))
}

/// True when three rotation channels have three distinct axes (Tait–Bryan).
pub fn is_tait_bryan(axes: &[usize]) -> bool {
    axes.len() == 3 && axes[0] != axes[1] && axes[1] != axes[2] && axes[0] != axes[2]
}

fn nearest(v: f64, r: f64) -> f64 {
    v + 360.0 * ((r - v) / 360.0).round()
}

/// Tait–Bryan angles (degrees) of `q` for channel axes `axes`, the solution nearest `reference`.
///
/// # Panics
/// When `axes` is not Tait–Bryan (check with [`is_tait_bryan`]).
pub fn to_euler(q: Quat, axes: [usize; 3], reference: [f64; 3]) -> [f64; 3] {
    let [i, j, k] = axes;
    assert!(is_tait_bryan(&axes), "to_euler needs three distinct axes");
    let m = to_mat(q);
    let r = |row: usize, col: usize| m[col][row];
    let s = if (j + 3 - i) % 3 == 1 { 1.0 } else { -1.0 };
    let t2 = (s * r(i, k)).clamp(-1.0, 1.0).asin();
    let t1 = (-s * r(j, k)).atan2(r(k, k));
    let t3 = (-s * r(i, j)).atan2(r(i, i));
    let a = [t1, t2, t3].map(f64::to_degrees);
    let b = [a[0] + 180.0, 180.0 - a[1], a[2] + 180.0];
    let fit = |x: [f64; 3]| {
        let y: [f64; 3] = std::array::from_fn(|n| nearest(x[n], reference[n]));
        let e: f64 = (0..3).map(|n| (y[n] - reference[n]).powi(2)).sum();
        (y, e)
    };
    let ((ya, ea), (yb, eb)) = (fit(a), fit(b));
    if ea <= eb {
        ya
    } else {
        yb
    }
}

/// Geodesic angle between two rotations (degrees).
pub fn angle_deg(a: Quat, b: Quat) -> f64 {
    let d: f64 = (0..4).map(|i| a[i] * b[i]).sum();
    (2.0 * d.abs().clamp(0.0, 1.0).acos()).to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::fk::{rotate_right, IDENTITY};

    #[test]
    fn euler_round_trip_for_every_tait_bryan_order() {
        // Angles away from gimbal lock (|θ₂| < 80°) come back to 1e-9° (acos/atan2 roundoff).
        let orders = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        for axes in orders {
            for ang in [
                [10.0, 20.0, 30.0],
                [-170.0, 75.0, 100.0],
                [45.0, -60.0, -135.0],
            ] {
                let q = from_euler(&axes, &ang);
                let back = to_euler(q, axes, ang);
                for n in 0..3 {
                    assert!(
                        (back[n] - ang[n]).abs() < 1e-9,
                        "{axes:?} {ang:?} → {back:?}"
                    );
                }
                // The quaternion's matrix is the FK's composition of the same channels.
                let mut m = IDENTITY;
                for n in 0..3 {
                    rotate_right(&mut m, axes[n], ang[n]);
                }
                let mq = to_mat(q);
                for c in 0..3 {
                    for r in 0..3 {
                        assert!((m[c][r] - mq[c][r]).abs() < 1e-12);
                    }
                }
            }
        }
    }

    #[test]
    fn slerp_takes_the_short_way_and_between_aligns() {
        let a = about_axis(2, 170.0);
        let b = about_axis(2, -170.0);
        let mid = slerp(a, b, 0.5);
        // Short way: through 180°, 10° from either end (not through 0°); acos near 1 turns
        // 1e-16 roundoff into ~1e-6°.
        assert!((angle_deg(mid, about_axis(2, 180.0))).abs() < 1e-5);
        let q = between([1.0, 0.0, 0.0], [0.0, 0.6, 0.8]);
        let v = rotate(q, [1.0, 0.0, 0.0]);
        assert!((v[1] - 0.6).abs() < 1e-12 && (v[2] - 0.8).abs() < 1e-12);
        let v = rotate(between([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]), [0.0, 0.0, 1.0]);
        assert!((v[2] + 1.0).abs() < 1e-12);
    }
}
