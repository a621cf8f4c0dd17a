//! Batch orchestration at the I/O edge, in three rooms:
//! - [`engine`]: the build engine (inputs, batch ingest, the streaming build, shards and
//!   merge, the output-folder policy), with typed errors;
//! - [`commands`]: one stage per command (queries, edit, equilibrium, twopac, plots,
//!   catalogue, and the entries of `frames`, `build` and `run`), `anyhow` at that edge;
//! - the configuration: [`spec`] (pipeline and body files, parsed) and [`job`] (a pipeline
//!   file resolved into a build and its query stages).

pub mod commands;
pub mod engine;
pub mod job;
pub mod spec;
