//! The error of every `gesture-sim` command, and the exit status it maps to (2 bad input,
//! 1 failure; see [`crate::cli`]). Command modules return it; only `cli` turns it into a
//! status, so no command module depends on the command line.

use std::io;
use std::path::PathBuf;

use gesture_runtime::prosody::ConfigError;
use gesture_trainer::audio::AudioError;

use crate::eval::ParseError;
use crate::live::LiveError;
use crate::run::RunError;

/// Why a subcommand failed.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
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
    /// `run` failed (boxed: rig errors are large).
    #[error(transparent)]
    Run(Box<RunError>),
    /// `live` or `devices` failed.
    #[error(transparent)]
    Live(#[from] LiveError),
    /// `demo` failed.
    #[error(transparent)]
    Demo(#[from] crate::demo::DemoError),
    /// `metrics` could not read or measure a run folder.
    #[error("{0}")]
    Metrics(String),
    /// `soak` found a failure.
    #[error("{0}")]
    Soak(String),
    /// `--vmc` could not start or send.
    #[error(transparent)]
    Vmc(#[from] crate::vmc::VmcError),
    /// `--ros2`, `--mcap` or the URDF could not start, be made or be sent.
    #[error(transparent)]
    Ros2(#[from] crate::ros2::Ros2Error),
    /// `play-show` failed (boxed: run errors are large).
    #[error(transparent)]
    PlayShow(Box<crate::play_show::PlayShowError>),
}

impl From<crate::play_show::PlayShowError> for SimError {
    fn from(e: crate::play_show::PlayShowError) -> Self {
        Self::PlayShow(Box::new(e))
    }
}

impl From<RunError> for SimError {
    fn from(e: RunError) -> Self {
        Self::Run(Box::new(e))
    }
}

impl SimError {
    /// The process exit status for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Audio(_) | Self::Read { .. } | Self::Data { .. } => 2,
            Self::Config(_) | Self::Output(_) => 1,
            Self::Run(e) => e.exit_code(),
            Self::PlayShow(e) => e.exit_code(),
            Self::Live(e) => e.exit_code(),
            Self::Demo(e) => e.exit_code(),
            Self::Metrics(_) => 2,
            Self::Soak(_) => 1,
            Self::Vmc(crate::vmc::VmcError::Send(_)) => 1,
            Self::Vmc(_) => 2,
            Self::Ros2(e) => e.exit_code(),
        }
    }
}
