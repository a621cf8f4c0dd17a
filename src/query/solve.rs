//! Closed-form stance scaling: β and the event times from six stance parameters.
//!
//! # Model
//! ```text
//! edit: f̃_a(τ) = β_a f_a(τ), Δt, Ω and φ unchanged                       (spec §6, eq 4)
//! (A1) β_h J_h = ve − vs          (A2) β_p J_p = vp − vps      (A3) β_v J_v = g T
//! (A4) x = ve·T − (ve − vs)·t_TD − β_h K_h
//! (A5) ze − zs = g T²/2 − g T t_TD − β_v K_v
//! regular case (J_h ≠ 0, J_p ≠ 0, J_v > 0), d = ve − vs, Δz = ze − zs, s̄_a = K_a/J_a:
//!   ((vs + ve)/2)·T² − (x + d·(s̄_h − s̄_v))·T + d·Δz/g = 0            (master quadratic)
//!   t_TD = T/2 − s̄_v − Δz/(g T),  t_LO = t_TD + Δt,  t_E = T,  β_v = g T / J_v
//!   y = vps·T + β_p ((T − t_TD) J_p − K_p)          perpendicular end-apex offset
//! stable roots: q = −½ (b + sign(b)·√(b² − 4ac)),  T ∈ {q/a, c/q};  a = 0 → T = −c/b
//! admissible: T > 0, β_h ≥ 0, β_p ≥ 0, β_v > 0 (tolerance 1e-12);
//!   u = t_TD + s̄_v, w = T − u with the signs of the original stance (else u, w > 0);
//!   flight before ⇒ t_TD ≥ 0;  flight after ⇒ t_E − t_LO ≥ 0 (where the recording has
//!   them: `StanceShape::from_boundaries`)
//! choice: smallest |T − T_orig|, ties (or no T_orig) → smaller T
//! ```
//! Degenerate branches (§6.4), with `J_a ≈ 0 ⇔ |J_a| ≤ ε_J (Δt/m)(|c0_a| + Σ_i c_ia)`:
//! (i) `J_v ≤ 0` (or ≈ 0) → [`Infeasible::NoSupport`]; (ii) `J_h ≈ 0` → `ve = vs`
//! required, `T = β_v,ref J_v/g`, `β_h` from A4 (or `β_h,ref` when `K_h ≈ 0` too);
//! (iii) `J_p ≈ 0` → `vp = vps` required, `β_p = β_p,ref`; (iv) quadratic identically
//! zero → `T = β_v,ref J_v/g`.
//!
//! # Frames and units
//! Stance frame (h, p, v = index 0, 1, 2; spec §2). Heights in metres above the contact
//! height `z_c`, velocities in m/s, times in seconds from the start apex, `J` in m/s,
//! `K` in m, β unit-free, `g` = [`GRAVITY`] m/s².
//!
//! # References
//! Pollard & Behmaram-Mosavat, *Force-Based Motion Editing for Locomotion Tasks*,
//! Appendix A (eq 13–22) as corrected by spec stance-model §5–§6.5.
//!
//! # Examples
//! ```
//! use stancelib::force_model::{AxisModel, ForceModel};
//! use stancelib::query::solve::{solve, Refs, Request, StanceShape};
//! // 70 kg, 0.25 s stance: constant push 50 N forward, 1400 N up.
//! let m = ForceModel {
//!     mass_kg: 70.0,
//!     dt_s: 0.25,
//!     axes: [AxisModel::constant(50.0), AxisModel::constant(0.0), AxisModel::constant(1400.0)],
//! };
//! let shape = StanceShape::from_model(&m, true, true, None);
//! // J_v = 5 m/s ⇒ T = 0.5097 s at β_v = 1; ask for the stance's own β = 1 outcome.
//! let (jh, t) = (m.j()[0], 5.0 / 9.81);
//! let t_td = t / 2.0 - 0.125; // Δz = 0, s̄_v = Δt/2
//! let req = Request {
//!     zs: 1.0, vs: 3.0, ze: 1.0, ve: 3.0 + jh, vp: 0.0, vps: 0.0,
//!     x: (3.0 + jh) * t - jh * t_td - m.k()[0],
//! };
//! let s = solve(&shape, &req, &Refs::default(), Some(t)).unwrap();
//! assert!((s.beta[0] - 1.0).abs() < 1e-12 && (s.beta[2] - 1.0).abs() < 1e-12);
//! assert!((s.t_td - t_td).abs() < 1e-12);
//! ```

