//! `gesture-train`: thin entry point; see `gesture_trainer::cli`.

use std::process::ExitCode;

fn main() -> ExitCode {
    // Ctrl-C: no half-written temporary file stays behind (gesture_trainer::output).
    let _ = ctrlc::set_handler(|| {
        gesture_trainer::output::remove_temporaries();
        std::process::exit(130);
    });
    let cli = match gesture_trainer::cli::parse_args::<gesture_trainer::cli::Cli>("gesture-train") {
        Ok(c) => c,
        Err(code) => return code,
    };
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
