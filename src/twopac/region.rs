//! The H-representation (eq 2) of a phase's static COM region, by exact projection of the
//! equality form onto the COM plane (two-pac §2.3, "support-function LPs").
//!
//! # Model
//!
//! With `c̈ = 0` the wrench is `w = m g (0, 0, 1, c_y, −c_x, 0)`, so the static region is a
//! vertical prism over the polygon
//!
//! ```text
//! Q = { (−τ_y(β̃), τ_x(β̃)) :  β̃ ≥ 0,  Σ β̃_k r_k = (0, 0, 1),  τ_z(β̃) = 0 }      (m)
//! τ(β̃) = Σ_k β̃_k (p_k × r_k),   β̃ = β/(m g)  (body weights; Q does not depend on m)
//! A c ≤ a :  rows (n_x, n_y, 0) with ‖n‖ = 1,  a = h_Q(n) = max_{c ∈ Q} n·c        (m)
//! ```
//!
//! The support function `h_Q` is one LP per direction, all on the same constraints, so a
//! phase-1 basis is found once and every further LP is warm-started (`twopac::simplex`).
//! The polygon is found by Bretl–Lall refinement: supports in 8 directions, then for each
//! pair of consecutive support points the outward normal of their chord is queried; if
//! `h_Q(n)` exceeds the chord by more than `tol_m` the new point splits the chord, else
//! the chord is a facet. To keep every LP bounded the region is clipped to a square of
//! half-side `box_half_m` around the contact points; rows lying on that square are then
//! dropped and the region is reported [`RegionStatus::Unbounded`] (all rows dropped:
//! every COM is static, force closure). A segment or a point (one or collinear contact
//! points on flat ground) keeps the 8 initial support rows, which close it exactly.
//!
//! # Frames and units
//!
//! World frame, Z up; rows unit, offsets in metres, so eq 6 slacks are metres (§2.3).
//!
//! # References
//!
//! Tonneau et al., 2PAC, eq 2; Bretl & Lall 2008, "Testing static equilibrium for legged
//! robots" (iterative projection); spec two-pac §2.3, §8.1.

use super::contact::{friction_rays, ContactPoint};
use super::polytope::Polytope;
use super::simplex::{LpFailure, Simplex};
use super::v3::cross;
use super::TwopacError;

/// Half-side of the clipping square around the contact points, m.
pub const DEFAULT_BOX_HALF_M: f64 = 1e3;
/// A support point farther than this beyond a chord splits it, m.
pub const DEFAULT_TOL_M: f64 = 1e-9;
/// Number of initial support directions (evenly spaced).
pub const DEFAULT_INITIAL_DIRECTIONS: usize = 8;
/// Refinement depth cap per chord (never reached by convex input).
pub const MAX_DEPTH: usize = 48;
/// Cap on the number of support LPs of one region (a polygon has at most this many
/// vertices here; reached only on non-finite input).
pub const MAX_LPS: usize = 4096;

/// Options of [`static_region`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegionOptions {
    /// See [`DEFAULT_BOX_HALF_M`].
    pub box_half_m: f64,
    /// See [`DEFAULT_TOL_M`].
    pub tol_m: f64,
    /// See [`DEFAULT_INITIAL_DIRECTIONS`] (at least 3).
    pub initial_directions: usize,
}

impl Default for RegionOptions {
    fn default() -> Self {
        RegionOptions {
            box_half_m: DEFAULT_BOX_HALF_M,
            tol_m: DEFAULT_TOL_M,
            initial_directions: DEFAULT_INITIAL_DIRECTIONS,
        }
    }
}

/// What kind of region was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RegionStatus {
    /// A bounded polygon (possibly a segment or a point).
    Bounded,
    /// Unbounded in some direction (no rows at all under force closure).
    Unbounded,
    /// No COM is in static equilibrium (no vertical support at all).
    Empty,
}

/// The static COM region of one contact set: `A c ≤ a` (eq 2) and its polygon.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticRegion {
    /// Rows `(n_x, n_y, 0)·c ≤ a`, unit normals, sorted by angle; empty when `Empty`.
    pub polytope: Polytope,
    /// Polygon vertices `(x, y)`, counter-clockwise (clipped to the square if unbounded).
    pub vertices: Vec<[f64; 2]>,
    /// Bounded, unbounded or empty.
    pub status: RegionStatus,
    /// Number of LPs solved (diagnostics).
    pub n_lps: usize,
}

impl StaticRegion {
    /// Whether `com` is statically balanced within `tol_m` (`false` when empty).
    pub fn contains(&self, com: [f64; 3], tol_m: f64) -> bool {
        self.status != RegionStatus::Empty && self.polytope.contains(com, tol_m)
    }
}

/// The LP of the support function `h_Q` on one contact set, warm-started.
struct SupportLp {
    lp: Simplex,
    /// Per column: `(−τ_y, τ_x)` coefficient of `c`, zero on the square's slacks.
    cx: Vec<f64>,
    cy: Vec<f64>,
    obj: Vec<f64>,
    n_lps: usize,
}

