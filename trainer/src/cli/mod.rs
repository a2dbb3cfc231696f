//! The `gesture-train` command line, and nothing else: each command's flags (clap) are
//! checked into the library's settings ([`args`]), the library does the work, and the result
//! is printed. Every command prints what it did to stdout and progress to stderr; an error is
//! one line on stderr and an exit status ([`CliError::exit_code`]: 2 bad input, 1 failure).
//! Output goes through `outln!`, which turns a closed stdout (`gesture-train ... | head`)
//! into a quiet [`CliError::BrokenPipe`] instead of a panic.

/// `println!` that returns a `Result` (see [`exit::write_line`]).
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::cli::exit::write_line(format_args!($($arg)*))
    };
}

pub mod args;
pub mod eval_inference;
pub mod eval_motion;
pub mod eval_style;
pub mod exit;
pub mod fit;
pub mod inspect;
pub mod pack;
mod stats;
mod synth;

use clap::{Parser, Subcommand};

pub use exit::{CliError, ExitKind};

/// Learns gesture controllers from motion capture with speech (BVH + WAV).
#[derive(Debug, Parser)]
#[command(name = "gesture-train", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Generate a synthetic speech+motion corpus with planted truth (truth.json).
    Synth(synth::SynthArgs),
    /// Summarize a corpus: durations, segments, kinematics, syllables per file.
    CorpusStats(stats::StatsArgs),
    /// Train the inference layer (HMM, prosody mixture, CRF) and write the model file.
    Fit(fit::FitArgs),
    /// Compare CRF, remapped HMM and prior on held-out data (the paper's Fig. 4).
    EvalInference(eval_inference::EvalArgs),
    /// Pack a model, a gesture library and a rig into a policy blob.
    Pack(pack::PackArgs),
    /// Motion quality of the online policy on held-out audio vs random, offline DP, mocap.
    EvalMotion(eval_motion::EvalMotionArgs),
    /// What each style (tone mix) does to the played motion: hand speed and kinematics.
    EvalStyle(eval_style::EvalStyleArgs),
    /// Validate a policy blob and summarize it: header, section sizes, dimensions, rig.
    Inspect(inspect::InspectArgs),
}

/// Parses the command line of `bin` like clap, but a bad command line is one line on stderr
/// (`bin: invalid value 'nan' for '--l2 <L2>': ... (see --help)`) and exit status 2, as every
/// other bad input; `--help` and `--version` print as usual and succeed.
pub fn parse_args<T: Parser>(bin: &str) -> Result<T, std::process::ExitCode> {
    use clap::error::ErrorKind;
    T::try_parse().map_err(|e| match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            let _ = e.print();
            std::process::ExitCode::SUCCESS
        }
        _ => {
            eprintln!("{bin}: {}", one_line(&e.render().to_string()));
            std::process::ExitCode::from(2)
        }
    })
}

/// The first line of a clap message without its `error: ` prefix, pointing to `--help`; a
/// line that ends in a colon takes the items listed under it (the missing arguments).
fn one_line(rendered: &str) -> String {
    let mut lines = rendered.lines().skip_while(|l| l.trim().is_empty());
    let first = lines.next().unwrap_or("");
    let mut out = first.strip_prefix("error: ").unwrap_or(first).to_string();
    if out.ends_with(':') {
        let items: Vec<&str> = lines
            .take_while(|l| !l.trim().is_empty())
            .map(str::trim)
            .collect();
        if !items.is_empty() {
            out = format!("{out} {}", items.join(", "));
        }
    }
    format!("{out} (see --help)")
}

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Synth(a) => synth::run(&a),
        Command::CorpusStats(a) => stats::run(&a),
        Command::Fit(a) => fit::run(&a),
        Command::EvalInference(a) => eval_inference::run(&a),
        Command::Pack(a) => pack::run(&a),
        Command::EvalMotion(a) => eval_motion::run(&a),
        Command::EvalStyle(a) => eval_style::run(&a),
        Command::Inspect(a) => inspect::run(&a),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bad_command_line_is_one_line_that_names_what_is_missing() {
        #[derive(Parser, Debug)]
        struct Args {
            #[arg(long)]
            train: String,
            #[arg(long, required_unless_present = "folds")]
            test: Option<String>,
            #[arg(long)]
            folds: Option<usize>,
        }
        let e = Args::try_parse_from(["x", "--train", "a"]).unwrap_err();
        let line = one_line(&e.render().to_string());
        assert_eq!(
            line,
            "the following required arguments were not provided: --test <TEST> (see --help)"
        );
        let e = Args::try_parse_from(["x", "--train", "a", "--folds", "two"]).unwrap_err();
        let line = one_line(&e.render().to_string());
        assert!(
            line.starts_with("invalid value 'two' for '--folds <FOLDS>'")
                && line.ends_with("(see --help)")
                && !line.contains('\n'),
            "{line}"
        );
    }
}
