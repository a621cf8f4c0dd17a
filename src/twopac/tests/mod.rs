//! Tests of the 2PAC core: the reference cases of spec two-pac §9, the acceptance cases of
//! issue 5, and cross-checks of one formulation against another.
//!
//! - `equilibrium`: rays (§2.1), margins R1/R2, point contact, force closure, tilted normals.
//! - `region`: H-representation (eq 2) against the clarabel LP and closed forms.
//! - `transition`: R3, R4, eq 6 vs eq 13, brute force, degenerate sets, empty kinematics.
//! - `curve`: Bezier boundary conditions, derivatives, split, kinematic guarantee.
//! - `trajectory`: sliding window, C² junctions, validation (§7).
//! - `hull`: convex hull H-rep of point clouds.
//! - `simplex`: the private LP solver on small closed-form LPs.

mod contact;
mod curve;
mod equilibrium;
mod hull;
mod region;
mod simplex;
mod timing;
mod trajectory;
mod transition;

use super::contact::{Contact, ContactShape};
use super::polytope::Polytope;

pub(crate) use crate::testkit::Rng;

/// A flat rectangular foot, `length × width`, centred at `pos`, normal `+z`.
pub(crate) fn flat_foot(name: &str, pos: [f64; 3], length: f64, width: f64, mu: f64) -> Contact {
    Contact::new(
        name,
        pos,
        [0.0, 0.0, 1.0],
        mu,
        0.0,
        ContactShape::Rectangle {
            length_m: length,
            width_m: width,
        },
    )
    .unwrap()
}

/// Explicit points with one normal.
pub(crate) fn point_set(pts: &[[f64; 3]], normal: [f64; 3], mu: f64) -> Contact {
    Contact::new(
        "points",
        [0.0; 3],
        normal,
        mu,
        0.0,
        ContactShape::Points(pts.to_vec()),
    )
    .unwrap()
}

/// The R3 kinematic box `x ∈ [−0.7, 0.7], y ∈ [−0.4, 0.4], z ∈ [0, 0.9]` around `(x, y)`.
pub(crate) fn r3_box(x: f64, y: f64) -> Polytope {
    Polytope::aabb([x - 0.7, y - 0.4, 0.0], [x + 0.7, y + 0.4, 0.9])
}

/// The R1 contact points of spec §9 (normals `+z`).
pub(crate) const R1_POINTS: [[f64; 3]; 8] = [
    [
        -0.7063474245027421,
        -0.06198334466697191,
        0.10500265776381526,
    ],
    [
        -0.7063472905523731,
        -0.16198334466619915,
        0.10500228815841565,
    ],
    [-0.8863472905327516, -0.1619835857670806, 0.1049996413498396],
    [
        -0.8863474244831206,
        -0.061983585767853365,
        0.10500001095523921,
    ],
    [-0.743396852364416, 0.08941693428431682, 0.10543429943259852],
    [
        -0.7433970921685953,
        -0.010583065199715004,
        0.10542414383677616,
    ],
    [
        -0.923397090748553,
        -0.010582635847966766,
        0.10544674982875823,
    ],
    [-0.9233968509443737, 0.08941736363606506, 0.1054569054245806],
];

/// The R1 COM of spec §9.
pub(crate) const R1_COM: [f64; 3] = [
    -0.8627637453900214,
    -0.00801979390773269,
    0.7459539226134653,
];

/// The ring scene of spec §8.1: 6 rectangles 0.2 × 0.1 m, radius 0.35 m, azimuth
/// `17.19° + 60° k`, height `0.05 k`, normals tilted 15° toward the axis, `μ = 0.5`.
pub(crate) fn ring_scene() -> Vec<Contact> {
    (0..6)
        .map(|k| {
            let th = (17.19 + 60.0 * k as f64).to_radians();
            let tilt = 15f64.to_radians();
            let n = [-tilt.sin() * th.cos(), -tilt.sin() * th.sin(), tilt.cos()];
            Contact::new(
                format!("c{k}"),
                [0.35 * th.cos(), 0.35 * th.sin(), 0.05 * k as f64],
                n,
                0.5,
                0.0,
                ContactShape::Rectangle {
                    length_m: 0.2,
                    width_m: 0.1,
                },
            )
            .unwrap()
        })
        .collect()
}