impl SupportLp {
    fn new(points: &[ContactPoint], centre: [f64; 2], half: f64) -> Result<Self, LpFailure> {
        let nb = 4 * points.len();
        let n = nb + 4;
        let mut a = vec![0.0; 8 * n];
        let mut cx = vec![0.0; n];
        let mut cy = vec![0.0; n];
        let mut k = 0;
        for p in points {
            for r in friction_rays(p.normal, p.mu) {
                let t = cross(p.pos, r);
                for i in 0..3 {
                    a[i * n + k] = r[i];
                }
                a[3 * n + k] = t[2];
                cx[k] = -t[1];
                cy[k] = t[0];
                // ±c_x, ±c_y rows of the clipping square
                a[4 * n + k] = cx[k];
                a[5 * n + k] = -cx[k];
                a[6 * n + k] = cy[k];
                a[7 * n + k] = -cy[k];
                k += 1;
            }
        }
        for s in 0..4 {
            a[(4 + s) * n + nb + s] = 1.0;
        }
        let b = [
            0.0,
            0.0,
            1.0,
            0.0,
            centre[0] + half,
            half - centre[0],
            centre[1] + half,
            half - centre[1],
        ];
        let lp = Simplex::new(&a, &b, n)?;
        Ok(SupportLp {
            lp,
            cx,
            cy,
            obj: vec![0.0; n],
            n_lps: 1,
        })
    }

    /// `(h_Q(d), argmax)` for direction `d`.
    fn support(&mut self, d: [f64; 2]) -> Result<(f64, [f64; 2]), LpFailure> {
        for ((o, x), y) in self.obj.iter_mut().zip(&self.cx).zip(&self.cy) {
            *o = d[0] * x + d[1] * y;
        }
        self.lp.maximise(&self.obj)?;
        self.n_lps += 1;
        let c = [self.lp.value_of(&self.cx), self.lp.value_of(&self.cy)];
        Ok((d[0] * c[0] + d[1] * c[1], c))
    }
}

/// The static COM region (eq 2) of a contact set, zero acceleration (§2.3, §8.1).
///
/// # Errors
///
/// [`TwopacError::Solver`] if an LP hits its pivot cap or turns out unbounded inside the
/// clipping square; [`TwopacError::NotConverged`] when more than [`MAX_LPS`] LPs are needed (numerical trouble or
/// non-finite points; never seen on valid input).
pub fn static_region(
    points: &[ContactPoint],
    opts: &RegionOptions,
) -> Result<StaticRegion, TwopacError> {
    let empty = || StaticRegion {
        polytope: Polytope::default(),
        vertices: Vec::new(),
        status: RegionStatus::Empty,
        n_lps: 1,
    };
    if points.is_empty() {
        return Ok(empty());
    }
    let np = points.len() as f64;
    let centre = [
        points.iter().map(|p| p.pos[0]).sum::<f64>() / np,
        points.iter().map(|p| p.pos[1]).sum::<f64>() / np,
    ];
    let fail = |what: &str, e: LpFailure| TwopacError::Solver {
        what: format!("static region: {what}: {e:?}"),
    };
    let mut lp = match SupportLp::new(points, centre, opts.box_half_m) {
        Ok(lp) => lp,
        Err(LpFailure::Infeasible) => return Ok(empty()),
        Err(e) => return Err(fail("phase 1", e)),
    };
    let nd = opts.initial_directions.max(3);
    let mut init = Vec::with_capacity(nd);
    for k in 0..nd {
        let th = std::f64::consts::TAU * k as f64 / nd as f64;
        let d = [th.cos(), th.sin()];
        let (h, c) = lp.support(d).map_err(|e| fail("support", e))?;
        init.push((d, h, c));
    }
    let (mut facets, found) = refine(&mut lp, &init, opts)?;
    let vertices = convex_hull_2d(&found, opts.tol_m);
    if !full_dimensional(&vertices, 100.0 * opts.tol_m) {
        facets.extend(init.iter().map(|&(d, h, _)| (d, h)));
    }
    let (facets, status) = drop_square_rows(facets, centre, opts.box_half_m);
    let facets = dedupe(facets);
    let polytope = Polytope {
        a: facets.iter().map(|&(n, _)| [n[0], n[1], 0.0]).collect(),
        b: facets.iter().map(|&(_, h)| h).collect(),
    };
    Ok(StaticRegion {
        polytope,
        vertices,
        status,
        n_lps: lp.n_lps,
    })
}

/// One initial support direction: `(d, h_Q(d), argmax)`.
type Support = ([f64; 2], f64, [f64; 2]);
/// A facet `n·c ≤ h` of the region (unit outward `n`, offset `h` in m).
type Facet = ([f64; 2], f64);

