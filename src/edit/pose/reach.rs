//! The reach IK: each pulled foot moved towards its goal by analytic two-bone IK of its leg
//! ([`place_feet`]), turned about its toe tip where the goal is beyond the leg's soft
//! reach, and the posture's reach step where a support leg still falls short
//! ([`reach_update`]).
//!
//! # Model
//! ```text
//! pull       goal = A + w_h·(ankle* − A)_h + w_v·(ankle* − A)_z,  orientation slerped by w_v
//!            (A: the ankle FK gives, [w_h, w_v]: the foot's Pull, goals)
//! toe pivot  beyond the soft reach ρ(|ankle* − H|): turn the foot about its toe tip T,
//!            heel up, by the smallest φ ≤ φ_max with |ankle*(φ) − H| = ρ (pivot_angle)
//!            ρ(d) = d for d ≤ d₀, else d₀ + (R − d₀)·tanh((d − d₀)/(R − d₀)),
//!            R = min(max_reach·(l₁ + l₂), √(l₁² + l₂² + 2 l₁ l₂ cos κ_min)),
//!            d₀ = min(R, max(soft_reach·(l₁ + l₂), |A_ref − H|))
//! knee       rotate the shank about n = (H − K) × (A − K) to |A − H| = |ankle* − H|
//! hip        the smallest rotation taking A − H onto ankle* − H
//! posture    s_k = |G_k − H_k − (c_plan − c)| − R_k: support leg k's shortfall after the
//!            coming root shift (G_k: its goal after the pivot, R_k: the knee's reach R at
//!            κ_min − POSTURE_KNEE_SLACK_DEG, at least 0);
//!            where one is positive, the damped least-squares step of edit::posture
//!            brings it to −tol (J_kd = ∂s_k/∂x_d by finite differences, once per frame)
//! ```
//!
//! # Frames and units
//! IK in file units and axes; shortfalls, COM and tolerances in metres, internal Z-up frame.

use super::goals::{FrameGoal, Pull};
use super::joints::{forward, turn_world, up_file, PoseWorkspace};
use super::reference::Reference;
use crate::edit::posture::{self, Posture, PostureFrame, Row, N_DOF, POSTURE_ZERO};
use crate::edit::rotation::{self as rot, Quat};
use crate::edit::EditOptions;
use crate::math::v3::{add, cross, dot, flexion_deg, norm, sub, V3};

/// One IK pass of the feet (step 2 of [`pose_frame`](super::frame::pose_frame)): each
/// pulled ankle goes part way ([`Pull`]) from where FK puts it towards its goal, by
/// two-bone IK and the goal orientation; `ws` is left with FK of the result. Returns the
/// largest distance of a planted (support) foot from its goal (m) and each pulled ankle's
/// goal after the toe pivot (file).
pub(super) fn place_feet(
    r: &Reference,
    ws: &mut PoseWorkspace,
    pulls: &[Option<(V3, Quat, Pull)>; 2],
    planted: [bool; 2],
    opts: &EditOptions,
) -> (f64, [Option<V3>; 2]) {
    let body = &r.body;
    let max_reach = opts.max_reach;
    let up = up_file(body);
    let goal: [Option<(V3, Quat)>; 2] = std::array::from_fn(|side| {
        pulls[side].map(|(p, q, [wh, wv])| {
            let ankle = r.legs[side][2];
            let (fp, fq) = (ws.file[ankle], ws.world_q[ankle]);
            // Part way from the reference foot: `wh` horizontally, `wv` vertically and in
            // orientation.
            let d = sub(p, fp);
            let dv = dot(d, up);
            let pos = std::array::from_fn(|i| fp[i] + wh * (d[i] - dv * up[i]) + wv * dv * up[i]);
            let (pos, q) = toe_pivot(r, ws, side, (pos, rot::slerp(fq, q, wv)), opts);
            if planted[side] {
                (pos, q)
            } else {
                (swing_reach(r, ws, side, pos, wv, opts), q)
            }
        })
    });
    for (side, g) in goal.iter().enumerate() {
        if let Some((p, _)) = *g {
            two_bone(r, ws, side, p, max_reach);
            forward(r, &ws.pose, &mut ws.world_q, &mut ws.file, &mut ws.pts);
        }
    }
    for (side, g) in goal.iter().enumerate() {
        if let Some((_, o)) = *g {
            let ankle = r.legs[side][2];
            let parent = body.skeleton.parents[ankle].map_or(rot::QUAT_IDENTITY, |p| ws.world_q[p]);
            ws.pose.q[ankle] = rot::normalize(rot::mul(rot::conj(parent), o));
        }
    }
    forward(r, &ws.pose, &mut ws.world_q, &mut ws.file, &mut ws.pts);
    // Support feet only: a swing foot may be out of reach and is not planted.
    let err = (0..2)
        .filter(|&side| planted[side])
        .filter_map(|side| goal[side].map(|(p, _)| norm(sub(ws.file[r.legs[side][2]], p))))
        .fold(0.0, f64::max)
        * body.unit_m;
    (err, goal.map(|g| g.map(|(p, _)| p)))
}

