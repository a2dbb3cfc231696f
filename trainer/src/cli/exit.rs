//! What a command returns: [`CliError`] and its exit status, which library errors are the
//! user's ([`ExitKind`]), and stdout lines that turn a closed pipe into a quiet stop
//! (`write_line`, through `outln!`).

use std::path::Path;

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
impl ExitKind for crate::evaluate::error::EvalError {
    fn is_input(&self) -> bool {
        crate::evaluate::error::EvalError::is_input(self)
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

/// Checks that an output folder can be created.
pub(crate) fn ensure_dir(dir: &Path) -> Result<(), CliError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| CliError::Input(format!("{}: cannot create folder: {e}", dir.display())))
}
