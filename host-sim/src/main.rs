//! `gesture-sim`: parses the command line and hands it to [`host_sim::cli`].

fn main() -> std::process::ExitCode {
    // Ctrl-C: no half-written temporary file stays behind (gesture_trainer::output).
    let _ = ctrlc::set_handler(|| {
        gesture_trainer::output::remove_temporaries();
        std::process::exit(130);
    });
    match gesture_trainer::cli::parse_args::<host_sim::cli::Cli>("gesture-sim") {
        Ok(cli) => host_sim::cli::run(&cli),
        Err(code) => code,
    }
}
