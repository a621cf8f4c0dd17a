//! What each command reads from a library: the stances and a library's summary for the
//! queries and `info` ([`read`], [`info`]), one clip's frames and stances for the plots
//! ([`clip_view`]), and the force exports of `forces` ([`forces`], [`per_contact`]).
//!
//! They read through [`super::codec`] (column names, typed tables) and never write a
//! library.

pub mod clip_view;
pub mod forces;
pub mod info;
pub mod per_contact;
#[doc(hidden)]
pub mod read;
