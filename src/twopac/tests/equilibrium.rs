//! Equality form, margins and statuses (spec §2.1, §2.2, §8.2, §9 R1, R2).

use super::{flat_foot, point_set, Rng, R1_COM, R1_POINTS};
use crate::twopac::contact::{friction_rays, Contact, ContactShape};
use crate::twopac::equilibrium::{wrench, EqualityForm, Status, GRAVITY};

const R2_POINTS: [[f64; 3]; 4] = [
    [0.05, 0.1, 0.0],
    [0.05, -0.1, 0.0],
    [-0.05, -0.1, 0.0],
    [-0.05, 0.1, 0.0],
];

#[test]
fn rays_for_vertical_normal_lean_along_the_diagonals_of_spec_2_1() {
    // §2.1: for n = e_z, T1 = −e_x, T2 = −e_y; r_j = n + μ(sin θ_j T1 + cos θ_j T2).
    let mu = 0.3;
    let rays = friction_rays([0.0, 0.0, 1.0], mu);
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let k = 1.0 / (1.0 + mu * mu).sqrt();
    // θ_0 = 45°: (−μ s, −μ s, 1); θ_1 = 135°: (−μ s, +μ s, 1); θ_2: (+,+); θ_3: (+,−).
    let expect = [[-1.0, -1.0], [-1.0, 1.0], [1.0, 1.0], [1.0, -1.0]];
    for (r, e) in rays.iter().zip(expect) {
        assert!((r[0] - e[0] * mu * s * k).abs() < 1e-15, "{r:?}");
        assert!((r[1] - e[1] * mu * s * k).abs() < 1e-15, "{r:?}");
        assert!((r[2] - k).abs() < 1e-15);
    }
}

