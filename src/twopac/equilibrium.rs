//! Static and dynamic equilibrium of a contact set in the equality form (eq 1, eq 12) and
//! the robustness margin of the reference implementation (two-pac §2.2, §8.2, §9).
//!
//! # Model
//!
//! ```text
//! G = [ I₃ … I₃ ; p̂_0 … p̂_{n_p−1} ]   (6 × 3n_p),   V = blockdiag(V_0 … V_{n_p−1})   (§2.1 rays)
//! w(c, c̈) = [ m (c̈ − g⃗) ;  c × m (c̈ − g⃗) ]                   (N, N·m; eq 1 with L̇ = 0)
//! equilibrium  ⇔  ∃ β ≥ 0 :  G V β = w(c, c̈)                  (β in N, unit rays)
//! static (c̈ = 0):  w = D c + d,   D = [0₃ₓ₃ ; m ĝ],   d = [−m g⃗ ; 0]           (eq 12)
//! margin: b0* = max b0  s.t.  G V β = w,  β_j ≥ b0 ∀j;    margin = b0* · 4μ/(1 + μ²)   (N)
//! ```
//!
//! `4μ/(1 + μ²) = ‖f₀ × r₀‖` with `f₀ = Σ_j r_j` the sum of a point's unit rays: the
//! reference implementation's conversion of `b0` to newtons (§9), with the smallest `μ` of
//! the set (§8.2). `G V β` is solved on the range of `G V` (a thin SVD): a wrench with a
//! component outside it (relative `1e-9`) is [`Status::Infeasible`], e.g. a single point
//! contact with the COM off its vertical. Force closure, `∃ β > 0 : G V β = 0`, makes the
//! margin unbounded: [`Status::ForceClosure`], every COM in equilibrium.
//!
//! # Frames and units
//!
//! World frame, Z up, `g⃗ = (0, 0, −9.81)` m/s²; m, kg, N; wrenches about the world origin.
//!
//! # References
//!
//! Tonneau et al., 2PAC, eq 1 and 12; Del Prete et al. 2016, "Fast algorithms to test
//! robust static equilibrium" (the margin `b0`); spec two-pac §2.2, §8.2, §9.

use super::contact::{friction_rays, is_degenerate, min_mu, Contact, ContactPoint};
use super::v3::{cross, scale};
use super::TwopacError;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus, ZeroConeT,
};
use nalgebra::{DMatrix, DVector};
use std::sync::OnceLock;

pub use crate::math::constants::GRAVITY;
/// Singular values of `G V` below this fraction of the largest are treated as zero.
pub const RANK_TOL_REL: f64 = 1e-9;
/// A wrench with `‖w − UUᵀw‖ > RANGE_TOL_REL · max(‖w‖, m g · 1 m)` is outside `range(G V)`.
pub const RANGE_TOL_REL: f64 = 1e-9;
/// Collinearity tolerance of §4 for `degenerate_contacts`, m.
pub const DEGENERATE_TOL_M: f64 = 1e-3;
/// Most contacts of one contact set: a phase of `twopac --phases` or the file of
/// `equilibrium --contacts` (count). The margin LP is dense in the 16 rays of a
/// rectangle's corners: its memory grows with the square of the contacts.
pub const MAX_CONTACTS: usize = 64;
/// Most contact points of one contact set: [`MAX_CONTACTS`] rectangles of 4 corners.
pub const MAX_CONTACT_POINTS: usize = 4 * MAX_CONTACTS;
/// Most COM states of one `equilibrium --points` table (rows), one LP each.
pub const MAX_COM_STATES: usize = 1_000_000;
/// Most contact-states of one `equilibrium` job: contacts × (COM states + the cells of
/// the `--png` slice, [`crate::plot::equilibrium::DEFAULT_SLICE_CELLS`]², each of which
/// may need its LP). One state's margin LP takes about 0.1–0.17 ms per contact on two
/// cores (measured with 4, 16 and 64 contacts × 2,000 states: 0.83 s, 4.6 s, 21 s, the
/// test profile, whose solver is built as in release), so the limit is about 3 minutes
/// there. 64 contacts × 20,000 states once ran for more than 300 s, and 10⁶ states
/// (within [`MAX_COM_STATES`]) for about 8 hours.
pub const MAX_CONTACT_STATES: usize = 1_000_000;
/// Force closure is declared when `max t s.t. G V β = 0, β ≥ t, t ≤ 1` exceeds this.
pub const FORCE_CLOSURE_T: f64 = 0.5;

