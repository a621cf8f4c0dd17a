//! Issue 15 (ingest at the speed of parsing): what the faster code must not change.
//!
//! The batched FK (several frames per SIMD lane, branch-free sin/cos) gives the same bits
//! on the AVX2 path and the scalar fallback, for one frame and in batches, and stays
//! within 1e-12 m of the libm FK it replaced, on every shared clip.

use std::collections::BTreeMap;
use std::path::PathBuf;

use stancelib::bvh::parse_file;
use stancelib::pipeline::engine::inputs::discover;
use stancelib::skeleton::fk::{self, FkWorkspace, Simd, IDENTITY};
use stancelib::skeleton::landmarks::{self, leg_length, Mapping};
use stancelib::skeleton::units::detect_unit;
use stancelib::skeleton::Skeleton;

use crate::util;

/// Metres per file unit of a clip, as the ingest detects it from the rest-pose legs; 1
/// (the strictest) when the skeleton maps onto no body.
fn metres_per_unit(skel: &Skeleton) -> f64 {
    let rest = fk::rest_pose(skel);
    match landmarks::map(skel, &rest, &BTreeMap::new()) {
        Ok(Mapping::Found(lm)) => {
            let legs = [
                [lm.left.hip, lm.left.knee, lm.left.ankle],
                [lm.right.hip, lm.right.knee, lm.right.ankle],
            ];
            detect_unit(leg_length(&rest, legs)).0.scale.min(1.0)
        }
        _ => 1.0,
    }
}

// See: issue 15 item 2 — batched SIMD sin/cos with runtime dispatch and a scalar fallback
// identical to 1e-12: on real clips, the same bits on both paths and within 1e-12 m of
// the libm FK.
#[test]
fn simd_fk_equals_the_scalar_fallback_and_the_libm_fk_on_real_clips() {
    let Some(data) = util::shared_or_skip("simd_fk_equals_the_scalar_fallback") else {
        return;
    };
    let roots: Vec<PathBuf> = ["bvh", "bvh-bulk", "forceplate"]
        .map(|d| data.join(d))
        .to_vec();
    let files = discover(&roots).expect("shared clips listed");
    let (mut clips, mut frames, mut worst_m) = (0, 0, 0.0f64);
    for path in &files {
        let Ok(b) = parse_file(path) else {
            continue; // the odd files that do not parse are the reader tests' business
        };
        let skel = Skeleton::from_bvh(&b);
        let (n, np) = (b.motion.n_frames(), skel.n_points());
        let batched: Vec<Vec<[f64; 3]>> = [Simd::Scalar, Simd::Avx2]
            .into_iter()
            .map(|simd| {
                let mut ws = FkWorkspace::new(&skel).with_simd(simd);
                let mut pts = vec![[0.0; 3]; n * np];
                fk::forward_frames(&skel, &mut ws, &b.motion.values, &mut pts);
                pts
            })
            .collect();
        let name = path.display();
        assert!(
            batched[0] == batched[1],
            "{name}: AVX2 and scalar FK differ"
        );
        let scale = metres_per_unit(&skel);
        let mut ws = FkWorkspace::new(&skel);
        let (mut one, mut libm) = (vec![[0.0; 3]; np], vec![[0.0; 3]; np]);
        let mut rot = vec![IDENTITY; skel.n_joints()];
        for f in 0..n {
            let row = b.motion.row(f);
            fk::forward(&skel, &mut ws, row, &mut one);
            assert!(
                one[..] == batched[0][f * np..(f + 1) * np],
                "{name} frame {f}: one frame differs from its batch"
            );
            fk::forward_libm(&skel, &mut rot, row, &mut libm);
            for (p, q) in one.iter().zip(&libm) {
                for k in 0..3 {
                    worst_m = worst_m.max((p[k] - q[k]).abs() * scale);
                }
            }
        }
        clips += 1;
        frames += n;
    }
    eprintln!("{clips} clips, {frames} frames: largest FK difference from libm {worst_m:.1e} m");
    assert!(clips >= 100, "only {clips} shared clips parsed");
    assert!(
        worst_m <= 1e-12,
        "FK moved by {worst_m:e} m from the libm FK"
    );
}
