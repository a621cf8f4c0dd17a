//! Convex hull of 3-D points as inequalities `K c ≤ k` (two-pac §3, the kinematic
//! polytopes), with parry's quickhull and coplanar triangles merged into one row.
//!
//! # Model
//!
//! ```text
//! triangles (parry3d quickhull) → unit outward normals n_t
//! merge: triangles with ‖n_t − n_u‖ ≤ coplanar_tol and |d_t − d_u| ≤ offset_tol
//! row:   n = normalised area-weighted mean of the group,   k = max_i n·x_i  (all input points)
//! ```
//!
//! Taking `k` as the maximum over **all** input points (not only the hull vertices) makes
//! every input point satisfy its H-rep up to the round-off of one dot product. Rows are
//! sorted by `(n_x, n_y, n_z, k)` so the output is deterministic.
//!
//! # Frames and units
//!
//! Whatever frame the points are in (§3: the effector's yaw frame); metres.
//!
//! # References
//!
//! Barber, Dobkin & Huhdanpaa 1996 (quickhull); spec two-pac §3.

use super::polytope::Polytope;
use super::v3::{add, cross, dot, norm, scale, sub, unit};
use super::TwopacError;
use parry3d_f64::math::Vector3;

/// Two triangle normals closer than this (unit vectors) may belong to one facet.
pub const DEFAULT_COPLANAR_TOL: f64 = 1e-7;
/// Two triangle offsets closer than this may belong to one facet, m.
pub const DEFAULT_OFFSET_TOL_M: f64 = 1e-9;

/// Options of [`hull_hrep`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HullOptions {
    /// See [`DEFAULT_COPLANAR_TOL`].
    pub coplanar_tol: f64,
    /// See [`DEFAULT_OFFSET_TOL_M`].
    pub offset_tol_m: f64,
}

impl Default for HullOptions {
    fn default() -> Self {
        HullOptions {
            coplanar_tol: DEFAULT_COPLANAR_TOL,
            offset_tol_m: DEFAULT_OFFSET_TOL_M,
        }
    }
}

/// The convex hull of `points` as `K c ≤ k`, one unit-normal row per facet.
///
/// # Errors
///
/// [`TwopacError::DegenerateHull`] for fewer than 4 points, non-finite points, all points
/// coplanar, or a hull the quickhull cannot build.
pub fn hull_hrep(points: &[[f64; 3]], opts: &HullOptions) -> Result<Polytope, TwopacError> {
    let degenerate = |msg: &str| TwopacError::DegenerateHull {
        n_points: points.len(),
        msg: msg.to_string(),
    };
    if points.len() < 4 {
        return Err(degenerate("fewer than 4 points"));
    }
    if !points.iter().flatten().all(|v| v.is_finite()) {
        return Err(degenerate("a point is not finite"));
    }
    let pts: Vec<Vector3> = points
        .iter()
        .map(|p| Vector3::new(p[0], p[1], p[2]))
        .collect();
    let (verts, tris) = parry3d_f64::transformation::try_convex_hull(&pts)
        .map_err(|e| degenerate(&format!("quickhull: {e:?}")))?;
    let v: Vec<[f64; 3]> = verts.iter().map(|p| [p.x, p.y, p.z]).collect();
    if v.is_empty() {
        return Err(degenerate("empty hull"));
    }
    let centroid = scale(
        1.0 / v.len() as f64,
        v.iter().fold([0.0; 3], |acc, p| add(acc, *p)),
    );
    // (unit normal, offset, area) per triangle, oriented away from the centroid.
    let mut faces: Vec<([f64; 3], f64, f64)> = Vec::with_capacity(tris.len());
    for t in &tris {
        let (a, b, c) = (v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
        let nrm = cross(sub(b, a), sub(c, a));
        let area2 = norm(nrm);
        if area2.is_nan() || area2 <= 0.0 {
            continue;
        }
        let mut n = scale(1.0 / area2, nrm);
        if dot(n, sub(a, centroid)) < 0.0 {
            n = scale(-1.0, n);
        }
        faces.push((n, dot(n, a), area2));
    }
    if faces.len() < 4 {
        return Err(degenerate("points are coplanar"));
    }
    // Group coplanar triangles (greedy; a hull has few distinct planes).
    let mut groups: Vec<([f64; 3], f64, [f64; 3])> = Vec::new(); // (first n, first d, Σ area·n)
    for (n, d, area) in faces {
        match groups.iter_mut().find(|g| {
            norm(sub(g.0, n)) <= opts.coplanar_tol && (g.1 - d).abs() <= opts.offset_tol_m
        }) {
            Some(g) => g.2 = add(g.2, scale(area, n)),
            None => groups.push((n, d, scale(area, n))),
        }
    }
    if groups.len() < 4 {
        return Err(degenerate("points are coplanar"));
    }
    let mut rows: Vec<([f64; 3], f64)> = groups
        .iter()
        .map(|g| {
            let n = unit(g.2);
            let k = points
                .iter()
                .map(|p| dot(n, *p))
                .fold(f64::NEG_INFINITY, f64::max);
            (n, k)
        })
        .collect();
    rows.sort_by(|a, b| {
        (a.0[0].total_cmp(&b.0[0]))
            .then(a.0[1].total_cmp(&b.0[1]))
            .then(a.0[2].total_cmp(&b.0[2]))
            .then(a.1.total_cmp(&b.1))
    });
    Ok(Polytope {
        a: rows.iter().map(|r| r.0).collect(),
        b: rows.iter().map(|r| r.1).collect(),
    })
}
