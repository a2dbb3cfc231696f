//! The `gesture-train` command line, and nothing else: each command's flags (clap) are
//! checked into the library's settings ([`args`]), the library does the work, and the result
//! is printed. Every command prints what it did to stdout and progress to stderr; an error is
//! one line on stderr and an exit status ([`CliError::exit_code`]: 2 bad input, 1 failure).
//! Output goes through `outln!`, which turns a closed stdout (`gesture-train ... | head`)
//! into a quiet [`CliError::BrokenPipe`] instead of a panic.

/// `println!` that returns a `Result` (see [`write_line`]).
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::cli::write_line(format_args!($($arg)*))
    };
}

pub mod args;
pub mod eval_inference;
pub mod eval_motion;
pub mod eval_style;
pub mod fit;
pub mod inspect;
pub mod pack;
mod stats;
mod synth;

use std::path::Path;

use clap::{Parser, Subcommand};

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

/// Why a command failed, and what the process should exit with: **2** for bad input (a
/// file that cannot be read or used, an option out of range: the user can fix it), **1** for
/// a failure of the machine or the program (an output that cannot be written, an internal
/// inconsistency), **0** quietly when stdout was closed early (`| head`). The same convention
/// holds for `gesture-sim`.
#[derive(Debug)]
pub enum CliError {
    /// Bad input: exit 2.
    Input(String),
    /// A failure: exit 1.
    Failure(String),
    /// Stdout is a closed pipe: stop quietly, exit 0.
    BrokenPipe,
}

impl CliError {
    /// The process exit status.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Input(_) => 2,
            Self::Failure(_) => 1,
            Self::BrokenPipe => 0,
        }
    }

    /// A failure of the machine or the program (exit 1).
    pub fn failure(e: impl std::fmt::Display) -> Self {
        Self::Failure(e.to_string())
    }
}

impl std::fmt::Display for CliError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Input(m) | Self::Failure(m) => f.write_str(m),
            Self::BrokenPipe => f.write_str("stdout closed"),
        }
    }
}

impl std::error::Error for CliError {}

/// Which library errors are the user's (exit 2) and which are failures (exit 1).
pub trait ExitKind {
    /// Whether the user's input is at fault.
    fn is_input(&self) -> bool {
        true
    }
}

impl<E: std::error::Error + ExitKind> From<E> for CliError {
    fn from(e: E) -> Self {
        if e.is_input() {
            Self::Input(e.to_string())
        } else {
            Self::Failure(e.to_string())
        }
    }
}

impl From<crate::output::OverwriteError> for CliError {
    fn from(e: crate::output::OverwriteError) -> Self {
        Self::Input(e.to_string())
    }
}

impl From<String> for CliError {
    fn from(m: String) -> Self {
        Self::Input(m)
    }
}

impl From<&str> for CliError {
    fn from(m: &str) -> Self {
        Self::Input(m.to_string())
    }
}

impl ExitKind for crate::corpus::CorpusError {}
impl ExitKind for crate::corpus::DiscoverError {}
impl ExitKind for crate::corpus::stats::StatsError {}
impl ExitKind for crate::audio::AudioError {}
impl ExitKind for crate::motion::BvhError {}
impl ExitKind for crate::control::library::LibraryError {}
impl ExitKind for crate::inference::model::ModelError {}
impl ExitKind for crate::inference::train::FitError {}
impl ExitKind for crate::synth::WriteError {
    fn is_input(&self) -> bool {
        false
    }
}
impl ExitKind for crate::output::OutputError {
    fn is_input(&self) -> bool {
        false
    }
}
impl ExitKind for serde_json::Error {
    fn is_input(&self) -> bool {
        false
    }
}
impl ExitKind for crate::pack::PackError {
    fn is_input(&self) -> bool {
        crate::pack::PackError::is_input(self)
    }
}
impl ExitKind for crate::evaluate::motion::EvalError {
    fn is_input(&self) -> bool {
        crate::evaluate::motion::EvalError::is_input(self)
    }
}

/// Writes one line to stdout; a closed pipe is [`CliError::BrokenPipe`], any other error a
/// failure. Used through [`outln!`], never `println!` (which panics on a closed pipe).
pub(crate) fn write_line(args: std::fmt::Arguments<'_>) -> Result<(), CliError> {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    writeln!(out, "{args}").map_err(|e| {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            CliError::BrokenPipe
        } else {
            CliError::failure(format!("stdout: {e}"))
        }
    })
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

/// Checks that an output folder can be created.
pub(crate) fn ensure_dir(dir: &Path) -> Result<(), CliError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| CliError::Input(format!("{}: cannot create folder: {e}", dir.display())))
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