/// The reach step's state within one frame: the posture on top of the base, and the
/// Jacobian of the support legs' shortfalls (computed once, when a shortfall first shows).
pub(super) struct ReachState {
    pub(super) y: Posture,
    pub(super) jac: Option<[Posture; 2]>,
}

/// Where the current iteration stands: its posture frame, posture `x`, the pivoted ankle
/// goals (file) and the pose's COM (m).
pub(super) struct ReachAt<'a> {
    pub(super) frame: &'a PostureFrame,
    pub(super) x: &'a Posture,
    pub(super) goals: &'a [Option<V3>; 2],
    pub(super) com_pose: V3,
}

/// One reach step ([`posture`]): the support legs' shortfalls after the coming root
/// shift, `s_k = |G_k − H_k − (c_plan − c)| − R_k` (m), and when one is positive the damped
/// least-squares posture that brings them to `−tol` (Jacobian by finite differences, once
/// per frame). Returns whether the posture moved (a support ankle by more than the solve
/// tolerance); `ws` keeps FK of the current pose.
pub(super) fn reach_update(
    r: &Reference,
    opts: &EditOptions,
    g: &FrameGoal,
    at: &ReachAt,
    st: &mut ReachState,
    ws: &mut PoseWorkspace,
) -> bool {
    let body = &r.body;
    let shift = sub(g.com, at.com_pose);
    let rows: [Option<(f64, V3, V3)>; 2] = std::array::from_fn(|k| {
        let goal = at.goals[k].filter(|_| g.planted[k])?;
        let [hip, knee, ankle] = r.legs[k];
        let (h, kn, a) = (ws.file[hip], ws.file[knee], ws.file[ankle]);
        let kappa = (opts.min_knee_flexion_deg - POSTURE_KNEE_SLACK_DEG).max(0.0);
        let reach = knee_reach([norm(sub(h, kn)), norm(sub(a, kn))], opts.max_reach, kappa);
        let reach = reach * body.unit_m;
        let hip_m = ws.pts[hip];
        let v = sub(sub(body.to_internal(goal), hip_m), shift);
        let d = norm(v);
        (d > 0.0).then(|| (d - reach, v.map(|c| c / d), hip_m))
    });
    let tol = opts.com_solve_tol_m;
    if st.jac.is_none() {
        if !rows.iter().flatten().any(|row| row.0 > tol) {
            return false;
        }
        st.jac = Some(reach_jacobian(r, opts, g, at, &rows, ws));
    }
    let Some(jac) = st.jac else { return false };
    let active: Vec<Row> = (0..2)
        .filter_map(|k| {
            let s0 = rows[k]?.0 - dot_dof(&jac[k], &st.y);
            (s0 > 0.0).then_some((jac[k], -tol - s0))
        })
        .collect();
    let y = if active.is_empty() {
        POSTURE_ZERO
    } else {
        posture::dls_step(&active, posture::DAMPING_M, &[-1.0; N_DOF], &[1.0; N_DOF])
    };
    let dy: Posture = std::array::from_fn(|d| y[d] - st.y[d]);
    let change = (0..2)
        .filter(|&k| rows[k].is_some())
        .map(|k| dot_dof(&jac[k], &dy).abs())
        .fold(0.0, f64::max);
    let moved = change > tol;
    if moved {
        st.y = y;
    }
    moved
}