#[test]
fn rays_lie_on_the_cone_for_any_normal() {
    // |f_t| = μ f_n for every ray, unit length; includes n ∥ e_y (the T1 switch).
    let mut rng = Rng::new(7);
    let mut normals = vec![[0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]];
    for _ in 0..50 {
        let v = [
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
        ];
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        normals.push([v[0] / n, v[1] / n, v[2] / n]);
    }
    for n in normals {
        let mu = 0.7;
        for r in friction_rays(n, mu) {
            let fn_ = r[0] * n[0] + r[1] * n[1] + r[2] * n[2];
            let ft = [r[0] - fn_ * n[0], r[1] - fn_ * n[1], r[2] - fn_ * n[2]];
            let ftn = (ft[0] * ft[0] + ft[1] * ft[1] + ft[2] * ft[2]).sqrt();
            assert!((ftn - mu * fn_).abs() < 1e-12, "n {n:?}");
            assert!(((r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt() - 1.0).abs() < 1e-12);
        }
    }
}

#[test]
fn r1_margin_is_17_1222_newtons() {
    // Spec §9 R1 (issue 5 acceptance): 17.1222 ± 1e-3 N.
    let form = EqualityForm::new(&[point_set(&R1_POINTS, [0.0, 0.0, 1.0], 0.5)], 55.8836).unwrap();
    let v = form.verdict(R1_COM, [0.0; 3]);
    assert_eq!(v.status, Status::Solved);
    let m = v.margin_n.unwrap();
    assert!((m - 17.1222).abs() < 1e-3, "margin {m}");
    assert!(v.in_equilibrium);
}

#[test]
fn r2_margin_and_large_acceleration() {
    // Spec §9 R2: ≈ 38.05 N static, ≈ −77546 N with c̈ = (1000, 0, 0).
    let form = EqualityForm::new(&[point_set(&R2_POINTS, [0.0, 0.0, 1.0], 0.3)], 54.0).unwrap();
    let v = form.verdict([0.0, 0.0, 1.0], [0.0; 3]);
    assert_eq!(v.status, Status::Solved);
    let m = v.margin_n.unwrap();
    assert!((m - 38.05).abs() < 0.005, "margin {m}");
    assert!(v.in_equilibrium);
    let v = form.verdict([0.0, 0.0, 1.0], [1000.0, 0.0, 0.0]);
    assert_eq!(v.status, Status::Solved);
    let m = v.margin_n.unwrap();
    // "≈ −77546": the reference prints 5 significant digits.
    assert!((m + 77546.0).abs() < 1.0, "margin {m}");
    assert!(!v.in_equilibrium);
}

#[test]
fn margin_solution_reproduces_the_wrench() {
    // Closed-form margin for a symmetric case: COM above the centre of 4 points on flat
    // ground, all rays equal by symmetry: 16 β cos α = m g with cos α = 1/√(1+μ²).
    let (m, mu) = (54.0, 0.3);
    let form = EqualityForm::new(&[point_set(&R2_POINTS, [0.0, 0.0, 1.0], mu)], m).unwrap();
    let v = form.verdict([0.0, 0.0, 0.8], [0.0; 3]);
    let b0 = v.b0_n.unwrap();
    // Tilting the rays away from the symmetric solution cannot raise the minimum, and
    // the symmetric solution is feasible: b0 = m g √(1+μ²)/16.
    let expect = m * GRAVITY * (1.0 + mu * mu).sqrt() / 16.0;
    assert!((b0 - expect).abs() < 1e-5 * expect, "b0 {b0} vs {expect}");
}

#[test]
fn single_point_contact_holds_the_com_only_on_its_vertical() {
    let c = Contact::new(
        "hand",
        [0.3, -0.2, 0.5],
        [0.0, 0.0, 1.0],
        0.5,
        0.0,
        ContactShape::Point,
    )
    .unwrap();
    let form = EqualityForm::new(&[c], 60.0).unwrap();
    assert!(form.degenerate);
    assert_eq!(form.rank(), 3);
    let above = form.verdict([0.3, -0.2, 1.4], [0.0; 3]);
    assert_eq!(above.status, Status::Solved);
    assert!(above.in_equilibrium);
    for off in [[0.31, -0.2, 1.4], [0.3, -0.2 + 1e-4, 1.4], [0.0, 0.0, 1.0]] {
        let v = form.verdict(off, [0.0; 3]);
        assert_eq!(v.status, Status::Infeasible, "{off:?}");
        assert!(!v.in_equilibrium);
        assert!(v.margin_n.is_none());
        assert_eq!(form.validation_slack(off, [0.0; 3]), f64::INFINITY);
    }
}

/// Two rectangles facing each other across x = ±0.2 (a grasp): internal forces cancel.
fn clamp() -> Vec<Contact> {
    let rect = ContactShape::Rectangle {
        length_m: 0.1,
        width_m: 0.1,
    };
    vec![
        Contact::new(
            "l",
            [-0.2, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            0.5,
            0.0,
            rect.clone(),
        )
        .unwrap(),
        Contact::new("r", [0.2, 0.0, 1.0], [-1.0, 0.0, 0.0], 0.5, 0.0, rect).unwrap(),
    ]
}

#[test]
fn opposing_contacts_are_force_closure_with_unbounded_margin() {
    let form = EqualityForm::new(&clamp(), 70.0).unwrap();
    assert!(form.force_closure());
    for (c, a) in [
        ([0.0, 0.0, 1.0], [0.0; 3]),
        ([5.0, -3.0, 0.0], [20.0, 0.0, -4.0]),
    ] {
        let v = form.verdict(c, a);
        assert_eq!(v.status, Status::ForceClosure);
        assert!(v.in_equilibrium);
        assert!(v.margin_n.is_none());
    }
    // A single wall is not force closure.
    let one = EqualityForm::new(&clamp()[..1], 70.0).unwrap();
    assert!(!one.force_closure());
}

#[test]
fn flat_feet_are_not_force_closure() {
    let f = [
        flat_foot("l", [0.0, 0.1, 0.0], 0.2, 0.1, 0.7),
        flat_foot("r", [0.0, -0.1, 0.0], 0.2, 0.1, 0.7),
    ];
    let form = EqualityForm::new(&f, 70.0).unwrap();
    assert!(!form.force_closure());
    assert_eq!(form.rank(), 6);
}

#[test]
fn steep_slope_beyond_the_pyramid_has_no_static_equilibrium() {
    // A foot on a 40° slope, μ = 0.5 < tan 40° = 0.84: no static COM anywhere (margin < 0);
    // on a 10° slope (tan 10° = 0.18 < μ/√2) the COM above the foot is balanced.
    for (deg, balanced) in [(40.0_f64, false), (10.0, true)] {
        let t = deg.to_radians();
        let c = Contact::new(
            "foot",
            [0.0; 3],
            [t.sin(), 0.0, t.cos()],
            0.5,
            0.0,
            ContactShape::Rectangle {
                length_m: 0.2,
                width_m: 0.1,
            },
        )
        .unwrap();
        let form = EqualityForm::new(&[c], 70.0).unwrap();
        let v = form.verdict([0.0, 0.0, 0.9], [0.0; 3]);
        assert_eq!(v.status, Status::Solved);
        assert_eq!(v.in_equilibrium, balanced, "slope {deg}: {v:?}");
    }
}

#[test]
fn static_rhs_is_d_c_plus_d() {
    // eq 12: D c + d = [−m g⃗; m g⃗ × c] = w(c, 0).
    let form = EqualityForm::new(&[point_set(&R2_POINTS, [0.0, 0.0, 1.0], 0.3)], 54.0).unwrap();
    let c = [0.3, -0.7, 1.1];
    let w = form.static_rhs(c);
    let mg = 54.0 * GRAVITY;
    let expect = [0.0, 0.0, mg, mg * c[1], -mg * c[0], 0.0];
    for k in 0..6 {
        assert!((w[k] - expect[k]).abs() < 1e-9);
    }
    assert_eq!(w, wrench(54.0, c, [0.0; 3]));
}
