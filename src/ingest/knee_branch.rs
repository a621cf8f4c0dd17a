//! Knee branch jumps: a knee mirrored across its hip–ankle line from one frame to the next.
//!
//! A clip made by fixed-length two-bone IK (OpenSim's Gait2354 walk, exported to BVH) may
//! put the knee on either side of the hip–ankle line when the leg is nearly straight: the
//! two solutions differ only by that mirror. Where the solver changes branch, the knee jumps
//! by twice its offset from the line in one frame (4–5 cm at 60 Hz on that walk, a knee
//! flexed 5° one frame and hyperextended 5° the next) while hip and ankle move smoothly;
//! the thigh and shank masses jump with it, and the COM's second derivative carries a
//! spike of about ±0.4 body weights fore-aft that no force made (issue 39 item 3).
//!
//! # Model
//! ```text
//! u_i = (A_i − H_i)/|A_i − H_i|,   p_i = (K_i − H_i) − ((K_i − H_i)·u_i) u_i     knee offset ⟂ the line
//! jump between i and i+1:  min(|p_i|, |p_{i+1}|) ≥ MIN_OFFSET_M,
//!                          |p_i + p_{i+1}| ≤ MIRROR_TOL · max(|p_i|, |p_{i+1}|)   (p_{i+1} ≈ −p_i)
//!                          and both knees flexed at most MAX_FLEXION_DEG (a nearly straight leg)
//! the jumps cut the clip into runs; a run bounded by a jump whose offsets point behind
//! the foot (mean p·f < 0, f: ankle → toe tip, horizontal) is mirrored back:
//!   K_i ← H_i + ((K_i − H_i)·u_i) u_i − p_i          (thigh and shank keep their lengths)
//! ```
//! Without a jump nothing changes: a knee that hyperextends smoothly is a person's, and
//! is kept. The repaired knees feed the segment-mass COM only; the joints written with
//! `--joints` stay the file's.
//!
//! # Units
//! Metres, internal Z-up frame.

use crate::math::v3::{add, dot, flexion_deg, norm, scale, sub, V3};

/// Least knee offset from the hip–ankle line on both frames of a jump, m: below it the
/// two branches are within a few millimetres and a swap moves no mass worth repairing.
pub const MIN_OFFSET_M: f64 = 0.005;
/// Largest `|p_i + p_{i+1}|` of a jump as a fraction of the larger offset: the knee lands
/// within a quarter of its offset of its own mirror image.
pub const MIRROR_TOL: f64 = 0.25;
/// Largest knee flexion on both frames of a jump, degrees: the branch ambiguity of a
/// fixed-length two-bone IK is that of a nearly straight leg (Gait2354: 5–7°). A bent knee
/// mirrored in one frame is another artefact: CMU subject 05's right leg swivels whole
/// about its hip–ankle line, foot included, by 23–29 cm at the knee at 33–40° of flexion,
/// and mirroring the knee alone would leave the foot turned; it is left as recorded.
pub const MAX_FLEXION_DEG: f64 = 15.0;

/// The knee's offset from its hip–ankle line and the line's unit direction (zero when
/// hip and ankle coincide).
fn offset(hip: V3, knee: V3, ankle: V3) -> (V3, V3) {
    let axis = sub(ankle, hip);
    let n = norm(axis);
    let u = if n > 0.0 {
        scale(1.0 / n, axis)
    } else {
        [0.0; 3]
    };
    let kh = sub(knee, hip);
    (sub(kh, scale(dot(kh, u), u)), u)
}

/// Is the step from offset `a` to offset `b`, flexions `fa` and `fb` (deg), a branch jump
/// (the model's test)?
fn is_jump(a: V3, b: V3, fa: f64, fb: f64) -> bool {
    let (na, nb) = (norm(a), norm(b));
    fa.max(fb) <= MAX_FLEXION_DEG
        && na.min(nb) >= MIN_OFFSET_M
        && norm(add(a, b)) <= MIRROR_TOL * na.max(nb)
}

