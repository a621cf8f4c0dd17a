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
    let (_, faces) = triangle_planes(points).map_err(|msg| degenerate(&msg))?;
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

/// One hull triangle's plane: unit outward normal `n`, offset `d = n·a` (m) and twice
/// its area (m²).
type TrianglePlane = ([f64; 3], f64, f64);

/// parry's quickhull of finite `points`: its vertices and the plane of every triangle
/// with a nonzero area, the normal oriented away from the vertices' centroid.
///
/// # Errors
/// The quickhull's failure or an empty hull, as a message.
fn triangle_planes(points: &[[f64; 3]]) -> Result<(Vec<[f64; 3]>, Vec<TrianglePlane>), String> {
    let pts: Vec<Vector3> = points
        .iter()
        .map(|p| Vector3::new(p[0], p[1], p[2]))
        .collect();
    let (verts, tris) = parry3d_f64::transformation::try_convex_hull(&pts)
        .map_err(|e| format!("quickhull: {e:?}"))?;
    drop(pts);
    let v: Vec<[f64; 3]> = verts.iter().map(|p| [p.x, p.y, p.z]).collect();
    if v.is_empty() {
        return Err("empty hull".to_string());
    }
    let centroid = scale(
        1.0 / v.len() as f64,
        v.iter().fold([0.0; 3], |acc, p| add(acc, *p)),
    );
    let mut faces: Vec<TrianglePlane> = Vec::with_capacity(tris.len());
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
    Ok((v, faces))
}

/// Points deeper than this inside the hull (m) are dropped by [`StreamedHull`]: no such
/// point is a vertex or the maximiser of a facet's `n·x`. A merged facet's normal is
/// within twice the coplanar tolerance (2e-7, triangles are grouped against the group's
/// first normal) of each of its triangles', which moves `n·x` by at most 2e-7 · |x − a|:
/// under δ for point sets up to 5 m across, and a contact frame's COM samples lie within
/// 1.3 leg lengths of the contact (the outlier rule). 1 µm is also ten orders of magnitude
/// above the round-off of a depth.
pub const KEEP_DEPTH_M: f64 = 1e-6;
/// Points gathered by [`StreamedHull`] before its running hull is rebuilt and the deep
/// points dropped.
pub const STREAM_CHUNK_POINTS: usize = 65_536;

/// The hull of a stream of points in bounded memory, equal bit for bit whatever the chunk
/// size, the order of the points or how they were split (a build's batches, a merge's
/// shards).
///
/// # Model
/// ```text
/// T(A)  = { p ∈ A : depth_H(p) ≤ δ },   H = conv A,  δ = KEEP_DEPTH_M,
///         depth_H(p) = min over H's triangle planes of (d − n·p)
/// hull  = hull_hrep(sort(T(A)), duplicates removed)
/// ```
/// `T(A)` holds every vertex of `H` and every maximiser of a facet's `n·x`, so the
/// polytope is that of all of `A` (the rows' offsets are the same maxima). It is computed
/// chunk by chunk: the running set `R` (at most `STREAM_CHUNK_POINTS` new points at a time)
/// is replaced by `T(R)`. Dropping a point is final, and safe: `conv R ⊆ H`, and depth
/// only grows with the body (`depth_H(p) ≥ depth_conv R(p)`), so a point dropped as deeper
/// than δ in `conv R` is deeper than δ in `H`. The last reduction is over a set holding all
/// of `H`'s vertices, so it yields `T(A)` itself, a set (sorted, without duplicates) that
/// does not depend on the chunks; the hull of that set is the output. (Up to round-off: a
/// point whose depth is within ~1e-16 m of δ may fall on either side of it, depending on
/// the triangulation it is tested against.)
///
/// Memory: the running set is the points within δ of the surface (a hull's vertices and
/// points on its facets) plus one chunk, not the stream. A stream that is all coplanar
/// (no 3-D hull) keeps every point, and then has no polytope anyway.
///
/// Speed: the depth test visits only the planes whose normals face the point (a cube map
/// of the normals with a lower bound per bucket, `PlaneIndex`), not every triangle. A new
/// point is tested against the last running hull as it arrives and dropped at once when
/// deeper than δ in it (safe by the same argument: `conv R ⊆ H`), so a chunk holds only
/// the points near or outside the running hull, and a stream that revisits its own poses
/// (a long recording, clips of one motion) rarely rebuilds the hull. A point found deep
/// leaves a lower bound on its depth as an anchor: the next points within that bound
/// less δ of it are deep too (depth is 1-Lipschitz), with no plane or bucket looked at.
#[derive(Debug, Clone)]
pub struct StreamedHull {
    kept: Vec<[f64; 3]>,
    pending: Vec<[f64; 3]>,
    chunk: usize,
    /// The planes of the running hull `conv R`, after the first reduction.
    index: Option<PlaneIndex>,
    /// The last point found deeper than δ, and a lower bound on its depth (m).
    anchor: Option<([f64; 3], f64)>,
}

