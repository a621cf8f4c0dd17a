//! Stage A fit of one stance (spec stance-model §4.1 steps 2–5): sample, DFT, dominant terms.
//!
//! # Model
//! ```text
//! τ_j = j/N, j = 0 … N−1 (τ = 1 not sampled),  t_j = t_TD + Δt·τ_j
//! f_j = R_s · m (a(t_j) − g⃗),   g⃗ = (0, 0, −g)  ⇒  world f_z = m (a_z + g)          N
//! X_k = Σ_j f_j e^{−2πi jk/N}                                  (per stance axis)
//! c0 = Re X_0 / N;   A_k = 2|X_k|/N,  φ_k = atan2(Im X_k, Re X_k)   for 1 ≤ k < N/2
//! candidates k = 1 … k_max,  k_max = min(⌊(N−1)/2⌋, j_cap),  j_cap = max(1, ⌊(n_st−3)/2⌋)
//! sort by A_k descending (ties → lower k); keep the shortest prefix with
//!   Σ A_k² ≥ η Σ_candidates A_k², at most K_max terms (and never a term with A_k = 0)
//! fit_rms = √( (1/N) Σ_j (f_j − f(τ_j))² ) = √( Σ_{bins left out} |X_k|² ) / N   (Parseval)
//! ```
//! The Nyquist bin (`k = N/2`, N even) is never a candidate because `k_max < N/2`.
//!
//! # Frames and units
//! `acc`: world acceleration splines (x, y, z; m/s², Z up) over clip time (s);
//! `r_s`: rows `e_h, e_p, e_v` in world coordinates, so `f_stance = R_s · f_world`;
//! forces in newtons, `Δt` in seconds, `m` in kilograms.
//!
//! # References
//! Pollard & Behmaram-Mosavat, eq 1; spec stance-model §4.1 (factor 2, Nyquist, `j_cap`).

use std::sync::Arc;

use realfft::num_complex::Complex;
use realfft::{RealFftPlanner, RealToComplex};

use super::{AxisModel, FitOptions, ForceModel, GRAVITY};
use crate::math::spline::NaturalSpline;
use crate::{Error, Result};

/// Smallest accepted `FitOptions::samples` (a DFT needs at least two samples).
pub const MIN_SAMPLES: usize = 2;
/// Largest accepted `FitOptions::samples`, 2²⁰ (a guard against absurd allocations; the
/// spec's `N` is 64).
pub const MAX_SAMPLES: usize = 1 << 20;

/// Per-thread scratch for [`fit_stage_a`]: the FFT plan and buffers for one `N`.
///
/// Build one per worker thread (e.g. rayon `map_init`) and reuse it for every stance; a
/// fit with another `samples` value re-plans it once.
pub struct FitWorkspace {
    n: usize,
    fft: Arc<dyn RealToComplex<f64>>,
    input: Vec<f64>,
    spectrum: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
    samples: [Vec<f64>; 3],
    order: Vec<usize>,
    amps: Vec<f64>,
}

impl std::fmt::Debug for FitWorkspace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FitWorkspace")
            .field("samples", &self.n)
            .finish()
    }
}

impl FitWorkspace {
    /// Plan for `samples` points, clamped to [`MIN_SAMPLES`] … [`MAX_SAMPLES`].
    pub fn new(samples: usize) -> Self {
        let n = samples.clamp(MIN_SAMPLES, MAX_SAMPLES);
        let fft = RealFftPlanner::<f64>::new().plan_fft_forward(n);
        FitWorkspace {
            n,
            input: fft.make_input_vec(),
            spectrum: fft.make_output_vec(),
            scratch: fft.make_scratch_vec(),
            fft,
            samples: std::array::from_fn(|_| vec![0.0; n]),
            order: Vec::with_capacity(n / 2),
            amps: Vec::with_capacity(n / 2 + 1),
        }
    }

    /// The number of samples `N` the workspace is planned for.
    pub fn samples(&self) -> usize {
        self.n
    }

    /// The three stance-axis sample vectors `f_j` (N) of the last [`fit_stage_a`].
    pub fn last_samples(&self) -> &[Vec<f64>; 3] {
        &self.samples
    }

    fn ensure(&mut self, samples: usize) {
        if self.n != samples.clamp(MIN_SAMPLES, MAX_SAMPLES) {
            *self = FitWorkspace::new(samples);
        }
    }
}

/// `j_cap = max(1, ⌊(n_st − 3)/2⌋)`: the bandwidth `n_st` stance frames support (§4.1).
///
/// Fewer than 5 stance frames give 1 (the formula's `max`). At 30 Hz a 0.22 s stance has
/// `n_st` = 6 → 1 or 7 → 2.
pub fn j_cap(n_st: usize) -> u32 {
    let j = n_st.saturating_sub(3) / 2;
    u32::try_from(j).unwrap_or(u32::MAX).max(1)
}

