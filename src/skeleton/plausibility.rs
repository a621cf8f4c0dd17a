//! Segment-length plausibility: a skeleton whose one OFFSET is far longer than the rest of
//! its segments is refused before forward kinematics, instead of giving a COM kilometres
//! away or overflowing f64 in a later stage (a head `OFFSET 1e6`, a joint `OFFSET 1e155`).
//!
//! # Model
//! ```text
//! ℓᵢ = |OFFSETᵢ|          every non-root joint and every End Site (file units), ℓ₁ ≥ ℓ₂ ≥ … > 0
//! k  = ⌈n / 10⌉           the longest tenth, left out of the size (a few bad segments)
//! s  = Σᵢ₌ₖ₊₁..ₙ ℓᵢ       the skeleton's size: the rest of its segments end to end
//! refused  ⇔  ℓ₁ > MAX_SEGMENT_RATIO · s
//! ```
//! The root's OFFSET is its place in the scene, not a segment, and is not counted. The size
//! is a sum, not a median, so that thousands of tiny joints (a hand of 20,000 1 mm
//! segments) do not make a thigh implausible. On the shared clips (122 skeletons: CMU,
//! Mixamo, DAZ, the Mass set) the longest segment is at most 0.34 s, so
//! [`MAX_SEGMENT_RATIO`] leaves a factor of 30 to spare.
//!
//! # Frames and units
//! File units throughout: the ratio is unit-free.

use super::Skeleton;
use crate::error::{Error, Result};

/// Longest segment allowed, as a multiple of the skeleton's size `s` (module docs).
pub const MAX_SEGMENT_RATIO: f64 = 10.0;
/// Share of the longest segments left out of the skeleton's size (at least one).
pub const SIZE_TRIM_SHARE: f64 = 0.1;

/// Refuse a skeleton with a segment longer than [`MAX_SEGMENT_RATIO`] × its size.
///
/// # Errors
/// `ErrorKind::Skeleton` naming the segment (joint or End Site), its length, the size and
/// the limit.
pub fn check_segments(skel: &Skeleton) -> Result<()> {
    // Scaled by the largest component, so that 1e155 is not squared into ∞: a skeleton
    // scaled as a whole keeps its ratios (and its overflow is reported by the stage that
    // meets it, naming the quantity).
    let norm = |v: &[f64; 3]| {
        let m = v.iter().fold(0.0f64, |m, c| m.max(c.abs()));
        if m == 0.0 || !m.is_finite() {
            return m;
        }
        m * v.iter().map(|c| (c / m) * (c / m)).sum::<f64>().sqrt()
    };
    // (point, length)
    let segments: Vec<(usize, f64)> = (0..skel.n_joints())
        .filter(|&j| skel.parents[j].is_some())
        .map(|j| (j, norm(&skel.offsets[j])))
        .chain(
            skel.end_sites
                .iter()
                .enumerate()
                .map(|(k, (_, off))| (skel.n_joints() + k, norm(off))),
        )
        .collect();
    let mut nonzero: Vec<f64> = segments
        .iter()
        .map(|(_, l)| *l)
        .filter(|l| *l > 0.0)
        .collect();
    if nonzero.len() < 3 {
        return Ok(());
    }
    nonzero.sort_by(|a, b| b.total_cmp(a));
    let trim = ((nonzero.len() as f64 * SIZE_TRIM_SHARE).ceil() as usize).max(1);
    let size: f64 = nonzero[trim..].iter().sum();
    let Some(&(point, longest)) = segments.iter().max_by(|a, b| a.1.total_cmp(&b.1)) else {
        return Ok(());
    };
    if longest.is_finite() && longest <= MAX_SEGMENT_RATIO * size {
        return Ok(());
    }
    Err(Error::skeleton(format!(
        "segment '{}' is {longest:.3e} file units long, {:.3e} × the skeleton's size \
         ({size:.4}, its other segments but the longest tenth, end to end): more than \
         MAX_SEGMENT_RATIO = {MAX_SEGMENT_RATIO} (an implausible OFFSET)",
        crate::error::echo(&skel.point_name(point)),
        longest / size,
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::parse_reader;

    fn skeleton(head_offset: &str) -> Skeleton {
        let text = format!(
            "HIERARCHY\nROOT Hips\n{{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n \
             JOINT Spine\n {{\n  OFFSET 0 10 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  \
             JOINT Head\n  {{\n   OFFSET {head_offset}\n   CHANNELS 3 Zrotation Xrotation Yrotation\n   \
             End Site\n   {{\n    OFFSET 0 5 0\n   }}\n  }}\n }}\n \
             JOINT LeftUpLeg\n {{\n  OFFSET 8 0 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  \
             End Site\n  {{\n   OFFSET 0 -40 0\n  }}\n }}\n}}\n\
             MOTION\nFrames: 1\nFrame Time: 0.01\n0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n"
        );
        Skeleton::from_bvh(&parse_reader(text.as_bytes()).unwrap())
    }

    #[test]
    fn a_skeleton_of_plausible_segments_passes() {
        // Segments 40, 15, 10, 8, 5: the longest is 1.2 × the size (15 + 10 + 8 + 5 = 38).
        assert!(check_segments(&skeleton("0 15 0")).is_ok());
    }

    // See: issue 40 item 5 — a head OFFSET 1e6 (COM 1.96 km, status ok) and a joint
    // OFFSET 1e155 (inf forces) are refused before forward kinematics.
    #[test]
    fn a_head_offset_of_1e6_and_a_joint_offset_of_1e155_are_refused() {
        for off in ["0 1e6 0", "1e155 -1e155 0", "0 1e26 0", "1e200 1e200 1e200"] {
            let e = check_segments(&skeleton(off)).unwrap_err();
            let msg = e.to_string();
            assert!(msg.contains("segment 'Head'"), "{off}: {msg}");
            assert!(msg.contains("MAX_SEGMENT_RATIO"), "{off}: {msg}");
        }
        // At the limit: 630 against a size of 40 + 10 + 8 + 5 = 63 (the head left out).
        assert!(check_segments(&skeleton("0 630 0")).is_ok());
        assert!(check_segments(&skeleton("0 631 0")).is_err());
    }
}
