//! Pelvis posture for reach: when a support foot's goal is beyond the leg's reach from the
//! hip where the planned COM puts it, the pelvis turns a little under a trunk that keeps its
//! orientation, so that the stance hip moves towards the foot relative to the COM (a runner
//! faster than recorded drops and turns the hip into the push instead of leaving the floor
//! early). The trunk's lean stays the recording's.
//!
//! # Model
//! ```text
//! degrees of freedom x ∈ [−1, 1]³ (scaled by the bound b):
//!   pelvis (root) pitch, roll, yaw    θ_d = x_d · b    about the root:  R_p = R_up(θ₂) R_fwd(θ₁) R_lat(θ₀)
//!   the trunk (first joint above the root) turned back by R_p⁻¹: its world orientation is kept
//!   so is the hip of a swinging leg, by weight w = 1 − h (h: how strongly the foot is held
//!   on its planted path, 1 at its contacts): q_hip = slerp(q_hip, (R_p W_parent)⁻¹ W_hip, w),
//!   so a swinging leg translates with the pelvis instead of swinging out with its turn (a
//!   10° roll threw the first swing of CMU `09_01` at 5 m/s 12 cm sideways; now under 2 cm
//!   beyond the recording's lateral range), and a leg leaving or meeting the floor turns with
//!   the pelvis as its planted IK does (a full turn back at liftoff snapped the leg: 14 g)
//!   axes: lateral l = horizontal unit of (H_L − H_R), up z, forward l × z (free pose)
//! shortfall of support leg k after the root correction (COM on the plan):
//!   s_k(x) = |G_k − H_k(x) − (c_plan − c(x))| − R_k
//!   (G_k: the ankle goal after the toe pivot, H_k: hip, R_k: reach, c: COM of the pose)
//! J_kd = ∂s_k/∂x_d by finite differences of FK + foot IK + COM (once per frame)
//! x = y,  y = argmin |y|² + |J y − t|²/λ²  (damped least squares, λ = DAMPING_M)
//!   rows: legs with s_k − J_k y > 0,  t_k = −margin − (s_k − J_k y)  (margin: solve tol, 10 µm)
//!   box x ∈ [−1, 1]: a DOF past its bound is fixed there and the rest re-solved
//! in time: x(i) = P_i − N_i per DOF,  P_i = max_j x_j⁺ κ(t_i − t_j),  N_i likewise for x⁻,
//!   κ(τ) = 1 − smoothstep(|τ|/T_ramp)   (the solved postures, ramped in and out over T_ramp)
//! ```
//! The minimum-norm update leaves the reference posture untouched wherever the leg reaches
//! (`y = 0` when no row is active) and otherwise changes the most effective turns most.
//! Until issue 37 a fourth degree of freedom leaned the trunk forward (15°) and the pelvis
//! pitch carried the trunk with it: the CMU run edited to 4 and 5 m/s leaned 35–39° (p95;
//! recorded at most 17.4°), and the push-offs that did not reach at 5 m/s did not reach
//! with the lean either; method and figures in `docs/edited-motion.md`.
//!
//! # Frames and units
//! Axes and rotations in file axes; shortfalls, the Jacobian's rows and the damping in metres
//! (per unit of `x`); the bound in radians.

use super::rotation::{self as rot, Quat};
use crate::math::v3::{cross, dot, norm, V3};

/// Number of posture degrees of freedom (pelvis pitch, roll, yaw). A trunk lean was a fourth
/// until issue 37 (see the module docs), and a sideways trunk lean was tried as a fifth: it
/// moves the COM along the leg by a twentieth of the others (0.5 mm per bound against
/// 7–15 mm) and, once the others reach their bounds, the least-squares step threw it from
/// one bound to the other between frames (14° a frame).
pub const N_DOF: usize = 3;
/// A posture change, each degree of freedom as a fraction of its bound.
pub type Posture = [f64; N_DOF];
/// No change.
pub const POSTURE_ZERO: Posture = [0.0; N_DOF];
/// Damping of the least-squares step, m: far below the shortfalls it removes (centimetres)
/// and far above the roundoff of a Jacobian row (1e-10 m), so a row that barely moves the
/// hip (a singular posture) takes no large step.
pub const DAMPING_M: f64 = 1e-3;
/// Finite-difference step of the Jacobian, in units of `x` (1e-3 of a bound: a hundredth of
/// a degree, far inside the linear range of FK).
pub const FD_STEP: f64 = 1e-3;