/// The knees of one leg with the runs on the mirrored branch mirrored back (the model), and
/// the frames changed. `hip`, `knee`, `ankle`, `toe` per frame (m); slices of equal length.
pub fn repair(hip: &[V3], knee: &[V3], ankle: &[V3], toe: &[V3]) -> (Vec<V3>, Vec<usize>) {
    let n = knee.len();
    let off: Vec<(V3, V3)> = (0..n).map(|i| offset(hip[i], knee[i], ankle[i])).collect();
    let flex: Vec<f64> = (0..n)
        .map(|i| flexion_deg(hip[i], knee[i], ankle[i]))
        .collect();
    let cuts: Vec<usize> = (1..n)
        .filter(|&i| is_jump(off[i - 1].0, off[i].0, flex[i - 1], flex[i]))
        .collect();
    let mut out = knee.to_vec();
    let mut changed = Vec::new();
    if cuts.is_empty() {
        return (out, changed);
    }
    let bounds: Vec<usize> = std::iter::once(0)
        .chain(cuts.iter().copied())
        .chain(std::iter::once(n))
        .collect();
    for w in bounds.windows(2) {
        let (a, b) = (w[0], w[1]);
        let behind: f64 = (a..b)
            .map(|i| {
                let f = sub(toe[i], ankle[i]);
                let fh = [f[0], f[1], 0.0];
                let l = norm(fh);
                if l > 0.0 {
                    dot(off[i].0, fh) / l
                } else {
                    0.0
                }
            })
            .sum();
        if behind < 0.0 {
            for i in a..b {
                let (p, _) = off[i];
                out[i] = sub(knee[i], scale(2.0, p));
                changed.push(i);
            }
        }
    }
    (out, changed)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A nearly straight leg walking along +x: hip 0.88 m above the ankle, the knee `d` m in
    /// front of the line (negative: behind), toe tip 0.15 m ahead of the ankle.
    fn leg(x: f64, d: f64) -> (V3, V3, V3, V3) {
        let hip = [x, 0.0, 0.95];
        let ankle = [x + 0.05, 0.0, 0.07];
        let (h, a) = (hip, ankle);
        let u = scale(1.0 / norm(sub(a, h)), sub(a, h));
        // In-plane normal of the line pointing forward (+x side).
        let fwd = [u[2].abs(), 0.0, -u[0] * u[2].signum()];
        let nf = scale(1.0 / norm(fwd), fwd);
        let knee = add(add(h, scale(0.5, sub(a, h))), scale(d, nf));
        (hip, knee, ankle, add(ankle, [0.15, 0.0, -0.05]))
    }

    fn track(offsets: &[f64]) -> [Vec<V3>; 4] {
        let mut t: [Vec<V3>; 4] = Default::default();
        for (i, &d) in offsets.iter().enumerate() {
            let (h, k, a, f) = leg(0.02 * i as f64, d);
            for (v, p) in t.iter_mut().zip([h, k, a, f]) {
                v.push(p);
            }
        }
        t
    }

    #[test]
    fn a_run_mirrored_behind_the_line_between_two_jumps_is_mirrored_back() {
        let d = [0.021, 0.021, -0.022, -0.022, -0.023, -0.022, 0.020, 0.023];
        let [h, k, a, f] = track(&d);
        let (fixed, changed) = repair(&h, &k, &a, &f);
        assert_eq!(changed, vec![2, 3, 4, 5]);
        for i in 0..d.len() {
            let (p, _) = offset(h[i], fixed[i], a[i]);
            // Every knee now in front by |d|, thigh and shank lengths kept.
            assert!((p[0].signum() - 1.0).abs() < 1e-12, "{i}: {p:?}");
            assert!((norm(p) - d[i].abs()).abs() < 1e-9, "{i}");
            let (l1, l1f) = (norm(sub(k[i], h[i])), norm(sub(fixed[i], h[i])));
            let (l2, l2f) = (norm(sub(a[i], k[i])), norm(sub(a[i], fixed[i])));
            assert!((l1 - l1f).abs() < 1e-12 && (l2 - l2f).abs() < 1e-12, "{i}");
        }
    }

    #[test]
    fn a_knee_that_hyperextends_smoothly_or_stays_behind_is_kept() {
        // Passes through the line over several frames: no frame pair is a mirror image
        // with both offsets above the minimum.
        let smooth = [0.02, 0.012, 0.004, -0.004, -0.012, -0.02];
        // Behind the line all along: a person who hyperextends, no jump.
        let behind = [-0.02, -0.021, -0.022, -0.02];
        for d in [&smooth[..], &behind[..]] {
            let [h, k, a, f] = track(d);
            let (fixed, changed) = repair(&h, &k, &a, &f);
            assert!(changed.is_empty(), "{d:?}");
            assert_eq!(fixed, k);
        }
    }

    #[test]
    fn a_bent_knee_mirrored_in_one_frame_is_left_as_recorded() {
        // 0.12 m off the line: about 30° of flexion, beyond MAX_FLEXION_DEG.
        let d = [0.12, 0.12, -0.12, -0.12, 0.12];
        let [h, k, a, f] = track(&d);
        assert!(flexion_deg(h[0], k[0], a[0]) > MAX_FLEXION_DEG);
        let (fixed, changed) = repair(&h, &k, &a, &f);
        assert!(changed.is_empty());
        assert_eq!(fixed, k);
    }

    #[test]
    fn a_jump_into_the_flexed_branch_keeps_the_flexed_run() {
        // Behind, then one jump to in front: the front run stays, the run behind is mirrored.
        let d = [-0.02, -0.02, 0.021, 0.022, 0.03];
        let [h, k, a, f] = track(&d);
        let (fixed, changed) = repair(&h, &k, &a, &f);
        assert_eq!(changed, vec![0, 1]);
        assert_eq!(&fixed[2..], &k[2..]);
    }
}