impl Default for StreamedHull {
    fn default() -> Self {
        StreamedHull::with_chunk(STREAM_CHUNK_POINTS)
    }
}

impl StreamedHull {
    /// A hull reduced every `chunk` points (at least 1).
    pub fn with_chunk(chunk: usize) -> StreamedHull {
        StreamedHull {
            kept: Vec::new(),
            pending: Vec::new(),
            chunk: chunk.max(1),
            index: None,
            anchor: None,
        }
    }

    /// Add a point; a non-finite point is ignored (it has no place in a hull), and so is
    /// one deeper than δ in the running hull (see the type's docs).
    pub fn push(&mut self, p: [f64; 3]) {
        if !p.iter().all(|v| v.is_finite()) {
            return;
        }
        if let Some(index) = &self.index {
            // Depth is 1-Lipschitz: depth(p) ≥ depth(a) − |p − a|, so a point close to the
            // last deep one is deep too (consecutive frames are centimetres apart).
            if let Some((a, floor)) = self.anchor {
                if floor - norm(sub(p, a)) > KEEP_DEPTH_M + BOUND_SLACK_M {
                    return;
                }
            }
            if let Some(floor) = index.depth_floor(p) {
                self.anchor = Some((p, floor));
                return;
            }
        }
        self.pending.push(p);
        if self.pending.len() >= self.chunk {
            self.reduce();
        }
    }

    /// Points held now (the running set and the pending chunk).
    pub fn held(&self) -> usize {
        self.kept.len() + self.pending.len()
    }

    /// Replace the running set and the pending points by their `T` (see the type's docs);
    /// a set with no solid 3-D hull (collinear or flat: parry then returns a segment or a
    /// two-sided flat mesh, not an error) is kept whole, and new points are not tested.
    fn reduce(&mut self) {
        let mut all = std::mem::take(&mut self.kept);
        all.append(&mut self.pending);
        let index = match triangle_planes(&all) {
            Ok((verts, faces)) => PlaneIndex::new(&verts, &faces),
            Err(_) => None,
        };
        self.anchor = None;
        let Some(index) = index else {
            self.kept = all;
            self.index = None;
            return;
        };
        all.retain(|p| index.near_a_plane(*p));
        self.kept = all;
        self.index = Some(index);
    }

    /// The polytope of every point pushed ([`hull_hrep`] of `T`, see the type's docs).
    ///
    /// # Errors
    /// As [`hull_hrep`]: fewer than 4 non-coplanar points.
    pub fn finish(mut self, opts: &HullOptions) -> Result<Polytope, TwopacError> {
        self.reduce();
        let mut t = self.kept;
        t.sort_by(|a, b| {
            a[0].total_cmp(&b[0])
                .then(a[1].total_cmp(&b[1]))
                .then(a[2].total_cmp(&b[2]))
        });
        t.dedup_by(|a, b| a.map(f64::to_bits) == b.map(f64::to_bits));
        hull_hrep(&t, opts)
    }
}

/// Cells per side of each of the cube map's 6 faces that bucket the planes by normal.
const NORMAL_CELLS: usize = 6;
/// Slack on a bucket's lower bound (m), far above its round-off: a bucket is skipped only
/// when every plane in it is deeper than δ by this much.
const BOUND_SLACK_M: f64 = 1e-9;