use crate::force_model::{ForceModel, GRAVITY};
use crate::stances::params::StanceParams;
use crate::stances::segment::Boundary;
use crate::stances::Stance;

/// Numerical-zero factor `ε_J` for `J_a` and `K_a` (spec §6.4).
pub const DEFAULT_EPS_J: f64 = 1e-9;
/// Relative tolerance of the degenerate-branch equalities: `tol = 1e-9·max(1, |a|, |b|)`
/// for `a = b` (spec §6.4 (ii)).
pub const DEFAULT_MATCH_TOL: f64 = 1e-9;
/// Tolerance of the admissibility inequalities (spec §6.5: each `≥ −1e-12`).
pub const DEFAULT_ADMISSIBLE_TOL: f64 = 1e-12;
/// A discriminant in `[−1e-14·(b² + |4ac|), 0)` is roundoff of a double root and counts
/// as 0 (the terms themselves carry ~1e-16 relative error).
pub const DEFAULT_DISC_REL_TOL: f64 = 1e-14;

/// A query: the six stance parameters wanted (stance frame, heights above `z_c`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Request {
    /// Start-apex height (m).
    pub zs: f64,
    /// Start-apex heading velocity (m/s).
    pub vs: f64,
    /// End-apex height (m).
    pub ze: f64,
    /// End-apex heading velocity (m/s).
    pub ve: f64,
    /// End-apex perpendicular velocity (m/s).
    pub vp: f64,
    /// Start-apex perpendicular velocity (m/s); 0 except for the facing fallback (§2).
    pub vps: f64,
    /// Heading distance from the start apex to the end apex (m).
    pub x: f64,
}

/// Reference scale factors used by the degenerate branches (spec §6.4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Refs {
    /// `β_h,ref` when `J_h ≈ 0` and `K_h ≈ 0`.
    pub beta_h: f64,
    /// `β_p,ref` when `J_p ≈ 0`.
    pub beta_p: f64,
    /// `β_v,ref` when `T` is free (`J_h ≈ 0`, or the quadratic vanishes).
    pub beta_v: f64,
}

impl Default for Refs {
    fn default() -> Self {
        Refs {
            beta_h: 1.0,
            beta_p: 1.0,
            beta_v: 1.0,
        }
    }
}

impl Refs {
    /// The references of the run-at-speed policy at `k = v / v_orig` (`β_h = k`, the others
    /// 1): a stance whose `J_h ≈ 0` keeps the policy's fore-aft scale.
    pub fn run(k: f64) -> Self {
        Refs {
            beta_h: k,
            ..Refs::default()
        }
    }
}

/// Tolerances of [`solve_with`]; see the `DEFAULT_*` constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveOptions {
    /// `ε_J`; default [`DEFAULT_EPS_J`].
    pub eps_j: f64,
    /// Relative equality tolerance; default [`DEFAULT_MATCH_TOL`].
    pub match_tol: f64,
    /// Admissibility slack (s or unit-free); default [`DEFAULT_ADMISSIBLE_TOL`].
    pub admissible_tol: f64,
    /// Relative discriminant slack; default [`DEFAULT_DISC_REL_TOL`].
    pub disc_rel_tol: f64,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            eps_j: DEFAULT_EPS_J,
            match_tol: DEFAULT_MATCH_TOL,
            admissible_tol: DEFAULT_ADMISSIBLE_TOL,
            disc_rel_tol: DEFAULT_DISC_REL_TOL,
        }
    }
}

/// What the solver needs of one stance: `J`, `K`, `Δt`, the ε_J scales and the rules.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StanceShape {
    /// `J_a` (m/s).
    pub j: [f64; 3],
    /// `K_a` (m).
    pub k: [f64; 3],
    /// `Δt` (s).
    pub dt: f64,
    /// `(Δt/m)(|c0_a| + Σ_i c_ia)` (m/s): `J_a ≈ 0` below `ε_J` times this.
    pub j_scale: [f64; 3],
    /// A `flight` boundary precedes the stance (rule 3: `t_TD ≥ 0`).
    pub before_flight: bool,
    /// A `flight` boundary follows the stance (rule 3: `t_E − t_LO ≥ 0`).
    pub after_flight: bool,
    /// `(u, w)` of the original stance (only their signs are used, rule 2).
    pub ref_signs: Option<(f64, f64)>,
    /// Values derived once from `j`, `k`, `dt` (build shapes with [`Self::from_model`];
    /// after changing those fields by hand, call [`Self::refresh`]).
    derived: Derived,
}

