//! Convex hull H-rep (spec §3).

use super::Rng;
use crate::twopac::hull::{hull_hrep, HullOptions};
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
