//! Local floor heights (spec com-from-bvh §7.1).
//!
//! # Model
//! ```text
//! m(k)       = min(z_TTIP,L(k), z_TTIP,R(k))
//! z_g(k)     = P₅{ m(i) : |t_i − t_k| ≤ T_floor }                  ground_z
//! foot point: floor_p(k) = P₅{ z_p(i) : same window }, or z_g(k) + clearance_p when
//!             floor_p(k) − z_g(k) > 0.15 m·(L_leg/0.84)
//! hand point: floor_p(k) = z_g(k) + clearance_p
//! h_p(k)     = z_p(k) − floor_p(k)
//! clearances (× L_leg/0.84): ankle 0.08, TTIP 0.01, wrist 0.04, MET3 0.02 m
//! ```

use crate::math::stats::running_percentile;

/// Floor percentile.
pub const FLOOR_PERCENTILE: f64 = 5.0;
/// A foot point whose own floor is this far above the ground never reached it, m (× L/0.84).
pub const FOOT_FLOOR_MAX_ABOVE_GROUND: f64 = 0.15;
/// Nominal clearance of the ankle above the floor in contact, m.
pub const CLEARANCE_ANKLE: f64 = 0.08;
/// Nominal clearance of the toe tip, m.
pub const CLEARANCE_TTIP: f64 = 0.01;
/// Nominal clearance of the wrist, m.
pub const CLEARANCE_WRIST: f64 = 0.04;
/// Nominal clearance of MET3, m.
pub const CLEARANCE_MET3: f64 = 0.02;

/// Half-window in frames: the largest `h` with `h·dt ≤ T_floor`.
pub fn half_window(dt: f64, t_floor: f64) -> usize {
    ((t_floor / dt) + 1e-9).floor().clamp(0.0, 1e12) as usize
}

/// Ground height `z_g` per frame from the two toe tips' heights.
pub fn ground(ttip_l: &[f64], ttip_r: &[f64], half: usize) -> Vec<f64> {
    let m: Vec<f64> = ttip_l.iter().zip(ttip_r).map(|(a, b)| a.min(*b)).collect();
    running_percentile(&m, half, FLOOR_PERCENTILE)
}

/// Height above its own floor of a foot point (`z`: its heights, m).
pub fn foot_heights(
    z: &[f64],
    ground: &[f64],
    half: usize,
    clearance: f64,
    scale: f64,
) -> Vec<f64> {
    let own = running_percentile(z, half, FLOOR_PERCENTILE);
    z.iter()
        .zip(own.iter().zip(ground))
        .map(|(zp, (f, g))| {
            let floor = if f - g > FOOT_FLOOR_MAX_ABOVE_GROUND * scale {
                g + clearance * scale
            } else {
                *f
            };
            zp - floor
        })
        .collect()
}

/// Height above its floor of a hand point.
pub fn hand_heights(z: &[f64], ground: &[f64], clearance: f64, scale: f64) -> Vec<f64> {
    z.iter()
        .zip(ground)
        .map(|(zp, g)| zp - (g + clearance * scale))
        .collect()
}
