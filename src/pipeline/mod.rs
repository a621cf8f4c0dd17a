//! Batch orchestration at the I/O edge: input discovery, clip names, per-file ingest in
//! parallel with a progress bar, and the declarative pipeline and body files.

pub mod batch;
pub mod build;
pub mod names;
pub mod spec;
