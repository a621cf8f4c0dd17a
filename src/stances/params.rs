//! Heading frame and the six stance parameters (spec stance-model §2, §3).
//!
//! # Model
//! ```text
//! e_v = (0,0,1);  e_h = v_TD,xy/|v_TD,xy| if |v_TD,xy| ≥ 0.2 m/s, else the facing direction
//!                 from the hips, else the previous stance's e_h, else +X;  e_p = e_v × e_h
//! R_s = [e_h; e_p; e_v] (rows): stance-frame vector = R_s · world vector
//! t_TD = −vz_TD/g,  zs = z_TD + vz_TD²/(2g),  vs = v_TD·e_h,  vps = v_TD·e_p
//! model-consistent liftoff (β = 1):
//!   v_LO = v_TD + (J_h, J_p, J_v − gΔt)
//!   p_LO − p_TD = v_TD Δt + (0, 0, −½gΔt²) + (P_h, P_p, P_v)
//! e = vz_LO/g,  ze = z_LO + vz_LO²/(2g),  ve = v_LO·e_h,  vp = v_LO·e_p
//! x = vs·t_TD + (p_LO − p_TD)·e_h + ve·e,   t_LO = t_TD + Δt,   t_E = t_LO + e
//! ```
//! Heights are above the contact height `z_c`; times are from the start apex.
//!
//! # References
//! spec stance-model §2, §3 (normative: model-consistent parameters).

use crate::math::constants::GRAVITY;
/// Below this horizontal touchdown speed the heading comes from the hips, m/s.
pub const V_MIN_HEADING: f64 = 0.2;

pub use crate::math::heading::{Heading, HeadingFrom};
use crate::math::v3::V3;

fn horizontal_unit(v: V3) -> Option<V3> {
    let n = v[0].hypot(v[1]);
    (n > 1e-9).then(|| [v[0] / n, v[1] / n, 0.0])
}

/// Choose the heading (spec §2).
pub fn heading(v_td: V3, facing: V3, previous: Option<V3>) -> Heading {
    if v_td[0].hypot(v_td[1]) >= V_MIN_HEADING {
        if let Some(e_h) = horizontal_unit(v_td) {
            return Heading {
                e_h,
                from: HeadingFrom::Velocity,
            };
        }
    }
    if let Some(e_h) = horizontal_unit(facing) {
        return Heading {
            e_h,
            from: HeadingFrom::Hips,
        };
    }
    match previous {
        Some(e_h) => Heading {
            e_h,
            from: HeadingFrom::Previous,
        },
        None => Heading {
            e_h: [1.0, 0.0, 0.0],
            from: HeadingFrom::WorldX,
        },
    }
}

/// The stance parameters of §3 (heights above `z_c`, times from the start apex).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StanceParams {
    /// Start-apex height, m.
    pub zs: f64,
    /// Start-apex heading velocity, m/s.
    pub vs: f64,
    /// End-apex height, m.
    pub ze: f64,
    /// End-apex heading velocity, m/s.
    pub ve: f64,
    /// End-apex perpendicular velocity, m/s.
    pub vp: f64,
    /// Start-apex perpendicular velocity, m/s.
    pub vps: f64,
    /// Heading distance from start apex to end apex, m.
    pub x: f64,
    /// COM height above `z_c` at touchdown, m.
    pub z_td: f64,
    /// COM height above `z_c` at liftoff, m.
    pub z_lo: f64,
    /// Touchdown time from the start apex, s.
    pub t_td: f64,
    /// Liftoff time from the start apex, s.
    pub t_lo: f64,
    /// End-apex time from the start apex, s.
    pub t_e: f64,
}

/// Parameters from a touchdown state and a liftoff displacement and velocity, all in stance
/// axes (`dp` = p_LO − p_TD, `v_lo`), with `z_td` above the contact height.
pub fn from_states(v_td: V3, z_td: f64, dp: V3, v_lo: V3, dt: f64) -> StanceParams {
    let t_td = -v_td[2] / GRAVITY;
    let zs = z_td + v_td[2] * v_td[2] / (2.0 * GRAVITY);
    let z_lo = z_td + dp[2];
    let e = v_lo[2] / GRAVITY;
    let ze = z_lo + v_lo[2] * v_lo[2] / (2.0 * GRAVITY);
    let x = v_td[0] * t_td + dp[0] + v_lo[0] * e;
    StanceParams {
        zs,
        vs: v_td[0],
        ze,
        ve: v_lo[0],
        vp: v_lo[1],
        vps: v_td[1],
        x,
        z_td,
        z_lo,
        t_td,
        t_lo: t_td + dt,
        t_e: t_td + dt + e,
    }
}

/// Model-consistent parameters (β = 1): the liftoff state from `J` and `P` of the force
/// model (§3, §5). `v_td` in stance axes.
pub fn model_consistent(v_td: V3, z_td: f64, j: V3, p: V3, dt: f64) -> StanceParams {
    let v_lo = [
        v_td[0] + j[0],
        v_td[1] + j[1],
        v_td[2] + j[2] - GRAVITY * dt,
    ];
    let dp = [
        v_td[0] * dt + p[0],
        v_td[1] * dt + p[1],
        v_td[2] * dt - 0.5 * GRAVITY * dt * dt + p[2],
    ];
    from_states(v_td, z_td, dp, v_lo, dt)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ballistic_hop_has_consistent_apices() {
        // Touchdown descending at 1 m/s, heading speed 3 m/s; a force that exactly reverses
        // the vertical velocity with zero net displacement offset (J_v = 2 + gΔt).
        let dt = 0.2;
        let j = [0.0, 0.0, 2.0 + GRAVITY * dt];
        // P_v for a constant force: J_v·Δt/2.
        let p = [0.0, 0.0, j[2] * dt / 2.0];
        let s = model_consistent([3.0, 0.0, -1.0], 0.9, j, p, dt);
        assert!((s.t_td - 1.0 / GRAVITY).abs() < 1e-12);
        assert!((s.zs - (0.9 + 1.0 / (2.0 * GRAVITY))).abs() < 1e-12);
        // Symmetric stance: liftoff at the touchdown height, rising at 1 m/s.
        assert!((s.z_lo - s.z_td).abs() < 1e-12 && (s.ze - s.zs).abs() < 1e-12);
        assert!((s.x - 3.0 * (2.0 / GRAVITY + dt)).abs() < 1e-12);
        assert!((s.t_e - (2.0 / GRAVITY + dt)).abs() < 1e-12);
    }

    #[test]
    fn heading_falls_back_in_order() {
        assert_eq!(
            heading([0.0, 2.0, -1.0], [1.0, 0.0, 0.0], None).from,
            HeadingFrom::Velocity
        );
        assert_eq!(
            heading([0.0, 0.1, 0.0], [0.0, -1.0, 0.0], None).e_h,
            [0.0, -1.0, 0.0]
        );
        assert_eq!(
            heading([0.0, 0.1, 0.0], [0.0, 0.0, 0.0], Some([0.0, 1.0, 0.0])).from,
            HeadingFrom::Previous
        );
        assert_eq!(heading([0.0; 3], [0.0; 3], None).from, HeadingFrom::WorldX);
        let h = heading([0.0, 2.0, 0.0], [0.0; 3], None);
        // e_p points to the character's left: heading +Y → e_p = −X.
        assert_eq!(h.to_stance([-1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
    }
}