fn dot_dof(a: &Posture, b: &Posture) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `∂s_k/∂x_d` of the support legs' shortfalls at posture `at.x` (m per unit of `x`):
/// each DOF stepped by [`posture::FD_STEP`], FK, foot IK and COM again, and the hip's move
/// after the root shift, `ΔH − Δc`, projected on the leg's direction `u_k` (`rows`:
/// shortfall, `u_k`, hip in m). `ws` is left with the pose it was given.
fn reach_jacobian(
    r: &Reference,
    opts: &EditOptions,
    g: &FrameGoal,
    at: &ReachAt,
    rows: &[Option<(f64, V3, V3)>; 2],
    ws: &mut PoseWorkspace,
) -> [Posture; 2] {
    ws.other.q.copy_from_slice(&ws.pose.q);
    let mut jac = [POSTURE_ZERO; 2];
    for d in 0..posture::N_DOF {
        let mut xd = *at.x;
        xd[d] += posture::FD_STEP;
        ws.pose.q.copy_from_slice(&ws.free_q);
        at.frame.apply(&xd, &mut ws.pose.q);
        forward(r, &ws.pose, &mut ws.world_q, &mut ws.file, &mut ws.pts);
        place_feet(r, ws, &g.pulls, g.planted, opts);
        let dc = sub(r.body.com(&ws.pts), at.com_pose);
        for (k, row) in rows.iter().enumerate() {
            if let Some((_, u, h)) = *row {
                let dh = sub(sub(ws.pts[r.legs[k][0]], h), dc);
                jac[k][d] = -dot(u, dh) / posture::FD_STEP;
            }
        }
    }
    ws.pose.q.copy_from_slice(&ws.other.q);
    forward(r, &ws.pose, &mut ws.world_q, &mut ws.file, &mut ws.pts);
    jac
}

/// Leg `side` as FK left it in `ws` (the reference leg, before IK): its hip (file) and
/// where its soft reach starts and ends (file units; [`soft_reach`]): from
/// `opts.soft_reach` of thigh plus shank, or the leg's own extension if longer, to the
/// knee's reach `R = min(max_reach·(l₁ + l₂), √(l₁² + l₂² + 2 l₁ l₂ cos κ_min))`
/// (`κ_min = opts.min_knee_flexion_deg`; the toe pivot takes the rest).
fn leg_reach(r: &Reference, ws: &PoseWorkspace, side: usize, opts: &EditOptions) -> (V3, f64, f64) {
    let [hip, knee, ankle] = r.legs[side];
    let (h, k, a) = (ws.file[hip], ws.file[knee], ws.file[ankle]);
    let (l1, l2) = (norm(sub(h, k)), norm(sub(a, k)));
    let hard = knee_reach([l1, l2], opts.max_reach, opts.min_knee_flexion_deg);
    (
        h,
        (opts.soft_reach * (l1 + l2)).max(norm(sub(a, h))).min(hard),
        hard,
    )
}

/// The knee's reach of a leg with thigh and shank `l` (any unit) at flexion `kappa_deg`:
/// `R = min(max_reach·(l₁ + l₂), √(l₁² + l₂² + 2 l₁ l₂ cos κ))`, the hip-to-ankle distance
/// at which the knee is as straight as it may be.
fn knee_reach(l: [f64; 2], max_reach: f64, kappa_deg: f64) -> f64 {
    let [l1, l2] = l;
    let bent = (l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * kappa_deg.to_radians().cos())
        .max(0.0)
        .sqrt();
    (max_reach * (l1 + l2)).min(bent)
}

/// How much straighter than the toe pivot's bound (`opts.min_knee_flexion_deg`) a support
/// knee may go before the pelvis turns to keep it ([`reach_update`]), degrees: with the
/// posture check's 10° tolerance below the source's least flexion, the toe pivot keeps the
/// first 5° ([`RUN_KNEE_SLACK_DEG`](crate::edit::RUN_KNEE_SLACK_DEG)), the pelvis the next
/// 2.5° and the last 2.5° are left to frames out of reach even so. (A jump's bound is 0°:
/// its pelvis turns only for a leg that does not reach straight.) Measured on runs edited
/// to 5 m/s (issue 37): with the pelvis turning only for a leg out of reach straight, the
/// fixture landed and two runners pushed off up to 15° straighter than recorded (exit 1);
/// turning at the pivot's own bound (0° here) kept every knee in range but the turns'
/// ramps moved the root up to 8.7 g (3 → 5 m/s) and 12.5 g (fixture); at 2.5°, 6.2 and
/// 11.1 g.
pub const POSTURE_KNEE_SLACK_DEG: f64 = 2.5;

