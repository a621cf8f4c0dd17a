//! Batch orchestration at the I/O edge: input discovery, clip names, per-file ingest in
//! parallel with a progress bar, the streaming library build, shards and their merge, the
//! output-folder policy, the declarative pipeline and body files, the `twopac` stage
//! with its output tables, and a library's catalogue (`list`).

pub mod batch;
pub mod build;
pub mod catalogue;
pub mod edit;
pub mod edit_outputs;
pub mod equilibrium;
pub mod inputs;
pub mod job;
pub mod memory;
pub mod merge;
pub mod names;
pub mod ordered;
pub mod output;
pub mod plots;
pub mod queries;
pub mod shard;
pub(crate) mod sink;
pub mod spec;
pub mod twopac;
pub mod twopac_outputs;
pub mod twopac_tables;
