//! Test data shared by the unit tests of every module: the one seeded generator and the one
//! builder of random force models.

use std::f64::consts::PI;

use crate::force_model::{AxisModel, ForceModel, GRAVITY};

/// SplitMix64 (Steele, Lea & Flood 2014): a seeded generator for test data.
pub(crate) struct Rng(u64);

impl Rng {
    /// A generator started at `seed`.
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub(crate) fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[lo, hi)`.
    pub(crate) fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }

    /// Uniform integer in `lo..=hi`.
    pub(crate) fn int(&mut self, lo: u32, hi: u32) -> u32 {
        lo + (self.next_u64() % u64::from(hi - lo + 1)) as u32
    }
}

/// The harmonic content of a random axis: `1..=terms` cosines of harmonics `1..=max_j`
/// (repeated `j` allowed).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Harmonics {
    /// Most cosine terms.
    pub(crate) terms: u32,
    /// Highest harmonic number.
    pub(crate) max_j: u32,
    /// Every harmonic `j − ½` instead of `j` (the half-range cosines of
    /// `force_model::cosine`), from the same random draws.
    pub(crate) halves: bool,
}

/// A random axis: DC `c0` (N) plus cosines of amplitude up to `amp` (N), phases in
/// `[−π, π)`.
pub(crate) fn random_axis(rng: &mut Rng, c0: f64, amp: f64, h: Harmonics) -> AxisModel {
    let n = rng.int(1, h.terms) as usize;
    let half = if h.halves { 0.5 } else { 0.0 };
    let harmonics: Vec<f64> = (0..n)
        .map(|_| f64::from(rng.int(1, h.max_j)) - half)
        .collect();
    AxisModel {
        c0,
        amps: (0..n).map(|_| rng.uniform(0.0, amp)).collect(),
        phases: (0..n).map(|_| rng.uniform(-PI, PI)).collect(),
        harmonics,
        poly: Vec::new(),
        fit_rms: 0.0,
    }
}

/// A random stance-like model: mass 40–100 kg, Δt 0.15–0.5 s, a vertical bell
/// `A(1 − cos 2πτ)` (`A` 1–3 body weights) plus ringing up to `ringing` body weights, and
/// horizontal forces: DC within ±0.3 (heading) and ±0.1 (perpendicular) body weights plus
/// cosines up to 0.5 and 0.2 body weights.
pub(crate) fn bell_model(rng: &mut Rng, ringing: f64, h: Harmonics) -> ForceModel {
    let mass_kg = rng.uniform(40.0, 100.0);
    let weight = mass_kg * GRAVITY;
    let bell = rng.uniform(1.0, 3.0) * weight;
    let mut v = random_axis(rng, bell, ringing * weight, h);
    v.harmonics.push(1.0);
    v.amps.push(bell);
    v.phases.push(PI);
    let h_dc = rng.uniform(-0.3, 0.3) * weight;
    let p_dc = rng.uniform(-0.1, 0.1) * weight;
    ForceModel {
        mass_kg,
        dt_s: rng.uniform(0.15, 0.5),
        axes: [
            random_axis(rng, h_dc, 0.5 * weight, h),
            random_axis(rng, p_dc, 0.2 * weight, h),
            v,
        ],
    }
}