/// Per-stance constants of the solver: `1/J_a`, `s̄_h`, `s̄_v`, and whether `J`, `K`, the
/// ε_J scales and `Δt > 0` are all finite.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Derived {
    inv_j: [f64; 3],
    s_bar_h: f64,
    s_bar_v: f64,
    valid: bool,
}

impl Derived {
    fn of(j: &[f64; 3], k: &[f64; 3], j_scale: &[f64; 3], dt: f64) -> Self {
        Derived {
            inv_j: j.map(|v| 1.0 / v),
            s_bar_h: k[0] / j[0],
            s_bar_v: k[2] / j[2],
            valid: j.iter().chain(k).chain(j_scale).all(|v| v.is_finite())
                && dt.is_finite()
                && dt > 0.0,
        }
    }
}

impl StanceShape {
    /// Recomputes the derived constants after `j`, `k`, `j_scale` or `dt` changed.
    pub fn refresh(&mut self) {
        self.derived = Derived::of(&self.j, &self.k, &self.j_scale, self.dt);
    }

    /// The shape of a force model, with its boundary rules and reference `(u, w)`.
    pub fn from_model(
        m: &ForceModel,
        before_flight: bool,
        after_flight: bool,
        ref_signs: Option<(f64, f64)>,
    ) -> Self {
        let j_scale = m.axes.each_ref().map(|a| {
            // A bound on max |f| over τ ∈ [0, 1]: |c0| + Σ|c_i| + Σ|p_k| (τ^k ≤ 1).
            let sum: f64 = a.c0.abs()
                + a.terms().map(|(_, c, _)| c.abs()).sum::<f64>()
                + a.poly.iter().map(|p| p.abs()).sum::<f64>();
            m.dt_s / m.mass_kg * sum
        });
        let (j, k) = (m.j(), m.k());
        StanceShape {
            derived: Derived::of(&j, &k, &j_scale, m.dt_s),
            j,
            k,
            dt: m.dt_s,
            j_scale,
            before_flight,
            after_flight,
            ref_signs,
        }
    }

    /// The shape of a library stance: boundaries from its kinds, `(u, w)` from its
    /// model-consistent `t_TD` and `t_E`.
    pub fn from_stance(s: &Stance) -> Self {
        Self::from_boundaries(&s.model, s.boundary_start, s.boundary_end, &s.params)
    }

    /// The shape of a model with the given boundary kinds and reference parameters
    /// (`(u, w)` from their `t_TD` and `t_E`).
    ///
    /// Rule 3 (a flight keeps the apex outside the stance) follows the recording, as rule 2
    /// does (a departure): a flight boundary whose recorded apex lies inside the stance
    /// (`t_TD < 0` or `t_E < t_LO`: a jog's short flight, where the COM already falls at
    /// liftoff or still rises at touchdown) does not impose it, else the recorded stance
    /// could not be solved at its own parameters.
    pub fn from_boundaries(
        m: &ForceModel,
        start: Boundary,
        end: Boundary,
        reference: &StanceParams,
    ) -> Self {
        let before = start == Boundary::Flight && reference.t_td >= 0.0;
        let after = end == Boundary::Flight && reference.t_e >= reference.t_lo;
        let mut shape = Self::from_model(m, before, after, None);
        shape.ref_signs = shape.centroid_split(reference.t_td, reference.t_e);
        shape
    }

    /// `(u, w) = (t_TD + s̄_v, T − u)` (s); `None` when `J_v = 0` or a value is not finite.
    pub fn centroid_split(&self, t_td: f64, t_e: f64) -> Option<(f64, f64)> {
        let u = t_td + self.k[2] / self.j[2];
        let w = t_e - u;
        (u.is_finite() && w.is_finite()).then_some((u, w))
    }
}

/// How `T` was determined.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Branch {
    /// A root of the master quadratic (§6.2).
    Quadratic,
    /// `vs + ve = 0`: the linear equation `T = −c/b` (§6.2).
    Linear,
    /// `J_h ≈ 0`: `T = β_v,ref J_v/g`, `β_h` from the distance (§6.4 (ii)).
    NoNetHorizontal,
    /// Quadratic identically zero: `T = β_v,ref J_v/g` (§6.4 (iv)).
    FreePeriod,
}

