//! Sampling a stance force model on its evaluation grid, in stance and world axes: the
//! rows of `stancelib forces`, for any model, through its evaluation interface only.
//!
//! # Model
//! ```text
//! τ_j = ForceModel::grid()[j]  (0 … 1, both ends)          t_j = td_clip_s + τ_j·dt_s
//! f_stance(τ) = (f_h, f_p, f_v) = (axes[0].eval(τ), axes[1].eval(τ), axes[2].eval(τ))
//! f_world = R_sᵀ · f_stance = f_h·e_h + f_p·e_p + f_v·e_v
//!         = f_h·(hx, hy, 0) + f_p·(−hy, hx, 0) + f_v·(0, 0, 1)
//! kinematic force (for comparison): f_kin = m·(a_com − g⃗) = m·(a_x, a_y, a_z + g)
//! ```
//! `R_s` (rows `e_h, e_p, e_v`) is [`Heading::rotation`]; the inverse map (world → stance,
//! `R_s · f`) is [`Heading::to_stance`]. For a unit heading the map is a rotation, so the
//! two triples have equal norms.
//!
//! # Frames and units
//! Stance axes `h, p, v` (spec stance-model §2), world axes right-handed with Z up; forces
//! in newtons (applied force on the body), times in seconds of clip time, `τ` unit-free.
//!
//! # References
//! spec stance-model §4.3 (grid), §11 (`td_clip_s`, `dt_s`, `heading_x`, `heading_y`).
//!
//! # Examples
//! ```
//! use stancelib::force_model::export::{sample_forces, StanceTimes};
//! use stancelib::force_model::{AxisModel, ForceModel};
//! use stancelib::stances::params::{Heading, HeadingFrom};
//! let model = ForceModel {
//!     mass_kg: 70.0,
//!     dt_s: 0.25,
//!     axes: [AxisModel::constant(100.0), AxisModel::constant(0.0), AxisModel::constant(700.0)],
//! };
//! let heading = Heading { e_h: [0.0, 1.0, 0.0], from: HeadingFrom::Velocity }; // running +Y
//! let rows = sample_forces(&model, StanceTimes { td_clip_s: 2.0, dt_s: 0.25 }, &heading);
//! assert_eq!(rows.len(), model.grid().len());
//! let last = rows.last().unwrap();
//! assert_eq!((last.tau, last.time_s), (1.0, 2.25));
//! assert_eq!(last.f_world, [0.0, 100.0, 700.0]); // the heading force points along +Y
//! ```

use super::{ForceModel, GRAVITY};
use crate::math::heading::Heading;

/// When a stance happened in its clip: the map `t = td_clip_s + τ·dt_s`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StanceTimes {
    /// Touchdown in clip time `td_clip_s`, s.
    pub td_clip_s: f64,
    /// Ground time `Δt`, s.
    pub dt_s: f64,
}

impl StanceTimes {
    /// Clip time of normalised stance time `τ`, s.
    pub fn time_s(&self, tau: f64) -> f64 {
        self.td_clip_s + tau * self.dt_s
    }
}

/// One sample of a stance's force model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceSample {
    /// Normalised stance time `τ ∈ [0, 1]`.
    pub tau: f64,
    /// Clip time `td_clip_s + τ·dt_s`, s.
    pub time_s: f64,
    /// `(f_h, f_p, f_v)` in stance axes, N.
    pub f_stance: [f64; 3],
    /// `(f_x, f_y, f_z)` in world axes (Z up), N.
    pub f_world: [f64; 3],
}

/// `R_sᵀ · f`: a stance-axes vector in world axes (Z up).
pub fn world_from_stance(heading: &Heading, f_stance: [f64; 3]) -> [f64; 3] {
    let r = heading.rotation();
    std::array::from_fn(|k| (0..3).map(|i| r[i][k] * f_stance[i]).sum())
}

/// The kinematic (applied) force `m·(a − g⃗) = m·(a_x, a_y, a_z + g)` of a COM
/// acceleration `a_world` (m/s², world axes, Z up), N: what Stage A samples (§4.1 step 3).
pub fn kinematic_force(mass_kg: f64, a_world: [f64; 3]) -> [f64; 3] {
    [
        mass_kg * a_world[0],
        mass_kg * a_world[1],
        mass_kg * (a_world[2] + GRAVITY),
    ]
}

