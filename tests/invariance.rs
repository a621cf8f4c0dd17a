//! Translation and yaw invariance of COM and contacts on a real clip of
//! `../shared/data/bvh`: the root moved and turned in the file moves and turns the COM the
//! same way and leaves the contacts unchanged.
//!
//! # References
//! spec com-from-bvh §2 (rotation convention), §3.2 (file to internal axes).

use stancelib::bvh::{Bvh, Channel};
use stancelib::ingest::IngestOptions;

use super::real_data::load;
use crate::util;

/// (name, yaw in degrees, file translation, expected map of internal COM positions).
type InvarianceCase = (
    &'static str,
    f64,
    [f64; 3],
    Box<dyn Fn([f64; 3]) -> [f64; 3]>,
);

type M3 = [[f64; 3]; 3];

fn mat_mul(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

/// Right-handed elementary rotation about file axis `axis`, degrees (spec §2).
fn elementary(axis: usize, deg: f64) -> M3 {
    let (s, c) = deg.to_radians().sin_cos();
    match axis {
        0 => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        1 => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        _ => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
    }
}

/// (z, y, x) degrees with `R = R_z(z) R_y(y) R_x(x)`.
fn euler_zyx(r: &M3) -> [f64; 3] {
    let y = (-r[2][0]).atan2((r[0][0] * r[0][0] + r[1][0] * r[1][0]).sqrt());
    let z = r[1][0].atan2(r[0][0]);
    let x = r[2][1].atan2(r[2][2]);
    [z.to_degrees(), y.to_degrees(), x.to_degrees()]
}

/// A copy of `bvh` whose kept rows (`skip..`) have the root moved by `p ↦ R_y(ψ)·p + d`
/// (file axes and units) and the root rotation left-multiplied by `R_y(ψ)`.
fn transformed(bvh: &Bvh, skip: usize, psi_deg: f64, d: [f64; 3]) -> Bvh {
    let root = &bvh.hierarchy.joints[0];
    use Channel::*;
    assert_eq!(
        root.channels,
        vec![Xposition, Yposition, Zposition, Zrotation, Yrotation, Xrotation],
        "root channel layout"
    );
    let c0 = root.first_channel;
    let ry = elementary(1, psi_deg);
    let mut out = bvh.clone();
    let nc = out.motion.n_channels;
    for f in skip..out.motion.n_frames() {
        let row = &mut out.motion.values[f * nc..(f + 1) * nc];
        let p = [row[c0], row[c0 + 1], row[c0 + 2]];
        for i in 0..3 {
            row[c0 + i] = (0..3).map(|k| ry[i][k] * p[k]).sum::<f64>() + d[i];
        }
        if psi_deg != 0.0 {
            let r = mat_mul(
                &mat_mul(&elementary(2, row[c0 + 3]), &elementary(1, row[c0 + 4])),
                &elementary(0, row[c0 + 5]),
            );
            let e = euler_zyx(&mat_mul(&ry, &r));
            row[c0 + 3..c0 + 6].copy_from_slice(&e);
        }
    }
    out
}

#[test]
fn translation_and_yaw_invariance() {
    let Some(data) = util::shared_or_skip("translation_and_yaw_invariance") else {
        return;
    };
    let clip = "run/cmu_09_01_run_mb";
    let base = load(&data, clip);
    let skip = base.summary.leadin_dropped.len();
    let s = base.summary.unit_scale.expect("unit scale");
    assert_eq!(
        base.summary.up_axis.as_deref(),
        Some("+Y"),
        "{clip} is +Y up in the file"
    );
    // Internal Z-up metres of a file vector: unit·(x, −z, y) (spec §3.2).
    let to_int = |v: [f64; 3]| [s * v[0], -s * v[2], s * v[1]];
    let d_file = [13.7, 2.5, -21.3]; // CMU units: ≈ 0.77 m, 0.14 m (up), −1.20 m
    let psi = 37.0f64;
    let d_int = to_int(d_file);
    let (sp, cp) = psi.to_radians().sin_cos();
    // R_y(ψ) in the file is a rotation by +ψ about internal +Z: X' = cX − sY, Y' = sX + cY.
    let cases: [InvarianceCase; 2] = [
        (
            "translate",
            0.0,
            d_file,
            Box::new(move |p: [f64; 3]| [p[0] + d_int[0], p[1] + d_int[1], p[2] + d_int[2]]),
        ),
        (
            "rotate 37°",
            psi,
            [0.0; 3],
            Box::new(move |p: [f64; 3]| [cp * p[0] - sp * p[1], sp * p[0] + cp * p[1], p[2]]),
        ),
    ];
    let mut failures = Vec::new();
    for (label, psi, d, expect) in &cases {
        let b2 = transformed(&base.bvh, skip, *psi, *d);
        let (s2, f2, _) = util::ingest_body(&b2, &IngestOptions::default(), label);
        let c2 = (s2, f2);
        // Precondition: lead-in detection (spec §2.1) sees the untouched rows.
        assert_eq!(
            c2.0.leadin_dropped, base.summary.leadin_dropped,
            "{label}: lead-in changed"
        );
        assert_eq!(
            c2.0.up_axis, base.summary.up_axis,
            "{label}: up axis changed"
        );
        assert_eq!(
            c2.1.frame, base.frames.frame,
            "{label}: kept frames changed"
        );
        let mut worst_abs = 0.0f64;
        let mut worst_ratio = 0.0f64; // |err| / max(1e-9, 1e-12·|coordinate|)
        for (k, (p0, p1)) in base.frames.com.iter().zip(&c2.1.com).enumerate() {
            let e = expect(*p0);
            for i in 0..3 {
                let err = (p1[i] - e[i]).abs();
                // CORRECTIONS issue 2 item 11: max(1e-9 m, 1e-12·|coordinate|).
                let tol = 1e-9f64.max(1e-12 * e[i].abs());
                worst_abs = worst_abs.max(err);
                worst_ratio = worst_ratio.max(err / tol);
                if err > tol && failures.len() < 20 {
                    failures.push(format!(
                        "{label}: frame {} axis {i}: COM {:.12} expected {:.12} (err {err:.3e} > {tol:.1e})",
                        base.frames.frame[k], p1[i], e[i]
                    ));
                }
            }
        }
        // Non-vacuity: the transform moved the COM (by ≥ 0.1 m somewhere: 0.8–1.4 m for the
        // translation, 2·r·sin(18.5°) at distance r from the vertical axis for the rotation).
        let moved = base
            .frames
            .com
            .iter()
            .zip(&c2.1.com)
            .map(|(a, b)| {
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
            })
            .fold(0.0, f64::max);
        assert!(
            moved > 0.1,
            "{label}: the COM moved by at most {moved} m: the transform was not applied"
        );
        let mut flips = 0;
        for e in 0..4 {
            flips += base.frames.contact[e]
                .iter()
                .zip(&c2.1.contact[e])
                .filter(|(a, b)| a != b)
                .count();
        }
        println!(
            "{clip} {label}: {} frames, COM moved up to {moved:.3} m, worst COM error {worst_abs:.3e} m ({worst_ratio:.2e} of the tolerance), contact flags differing: {flips}",
            base.frames.com.len()
        );
        if flips > 0 {
            failures.push(format!("{label}: {flips} contact flags differ"));
        }
    }
    assert!(
        failures.is_empty(),
        "invariance failures:\n{}",
        failures.join("\n")
    );
}
