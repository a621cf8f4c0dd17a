//! `stancelib`: thin entry point. Parse arguments, run, map the outcome to an exit code
//! (0 ok, 1 finished with per-clip failures, 2 fatal or every clip failed, 3 an infeasible
//! edit written with `--allow-infeasible`).
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = stancelib::cli::args::parse();
    match stancelib::cli::run(args) {
        Ok(stancelib::cli::Outcome::Clean) => ExitCode::SUCCESS,
        Ok(stancelib::cli::Outcome::SomeFailed) => ExitCode::from(1),
        Ok(stancelib::cli::Outcome::AllFailed) => ExitCode::from(2),
        Ok(stancelib::cli::Outcome::Infeasible) => ExitCode::from(3),
        Err(e) => {
            let msg = stancelib::error::escape_but(&format!("{e:#}"), &['\n', '\t']);
            eprintln!("stancelib: error: {msg}");
            ExitCode::from(2)
        }
    }
}
