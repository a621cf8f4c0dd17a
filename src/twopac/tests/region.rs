//! H-representation of the static COM region (eq 2, spec §2.3) against the equality LP.

use super::{flat_foot, point_set, ring_scene, Rng, R1_COM, R1_POINTS};
use crate::twopac::contact::{contact_points, Contact, ContactShape};
use crate::twopac::equilibrium::{EqualityForm, Status};
use crate::twopac::region::{static_region, RegionOptions, RegionStatus};

/// Random COMs around the contacts: the H-rep verdict equals the clarabel LP's wherever
/// the point is farther than 1e-6 m from the region's boundary (the LP's own accuracy).
fn cross_check(contacts: &[Contact], half: f64, n: usize, seed: u64) -> (usize, usize) {
    let form = EqualityForm::new(contacts, 70.0).unwrap();
    let region = static_region(&form.points, &RegionOptions::default()).unwrap();
    let pts = &form.points;
    let cx = pts.iter().map(|p| p.pos[0]).sum::<f64>() / pts.len() as f64;
    let cy = pts.iter().map(|p| p.pos[1]).sum::<f64>() / pts.len() as f64;
    let mut rng = Rng::new(seed);
    let (mut inside, mut checked) = (0, 0);
    for _ in 0..n {
        let c = [
            cx + rng.uniform(-half, half),
            cy + rng.uniform(-half, half),
            rng.uniform(0.5, 1.2),
        ];
        let viol = region.polytope.max_violation(c);
        if viol.abs() < 1e-6 {
            continue;
        }
        let v = form.verdict(c, [0.0; 3]);
        assert_eq!(v.status, Status::Solved);
        let lp_inside = v.b0_n.unwrap() > 0.0;
        assert_eq!(
            viol < 0.0,
            lp_inside,
            "c {c:?}: H-rep violation {viol}, LP {v:?}"
        );
        inside += usize::from(lp_inside);
        checked += 1;
    }
    (inside, checked)
}

#[test]
fn hrep_matches_equality_lp_on_r1_points() {
    // Nearly coplanar points (spec §9 R1): a double description may fail; projection not.
    let c = [point_set(&R1_POINTS, [0.0, 0.0, 1.0], 0.5)];
    let (inside, checked) = cross_check(&c, 0.25, 300, 1);
    assert!(inside > 30 && checked - inside > 30, "{inside}/{checked}");
    let form = EqualityForm::new(&c, 55.8836).unwrap();
    let region = static_region(&form.points, &RegionOptions::default()).unwrap();
    assert!(region.contains(R1_COM, 0.0));
}

#[test]
fn hrep_matches_equality_lp_on_the_tilted_ring() {
    let (inside, checked) = cross_check(&ring_scene(), 0.6, 400, 2);
    assert!(inside > 30 && checked - inside > 30, "{inside}/{checked}");
}

#[test]
fn hrep_matches_equality_lp_for_a_foot_and_a_hand_on_a_wall() {
    // Non-coplanar contacts (§2.3 "Check"): foot on the floor, hand on a wall x = 0.5.
    let foot = flat_foot("foot", [0.0, 0.0, 0.0], 0.22, 0.09, 0.7);
    let hand = Contact::new(
        "hand",
        [0.5, 0.2, 1.2],
        [-1.0, 0.0, 0.0],
        0.7,
        0.0,
        ContactShape::Rectangle {
            length_m: 0.1,
            width_m: 0.08,
        },
    )
    .unwrap();
    let (inside, checked) = cross_check(&[foot, hand], 0.6, 600, 3);
    assert!(inside > 30 && checked - inside > 30, "{inside}/{checked}");
}

#[test]
fn polygon_vertices_have_zero_margin_and_facets_separate_in_from_out() {
    // The boundary of the region is exactly where b0* = 0.
    let contacts = ring_scene();
    let form = EqualityForm::new(&contacts, 75.0).unwrap();
    let region = static_region(&form.points, &RegionOptions::default()).unwrap();
    assert_eq!(region.status, RegionStatus::Bounded);
    let scale = 75.0 * 9.81;
    for v in &region.vertices {
        let b0 = form.verdict([v[0], v[1], 1.0], [0.0; 3]).b0_n.unwrap();
        assert!(b0.abs() < 1e-6 * scale, "vertex {v:?}: b0 {b0}");
    }
    let nv = region.vertices.len();
    for i in 0..nv {
        let (a, b) = (region.vertices[i], region.vertices[(i + 1) % nv]);
        let mid = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
        let e = [b[0] - a[0], b[1] - a[1]];
        let l = e[0].hypot(e[1]);
        let out = [e[1] / l, -e[0] / l];
        for (sign, expect) in [(1.0, false), (-1.0, true)] {
            let c = [
                mid[0] + sign * 1e-4 * out[0],
                mid[1] + sign * 1e-4 * out[1],
                0.9,
            ];
            assert_eq!(
                form.verdict(c, [0.0; 3]).in_equilibrium,
                expect,
                "edge {i} {sign}"
            );
        }
    }
}

