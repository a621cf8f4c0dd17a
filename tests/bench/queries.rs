//! Query benchmarks (issue 4): candidate evaluations and the 200 × 200 jump map.
//!
//! Run with `cargo bench --bench queries` (`make bench`).
//!
//! - `candidate_evals`: the closed form (`query::solve::solve`, §6.2–§6.5) plus the fast
//!   filters (eq 5, 10, 12) for 1,000 requests on each stance of the shared library, one
//!   thread. Target: at least 20 million evaluations per second per core (CORRECTIONS
//!   Issue 4 item 3).
//! - `jump_map_200`: `query::map::jump_map` over every liftoff/landing pair of one
//!   character of the shared library on a 200 × 200 (u_apex, height) grid, exact checks
//!   included, default rayon pool, no file writing and no PNG. Target: under 1 s on 2 cores.
//!
//! Both load the library built from `../shared/data/bvh` (skipped with a message when
//! `../shared` is absent).
//!
//! # Results
//! Recorded in the issue notes with date and machine (2-core x86_64 sandbox).

use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use stancelib::library::readers::read::read_stances;
use stancelib::pipeline::engine::inputs::discover;
use stancelib::pipeline::engine::streaming::{build_and_write, BuildOptions};
use stancelib::query::feasibility::{approx, relative_limits};
use stancelib::query::map::{jump_map, stance_relative_limits, Axis};
use stancelib::query::pool::Prepared;
use stancelib::query::solve::{solve, Refs, Request};

/// The prepared pool of the shared library, or `None` (with a message) without `../shared`.
fn shared_pool() -> Option<(tempfile::TempDir, Vec<Prepared>)> {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/bvh");
    if !data.is_dir() {
        eprintln!("query benchmarks skipped: ../shared/data/bvh is absent");
        return None;
    }
    let dir = tempfile::tempdir().expect("temp dir");
    let lib = dir.path().join("lib");
    let files = discover(&[data]).expect("shared clips");
    build_and_write(&files, &lib, &BuildOptions::default(), false).expect("build");
    let stances = read_stances(&lib.join("stances.parquet")).expect("stances");
    Some((dir, stances.into_iter().map(Prepared::new).collect()))
}

/// 1,000 requests per stance: its own parameters with the speeds scaled by 0.5–1.5 and the
/// heights moved by ±10 cm (a sweep a query would run).
fn requests(pool: &[Prepared]) -> Vec<(usize, Request)> {
    let mut out = Vec::with_capacity(pool.len() * 1000);
    for (i, p) in pool.iter().enumerate() {
        let q = p.stance.params;
        for n in 0..1000 {
            let k = 0.5 + n as f64 / 1000.0;
            let dz = 0.2 * (n % 10) as f64 / 10.0 - 0.1;
            let req = Request {
                zs: q.zs,
                vs: k * q.vs,
                ze: q.ze + dz,
                ve: k * q.ve,
                vp: q.vp,
                vps: q.vps,
                x: k * q.x,
            };
            out.push((i, req));
        }
    }
    out
}

fn candidate_evals(c: &mut Criterion) {
    let Some((_dir, pool)) = shared_pool() else {
        return;
    };
    let reqs = requests(&pool);
    let limits: Vec<_> = pool
        .iter()
        .map(|p| relative_limits(&p.stance.coef))
        .collect();
    let refs = Refs::default();
    let mut g = c.benchmark_group("candidate_evals");
    g.sample_size(20).measurement_time(Duration::from_secs(10));
    g.throughput(Throughput::Elements(reqs.len() as u64));
    g.bench_function("closed_form_and_filters", |b| {
        b.iter(|| {
            let mut feasible = 0usize;
            for (i, req) in &reqs {
                let p = &pool[*i];
                if let Ok(s) = solve(&p.shape, req, &refs, Some(p.stance.params.t_e)) {
                    let c = &p.stance.coef;
                    feasible += usize::from(approx(c.a_f, c.a_mu, s.beta, &limits[*i]));
                }
            }
            black_box(feasible)
        })
    });
    g.finish();
}

fn jump_map_200(c: &mut Criterion) {
    let Some((_dir, pool)) = shared_pool() else {
        return;
    };
    let heights = Axis {
        start: 0.6,
        stop: 1.6,
        step: 1.0 / 199.0,
    }
    .values();
    let speeds = Axis {
        start: 0.0,
        stop: 5.0,
        step: 5.0 / 199.0,
    }
    .values();
    assert_eq!((heights.len(), speeds.len()), (200, 200));
    let map =
        jump_map(&pool, &heights, &speeds, &stance_relative_limits).expect("within the map limits");
    eprintln!(
        "jump_map_200: {} pairs × 40,000 cells, IoU {:.4}",
        map.pairs.len(),
        map.agreement.iou()
    );
    let mut g = c.benchmark_group("jump_map_200");
    g.sample_size(10).measurement_time(Duration::from_secs(15));
    g.throughput(Throughput::Elements((map.pairs.len() * 40_000) as u64));
    g.bench_function("pairs_cells_exact", |b| {
        b.iter(|| {
            black_box(
                jump_map(&pool, &heights, &speeds, &stance_relative_limits).map(|m| m.agreement),
            )
        })
    });
    g.finish();
}

criterion_group!(benches, candidate_evals, jump_map_200);
criterion_main!(benches);
