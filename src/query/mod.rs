//! Queries on the stance library: closed-form stance scaling, its feasibility, and the
//! run, jump and map queries built on them.
//!
//! Data flow: `library::readers::read::open_library` → [`pool::PoolStance`] (one library row) →
//! [`pool::Prepared`] (tables built once) → [`solve`] (spec stance-model §6.1–§6.5) →
//! [`feasibility`] (§7.3 filters, §7.4 exact check, §8.3 contact point, §7.5 limits) →
//! [`run`] (§6.8 run at speed v, §9 new characters).
//!
//! # Frames and units
//! Stance frame (h, p, v), SI units; heights above the contact height `z_c`.

pub mod feasibility;
pub mod gait;
pub mod jump;
pub mod limits;
pub mod map;
pub mod pairs;
pub mod pool;
pub mod run;
pub mod solve;
pub mod tables;

#[cfg(test)]
pub(crate) mod testkit;
