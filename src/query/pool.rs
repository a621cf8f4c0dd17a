//! The stances a query draws from: one library row with the per-stance grids every query
//! reuses, and the new-character map of dynamic similarity (spec stance-model §9).
//!
//! # Model
//! ```text
//! length, position, zs, ze, x, z_c, cp, χ, ext      × L        mass, force, c0, c_i, F      × M
//! time, Δt, t_TD, t_LO, T                            × √L       velocity vs, ve, vp, vps     × √L
//! A^F (force²)                                       × M²       A^μ, μ, β, j, φ              × 1
//! angular impulse H, H_0                             × M L^{3/2}
//! ```
//! `L = L_leg,target / L_leg,source`, `M = m_target / m_source`, `g` unchanged (Froude
//! scaling: base factors mass `M`, length `L`, time `√L`).
//!
//! # References
//! spec stance-model §9 (table), §7.2 (what is stored per stance), §11 (columns).

use crate::constraints::coefficients::friction_demand;
use crate::constraints::{Coefficients, SampledGrids, StanceContext};
use crate::stances::params::StanceParams;

use super::feasibility::ImpulseMoments;
use super::solve::StanceShape;

pub use crate::library::codec::stances::PoolStance;

impl PoolStance {
    /// The stance's own context `(vs, vps, t_TD, z_TD, cp)` (§7.3).
    pub fn context(&self) -> StanceContext {
        StanceContext {
            vs: self.params.vs,
            vps: self.params.vps,
            t_td: self.params.t_td,
            z_td: self.params.z_td,
            cp: self.cp,
        }
    }

    /// The same stance performed by a character `L` times as long and `M` times as heavy
    /// (§9); `L = M = 1` returns an identical copy.
    pub fn scaled(&self, length: f64, mass: f64) -> PoolStance {
        let (l, m, t) = (length, mass, length.sqrt());
        let p = &self.params;
        let params = StanceParams {
            zs: p.zs * l,
            vs: p.vs * t,
            ze: p.ze * l,
            ve: p.ve * t,
            vp: p.vp * t,
            vps: p.vps * t,
            x: p.x * l,
            z_td: p.z_td * l,
            z_lo: p.z_lo * l,
            t_td: p.t_td * t,
            t_lo: p.t_lo * t,
            t_e: p.t_e * t,
        };
        let mut model = self.model.clone();
        model.mass_kg *= m;
        model.dt_s *= t;
        for axis in &mut model.axes {
            axis.c0 *= m;
            axis.amps.iter_mut().for_each(|c| *c *= m);
            axis.poly.iter_mut().for_each(|c| *c *= m);
            axis.fit_rms *= m;
        }
        let c = &self.coef;
        let ang = m * l * t;
        let coef = Coefficients {
            a_f: c.a_f.map(|v| v * m * m),
            min_f_v: c.min_f_v * m,
            f_peak: c.f_peak * m,
            ext_min: c.ext_min * l,
            ext_max: c.ext_max * l,
            ang_impulse: c.ang_impulse.map(|v| v * ang),
            ang_impulse_h0: c.ang_impulse_h0.map(|v| v * ang),
            ..*c
        };
        PoolStance {
            z_c: self.z_c * l,
            params,
            model,
            cp: self.cp.map(|v| v * l),
            coef,
            ..self.clone()
        }
    }
}

impl PoolStance {
    /// The same force profile stretched in time by `σ` (time is a degree of freedom of
    /// the scaling, not only the force):
    ///
    /// ```text
    /// f̃(t) = f(t/σ):  Δt̃ = σ Δt,  J̃_a = σ J_a (m/s),  K̃_a = σ² K_a (m),  S̃_a = σ² S_a (m)
    /// t̃_TD, t̃_LO, t̃_E = σ·(t_TD, t_LO, t_E)   (so the centroid split (u, w) keeps its signs)
    /// ```
    ///
    /// Forces on the normalised grid, `A^F`, `A^μ` and `μ_req` are unchanged (a scale β on
    /// top gives `β f(t/σ)`); the stance's recorded extremes and angular impulse stay
    /// those of the recording (relative limits and `H_des` refer to what was recorded).
    /// `σ = 1` returns an identical copy. Rebuild [`Prepared`] from the result: its `J`,
    /// `K` and `S` follow from `Δt̃` exactly.
    pub fn time_scaled(&self, sigma: f64) -> PoolStance {
        let mut s = self.clone();
        s.model.dt_s *= sigma;
        s.params.t_td *= sigma;
        s.params.t_lo *= sigma;
        s.params.t_e *= sigma;
        s
    }
}

/// A stance with the grids every query of it reuses (built once, O(N_s)).
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The library row.
    pub stance: PoolStance,
    /// Solver view: `J`, `K`, `Δt`, boundary rules, reference centroid signs.
    pub shape: StanceShape,
    /// `f_a(τ_k)`, `S_a(τ_k)` on the stance's grid (§7.4).
    pub grids: SampledGrids,
    /// Context-free moments of the contact point (§8.3).
    pub moments: ImpulseMoments,
}

impl Prepared {
    /// Builds the grids of `stance`.
    pub fn new(stance: PoolStance) -> Self {
        let shape = StanceShape::from_boundaries(
            &stance.model,
            stance.boundary_start,
            stance.boundary_end,
            &stance.params,
        );
        Prepared {
            grids: SampledGrids::new(&stance.model),
            moments: ImpulseMoments::new(&stance.model),
            shape,
            stance,
        }
    }

    /// Builds the grids of `stance` with the friction check's active set at `λ_act`
    /// (`f_v ≥ λ_act · max f_v`): the exact check uses it, and the stance's `A^μ` and
    /// `μ_req` (eq 11 filter, relative limits) are recomputed on it.
    pub fn with_active_fraction(stance: PoolStance, active_fraction: f64) -> Self {
        let mut p = Prepared::new(stance);
        p.grids.active_fraction = active_fraction;
        let (a_mu, mu_req) = friction_demand(&p.grids, p.grids.max_f_v, active_fraction);
        p.stance.coef.a_mu = a_mu;
        p.stance.coef.mu_req = mu_req;
        p
    }
}
