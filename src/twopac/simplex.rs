//! A small dense two-phase tableau simplex for `max cᵀx, A x = b, x ≥ 0`, warm-started
//! across objectives (private to `twopac`; the H-representation of [`super::region`] runs
//! one LP per support direction on the same constraints).
//!
//! # Model
//!
//! ```text
//! phase 1:  max −Σ aᵢ   s.t.  A x + a = b (rows flipped so b ≥ 0),  x, a ≥ 0
//! phase 2:  max cᵀx     from the last optimal basis (Dantzig pricing, Bland after stalls)
//! ```
//!
//! Redundant rows (an artificial left basic at zero with no structural pivot) are deleted.
//!
//! # References
//!
//! Chvátal, *Linear Programming* (1983), ch. 2–3 (tableau, two phases, Bland's rule).

/// Reduced cost above which a column may enter.
const COST_TOL: f64 = 1e-11;
/// Smallest pivot element accepted.
const PIVOT_TOL: f64 = 1e-9;
/// Phase-1 residual (sum of artificials, relative to `1 + ‖b‖∞`) below which the
/// constraints are feasible.
const FEAS_TOL: f64 = 1e-9;
/// Pivots with Dantzig pricing before switching to Bland's rule (anti-cycling).
const DANTZIG_PIVOTS: usize = 200;

/// Why an LP has no optimum.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LpFailure {
    /// `A x = b, x ≥ 0` has no solution.
    Infeasible,
    /// The objective grows without bound.
    Unbounded,
    /// The pivot cap was reached (numerical trouble).
    IterationLimit,
}

/// A feasible basis of `A x = b, x ≥ 0` with its tableau `B⁻¹ [A | b]`.
#[derive(Debug, Clone)]
pub(crate) struct Simplex {
    m: usize,
    n: usize,
    /// `m × (n + 1)` row-major; the last column is the basic solution.
    t: Vec<f64>,
    basis: Vec<usize>,
    /// Reduced-cost scratch, len `n`.
    cost: Vec<f64>,
}

impl Simplex {
    /// Phase 1 on `A x = b, x ≥ 0`; `a` is `m × n` row-major.
    pub(crate) fn new(a: &[f64], b: &[f64], n: usize) -> Result<Simplex, LpFailure> {
        let m = b.len();
        assert_eq!(a.len(), m * n, "simplex: A is not m × n");
        let w = n + m + 1;
        let mut t = vec![0.0; m * w];
        for i in 0..m {
            let s = if b[i] < 0.0 { -1.0 } else { 1.0 };
            for j in 0..n {
                t[i * w + j] = s * a[i * n + j];
            }
            t[i * w + n + i] = 1.0;
            t[i * w + n + m] = s * b[i];
        }
        let mut p1 = Simplex {
            m,
            n: n + m,
            t,
            basis: (n..n + m).collect(),
            cost: vec![0.0; n + m],
        };
        let mut c1 = vec![0.0; n + m];
        c1[n..].iter_mut().for_each(|c| *c = -1.0);
        p1.maximise(&c1)?;
        let bscale = 1.0 + b.iter().fold(0.0_f64, |acc, v| acc.max(v.abs()));
        let infeas: f64 = (0..m)
            .filter(|&i| p1.basis[i] >= n)
            .map(|i| p1.rhs(i))
            .sum();
        if infeas > FEAS_TOL * bscale {
            return Err(LpFailure::Infeasible);
        }
        // Drive artificials out of the basis; delete rows where that is impossible.
        let mut keep = vec![true; m];
        for (i, keep_i) in keep.iter_mut().enumerate() {
            if p1.basis[i] < n {
                continue;
            }
            let row = &p1.t[i * w..i * w + n];
            let best =
                (0..n)
                    .map(|j| (j, row[j].abs()))
                    .fold((usize::MAX, PIVOT_TOL), |acc, (j, v)| {
                        if v > acc.1 {
                            (j, v)
                        } else {
                            acc
                        }
                    });
            if best.0 == usize::MAX {
                *keep_i = false;
            } else {
                p1.pivot(i, best.0);
            }
        }
        let rows: Vec<usize> = (0..m).filter(|&i| keep[i]).collect();
        let m2 = rows.len();
        let mut t2 = Vec::with_capacity(m2 * (n + 1));
        for &i in &rows {
            t2.extend_from_slice(&p1.t[i * w..i * w + n]);
            t2.push(p1.t[i * w + n + m].max(0.0));
        }
        Ok(Simplex {
            m: m2,
            n,
            t: t2,
            basis: rows.iter().map(|&i| p1.basis[i]).collect(),
            cost: vec![0.0; n],
        })
    }

