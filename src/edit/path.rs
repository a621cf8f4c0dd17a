//! The planned COM path: scaled stances in closed form, ballistic flights, chained apex to
//! apex with continuous position and velocity.
//!
//! # Model
//! ```text
//! stance k, local time s = t − t0_k ∈ [0, T_k] from its start apex, τ = (s − t_TD)/Δt:
//!   E_a(s) = 0                                  s ≤ t_TD          (flight before)
//!          = (Δt²/m) F2_a(τ)                    t_TD ≤ s ≤ t_LO   (stance, closed form)
//!          = P_a + J_a (s − t_LO)               s ≥ t_LO          (flight after)
//!   h(s) = vs·s + β_h E_h(s),   p(s) = vps·s + β_p E_p(s),   v(s) = zs − g s²/2 + β_v E_v(s)
//!   c(t) = o_k + h(s) e_h,k + p(s) e_p,k + (z_c,k + v(s)) e_z      (o_k horizontal)
//! chaining: o_{k+1} = c_k(T_k) horizontally, t0_{k+1} = t0_k + T_k,
//!   e_h,{k+1} = unit horizontal ċ_k(T_k)  (the heading is the touchdown velocity),
//!   and the request of k+1 starts with vs = |ċ_k(T_k)|, vps = 0, zs + z_c = ze_k + z_c,k
//! ```
//! With that request the joint is exact: the flight between two stances is one parabola of
//! curvature −g, its position and velocity continuous at the apex where the stances meet.
//! A stance may carry the recording's detail `d(u)` (`edit::detail`): added to `(h, p, v)`
//! in stance, `d(1)` after liftoff; where it joins a planned flight it is 0 with zero
//! velocity (touchdown) or has zero velocity (liftoff), so the joins above stay exact and
//! the flights ballistic. A jump's landing is chained in its own heading instead
//! ([`PlannedStance::chain_in_own_heading`]), starting with the flight's velocity.
//!
//! # Frames and units
//! World: metres, seconds, internal Z-up frame. Stance axes `h, p, v` (index 0, 1, 2).

use super::detail::StanceDetail;
use crate::force_model::{ForceModel, GRAVITY};

use crate::math::v3::V3;

/// One stance of the plan, solved and placed in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedStance {
    /// Index of the source stance (in the caller's list).
    pub source: usize,
    /// The (character-scaled) force model.
    pub model: ForceModel,
    /// `(β_h, β_p, β_v)`.
    pub beta: [f64; 3],
    /// Start-apex height above `z_c` (m), heading and perpendicular speeds (m/s).
    pub zs: f64,
    /// Start-apex heading velocity (m/s).
    pub vs: f64,
    /// Start-apex perpendicular velocity (m/s).
    pub vps: f64,
    /// Touchdown, liftoff and end-apex times from the start apex (s).
    pub t_td: f64,
    /// Liftoff time from the start apex (s).
    pub t_lo: f64,
    /// End-apex time `T` (s).
    pub t_e: f64,
    /// Contact height (m).
    pub z_c: f64,
    /// Contact point relative to the COM at touchdown, stance axes `(h, p)` (m).
    pub cp: [f64; 2],
    /// World time of the start apex (s).
    pub t0: f64,
    /// World horizontal position of the start apex `(x, y)` (m).
    pub origin: [f64; 2],
    /// Unit heading `e_h` in world `(x, y)`.
    pub heading: [f64; 2],
    /// The recording's detail added to the model's path (`None`: the model's path alone).
    pub detail: Option<StanceDetail>,
}

impl PlannedStance {
    /// `(E_a(s), Ė_a(s))` of axis `a` at local time `s` (m, m/s).
    fn e(&self, a: usize, s: f64) -> (f64, f64) {
        let m = &self.model;
        let (dt, mass) = (m.dt_s, m.mass_kg);
        if s <= self.t_td {
            (0.0, 0.0)
        } else if s < self.t_lo {
            let tau = (s - self.t_td) / dt;
            let ax = &m.axes[a];
            (dt * dt / mass * ax.f2(tau), dt / mass * ax.f1(tau))
        } else {
            let ax = &m.axes[a];
            let (p, j) = (dt * dt / mass * ax.f2(1.0), dt / mass * ax.f1(1.0));
            (p + j * (s - self.t_lo), j)
        }
    }

