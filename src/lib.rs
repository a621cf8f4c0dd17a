//! # stancelib
//!
//! Turns motion-capture clips (BVH) into a physically grounded stance library.
//!
//! ## Stages
//! The whole crate, data left to right; `math` (constants, 3-vectors, SG, fits, heading) serves
//! every stage, and only `bvh`, `library`, `pipeline` and `cli` touch files.
//! ```text
//!            ┌──────────────────────────── ingest (one clip, pure) ─────────────────────────┐
//! BVH ─ bvh ─┤ skeleton (model, landmarks, units, FK, COM)                                  │
//!   (parse)  │   → contacts::tracks → contacts::detect → contacts::runs_and_flights          │
//!            └─ ClipFrames, ClipSummary (flights), ContactRun ──────────────────────────────┘
//!                 │
//!                 ├─ stances path:  stances (segment, assemble_clip)
//!                 │                   → force_model (fit per stance) → constraints (grids, coefficients)
//!                 │                   → library (stances.parquet, frames, contacts, clips, errors)
//!                 │                   → query (solve, feasibility, run, jump, map)
//!                 │                   → edit (select, plan, COM path, pose) → bvh::write (edited clip)
//!                 │
//!                 └─ twopac path:   twopac::limb_reach (polytopes from contact samples)
//!                                     → library (kinematics.parquet); twopac::clip (phases
//!                                     from a clip's contact runs) or a phases JSON → twopac
//!                                     (contacts, static region, transitions, trajectory,
//!                                     validation)
//!
//! pipeline drives the stages and writes their outputs, in three rooms: pipeline::engine
//! (batch ingest in parallel, inputs, the streaming build, shards and merge; typed errors),
//! pipeline::commands (one stage per command from typed options: queries, edit,
//! equilibrium, twopac, plots, catalogue; anyhow at that edge) and the configuration
//! (pipeline::spec, pipeline::job). library keeps the tables in three rooms as well:
//! library::codec (column names, each table to and from Parquet, the manifest),
//! library::storage (the Parquet engine: streamed row groups, spill, atomic writes,
//! layouts) and library::readers (what each command reads). cli only parses arguments into
//! those options, delegates and prints. plot draws PNGs of the results; synth makes clips
//! with known truth for the tests. Imports go one way: no circle between files or
//! top-level modules (`tests/source_layout.rs`).
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
//! - **stance**: a contact period between flights (issue 3); one clip's stances are
//!   *assembled* (`stances::assemble`).
//! - **build**: the `build` command and its streaming engine (`pipeline::engine`).
//! - **table**: a Parquet table of a library or of a command's output (`library::codec`);
//!   a stance's functions sampled on its grid are its *grids* (`constraints::grids`).
//! - **limits**: the physical limits a query checks (μ, `F_max`, χ: `stances::limits`,
//!   `query::limits`); the documented bounds on the work an input may ask for are *caps*
//!   (the `MAX_*` constants, `ErrorKind::Cap`).
//! - **kinematics**: the `kinematics.parquet` table of kinematic polytopes and its codec
//!   (`library::codec::kinematics`); forward kinematics is `skeleton::fk`, and
//!   `twopac::limb_reach` builds the polytopes.
//! - **reference**: the edit's time-warped source recording (`edit::pose::reference`); the
//!   FK the SIMD path is checked against is `skeleton::fk::forward_libm`.
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