/// How the verdict was reached (§8.2 `status`); whether the state is in equilibrium is
/// [`Verdict::in_equilibrium`], never the status alone.
///
/// | status | in equilibrium | margin |
/// |---|---|---|
/// | `solved` | when `margin > 0` | the LP's, N (≤ 0: how far outside) |
/// | `force_closure` | always | unbounded (null) |
/// | `infeasible` | never | null: no force distribution makes the wrench |
/// | `solver_failed` | never | null |
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Status {
    /// The margin LP was solved: `in_equilibrium = margin > 0`; a margin `≤ 0` is a COM
    /// state outside the region (named `ok` before issue 38, which read as "in equilibrium").
    Solved,
    /// Internal forces can grow without bound: every COM is in equilibrium, margin unbounded.
    ForceClosure,
    /// `G V β = w` has no solution with `β ≥ 0` at any margin.
    Infeasible,
    /// The LP solver stopped without an answer, or the COM state is not finite
    /// (reported, never hidden).
    SolverFailed,
}

impl Status {
    /// The lower-case name used in output tables (`solved`, `force_closure`, …).
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Solved => "solved",
            Status::ForceClosure => "force_closure",
            Status::Infeasible => "infeasible",
            Status::SolverFailed => "solver_failed",
        }
    }
}

/// The equilibrium verdict at one COM state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Verdict {
    /// What kind of answer this is.
    pub status: Status,
    /// In equilibrium (strictly inside for `Solved`; always for `ForceClosure`).
    pub in_equilibrium: bool,
    /// Robustness margin `b0* · 4μ/(1 + μ²)`, N; `None` unless `status == Solved`.
    pub margin_n: Option<f64>,
    /// The raw LP optimum `b0*`, N (smallest ray coefficient); `None` unless `Solved`.
    pub b0_n: Option<f64>,
}

/// The equality form of one contact set: generators `G V`, its range, force closure.
#[derive(Debug, Clone)]
pub struct EqualityForm {
    /// Total mass `m`, kg.
    pub mass_kg: f64,
    /// The contact points, in order (4 columns each).
    pub points: Vec<ContactPoint>,
    /// Columns of `G V`: `(r, p × r)` per point and ray, 6-vectors.
    pub generators: Vec<[f64; 6]>,
    /// `4μ/(1 + μ²)` with the smallest `μ` of the set (0 without points).
    pub b0_to_newton: f64,
    /// One point or collinear points (§4, 1 mm).
    pub degenerate: bool,
    /// `∃ β > 0 : G V β = 0` (an LP, computed on first use).
    force_closure: OnceLock<bool>,
    /// Orthonormal basis of `range(G V)`, 6 × rank (an SVD, computed on first use).
    range: OnceLock<DMatrix<f64>>,
}

/// The gravito-inertial wrench `w(c, c̈) = [m(c̈ − g⃗); c × m(c̈ − g⃗)]` (eq 1, `L̇ = 0`).
pub fn wrench(mass_kg: f64, com: [f64; 3], acc: [f64; 3]) -> [f64; 6] {
    let f = scale(mass_kg, [acc[0], acc[1], acc[2] + GRAVITY]);
    let t = cross(com, f);
    [f[0], f[1], f[2], t[0], t[1], t[2]]
}

/// The generator columns `(r_j, p × r_j)` of `G V` for a list of points (§2.1, §2.2).
pub fn generators(points: &[ContactPoint]) -> Vec<[f64; 6]> {
    let mut out = Vec::with_capacity(4 * points.len());
    for p in points {
        for r in friction_rays(p.normal, p.mu) {
            let t = cross(p.pos, r);
            out.push([r[0], r[1], r[2], t[0], t[1], t[2]]);
        }
    }
    out
}

