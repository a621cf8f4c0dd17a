//! Sine and cosine of angles in degrees, branch-free so that a loop over many angles
//! compiles to SIMD instructions.
//!
//! # Model
//! ```text
//! k = round(x / 90°),  d = x − 90°·k  (exact: both are multiples of ulp(x)),  r = d · π/180 ∈ [−π/4, π/4]
//! sin r ≈ r − r³/3! + … − r¹⁵/15!      (truncation < 5e-17 on |r| ≤ π/4)
//! cos r ≈ 1 − r²/2! + … + r¹⁶/16!      (truncation < 3e-18)
//! (sin x, cos x) = quadrant k mod 4 of (sin r, cos r): swap for odd k, signs by k
//! ```
//! Exact 0 and ±1 at multiples of 90°. Within 6e-16 of libm `sin_cos(x.to_radians())`
//! on ±360°, most of it libm's own error: `to_radians` rounds the argument by up to
//! 4.4e-16 there. For larger angles that rounding grows with |x| while the exact reduction
//! here does not; against libm of the exactly reduced `x mod 360°` the difference stays
//! under 1e-15 over ±10⁶ degrees (both bounds are checked by the test below). Angles of
//! more than [`MAX_REDUCED_DEG`] in magnitude, where `90°·k` is no longer exact, take libm.
//!
//! The same operations in the same order give the same bits whatever the instruction set
//! (Rust never fuses a multiply and an add on its own), so a caller may compile the loop
//! for AVX2 behind a run-time check and keep this scalar code as the fallback.
//!
//! # References
//! Muller, *Elementary Functions* (3rd ed.), §11 (additive range reduction).

/// 1.5·2⁵²: adding it rounds a double of magnitude < 2⁵¹ to an integer, kept in the low
/// bits of the sum's mantissa.
const ROUND_MAGIC: f64 = 6755399441055744.0;

/// Largest angle magnitude the polynomial path reduces, degrees (2⁴⁴: `90°·k` and
/// `x − 90°·k` stay exact below it); larger angles take libm.
pub const MAX_REDUCED_DEG: f64 = 17_592_186_044_416.0;

/// sin and cos of `x` degrees by the polynomial path (no large-angle check).
#[inline(always)]
fn sincos_deg_poly(x: f64) -> (f64, f64) {
    let k = x * (1.0 / 90.0) + ROUND_MAGIC;
    let quad = k.to_bits() & 3;
    let r = (x - (k - ROUND_MAGIC) * 90.0) * (std::f64::consts::PI / 180.0);
    let r2 = r * r;
    #[rustfmt::skip]
    let s = r + r * r2 * (-1.0 / 6.0 + r2 * (1.0 / 120.0 + r2 * (-1.0 / 5040.0
        + r2 * (1.0 / 362880.0 + r2 * (-1.0 / 39916800.0 + r2 * (1.0 / 6227020800.0
        + r2 * (-1.0 / 1307674368000.0)))))));
    #[rustfmt::skip]
    let c = 1.0 + r2 * (-0.5 + r2 * (1.0 / 24.0 + r2 * (-1.0 / 720.0
        + r2 * (1.0 / 40320.0 + r2 * (-1.0 / 3628800.0 + r2 * (1.0 / 479001600.0
        + r2 * (-1.0 / 87178291200.0 + r2 * (1.0 / 20922789888000.0))))))));
    let swap = quad & 1 == 1;
    let (s1, c1) = (if swap { c } else { s }, if swap { s } else { c });
    let sn = if quad & 2 != 0 { -s1 } else { s1 };
    let cn = if (quad + 1) & 2 != 0 { -c1 } else { c1 };
    (sn, cn)
}

/// sin and cos of `x` degrees (see the module docs).
#[inline(always)]
pub fn sincos_deg(x: f64) -> (f64, f64) {
    if x.abs() <= MAX_REDUCED_DEG {
        sincos_deg_poly(x)
    } else {
        x.to_radians().sin_cos()
    }
}

/// [`sincos_deg`] of 4 angles: the polynomial branch-free over the lanes (one SIMD
/// register each under AVX2), libm only when a lane exceeds [`MAX_REDUCED_DEG`].
#[inline(always)]
pub fn sincos_deg_x4(x: [f64; 4]) -> ([f64; 4], [f64; 4]) {
    let sc: [(f64, f64); 4] = std::array::from_fn(|l| sincos_deg_poly(x[l]));
    let mut s: [f64; 4] = std::array::from_fn(|l| sc[l].0);
    let mut c: [f64; 4] = std::array::from_fn(|l| sc[l].1);
    if x.iter().any(|v| v.abs() > MAX_REDUCED_DEG) {
        for l in 0..4 {
            (s[l], c[l]) = sincos_deg(x[l]);
        }
    }
    (s, c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agrees_with_libm_over_a_million_degrees() {
        // 1e-15: a few ulp of 1 (libm ≤ 1 ulp, the reduction one rounding, the
        // polynomial's truncation < 5e-17 and its rounding a few ulp).
        let mut rng = crate::testkit::Rng::new(0x9e37_79b9);
        let (mut worst, mut worst_turn): (f64, f64) = (0.0, 0.0);
        for i in 0..200_000 {
            let a = if i % 2 == 0 {
                rng.uniform(-360.0, 360.0)
            } else {
                rng.uniform(-1e6, 1e6)
            };
            let (s, c) = sincos_deg(a);
            // `%` is exact: the reference sees the same angle, reduced without rounding.
            let (s0, c0) = (a % 360.0).to_radians().sin_cos();
            let d = (s - s0).abs().max((c - c0).abs());
            worst = worst.max(d);
            if i % 2 == 0 {
                worst_turn = worst_turn.max(d);
            }
        }
        eprintln!("sincos_deg vs libm: {worst_turn:e} on ±360°, {worst:e} on ±1e6°");
        assert!(
            worst_turn <= 6e-16,
            "largest difference on ±360° {worst_turn:e}"
        );
        assert!(worst < 1e-15, "largest difference from libm {worst:e}");
    }

    #[test]
    fn exact_at_multiples_of_ninety_degrees() {
        for (k, (s, c)) in [(0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0)]
            .into_iter()
            .enumerate()
        {
            for turn in [-720.0, -360.0, 0.0, 360.0, 1080.0] {
                let a = 90.0 * k as f64 + turn;
                assert_eq!(sincos_deg(a), (s, c), "{a}°");
            }
        }
    }

    #[test]
    fn huge_angles_take_libm_and_lanes_equal_scalars() {
        let a = [3e15, -1e20, 12.5, -400.25];
        let (s, c) = sincos_deg_x4(a);
        for l in 0..4 {
            assert_eq!((s[l], c[l]), sincos_deg(a[l]));
        }
        assert_eq!(sincos_deg(3e15), 3e15f64.to_radians().sin_cos());
    }
}
