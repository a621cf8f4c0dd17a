//! How far from its COM a body reaches a contact: the largest COM-to-contact distance its
//! legs can give, from its own segments (the jump limits' `χ_max`, `query::limits`).
//!
//! # Model
//! ```text
//! R = √((d + L_leg)² + w²) + a                                     (m)
//! d = median over frames of |COM − (H_L + H_R)/2|                   (COM above the hips)
//! w = median over frames of |H_L − H_R| / 2                        (hip centre to hip)
//! a = median over frames and feet of |ankle − toe tip|               (the foot on its toe)
//! ```
//! The leg straight below the hip (`L_leg`: thigh + shank), the foot in line with the
//! shank on its toe tip, the trunk carrying the COM `d` above the hip centre: no pose puts
//! the contact farther from the COM. Medians of the recording, so a pose held for a frame
//! does not set it.
//!
//! Measured against the edited jumps that stay on their plan and those that do not
//! (`docs/edited-motion.md`): R agrees with the edit on 14 of 16 jumps of five bodies
//! (the misses: a plan 9 mm inside R yet 6 mm off, one 21 mm beyond it yet on the plan). It
//! says nothing of runs, whose touchdown is limited by how far ahead the foot lands, not
//! how far: it limits jumps only.

use crate::math::stats::median;
use crate::math::v3::{norm, sub, V3};

/// `R = √((d + L)² + w²) + a` (module docs), m.
pub fn reach_from(com_above_hips_m: f64, half_hip_width_m: f64, foot_m: f64, leg_m: f64) -> f64 {
    (com_above_hips_m + leg_m).hypot(half_hip_width_m) + foot_m
}

/// The reach of a recorded body (module docs): per frame its COM, hip centres (left,
/// right), ankles and toe tips (left, right), all in metres; `None` when no frame is
/// finite or `leg_m` is not finite and positive.
pub fn body_reach_m(
    com: &[V3],
    hips: &[[V3; 2]],
    ankles: &[[V3; 2]],
    toes: &[[V3; 2]],
    leg_m: f64,
) -> Option<f64> {
    if !(leg_m.is_finite() && leg_m > 0.0) {
        return None;
    }
    let finite = |v: f64| v.is_finite().then_some(v);
    let d: Vec<f64> = com
        .iter()
        .zip(hips)
        .filter_map(|(c, [l, r])| {
            let mid: V3 = std::array::from_fn(|k| 0.5 * (l[k] + r[k]));
            finite(norm(sub(*c, mid)))
        })
        .collect();
    let w: Vec<f64> = hips
        .iter()
        .filter_map(|[l, r]| finite(0.5 * norm(sub(*l, *r))))
        .collect();
    let a: Vec<f64> = ankles
        .iter()
        .zip(toes)
        .flat_map(|(an, to)| [0, 1].map(|k| norm(sub(an[k], to[k]))))
        .filter_map(finite)
        .collect();
    Some(reach_from(median(&d)?, median(&w)?, median(&a)?, leg_m))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_straight_body_reaches_its_hip_offset_leg_and_foot() {
        // COM 0.1 m above the hip centre, hips ±0.09 m, foot 0.2 m, legs 0.84 m: the
        // contact below one hip on the toe is √(0.94² + 0.09²) + 0.2 away.
        let (d, w, a, l) = (0.1, 0.09, 0.2, 0.84);
        let by_hand = (0.94_f64 * 0.94 + 0.09 * 0.09).sqrt() + 0.2;
        assert!((reach_from(d, w, a, l) - by_hand).abs() < 1e-12);
        let n = 5;
        let com = vec![[0.0, 0.0, 1.0 + d]; n];
        let hips = vec![[[0.0, w, 1.0], [0.0, -w, 1.0]]; n];
        let ankles = vec![[[0.0, w, 0.16], [0.0, -w, 0.16]]; n];
        let toes = vec![[[0.2, w, 0.16], [0.0, -w, -0.04]]; n];
        let r = body_reach_m(&com, &hips, &ankles, &toes, l).unwrap();
        assert!((r - by_hand).abs() < 1e-12, "{r} vs {by_hand}");
        // One wild frame does not set it (medians).
        let mut com2 = com.clone();
        com2[2] = [0.0, 0.0, 9.0];
        assert!((body_reach_m(&com2, &hips, &ankles, &toes, l).unwrap() - by_hand).abs() < 1e-12);
        assert_eq!(body_reach_m(&com, &hips, &ankles, &toes, f64::NAN), None);
        assert_eq!(body_reach_m(&[], &[], &[], &[], l), None);
    }
}