impl EqualityForm {
    /// The equality form of `contacts` for mass `mass_kg`.
    ///
    /// # Errors
    ///
    /// As [`EqualityForm::from_points`].
    pub fn new(contacts: &[Contact], mass_kg: f64) -> Result<EqualityForm, TwopacError> {
        let points: Vec<ContactPoint> = contacts.iter().flat_map(Contact::points).collect();
        EqualityForm::from_points(points, mass_kg)
    }

    /// [`EqualityForm::new`] from contact points.
    ///
    /// # Errors
    ///
    /// [`TwopacError::InvalidMass`] for a non-positive or non-finite mass;
    /// [`TwopacError::Cap`] for more than [`MAX_CONTACT_POINTS`] points.
    pub fn from_points(
        points: Vec<ContactPoint>,
        mass_kg: f64,
    ) -> Result<EqualityForm, TwopacError> {
        if !(mass_kg.is_finite() && mass_kg > 0.0) {
            return Err(TwopacError::InvalidMass { mass_kg });
        }
        if points.len() > MAX_CONTACT_POINTS {
            return Err(TwopacError::Cap {
                what: "contact points in one contact set",
                found: points.len().to_string(),
                max: MAX_CONTACT_POINTS,
                cap: "MAX_CONTACT_POINTS",
            });
        }
        let generators = generators(&points);
        let mu = min_mu(&points).unwrap_or(0.0);
        Ok(EqualityForm {
            mass_kg,
            degenerate: points.is_empty() || is_degenerate(&points, DEGENERATE_TOL_M),
            points,
            generators,
            b0_to_newton: 4.0 * mu / (1.0 + mu * mu),
            force_closure: OnceLock::new(),
            range: OnceLock::new(),
        })
    }

    fn range(&self) -> &DMatrix<f64> {
        self.range.get_or_init(|| range_basis(&self.generators))
    }

    /// Rank of `G V` (6 unless degenerate).
    pub fn rank(&self) -> usize {
        self.range().ncols()
    }

    /// Whether the set is in force closure (`∃ β > 0 : G V β = 0`): every COM and
    /// acceleration is then in equilibrium.
    pub fn force_closure(&self) -> bool {
        *self
            .force_closure
            .get_or_init(|| self.detect_force_closure())
    }

    /// `‖w − UUᵀw‖`: the part of `w` no force distribution can produce.
    pub fn range_residual(&self, w: &[f64; 6]) -> f64 {
        let wv = DVector::from_column_slice(w);
        let u = self.range();
        let proj = u * (u.transpose() * &wv);
        (wv - proj).norm()
    }

    /// Whether `w` lies in `range(G V)` within [`RANGE_TOL_REL`].
    fn in_range(&self, w: &[f64; 6]) -> bool {
        let scale = (w.iter().map(|v| v * v).sum::<f64>().sqrt()).max(self.mass_kg * GRAVITY);
        self.range_residual(w) <= RANGE_TOL_REL * scale
    }

    /// `max t  s.t.  G V β = 0, β_j ≥ t, t ≤ 1` exceeds [`FORCE_CLOSURE_T`].
    fn detect_force_closure(&self) -> bool {
        if self.generators.is_empty() || self.rank() == 0 {
            return false;
        }
        let (t, status) = self.max_min_coefficient(&[0.0; 6], Some(1.0));
        matches!(status, SolverStatus::Solved | SolverStatus::AlmostSolved) && t > FORCE_CLOSURE_T
    }

