//! The one integration-test binary. Table of contents:
//!
//! - `analyst`: issue 17 — the README's demo commands run and its column tables are the
//!   written schemas; manifest date and command line, query outputs naming their library,
//!   `info`, negative numbers, `--help` limits, `--quiet` and `--json`.
//! - `bad_input`: malformed files name file and line; a 300 MB stream loads.
//! - `bvh_oracle`: differential test of the BVH reader against the `bvh_anim` crate on every
//!   shared clip it reads (f32 precision), and a write-and-reread round trip.
//! - `contacts_physics`: sub-frame contact events against the plates, no non-ballistic
//!   no-contact interval on real clips, a stance on a platform, a skeleton without a head.
//! - `cli`: the binary end to end: table layout, exit codes, determinism, atomic writes, pipelines.
//! - `force_export`: `forces` (the model on its grid, impulse, norms) and `plot stance` (PNG,
//!   plates of the treadmill run); unknown stances exit 2 and write nothing.
//! - `edit_motion`: issue 14 — `edit run`/`edit jump` BVH re-ingested: COM on the plan,
//!   planted feet, contact timing, speed, jump apex, flight curvature, joint steps, identity.
//! - `fixtures`: generated clips equal the generator; ingest recovers their COM, contacts, unit, axis.
//! - `regression`: one test per review finding, named after it.
//! - `safety_outputs`: issue 11 — `--out` never destroys what the tool did not write; input
//!   links, cycles and special files; per-input errors; stale temporaries; the build lock.
//! - `stances`: stances of real clips: flights on both sides, impulse–momentum, walks, running forces.
//! - `util`: shared helpers (paths to `../shared`, skip messages, temp dirs, running the binary).
//! - `multicontact`: static (elevated) hand and foot contacts on the climbing clip.
//! - `props`: property tests: mutated and extreme inputs never panic the reader or the ingest.
//! - `readers`: pyarrow and DuckDB open the library (row counts, metadata, values).
//! - `safety_inputs`: issue 11 reader and numeric items: SG window bound, no silent NaN,
//!   100k-joint and 100k-deep files, escaped short messages, line bound, CR-only files, and
//!   the mutation fuzzer (bounded; `make fuzz` runs it for a time budget).
//! - `real_data`: every shared BVH loads; flight physics, walk/run contact patterns, invariance.
//! - `forceplate`: contact events and kinematic force against the shared force-plate clips.
//! - `forceplate_stances`: stance force models against the force plates (per stance, per foot).
//! - `stances_truth`: stances of the fixtures against the generator's truth; Parquet round trip.
//! - `scale`: issue 16 — streaming build (any batch size and thread count), `--shard I/N`
//!   and `merge` equal to one build byte for byte, merge refusals, the Spark driver.
//! - `safety_limits`: issue 11 items 6, 10, 11, 12: every documented work limit refused
//!   before work (exit 2, field and limit named), pipelines validated before the library
//!   is touched, no option accepted and ignored, duplicate JSON/TOML keys refused.
//! - `structure_stages`: issue 13 items 1, 4 — the contact stage's entry points give the
//!   ingest's contacts; a per-clip ingest error keeps its kind (not "skeleton").
//! - `twopac`: `equilibrium` and `twopac` on `fixtures/twopac/`: reference margins, boundary
//!   states, transitions inside kinematic boxes, timings.json, bad JSON with its path.
mod analyst;
mod bad_input;
mod bvh_oracle;
mod cli;
mod contacts_physics;
mod edit_motion;
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
mod safety_inputs;
mod safety_limits;
mod safety_outputs;
mod scale;
mod stances;
mod stances_truth;
mod structure_stages;
mod twopac;
mod util;
