//! Moved: the query outputs' tables live in [`crate::query::tables`] (the query module owns
//! its codec; `library` does not depend on `query`). This re-export remains only until
//! `edit/plan.rs` imports `violation_name` from there; then this file goes.

pub use crate::query::tables::violation_name;
