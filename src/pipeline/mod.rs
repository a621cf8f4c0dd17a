//! Batch orchestration at the I/O edge: input discovery, clip names, per-file ingest in
//! parallel with a progress bar, the streaming library build, shards and their merge, the
//! output-folder policy, and the declarative pipeline and body files.

pub mod batch;
pub mod build;
pub mod inputs;
pub mod merge;
pub mod names;
pub mod output;
pub mod shard;
pub(crate) mod sink;
pub mod spec;
