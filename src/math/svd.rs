//! A singular value decomposition that refuses non-finite input instead of panicking.
//!
//! nalgebra's `SVD::new` sorts the singular values with `partial_cmp(..).expect(..)`, so a
//! NaN or ∞ anywhere in the matrix panics (found by the mutation fuzzer on a mutated clip
//! whose samples reached a least-squares fit). Every SVD of the crate goes through
//! [`svd`], which answers `None` there; callers fall back as they do for a singular system.

use nalgebra::{DMatrix, Dyn, SVD};

/// Convergence tolerance of the implicit-shift iteration: nalgebra's own default for
/// `SVD::new` (5 ε), so results are those of `SVD::new` bit for bit.
const SVD_EPS: f64 = 5.0 * f64::EPSILON;
/// Most implicit-shift iterations (`SVD::new` has no bound). The fits here are at most a
/// few hundred rows by 17 columns and converge in tens of iterations; the bound only stops a
/// pathological input.
pub const MAX_SVD_ITERATIONS: usize = 100_000;

/// The SVD of `m` (`U` and `Vᵀ` as requested), or `None` when an entry is not finite or
/// the iteration does not converge within [`MAX_SVD_ITERATIONS`].
pub fn svd(m: DMatrix<f64>, compute_u: bool, compute_v: bool) -> Option<SVD<f64, Dyn, Dyn>> {
    if !m.iter().all(|v| v.is_finite()) {
        return None;
    }
    SVD::try_new(m, compute_u, compute_v, SVD_EPS, MAX_SVD_ITERATIONS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_input_gives_none_and_finite_input_a_decomposition() {
        let mut m = DMatrix::from_row_slice(2, 2, &[3.0, 0.0, 0.0, 2.0]);
        let d = svd(m.clone(), true, true).expect("finite");
        assert!((d.singular_values[0] - 3.0).abs() < 1e-12);
        m[(1, 0)] = f64::NAN;
        assert!(svd(m.clone(), true, true).is_none());
        m[(1, 0)] = f64::INFINITY;
        assert!(svd(m, true, false).is_none());
    }
}
