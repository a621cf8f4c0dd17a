//! The FK kernel over `L` frames at once, one frame per f64 lane, and its run-time
//! dispatch: AVX2 + FMA when the CPU has both, else the same code built for the baseline
//! instruction set (the scalar fallback).
//!
//! # Model
//! ```text
//! per rotation channel k, lane l:  (sₖₗ, cₖₗ) = sincos_deg(q_l[idx_k])      one pass
//! per joint j, lane l:             R_j = R_p(j) · Π R_axis(sₖₗ, cₖₗ),  P_j = P_p(j) + R_p(j)·t_j
//! ```
//! the same operations, in the same order, as the one-frame FK of [`super`]; every
//! scalar becomes `L` values, so the sines, cosines, column mixes and products run `L`
//! wide with no shuffles, and lanes never mix: a frame's points do not depend on the
//! frames beside it nor on `L`.
//!
//! # Accuracy
//! [`crate::math::trig::sincos_deg`] reduces the angle by 90° exactly and evaluates Taylor
//! polynomials of degree 15 (sin) and 16 (cos) on |r| ≤ π/4: truncation < 5e-17, result
//! within 6e-16 of libm `sin_cos(x.to_radians())` on ±360° and within 1e-15 of libm of the
//! exactly reduced angle up to ±10⁶ degrees (angles beyond 2⁴⁴ degrees take libm).
//! Through a chain of rotations a point moves by at most a few ulp of its distance from
//! the root: well under 1e-12 m for a human skeleton (the tests check 1e-12 against the
//! libm FK, [`super::forward_libm`]).
//!
//! # Same bits on every path
//! Rust never contracts a multiply and an add into an FMA on its own (no fast-math), and
//! the AVX2 build runs the very same source, so [`Simd::Avx2`] and [`Simd::Scalar`] give
//! identical bits; the tests assert it, on random skeletons and on real clips.

use crate::math::trig::{sincos_deg, sincos_deg_x4};
use crate::skeleton::model::{Skeleton, TranslationMode};

/// Frames per SIMD batch of [`super::forward_frames`]: one frame per f64 lane of a
/// 256-bit register (AVX2).
pub const FK_LANES: usize = 4;

/// `L` values of one scalar, one per frame.
type Lanes<const L: usize> = [f64; L];

/// The instruction set of [`super::forward_frames`]' batches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Simd {
    /// Plain code (SSE2 on x86_64): the fallback, and what the tests check AVX2 against.
    Scalar,
    /// AVX2 with FMA, when the CPU reports both (x86_64 only).
    Avx2,
}

impl Simd {
    /// The best the running CPU supports.
    pub fn detect() -> Simd {
        #[cfg(target_arch = "x86_64")]
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
            return Simd::Avx2;
        }
        Simd::Scalar
    }
}

/// The skeleton's rotation channels as flat tables, built once per workspace.
#[derive(Debug, Clone)]
pub(super) struct RotTables {
    /// Row index of every rotation channel, joints in order.
    idx: Vec<usize>,
    /// Axis (0 x, 1 y, 2 z) of every rotation channel.
    axis: Vec<u8>,
    /// Range of `idx` per joint.
    joint: Vec<(usize, usize)>,
}

impl RotTables {
    /// The tables of `skel`.
    pub(super) fn new(skel: &Skeleton) -> RotTables {
        let (mut idx, mut axis, mut joint) = (Vec::new(), Vec::new(), Vec::new());
        for ch in &skel.channels {
            let start = idx.len();
            for &(a, i) in &ch.rotations {
                idx.push(i);
                axis.push(a as u8);
            }
            joint.push((start, idx.len()));
        }
        RotTables { idx, axis, joint }
    }
}

/// Per-lane scratch: per joint, world rotation (`rot[j][col][row]`) and position; per
/// rotation channel, its sine and cosine.
#[derive(Debug, Clone)]
pub(super) struct Scratch<const L: usize> {
    rot: Vec<[[Lanes<L>; 3]; 3]>,
    pos: Vec<[Lanes<L>; 3]>,
    sin: Vec<Lanes<L>>,
    cos: Vec<Lanes<L>>,
}

