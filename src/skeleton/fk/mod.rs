//! Forward kinematics: every joint and End Site position of one frame, in file units and
//! file axes.
//!
//! # Model
//! ```text
//! R_j = R_p(j) · R_j^local,   P_j = P_p(j) + R_p(j) · t_j^local     (root: R_p = I, P_p = 0)
//! End Site of j:  P_j + R_j · OFFSET_end
//! Elementary rotations (right-handed, degrees in the file):
//! R_x(θ) = [[1,0,0],[0,c,−s],[0,s,c]],  R_y(θ) = [[c,0,s],[0,1,0],[−s,0,c]],
//! R_z(θ) = [[c,−s,0],[s,c,0],[0,0,1]]
//! ```
//! Right-multiplying by an elementary rotation mixes two columns of the running matrix,
//! so a joint costs one `sin_cos` and four multiply-adds per column pair and channel.
//!
//! The sines and cosines of a frame come first, in one branch-free pass
//! ([`crate::math::trig::sincos_deg`], within 6e-16 of libm), and [`forward_frames`] runs
//! [`FK_LANES`] frames at once, one per SIMD lane, on AVX2 when the CPU has it: the kernel
//! and its accuracy are in module `simd`. Every path gives the same bits.
//!
//! # References
//! spec com-from-bvh §2 (verified); pinocchio `kinematics.hxx` (parents before children).
//!
//! # Examples
//! ```
//! use stancelib::{bvh, skeleton::{Skeleton, fk}};
//! let text = "HIERARCHY\nROOT A\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n JOINT B\n {\n  OFFSET 1 0 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  End Site\n  {\n   OFFSET 1 0 0\n  }\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 90 0 0 0 0 0\n";
//! let b = bvh::parse_reader(text.as_bytes()).unwrap();
//! let skel = Skeleton::from_bvh(&b);
//! let mut ws = fk::FkWorkspace::new(&skel);
//! let mut pts = vec![[0.0; 3]; skel.n_points()];
//! fk::forward(&skel, &mut ws, b.motion.row(0), &mut pts);
//! assert!((pts[2][1] - 2.0).abs() < 1e-12); // End Site rotated by 90° about Z: (0, 2, 0)
//! ```

use super::model::{Skeleton, TranslationMode};

/// A 3×3 rotation stored by columns: `m[c][r]`.
pub type Mat3 = [[f64; 3]; 3];

/// The identity rotation.
pub const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

mod simd;

pub use simd::{Simd, FK_LANES};

/// Per-thread scratch: the skeleton's rotation channels as flat tables, and the world
/// rotations and positions of one frame ([`forward`]) or [`FK_LANES`] frames
/// ([`forward_frames`]).
#[derive(Debug, Clone)]
pub struct FkWorkspace {
    tab: simd::RotTables,
    one: simd::Scratch<1>,
    four: simd::Scratch<FK_LANES>,
    /// Which instruction set the batches run on (detected once).
    simd: Simd,
}

impl FkWorkspace {
    /// Scratch sized for `skel`, batches on the best instruction set of the CPU.
    pub fn new(skel: &Skeleton) -> FkWorkspace {
        let tab = simd::RotTables::new(skel);
        FkWorkspace {
            one: simd::Scratch::new(skel.n_joints(), &tab),
            four: simd::Scratch::new(skel.n_joints(), &tab),
            tab,
            simd: Simd::detect(),
        }
    }

    /// The same scratch with batches on `simd` (the tests compare the two paths);
    /// `Simd::Avx2` on a CPU without it falls back to `Simd::Scalar`.
    pub fn with_simd(mut self, simd: Simd) -> FkWorkspace {
        self.simd = if simd == Simd::Avx2 && Simd::detect() != Simd::Avx2 {
            Simd::Scalar
        } else {
            simd
        };
        self
    }

    /// The instruction set the batches run on.
    pub fn simd(&self) -> Simd {
        self.simd
    }
}

