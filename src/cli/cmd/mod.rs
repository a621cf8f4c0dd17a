//! One module per subcommand.

pub mod build;
pub mod equilibrium;
pub mod frames;
pub mod map;
pub mod query;
pub mod run;
pub mod synth;
pub mod twopac;