    /// The detail `(d, ḋ)` at local time `s` (m, m/s; zero before touchdown).
    fn detail_at(&self, s: f64) -> (V3, V3) {
        match &self.detail {
            Some(d) if s > self.t_td => {
                let span = self.t_lo - self.t_td;
                let u = if span > 0.0 {
                    (s - self.t_td) / span
                } else {
                    1.0
                };
                let (p, dp) = d.at(u);
                let rate = if span > 0.0 { 1.0 / span } else { 0.0 };
                (p, dp.map(|x| x * rate))
            }
            _ => ([0.0; 3], [0.0; 3]),
        }
    }

    /// COM position and velocity in stance axes `(h, p, v)` at local time `s` (v: height
    /// above `z_c`), the detail included.
    pub fn local(&self, s: f64) -> (V3, V3) {
        let b = self.beta;
        let (eh, dh) = self.e(0, s);
        let (ep, dp) = self.e(1, s);
        let (ev, dv) = self.e(2, s);
        let (d, dd) = self.detail_at(s);
        (
            [
                self.vs * s + b[0] * eh + d[0],
                self.vps * s + b[1] * ep + d[1],
                self.zs - 0.5 * GRAVITY * s * s + b[2] * ev + d[2],
            ],
            [
                self.vs + b[0] * dh + dd[0],
                self.vps + b[1] * dp + dd[1],
                -GRAVITY * s + b[2] * dv + dd[2],
            ],
        )
    }

    /// A stance-axes vector `(h, p, v)` in the world frame.
    pub fn to_world(&self, l: V3) -> V3 {
        let [hx, hy] = self.heading;
        [hx * l[0] - hy * l[1], hy * l[0] + hx * l[1], l[2]]
    }

    /// A world vector in stance axes `(h, p, v)` (the inverse of [`Self::to_world`]).
    pub fn to_local(&self, w: V3) -> V3 {
        let [hx, hy] = self.heading;
        [hx * w[0] + hy * w[1], -hy * w[0] + hx * w[1], w[2]]
    }

    /// World COM position and velocity at world time `t` (m, m/s).
    pub fn com(&self, t: f64) -> (V3, V3) {
        let (p, v) = self.local(t - self.t0);
        let w = self.to_world(p);
        (
            [
                self.origin[0] + w[0],
                self.origin[1] + w[1],
                self.z_c + w[2],
            ],
            self.to_world(v),
        )
    }

    /// World touchdown and liftoff times (s).
    pub fn contact_window(&self) -> (f64, f64) {
        (self.t0 + self.t_td, self.t0 + self.t_lo)
    }

    /// World end-apex time (s).
    pub fn end(&self) -> f64 {
        self.t0 + self.t_e
    }

    /// The planned contact point in the world: COM at touchdown plus `cp`, at `z_c` (m).
    pub fn contact_point(&self) -> V3 {
        let (c, _) = self.com(self.t0 + self.t_td);
        let d = self.to_world([self.cp[0], self.cp[1], 0.0]);
        [c[0] + d[0], c[1] + d[1], self.z_c]
    }

    /// Places the next stance at this one's end apex: its `t0`, origin and heading
    /// (the horizontal velocity there); returns the start speed `|ċ_h|` it must request.
    pub fn chain(&self, next: &mut PlannedStance) -> f64 {
        let v = self.start_next(next);
        let speed = v[0].hypot(v[1]);
        next.heading = if speed > 0.0 {
            [v[0] / speed, v[1] / speed]
        } else {
            self.heading
        };
        speed
    }

    /// Starts `next` at this stance's end apex (its `t0` and horizontal origin); returns the
    /// world COM velocity there.
    fn start_next(&self, next: &mut PlannedStance) -> V3 {
        let (c, v) = self.com(self.end());
        next.t0 = self.end();
        next.origin = [c[0], c[1]];
        v
    }

    /// Places the next stance of a jump at this one's end apex in its own heading (the
    /// landing keeps the heading it was recorded with, as the liftoff does, so the body
    /// turns between them as it did in the recording): its `t0` and origin, and its start
    /// velocities `(vs, vps)` the flight's velocity there in its axes, so the join is C¹.
    /// The jump query shares one apex speed `u_apex` along the liftoff's heading; a
    /// landing recorded a few degrees off that heading starts with those components of it
    /// (and of a start drift the liftoff keeps, `vps1` with `β_p1 = 0`).
    pub fn chain_in_own_heading(&self, next: &mut PlannedStance) {
        let w = self.start_next(next);
        let v = next.to_local(w);
        next.vs = v[0];
        next.vps = v[1];
    }
}

