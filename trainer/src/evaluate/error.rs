//! Why an evaluation failed ([`EvalError`]): the user's input, or the packed blob.

use crate::pack::PackError;

/// Why an evaluation failed.
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    /// Packing the model and library.
    #[error(transparent)]
    Pack(#[from] PackError),
    /// Reading the audio.
    #[error(transparent)]
    Audio(#[from] crate::audio::AudioError),
    /// Reading the motion capture.
    #[error(transparent)]
    Bvh(#[from] crate::motion::BvhError),
    /// Analysing motion, speech or the options.
    #[error("{0}")]
    Input(String),
    /// The device refused the packed blob or a pose could not be rebuilt (a packer bug).
    #[error("the packed blob: {0}")]
    Device(String),
}

impl EvalError {
    /// Whether the user's input is at fault.
    pub fn is_input(&self) -> bool {
        match self {
            Self::Pack(e) => e.is_input(),
            Self::Device(_) => false,
            _ => true,
        }
    }
}
