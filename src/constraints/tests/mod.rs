//! Tests of the constraint coefficients: brute force on the grid, an RK4 integration of the
//! COM, Simpson quadrature of the angular impulse, and conservativeness of the filters.

// Tests index several per-axis arrays by one axis number; iterators would obscure that.
#![allow(clippy::needless_range_loop)]

mod extension;
mod force;
mod impulse;

use super::StanceContext;
use crate::force_model::ForceModel;
use crate::testkit::Harmonics;
pub(super) use crate::testkit::Rng;

/// A random stance-like model (`testkit::bell_model`): ringing up to 0.1 body weights,
/// 1–4 harmonics `j ∈ 1..=6` per axis.
pub(super) fn random_model(rng: &mut Rng) -> ForceModel {
    random_model_with(rng, false)
}

/// [`random_model`], or with `halves` every harmonic `j − ½` (half-range cosines, the
/// Fourier model of `force_model::cosine`) from the same draws.
pub(super) fn random_model_with(rng: &mut Rng, halves: bool) -> ForceModel {
    let h = Harmonics {
        terms: 4,
        max_j: 6,
        halves,
    };
    crate::testkit::bell_model(rng, 0.1, h)
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
