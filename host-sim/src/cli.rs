//! The `gesture-sim` command line: argument definitions, dispatch, exit codes, error lines.
//!
//! Exit codes: 0 success (also when stdout is closed early, e.g. `| head`); 1 an internal
//! failure (writing output failed, the front-end refused its own default configuration);
//! 2 bad input (an unreadable or unsupported file, a malformed reference) and, from clap, bad
//! usage. Every error is one line on stderr: `gesture-sim: <file>: <reason>`.
//!
//! Output goes through one `BufWriter` on the locked stdout; nothing here uses `println!`, so
//! a closed pipe is an ordinary error value and never a panic.

use std::io::{self, BufWriter, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use gesture_runtime::prosody::ConfigError;
use gesture_trainer::audio::AudioError;

use crate::eval::ParseError;
use crate::{bench, eval_cmd, prosody_cmd};

/// Runs the gesture-controller runtime on the desktop.
#[derive(Debug, Parser)]
#[command(name = "gesture-sim", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Print a WAV file's per-frame prosody (or its syllables) as CSV.
    Prosody {
        /// The WAV file (8-48 kHz; 8/16/24/32-bit integer or 32-bit float; mono or stereo).
        #[arg(value_name = "WAV")]
        wav: PathBuf,
        /// One row per syllable instead of per 10 ms frame.
        #[arg(long)]
        syllables: bool,
    },
    /// Compare the front-end with Praat on the shared recordings (skips if they are absent).
    EvalProsody {
        /// Data folder [default: ../shared/data, else the one next to the workspace].
        #[arg(long, value_name = "DIR")]
        data: Option<PathBuf>,
        /// Print one JSON object instead of tables.
        #[arg(long)]
        json: bool,
    },
    /// Time the front-end on generated speech-like audio (or a WAV file).
    BenchProsody {
        /// Seconds of generated audio.
        #[arg(long, default_value_t = 60.0, value_parser = parse_seconds)]
        seconds: f64,
        /// Number of timed runs.
        #[arg(long, default_value_t = 7, value_parser = clap::value_parser!(u32).range(1..=1000))]
        runs: u32,
        /// Analyse this WAV file instead of generated audio.
        #[arg(long, value_name = "FILE")]
        wav: Option<PathBuf>,
    },
}

fn parse_seconds(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if v.is_finite() && v > 0.0 && v <= 3600.0 {
        Ok(v)
    } else {
        Err("must be more than 0 and at most 3600".into())
    }
}

/// Why a subcommand failed.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// An audio file could not be loaded (its message names the file).
    #[error(transparent)]
    Audio(#[from] AudioError),
    /// A data file could not be read.
    #[error("{}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: io::Error,
    },
    /// A reference or prompts file is malformed.
    #[error("{}: {source}", path.display())]
    Data {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        source: ParseError,
    },
    /// The front-end refused its configuration (a bug: the default is used).
    #[error("front-end configuration: {0}")]
    Config(#[from] ConfigError),
    /// Writing the output failed.
    #[error("writing output: {0}")]
    Output(#[from] io::Error),
}

impl CliError {
    /// The process exit status for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Audio(_) | Self::Read { .. } | Self::Data { .. } => 2,
            Self::Config(_) | Self::Output(_) => 1,
        }
    }
}

/// Runs a parsed command line, writing results to `out`.
pub fn execute(cli: &Cli, out: &mut impl Write) -> Result<(), CliError> {
    match &cli.command {
        Command::Prosody { wav, syllables } => prosody_cmd::run(wav, *syllables, out),
        Command::EvalProsody { data, json } => eval_cmd::run(data.as_deref(), *json, out),
        Command::BenchProsody { seconds, runs, wav } => {
            bench::run(*seconds, *runs, wav.as_deref(), out)
        }
    }
}

/// Runs a parsed command line on stdout and turns the outcome into an exit code (see the
/// module docs).
pub fn run(cli: &Cli) -> ExitCode {
    let mut out = BufWriter::new(io::stdout().lock());
    let result = execute(cli, &mut out).and_then(|()| out.flush().map_err(CliError::Output));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::Output(e)) if e.kind() == io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
        Err(e) => {
            // If stderr is gone too there is nobody left to tell.
            let _ = writeln!(io::stderr(), "gesture-sim: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
