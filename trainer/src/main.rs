//! `gesture-train`: thin entry point; see `gesture_trainer::cli`.

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = gesture_trainer::cli::Cli::parse();
    match gesture_trainer::cli::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if !matches!(e, gesture_trainer::cli::CliError::BrokenPipe) {
                eprintln!("gesture-train: {e}");
            }
            ExitCode::from(e.exit_code())
        }
    }
}