/// `m · v` for a column-stored matrix.
#[inline(always)]
pub fn mul_vec(m: &Mat3, v: &[f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}

/// Right-multiply `m` by the elementary rotation about `axis` by `deg` degrees, in place.
#[inline(always)]
pub fn rotate_right(m: &mut Mat3, axis: usize, deg: f64) {
    let (s, c) = deg.to_radians().sin_cos();
    // Constant column indices per arm keep the matrix in registers (a run-time index pair
    // spilled it to the stack: +26 % FK throughput, tests/bench/stages.rs).
    match axis {
        0 => mix::<1, 2>(m, s, c), // M·R_x: col1' = c·col1 + s·col2, col2' = −s·col1 + c·col2
        1 => mix::<2, 0>(m, s, c), // M·R_y: col2' = c·col2 + s·col0, col0' = −s·col2 + c·col0
        _ => mix::<0, 1>(m, s, c), // M·R_z: col0' = c·col0 + s·col1, col1' = −s·col0 + c·col1
    }
}

/// `col_A' = c·col_A + s·col_B`, `col_B' = −s·col_A + c·col_B`.
#[inline(always)]
fn mix<const A: usize, const B: usize>(m: &mut Mat3, s: f64, c: f64) {
    let (ca, cb) = (m[A], m[B]);
    m[A] = [
        c * ca[0] + s * cb[0],
        c * ca[1] + s * cb[1],
        c * ca[2] + s * cb[2],
    ];
    m[B] = [
        -s * ca[0] + c * cb[0],
        -s * ca[1] + c * cb[1],
        -s * ca[2] + c * cb[2],
    ];
}

/// The local translation of joint `j` for a motion row.
#[inline(always)]
pub fn local_translation(skel: &Skeleton, j: usize, row: &[f64]) -> [f64; 3] {
    let ch = &skel.channels[j];
    let off = skel.offsets[j];
    match ch.mode {
        TranslationMode::Offset => off,
        TranslationMode::Replace => {
            std::array::from_fn(|a| ch.translations[a].map_or(off[a], |i| row[i]))
        }
        TranslationMode::Delta => {
            std::array::from_fn(|a| off[a] + ch.translations[a].map_or(0.0, |i| row[i]))
        }
    }
}

/// Local rotation of joint `j` for a motion row (rotation channels in the order listed).
pub fn local_rotation(skel: &Skeleton, j: usize, row: &[f64]) -> Mat3 {
    let mut m = IDENTITY;
    for &(axis, idx) in &skel.channels[j].rotations {
        rotate_right(&mut m, axis, row[idx]);
    }
    m
}

/// Forward kinematics of one frame: `points` (len = `skel.n_points()`) receives every
/// joint then every End Site, file units and axes. The same bits as the frame's lane in
/// [`forward_frames`] (sines and cosines by [`crate::math::trig::sincos_deg`]).
///
/// # Panics
/// If `row.len() < skel.n_channels` or `points.len() < skel.n_points()` (programmer error;
/// the clip pipeline sizes both from the skeleton).
pub fn forward(skel: &Skeleton, ws: &mut FkWorkspace, row: &[f64], points: &mut [[f64; 3]]) {
    assert!(row.len() >= skel.n_channels && points.len() >= skel.n_points());
    simd::forward_lanes::<1>(skel, &ws.tab, &mut ws.one, [row], &mut [points]);
}

/// Forward kinematics of many frames: `points` receives `n · skel.n_points()` points,
/// frame after frame, each as [`forward`] gives it, from the `n` motion rows that `rows`
/// holds back to back (`n · skel.n_channels` values, or more). [`FK_LANES`] frames run at
/// once, on AVX2 when the workspace says so ([`FkWorkspace::simd`]); the last partial
/// batch repeats its last frame in the unused lanes. The result does not depend on the
/// instruction set.
///
/// # Panics
/// If `points.len()` is not a multiple of `skel.n_points()` or `rows` holds fewer than
/// `n` rows (programmer error).
pub fn forward_frames(
    skel: &Skeleton,
    ws: &mut FkWorkspace,
    rows: &[f64],
    points: &mut [[f64; 3]],
) {
    let (nc, np) = (skel.n_channels, skel.n_points());
    assert!(points.len().is_multiple_of(np));
    let n = points.len() / np;
    assert!(rows.len() >= n * nc);
    let row = |f: usize| &rows[f * nc..(f + 1) * nc];
    let full = n / FK_LANES * FK_LANES;
    let (head, tail) = points.split_at_mut(full * np);
    for (b, out) in head.chunks_exact_mut(FK_LANES * np).enumerate() {
        let rows4: [&[f64]; FK_LANES] = std::array::from_fn(|l| row(b * FK_LANES + l));
        simd::batch(skel, &ws.tab, &mut ws.four, ws.simd, rows4, out);
    }
    if full < n {
        let m = n - full;
        let rows4: [&[f64]; FK_LANES] = std::array::from_fn(|l| row(full + l.min(m - 1)));
        let mut out = vec![[0.0; 3]; FK_LANES * np];
        simd::batch(skel, &ws.tab, &mut ws.four, ws.simd, rows4, &mut out);
        tail.copy_from_slice(&out[..m * np]);
    }
}

/// Forward kinematics of one frame with libm's `sin_cos` per channel ([`rotate_right`]):
/// what [`forward`] computed before the batched sines and cosines, kept for the tests and
/// benchmarks to compare against (within 1e-12, see module `simd`).
///
/// # Panics
/// As [`forward`]; `rot` is per-joint scratch of `skel.n_joints()` rotations.
pub fn forward_libm(skel: &Skeleton, rot: &mut [Mat3], row: &[f64], points: &mut [[f64; 3]]) {
    assert!(row.len() >= skel.n_channels && points.len() >= skel.n_points());
    for j in 0..skel.n_joints() {
        let t = local_translation(skel, j, row);
        let (mut r, p) = match skel.parents[j] {
            None => (IDENTITY, t),
            Some(pj) => {
                let rp = rot[pj];
                let d = mul_vec(&rp, &t);
                let pp = points[pj];
                (rp, [pp[0] + d[0], pp[1] + d[1], pp[2] + d[2]])
            }
        };
        for &(axis, idx) in &skel.channels[j].rotations {
            rotate_right(&mut r, axis, row[idx]);
        }
        rot[j] = r;
        points[j] = p;
    }
    let nj = skel.n_joints();
    for (e, (j, off)) in skel.end_sites.iter().enumerate() {
        let d = mul_vec(&rot[*j], off);
        let p = points[*j];
        points[nj + e] = [p[0] + d[0], p[1] + d[1], p[2] + d[2]];
    }
}

/// The rest pose: every joint at its OFFSET, every rotation the identity (spec §2).
pub fn rest_pose(skel: &Skeleton) -> Vec<[f64; 3]> {
    let mut pts = vec![[0.0; 3]; skel.n_points()];
    for j in 0..skel.n_joints() {
        let o = skel.offsets[j];
        pts[j] = match skel.parents[j] {
            None => o,
            Some(p) => [pts[p][0] + o[0], pts[p][1] + o[1], pts[p][2] + o[2]],
        };
    }
    let nj = skel.n_joints();
    for (e, (j, o)) in skel.end_sites.iter().enumerate() {
        pts[nj + e] = [pts[*j][0] + o[0], pts[*j][1] + o[1], pts[*j][2] + o[2]];
    }
    pts
}

/// Geodesic angle (degrees) between two rotations: `acos((tr(A Bᵀ) − 1)/2)`.
pub fn geodesic_deg(a: &Mat3, b: &Mat3) -> f64 {
    // tr(A Bᵀ) = Σ_c Σ_r a[c][r] b[c][r]
    let tr: f64 = (0..3)
        .map(|c| (0..3).map(|r| a[c][r] * b[c][r]).sum::<f64>())
        .sum();
    ((tr - 1.0) / 2.0).clamp(-1.0, 1.0).acos().to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::Rng;
    use nalgebra::{Rotation3, Vector3};

    fn na(axis: usize, deg: f64) -> Rotation3<f64> {
        let ax = [Vector3::x_axis(), Vector3::y_axis(), Vector3::z_axis()][axis];
        Rotation3::from_axis_angle(&ax, deg.to_radians())
    }

    #[test]
    fn composition_matches_nalgebra_intrinsic_product() {
        // R = R_a1 · R_a2 · R_a3 for every order, checked against nalgebra's rotations.
        for order in [[2, 0, 1], [2, 1, 0], [0, 2, 1], [1, 2, 0], [0, 1, 2]] {
            let ang = [37.0, -71.5, 128.25];
            let mut m = IDENTITY;
            let mut r = Rotation3::identity();
            for k in 0..3 {
                rotate_right(&mut m, order[k], ang[k]);
                r *= na(order[k], ang[k]);
            }
            for c in 0..3 {
                for rr in 0..3 {
                    assert!((m[c][rr] - r[(rr, c)]).abs() < 1e-14);
                }
            }
        }
    }

    const AXES: [&str; 3] = ["Xrotation", "Yrotation", "Zrotation"];
    const POSITIONS: &str = "Xposition Yposition Zposition";

    /// The three rotation channels in a random order.
    fn shuffled_axes(rng: &mut Rng) -> [&'static str; 3] {
        let mut axes = AXES;
        for i in (1..3).rev() {
            axes.swap(i, rng.int(0, i as u32) as usize);
        }
        axes
    }

    /// One random joint (and its subtree, at most `depth` deeper) as BVH text; `span`
    /// receives the range of each of its channels' values (position ±5, angle ±180).
    fn random_joint(rng: &mut Rng, depth: u32, span: &mut Vec<f64>, out: &mut String) {
        let o: Vec<String> = (0..3)
            .map(|_| format!("{:.5}", rng.uniform(-4.0, 4.0)))
            .collect();
        out.push_str(&format!("OFFSET {}\n", o.join(" ")));
        let n_rot = rng.int(0, 3) as usize;
        let mut axes: Vec<&str> = shuffled_axes(rng)[..n_rot].to_vec();
        let with_pos = rng.int(0, 4) == 0;
        if with_pos {
            axes.insert(0, POSITIONS);
        }
        if with_pos {
            span.extend([5.0; 3]);
        }
        span.extend(vec![180.0; n_rot]);
        let n_ch = n_rot + if with_pos { 3 } else { 0 };
        out.push_str(&format!("CHANNELS {n_ch} {}\n", axes.join(" ")));
        let children = if depth == 0 { 0 } else { rng.int(0, 3) };
        for _ in 0..children {
            // The text's length so far: a unique name.
            out.push_str(&format!("JOINT J{}\n{{\n", out.len()));
            random_joint(rng, depth - 1, span, out);
            out.push_str("}\n");
        }
        if children == 0 {
            let e: Vec<String> = (0..3)
                .map(|_| format!("{:.5}", rng.uniform(-2.0, 2.0)))
                .collect();
            out.push_str(&format!("End Site\n{{\nOFFSET {}\n}}\n", e.join(" ")));
        }
    }

    /// A random skeleton (root with 6 channels in a random order, up to 4 levels, random
    /// rotation channels, some position channels) and `n` frames of seeded values: the
    /// root within ±100 units, other positions ±5, angles ±180°, one in 20 ±20 000°.
    fn random_clip(seed: u64, n: usize) -> crate::bvh::Bvh {
        let mut rng = Rng::new(seed);
        let mut t = String::from("HIERARCHY\nROOT R\n{\nOFFSET 0 0 0\nCHANNELS 6 ");
        t += &format!("{POSITIONS} {}\n", shuffled_axes(&mut rng).join(" "));
        let mut span = vec![100.0, 100.0, 100.0, 180.0, 180.0, 180.0];
        for c in 0..rng.int(1, 3) {
            t += &format!("JOINT C{c}\n{{\n");
            random_joint(&mut rng, 3, &mut span, &mut t);
            t += "}\n";
        }
        t += &format!("}}\nMOTION\nFrames: {n}\nFrame Time: 0.01\n");
        for _ in 0..n {
            let vals: Vec<String> = span
                .iter()
                .map(|&s| {
                    let s = if s == 180.0 && rng.int(0, 20) == 0 {
                        2e4
                    } else {
                        s
                    };
                    format!("{:.6}", rng.uniform(-s, s))
                })
                .collect();
            t += &vals.join(" ");
            t.push('\n');
        }
        crate::bvh::parse_reader(t.as_bytes()).expect("the generated clip parses")
    }

    // See: issue 15 item 2 — batched SIMD sin/cos with a scalar fallback identical to
    // 1e-12: here the same bits on both paths and for single frames, and within 1e-12 of
    // the libm FK.
    #[test]
    fn simd_batches_equal_the_scalar_fallback_on_random_skeletons() {
        for seed in 0..40 {
            let n = 11; // two batches of 4 and a partial one of 3
            let b = random_clip(seed, n);
            let skel = Skeleton::from_bvh(&b);
            let np = skel.n_points();
            let by_simd: Vec<Vec<[f64; 3]>> = [Simd::Scalar, Simd::Avx2]
                .into_iter()
                .map(|simd| {
                    let mut ws = FkWorkspace::new(&skel).with_simd(simd);
                    let mut pts = vec![[0.0; 3]; n * np];
                    forward_frames(&skel, &mut ws, &b.motion.values, &mut pts);
                    pts
                })
                .collect();
            assert_eq!(
                by_simd[0], by_simd[1],
                "seed {seed}: AVX2 and scalar differ"
            );
            let mut ws = FkWorkspace::new(&skel);
            let (mut one, mut libm) = (vec![[0.0; 3]; np], vec![[0.0; 3]; np]);
            let mut rot = vec![IDENTITY; skel.n_joints()];
            for f in 0..n {
                forward(&skel, &mut ws, b.motion.row(f), &mut one);
                assert_eq!(
                    one[..],
                    by_simd[0][f * np..(f + 1) * np],
                    "seed {seed} frame {f}"
                );
                // Points within about 40 units of the root through up to 15 rotations, each
                // sine and cosine within 1e-15 of libm's: well under 1e-12.
                forward_libm(&skel, &mut rot, b.motion.row(f), &mut libm);
                for (p, q) in one.iter().zip(&libm) {
                    for a in 0..3 {
                        let d = (p[a] - q[a]).abs();
                        assert!(d <= 1e-12, "seed {seed} frame {f}: {p:?} vs {q:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn geodesic_angle_of_a_known_rotation() {
        let mut m = IDENTITY;
        rotate_right(&mut m, 1, 33.0);
        assert!((geodesic_deg(&m, &IDENTITY) - 33.0).abs() < 1e-9);
    }
}
