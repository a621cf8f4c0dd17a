//! Command-line interface: validated arguments → one command per subcommand.

pub mod args;
pub mod cmd;

use std::sync::atomic::{AtomicBool, Ordering};

use args::{Cli, Command, EditCommand, MapCommand, PlotCommand, QueryCommand};

static QUIET: AtomicBool = AtomicBool::new(false);
static JSON: AtomicBool = AtomicBool::new(false);

/// `--quiet`: nothing on stdout, no progress bar; errors still go to stderr.
pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// `--json`: the command's summary as one JSON object on stdout, and nothing else there.
pub fn json() -> bool {
    JSON.load(Ordering::Relaxed)
}

/// Prints a line of a command's human-readable report on stdout, unless `--quiet` or
/// `--json` is given (through [`print_line`]: a closed stdout ends the report quietly).
#[macro_export]
macro_rules! say {
    ($($t:tt)*) => {
        if !$crate::cli::quiet() && !$crate::cli::json() {
            $crate::cli::print_line(format_args!($($t)*));
        }
    };
}

/// Set once stdout is gone (broken pipe) or failed: nothing more is written there.
static STDOUT_DONE: AtomicBool = AtomicBool::new(false);

/// The first failure to write stdout other than a broken pipe (reported by [`run`]).
static STDOUT_ERROR: std::sync::Mutex<Option<std::io::Error>> = std::sync::Mutex::new(None);

/// Writes one line on stdout: the only way the commands print there. When the reader of
/// stdout is gone (`stancelib info LIB | head -1`: a broken pipe) the line and every later
/// one are dropped quietly and the command finishes its work, as ripgrep ends quietly on
/// a broken pipe; the exit code is the command's own (0 when its work succeeded), and
/// outputs it writes to files are still written. Any other write error (a full disk) is
/// kept and makes [`run`] fail with it once the command is done. Control characters
/// other than line breaks and tabs (an ESC from a clip name or a character id) are
/// written escaped ([`crate::error::escape_but`]): nothing read from data reaches the
/// terminal as a control sequence.
pub fn print_line(args: std::fmt::Arguments<'_>) {
    use std::io::Write;
    if STDOUT_DONE.load(Ordering::Relaxed) || !crate::library::storage::generation::before_print() {
        return;
    }
    let line = crate::error::escape_but(&args.to_string(), &['\n', '\t']);
    let mut out = std::io::stdout().lock();
    if let Err(e) = out
        .write_fmt(format_args!("{line}\n"))
        .and_then(|()| out.flush())
    {
        STDOUT_DONE.store(true, Ordering::Relaxed);
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            if let Ok(mut first) = STDOUT_ERROR.lock() {
                first.get_or_insert(e);
            }
        }
    }
}

/// Prints `summary` on stdout as one line of JSON when `--json` is given (and not
/// `--quiet`).
pub fn summary_json(summary: &serde_json::Value) {
    if json() && !quiet() {
        print_line(format_args!("{summary}"));
    }
}

/// How a command finished (fatal errors are `Err`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Every input was processed (ok or skipped).
    Clean,
    /// Finished, but some inputs failed (exit code 1).
    SomeFailed,
    /// Every input failed: nothing could be done (exit code 2; the tables still say why).
    AllFailed,
    /// Written, but the result breaks a constraint (exit code 3: an edit with
    /// `--allow-infeasible`).
    Infeasible,
}

/// Run a parsed command line.
///
/// # Errors
/// Fatal errors (bad configuration, unreadable inputs, unwritable output): exit code 2.
/// Stdout that cannot be written for another reason than a broken pipe is one of them
/// ([`print_line`]).
pub fn run(cli: Cli) -> anyhow::Result<Outcome> {
    QUIET.store(cli.quiet, Ordering::Relaxed);
    JSON.store(cli.json, Ordering::Relaxed);
    crate::pipeline::engine::batch::set_progress(!cli.quiet);
    let outcome = dispatch(cli.command)?;
    match STDOUT_ERROR.lock().ok().and_then(|mut e| e.take()) {
        Some(e) => Err(anyhow::Error::new(e).context("cannot write to stdout")),
        None => Ok(outcome),
    }
}

/// Run one command. The commands that read a library read one generation of it
/// ([`read_consistently`]).
fn dispatch(command: Command) -> anyhow::Result<Outcome> {
    use crate::library::storage::generation::read_consistently;
    fn on<A: Clone>(
        lib: &std::path::Path,
        a: A,
        run: fn(A) -> anyhow::Result<Outcome>,
    ) -> anyhow::Result<Outcome> {
        read_consistently(lib, || run(a.clone()))
    }
    match command {
        Command::Info(a) => on(&a.lib.clone(), a, cmd::info::run),
        Command::List(a) => on(&a.lib.clone(), a, cmd::list::run),
        Command::Frames(a) => cmd::frames::run(a),
        Command::Run(a) => cmd::run::run(a),
        Command::Build(a) => cmd::build::run(a),
        Command::Merge(a) => cmd::build::run_merge(a),
        Command::Synth(a) => cmd::synth::run(a),
        Command::Query(QueryCommand::Run(a)) => on(&a.lib.clone(), a, cmd::query::run),
        Command::Query(QueryCommand::Jump(a)) => on(&a.lib.clone(), a, cmd::query::run_jump),
        Command::Map(MapCommand::Jumps(a)) => on(&a.lib.clone(), a, cmd::map::run),
        Command::Equilibrium(a) => cmd::equilibrium::run(a),
        // With `--lib` it reads the library's polytopes and clips: one generation of it.
        Command::Twopac(a) => match a.lib.clone() {
            Some(lib) => on(&lib, a, cmd::twopac::run),
            None => cmd::twopac::run(a),
        },
        Command::Forces(a) => on(&a.lib.clone(), a, cmd::forces::run),
        Command::Plot(PlotCommand::Stance(a)) => on(&a.lib.clone(), a, cmd::plot::run_stance),
        Command::Edit(EditCommand::Run(a)) => on(&a.common.lib.clone(), a, cmd::edit::run),
        Command::Edit(EditCommand::Jump(a)) => on(&a.common.lib.clone(), a, cmd::edit::run_jump),
        Command::Plot(PlotCommand::Clip(a)) => on(&a.lib.clone(), a, cmd::plot::run_clip),
    }
}
