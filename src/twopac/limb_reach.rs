//! Kinematic polytopes from in-memory contact samples (spec two-pac §3, eq 3–4): where
//! the COM can be relative to an effector in contact, learned from the database.
//!
//! # Model
//! ```text
//! point:    ʳc = R_eᵀ (c − p_e)        COM in the effector's contact frame (m)
//!           ([`crate::contacts::contact_runs::com_in_contact_frame`])
//! outliers: per (character, effector): drop |ʳc − centroid| > P99.5 of those distances,
//!           and |ʳc| > 1.3 · L_leg
//! hull:     K_e ʳc ≤ k_e, unit outward rows, coplanar facets merged (≥ 4 non-coplanar points)
//! ```
//! `R_e` is yaw-only with `z` up, so one polytope serves any level surface and yaw; a
//! contact at `(p, R)` uses `K_w = K_e Rᵀ`, `k_w = k_e + K_e Rᵀ p`
//! ([`Polytope::to_world_yaw`]).
//!
//! # Memory: streamed, a group at a time
//! A library build keeps the samples on disk and reduces one (character, effector) at a
//! time in passes over that group's samples, holding little state: the count, then the
//! centroid (summed in file order, as the in-memory rule), then the `n − k` largest
//! distances (the P99.5 needs only the order statistics of ranks `k` and `k + 1`, about
//! 0.5 % of the distances), then the kept points stream into a [`StreamedHull`], which
//! holds only the points within 1 µm of its surface plus one chunk. The polytope is that
//! of a canonical point set (sorted, see [`StreamedHull`]), so it is the same bit for bit
//! whatever the build's batches or the shards of a merge (the samples come in (clip,
//! frame) order every time, so the centroid's sum is too).
//!
//! # References
//! spec two-pac §3; com-from-bvh §7.5 (contact frames).

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::convert::Infallible;

use super::hull::{hull_hrep, HullOptions, StreamedHull};
use super::polytope::Polytope;
use crate::math::stats::{interpolate_rank, percentile_rank};
use crate::math::v3::{norm, sub};

/// Distance percentile beyond which points are outliers.
pub const OUTLIER_PERCENTILE: f64 = 99.5;
/// Points farther than this many leg lengths from the contact are dropped.
pub const MAX_LEG_LENGTHS: f64 = 1.3;

/// The outlier rules of one (character, effector), fitted to its points: the centroid of
/// the finite points, the P99.5 of their distances to it, and the reach `1.3 · L_leg`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutlierRule {
    centroid: [f64; 3],
    limit_m: f64,
    reach_m: f64,
}

/// A distance ordered by `f64::total_cmp` (for the heap of the largest distances).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Total(f64);
impl Eq for Total {}
impl PartialOrd for Total {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Total {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

fn is_finite(p: &[f64; 3]) -> bool {
    p.iter().all(|v| v.is_finite())
}

impl OutlierRule {
    /// Fit the rules in three passes over the points: `pass(f)` must call `f` on every
    /// point, in the same order each time (a file read again, a slice). Memory: the
    /// `n − ⌊0.995 (n − 1)⌋` largest distances, not the points.
    ///
    /// # Errors
    /// The first error of `pass`.
    pub fn fit<E>(
        leg_m: f64,
        mut pass: impl FnMut(&mut dyn FnMut(&[f64; 3])) -> Result<(), E>,
    ) -> Result<OutlierRule, E> {
        let mut n = 0usize;
        pass(&mut |p| n += usize::from(is_finite(p)))?;
        let mut centroid = [0.0; 3];
        pass(&mut |p| {
            if is_finite(p) {
                for k in 0..3 {
                    centroid[k] += p[k] / n as f64;
                }
            }
        })?;
        let (k, frac) = percentile_rank(n, OUTLIER_PERCENTILE);
        let top = n - k.min(n);
        let mut largest: BinaryHeap<Reverse<Total>> = BinaryHeap::with_capacity(top + 1);
        pass(&mut |p| {
            if is_finite(p) {
                let d = Total(distance(p, &centroid));
                // Full: only a distance above the least kept one enters.
                if largest.len() < top {
                    largest.push(Reverse(d));
                } else if largest.peek().is_some_and(|Reverse(least)| d > *least) {
                    largest.pop();
                    largest.push(Reverse(d));
                }
            }
        })?;
        let lo = largest.pop().map(|Reverse(Total(d))| d);
        let hi = largest.pop().map(|Reverse(Total(d))| d);
        Ok(OutlierRule {
            centroid,
            limit_m: lo.map_or(f64::INFINITY, |lo| interpolate_rank(lo, hi, frac)),
            reach_m: MAX_LEG_LENGTHS * leg_m,
        })
    }

