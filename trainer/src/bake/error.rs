//! Why a bake fails.

/// Why a bake failed.
#[derive(Debug, thiserror::Error)]
pub enum BakeError {
    /// The blob's controller could not be built.
    #[error("the blob's controller: {0}")]
    Blob(String),
    /// The plan could not be written or played as a show.
    #[error("the baked show: {0}")]
    Show(String),
}
