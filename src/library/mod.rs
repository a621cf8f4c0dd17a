//! The columnar outputs: one record per input clip, turned into `frames.parquet`,
//! `clips.parquet`, `contacts.parquet` and (optionally) `joints.parquet`, written
//! atomically (temporary name, then rename); `stances.parquet` and the kinematics tables
//! beside them.
//!
//! Three rooms:
//! - [`codec`]: the table codecs: column names and keys (`schema`, the flat registry), each
//!   table to and from Parquet, `manifest.json` and provenance.
//! - [`storage`]: the Parquet engine, whatever the table: streamed row groups, scratch and
//!   spill files, atomic replacement, layouts, one generation per read, integrity.
//! - [`readers`]: what each command reads from a library (`info`, the queries' stance pool,
//!   the plots' clip view, the force exports).
//!
//! # References
//! spec com-from-bvh §8 (column tables); STYLE.md §5.6 (deterministic files).

pub mod codec;
pub mod readers;
pub mod storage;

use crate::ingest::{ClipFrames, ClipSummary, ContactRun};

/// Status of one input file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Ingested.
    Ok,
    /// Not a body, or too short (not a failure).
    Skipped,
    /// Could not be read or mapped (a failure).
    Error,
}

impl Status {
    /// Value of the `status` column.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Skipped => "skipped",
            Status::Error => "error",
        }
    }
}

/// Everything known about one input file after ingest.
#[derive(Debug, Clone, PartialEq)]
pub struct ClipRecord {
    /// The path as given.
    pub path: String,
    /// Clip name (spec com-from-bvh §1.1).
    pub clip: String,
    /// SHA-256 of the file's bytes, hex (empty when unreadable).
    pub content_sha256: String,
    /// Outcome.
    pub status: Status,
    /// Skip reason or error message.
    pub message: Option<String>,
    /// Where an `error` happened: `input`, `parse`, `mapping` or `frames` (`errors.parquet`).
    pub error_stage: Option<&'static str>,
    /// Body mass used, kg.
    pub mass_kg: f64,
    /// Per-clip fields (defaults when the file did not parse).
    pub summary: ClipSummary,
    /// Per-frame table (status `ok` only).
    pub frames: Option<ClipFrames>,
    /// Contact runs (status `ok` only).
    pub contacts: Vec<ContactRun>,
}

impl ClipRecord {
    /// What a streamed run keeps of a written clip (path, name, status, message): the rest
    /// is in its tables. A whole record is about 1 kB even without its frames (its summary
    /// is inline); the 25× replica's build kept 4.4 MB of them at its peak (1.9 kB a clip
    /// with the `Vec`'s spare capacity).
    pub fn written(self) -> ClipStatus {
        ClipStatus {
            path: self.path,
            clip: self.clip,
            status: self.status,
            message: self.message,
        }
    }
}

/// The outcome of one written clip, as a batch run reports it.
#[derive(Debug, Clone, PartialEq)]
pub struct ClipStatus {
    /// The path as given.
    pub path: String,
    /// Clip name.
    pub clip: String,
    /// Outcome.
    pub status: Status,
    /// Skip reason or error message.
    pub message: Option<String>,
}
