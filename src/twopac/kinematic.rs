//! Kinematic polytopes from in-memory contact samples (spec two-pac §3, eq 3–4): where
//! the COM can be relative to an effector in contact, learned from the database.
//!
//! # Model
//! ```text
//! point:    ʳc = R_eᵀ (c − p_e)        COM in the effector's contact frame (m)
//!           ([`crate::kinematics::com_in_contact_frame`])
//! outliers: per (character, effector): drop |ʳc − centroid| > P99.5 of those distances,
//!           and |ʳc| > 1.3 · L_leg
//! hull:     K_e ʳc ≤ k_e, unit outward rows, coplanar facets merged (≥ 4 non-coplanar points)
//! ```
//! `R_e` is yaw-only with `z` up, so one polytope serves any level surface and yaw; a
//! contact at `(p, R)` uses `K_w = K_e Rᵀ`, `k_w = k_e + K_e Rᵀ p`
//! ([`Polytope::to_world_yaw`]).
//!
//! # Memory: why one group's points are held
//! A library build keeps the samples on disk and reduces one (character, effector) at a
//! time; that group's points are then in memory (~200 bytes a point with the hull's
//! copies). The outlier rule alone would need only bounded state (a streamed centroid in
//! file order, and the P99.5 order statistics by a radix selection over the distances),
//! but the hull would not: parry's quickhull normalises the points by the covariance of
//! **all** of them (interior points included), picks its first triangle from that
//! normalisation, and takes each facet's farthest point from that facet's conflict list,
//! which can be a point inside the final hull (the point farther out may sit in another
//! facet's list). So a hull of a bounded subset (the boundary points, say) gives the same
//! polytope only up to the order of its triangles and their vertices, and the rounding of
//! the normals and offsets follows that order: the bytes of `kinematics.parquet` would
//! change. Exact identity with the in-memory build therefore keeps one group's points.
//!
//! # References
//! spec two-pac §3; com-from-bvh §7.5 (contact frames).

use super::hull::{hull_hrep, HullOptions};
use super::polytope::Polytope;
use crate::math::stats::percentile_sorted;

/// Distance percentile beyond which points are outliers.
pub const OUTLIER_PERCENTILE: f64 = 99.5;
/// Points farther than this many leg lengths from the contact are dropped.
pub const MAX_LEG_LENGTHS: f64 = 1.3;

/// Which points survive the outlier rules, for one character and effector.
///
/// Non-finite points never survive; an empty set stays empty.
pub fn inliers(points: &[[f64; 3]], leg_m: f64) -> Vec<bool> {
    let finite: Vec<bool> = points
        .iter()
        .map(|p| p.iter().all(|v| v.is_finite()))
        .collect();
    let n = finite.iter().filter(|&&f| f).count();
    if n == 0 {
        return vec![false; points.len()];
    }
    let mut centroid = [0.0; 3];
    for (p, _) in points.iter().zip(&finite).filter(|(_, &f)| f) {
        for k in 0..3 {
            centroid[k] += p[k] / n as f64;
        }
    }
    let dist = |p: &[f64; 3]| {
        ((p[0] - centroid[0]).powi(2) + (p[1] - centroid[1]).powi(2) + (p[2] - centroid[2]).powi(2))
            .sqrt()
    };
    let mut d: Vec<f64> = points
        .iter()
        .zip(&finite)
        .filter(|(_, &f)| f)
        .map(|(p, _)| dist(p))
        .collect();
    // Sorted in place (no second copy of the distances).
    d.sort_by(f64::total_cmp);
    let limit = percentile_sorted(&d, OUTLIER_PERCENTILE).unwrap_or(f64::INFINITY);
    drop(d);
    let reach = MAX_LEG_LENGTHS * leg_m;
    points
        .iter()
        .zip(&finite)
        .map(|(p, &f)| {
            let norm = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            f && dist(p) <= limit && norm <= reach
        })
        .collect()
}

/// The polytope of a point set (unit outward rows, coplanar facets merged).
///
/// # Errors
/// Fewer than 4 non-coplanar points (the effector then has no polytope).
pub fn polytope(points: &[[f64; 3]]) -> Result<Polytope, crate::twopac::TwopacError> {
    hull_hrep(points, &HullOptions::default())
}

/// One (character, effector)'s samples after the outlier rules, and their polytope:
/// `(keep, polytope)`, `keep[i]` for `points[i]`; no polytope from fewer than 4
/// non-coplanar kept points. The points are dropped before the hull is built (memory:
/// the hull's copies of the kept points are the peak of a library build).
pub fn kinematic_polytope(points: Vec<[f64; 3]>, leg_m: f64) -> (Vec<bool>, Option<Polytope>) {
    let keep = inliers(&points, leg_m);
    let kept: Vec<[f64; 3]> = points
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(p, _)| *p)
        .collect();
    drop(points);
    let poly = polytope(&kept).ok();
    (keep, poly)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outliers_by_percentile_reach_and_non_finite() {
        // 1000 points on a small cloud around (0, 0, 0.9), one far point, one NaN.
        let mut pts: Vec<[f64; 3]> = (0..1000)
            .map(|i| {
                let t = i as f64 * 0.618;
                [0.1 * t.sin(), 0.1 * t.cos(), 0.9 + 0.05 * (3.0 * t).sin()]
            })
            .collect();
        pts.push([0.0, 0.0, 1.5]); // within P99.5? no: farthest of all
        pts.push([f64::NAN, 0.0, 0.9]);
        let keep = inliers(&pts, 0.9);
        assert!(!keep[1000] && !keep[1001]);
        let kept = keep.iter().filter(|&&k| k).count();
        // P99.5 of 1001 distances drops about 5 points, the far one among them.
        assert!((990..1000).contains(&kept), "{kept}");
        // A short leg drops every point beyond 1.3 L_leg.
        let short = inliers(&pts, 0.5);
        assert!(short
            .iter()
            .zip(&pts)
            .all(|(&k, p)| !k || (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() <= 0.65));
        assert!(inliers(&[], 1.0).is_empty());
    }

    #[test]
    fn polytope_holds_its_points() {
        let pts: Vec<[f64; 3]> = (0..500)
            .map(|i| {
                let t = i as f64;
                [
                    0.2 * (0.37 * t).sin(),
                    0.15 * (0.73 * t).cos(),
                    0.8 + 0.1 * (1.3 * t).sin(),
                ]
            })
            .collect();
        let p = polytope(&pts).expect("a hull");
        assert!(pts.iter().all(|&c| p.contains(c, 1e-9)));
        assert!(!p.contains([0.0, 0.0, 2.0], 1e-9));
        assert!(polytope(&pts[..3]).is_err());
    }
}