/// Why a query has no admissible solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Infeasible {
    /// A request, reference or shape value is not finite, or `Δt ≤ 0`.
    InvalidInput,
    /// `J_v ≤ 0` or `J_v ≈ 0`: the stance cannot support the body (§6.4 (i)).
    NoSupport,
    /// `J_h ≈ 0` but `ve ≠ vs` (§6.4 (ii)).
    NoNetHorizontalImpulse,
    /// `J_h ≈ 0`, `K_h ≈ 0` but `x ≠ ve·T` (§6.4 (ii)).
    NoNetHorizontalMoment,
    /// `J_p ≈ 0` but `vp ≠ vps` (§6.4 (iii)).
    NoNetPerpendicularImpulse,
    /// The master quadratic has no real root.
    NegativeDiscriminant,
    /// `vs + ve = 0` and `b = 0` but `c ≠ 0`: the linear equation has no root.
    NoRoot,
    /// Every root breaks rule 1 (`T > 0`, `β ≥ 0`).
    SignRule,
    /// Every root breaks rule 2 (centroid signs), the best passing rule 1.
    CentroidRule,
    /// Every root breaks rule 3 (flight signs), the best passing rules 1–2.
    FlightRule,
    /// A finite request produced a non-finite solution (overflow).
    NonFinite,
}

impl std::fmt::Display for Infeasible {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Infeasible::InvalidInput => "non-finite request, reference or stance value",
            Infeasible::NoSupport => "vertical impulse J_v is not positive",
            Infeasible::NoNetHorizontalImpulse => "horizontal force has no net impulse",
            Infeasible::NoNetHorizontalMoment => "horizontal force has no net moment",
            Infeasible::NoNetPerpendicularImpulse => "perpendicular force has no net impulse",
            Infeasible::NegativeDiscriminant => "negative discriminant",
            Infeasible::NoRoot => "linear equation has no root",
            Infeasible::SignRule => "sign rule (T > 0, β ≥ 0)",
            Infeasible::CentroidRule => "centroid rule (signs of u, w)",
            Infeasible::FlightRule => "flight rule (t_TD ≥ 0 or t_E ≥ t_LO)",
            Infeasible::NonFinite => "solution overflows",
        })
    }
}

impl std::error::Error for Infeasible {}

/// One root of the scaling equations, before admissibility.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// `(β_h, β_p, β_v)`.
    pub beta: [f64; 3],
    /// Touchdown time `t_TD` (s).
    pub t_td: f64,
    /// End-apex time `T = t_E` (s).
    pub t_e: f64,
    /// `u = t_TD + s̄_v` (s).
    pub u: f64,
    /// `w = T − u` (s).
    pub w: f64,
}

/// Up to two candidates (the roots of the master quadratic), stored inline so a query
/// allocates nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Roots {
    len: usize,
    items: [Candidate; 2],
}

impl Roots {
    const EMPTY: Candidate = Candidate {
        beta: [0.0; 3],
        t_td: 0.0,
        t_e: 0.0,
        u: 0.0,
        w: 0.0,
    };

    fn one(c: Candidate) -> Self {
        Roots {
            len: 1,
            items: [c, Self::EMPTY],
        }
    }

    fn two(a: Candidate, b: Candidate) -> Self {
        Roots {
            len: 2,
            items: [a, b],
        }
    }

    /// The candidates, in root order.
    pub fn as_slice(&self) -> &[Candidate] {
        &self.items[..self.len]
    }

    /// Iterates over the candidates.
    pub fn iter(&self) -> std::slice::Iter<'_, Candidate> {
        self.as_slice().iter()
    }
}

/// An admissible solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solution {
    /// `(β_h, β_p, β_v)`.
    pub beta: [f64; 3],
    /// Touchdown time `t_TD` (s from the start apex).
    pub t_td: f64,
    /// Liftoff time `t_LO = t_TD + Δt` (s).
    pub t_lo: f64,
    /// End-apex time `t_E = T` (s).
    pub t_e: f64,
    /// Perpendicular offset of the end apex from the start apex (m).
    pub y: f64,
    /// How `T` was found.
    pub branch: Branch,
    /// `T` of the other admissible root, when two are admissible (§6.5).
    pub other_t_e: Option<f64>,
}

