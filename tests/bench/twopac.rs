//! 2PAC benchmarks (issue 5, spec two-pac §8.1), on the committed fixtures.
//!
//! Run with `cargo bench --bench twopac` (`make bench`).
//!
//! - `hrep_ring_scene`: the H-representation `A c ≤ a` of the static COM region of the
//!   6-rectangle ring scene (`fixtures/twopac/ring_contacts.json`, 24 points, 96
//!   generators, zero acceleration). Target: under 0.5 ms.
//! - `transition_qp_eq6`: one eq 6 transition QP (H-rep precomputed) between the double
//!   support and the next single support of `fixtures/twopac/walk_flat.json`. Target:
//!   under 5 µs median.
//! - `trajectory_10_phases`: the whole 10-phase plan of `walk_flat.json` from raw contacts
//!   (phase states, 9 transitions, Bezier windows, switch parameters), no validation.
//!   Target: under 2 ms.
//!
//! # Results
//! Recorded in the issue notes with date and machine (2-core x86_64 sandbox).

use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use stancelib::twopac::bezier::ComState;
use stancelib::twopac::contact::contact_points;
use stancelib::twopac::phases::{parse_contacts, parse_phases};
use stancelib::twopac::region::{static_region, RegionOptions};
use stancelib::twopac::trajectory::{plan, Phase, PlanOptions};
use stancelib::twopac::transition::{transition_eq6, TransitionOptions};

fn fixture(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/twopac")
        .join(name);
    std::fs::read_to_string(p).expect("fixture")
}

fn walk() -> (Vec<Phase>, f64, ComState) {
    let file = parse_phases(&fixture("walk_flat.json")).expect("walk_flat.json");
    let phases = file.to_phases(&|_| None).expect("inline polytopes");
    (phases, file.mass_kg, file.start)
}

fn hrep_ring_scene(c: &mut Criterion) {
    let ring = parse_contacts(&fixture("ring_contacts.json")).expect("ring_contacts.json");
    let points = contact_points(&ring.contacts);
    let opts = RegionOptions::default();
    let mut g = c.benchmark_group("twopac");
    g.measurement_time(Duration::from_secs(5));
    g.bench_function("hrep_ring_scene", |b| {
        b.iter(|| black_box(static_region(&points, &opts).expect("region")))
    });
    g.finish();
}

fn transition_qp_eq6(c: &mut Criterion) {
    let (phases, _, _) = walk();
    // Phase 0 (double support) → phase 1: statics of phase 1, kinematics of both.
    let statics = static_region(
        &contact_points(&phases[1].contacts),
        &RegionOptions::default(),
    )
    .expect("region");
    let kin = phases[0].polytope().stacked(&phases[1].polytope());
    let start = phases[0].com.unwrap_or([0.0; 3]);
    let opts = TransitionOptions::default();
    let mut g = c.benchmark_group("twopac");
    g.measurement_time(Duration::from_secs(5));
    g.bench_function("transition_qp_eq6", |b| {
        b.iter(|| black_box(transition_eq6(&statics, false, &kin, start, &opts).expect("qp")))
    });
    g.finish();
}

fn trajectory_10_phases(c: &mut Criterion) {
    let (phases, mass, start) = walk();
    assert_eq!(phases.len(), 10, "walk_flat.json has 10 phases");
    let opts = PlanOptions::default();
    let mut g = c.benchmark_group("twopac");
    g.measurement_time(Duration::from_secs(5));
    g.bench_function("trajectory_10_phases", |b| {
        b.iter(|| black_box(plan(&phases, mass, &start, &opts).expect("plan")))
    });
    g.finish();
}

criterion_group!(
    benches,
    hrep_ring_scene,
    transition_qp_eq6,
    trajectory_10_phases
);
criterion_main!(benches);