    /// The point survives: finite, within the P99.5 distance of the centroid and within
    /// the reach of the contact.
    pub fn keeps(&self, p: &[f64; 3]) -> bool {
        is_finite(p) && distance(p, &self.centroid) <= self.limit_m && norm(*p) <= self.reach_m
    }
}

/// `|p − c|`, m.
fn distance(p: &[f64; 3], c: &[f64; 3]) -> f64 {
    norm(sub(*p, *c))
}

/// A point visitor of one pass of [`OutlierRule::fit`].
type Visit<'a> = &'a mut dyn FnMut(&[f64; 3]);

/// A slice as the passes of [`OutlierRule::fit`].
fn slice_pass(points: &[[f64; 3]]) -> impl FnMut(Visit) -> Result<(), Infallible> + '_ {
    move |f| {
        points.iter().for_each(&mut *f);
        Ok(())
    }
}

/// Which points survive the outlier rules, for one character and effector.
///
/// Non-finite points never survive; an empty set stays empty.
pub fn inliers(points: &[[f64; 3]], leg_m: f64) -> Vec<bool> {
    let rule = match OutlierRule::fit(leg_m, slice_pass(points)) {
        Ok(rule) => rule,
        Err(never) => match never {},
    };
    points.iter().map(|p| rule.keeps(p)).collect()
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
/// non-coplanar kept points. The same as a library build's streamed reduction (the rules
/// of [`OutlierRule`], the hull of a [`StreamedHull`]) on points held in memory.
pub fn kinematic_polytope(points: &[[f64; 3]], leg_m: f64) -> (Vec<bool>, Option<Polytope>) {
    let keep = inliers(points, leg_m);
    let mut hull = StreamedHull::default();
    for (p, _) in points.iter().zip(&keep).filter(|(_, k)| **k) {
        hull.push(*p);
    }
    (keep, hull.finish(&HullOptions::default()).ok())
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

    /// The rules written out with every distance sorted (the in-memory form the streamed
    /// fit replaces): numpy's linear percentile, the centroid summed in order.
    fn reference_keep(points: &[[f64; 3]], leg_m: f64) -> Vec<bool> {
        let fin: Vec<&[f64; 3]> = points
            .iter()
            .filter(|p| p.iter().all(|v| v.is_finite()))
            .collect();
        let n = fin.len() as f64;
        let mut c = [0.0; 3];
        for p in &fin {
            for k in 0..3 {
                c[k] += p[k] / n;
            }
        }
        let dist = |p: &[f64; 3]| {
            ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt()
        };
        let mut d: Vec<f64> = fin.iter().map(|p| dist(p)).collect();
        d.sort_by(f64::total_cmp);
        let limit = if d.is_empty() {
            f64::INFINITY
        } else {
            let r = 0.995 * (d.len() - 1) as f64;
            let k = r as usize;
            let hi = d.get(k + 1).copied().unwrap_or(d[k]);
            d[k] + (r - k as f64) * (hi - d[k])
        };
        points
            .iter()
            .map(|p| {
                p.iter().all(|v| v.is_finite())
                    && dist(p) <= limit
                    && (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() <= 1.3 * leg_m
            })
            .collect()
    }

    #[test]
    fn the_streamed_rule_keeps_what_sorting_every_distance_keeps() {
        let mut rng = crate::testkit::Rng::new(41);
        for n in [1, 2, 3, 7, 199, 200, 201, 5000] {
            let mut pts: Vec<[f64; 3]> = (0..n)
                .map(|_| [0.0; 3].map(|_| rng.uniform(-0.5, 0.5)))
                .collect();
            if n > 3 {
                pts[1] = pts[0]; // ties
                pts[2] = [f64::INFINITY, 0.0, 0.0];
            }
            for leg in [0.3, 0.9] {
                assert_eq!(
                    inliers(&pts, leg),
                    reference_keep(&pts, leg),
                    "n {n} leg {leg}"
                );
            }
        }
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