/// A swinging (not planted) ankle goal `p` (file) brought within the extension the leg has
/// at knee flexion `κ_b` of its hip, along the line to the hip (the foot rises and comes
/// forward with the body instead of the knee straightening past the reference's):
///
/// ```text
/// κ_ref = π − ∠(H − K, A − K)                   the reference leg's knee flexion (free pose)
/// κ_b   = w κ_min + (1 − w) max(κ_min, κ_ref − s)   w: the foot's hold near its contact
/// e(κ)  = √(l₁² + l₂² + 2 l₁ l₂ cos κ)           hip-to-ankle extension at flexion κ
/// p ← H + (p − H) · e(κ_b) / |p − H|             when |p − H| > e(κ_b)
/// ```
/// (`κ_min = opts.min_knee_flexion_deg`, `s` = [`RUN_KNEE_SLACK_DEG`](crate::edit::RUN_KNEE_SLACK_DEG)).
/// At the contact (`w = 1`) the bound is the stance's, so the goal is continuous through
/// liftoff and touchdown; away from it the knee straightens at most `s` beyond the
/// reference's. A run edited far above its recorded speed held the lifted foot near its
/// contact while the body moved on faster than recorded, and the knee locked through the
/// flight where the recording bends it to 51° (issue 37; `docs/edited-motion.md`).
fn swing_reach(
    r: &Reference,
    ws: &PoseWorkspace,
    side: usize,
    p: V3,
    w: f64,
    opts: &EditOptions,
) -> V3 {
    let [hip, knee, ankle] = r.legs[side];
    let (h, k, a) = (ws.file[hip], ws.file[knee], ws.file[ankle]);
    let (l1, l2) = (norm(sub(h, k)), norm(sub(a, k)));
    let d = norm(sub(p, h));
    if l1 == 0.0 || l2 == 0.0 || d == 0.0 {
        return p;
    }
    let kappa_ref = flexion_deg(h, k, a).to_radians();
    let kappa_min = opts.min_knee_flexion_deg.to_radians();
    let e = swing_extension([l1, l2], kappa_ref, kappa_min, w);
    if d <= e {
        return p;
    }
    std::array::from_fn(|i| h[i] + (p[i] - h[i]) * e / d)
}

/// `e(κ_b)` of [`swing_reach`]: the hip-to-ankle extension of a leg with thigh and shank
/// `l` (any unit) at the bound flexion `κ_b = w κ_min + (1 − w) max(κ_min, κ_ref − s)`
/// (rad; `w` clamped to `[0, 1]`).
fn swing_extension(l: [f64; 2], kappa_ref: f64, kappa_min: f64, w: f64) -> f64 {
    let free = kappa_min.max(kappa_ref - crate::edit::RUN_KNEE_SLACK_DEG.to_radians());
    let w = w.clamp(0.0, 1.0);
    let kappa = w * kappa_min + (1.0 - w) * free;
    let [l1, l2] = l;
    (l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * kappa.cos())
        .max(0.0)
        .sqrt()
}

/// The foot goal `(ankle, orientation)` (file frame) of leg `side`, turned about its
/// toe tip (heel up, [`pivot_angle`]) when the ankle is beyond the leg's soft reach
/// ([`leg_reach`]) from the hip; unchanged when it is within it or the leg has no toe
/// below its ankle.
fn toe_pivot(
    r: &Reference,
    ws: &PoseWorkspace,
    side: usize,
    goal: (V3, Quat),
    opts: &EditOptions,
) -> (V3, Quat) {
    let Some(tp) = r.toes[side] else { return goal };
    let ankle = r.legs[side][2];
    let (h, start, hard) = leg_reach(r, ws, side, opts);
    let a = ws.file[ankle];
    let (p, q) = goal;
    let d = norm(sub(p, h));
    let reach = soft_reach(d, start, hard);
    if d <= reach {
        return goal;
    }
    let toe_ankle = rot::rotate(rot::conj(ws.world_q[ankle]), sub(ws.file[tp], a));
    let toe = add(p, rot::rotate(q, toe_ankle));
    let axis = cross(up_file(&r.body), sub(toe, p));
    let n = norm(axis);
    if n == 0.0 {
        return goal;
    }
    let axis = axis.map(|v| v / n);
    let u = sub(p, toe);
    let phi = pivot_angle(toe, u, axis, h, reach, opts.max_toe_pivot_deg.to_radians());
    let turn = rot::axis_angle(axis, phi);
    (add(toe, rot::rotate(turn, u)), rot::mul(turn, q))
}

