//! The one integration-test binary. Table of contents, by stage (a module per line; the
//! `mod` lines below follow the same order). Tests that read `../shared/data` go through
//! `util::shared_or_skip`: in CI (`CI=true`) a missing folder fails them, elsewhere they
//! skip with a `SKIPPED` line that `cargo test` shows (see `util::skip_or_fail`).
//!
//! # Reading BVH
//! - `bvh_oracle`: differential test of the BVH reader against the `bvh_anim` crate on every
//!   shared clip it reads (f32 precision), and a write-and-reread round trip.
//! - `bad_input`: malformed files name file and line; a 300 MB stream loads.
//! - `props`: property tests: mutated and extreme inputs never panic the reader or the ingest.
//!
//! # Ingest: skeleton, COM, contacts
//! - `fixtures`: generated clips equal the generator; ingest recovers their COM, contacts, unit, axis.
//! - `real_data`: every shared BVH loads; flight physics, walk/run contact patterns.
//! - `invariance`: translating and turning a real clip moves its COM alike, contacts unchanged.
//! - `contacts_physics`: sub-frame contact events against the plates, no non-ballistic
//!   no-contact interval on real clips, a stance on a platform, a skeleton without a head.
//! - `held_out_jumps`: issue 39 item 4 — real jumps rewritten Z-up, in inches, without End
//!   Sites or toe joints: landings within a frame of the COM's deceleration and the plates,
//!   no contact at an apex, flights within 3 m/s² of −g.
//! - `multicontact`: static (elevated) hand and foot contacts on the climbing clip.
//! - `forceplate`: contact events and kinematic force against the shared force-plate clips.
//!
//! # Stances and force models
//! - `stances`: stances of real clips: flights on both sides, impulse–momentum, walks, running forces.
//! - `stances_truth`: stances of the fixtures against the generator's truth (segmentation,
//!   the six parameters against the exact flights).
//! - `force_truth`: Stage A force models of the fixtures against the true applied force;
//!   the force model's Parquet round trip.
//! - `forceplate_stances`: stance force models against the force plates (per stance, per foot).
//! - `per_contact`: issue 39 item 3 — walking contact timing against the plates (ratios
//!   chosen leaving one walk out), `forces --per-contact` per foot against each foot's
//!   plate on the walks, its Parquet/CSV/`.mot` outputs and refusals.
//!
//! # Library: tables, readers, scale
//! - `golden`: issue 13 — the demo job's outputs equal `fixtures/golden/demo/` (library
//!   Parquet byte for byte, manifest without volatile fields, query outputs by content).
//! - `readers`: pyarrow and DuckDB open the library (row counts, metadata, values).
//! - `force_export`: `forces` (the model on its grid, impulse, norms) and `plot stance` (PNG,
//!   plates of the treadmill run); unknown stances exit 2 and write nothing.
//! - `scale`: issue 16 — streaming build (any batch size and thread count), `--shard I/N`
//!   and `merge` equal to one build byte for byte, merge refusals, the Spark driver.
//! - `dataset`: issue 16 item 3 — `--layout dataset`: the same tables and query outputs as
//!   the file layout, merges and incremental builds of it, and DuckDB, pyarrow, polars and
//!   Spark reading one character's partition (pruned).
//! - `scale_memory`: issue 16 items 1–2 — kinematic samples spilled to disk, not held:
//!   no scratch left behind, shards whose samples span several row groups merge exactly.
//!
//! # Queries
//! - `queries`: the run-at-speed sweep, recorded jumps feasible as recorded, the jump map and
//!   the issue 12 targets on the libraries of the shared clips.
//! - `run_predictions`: issue 37 — `query run` from each force-plate run to every speed the
//!   same runner ran, against that runner's plates (contact time, step period, peak force, μ).
//!
//! # 2PAC: kinematics and trajectories
//! - `kinematics`: kinematic polytopes of the shared clips hold their points, the COM sits
//!   above the feet, the tables read back.
//! - `twopac`: `equilibrium` and `twopac` on `fixtures/twopac/`: reference margins, boundary
//!   states, transitions inside kinematic boxes, timings.json, bad JSON with its path.
//!
//! # Edited motion
//! - `edit_checks`: issue 14 — the remaining checks: a jump higher than recorded lifts off and
//!   lands on time on its toes, every frame converged; a real run's support foot holds still.
//!   Issue 37 item 5 — edited runs have the query's contact time and cadence and stay in the
//!   recorded posture; higher jumps keep bent knees in flight, no root spike. Issue 38 item
//!   1 — edits print verdict, deciding constraint, cycle or pair, and exit by the verdict.
//! - `edit_motion`: issue 14 — `edit run`/`edit jump` BVH re-ingested: COM on the plan,
//!   planted feet, contact timing, speed, jump apex, flight curvature, joint steps, identity.
//!
//! # Command line and documentation
//! - `cli`: the binary end to end: table layout, exit codes, determinism, atomic writes, pipelines.
//! - `documentation`: issue 17 — the README's demo commands run and answer with numbers (issue 38
//!   item 6), the README has at most 300 lines, `docs/first-hour.md` runs as written and
//!   reaches its answers, `docs/tables.md` is the written schemas; manifest date and
//!   command line, query outputs naming their library, `info`, negative numbers, `--help`
//!   limits, `--quiet` and `--json`.
//! - `catalogue`: issue 38 item 2 — `list`: characters, run cycles (against `query run`), jumps.
//! - `duplicates`: issue 38 item 3 — copied clips reported by `info` and answering once;
//!   clips a query leaves out named, `--keep-left-out`.
//! - `masses`: issue 38 item 4 — `--masses` (and the pipeline key): a mass per clip in
//!   `clips.parquet` and `info`, the default mass a warning, bad tables refused.
//! - `pictures`: issue 38 item 5 — every picture kind written by its command of
//!   `docs/pictures.md`, its example there, small.
//!
//! # Safety (issue 11)
//! - `safety_inputs`: reader and numeric items: SG window bound, no silent NaN, 100k-joint
//!   and 100k-deep files, and the mutation fuzzer (bounded; `make fuzz` runs it for a time budget).
//! - `safety_messages`: escaped short error messages, the line bound, CR-only and empty files.
//! - `safety_caps`: item 6: every documented work cap refused before work (exit 2,
//!   field and cap named).
//! - `safety_numbers`: issue 40 item 5: implausible segments, non-finite stance rows and
//!   out-of-bound 2PAC inputs are errors, never inf or NaN written with status ok.
//! - `safety_options`: items 10–12: pipelines validated before the library is touched, no
//!   option accepted and ignored, duplicate JSON/TOML keys refused.
//! - `safety_outputs`: `--out` never destroys what the tool did not write; input links,
//!   cycles and special files; per-input errors; stale temporaries; the build lock.
//! - `safety_reuse`: issue 40 items 1, 4, 7: incremental builds and merges check what they
//!   reuse against the manifest's content hashes and rows per clip; `frames` never writes into a library.
//! - `safety_side_inputs`: issue 40 items 2, 3, 8, 10: side inputs as BVH inputs, clip budget, closed stdout, atomic `synth`.
//! - `safety_work`: issue 40 item 6: limits sized by work (equilibrium contacts × states,
//!   edit frames × joints, pipeline globs), refused before the work.
//! - `safety_swap`: issue 40 item 9: reads during rebuilds answer from one generation of
//!   the library or say that it changed.
//! - `safety_names`: issue 40 item 11: merge mismatches by key, echoed input cut, data
//!   escaped on the terminal, "rebuild" for old layouts, injective file names, `--pair`
//!   with `:` in clip names, the manifest read bounded.
//!
//! # Structure (issues 13, 41)
//! - `cli_options`: issue 13 items 2–3 — enumerated options parsed (any case) and refused
//!   before work; outputs of every kind leave no temporary behind.
//! - `stage_entry_points`: issue 13 items 1, 4 — the contact stage's entry points give the
//!   ingest's contacts; batch ingest errors keep their kind.
//! - `source_layout`: issue 41 — no import circle between files or top-level modules of
//!   `src/`, no file over 800 lines but the registries, no `anyhow` in the build engine.
//!
//! # Speed (issue 15)
//! - `speed`: the batched SIMD FK equals its scalar fallback bit for bit and the libm FK to
//!   1e-12 m on the shared clips.
//!
//! # Regressions and helpers
//! - `regression`: one test per review finding, named after it.
//! - `util`: shared helpers: the shared-data gate and skips, fixtures and their library, the
//!   demo folder, running the binary, manifests without volatile fields, file snapshots.

// Reading BVH
mod bad_input;
mod bvh_oracle;
mod props;
// Ingest
mod contacts_physics;
mod fixtures;
mod forceplate;
mod held_out_jumps;
mod invariance;
mod multicontact;
mod real_data;
// Stances and force models
mod force_truth;
mod forceplate_stances;
mod per_contact;
mod stances;
mod stances_truth;
// Library
mod dataset;
mod force_export;
mod golden;
mod readers;
mod scale;
mod scale_memory;
// Queries
mod queries;
mod run_predictions;
// 2PAC
mod kinematics;
mod twopac;
// Edited motion
mod edit_checks;
mod edit_motion;
// Command line and documentation
mod catalogue;
mod cli;
mod documentation;
mod duplicates;
mod masses;
mod pictures;
mod verdicts;
// Safety
mod safety_caps;
mod safety_inputs;
mod safety_messages;
mod safety_names;
mod safety_numbers;
mod safety_options;
mod safety_outputs;
mod safety_reuse;
mod safety_side_inputs;
mod safety_swap;
mod safety_work;
// Structure (issues 13, 41)
mod cli_options;
mod source_layout;
mod stage_entry_points;
// Speed (issue 15)
mod speed;
// Regressions and helpers
mod regression;
mod util;