    /// `max b0  s.t.  Uᵀ G V β = Uᵀ w,  β_j ≥ b0` (and `b0 ≤ cap`), by clarabel.
    fn max_min_coefficient(&self, w: &[f64; 6], cap: Option<f64>) -> (f64, SolverStatus) {
        let n = self.generators.len();
        let r = self.rank();
        let mut rows: Vec<Vec<f64>> = Vec::with_capacity(r + n + 1);
        let mut rhs = Vec::with_capacity(r + n + 1);
        for k in 0..r {
            let u = self.range().column(k);
            let mut row = vec![0.0; n + 1];
            for (j, g) in self.generators.iter().enumerate() {
                row[j] = (0..6).map(|i| u[i] * g[i]).sum();
            }
            rows.push(row);
            rhs.push((0..6).map(|i| u[i] * w[i]).sum());
        }
        for j in 0..n {
            // b0 − β_j ≤ 0
            let mut row = vec![0.0; n + 1];
            row[j] = -1.0;
            row[n] = 1.0;
            rows.push(row);
            rhs.push(0.0);
        }
        if let Some(cap) = cap {
            let mut row = vec![0.0; n + 1];
            row[n] = 1.0;
            rows.push(row);
            rhs.push(cap);
        }
        let mut q = vec![0.0; n + 1];
        q[n] = -1.0;
        let a = CscMatrix::from(rows.iter().map(|r| r.iter()));
        let p = CscMatrix::<f64>::zeros((n + 1, n + 1));
        let cones = [ZeroConeT(r), NonnegativeConeT(rows.len() - r)];
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .build()
            .expect("clarabel default settings are valid");
        let Ok(mut solver) = DefaultSolver::new(&p, &q, &a, &rhs, &cones, settings) else {
            return (f64::NAN, SolverStatus::NumericalError);
        };
        solver.solve();
        (solver.solution.x[n], solver.solution.status)
    }

    /// The verdict and robustness margin at COM `com` with acceleration `acc` (§8.2, §9).
    pub fn verdict(&self, com: [f64; 3], acc: [f64; 3]) -> Verdict {
        let none = |status, in_equilibrium| Verdict {
            status,
            in_equilibrium,
            margin_n: None,
            b0_n: None,
        };
        if !com.iter().chain(&acc).all(|v| v.is_finite()) {
            return none(Status::SolverFailed, false);
        }
        if self.force_closure() {
            return none(Status::ForceClosure, true);
        }
        let w = wrench(self.mass_kg, com, acc);
        if self.generators.is_empty() || !self.in_range(&w) {
            return none(Status::Infeasible, false);
        }
        let (b0, status) = self.max_min_coefficient(&w, None);
        match status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => {
                let margin = b0 * self.b0_to_newton;
                Verdict {
                    status: Status::Solved,
                    in_equilibrium: margin > 0.0,
                    margin_n: Some(margin),
                    b0_n: Some(b0),
                }
            }
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                none(Status::Infeasible, false)
            }
            SolverStatus::DualInfeasible | SolverStatus::AlmostDualInfeasible => {
                none(Status::ForceClosure, true)
            }
            _ => none(Status::SolverFailed, false),
        }
    }

    /// The §7 validation slack `s* = min s  s.t.  G V β = w, β + s ≥ 0, s ≥ 0`, N.
    ///
    /// Equal to `max(0, −b0*)` (substitute `b0 = −s`); `0` under force closure, `+∞` when
    /// infeasible or when the solver fails.
    pub fn validation_slack(&self, com: [f64; 3], acc: [f64; 3]) -> f64 {
        let v = self.verdict(com, acc);
        match v.status {
            Status::ForceClosure => 0.0,
            Status::Solved => (-v.b0_n.unwrap_or(f64::NAN)).max(0.0),
            Status::Infeasible | Status::SolverFailed => f64::INFINITY,
        }
    }

    /// The static right-hand side `D c + d` (eq 12), i.e. `w(c, 0)`.
    pub fn static_rhs(&self, com: [f64; 3]) -> [f64; 6] {
        wrench(self.mass_kg, com, [0.0; 3])
    }
}

/// Orthonormal basis of the span of the generator columns (thin SVD of `G V`).
fn range_basis(generators: &[[f64; 6]]) -> DMatrix<f64> {
    if generators.is_empty() {
        return DMatrix::zeros(6, 0);
    }
    let gv = DMatrix::from_fn(6, generators.len(), |i, j| generators[j][i]);
    let Some(svd) = crate::math::svd::svd(gv, true, false) else {
        return DMatrix::zeros(6, 0);
    };
    let u = svd.u.expect("svd computed with u");
    let smax = svd.singular_values.max();
    let keep: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&k| svd.singular_values[k] > RANK_TOL_REL * smax && smax > 0.0)
        .collect();
    DMatrix::from_fn(6, keep.len(), |i, k| u[(i, keep[k])])
}