/// [`solve_with`] with the default [`SolveOptions`].
pub fn solve(
    shape: &StanceShape,
    req: &Request,
    refs: &Refs,
    t_orig: Option<f64>,
) -> Result<Solution, Infeasible> {
    solve_with(shape, req, refs, t_orig, &SolveOptions::default())
}

/// Solves §6.2/§6.4, keeps the admissible roots (§6.5) and picks one.
///
/// `t_orig`: the original `T`, used to choose between two admissible roots.
///
/// # Errors
/// An [`Infeasible`] reason; never a NaN.
#[inline]
pub fn solve_with(
    shape: &StanceShape,
    req: &Request,
    refs: &Refs,
    t_orig: Option<f64>,
    opts: &SolveOptions,
) -> Result<Solution, Infeasible> {
    let (cands, branch) = candidates(shape, req, refs, opts)?;
    let mut worst = Infeasible::SignRule;
    // The best admissible candidate so far and the T of the other one (§6.5 choice).
    let (mut best, mut other): (Option<Candidate>, Option<f64>) = (None, None);
    for c in cands.iter() {
        match admissible(shape, c, opts.admissible_tol) {
            Ok(()) => match best {
                Some(b) if !better(c, &b, t_orig) => other = Some(c.t_e),
                Some(b) => {
                    other = Some(b.t_e);
                    best = Some(*c);
                }
                None => best = Some(*c),
            },
            Err(e) => worst = later(worst, e),
        }
    }
    let Some(best) = best else {
        return Err(worst);
    };
    let y = req.vps * best.t_e + best.beta[1] * ((best.t_e - best.t_td) * shape.j[1] - shape.k[1]);
    let sol = Solution {
        beta: best.beta,
        t_td: best.t_td,
        t_lo: best.t_td + shape.dt,
        t_e: best.t_e,
        y,
        branch,
        other_t_e: other,
    };
    let finite = (sol.beta[0] + sol.beta[1] + sol.beta[2] + sol.t_td + sol.t_lo + sol.t_e + sol.y)
        .is_finite();
    if finite {
        Ok(sol)
    } else {
        Err(Infeasible::NonFinite)
    }
}

/// `a` is preferred to `b`: smaller `|T − T_orig|`, ties (and every pair when `t_orig` is
/// `None`) to the smaller `T` (§6.5).
fn better(a: &Candidate, b: &Candidate, t_orig: Option<f64>) -> bool {
    let key = |c: &Candidate| t_orig.map_or(0.0, |t| (c.t_e - t).abs());
    key(a)
        .total_cmp(&key(b))
        .then(a.t_e.total_cmp(&b.t_e))
        .is_lt()
}

/// The later of two rule failures (rule 1 < rule 2 < rule 3).
fn later(a: Infeasible, b: Infeasible) -> Infeasible {
    let rank = |e: Infeasible| match e {
        Infeasible::SignRule => 0,
        Infeasible::CentroidRule => 1,
        _ => 2,
    };
    if rank(b) > rank(a) {
        b
    } else {
        a
    }
}

/// `|a − b| ≤ tol·max(1, |a|, |b|)`: the equality `a = b` for the degenerate branches.
fn matches(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * 1f64.max(a.abs()).max(b.abs())
}

