//! Command-line interface: validated arguments → one command per subcommand.

pub mod args;
pub mod cmd;

use args::{Cli, Command, EditCommand, MapCommand, PlotCommand, QueryCommand};

/// How a command finished (fatal errors are `Err`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Every input was processed (ok or skipped).
    Clean,
    /// Finished, but some inputs failed (exit code 1).
    SomeFailed,
    /// Every input failed: nothing could be done (exit code 2; the tables still say why).
    AllFailed,
}

/// Run a parsed command line.
///
/// # Errors
/// Fatal errors (bad configuration, unreadable inputs, unwritable output): exit code 2.
pub fn run(cli: Cli) -> anyhow::Result<Outcome> {
    match cli.command {
        Command::Frames(a) => cmd::frames::run(a),
        Command::Run(a) => cmd::run::run(a),
        Command::Build(a) => cmd::build::run(a),
        Command::Merge(a) => cmd::build::run_merge(a),
        Command::Synth(a) => cmd::synth::run(a),
        Command::Query(QueryCommand::Run(a)) => cmd::query::run(a),
        Command::Query(QueryCommand::Jump(a)) => cmd::query::run_jump(a),
        Command::Map(MapCommand::Jumps(a)) => cmd::map::run(a),
        Command::Equilibrium(a) => cmd::equilibrium::run(a),
        Command::Twopac(a) => cmd::twopac::run(a),
        Command::Forces(a) => cmd::forces::run(a),
        Command::Plot(PlotCommand::Stance(a)) => cmd::plot::run_stance(a),
        Command::Edit(EditCommand::Run(a)) => cmd::edit::run(a),
        Command::Edit(EditCommand::Jump(a)) => cmd::edit::run_jump(a),
    }
}
