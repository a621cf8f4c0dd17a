//! Flight fits of the no-contact runs, the ballistic test and the effective time scale.
//!
//! # Model
//! ```text
//! no-contact run a..b not touching a clip edge; interior a+2 … b−2, n_int = b − a − 3
//! n_int ≥ 4:  x(t), y(t) lines, z(t) = ½ a_z t² + v t + z₀ (free curvature);
//!             horizontal curvatures a_x, a_y from parabolas of x(t), y(t)
//! n_int 2–3:  same with a_z fixed at −g;  n_int < 2: no fit
//! s_eff = sqrt(|a_z|/g)  (a_z < 0)
//! ballistic ⇔ n·dt ≤ 1.0 s ∧ curvature ∈ [−2g, −g/2], curvature = a_z (n_int ≥ 4) or
//!             ā_z = (v_z(b+1) − v_z(a−1)) / (t_{b+1} − t_{a−1})   (SG velocity)
//! airborne ⇔ n·dt ≥ 0.1 s − 1 µs ∧ n·dt ≤ 1.0 s ∧ n_int ≥ 4
//! a_z_all: curvature of the free parabola of z(t) over every frame inside the interval
//!          (n ≥ 5): frames a … b, or, given the sub-frame liftoff before it and
//!          touchdown after it (contacts::timing), the frames strictly between them; the
//!          physics cross-check's measure (contacts::support)
//! clip s_eff = median s_eff over airborne runs with a_z < 0; flight_az_median likewise of a_z
//! ```
//!
//! # Frames and units
//! COM in metres (Z up), times in seconds, accelerations in m/s².
//!
//! # References
//! spec com-from-bvh §7.7.

use super::contact_runs::ContactRun;
use super::{runs, ClipMotion};
use crate::math::polyfit::{fit, fit_fixed_curvature, Poly};
use crate::math::stats::median;

pub use crate::math::constants::GRAVITY as G;
/// Longest flight, s.
pub const T_FLIGHT_MAX_S: f64 = 1.0;
/// Shortest airborne interval, s.
pub const AIRBORNE_MIN_S: f64 = 0.1;
/// Tolerance on the airborne length (0.1 s at 120 Hz is 0.0999996 s), s.
pub const AIRBORNE_TOL_S: f64 = 1e-6;

/// The ballistic model of one flight: `ĉ(t)` per axis.
#[derive(Debug, Clone, PartialEq)]
pub struct FlightFit {
    /// x(t), y(t), z(t).
    pub axes: [Poly; 3],
}

impl FlightFit {
    /// Fitted position at `t`.
    pub fn position(&self, t: f64) -> [f64; 3] {
        std::array::from_fn(|i| self.axes[i].eval(t))
    }

    /// Fitted velocity at `t`.
    pub fn velocity(&self, t: f64) -> [f64; 3] {
        std::array::from_fn(|i| self.axes[i].deriv(t))
    }
}

/// Diagnostics of one no-contact run not touching a clip edge.
#[derive(Debug, Clone, PartialEq)]
pub struct Flight {
    /// First frame of the run (file row index).
    pub first_frame: i64,
    /// Last frame of the run (file row index).
    pub last_frame: i64,
    /// `n·dt`, s.
    pub duration_s: f64,
    /// Fitted vertical curvature (free fit only), m/s².
    pub a_z: Option<f64>,
    /// Horizontal curvature along x (free fit only), m/s².
    pub a_x: Option<f64>,
    /// Horizontal curvature along y (free fit only), m/s².
    pub a_y: Option<f64>,
    /// Residual RMS of |c − ĉ| over the interior, m.
    pub rms_m: Option<f64>,
    /// Effective time scale (free fit with a_z < 0).
    pub s_eff: Option<f64>,
    /// Vertical curvature of a free parabola over every frame inside the run (at least 5;
    /// between the sub-frame events when they are known, [`curvature_inside`]), m/s²: the
    /// measure of the physics cross-check ([`crate::contacts::support`]). The interior
    /// fit (`a_z`) leaves out two frames at each end; on a 0.1 s running flight that is 8
    /// frames of 12 and ±3 m/s² of scatter.
    pub a_z_all: Option<f64>,
    /// Sub-frame duration `t_TD − t_LO` between the liftoff that opens the run and the
    /// touchdown that closes it ([`crate::contacts::timing`]), s; `None` when either is
    /// unknown.
    pub events_duration_s: Option<f64>,
    /// The sub-frame liftoff and touchdown `(t_LO, t_TD)` that bound the run (clip time,
    /// s), when both are known: the frames strictly between them are certainly airborne.
    pub events_s: Option<(f64, f64)>,
    /// Mean SG vertical acceleration across an untested run, m/s².
    pub a_z_mean: Option<f64>,
    /// Passes the ballistic test.
    pub ballistic: bool,
    /// Free-curvature fit available (n_int ≥ 4).
    pub tested: bool,
    /// Airborne interval (counts for the clip's s_eff).
    pub airborne: bool,
    /// The fitted ballistic model, when n_int ≥ 2.
    pub fit: Option<FlightFit>,
}