/// The model's force at every point of its evaluation grid ([`ForceModel::grid`]), in
/// grid order (τ increasing from 0 to 1).
pub fn sample_forces(
    model: &ForceModel,
    times: StanceTimes,
    heading: &Heading,
) -> Vec<ForceSample> {
    model
        .grid()
        .into_iter()
        .map(|tau| {
            let f_stance = model.axes.each_ref().map(|a| a.eval(tau));
            ForceSample {
                tau,
                time_s: times.time_s(tau),
                f_stance,
                f_world: world_from_stance(heading, f_stance),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::force_model::AxisModel;
    use crate::math::heading::HeadingFrom;
    use crate::testkit::Rng;

    fn norm(v: [f64; 3]) -> f64 {
        v.iter().map(|x| x * x).sum::<f64>().sqrt()
    }

    #[test]
    fn world_and_stance_agree_both_ways_on_random_headings() {
        let mut rng = Rng::new(0x00f0_cee4);
        for _ in 0..200 {
            let psi = rng.uniform(0.0, std::f64::consts::TAU);
            let h = Heading {
                e_h: [psi.cos(), psi.sin(), 0.0],
                from: HeadingFrom::Velocity,
            };
            let f = [
                rng.uniform(-250.0, 250.0),
                rng.uniform(-100.0, 100.0),
                rng.uniform(0.0, 1500.0),
            ];
            let w = world_from_stance(&h, f);
            // The inverse map of the stance module returns f (roundoff of 2 products).
            let back = h.to_stance(w);
            for a in 0..3 {
                assert!((back[a] - f[a]).abs() < 1e-12 * (1.0 + f[a].abs()));
            }
            assert!((norm(w) - norm(f)).abs() < 1e-12 * norm(f));
            assert_eq!(w[2], f[2], "vertical is the same axis");
        }
    }

    #[test]
    fn samples_are_the_model_on_its_grid() {
        let model = ForceModel {
            mass_kg: 70.0,
            dt_s: 0.3,
            axes: [
                AxisModel {
                    c0: 20.0,
                    harmonics: vec![1.0],
                    amps: vec![150.0],
                    phases: vec![1.2],
                    ..Default::default()
                },
                AxisModel::constant(-5.0),
                AxisModel {
                    c0: 900.0,
                    harmonics: vec![1.0, 20.0],
                    amps: vec![700.0, 3.0],
                    phases: vec![std::f64::consts::PI, 0.0],
                    ..Default::default()
                },
            ],
        };
        let h = Heading {
            e_h: [0.6, -0.8, 0.0],
            from: HeadingFrom::Hips,
        };
        let times = StanceTimes {
            td_clip_s: 1.25,
            dt_s: 0.3,
        };
        let rows = sample_forces(&model, times, &h);
        let grid = model.grid();
        assert_eq!(rows.len(), grid.len());
        assert_eq!(grid.len(), 321, "j_max 20 → 16·20 + 1 points");
        for (r, &tau) in rows.iter().zip(&grid) {
            assert_eq!(r.tau, tau);
            assert_eq!(r.time_s, 1.25 + tau * 0.3);
            for a in 0..3 {
                assert_eq!(r.f_stance[a], model.axes[a].eval(tau));
            }
            // e_h = (0.6, −0.8), e_p = (0.8, 0.6): f_x = 0.6 f_h + 0.8 f_p, f_y = −0.8 f_h + 0.6 f_p.
            let [fh, fp, fv] = r.f_stance;
            let want = [0.6 * fh + 0.8 * fp, -0.8 * fh + 0.6 * fp, fv];
            for (got, want) in r.f_world.iter().zip(want) {
                assert!((got - want).abs() < 1e-12 * (1.0 + want.abs()));
            }
        }
        assert_eq!((rows[0].tau, rows[rows.len() - 1].tau), (0.0, 1.0));
        assert_eq!(rows[rows.len() - 1].time_s, 1.25 + 0.3);
    }
}