impl<const L: usize> Scratch<L> {
    /// Scratch for the skeleton of `tab` (`n_joints` joints).
    pub(super) fn new(n_joints: usize, tab: &RotTables) -> Self {
        let n_rot = tab.idx.len();
        Scratch {
            rot: vec![[[[0.0; L]; 3]; 3]; n_joints],
            pos: vec![[[0.0; L]; 3]; n_joints],
            sin: vec![[0.0; L]; n_rot],
            cos: vec![[0.0; L]; n_rot],
        }
    }
}

/// `col_A' = c·col_A + s·col_B`, `col_B' = −s·col_A + c·col_B` on `L` frames at once
/// (`super::mix` per lane).
#[inline(always)]
fn mix_lanes<const A: usize, const B: usize, const L: usize>(
    m: &mut [[Lanes<L>; 3]; 3],
    s: &Lanes<L>,
    c: &Lanes<L>,
) {
    let (ca, cb) = (m[A], m[B]);
    m[A] = std::array::from_fn(|r| std::array::from_fn(|l| c[l] * ca[r][l] + s[l] * cb[r][l]));
    m[B] = std::array::from_fn(|r| std::array::from_fn(|l| -s[l] * ca[r][l] + c[l] * cb[r][l]));
}

/// `m · v` on `L` frames at once (`super::mul_vec` per lane).
#[inline(always)]
fn mul_vec_lanes<const L: usize>(m: &[[Lanes<L>; 3]; 3], v: &[Lanes<L>; 3]) -> [Lanes<L>; 3] {
    std::array::from_fn(|r| {
        std::array::from_fn(|l| m[0][r][l] * v[0][l] + m[1][r][l] * v[1][l] + m[2][r][l] * v[2][l])
    })
}

/// The sines and cosines of every rotation channel of the `L` rows, in one pass.
#[inline(always)]
fn sincos_pass<const L: usize>(tab: &RotTables, x: &mut Scratch<L>, rows: &[&[f64]; L]) {
    for (k, &i) in tab.idx.iter().enumerate() {
        let a: Lanes<L> = std::array::from_fn(|l| rows[l][i]);
        if L == FK_LANES {
            let mut a4 = [0.0; FK_LANES];
            a4.copy_from_slice(&a);
            let (s4, c4) = sincos_deg_x4(a4);
            x.sin[k] = std::array::from_fn(|l| s4[l]);
            x.cos[k] = std::array::from_fn(|l| c4[l]);
        } else {
            let sc: [(f64, f64); L] = std::array::from_fn(|l| sincos_deg(a[l]));
            x.sin[k] = std::array::from_fn(|l| sc[l].0);
            x.cos[k] = std::array::from_fn(|l| sc[l].1);
        }
    }
}

/// The local translation of joint `j` on `L` rows: `super::local_translation` per lane,
/// the same additions (a Delta coordinate without a channel is `OFFSET + 0`).
#[inline(always)]
fn translation_lanes<const L: usize>(
    skel: &Skeleton,
    j: usize,
    rows: &[&[f64]; L],
) -> [Lanes<L>; 3] {
    let ch = &skel.channels[j];
    let off = skel.offsets[j];
    match ch.mode {
        TranslationMode::Offset => off.map(|v| [v; L]),
        TranslationMode::Replace => std::array::from_fn(|a| match ch.translations[a] {
            Some(i) => std::array::from_fn(|l| rows[l][i]),
            None => [off[a]; L],
        }),
        TranslationMode::Delta => std::array::from_fn(|a| match ch.translations[a] {
            Some(i) => std::array::from_fn(|l| off[a] + rows[l][i]),
            None => [off[a] + 0.0; L],
        }),
    }
}

