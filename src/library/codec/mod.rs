//! The table codecs: the library's tables, column by column, to and from Parquet. The
//! flat registry of file names, column names and metadata keys ([`schema`]), column
//! builders (`columns`), the per-clip tables ([`mod@write`]), `stances.parquet`
//! ([`stances`]), the kinematics tables ([`kinematics`]), typed reading of any table
//! ([`table`]), `manifest.json` ([`manifest`]) and the provenance outside the tables
//! ([`provenance`]).
//!
//! The files themselves are written and read by [`super::storage`].

pub(crate) mod columns;
pub mod kinematics;
pub mod manifest;
pub mod provenance;
pub mod schema;
pub mod stances;
pub mod table;
pub mod write;
