//! Batch orchestration at the I/O edge: input discovery, clip names, per-file ingest in
//! parallel with a progress bar, the output-folder policy, and the declarative pipeline
//! and body files.

pub mod batch;
pub mod build;
pub mod inputs;
pub mod names;
pub mod output;
pub mod spec;