/// `k_max = min(⌊(N − 1)/2⌋, j_cap(n_st))`: the largest candidate harmonic.
pub fn k_max(samples: usize, n_st: usize) -> u32 {
    let half = u32::try_from(samples.saturating_sub(1) / 2).unwrap_or(u32::MAX);
    half.min(j_cap(n_st))
}

fn check_options(opts: &FitOptions) -> Result<()> {
    if !(MIN_SAMPLES..=MAX_SAMPLES).contains(&opts.samples) {
        return Err(Error::invalid(
            "fit.samples",
            format!("{} is not in [{MIN_SAMPLES}, {MAX_SAMPLES}]", opts.samples),
        ));
    }
    if !(0.0..=1.0).contains(&opts.energy) {
        return Err(Error::invalid(
            "fit.energy",
            format!("{} is not in [0, 1]", opts.energy),
        ));
    }
    Ok(())
}

/// Steps 4–5 on one axis: DFT of `samples` (N), candidates `1 … k_max`, dominant terms.
///
/// Uses `ws` for the FFT (re-planned if `samples.len()` differs); `fit_rms` is set over
/// the given samples. Errors when the number of samples is outside [`MIN_SAMPLES`] …
/// [`MAX_SAMPLES`] or `opts.energy` is outside `[0, 1]`; `opts.samples` is ignored here.
pub fn fit_axis(
    ws: &mut FitWorkspace,
    samples: &[f64],
    k_max: u32,
    opts: &FitOptions,
) -> Result<AxisModel> {
    check_options(&FitOptions {
        samples: samples.len(),
        ..*opts
    })?;
    ws.ensure(samples.len());
    ws.input.copy_from_slice(samples);
    Ok(dft_select(ws, k_max, opts))
}

/// DFT of `ws.input` and the §4.1 step 5 selection; `ws.input` is consumed.
fn dft_select(ws: &mut FitWorkspace, k_max: u32, opts: &FitOptions) -> AxisModel {
    let FitWorkspace {
        n,
        fft,
        input,
        spectrum,
        scratch,
        order,
        amps,
        ..
    } = ws;
    let nf = *n as f64;
    if fft.process_with_scratch(input, spectrum, scratch).is_err() {
        // Only on a buffer-length mismatch, which `ensure` rules out: a constant 0 model.
        return AxisModel::constant(0.0);
    }
    let k_max = usize::try_from(k_max)
        .unwrap_or(usize::MAX)
        .min((*n - 1) / 2);
    amps.clear();
    amps.extend(spectrum[..=k_max].iter().map(|x| 2.0 * x.norm() / nf)); // factor 2 (§4.1)
    dominant_order(amps, order);
    let target = opts.energy * amps[1..].iter().map(|a| a * a).sum::<f64>();
    let mut model = AxisModel::constant(spectrum[0].re / nf);
    let mut kept = 0.0;
    for &k in order.iter().take(opts.max_harmonics) {
        if kept >= target || amps[k] == 0.0 || !amps[k].is_finite() {
            break;
        }
        kept += amps[k] * amps[k];
        model.harmonics.push(k as f64);
        model.amps.push(amps[k]);
        model.phases.push(spectrum[k].im.atan2(spectrum[k].re));
    }
    // Parseval: (1/N) Σ_j r_j² = (1/N²) Σ_k |R_k|², R = the bins the model leaves out
    // (the pairs k, N−k of the dropped k < N/2, and the Nyquist bin for even N).
    let paired = &spectrum[1..=(*n - 1) / 2];
    let mut ss: f64 = (1u32..)
        .zip(paired)
        .filter(|(k, _)| !model.harmonics.contains(&f64::from(*k)))
        .map(|(_, x)| 2.0 * x.norm_sqr())
        .sum();
    if *n % 2 == 0 {
        ss += spectrum[*n / 2].norm_sqr();
    }
    model.fit_rms = ss.sqrt() / nf;
    model
}

/// Fill `order` with `1 … amps.len()−1` sorted by `amps[k]` descending, ties → lower `k`.
fn dominant_order(amps: &[f64], order: &mut Vec<usize>) {
    order.clear();
    order.extend(1..amps.len());
    // A total order (ties → lower k), so the unstable sort is deterministic.
    order.sort_unstable_by(|&a, &b| amps[b].total_cmp(&amps[a]).then(a.cmp(&b)));
}

/// RMS over `τ_j = j/N` of `samples[j] − model(τ_j)` (N), evaluated directly; tests only.
#[cfg(test)]
fn rms_residual(samples: &[f64], model: &AxisModel) -> f64 {
    let nf = samples.len() as f64;
    let ss: f64 = samples
        .iter()
        .enumerate()
        .map(|(j, &f)| (f - model.eval(j as f64 / nf)).powi(2))
        .sum();
    (ss / nf).sqrt()
}

