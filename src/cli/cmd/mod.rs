//! One module per subcommand.

pub mod frames;
pub mod run;
pub mod synth;