/// Forward kinematics of `L` frames, one per lane: lane `l` reads `rows[l]` and writes
/// every joint then every End Site into `points[l]`.
#[inline(always)]
pub(super) fn forward_lanes<const L: usize>(
    skel: &Skeleton,
    tab: &RotTables,
    x: &mut Scratch<L>,
    rows: [&[f64]; L],
    points: &mut [&mut [[f64; 3]]; L],
) {
    sincos_pass(tab, x, &rows);
    let (one, zero) = ([1.0; L], [0.0; L]);
    let ident = [[one, zero, zero], [zero, one, zero], [zero, zero, one]];
    for j in 0..skel.n_joints() {
        let t = translation_lanes(skel, j, &rows);
        let (mut r, p) = match skel.parents[j] {
            None => (ident, t),
            Some(pj) => {
                let rp = x.rot[pj];
                let d = mul_vec_lanes(&rp, &t);
                let pp = x.pos[pj];
                let p = std::array::from_fn(|a| std::array::from_fn(|l| pp[a][l] + d[a][l]));
                (rp, p)
            }
        };
        let (k0, k1) = tab.joint[j];
        let sc = x.sin[k0..k1].iter().zip(&x.cos[k0..k1]);
        for (&axis, (s, c)) in tab.axis[k0..k1].iter().zip(sc) {
            // Constant column indices per arm keep the matrix in registers (a run-time
            // index pair spilled it to the stack: +26 % FK throughput, stages bench).
            match axis {
                0 => mix_lanes::<1, 2, L>(&mut r, s, c), // M·R_x
                1 => mix_lanes::<2, 0, L>(&mut r, s, c), // M·R_y
                _ => mix_lanes::<0, 1, L>(&mut r, s, c), // M·R_z
            }
        }
        x.rot[j] = r;
        x.pos[j] = p;
        for (l, out) in points.iter_mut().enumerate() {
            out[j] = [p[0][l], p[1][l], p[2][l]];
        }
    }
    let nj = skel.n_joints();
    for (e, (j, off)) in skel.end_sites.iter().enumerate() {
        let d = mul_vec_lanes(&x.rot[*j], &off.map(|v| [v; L]));
        let p = x.pos[*j];
        for (l, out) in points.iter_mut().enumerate() {
            out[nj + e] = [p[0][l] + d[0][l], p[1][l] + d[1][l], p[2][l] + d[2][l]];
        }
    }
}

/// [`forward_lanes`] over [`FK_LANES`] frames compiled for AVX2 + FMA.
///
/// # Safety
/// The CPU must support AVX2 and FMA ([`Simd::detect`] says [`Simd::Avx2`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn forward_x4_avx2(
    skel: &Skeleton,
    tab: &RotTables,
    x: &mut Scratch<FK_LANES>,
    rows: [&[f64]; FK_LANES],
    points: &mut [&mut [[f64; 3]]; FK_LANES],
) {
    forward_lanes::<FK_LANES>(skel, tab, x, rows, points)
}

/// One batch of [`FK_LANES`] frames into `out` (`FK_LANES · np` points, frame after
/// frame) on `simd`; `Simd::Avx2` must come from [`Simd::detect`].
pub(super) fn batch(
    skel: &Skeleton,
    tab: &RotTables,
    x: &mut Scratch<FK_LANES>,
    simd: Simd,
    rows: [&[f64]; FK_LANES],
    out: &mut [[f64; 3]],
) {
    let np = skel.n_points();
    let (p01, p23) = out.split_at_mut(2 * np);
    let (p0, p1) = p01.split_at_mut(np);
    let (p2, p3) = p23.split_at_mut(np);
    let mut pts = [p0, p1, p2, p3];
    match simd {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: a workspace holds `Simd::Avx2` only when `Simd::detect` found AVX2 and
        // FMA on this CPU (`FkWorkspace::new`, `FkWorkspace::with_simd`).
        Simd::Avx2 => unsafe { forward_x4_avx2(skel, tab, x, rows, &mut pts) },
        _ => forward_lanes::<FK_LANES>(skel, tab, x, rows, &mut pts),
    }
}
