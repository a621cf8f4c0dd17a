//! Queries on the stance library: closed-form stance scaling and its feasibility.
//!
//! Modules: [`solve`] (spec stance-model §6.1–§6.5: β and event times from six stance
//! parameters, degenerate branches, admissibility and root choice) and [`feasibility`]
//! (§7.3 fast filters, §7.4 exact sampled check, §8.3 closed-form contact point, §7.5
//! relative limits). The `query` and `map` commands that use them are not built yet.
//!
//! # Frames and units
//! Stance frame (h, p, v), SI units; heights above the contact height `z_c`.

pub mod feasibility;
pub mod solve;
