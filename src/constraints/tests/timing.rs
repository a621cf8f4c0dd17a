//! Per-stance cost of the full precompute (run with `--release -- --ignored`).

use super::{random_context, random_model, Rng};
use crate::constraints::{precompute_with, PrecomputeOptions, SampledTables};
use std::time::Instant;

#[test]
#[ignore = "timing; meaningful only in release"]
fn ten_thousand_stances_precompute_quickly() {
    let mut rng = Rng::new(99);
    let stances: Vec<_> = (0..10_000)
        .map(|_| (random_model(&mut rng), random_context(&mut rng)))
        .collect();
    let (opts, mut tables) = (PrecomputeOptions::default(), SampledTables::default());
    let start = Instant::now();
    let mut checksum = 0.0;
    for (model, ctx) in &stances {
        checksum += precompute_with(model, ctx, &opts, &mut tables).ext_max;
    }
    let elapsed = start.elapsed().as_secs_f64();
    println!("10,000 stances: {elapsed:.3} s ({checksum:.3})");
    // Target (issue 3 item 7): well under 1 s in release, one thread.
    assert!(elapsed < 1.0, "{elapsed} s");
}