/// Which part of the plan a time falls in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Between touchdown and liftoff of stance `k`.
    Stance(usize),
    /// In the air after stance `before` (if any) and before stance `after` (if any).
    Flight {
        /// The stance whose liftoff starts the flight.
        before: Option<usize>,
        /// The stance whose touchdown ends it.
        after: Option<usize>,
    },
    /// Before the first touchdown of a jump: the recording's own frames before its liftoff
    /// stance (the rest it starts from, [`ComPath::lead_in_s`]).
    Rest,
}

/// The whole planned path: stances in time order, chained.
#[derive(Debug, Clone, PartialEq)]
pub struct ComPath {
    /// The stances, each placed by [`PlannedStance::chain`] from the one before.
    pub stances: Vec<PlannedStance>,
    /// First planned time (s): the first apex of a run, the first touchdown of a jump.
    pub t_start: f64,
    /// Last output time (s).
    pub t_end: f64,
    /// The recording written before `t_start`, s (a jump's lead-in,
    /// [`crate::edit::LEAD_IN_S`]; 0 for a run). Output starts at `t_start − lead_in_s`,
    /// rounded to whole output frames.
    pub lead_in_s: f64,
}

impl ComPath {
    /// The stance whose apex-to-apex window holds `t` (the first or last outside).
    pub fn owner(&self, t: f64) -> usize {
        self.stances
            .iter()
            .position(|s| t < s.end())
            .unwrap_or(self.stances.len().saturating_sub(1))
    }

    /// World COM position and velocity at `t`.
    pub fn com(&self, t: f64) -> (V3, V3) {
        self.stances[self.owner(t)].com(t)
    }

