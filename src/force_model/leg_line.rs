//! The leg line: where a running stance's force points, from the stance foot and the COM
//! (a departure from the paper; docs `stance-model.md` §4.4).
//!
//! # Model
//! ```text
//! support point   s(τ) = a(τ) + φ τ (e(τ) − a(τ))     a: ankle, e: toe tip, φ: roll fraction
//! leg line        d(τ) = R_s (c(τ) − s(τ))            c: COM, R_s: stance axes (h, p, v)
//! slopes          g_h(τ) = d_h/d_v,   g_p(τ) = d_p/d_v                          (unit-free)
//! ratio data      s'_a(τ_j) = (1 − λ) s_a(τ_j) + λ f_v(τ_j) g_a(τ_j),   a = h, p      N
//! ```
//! The ratio model's `q_h`, `q_p` are then fitted to `s'` exactly as to the kinematic force
//! (load-weighted, impulse met, travel soft; [`super::ratio`]), so `λ = 0` is the kinematic
//! fit and `λ = 1` fits the ratio to the leg line alone.
//!
//! Why: the fore-aft force of the kinematic COM acceleration is about as far from the force
//! plates as the plate force varies (RMSE 69 / 102 / 132 N against a plate standard
//! deviation of 74 / 118 / 137 N on the runs at 2, 3 and 4 m/s: 3 mm of COM error at the
//! 4 Hz of a stance is 140 N), so a ratio fitted to it follows noise, and the friction demand
//! of the 20 % active set — the push-off's `|f_t|/f_v` — came out 0.54–1.08 times the
//! plates' depending on the clip. The direction of the force is far better known than its
//! horizontal size: a running leg pushes roughly along the line from the rolling foot to the
//! COM (the spring-mass picture), and the foot rolls from the ankle at touchdown towards the
//! ball at push-off. With `φ` and `λ` chosen by leaving one plate clip out (docs, §4.4) the
//! friction demand of every plate run is within 0.06 of the plates.
//!
//! # Frames and units
//! Positions in metres (world, Z up), times in seconds, slopes unit-free.

use crate::math::spline::NaturalSpline;
use crate::math::v3::V3;

/// Default roll fraction `φ` (fit option `roll_fraction`): at push-off the support point sits
/// this far from the ankle towards the toe tip (the ball of the foot lies at about 0.7);
/// chosen by leaving one plate run out (docs `stance-model.md` §4.4).
pub const DEFAULT_ROLL_FRACTION: f64 = 0.5;
/// Default weight `λ` of the leg line in the ratio data (fit option `leg_line_weight`);
/// chosen by leaving one plate run out (docs `stance-model.md` §4.4).
pub const DEFAULT_LEG_LINE_WEIGHT: f64 = 1.0;
/// Smallest height of the COM above the support point for a slope, m: below it (a crouch, a
/// hand stance, a skeleton in the wrong unit) the slope is not a leg's and the leg line is
/// not used.
pub const MIN_LEG_HEIGHT_M: f64 = 0.3;

/// One foot's ankle and toe tip per frame, and the COM, over clip time.
pub struct LegLine<'a> {
    /// Frame times, s (increasing).
    pub time_s: &'a [f64],
    /// Ankle centre per frame, m.
    pub ankle: &'a [V3],
    /// Toe tip per frame, m.
    pub toe: &'a [V3],
    /// COM position splines (x, y, z) over clip time, m.
    pub com: &'a [NaturalSpline; 3],
}

/// `v` at time `t` by linear interpolation between the frames around it (clamped at the ends).
fn at_time(time_s: &[f64], v: &[V3], t: f64) -> Option<V3> {
    let n = time_s.len().min(v.len());
    if n == 0 {
        return None;
    }
    let k = time_s[..n].partition_point(|&x| x <= t);
    if k == 0 {
        return Some(v[0]);
    }
    if k >= n {
        return Some(v[n - 1]);
    }
    let (t0, t1) = (time_s[k - 1], time_s[k]);
    let w = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
    Some(std::array::from_fn(|i| {
        v[k - 1][i] + w * (v[k][i] - v[k - 1][i])
    }))
}

impl LegLine<'_> {
    /// The slopes `g_h`, `g_p` at `τ_j` of a stance (`t = t_TD + Δt τ_j`) with roll fraction
    /// `φ`; `None` where the COM is less than [`MIN_LEG_HEIGHT_M`] above the support point
    /// or a value is not finite.
    pub fn slopes(
        &self,
        (t_td, dt): (f64, f64),
        r_s: &[[f64; 3]; 3],
        tau: &[f64],
        roll: f64,
    ) -> Option<[Vec<f64>; 2]> {
        let mut g: [Vec<f64>; 2] = Default::default();
        for &u in tau {
            let t = t_td + dt * u;
            let (a, e) = (
                at_time(self.time_s, self.ankle, t)?,
                at_time(self.time_s, self.toe, t)?,
            );
            let d: V3 =
                std::array::from_fn(|i| self.com[i].eval(t) - (a[i] + roll * u * (e[i] - a[i])));
            let ds: V3 =
                std::array::from_fn(|r| r_s[r][0] * d[0] + r_s[r][1] * d[1] + r_s[r][2] * d[2]);
            if ds.iter().any(|x| !x.is_finite()) || ds[2] < MIN_LEG_HEIGHT_M {
                return None;
            }
            g[0].push(ds[0] / ds[2]);
            g[1].push(ds[1] / ds[2]);
        }
        Some(g)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(t: &[f64], z: f64) -> [NaturalSpline; 3] {
        let sp = |f: &dyn Fn(f64) -> f64| {
            NaturalSpline::new(t, &t.iter().map(|&x| f(x)).collect::<Vec<_>>()).unwrap()
        };
        [sp(&|x| 3.0 * x), sp(&|_| 0.1), sp(&|_| z)]
    }

    #[test]
    fn a_com_passing_over_a_still_foot_gives_the_leg_angle() {
        // COM at 3 m/s, 1 m up, 0.1 m to the side of an ankle at the origin whose toe tip is
        // 0.2 m ahead: at τ the support point is 0.2 φ τ ahead, so g_h = (3t − 0.2φτ)/1.
        let t: Vec<f64> = (0..40).map(|k| k as f64 * 0.01).collect();
        let com = line(&t, 1.0);
        let ankle = vec![[0.0; 3]; t.len()];
        let toe = vec![[0.2, 0.0, 0.0]; t.len()];
        let leg = LegLine {
            time_s: &t,
            ankle: &ankle,
            toe: &toe,
            com: &com,
        };
        let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let tau = [0.0, 0.5, 1.0];
        let g = leg.slopes((0.05, 0.25), &eye, &tau, 0.7).unwrap();
        for (j, &u) in tau.iter().enumerate() {
            let want = 3.0 * (0.05 + 0.25 * u) - 0.2 * 0.7 * u;
            assert!(
                (g[0][j] - want).abs() < 1e-9,
                "τ {u}: {} vs {want}",
                g[0][j]
            );
            assert!((g[1][j] - 0.1).abs() < 1e-9);
        }
    }

    #[test]
    fn no_slope_below_a_legs_height() {
        let t: Vec<f64> = (0..10).map(|k| k as f64 * 0.01).collect();
        let com = line(&t, 0.2);
        let feet = vec![[0.0; 3]; t.len()];
        let leg = LegLine {
            time_s: &t,
            ankle: &feet,
            toe: &feet,
            com: &com,
        };
        let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(leg.slopes((0.0, 0.05), &eye, &[0.0, 1.0], 0.7).is_none());
    }
}
