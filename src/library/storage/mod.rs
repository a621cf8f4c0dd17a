//! The Parquet engine under the library: how its files are written, laid out and read
//! back, whatever table they hold. Streamed writing one row group at a time ([`stream`]),
//! row groups moved between files ([`row_groups`], [`group_reader`], `footer`),
//! scratch files and spilled samples ([`scratch`], [`spill`]), atomic replacement
//! ([`atomic`]), the two folder layouts ([`layout`]), one generation per read
//! ([`generation`]) and the content check of a finished library ([`integrity`]).
//!
//! The column names and the table codecs are in [`super::codec`]; what each command reads
//! is in [`super::readers`].

pub mod atomic;
pub(crate) mod footer;
pub mod generation;
pub mod group_reader;
pub mod integrity;
pub mod layout;
pub mod row_groups;
pub mod scratch;
pub mod spill;
pub mod stream;
