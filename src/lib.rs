//! # stancelib
//!
//! Turns motion-capture clips (BVH) into a physically grounded stance library.
//!
//! ## Stages
//! ```text
//! bvh (parse) → skeleton (model, FK, landmarks, units, COM) → contacts (floors, flags,
//! flights) → ingest (one clip, pure) → library (Parquet tables) ← cli / pipeline (I/O)
//! ```
//!
//! The method of each stage (equations, units, the papers' numbering and where the tool
//! departs from them) is in the repository's `docs/`. Citations `spec com-from-bvh §N`,
//! `spec stance-model §N` and `spec two-pac §N` in these docs are the numbered sections of
//! `docs/com-from-bvh.md`, `docs/stance-model.md` and `docs/two-pac.md`;
//! `CORRECTIONS Issue N item K` are the entries of `docs/decisions.md`.
//!
//! ## Glossary
//! - **clip**: one BVH file; its name is the file stem (spec com-from-bvh §1.1).
//! - **frame**: one row of the MOTION section; indices are the file's own, also when
//!   lead-in rows are dropped.
//! - **COM**: whole-body centre of mass from the de Leva segment table, metres, Z up.
//! - **contact**: an effector (foot or hand) supported by the ground or a surface.
//! - **flight**: a no-contact run that passes the ballistic test.
//! - **stance**: a contact period between flights (issue 3).
//!
//! Units are SI throughout: metres, seconds, kilograms, newtons; the world frame is
//! right-handed with Z up.
#![warn(missing_docs)]

pub mod bvh;
pub mod cli;
pub mod constraints;
pub mod contacts;
pub mod edit;
pub mod error;
pub mod force_model;
pub mod ingest;
pub mod kinematics;
pub mod library;
pub mod math;
pub mod pipeline;
pub mod plot;
pub mod query;
pub mod skeleton;
pub mod stances;
pub mod synth;
#[cfg(test)]
pub(crate) mod testkit;
pub mod twopac;

pub use error::{Error, ErrorKind, Result};