/// Fit one no-contact run `a..=b` (kept-frame indices) of the raw COM `c` at times `t`,
/// with SG vertical velocity `vz`. `frame0` converts kept indices to file rows.
pub fn fit_run(
    c: &[[f64; 3]],
    t: &[f64],
    vz: &[f64],
    a: usize,
    b: usize,
    dt: f64,
    frame0: i64,
) -> Flight {
    let n = b - a + 1;
    let duration_s = n as f64 * dt;
    let int: Vec<usize> = if b >= a + 4 {
        (a + 2..=b - 2).collect()
    } else {
        Vec::new()
    };
    let ti: Vec<f64> = int.iter().map(|&k| t[k]).collect();
    let axis = |ax: usize| -> Vec<f64> { int.iter().map(|&k| c[k][ax]).collect() };
    let n_int = int.len();
    let mut f = Flight {
        first_frame: frame0 + a as i64,
        last_frame: frame0 + b as i64,
        duration_s,
        a_z: None,
        a_x: None,
        a_y: None,
        rms_m: None,
        s_eff: None,
        a_z_all: None,
        events_duration_s: None,
        events_s: None,
        a_z_mean: None,
        ballistic: false,
        tested: n_int >= 4,
        airborne: false,
        fit: None,
    };
    let lines = (fit(&ti, &axis(0), 1), fit(&ti, &axis(1), 1));
    let zfit = if n_int >= 4 {
        fit(&ti, &axis(2), 2)
    } else {
        fit_fixed_curvature(&ti, &axis(2), -G)
    };
    if let ((Some(x), Some(y)), Some(z)) = (lines, zfit) {
        if n_int >= 2 {
            let ff = FlightFit { axes: [x, y, z] };
            let ss: f64 = int
                .iter()
                .map(|&k| {
                    let p = ff.position(t[k]);
                    (0..3).map(|i| (c[k][i] - p[i]).powi(2)).sum::<f64>()
                })
                .sum();
            if n_int >= 4 {
                let az = ff.axes[2].curvature();
                f.a_z = Some(az);
                f.rms_m = Some((ss / n_int as f64).sqrt());
                f.s_eff = (az < 0.0).then(|| (az.abs() / G).sqrt());
                f.a_x = fit(&ti, &axis(0), 2).map(|p| p.curvature());
                f.a_y = fit(&ti, &axis(1), 2).map(|p| p.curvature());
            }
            f.fit = Some(ff);
        }
    }
    f.a_z_all = curvature_inside(c, t, a, b, None);
    let curvature = if f.tested {
        f.a_z
    } else if a >= 1 && b + 1 < t.len() {
        let m = (vz[b + 1] - vz[a - 1]) / (t[b + 1] - t[a - 1]);
        f.a_z_mean = Some(m);
        Some(m)
    } else {
        None
    };
    f.ballistic = duration_s <= T_FLIGHT_MAX_S
        && curvature.is_some_and(|k| (-2.0 * G..=-0.5 * G).contains(&k));
    f.airborne =
        (AIRBORNE_MIN_S - AIRBORNE_TOL_S..=T_FLIGHT_MAX_S).contains(&duration_s) && f.tested;
    f
}

