//! Why packing failed ([`PackError`]), with the split the command line's exit status needs:
//! the user's input at fault, or the machine.

use gesture_runtime::blob::encode::EncodeError;

use crate::control::library::LibraryError;
use crate::control::style::ToneError;
use crate::inference::model::ModelError;
use crate::output::OutputError;
use crate::rig::RigError;

/// Why packing failed.
#[derive(Debug, thiserror::Error)]
pub enum PackError {
    /// The model file.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// Finding the library's files.
    #[error(transparent)]
    Discover(#[from] crate::corpus::DiscoverError),
    /// No BVH among the library's paths.
    #[error("the library has no .bvh files")]
    NoBvh,
    /// Reading or segmenting the library.
    #[error(transparent)]
    Library(#[from] LibraryError),
    /// The rig file or its binding (boxed: the largest error).
    #[error(transparent)]
    Rig(Box<RigError>),
    /// Takes with different skeletons.
    #[error(
        "the library mixes skeletons: {first} and {other} differ ({diff}); pack one skeleton \
         per library"
    )]
    MixedSkeletons {
        /// The first take.
        first: String,
        /// The differing take.
        other: String,
        /// The first difference.
        diff: String,
    },
    /// The budget cannot be met.
    #[error(
        "the blob does not fit {budget} bytes even with one successor per exit point \
         ({size} bytes): use a smaller library, fewer rig channels, or a larger budget"
    )]
    Budget {
        /// The budget.
        budget: usize,
        /// The smallest size reached.
        size: usize,
    },
    /// The model's front-end settings are not ones this runtime accepts.
    #[error("{0}")]
    FrontEnd(String),
    /// A tone's motion or options.
    #[error("{0}")]
    Style(String),
    /// A tone's transform could not be fitted.
    #[error(transparent)]
    Tone(#[from] ToneError),
    /// The labels do not fit the library.
    #[error("{0}")]
    Label(String),
    /// The writer refused the content (a packer bug or a dimension beyond the format).
    #[error(transparent)]
    Encode(#[from] EncodeError),
    /// Writing the blob.
    #[error(transparent)]
    Output(#[from] OutputError),
}

impl From<RigError> for PackError {
    fn from(e: RigError) -> Self {
        Self::Rig(Box::new(e))
    }
}

impl PackError {
    /// Whether the user's input is at fault (a file, an option), not the machine or the code.
    pub fn is_input(&self) -> bool {
        !matches!(
            self,
            Self::Output(_) | Self::Encode(EncodeError::Invalid(_) | EncodeError::Encode)
        )
    }
}
