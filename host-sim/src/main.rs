//! `gesture-sim`: parses the command line and hands it to [`host_sim::cli`].

use clap::Parser;

fn main() -> std::process::ExitCode {
    host_sim::cli::run(&host_sim::cli::Cli::parse())
}