/// The leg's share `ρ(d)` of a hip-to-ankle distance `d` (any unit): `d` up to `start`,
/// then approaching `hard` smoothly, `start + (hard − start)·tanh((d − start)/(hard − start))`
/// (slope 1 and no curvature at `start`); `min(d, hard)` when `start ≥ hard`.
fn soft_reach(d: f64, start: f64, hard: f64) -> f64 {
    if d <= start {
        d
    } else if hard > start {
        start + (hard - start) * ((d - start) / (hard - start)).tanh()
    } else {
        d.min(hard)
    }
}

/// The smallest turn `φ ∈ [0, φ_max]` (rad) about `axis` (unit, ⟂ `u`) through the toe
/// tip `toe` that brings the ankle `toe + u` within `reach` of the hip `hip`:
/// ```text
/// ankle(φ) = T + u cos φ + (n × u) sin φ,   |ankle(φ) − H|² = R²
///   ⇔ A cos φ + B sin φ = C,  A = 2(T − H)·u,  B = 2(T − H)·(n × u),  C = R² − |T − H|² − |u|²
/// ```
/// the first root above 0; without one (the hip too far even from the nearest ankle
/// position) the turn to that nearest position; both capped at `φ_max`.
fn pivot_angle(toe: V3, u: V3, axis: V3, hip: V3, reach: f64, max_rad: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let th = sub(toe, hip);
    let w = cross(axis, u);
    let (a, b) = (2.0 * dot(th, u), 2.0 * dot(th, w));
    let c = reach * reach - dot(th, th) - dot(u, u);
    let m = a.hypot(b);
    if m == 0.0 {
        return 0.0;
    }
    let psi = b.atan2(a);
    let phi = if c / m >= -1.0 {
        let d = (c / m).min(1.0).acos();
        [psi - d, psi + d]
            .map(|x| x.rem_euclid(TAU))
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    } else {
        (psi + PI).rem_euclid(TAU)
    };
    if phi > PI {
        0.0
    } else {
        phi.min(max_rad)
    }
}

