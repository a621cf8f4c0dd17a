//! Contact detection: local floors, per-effector hysteresis with minimum durations, the
//! optional static (elevated) contact mode, and the flight fits of the airborne runs.
//!
//! Data flow: contact-point trajectories (metres, Z up) → [`floor`] heights →
//! [`detect`] flags per effector → [`flight`] diagnostics of the no-contact runs.

pub mod detect;
pub mod flight;
pub mod floor;
pub mod options;
pub mod support;
pub mod timing;

pub use options::ContactOptions;

/// Support effectors, in output order.
pub const EFFECTORS: [&str; 4] = ["left_foot", "right_foot", "left_hand", "right_hand"];

/// Maximal runs `(first, last)` (inclusive indices) where `flags` is true.
pub fn runs(flags: &[bool]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, &f) in flags.iter().enumerate() {
        match (f, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push((s, i - 1));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s, flags.len() - 1));
    }
    out
}

/// Unsmoothed 3-D speed by central differences (one-sided at the ends), m/s
/// (spec com-from-bvh §6): `v(k) = |p(k+1) − p(k−1)|·F/2`.
pub fn raw_speed(p: &[[f64; 3]], dt: f64) -> Vec<f64> {
    let n = p.len();
    let d = |a: usize, b: usize| {
        let v: [f64; 3] = std::array::from_fn(|i| p[a][i] - p[b][i]);
        (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
    };
    (0..n)
        .map(|k| match (k, n) {
            (_, 0 | 1) => 0.0,
            (0, _) => d(1, 0) / dt,
            (k, n) if k == n - 1 => d(k, k - 1) / dt,
            (k, _) => d(k + 1, k - 1) / (2.0 * dt),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_and_speeds() {
        assert_eq!(
            runs(&[false, true, true, false, true]),
            vec![(1, 2), (4, 4)]
        );
        assert!(runs(&[]).is_empty());
        let p: Vec<[f64; 3]> = (0..5).map(|i| [i as f64 * 0.1, 0.0, 0.0]).collect();
        assert!(raw_speed(&p, 0.1).iter().all(|v| (v - 1.0).abs() < 1e-12));
    }
}
