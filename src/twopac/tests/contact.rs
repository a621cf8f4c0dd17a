//! Contact frames, corners and the kinematic frame change (spec §1.1, §3).

use super::Rng;
use crate::twopac::contact::{frame_axes, Contact, ContactShape};
use crate::twopac::polytope::Polytope;
use crate::twopac::TwopacError;

fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() <= tol)
}

#[test]
fn rectangle_corners_follow_the_frame_and_the_spec_order() {
    // Flat, yaw 0: x = +X, y = +Y; corners (+l/2, +w/2), (+l/2, −w/2), (−l/2, −w/2), (−l/2, +w/2).
    let c = Contact::new(
        "foot",
        [1.0, 2.0, 0.0],
        [0.0, 0.0, 2.0],
        0.5,
        0.0,
        ContactShape::Rectangle {
            length_m: 0.2,
            width_m: 0.1,
        },
    )
    .unwrap();
    assert_eq!(c.normal, [0.0, 0.0, 1.0]);
    let p: Vec<[f64; 3]> = c.points().iter().map(|p| p.pos).collect();
    let expect = [
        [1.1, 2.05, 0.0],
        [1.1, 1.95, 0.0],
        [0.9, 1.95, 0.0],
        [0.9, 2.05, 0.0],
    ];
    for (a, b) in p.iter().zip(expect) {
        assert!(close(*a, b, 1e-15), "{a:?} {b:?}");
    }
    // Yaw 90°: x = +Y, y = −X.
    let (x, y) = frame_axes([0.0, 0.0, 1.0], std::f64::consts::FRAC_PI_2);
    assert!(close(x, [0.0, 1.0, 0.0], 1e-15) && close(y, [-1.0, 0.0, 0.0], 1e-15));
    // Normal ∥ X (a wall): x is the projection of +Y.
    let (x, y) = frame_axes([-1.0, 0.0, 0.0], 0.0);
    assert!(close(x, [0.0, 1.0, 0.0], 1e-15), "{x:?}");
    assert!(close(y, [0.0, 0.0, -1.0], 1e-15), "{y:?}");
    // Tilted normal: x is the normalised projection of +X, orthogonal to n.
    let n = [0.3, 0.0, 0.9539392014169456];
    let (x, _) = frame_axes(n, 0.0);
    assert!((x[0] * n[0] + x[2] * n[2]).abs() < 1e-15 && x[0] > 0.9 && x[1] == 0.0);
}

#[test]
fn malformed_contacts_are_errors() {
    let bad = [
        Contact::new("a", [0.0; 3], [0.0; 3], 0.5, 0.0, ContactShape::Point),
        Contact::new(
            "b",
            [0.0; 3],
            [0.0, 0.0, 1.0],
            -0.1,
            0.0,
            ContactShape::Point,
        ),
        Contact::new(
            "c",
            [f64::NAN, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            0.5,
            0.0,
            ContactShape::Point,
        ),
        Contact::new(
            "d",
            [0.0; 3],
            [0.0, 0.0, 1.0],
            0.5,
            0.0,
            ContactShape::Points(vec![]),
        ),
        Contact::new(
            "e",
            [0.0; 3],
            [0.0, 0.0, 1.0],
            0.5,
            0.0,
            ContactShape::Rectangle {
                length_m: -0.1,
                width_m: 0.1,
            },
        ),
    ];
    for (r, name) in bad.into_iter().zip(["a", "b", "c", "d", "e"]) {
        match r {
            Err(TwopacError::InvalidContact { effector, .. }) => assert_eq!(effector, name),
            other => panic!("{name}: {other:?}"),
        }
    }
}

#[test]
fn kinematic_rows_move_with_the_contact_frame() {
    // §3: ʳc = Rᵀ(c − p); K_w c − k_w must equal K_e ʳc − k_e for every c.
    let ke = Polytope::new(
        vec![
            [1.0, 0.3, 0.0],
            [-1.0, 0.0, 0.2],
            [0.1, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.2, -1.0],
        ],
        vec![0.5, 0.4, 0.3, 0.3, 1.0, -0.2],
    );
    let mut rng = Rng::new(31);
    for _ in 0..50 {
        let yaw = rng.uniform(-3.0, 3.0);
        let p = [
            rng.uniform(-2.0, 2.0),
            rng.uniform(-2.0, 2.0),
            rng.uniform(0.0, 1.0),
        ];
        let kw = ke.to_world_yaw(p, yaw);
        let c = [
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
            rng.uniform(-1.0, 2.0),
        ];
        let d = [c[0] - p[0], c[1] - p[1], c[2] - p[2]];
        let (s, co) = yaw.sin_cos();
        let local = [co * d[0] + s * d[1], -s * d[0] + co * d[1], d[2]];
        for i in 0..ke.len() {
            let w = kw.a[i][0] * c[0] + kw.a[i][1] * c[1] + kw.a[i][2] * c[2] - kw.b[i];
            let e = ke.a[i][0] * local[0] + ke.a[i][1] * local[1] + ke.a[i][2] * local[2] - ke.b[i];
            assert!((w - e).abs() < 1e-12, "{w} {e}");
        }
    }
}