/// Analytic two-bone IK of one leg towards `target` (file frame): knee about its hinge,
/// then the hip by the smallest rotation. Reach is clamped to `max_reach` of the leg.
fn two_bone(r: &Reference, ws: &mut PoseWorkspace, side: usize, target: V3, max_reach: f64) {
    let [hip, knee, ankle] = r.legs[side];
    let (h, k, a) = (ws.file[hip], ws.file[knee], ws.file[ankle]);
    let (v1, v2) = (sub(h, k), sub(a, k));
    let (l1, l2) = (norm(v1), norm(v2));
    if l1 == 0.0 || l2 == 0.0 {
        return;
    }
    let lo = (l1 - l2).abs() * 1.001;
    let d = norm(sub(target, h)).clamp(lo, max_reach * (l1 + l2));
    let cur = (dot(v1, v2) / (l1 * l2)).clamp(-1.0, 1.0).acos();
    let want = ((l1 * l1 + l2 * l2 - d * d) / (2.0 * l1 * l2))
        .clamp(-1.0, 1.0)
        .acos();
    let c = cross(v1, v2);
    let n = if norm(c) > 1e-6 * l1 * l2 {
        let n = c.map(|v| v / norm(c));
        ws.knee_axis[side] = Some(n);
        n
    } else {
        ws.knee_axis[side].unwrap_or_else(|| rot::rotate(ws.world_q[knee], [1.0, 0.0, 0.0]))
    };
    let dk = rot::axis_angle(n, want - cur);
    turn_world(r, &mut ws.pose, &ws.world_q, knee, dk);
    let a2 = add(k, rot::rotate(dk, v2));
    let dh = rot::between(sub(a2, h), sub(target, h));
    turn_world(r, &mut ws.pose, &ws.world_q, hip, dh);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Law of cosines, independently: the ankle of a hip at the origin, a thigh along −z
    /// and a shank turned back by the flexion `k` (rad) in the x–z plane.
    fn extension_at(l1: f64, l2: f64, k: f64) -> f64 {
        let knee = [0.0, 0.0, -l1];
        let ankle = add(knee, [-l2 * k.sin(), 0.0, -l2 * k.cos()]);
        norm(ankle)
    }

    #[test]
    fn a_held_swing_foot_has_the_stance_bound_and_a_free_one_the_reference_knee_less_the_slack() {
        let (l1, l2) = (0.45, 0.42);
        let (k_ref, k_min) = (60f64.to_radians(), 10f64.to_radians());
        let slack = crate::edit::RUN_KNEE_SLACK_DEG.to_radians();
        // At the contact: the stance's bound.
        let held = swing_extension([l1, l2], k_ref, k_min, 1.0);
        assert!((held - extension_at(l1, l2, k_min)).abs() < 1e-12);
        // Away from it: the reference knee less the slack.
        let free = swing_extension([l1, l2], k_ref, k_min, 0.0);
        assert!((free - extension_at(l1, l2, k_ref - slack)).abs() < 1e-12);
        // Between: continuous and shorter as the hold fades; weights outside [0, 1] clamp.
        let mut last = held;
        for i in 1..=10 {
            let e = swing_extension([l1, l2], k_ref, k_min, 1.0 - f64::from(i) / 10.0);
            assert!(
                e < last && last - e <= 0.2 * (held - free),
                "{i}: {e} after {last}"
            );
            last = e;
        }
        assert_eq!(swing_extension([l1, l2], k_ref, k_min, 2.0), held);
        assert_eq!(swing_extension([l1, l2], k_ref, k_min, -1.0), free);
        // A reference straighter than the stance bound plus the slack adds nothing.
        let straight = swing_extension([l1, l2], k_min, k_min, 0.0);
        assert!((straight - held).abs() < 1e-12);
    }

    /// Ankle 8 cm above the floor, toe tip 19 cm ahead on it, Z up, pivot axis +y.
    const TOE: V3 = [0.19, 0.0, 0.0];
    const U: V3 = [-0.19, 0.0, 0.08];
    const AXIS: V3 = [0.0, 1.0, 0.0];

    fn ankle_at(phi: f64) -> V3 {
        add(TOE, rot::rotate(rot::axis_angle(AXIS, phi), U))
    }

    #[test]
    fn toe_pivot_puts_the_ankle_at_the_reach_with_the_heel_up() {
        let hip = [0.0, 0.0, 0.98];
        for reach in [0.88, 0.85, 0.8] {
            let phi = pivot_angle(TOE, U, AXIS, hip, reach, 50f64.to_radians());
            let a = ankle_at(phi);
            // Closed form against the quaternion rotation: roundoff (1e-12 m).
            assert!((norm(sub(a, hip)) - reach).abs() < 1e-12, "reach {reach}");
            assert!(phi > 0.0 && a[2] > U[2], "heel up: φ {phi}, ankle {a:?}");
            // The first root: every smaller turn leaves the ankle out of reach.
            assert!(norm(sub(ankle_at(0.999 * phi), hip)) > reach);
        }
    }

    #[test]
    fn toe_pivot_out_of_range_turns_to_the_nearest_ankle_or_the_cap() {
        let hip = [0.0, 0.0, 0.98];
        let cap = 50f64.to_radians();
        // 0.3 m: no turn reaches; the nearest ankle position lies past the cap.
        assert_eq!(pivot_angle(TOE, U, AXIS, hip, 0.3, cap), cap);
        let phi = pivot_angle(TOE, U, AXIS, hip, 0.3, std::f64::consts::PI);
        let d = |p: f64| norm(sub(ankle_at(p), hip));
        // The nearest point of the circle (sampled at 0.001 rad around it).
        assert!(
            d(phi) <= d(phi - 1e-3) && d(phi) <= d(phi + 1e-3),
            "φ {phi}"
        );
    }
}