/// Vertical curvature of the free parabola of the raw COM height over the frames of the
/// no-contact run `a..=b`, m/s²; with `events = Some((t_lo, t_td))` (the sub-frame
/// liftoff that opens it and touchdown that closes it) over the frames strictly between
/// the two instead. `None` with fewer than 5 frames.
pub fn curvature_inside(
    c: &[[f64; 3]],
    t: &[f64],
    a: usize,
    b: usize,
    events: Option<(f64, f64)>,
) -> Option<f64> {
    let ks: Vec<usize> = match events {
        None => (a..=b).collect(),
        Some((lo, td)) => (0..t.len()).filter(|&k| t[k] > lo && t[k] < td).collect(),
    };
    if ks.len() < 5 {
        return None;
    }
    let tk: Vec<f64> = ks.iter().map(|&k| t[k]).collect();
    let zk: Vec<f64> = ks.iter().map(|&k| c[k][2]).collect();
    fit(&tk, &zk, 2).map(|p| p.curvature())
}

/// Flights (§7.7) of the clip's no-contact runs not at a clip edge (no effector in
/// `contact` on any frame of the run), each with the curvature between the sub-frame
/// liftoff and touchdown that bound it (from the contact runs `runs_out`, when both are
/// known).
pub fn flights(
    contact: &[Vec<bool>; 4],
    runs_out: &[ContactRun],
    motion: &ClipMotion,
) -> Vec<Flight> {
    let (com, time_s, frame) = (motion.com, motion.time_s, motion.frame);
    let n = frame.len();
    let none: Vec<bool> = (0..n).map(|f| !contact.iter().any(|c| c[f])).collect();
    runs(&none)
        .into_iter()
        .filter(|&(a, b)| a > 0 && b + 1 < n)
        .map(|(a, b)| {
            let mut f = fit_run(com, time_s, motion.com_vz, a, b, motion.dt, frame[0]);
            let lo = runs_out
                .iter()
                .filter(|r| r.last_frame == frame[a - 1])
                .filter_map(|r| r.lo_time_s)
                .reduce(f64::max);
            let td = runs_out
                .iter()
                .filter(|r| r.first_frame == frame[b + 1])
                .filter_map(|r| r.td_time_s)
                .reduce(f64::min);
            if let (Some(lo), Some(td)) = (lo, td) {
                f.a_z_all = curvature_inside(com, time_s, a, b, Some((lo, td))).or(f.a_z_all);
                f.events_duration_s = Some(td - lo);
                f.events_s = Some((lo, td));
            }
            f
        })
        .collect()
}

/// Clip summary: (median s_eff, median a_z) over airborne runs with a_z < 0.
pub fn clip_summary(flights: &[Flight]) -> (Option<f64>, Option<f64>) {
    let air: Vec<&Flight> = flights
        .iter()
        .filter(|f| f.airborne && f.a_z.is_some_and(|a| a < 0.0))
        .collect();
    let s: Vec<f64> = air.iter().filter_map(|f| f.s_eff).collect();
    let az: Vec<f64> = air.iter().filter_map(|f| f.a_z).collect();
    (median(&s), median(&az))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_exact_parabola_is_ballistic_with_unit_time_scale() {
        let dt = 1.0 / 120.0;
        let t: Vec<f64> = (0..60).map(|k| k as f64 * dt).collect();
        let c: Vec<[f64; 3]> = t
            .iter()
            .map(|&t| [2.0 * t, 0.1, 1.0 + 2.0 * t - 0.5 * G * t * t])
            .collect();
        let vz: Vec<f64> = t.iter().map(|&t| 2.0 - G * t).collect();
        let f = fit_run(&c, &t, &vz, 10, 40, dt, 1);
        assert!(f.tested && f.ballistic && f.airborne);
        assert!((f.a_z.unwrap() + G).abs() < 1e-8);
        assert!(f.a_x.unwrap().abs() < 1e-8);
        assert!((f.s_eff.unwrap() - 1.0).abs() < 1e-9);
        assert_eq!((f.first_frame, f.last_frame), (11, 41));
        let v = f.fit.as_ref().unwrap().velocity(t[12]);
        assert!((v[2] - vz[12]).abs() < 1e-8 && (v[0] - 2.0).abs() < 1e-9);
        let short = fit_run(&c, &t, &vz, 10, 13, dt, 0);
        assert!(!short.tested && short.ballistic && (short.a_z_mean.unwrap() + G).abs() < 1e-9);
        assert_eq!(
            clip_summary(&[f]).0.map(|s| (s - 1.0).abs() < 1e-9),
            Some(true)
        );
    }
}
