//! Why a blob could not be built ([`EncodeError`]), and the checks every section's
//! constructor uses to fit a count or index into its field's integer type.

use alloc::string::String;
use core::fmt;

use crate::blob::error::BlobError;

/// Why a blob could not be built.
#[derive(Clone, Debug, PartialEq)]
pub enum EncodeError {
    /// A dimension or index does not fit its field's type.
    TooLarge {
        /// What overflowed.
        what: &'static str,
        /// Its value.
        value: usize,
        /// The field's type.
        ty: &'static str,
    },
    /// Inputs that disagree with each other (lengths, non-finite values).
    Inconsistent(String),
    /// postcard refused to serialize (does not happen for these types).
    Encode,
    /// The encoded blob breaks a rule of the format.
    Invalid(BlobError),
}

impl fmt::Display for EncodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TooLarge { what, value, ty } => write!(
                f,
                "{what} = {value} does not fit the blob's {ty} field (use a smaller model, \
                 library or rig)"
            ),
            Self::Inconsistent(m) => f.write_str(m),
            Self::Encode => f.write_str("cannot encode the payload"),
            Self::Invalid(e) => write!(f, "the packed blob would be refused by the runtime: {e}"),
        }
    }
}

impl core::error::Error for EncodeError {}

/// `value` as the field type `T`, or [`EncodeError::TooLarge`] naming `what` and `ty`.
pub(super) fn fit<T: TryFrom<usize>>(
    what: &'static str,
    value: usize,
    ty: &'static str,
) -> Result<T, EncodeError> {
    T::try_from(value).map_err(|_| EncodeError::TooLarge { what, value, ty })
}

/// An [`EncodeError::Inconsistent`] with `msg`.
pub(super) fn inconsistent<T>(msg: String) -> Result<T, EncodeError> {
    Err(EncodeError::Inconsistent(msg))
}
