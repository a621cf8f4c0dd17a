//! The build engine: input discovery and side-file reading, clip names, per-file ingest
//! in parallel with a progress bar, the streaming library build and its sink, shards and
//! their merge, and the output-folder policy. Typed errors only ([`crate::Error`]); the
//! commands above ([`super::commands`]) add their context.

pub mod batch;
pub(crate) mod cursor;
pub mod inputs;
pub mod memory;
pub mod merge;
pub mod names;
pub mod ordered;
pub mod output;
pub mod shard;
pub(crate) mod sink;
pub mod streaming;
pub mod tables;
