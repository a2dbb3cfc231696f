//! `gesture-train`: thin entry point; see `gesture_trainer::cli`.

use clap::Parser;

fn main() {
    let cli = gesture_trainer::cli::Cli::parse();
    if let Err(e) = gesture_trainer::cli::run(cli) {
        eprintln!("gesture-train: {e}");
        std::process::exit(2);
    }
}
