//! One module per subcommand.

pub mod build;
pub mod frames;
pub mod run;
pub mod synth;