    /// The phase of time `t` ([`Phase::Rest`] before `t_start`).
    pub fn phase(&self, t: f64) -> Phase {
        if t < self.t_start {
            return Phase::Rest;
        }
        for (k, s) in self.stances.iter().enumerate() {
            let (td, lo) = s.contact_window();
            if t < td {
                return Phase::Flight {
                    before: k.checked_sub(1),
                    after: Some(k),
                };
            }
            if t <= lo {
                return Phase::Stance(k);
            }
        }
        Phase::Flight {
            before: self.stances.len().checked_sub(1),
            after: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::force_model::AxisModel;

    fn stance(fh: f64, fv: f64) -> PlannedStance {
        PlannedStance {
            source: 0,
            model: ForceModel {
                mass_kg: 70.0,
                dt_s: 0.25,
                axes: [
                    AxisModel::constant(fh),
                    AxisModel::constant(0.0),
                    AxisModel::constant(fv),
                ],
            },
            beta: [1.0; 3],
            zs: 1.0,
            vs: 3.0,
            vps: 0.0,
            t_td: 0.1,
            t_lo: 0.35,
            t_e: 0.45,
            z_c: 0.0,
            cp: [0.1, 0.0],
            t0: 0.0,
            origin: [0.0, 0.0],
            heading: [1.0, 0.0],
            detail: None,
        }
    }

    #[test]
    fn constant_force_stance_matches_the_textbook_parabolas() {
        // f_h = 70 N, f_v = 1400 N on 70 kg: a_h = 1, a_v = 20 − g in stance (exact).
        let s = stance(70.0, 1400.0);
        for &t in &[0.05, 0.1, 0.2, 0.35, 0.4] {
            let (p, v) = s.com(t);
            let u = (t - 0.1f64).clamp(0.0, 0.25);
            let after = (t - 0.35f64).max(0.0);
            let h = 3.0 * t + 0.5 * u * u + 0.25 * after;
            let z = 1.0 - 0.5 * GRAVITY * t * t + 10.0 * u * u + 5.0 * after;
            // Closed forms of constant forces: roundoff only (1e-12 m).
            assert!(
                (p[0] - h).abs() < 1e-12 && (p[2] - z).abs() < 1e-12,
                "t = {t}"
            );
            assert!((v[0] - (3.0 + u)).abs() < 1e-12);
        }
    }

    #[test]
    fn a_detail_keeps_the_joins_smooth_and_the_flight_after_ballistic() {
        // ρ: 2 cm forward, 1 cm sideways, 1.5 cm up over the stance, with a bump.
        let u: Vec<f64> = (0..=24).map(|i| i as f64 / 24.0).collect();
        let rho: Vec<V3> = u
            .iter()
            .map(|&x| {
                let b = (std::f64::consts::PI * x).sin();
                [0.02 * x + 0.005 * b, 0.01 * x * x, 0.015 * x + 0.004 * b]
            })
            .collect();
        let plain = stance(20.0, 1400.0);
        let s = PlannedStance {
            detail: StanceDetail::from_samples(&u, &rho),
            ..plain.clone()
        };
        let end = s.detail.as_ref().unwrap().end_offset();
        let (h, eps) = (1e-6, 1e-9);
        for &t in &[s.t_td, s.t_lo] {
            let ((p0, v0), (p1, v1)) = (s.com(t - eps), s.com(t + eps));
            for a in 0..3 {
                // Continuous value and slope: differences of O(eps·|c̈|) only.
                assert!(
                    (p1[a] - p0[a]).abs() < 1e-7 && (v1[a] - v0[a]).abs() < 1e-6,
                    "t = {t}"
                );
            }
        }
        // Before touchdown the model's path; after liftoff the model's plus d(1), a
        // constant: same velocity, curvature −g (second difference, roundoff ~1e-4 m/s²).
        let (pa, va) = (s.com(0.05), plain.com(0.05));
        assert_eq!(pa, va);
        for &t in &[0.37, 0.42] {
            let ((p, v), (q, w)) = (s.com(t), plain.com(t));
            let off = s.to_world(end);
            for a in 0..3 {
                assert!((p[a] - q[a] - off[a]).abs() < 1e-12 && (v[a] - w[a]).abs() < 1e-12);
            }
            let z = |t: f64| s.com(t).0[2];
            let acc = (z(t + h) - 2.0 * z(t) + z(t - h)) / (h * h);
            assert!((acc + GRAVITY).abs() < 1e-3, "flight curvature {acc}");
        }
        // Heights end where the model's do.
        assert!(end[2].abs() < 1e-15 && (end[0] - 0.02).abs() < 1e-12);
    }

    #[test]
    fn a_jump_chain_keeps_the_next_heading_and_carries_the_flight_velocity() {
        // A liftoff that ends its apex with a sideways drift (vp ≠ 0), a landing recorded
        // 90° off its heading: the landing keeps its heading, starts with the flight's
        // velocity in its axes, and the plan is continuous in position and velocity at
        // the apex.
        let mut a = stance(20.0, 1400.0);
        a.vps = 0.1;
        let mut b = PlannedStance {
            heading: [0.0, 1.0],
            ..stance(-20.0, 1400.0)
        };
        a.chain_in_own_heading(&mut b);
        let t = a.end();
        let (pa, va) = a.com(t);
        b.zs = pa[2] - b.z_c;
        let (pb, vb) = b.com(t);
        assert_eq!(b.heading, [0.0, 1.0]);
        // a's heading is +x: its end velocity (vx, 0.1) is (0.1, −vx) in b's axes.
        assert!((b.vs - 0.1).abs() < 1e-12, "vs {}", b.vs);
        assert!((b.vps + va[0]).abs() < 1e-12, "vps {}", b.vps);
        // Horizontal position and velocity (the height is the request's `zs`, set above;
        // the fixture's end is not a true apex, so its vertical velocity is not b's 0).
        for i in 0..2 {
            assert!(
                (pa[i] - pb[i]).abs() < 1e-12 && (va[i] - vb[i]).abs() < 1e-12,
                "axis {i}"
            );
        }
    }

    #[test]
    fn chained_stances_join_with_continuous_position_and_velocity() {
        let a = stance(20.0, 1400.0);
        let mut b = PlannedStance {
            heading: [0.0, 1.0],
            ..stance(-20.0, 1400.0)
        };
        let speed = a.chain(&mut b);
        b.vs = speed;
        let t = a.end();
        let (pa, va) = a.com(t);
        let (pb, vb) = b.com(t);
        b.zs = pa[2] - b.z_c;
        let (pb2, _) = b.com(t);
        for i in 0..2 {
            assert!((pa[i] - pb[i]).abs() < 1e-12 && (va[i] - vb[i]).abs() < 1e-12);
        }
        assert!((pa[2] - pb2[2]).abs() < 1e-12);
        // Finite-difference velocity inside the stance: central step 1e-5 s, error O(h²·ȧ).
        let h = 1e-5;
        let (p1, _) = a.com(0.2 + h);
        let (p0, _) = a.com(0.2 - h);
        let (_, v) = a.com(0.2);
        assert!(((p1[2] - p0[2]) / (2.0 * h) - v[2]).abs() < 1e-6);
    }
}
