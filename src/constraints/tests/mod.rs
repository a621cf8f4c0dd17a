//! Tests of the constraint coefficients: brute force on the grid, an RK4 integration of the
//! COM, Simpson quadrature of the angular impulse, and conservativeness of the filters.

// Tests index several per-axis arrays by one axis number; iterators would obscure that.
#![allow(clippy::needless_range_loop)]

mod extension;
mod force;
mod impulse;

use super::StanceContext;
use crate::force_model::{AxisModel, ForceModel, GRAVITY};
pub(super) use crate::testkit::Rng;
use std::f64::consts::PI;

/// A random axis: DC `c0` plus 1–4 harmonics `j ∈ 1..=6` of amplitude up to `amp` (N).
fn random_axis(rng: &mut Rng, c0: f64, amp: f64) -> AxisModel {
    let n = rng.int(1, 4) as usize;
    let harmonics: Vec<u32> = (0..n).map(|_| rng.int(1, 6)).collect();
    AxisModel {
        c0,
        amps: (0..n).map(|_| rng.uniform(0.0, amp)).collect(),
        phases: (0..n).map(|_| rng.uniform(-PI, PI)).collect(),
        harmonics,
        poly: Vec::new(),
        fit_rms: 0.0,
    }
}

/// A random stance-like model: a vertical bell `A(1 − cos 2πτ)` plus ringing, and
/// horizontal forces with random harmonics (repeated `j` allowed).
pub(super) fn random_model(rng: &mut Rng) -> ForceModel {
    let mass_kg = rng.uniform(40.0, 100.0);
    let weight = mass_kg * GRAVITY;
    let bell = rng.uniform(1.0, 3.0) * weight;
    let mut v = random_axis(rng, bell, 0.1 * weight);
    v.harmonics.push(1);
    v.amps.push(bell);
    v.phases.push(PI);
    let h_dc = rng.uniform(-0.3, 0.3) * weight;
    let p_dc = rng.uniform(-0.1, 0.1) * weight;
    ForceModel {
        mass_kg,
        dt_s: rng.uniform(0.15, 0.5),
        axes: [
            random_axis(rng, h_dc, 0.5 * weight),
            random_axis(rng, p_dc, 0.2 * weight),
            v,
        ],
    }
}

/// A random original context: running-like speeds, heights, contact points.
pub(super) fn random_context(rng: &mut Rng) -> StanceContext {
    StanceContext {
        vs: rng.uniform(-1.0, 6.0),
        vps: rng.uniform(-0.5, 0.5),
        t_td: rng.uniform(0.0, 0.3),
        z_td: rng.uniform(0.7, 1.1),
        cp: [rng.uniform(-0.4, 0.4), rng.uniform(-0.2, 0.2)],
    }
}

/// `f(τ)` as a vector (h, p, v) through the force model's own evaluator.
pub(super) fn force_at(model: &ForceModel, tau: f64) -> [f64; 3] {
    [0, 1, 2].map(|a| model.axes[a].eval(tau))
}
