//! Library benchmarks (issue 3): a full build of `../shared/data/bvh` (22 clips, 16 MB)
//! into a temporary folder, and 10,000 stances from ingest outputs to stance rows.
//!
//! Run with `cargo bench --bench library` (`make bench`).
//!
//! - `build_shared`: `pipeline::engine::streaming::build_and_write` of every shared clip (ingest, stances,
//!   force fits, coefficients, five Parquet tables and the manifest), wall time with the
//!   default rayon pool. Target: under 2 s on 2 cores. Skipped with a message when
//!   `../shared` is absent.
//! - `stances_10k`: `stances::assemble_clip` on the 120 Hz fixture run (4 stances) 2,500 times:
//!   segmentation, Stage A (spline, DFT, dominant terms), closed-form integrals, coefficient
//!   tables and `H_0`, no I/O (CORRECTIONS issue 3 item 7). Target: under 1 s, one thread.
//!
//! # Results
//! Recorded in the issue notes with date and machine (2-core x86_64 sandbox).

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use stancelib::ingest::{ingest, ClipOutcome, IngestOptions};
use stancelib::pipeline::engine::inputs::discover;
use stancelib::pipeline::engine::streaming::{build_and_write, BuildOptions};
use stancelib::stances::{assemble_clip, StanceOptions};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn build_shared(c: &mut Criterion) {
    let data = root().join("../shared/data/bvh");
    if !data.is_dir() {
        eprintln!("build_shared skipped: ../shared/data/bvh is absent");
        return;
    }
    let files: Vec<PathBuf> = discover(&[data]).expect("shared clips");
    let frames: u64 = files
        .iter()
        .filter_map(|f| stancelib::bvh::parse_file(f).ok())
        .map(|b| b.motion.n_frames() as u64)
        .sum();
    let out = tempfile::tempdir().expect("temp dir");
    let lib = out.path().join("lib");
    let opts = BuildOptions::default();
    let mut g = c.benchmark_group("build_shared");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    g.throughput(Throughput::Elements(frames));
    g.bench_function("22_clips_frames", |b| {
        b.iter(|| black_box(build_and_write(&files, &lib, &opts, false).expect("build")))
    });
    g.finish();
}

fn stances_10k(c: &mut Criterion) {
    let bvh = stancelib::bvh::parse_file(&root().join("fixtures/bvh/run_120hz_m_yup.bvh"))
        .expect("fixture");
    let ClipOutcome::Body {
        summary,
        frames,
        contacts,
    } = ingest(&bvh, &IngestOptions::default()).expect("ingest")
    else {
        panic!("fixture skipped")
    };
    let opts = StanceOptions::default();
    let per_clip = assemble_clip("run", &frames, &summary, &contacts, 70.0, &opts)
        .0
        .len();
    let reps = 10_000 / per_clip.max(1);
    let mut g = c.benchmark_group("stances_10k");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    g.throughput(Throughput::Elements((reps * per_clip) as u64));
    g.bench_function("fit_and_coefficients", |b| {
        b.iter(|| {
            let mut n = 0;
            for _ in 0..reps {
                n += black_box(assemble_clip(
                    "run", &frames, &summary, &contacts, 70.0, &opts,
                ))
                .0
                .len();
            }
            n
        })
    });
    g.finish();
}

criterion_group!(benches, build_shared, stances_10k);
criterion_main!(benches);
