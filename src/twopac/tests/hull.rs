//! Convex hull H-rep (spec §3).

use super::Rng;
use crate::twopac::hull::{hull_hrep, HullOptions, StreamedHull};
use crate::twopac::TwopacError;

#[test]
fn cube_has_six_facets() {
    let mut pts = Vec::new();
    for i in 0..8 {
        pts.push([
            if i & 1 == 0 { -0.5 } else { 0.5 },
            if i & 2 == 0 { -0.25 } else { 0.25 },
            if i & 4 == 0 { 0.0 } else { 1.0 },
        ]);
    }
    // Interior points and points on the faces must not add facets.
    let mut rng = Rng::new(21);
    for _ in 0..200 {
        pts.push([
            rng.uniform(-0.5, 0.5),
            rng.uniform(-0.25, 0.25),
            rng.uniform(0.0, 1.0),
        ]);
        pts.push([0.5, rng.uniform(-0.25, 0.25), rng.uniform(0.0, 1.0)]);
    }
    let h = hull_hrep(&pts, &HullOptions::default()).unwrap();
    assert_eq!(h.len(), 6);
    for (a, b) in h.a.iter().zip(&h.b) {
        let axis = (0..3).position(|k| a[k].abs() > 0.5).unwrap();
        assert!((a[axis].abs() - 1.0).abs() < 1e-12, "{a:?}");
        let expect = match (axis, a[axis] > 0.0) {
            (0, _) => 0.5,
            (1, _) => 0.25,
            (2, true) => 1.0,
            (2, false) => 0.0,
            _ => unreachable!(),
        };
        assert!((b - expect).abs() < 1e-12, "{a:?} {b}");
    }
}

#[test]
fn every_point_of_a_cloud_is_inside_and_every_facet_touches_it() {
    let mut rng = Rng::new(22);
    let pts: Vec<[f64; 3]> = (0..20000)
        .map(|_| {
            // An ellipsoid-ish cloud (COM samples in a foot frame have this shape).
            let v = [
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
            ];
            let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt().max(1.0);
            [0.3 * v[0] / r, 0.2 * v[1] / r, 0.8 + 0.15 * v[2] / r]
        })
        .collect();
    let h = hull_hrep(&pts, &HullOptions::default()).unwrap();
    assert!(h.len() >= 4);
    for p in &pts {
        assert!(h.max_violation(*p) <= 1e-9, "{p:?}");
    }
    for (a, b) in h.a.iter().zip(&h.b) {
        assert!(((a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt() - 1.0).abs() < 1e-12);
        let on = pts
            .iter()
            .filter(|p| (a[0] * p[0] + a[1] * p[1] + a[2] * p[2] - b).abs() < 1e-9)
            .count();
        assert!(on >= 3, "facet {a:?} touches {on} points");
    }
}

#[test]
fn coplanar_or_too_few_points_have_no_polytope() {
    let flat: Vec<[f64; 3]> = (0..10)
        .map(|i| [i as f64, (i * i) as f64 * 0.1, 0.5])
        .collect();
    let e = hull_hrep(&flat, &HullOptions::default()).unwrap_err();
    assert!(matches!(e, TwopacError::DegenerateHull { .. }), "{e:?}");
    let e = hull_hrep(
        &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &HullOptions::default(),
    );
    assert!(e.is_err());
}

/// An ellipsoid-ish cloud (the shape of COM samples in a foot frame), plus points on one
/// flat face (coplanar hull points, the hard case for a canonical hull).
fn cloud(seed: u64, n: usize) -> Vec<[f64; 3]> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|i| {
            let v = [
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
            ];
            let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt().max(1.0);
            let z = 0.8 + 0.15 * v[2] / r;
            // Every tenth point on the plane z = 0.7 (inside the ellipsoid's footprint).
            let z = if i % 10 == 0 { 0.7 } else { z.max(0.7) };
            [0.3 * v[0] / r, 0.2 * v[1] / r, z]
        })
        .collect()
}

fn streamed(points: &[[f64; 3]], chunk: usize) -> (crate::twopac::polytope::Polytope, usize) {
    let mut h = StreamedHull::with_chunk(chunk);
    let mut most = 0;
    for p in points {
        h.push(*p);
        most = most.max(h.held());
    }
    (h.finish(&HullOptions::default()).unwrap(), most)
}

fn bits(p: &crate::twopac::polytope::Polytope) -> Vec<u64> {
    p.a.iter()
        .flatten()
        .chain(&p.b)
        .map(|v| v.to_bits())
        .collect()
}