/// The kinematic applied force of one stance, `R_s · m (a(t) − g⃗)` (N, stance axes).
pub struct StanceForce<'a> {
    /// Natural splines of the SG world acceleration (x, y, z; m/s²) over clip time (s).
    pub acc: &'a [NaturalSpline; 3],
    /// Touchdown (s, the splines' time axis).
    pub t_td: f64,
    /// Stance duration `Δt` (s).
    pub dt: f64,
    /// Rows `e_h, e_p, e_v` in world coordinates.
    pub r_s: [[f64; 3]; 3],
    /// Body mass `m` (kg).
    pub mass_kg: f64,
    /// The stance foot's leg line (a single-foot running stance), else `None`.
    pub leg: Option<super::LegLine<'a>>,
}

impl StanceForce<'_> {
    /// Checks `Δt > 0`, `m > 0` and finite `t_TD`, `R_s`; `step` prefixes the message.
    ///
    /// # Errors
    /// [`crate::ErrorKind::Numeric`] saying which value is bad (they are computed upstream:
    /// the stance times, the heading, the body mass carried through).
    pub fn check(&self, step: &str) -> Result<()> {
        let bad = |what: String| Err(Error::numeric(format!("{step}: {what}")));
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return bad(format!("stance duration {} s is not positive", self.dt));
        }
        if !(self.mass_kg.is_finite() && self.mass_kg > 0.0) {
            return bad(format!("body mass {} kg is not positive", self.mass_kg));
        }
        if !self.t_td.is_finite() || self.r_s.iter().flatten().any(|v| !v.is_finite()) {
            return bad("touchdown time or stance rotation is not finite".into());
        }
        Ok(())
    }

    /// Fills `out[a][j]` with the force at `t = t_TD + Δt·τ_j`; false if any is not finite.
    pub fn sample(&self, tau: impl Iterator<Item = f64>, out: &mut [Vec<f64>; 3]) -> bool {
        let mut j = 0;
        for (k, t) in tau.map(|u| self.t_td + self.dt * u).enumerate() {
            let m = self.mass_kg;
            let f_world = [
                m * self.acc[0].eval(t),
                m * self.acc[1].eval(t),
                m * (self.acc[2].eval(t) + GRAVITY),
            ];
            for (axis, row) in self.r_s.iter().enumerate() {
                let f = row[0] * f_world[0] + row[1] * f_world[1] + row[2] * f_world[2];
                match out[axis].get_mut(k) {
                    Some(slot) => *slot = f,
                    None => out[axis].push(f),
                }
            }
            j = k + 1;
        }
        out.iter_mut().for_each(|o| o.truncate(j));
        out.iter().flatten().all(|v| v.is_finite())
    }
}

/// Stage A (§4.1 steps 2–5) for one stance: the stance-frame [`ForceModel`].
///
/// # Arguments
/// * `acc`: natural splines of the SG world acceleration (x, y, z; m/s²) over the clip's
///   kept frames, clip time in seconds (the linear extension applies outside them);
/// * `t_td`: touchdown (s, the splines' time axis); `dt`: stance duration `Δt` (s);
/// * `r_s`: rows `e_h, e_p, e_v` in world coordinates; `mass_kg`: body mass `m`;
/// * `n_st`: number of stance frames (sets `j_cap`; below 5 frames `j_cap = 1`).
///
/// # Errors
/// [`crate::ErrorKind::Numeric`] when `dt` or `mass_kg` is not finite and positive, `t_td`
/// or an entry of `r_s` is not finite, or a sampled force is not finite;
/// [`crate::ErrorKind::Invalid`] when `opts.samples ∉ [2, 2²⁰]` or `opts.energy ∉ [0, 1]`. Nothing else fails; `max_harmonics = 0` keeps only `c0`.
#[allow(clippy::too_many_arguments)]
pub fn fit_stage_a(
    ws: &mut FitWorkspace,
    acc: &[NaturalSpline; 3],
    t_td: f64,
    dt: f64,
    r_s: [[f64; 3]; 3],
    mass_kg: f64,
    n_st: usize,
    opts: &FitOptions,
) -> Result<ForceModel> {
    let bad = |what: String| Err(Error::numeric(format!("stage a: {what}")));
    check_options(opts)?;
    let stance = StanceForce {
        acc,
        t_td,
        dt,
        r_s,
        mass_kg,
        leg: None,
    };
    stance.check("stage a")?;
    ws.ensure(opts.samples);
    let n = ws.n;
    if !stance.sample((0..n).map(|j| j as f64 / n as f64), &mut ws.samples) {
        return bad(format!("sampled force is not finite near t = {t_td} s"));
    }
    let k_max = k_max(n, n_st);
    let mut axes: [AxisModel; 3] = Default::default();
    for (axis, model) in axes.iter_mut().enumerate() {
        ws.input.copy_from_slice(&ws.samples[axis]);
        *model = dft_select(ws, k_max, opts);
    }
    Ok(ForceModel {
        mass_kg,
        dt_s: dt,
        axes,
    })
}

#[cfg(test)]
mod tests;