/// A hull's triangle planes bucketed by normal direction (a cube map), for the depth test
/// `∃ f: d_f − n_f·p ≤ δ` without scanning every plane.
///
/// With `c` the vertices' centroid, `q = p − c` and `h_f = d_f − n_f·c` (> 0), a bucket `B`
/// with mean direction `u` and spread `r = max |n_f − u|` bounds its planes' depths by
/// ```text
/// d_f − n_f·p = h_f − n_f·q ≥ min_B h − u·q − r |q|
/// ```
/// so a bucket whose bound exceeds δ (plus a slack) is skipped whole: only the few buckets
/// facing `p` are scanned, and a point near the centre none.
#[derive(Debug, Clone)]
struct PlaneIndex {
    centroid: [f64; 3],
    buckets: Vec<PlaneBucket>,
}

/// One cube-map cell of a [`PlaneIndex`]: mean unit direction, spread, least `h`, and
/// its planes `(n, d)`.
type PlaneBucket = ([f64; 3], f64, f64, Vec<([f64; 3], f64)>);

impl PlaneIndex {
    /// The index of a hull's planes; `None` unless the hull is solid: at least 4 planes,
    /// each farther than δ from the vertices' centroid (a collinear set has no planes, a
    /// flat one's two-sided mesh passes through its centroid).
    fn new(verts: &[[f64; 3]], faces: &[TrianglePlane]) -> Option<PlaneIndex> {
        let centroid = scale(
            1.0 / verts.len().max(1) as f64,
            verts.iter().fold([0.0; 3], |acc, p| add(acc, *p)),
        );
        let mut cells: Vec<Vec<([f64; 3], f64)>> =
            vec![Vec::new(); 6 * NORMAL_CELLS * NORMAL_CELLS];
        for (n, d, _) in faces {
            cells[cube_cell(*n)].push((*n, *d));
        }
        let buckets = cells
            .into_iter()
            .filter(|planes| !planes.is_empty())
            .map(|planes| {
                let u = unit(planes.iter().fold([0.0; 3], |acc, (n, _)| add(acc, *n)));
                let spread = planes
                    .iter()
                    .map(|(n, _)| norm(sub(*n, u)))
                    .fold(0.0, f64::max);
                let h_min = planes
                    .iter()
                    .map(|(n, d)| d - dot(*n, centroid))
                    .fold(f64::INFINITY, f64::min);
                (u, spread, h_min, planes)
            })
            .collect::<Vec<PlaneBucket>>();
        let solid = faces.len() >= 4
            && buckets
                .iter()
                .all(|(_, _, h_min, _)| *h_min > KEEP_DEPTH_M + BOUND_SLACK_M);
        solid.then_some(PlaneIndex { centroid, buckets })
    }

    /// A lower bound on the depth of `p` under every plane (m) when it is deeper than δ
    /// under all of them: the least of the skipped buckets' bounds and of the depths
    /// under the planes looked at; `None` when some plane has `d − n·p ≤ KEEP_DEPTH_M`
    /// (`p` within δ of the hull's surface or outside it).
    fn depth_floor(&self, p: [f64; 3]) -> Option<f64> {
        let q = sub(p, self.centroid);
        let q_norm = norm(q);
        let mut floor = f64::INFINITY;
        for (u, spread, h_min, planes) in &self.buckets {
            let bound = h_min - dot(*u, q) - spread * q_norm;
            // A NaN bound (a degenerate bucket) is never skipped.
            if bound > KEEP_DEPTH_M + BOUND_SLACK_M {
                floor = floor.min(bound);
                continue;
            }
            for (n, d) in planes {
                let depth = d - dot(*n, p);
                if depth <= KEEP_DEPTH_M {
                    return None;
                }
                floor = floor.min(depth);
            }
        }
        Some(floor)
    }

    /// Some plane has `d − n·p ≤ KEEP_DEPTH_M`: `p` is within δ of the hull's surface or
    /// outside it.
    fn near_a_plane(&self, p: [f64; 3]) -> bool {
        self.depth_floor(p).is_none()
    }
}

/// The cube-map cell of a unit normal: its dominant axis and sign, then the other two
/// coordinates over the dominant one, each in `NORMAL_CELLS` bins of [−1, 1].
fn cube_cell(n: [f64; 3]) -> usize {
    let axis = (0..3)
        .max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(0);
    let face = 2 * axis + usize::from(n[axis] < 0.0);
    let bin = |v: f64| {
        let t = (v / n[axis].abs() + 1.0) / 2.0;
        ((t * NORMAL_CELLS as f64) as usize).min(NORMAL_CELLS - 1)
    };
    let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
    (face * NORMAL_CELLS + bin(n[a])) * NORMAL_CELLS + bin(n[b])
}