/// Refine every chord between consecutive initial support points (counter-clockwise) by
/// the support in its outward normal, until the gap is within `tol_m` or [`MAX_DEPTH`]:
/// returns the facets `(n, h)` and every support point found.
fn refine(
    lp: &mut SupportLp,
    init: &[Support],
    opts: &RegionOptions,
) -> Result<(Vec<Facet>, Vec<[f64; 2]>), TwopacError> {
    let fail = |what: &str, e: LpFailure| TwopacError::Solver {
        what: format!("static region: {what}: {e:?}"),
    };
    let nd = init.len();
    let mut facets: Vec<Facet> = Vec::new();
    let mut found: Vec<[f64; 2]> = init.iter().map(|x| x.2).collect();
    for k in 0..nd {
        let (_, _, c0) = init[k];
        let (_, _, c1) = init[(k + 1) % nd];
        // Refine the chord c0 → c1 (counter-clockwise): stack of chords.
        let mut stack = vec![(c0, c1, 0usize)];
        while let Some((a, b, depth)) = stack.pop() {
            let e = [b[0] - a[0], b[1] - a[1]];
            let len = e[0].hypot(e[1]);
            if len <= opts.tol_m {
                continue;
            }
            let n = [e[1] / len, -e[0] / len];
            let (h, c) = lp.support(n).map_err(|e| fail("support", e))?;
            let chord = n[0] * a[0] + n[1] * a[1];
            if lp.n_lps > MAX_LPS {
                return Err(TwopacError::NotConverged {
                    what: format!("static region: support LPs (cap MAX_LPS = {MAX_LPS})"),
                    iterations: lp.n_lps,
                });
            }
            // A NaN gap also ends the refinement.
            let gap = h - chord;
            if gap.is_nan() || gap <= opts.tol_m || depth >= MAX_DEPTH {
                facets.push((n, h.max(chord)));
            } else {
                found.push(c);
                stack.push((c, b, depth + 1));
                stack.push((a, c, depth + 1));
            }
        }
    }
    Ok((facets, found))
}

/// Drop the facets that lie on the clipping square (half-width `box_half_m` about
/// `centre`); the region is unbounded when there were any.
fn drop_square_rows(
    mut facets: Vec<Facet>,
    centre: [f64; 2],
    box_half_m: f64,
) -> (Vec<Facet>, RegionStatus) {
    let lim = [
        centre[0] + box_half_m,
        box_half_m - centre[0],
        centre[1] + box_half_m,
        box_half_m - centre[1],
    ];
    let axes = [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]];
    let on_square = |n: [f64; 2], h: f64| {
        axes.iter().zip(lim).any(|(ax, l)| {
            (n[0] - ax[0]).abs() + (n[1] - ax[1]).abs() < 1e-9 && h >= l - 1e-6 * box_half_m
        })
    };
    let before = facets.len();
    facets.retain(|&(n, h)| !on_square(n, h));
    let status = if facets.len() < before {
        RegionStatus::Unbounded
    } else {
        RegionStatus::Bounded
    };
    (facets, status)
}

/// Sort facets by angle and merge equal normals (keeping the larger offset).
fn dedupe(mut facets: Vec<([f64; 2], f64)>) -> Vec<([f64; 2], f64)> {
    facets.sort_by(|a, b| {
        let ta = a.0[1].atan2(a.0[0]);
        let tb = b.0[1].atan2(b.0[0]);
        ta.total_cmp(&tb)
    });
    let mut out: Vec<([f64; 2], f64)> = Vec::with_capacity(facets.len());
    for f in facets {
        match out.last_mut() {
            Some(last) if (last.0[0] - f.0[0]).abs() + (last.0[1] - f.0[1]).abs() < 1e-12 => {
                last.1 = last.1.max(f.1);
            }
            _ => out.push(f),
        }
    }
    if out.len() > 1 {
        let (first, last) = (out[0], out[out.len() - 1]);
        if (last.0[0] - first.0[0]).abs() + (last.0[1] - first.0[1]).abs() < 1e-12 {
            out[0].1 = first.1.max(last.1);
            out.pop();
        }
    }
    out
}

/// Whether the points span an area: some point is farther than `tol` from the line
/// through the two farthest-apart points.
fn full_dimensional(v: &[[f64; 2]], tol: f64) -> bool {
    if v.len() < 3 {
        return false;
    }
    let mut best = (0.0, 0, 0);
    for i in 0..v.len() {
        for j in i + 1..v.len() {
            let d = (v[i][0] - v[j][0]).hypot(v[i][1] - v[j][1]);
            if d > best.0 {
                best = (d, i, j);
            }
        }
    }
    let (a, b) = (v[best.1], v[best.2]);
    let e = [(b[0] - a[0]) / best.0, (b[1] - a[1]) / best.0];
    v.iter()
        .any(|p| ((p[0] - a[0]) * e[1] - (p[1] - a[1]) * e[0]).abs() > tol)
}

/// Counter-clockwise convex hull (Andrew's monotone chain), merging points closer than
/// `tol` and dropping collinear ones.
pub fn convex_hull_2d(points: &[[f64; 2]], tol: f64) -> Vec<[f64; 2]> {
    let mut p: Vec<[f64; 2]> = points.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup_by(|a, b| (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol);
    if p.len() < 3 {
        return p;
    }
    let turn = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while hull.len() >= start + 2
                && turn(hull[hull.len() - 2], hull[hull.len() - 1], q) <= tol * tol
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}
