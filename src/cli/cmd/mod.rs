//! One module per subcommand.

pub mod build;
pub mod edit;
pub mod equilibrium;
pub mod forces;
pub mod frames;
pub mod info;
pub mod list;
pub mod map;
pub mod plot;
pub mod query;
pub mod run;
pub mod synth;
pub mod twopac;