#[test]
fn two_flat_feet_give_their_bounding_rectangle() {
    // Closed form: on flat ground the region is the support polygon (§2.2).
    let f = [
        flat_foot("l", [0.0, 0.1, 0.0], 0.2172, 0.138, 0.5),
        flat_foot("r", [0.0, -0.1, 0.0], 0.2172, 0.138, 0.5),
    ];
    let region = static_region(&contact_points(&f), &RegionOptions::default()).unwrap();
    assert_eq!(region.status, RegionStatus::Bounded);
    assert_eq!(region.polytope.len(), 4);
    for (a, b) in region.polytope.a.iter().zip(&region.polytope.b) {
        let expect = if a[0].abs() > 0.5 { 0.1086 } else { 0.169 };
        assert!((a[0].abs() + a[1].abs() - 1.0).abs() < 1e-12, "{a:?}");
        assert!((b - expect).abs() < 1e-9, "{a:?} {b}");
    }
}

#[test]
fn tilted_foot_region_is_the_vertical_projection_of_the_foot() {
    // A 10° slope about y: friction suffices, so the COM must be above the patch (the
    // vertical line through it meets the patch): corners' x shrink by cos 10°.
    let t = 10f64.to_radians();
    let c = Contact::new(
        "foot",
        [0.2, 0.1, 0.3],
        [t.sin(), 0.0, t.cos()],
        0.5,
        0.0,
        ContactShape::Rectangle {
            length_m: 0.2,
            width_m: 0.1,
        },
    )
    .unwrap();
    let region = static_region(&c.points(), &RegionOptions::default()).unwrap();
    assert_eq!(region.vertices.len(), 4);
    for p in c.points() {
        let hit = region
            .vertices
            .iter()
            .any(|v| (v[0] - p.pos[0]).abs() < 1e-9 && (v[1] - p.pos[1]).abs() < 1e-9);
        assert!(
            hit,
            "corner {:?} not a vertex of {:?}",
            p.pos, region.vertices
        );
    }
    let xs: Vec<f64> = region.vertices.iter().map(|v| v[0]).collect();
    let width =
        xs.iter().cloned().fold(f64::MIN, f64::max) - xs.iter().cloned().fold(f64::MAX, f64::min);
    assert!((width - 0.2 * t.cos()).abs() < 1e-9);
}

#[test]
fn single_point_region_is_that_point_and_a_line_contact_a_segment() {
    let p = Contact::new(
        "hand",
        [0.3, -0.2, 0.5],
        [0.0, 0.0, 1.0],
        0.5,
        0.0,
        ContactShape::Point,
    )
    .unwrap();
    let region = static_region(&p.points(), &RegionOptions::default()).unwrap();
    assert_eq!(region.status, RegionStatus::Bounded);
    assert!(region.contains([0.3, -0.2, 2.0], 1e-9));
    for off in [[0.3 + 1e-6, -0.2, 1.0], [0.3, -0.2 - 1e-6, 1.0]] {
        assert!(!region.contains(off, 1e-9), "{off:?}");
    }
    // Two points: a segment from (0, 0) to (0.4, 0).
    let bar = point_set(&[[0.0, 0.0, 0.0], [0.4, 0.0, 0.0]], [0.0, 0.0, 1.0], 0.5);
    let region = static_region(&bar.points(), &RegionOptions::default()).unwrap();
    assert!(region.contains([0.2, 0.0, 1.0], 1e-9));
    assert!(region.contains([0.4, 0.0, 1.0], 1e-9));
    assert!(!region.contains([0.2, 1e-6, 1.0], 1e-9));
    assert!(!region.contains([0.4 + 1e-6, 0.0, 1.0], 1e-9));
}

#[test]
fn force_closure_region_has_no_rows_and_no_support_is_empty() {
    let rect = ContactShape::Rectangle {
        length_m: 0.1,
        width_m: 0.1,
    };
    let clamp = [
        Contact::new(
            "l",
            [-0.2, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            0.5,
            0.0,
            rect.clone(),
        )
        .unwrap(),
        Contact::new(
            "r",
            [0.2, 0.0, 1.0],
            [-1.0, 0.0, 0.0],
            0.5,
            0.0,
            rect.clone(),
        )
        .unwrap(),
    ];
    let region = static_region(&contact_points(&clamp), &RegionOptions::default()).unwrap();
    assert_eq!(region.status, RegionStatus::Unbounded);
    assert!(region.polytope.is_empty());
    assert!(region.contains([40.0, -7.0, 0.0], 0.0));
    // A frictionless wall alone cannot hold any weight.
    let wall = Contact::new("w", [0.2, 0.0, 1.0], [-1.0, 0.0, 0.0], 0.0, 0.0, rect).unwrap();
    let region = static_region(&wall.points(), &RegionOptions::default()).unwrap();
    assert_eq!(region.status, RegionStatus::Empty);
    assert!(!region.contains([0.0, 0.0, 1.0], 1.0));
}

#[test]
fn non_finite_points_end_quickly() {
    // Regression: a NaN gap once split chords down to the depth cap (2^48 LPs).
    use crate::twopac::contact::ContactPoint;
    let mut pts = contact_points(&[flat_foot("f", [0.0; 3], 0.2, 0.1, 0.5)]);
    pts.push(ContactPoint {
        pos: [f64::NAN, 0.0, 0.0],
        normal: [0.0, 0.0, 1.0],
        mu: 0.5,
    });
    let t = std::time::Instant::now();
    let _ = static_region(&pts, &RegionOptions::default());
    assert!(t.elapsed().as_secs_f64() < 5.0);
    let form = EqualityForm::new(&[flat_foot("f", [0.0; 3], 0.2, 0.1, 0.5)], 70.0).unwrap();
    assert_eq!(
        form.verdict([f64::NAN, 0.0, 1.0], [0.0; 3]).status,
        Status::SolverFailed
    );
}