/// A joint that keeps its world rotation (by `weight`) when the pelvis turns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kept {
    /// The joint.
    pub joint: usize,
    /// Its parent's world rotation in the free pose.
    pub parent_world: Quat,
    /// Its own world rotation in the free pose.
    pub world: Quat,
    /// 1: kept; 0: turned with the pelvis; between, slerped.
    pub weight: f64,
}

/// The joints, axes and free-pose world rotations one frame's posture changes act on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PostureFrame {
    /// Lateral, forward and up unit axes (file axes).
    axes: [V3; 3],
    /// Root joint.
    root: usize,
    /// Joints that keep their world rotation when the pelvis turns: the trunk, and the hips
    /// of swinging legs ([`Kept`]).
    kept: [Option<Kept>; 3],
    /// Bound of each pelvis turn (rad).
    bound: f64,
}

impl PostureFrame {
    /// The frame of a free pose: hips `hips` (left, right; file), up axis `up` (file, unit),
    /// the root, the joints that keep their world rotation ([`Kept`]: the trunk, and the hip
    /// of each leg by how little its foot is held), and the bound of the pelvis turns (rad).
    pub fn new(
        hips: [V3; 2],
        up: V3,
        root: usize,
        kept: [Option<Kept>; 3],
        bound: f64,
    ) -> PostureFrame {
        let d: V3 = std::array::from_fn(|i| hips[0][i] - hips[1][i]);
        let h = dot(d, up);
        let lat: V3 = std::array::from_fn(|i| d[i] - h * up[i]);
        let n = norm(lat);
        let lat = if n > 0.0 {
            lat.map(|v| v / n)
        } else {
            // Hips on a vertical line: any horizontal axis (a degenerate pose, no reach gain).
            let a = if up[0].abs() < 0.9 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            };
            let c = cross(up, a);
            let m = norm(c);
            c.map(|v| v / m)
        };
        let fwd = cross(lat, up);
        PostureFrame {
            axes: [lat, fwd, up],
            root,
            kept,
            bound,
        }
    }

    /// Applies posture `x` to the free pose's local rotations `q` (in place): the root
    /// turned by `R_p = R_up(θ₂) R_fwd(θ₁) R_lat(θ₀)` about its own position, the kept joints
    /// keeping their world rotation by their weight `w`
    /// (`q_t = slerp(q_t, (R_p W_parent)⁻¹ W_t, w)`).
    pub fn apply(&self, x: &Posture, q: &mut [Quat]) {
        if x.iter().all(|&v| v == 0.0) {
            return;
        }
        let [lat, fwd, up] = self.axes;
        let b = self.bound;
        let rp = rot::mul(
            rot::axis_angle(up, x[2] * b),
            rot::mul(
                rot::axis_angle(fwd, x[1] * b),
                rot::axis_angle(lat, x[0] * b),
            ),
        );
        q[self.root] = rot::normalize(rot::mul(rp, q[self.root]));
        for k in self.kept.iter().flatten() {
            let parent = rot::mul(rp, k.parent_world);
            let back = rot::normalize(rot::mul(rot::conj(parent), k.world));
            q[k.joint] = if k.weight >= 1.0 {
                back
            } else {
                rot::slerp(q[k.joint], back, k.weight.max(0.0))
            };
        }
    }
}

/// One active row of the least-squares step: `∂s/∂x` (m) and the wanted `J·y` (m).
pub type Row = (Posture, f64);

/// The damped least-squares step `y = Jᵀ (J Jᵀ + λ² I)⁻¹ t` over at most two rows, inside
/// the box `lo ≤ y ≤ hi`: a DOF the step pushes past its bound is fixed at the bound, its
/// share moved to the targets, and the rest solved again (at most [`N_DOF`] rounds).
pub fn dls_step(rows: &[Row], lambda: f64, lo: &Posture, hi: &Posture) -> Posture {
    let mut y = POSTURE_ZERO;
    let mut fixed = [false; N_DOF];
    for _ in 0..=N_DOF {
        let t: Vec<f64> = rows
            .iter()
            .map(|(j, t)| {
                t - (0..N_DOF)
                    .filter(|&d| fixed[d])
                    .map(|d| j[d] * y[d])
                    .sum::<f64>()
            })
            .collect();
        let jf: Vec<Posture> = rows
            .iter()
            .map(|(j, _)| std::array::from_fn(|d| if fixed[d] { 0.0 } else { j[d] }))
            .collect();
        let z = solve_small(&jf, &t, lambda * lambda);
        let mut clamped = false;
        let free: Vec<usize> = (0..N_DOF).filter(|&d| !fixed[d]).collect();
        for d in free {
            let v: f64 = jf.iter().zip(&z).map(|(j, z)| j[d] * z).sum();
            y[d] = v.clamp(lo[d], hi[d]);
            if y[d] != v {
                fixed[d] = true;
                clamped = true;
            }
        }
        if !clamped {
            break;
        }
    }
    y
}