/// All roots of §6.2 (or the single solution of a degenerate branch), before §6.5.
///
/// # Errors
/// [`Infeasible::InvalidInput`], the §6.4 reasons, [`Infeasible::NegativeDiscriminant`]
/// or [`Infeasible::NoRoot`].
#[inline]
pub fn candidates(
    shape: &StanceShape,
    req: &Request,
    refs: &Refs,
    opts: &SolveOptions,
) -> Result<(Roots, Branch), Infeasible> {
    let inputs = [
        req.zs,
        req.vs,
        req.ze,
        req.ve,
        req.vp,
        req.vps,
        req.x,
        refs.beta_h,
        refs.beta_p,
        refs.beta_v,
    ];
    // One test for all ten: a sum is finite iff every term is (NaN and ±∞ propagate; a
    // finite overflow needs values near 1e308, rejected too).
    if !(shape.derived.valid && inputs.iter().sum::<f64>().is_finite()) {
        return Err(Infeasible::InvalidInput);
    }
    let jv = shape.j[2];
    let near_zero = |a: usize| shape.j[a].abs() <= opts.eps_j * shape.j_scale[a];
    // (i) support.
    if jv <= 0.0 || near_zero(2) {
        return Err(Infeasible::NoSupport);
    }
    // (iii) perpendicular.
    let beta_p = if near_zero(1) {
        if !matches(req.vp, req.vps, opts.match_tol) {
            return Err(Infeasible::NoNetPerpendicularImpulse);
        }
        refs.beta_p
    } else {
        (req.vp - req.vps) * shape.derived.inv_j[1]
    };
    let inv_g = 1.0 / GRAVITY; // a constant: the divisions by g become products
    let mk = Maker {
        shape,
        req,
        refs,
        opts,
        sv: shape.derived.s_bar_v,
        dz_g: (req.ze - req.zs) * inv_g,
        beta_p,
        inv_jv: shape.derived.inv_j[2],
    };
    // (ii) no net horizontal impulse.
    if near_zero(0) {
        return mk.no_net_horizontal();
    }
    mk.quadratic()
}

/// One request on one stance and what every candidate of it shares: `t_TD`, `u`, `w` and
/// `β` for one `T > 0`.
struct Maker<'a> {
    shape: &'a StanceShape,
    req: &'a Request,
    refs: &'a Refs,
    opts: &'a SolveOptions,
    /// `s̄_v`, s.
    sv: f64,
    /// `(z_e − z_s)/g`, s².
    dz_g: f64,
    /// `β_p` (§6.4 (iii)).
    beta_p: f64,
    /// `1/J_v`.
    inv_jv: f64,
}

impl Maker<'_> {
    /// The candidate for `T` with `inv_t` = 1/T (passed in when a root gives it without a
    /// division).
    #[inline]
    fn make_inv(&self, t: f64, inv_t: f64, beta_h: f64) -> Candidate {
        let t_td = t / 2.0 - self.sv - self.dz_g * inv_t;
        let u = t_td + self.sv;
        Candidate {
            beta: [beta_h, self.beta_p, GRAVITY * t * self.inv_jv],
            t_td,
            t_e: t,
            u,
            w: t - u,
        }
    }

    /// The candidate for a root `T`: [`Maker::make_inv`] for `T > 0` finite, else the
    /// placeholder that fails rule 1.
    #[inline]
    fn at_inv(&self, t: f64, inv_t: f64, beta_h: f64) -> Candidate {
        if t > 0.0 && t.is_finite() {
            self.make_inv(t, inv_t, beta_h)
        } else {
            sign_fail(t, self.beta_p)
        }
    }

    #[inline]
    fn at(&self, t: f64, beta_h: f64) -> Candidate {
        self.at_inv(t, 1.0 / t, beta_h)
    }

    /// §6.4 (ii), no net horizontal impulse: `T` from `β_v,ref`, `β_h` from A4.
    #[inline]
    fn no_net_horizontal(&self) -> Result<(Roots, Branch), Infeasible> {
        let (shape, req, refs, opts, mk) = (self.shape, self.req, self.refs, self.opts, self);
        if !matches(req.ve, req.vs, opts.match_tol) {
            return Err(Infeasible::NoNetHorizontalImpulse);
        }
        let t = refs.beta_v * shape.j[2] / GRAVITY;
        if t <= 0.0 {
            return Ok((Roots::one(sign_fail(t, mk.beta_p)), Branch::NoNetHorizontal));
        }
        let mut c = mk.make_inv(t, 1.0 / t, 0.0);
        let moment_scale = shape.dt * shape.j_scale[0];
        let rest = req.ve * t - (req.ve - req.vs) * c.t_td;
        let kh = shape.k[0];
        c.beta[0] = if kh.abs() <= opts.eps_j * moment_scale {
            if !matches(req.x, rest, opts.match_tol) {
                return Err(Infeasible::NoNetHorizontalMoment);
            }
            refs.beta_h
        } else {
            (rest - req.x) / kh
        };
        Ok((Roots::one(c), Branch::NoNetHorizontal))
    }

    /// §6.2 `a T² + b T + c = 0` (and its degenerate forms of §6.4 (iv)), roots by the
    /// stable formula `q = −(b + sign(b)·√disc)/2`, `T1 = q/a`, `T2 = c/q`.
    #[inline]
    fn quadratic(&self) -> Result<(Roots, Branch), Infeasible> {
        let (shape, req, refs, opts, mk) = (self.shape, self.req, self.refs, self.opts, self);
        let d = req.ve - req.vs;
        let dz = req.ze - req.zs;
        let beta_h = d * shape.derived.inv_j[0];
        let (sh, sv) = (shape.derived.s_bar_h, mk.sv);
        let a = (req.vs + req.ve) / 2.0;
        let b = -(req.x + d * (sh - sv));
        let c = d * mk.dz_g;
        if a == 0.0 {
            // "Identically zero" (§6.4 (iv)) relative to the terms of b and the factors of c.
            let b_tol = opts.match_tol * 1f64.max(req.x.abs()).max((d * (sh - sv)).abs());
            let c_tol = opts.match_tol * 1f64.max(d.abs()).max(dz.abs());
            if b.abs() > b_tol {
                let t = -c / b;
                return Ok((Roots::one(mk.at(t, beta_h)), Branch::Linear));
            }
            if c.abs() > c_tol {
                return Err(Infeasible::NoRoot);
            }
            let t = refs.beta_v * shape.j[2] / GRAVITY;
            return Ok((Roots::one(mk.at(t, beta_h)), Branch::FreePeriod));
        }
        let mut disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            if disc >= -opts.disc_rel_tol * (b * b + (4.0 * a * c).abs()) {
                disc = 0.0;
            } else {
                return Err(Infeasible::NegativeDiscriminant);
            }
        }
        if !disc.is_finite() {
            return Err(Infeasible::NonFinite);
        }
        let q = -0.5 * (b + b.signum() * disc.sqrt());
        let roots = if q == 0.0 {
            Roots::one(mk.at(0.0, beta_h)) // b = 0 and disc = 0 ⇒ c = 0: the double root T = 0
        } else if disc == 0.0 {
            Roots::one(mk.at(q / a, beta_h))
        } else {
            // T1 = q/a, T2 = c/q: with 1/q, 1/T1 = a/q and T2 need no division of their own.
            let inv_q = 1.0 / q;
            Roots::two(
                mk.at_inv(q / a, a * inv_q, beta_h),
                mk.at(c * inv_q, beta_h),
            )
        };
        Ok((roots, Branch::Quadratic))
    }
}

