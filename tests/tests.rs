//! The one integration-test binary. Table of contents:
//!
//! - `bad_input`: malformed files name file and line; a 300 MB stream loads.
//! - `bvh_oracle`: differential test of the BVH reader against the `bvh_anim` crate on every
//!   shared clip it reads (f32 precision), and a write-and-reread round trip.
//! - `cli`: the binary end to end: table layout, exit codes, determinism, atomic writes, pipelines.
//! - `force_export`: `forces` (the model on its grid, impulse, norms) and `plot stance` (PNG,
//!   plates of the treadmill run); unknown stances exit 2 and write nothing.
//! - `fixtures`: generated clips equal the generator; ingest recovers their COM, contacts, unit, axis.
//! - `regression`: one test per review finding, named after it.
//! - `stances`: stances of real clips: flights on both sides, impulse–momentum, walks, running forces.
//! - `util`: shared helpers (paths to `../shared`, skip messages, temp dirs, running the binary).
//! - `multicontact`: static (elevated) hand and foot contacts on the climbing clip.
//! - `props`: property tests: mutated and extreme inputs never panic the reader or the ingest.
//! - `readers`: pyarrow and DuckDB open the library (row counts, metadata, values).
//! - `real_data`: every shared BVH loads; flight physics, walk/run contact patterns, invariance.
//! - `forceplate`: contact events and kinematic force against the shared force-plate clips.
//! - `forceplate_stances`: stance force models against the force plates (per stance, per foot).
//! - `stances_truth`: stances of the fixtures against the generator's truth; Parquet round trip.
//! - `twopac`: `equilibrium` and `twopac` on `fixtures/twopac/`: reference margins, boundary
//!   states, transitions inside kinematic boxes, timings.json, bad JSON with its path.
mod bad_input;
mod bvh_oracle;
mod cli;
mod fixtures;
mod force_export;
mod forceplate;
mod forceplate_stances;
mod kinematics;
mod multicontact;
mod props;
mod queries;
mod readers;
mod real_data;
mod regression;
mod stances;
mod stances_truth;
mod twopac;
mod util;
