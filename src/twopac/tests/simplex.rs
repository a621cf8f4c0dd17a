//! The private simplex on LPs with known optima.

use crate::twopac::simplex::{LpFailure, Simplex};

#[test]
fn small_lp_with_known_optimum_and_warm_restarts() {
    // max x + y  s.t.  x + 2y + s1 = 4,  3x + y + s2 = 6  → (x, y) = (1.6, 1.2).
    let a = [1.0, 2.0, 1.0, 0.0, 3.0, 1.0, 0.0, 1.0];
    let mut lp = Simplex::new(&a, &[4.0, 6.0], 4).unwrap();
    lp.maximise(&[1.0, 1.0, 0.0, 0.0]).unwrap();
    let x = lp.solution();
    assert!(
        (x[0] - 1.6).abs() < 1e-12 && (x[1] - 1.2).abs() < 1e-12,
        "{x:?}"
    );
    // Warm restart with another objective: max x → (2, 0).
    lp.maximise(&[1.0, 0.0, 0.0, 0.0]).unwrap();
    assert!((lp.value_of(&[1.0, 0.0, 0.0, 0.0]) - 2.0).abs() < 1e-12);
    // max y → (0, 2).
    lp.maximise(&[0.0, 1.0, 0.0, 0.0]).unwrap();
    assert!((lp.value_of(&[0.0, 1.0, 0.0, 0.0]) - 2.0).abs() < 1e-12);
}

#[test]
fn infeasible_unbounded_and_redundant_rows() {
    // x + y = 1 and x + y = 2: infeasible.
    let r = Simplex::new(&[1.0, 1.0, 1.0, 1.0], &[1.0, 2.0], 2);
    assert_eq!(r.unwrap_err(), LpFailure::Infeasible);
    // x − y = 0: max x is unbounded.
    let mut lp = Simplex::new(&[1.0, -1.0], &[0.0], 2).unwrap();
    assert_eq!(lp.maximise(&[1.0, 0.0]).unwrap_err(), LpFailure::Unbounded);
    // A repeated row is dropped: x + y = 1 twice, max x → 1.
    let mut lp = Simplex::new(&[1.0, 1.0, 1.0, 1.0], &[1.0, 1.0], 2).unwrap();
    lp.maximise(&[1.0, 0.0]).unwrap();
    assert!((lp.solution()[0] - 1.0).abs() < 1e-12);
    // Negative right-hand side: −x − y = −3, max −x → x = 0, y = 3.
    let mut lp = Simplex::new(&[-1.0, -1.0], &[-3.0], 2).unwrap();
    lp.maximise(&[-1.0, 0.0]).unwrap();
    assert!((lp.solution()[1] - 3.0).abs() < 1e-12);
}