/// A placeholder candidate for `T ≤ 0` (no `t_TD` exists); it fails rule 1.
fn sign_fail(t: f64, beta_p: f64) -> Candidate {
    Candidate {
        beta: [0.0, beta_p, 0.0],
        t_td: 0.0,
        t_e: t,
        u: 0.0,
        w: 0.0,
    }
}

/// §6.5 rules 1–3 for one candidate, with slack `tol`.
///
/// # Errors
/// The first rule broken: [`Infeasible::SignRule`], [`Infeasible::CentroidRule`] or
/// [`Infeasible::FlightRule`].
#[inline]
pub fn admissible(shape: &StanceShape, c: &Candidate, tol: f64) -> Result<(), Infeasible> {
    // One test for all seven: a sum is finite iff every term is (a NaN or ±∞ term
    // propagates; finite terms this large do not occur in a stance).
    let finite = (c.beta[0] + c.beta[1] + c.beta[2] + c.t_td + c.t_e + c.u + c.w).is_finite();
    // T > 0 strictly: t_TD = T/2 − s̄_v − Δz/(gT) needs it; then β_v = gT/J_v > 0.
    let signs = c.t_e > 0.0 && c.beta[0] >= -tol && c.beta[1] >= -tol && c.beta[2] > 0.0;
    if !finite || !signs {
        return Err(Infeasible::SignRule);
    }
    let (su, sw) = shape.ref_signs.unwrap_or((1.0, 1.0));
    // signum(+0.0) = +1: a zero reference counts as positive.
    if c.u * su.signum() < -tol || c.w * sw.signum() < -tol {
        return Err(Infeasible::CentroidRule);
    }
    if shape.before_flight && c.t_td < -tol {
        return Err(Infeasible::FlightRule);
    }
    if shape.after_flight && c.t_e - (c.t_td + shape.dt) < -tol {
        return Err(Infeasible::FlightRule);
    }
    Ok(())
}

#[cfg(test)]
mod tests;