/// `z = (J Jᵀ + μ I)⁻¹ t` for one or two rows (Cramer's rule); zeros for more rows or a
/// singular system.
fn solve_small(j: &[Posture], t: &[f64], mu: f64) -> Vec<f64> {
    let g = |a: usize, b: usize| dot_n(&j[a], &j[b]);
    match j.len() {
        1 => {
            let a = g(0, 0) + mu;
            vec![if a > 0.0 { t[0] / a } else { 0.0 }]
        }
        2 => {
            let (a, b, d) = (g(0, 0) + mu, g(0, 1), g(1, 1) + mu);
            let det = a * d - b * b;
            if det > 0.0 {
                vec![(d * t[0] - b * t[1]) / det, (a * t[1] - b * t[0]) / det]
            } else {
                vec![0.0; 2]
            }
        }
        n => vec![0.0; n],
    }
}

fn dot_n(a: &Posture, b: &Posture) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The solved postures of consecutive frames `xs` (frame time `dt`, s), ramped in and out
/// over `ramp_s` (s): per DOF, the largest positive value `x_j⁺ κ(t_i − t_j)` minus the
/// largest negative one, `κ(τ) = 1 − smoothstep(|τ| / ramp_s)`, so the result is at least
/// the solved value wherever one sign dominates, reaches zero `ramp_s` away from every
/// solved posture, and is continuous in time.
pub fn envelope(xs: &[Posture], dt: f64, ramp_s: f64) -> Vec<Posture> {
    let w = if dt > 0.0 {
        (ramp_s / dt).ceil() as usize
    } else {
        0
    };
    let kappa = |n: usize| {
        if ramp_s <= 0.0 {
            return if n == 0 { 1.0 } else { 0.0 };
        }
        let u = (n as f64 * dt / ramp_s).clamp(0.0, 1.0);
        1.0 - u * u * (3.0 - 2.0 * u)
    };
    let nonzero: Vec<usize> = (0..xs.len())
        .filter(|&j| xs[j].iter().any(|&v| v != 0.0))
        .collect();
    // Positive and negative envelopes per DOF, then their difference.
    let mut pos = vec![POSTURE_ZERO; xs.len()];
    let mut neg = vec![POSTURE_ZERO; xs.len()];
    for &j in &nonzero {
        for i in j.saturating_sub(w)..(j + w + 1).min(xs.len()) {
            let k = kappa(i.abs_diff(j));
            for d in 0..N_DOF {
                let v = xs[j][d] * k;
                pos[i][d] = pos[i][d].max(v);
                neg[i][d] = neg[i][d].max(-v);
            }
        }
    }
    pos.iter()
        .zip(&neg)
        .map(|(p, n)| std::array::from_fn(|d| p[d] - n[d]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dls_step_meets_one_row_with_the_minimum_norm_change() {
        let j = [0.02, -0.01, 0.03];
        let y = dls_step(&[(j, -0.01)], 0.0, &[-1.0; N_DOF], &[1.0; N_DOF]);
        // Undamped, one row, no bound active: J·y = t, and y is parallel to J.
        assert!((dot_n(&j, &y) + 0.01).abs() < 1e-12, "{y:?}");
        let s = y[0] / j[0];
        for d in 0..N_DOF {
            assert!((y[d] - s * j[d]).abs() < 1e-12, "{y:?}");
        }
    }

    #[test]
    fn dls_step_moves_a_clamped_share_to_the_other_dofs() {
        let j = [0.02, 0.0, 0.02];
        // Unbounded the step would be 1.0 on each DOF (over the 0.5 bound).
        let hi = [0.5, 1.0, 1.0];
        let y = dls_step(&[(j, -0.04)], 0.0, &[-1.0; N_DOF], &[1.0; N_DOF]);
        assert!(
            (y[0] + 1.0).abs() < 1e-12 && (y[2] + 1.0).abs() < 1e-12,
            "{y:?}"
        );
        let y = dls_step(&[(j, 0.03)], 0.0, &[-1.0; N_DOF], &hi);
        assert_eq!(y[0], 0.5);
        assert!((dot_n(&j, &y) - 0.03).abs() < 1e-12, "{y:?}");
    }

    #[test]
    fn envelope_ramps_in_and_out_and_keeps_the_solved_peak() {
        let dt = 0.01;
        let mut xs = vec![POSTURE_ZERO; 41];
        xs[20] = [0.5, -0.2, 0.0];
        xs[21] = [0.3, 0.0, 0.0];
        let e = envelope(&xs, dt, 0.1);
        assert_eq!(e[20], xs[20]);
        assert!(e[21][0] >= xs[21][0]);
        // Zero a ramp away, monotone on each side.
        assert_eq!(e[9], POSTURE_ZERO);
        assert_eq!(e[32], POSTURE_ZERO);
        for i in 10..20 {
            assert!(
                e[i][0] >= e[i - 1][0] && e[i][1] <= e[i - 1][1],
                "frame {i}"
            );
        }
    }

    #[test]
    fn pelvis_turns_under_a_trunk_and_a_free_leg_that_keep_their_world_orientation() {
        // Root 0, trunk 1 and a swinging hip 3 (through a hip link 2) below the root, a
        // planted hip 4; Z up, hips along ±y: lateral +y.
        let up = [0.0, 0.0, 1.0];
        let q_root = rot::axis_angle([0.0, 0.0, 1.0], 0.3);
        let q_trunk = rot::axis_angle([0.0, 1.0, 0.0], 0.2);
        let q_link = rot::axis_angle([1.0, 0.0, 0.0], 0.1);
        let q_hip = rot::axis_angle([0.0, 1.0, 0.0], -0.6);
        let q_planted = rot::axis_angle([0.0, 1.0, 0.0], 0.4);
        let w_trunk = rot::mul(q_root, q_trunk);
        let w_link = rot::mul(q_root, q_link);
        let w_hip = rot::mul(w_link, q_hip);
        let fr = PostureFrame::new(
            [[0.0, 0.1, 0.0], [0.0, -0.1, 0.0]],
            up,
            0,
            [
                Some(Kept {
                    joint: 1,
                    parent_world: q_root,
                    world: w_trunk,
                    weight: 1.0,
                }),
                Some(Kept {
                    joint: 3,
                    parent_world: w_link,
                    world: w_hip,
                    weight: 1.0,
                }),
                None,
            ],
            10f64.to_radians(),
        );
        let mut q = vec![q_root, q_trunk, q_link, q_hip, q_planted];
        fr.apply(&[0.7, -0.4, 1.0], &mut q);
        // The root turned; the trunk's and the free hip's world rotations are the free
        // pose's, while the planted leg turns with the pelvis (its IK places it after).
        assert!(rot::angle_deg(q[0], q_root) > 5.0);
        let w = rot::mul(q[0], q[1]);
        assert!(
            rot::angle_deg(w, w_trunk) < 1e-9,
            "{}",
            rot::angle_deg(w, w_trunk)
        );
        let w = rot::mul(rot::mul(q[0], q[2]), q[3]);
        // acos near 1: a few 1e-6° of round-off.
        assert!(
            rot::angle_deg(w, w_hip) < 1e-5,
            "{}",
            rot::angle_deg(w, w_hip)
        );
        // Half kept: halfway between turned with the pelvis and kept.
        let mut half = fr;
        half.kept[1] = half.kept[1].map(|k| Kept { weight: 0.5, ..k });
        let mut q = vec![q_root, q_trunk, q_link, q_hip, q_planted];
        half.apply(&[0.7, -0.4, 1.0], &mut q);
        let w = rot::mul(rot::mul(q[0], q[2]), q[3]);
        let turned = rot::mul(rot::mul(q[0], q_link), q_hip);
        let (to_kept, to_turned) = (rot::angle_deg(w, w_hip), rot::angle_deg(w, turned));
        assert!(
            to_kept > 1.0 && (to_kept - to_turned).abs() < 1e-6,
            "{to_kept} {to_turned}"
        );
        let w = rot::mul(q[0], q[4]);
        assert!(rot::angle_deg(w, rot::mul(q_root, q_planted)) > 5.0);
    }
}
