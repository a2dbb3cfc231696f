//! `gesture-sim`: parses the command line and hands it to [`host_sim::cli`].

fn main() -> std::process::ExitCode {
    gesture_trainer::output::remove_temporaries_on_interrupt();
    match gesture_trainer::cli::parse_args::<host_sim::cli::Cli>("gesture-sim") {
        Ok(cli) => host_sim::cli::run(&cli),
        Err(code) => code,
    }
}