#[test]
fn a_streamed_hull_is_the_same_bits_whatever_the_chunks_and_order() {
    let pts = cloud(31, 30_000);
    let (whole, _) = streamed(&pts, usize::MAX);
    for chunk in [257, 4096, 65_536] {
        assert_eq!(
            bits(&streamed(&pts, chunk).0),
            bits(&whole),
            "chunk {chunk}"
        );
    }
    // Another order: reversed, and interleaved halves (shards arriving in another order).
    let rev: Vec<[f64; 3]> = pts.iter().rev().copied().collect();
    assert_eq!(bits(&streamed(&rev, 1000).0), bits(&whole));
    let mut mixed: Vec<[f64; 3]> = pts.iter().skip(1).step_by(2).copied().collect();
    mixed.extend(pts.iter().step_by(2));
    assert_eq!(bits(&streamed(&mixed, 3000).0), bits(&whole));
    // Duplicates (a clip read twice under two names) change nothing.
    let mut twice = pts.clone();
    twice.extend(&pts);
    assert_eq!(bits(&streamed(&twice, 5000).0), bits(&whole));
}

#[test]
fn a_streamed_hull_is_the_hull_of_all_its_points() {
    let pts = cloud(32, 20_000);
    let (h, _) = streamed(&pts, 2048);
    let all = hull_hrep(&pts, &HullOptions::default()).unwrap();
    // Every row's offset is the maximum of n·x over all the points, to the bit.
    for (n, d) in h.a.iter().zip(&h.b) {
        let max = pts
            .iter()
            .map(|p| n[0] * p[0] + n[1] * p[1] + n[2] * p[2])
            .fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(max.to_bits(), d.to_bits(), "row {n:?}");
    }
    assert!(pts.iter().all(|p| h.max_violation(*p) <= 1e-12));
    // The same facets as the in-memory hull of every point (its triangulation may round
    // the merged normals differently).
    assert_eq!(h.len(), all.len());
    for (n, d) in all.a.iter().zip(&all.b) {
        let close =
            h.a.iter()
                .zip(&h.b)
                .any(|(m, e)| (0..3).all(|k| (m[k] - n[k]).abs() < 1e-9) && (e - d).abs() < 1e-9);
        assert!(
            close,
            "facet {n:?} {d} of the whole hull is not in the streamed one"
        );
    }
}

#[test]
fn a_streamed_hull_holds_the_surface_not_the_stream() {
    // Uniform inside the ellipsoid (no point on its curved surface), a tenth of them on
    // the flat face z = 0.7.
    let mut rng = Rng::new(33);
    let mut pts = Vec::new();
    while pts.len() < 300_000 {
        let v = [0; 3].map(|_| rng.uniform(-1.0, 1.0));
        if v[0] * v[0] + v[1] * v[1] + v[2] * v[2] <= 1.0 {
            let z = if pts.len() % 10 == 0 {
                0.7
            } else {
                (0.8 + 0.15 * v[2]).max(0.7)
            };
            pts.push([0.3 * v[0], 0.2 * v[1], z]);
        }
    }
    let chunk = 8192;
    let (_, most) = streamed(&pts, chunk);
    // The flat face's points lie on the surface and stay; the interior goes.
    let on_face = pts.iter().filter(|p| p[2] == 0.7).count();
    assert!(most <= chunk + on_face + 5_000, "held {most} points");
    let solid: Vec<[f64; 3]> = pts.iter().filter(|p| p[2] > 0.7).copied().collect();
    let (_, most) = streamed(&solid, chunk);
    assert!(
        most <= chunk + 5_000,
        "held {most} of {} points",
        solid.len()
    );
}

#[test]
fn a_collinear_first_chunk_drops_nothing_that_follows() {
    // parry gives a collinear chunk a segment, not an error: no planes to test against,
    // so the chunk is kept and the points after it are not dropped.
    let mut h = StreamedHull::with_chunk(16);
    let line: Vec<[f64; 3]> = (0..16).map(|i| [0.1 * i as f64, 0.0, 0.0]).collect();
    let cube: Vec<[f64; 3]> = (0..8)
        .map(|k| [(k & 1) as f64, ((k >> 1) & 1) as f64, ((k >> 2) & 1) as f64])
        .collect();
    for p in line.iter().chain(&cube) {
        h.push(*p);
    }
    assert_eq!(
        h.held(),
        24,
        "nothing dropped against a hull without volume"
    );
    let all: Vec<[f64; 3]> = line.iter().chain(&cube).copied().collect();
    let (whole, _) = streamed(&all, usize::MAX);
    assert_eq!(
        bits(&h.finish(&HullOptions::default()).unwrap()),
        bits(&whole)
    );
}

#[test]
fn a_flat_stream_has_no_polytope() {
    let mut h = StreamedHull::with_chunk(16);
    for i in 0..100 {
        h.push([i as f64, (i * i % 7) as f64, 0.5]);
    }
    h.push([f64::NAN, 0.0, 0.0]);
    assert_eq!(h.held(), 100, "a flat set is kept whole, a NaN ignored");
    let e = h.finish(&HullOptions::default()).unwrap_err();
    assert!(matches!(e, TwopacError::DegenerateHull { .. }), "{e:?}");
}