    #[inline]
    fn rhs(&self, i: usize) -> f64 {
        self.t[i * (self.n + 1) + self.n]
    }

    fn pivot(&mut self, r: usize, j: usize) {
        let w = self.n + 1;
        let p = self.t[r * w + j];
        for v in &mut self.t[r * w..(r + 1) * w] {
            *v /= p;
        }
        let (before, rest) = self.t.split_at_mut(r * w);
        let (prow, after) = rest.split_at_mut(w);
        for row in before.chunks_exact_mut(w).chain(after.chunks_exact_mut(w)) {
            let f = row[j];
            if f != 0.0 {
                for (v, pv) in row.iter_mut().zip(prow.iter()) {
                    *v -= f * pv;
                }
                row[j] = 0.0;
            }
        }
        self.basis[r] = j;
    }

    /// Phase 2: maximise `cᵀx` (len `n`) from the current basis.
    pub(crate) fn maximise(&mut self, c: &[f64]) -> Result<(), LpFailure> {
        let (m, n, w) = (self.m, self.n, self.n + 1);
        let cap = 50 * (m + n) + 100;
        for it in 0..cap {
            self.cost.copy_from_slice(c);
            for i in 0..m {
                let cb = c[self.basis[i]];
                if cb != 0.0 {
                    let row = &self.t[i * w..i * w + n];
                    for (d, v) in self.cost.iter_mut().zip(row) {
                        *d -= cb * v;
                    }
                }
            }
            let enter =
                if it < DANTZIG_PIVOTS {
                    let (j, d) = self.cost.iter().enumerate().fold(
                        (usize::MAX, COST_TOL),
                        |acc, (j, &d)| if d > acc.1 { (j, d) } else { acc },
                    );
                    (d > COST_TOL).then_some(j)
                } else {
                    self.cost.iter().position(|&d| d > COST_TOL)
                };
            let Some(j) = enter else {
                return Ok(());
            };
            let mut leave: Option<(usize, f64)> = None;
            for i in 0..m {
                let a = self.t[i * w + j];
                if a > PIVOT_TOL {
                    let ratio = self.rhs(i).max(0.0) / a;
                    let better = match leave {
                        None => true,
                        Some((l, best)) => {
                            ratio < best || (ratio == best && self.basis[i] < self.basis[l])
                        }
                    };
                    if better {
                        leave = Some((i, ratio));
                    }
                }
            }
            let Some((r, _)) = leave else {
                return Err(LpFailure::Unbounded);
            };
            self.pivot(r, j);
        }
        Err(LpFailure::IterationLimit)
    }

    /// `Σ_j coeff_j x_j` at the current basic solution (`coeff` len `n`).
    pub(crate) fn value_of(&self, coeff: &[f64]) -> f64 {
        (0..self.m)
            .map(|i| coeff[self.basis[i]] * self.rhs(i))
            .sum()
    }

    /// The current basic solution (len `n`).
    #[cfg(test)]
    pub(crate) fn solution(&self) -> Vec<f64> {
        let mut x = vec![0.0; self.n];
        for i in 0..self.m {
            x[self.basis[i]] = self.rhs(i);
        }
        x
    }
}
