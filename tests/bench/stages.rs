//! Criterion benchmarks (filled in by the bench commit).
fn main() {}
