//! The policy blob: one byte string holding everything the device needs (front-end settings,
//! GMM and CRF, value tables and successors, controller settings, gesture library frames, rig
//! calibration), checked once at load; and, with the `encode` feature, the writer.
//!
//! ```text
//!  0      4        6      8            12     16
//!  "GSTB" version  flags  payload_len  crc32  postcard payload (payload_len bytes)
//!         u16 LE   u16 LE u32 LE       u32 LE front_end | inference | policy | control
//!                                                | library | rig | skeleton (optional)
//! ```
//!
//! `docs/blob-format.md` is the normative description: field meanings and units, the postcard
//! encoding, every validation rule and the error it gives, and the versioning policy. This
//! module is the format's only implementation: the reader below and, behind the `encode`
//! feature (host tools), the writer in `encode`, side by side.
//!
//! - `format`: the header's constants and the capacities of every section ([`MAX_SEGMENTS`],
//!   ...);
//! - `header`: magic, version, flags, length, CRC ([`Header`]);
//! - `payload`: the wire structs, one per section ([`Payload`]);
//! - `records`: fixed-size records in the byte tables and their little-endian readers;
//! - `quantize`: the one quantizer of every `i16` table ([`quantize_symmetric`],
//!   [`quantize_range`]);
//! - `validate`: every rule of the format, in the documented order;
//! - `view`: the validated [`Blob`] and its accessors;
//! - `tables`: the blob as the controller's [`PolicyTables`](crate::policy::PolicyTables) and
//!   [`LibraryFrames`](crate::player::LibraryFrames);
//! - `skeleton`: the host-side skeleton section ([`SkeletonView`], [`BvhChannel`] codes);
//! - `field`: the sections and fields as docs/blob-format.md names them ([`Section`],
//!   [`Field`]);
//! - `error`: [`BlobError`], named by phase and field;
//! - `encode` (feature `encode`): owned sections, table layout and the
//!   serializer, checked against [`Blob::parse`].
//!
//! **Invariants.** [`Blob::parse`] is the only gate: it never panics and never allocates for
//! any input bytes, and returns a [`BlobError`] naming the first rule broken. Once it returns
//! `Ok`, every dimension is within the runtime's capacities, every table's length matches its
//! dimensions, every index stored in the blob is in range and every scale is finite, so the
//! accessors are infallible: they do no checks that can fail and never panic.
//!
//! **Zero copy.** The payload's tables are borrowed `&[u8]` of little-endian values, read on
//! access, so a blob can stay in flash; a [`Blob`] is a few hundred bytes of slices and
//! dimensions. Parsing walks the payload once (CRC, decode, validation), O(size), and checks
//! the front-end settings with [`ProsodyConfig::validate`](crate::prosody::ProsodyConfig)
//! without building a front-end, so it needs only a few hundred bytes of stack.

mod crc;
#[cfg(feature = "encode")]
pub mod encode;
mod error;
mod field;
mod format;
mod header;
mod payload;
mod quantize;
mod records;
mod skeleton;
mod tables;
mod validate;
mod view;

pub use crc::{crc32, Crc32};
pub use error::BlobError;
pub use field::{Field, Section};
pub use format::*;
pub use header::Header;
pub use payload::{
    ControlSection, FrontEndSection, I16Section, InferenceSection, LabelsSection, LibrarySection,
    Payload, PolicySection, RigSection, SkeletonSection, StylesSection, CALIBRATION_RECORD_BYTES,
    DRIVE_RECORD_BYTES, END_SITE_RECORD_BYTES, ENTRY_RECORD_BYTES, EXIT_RECORD_BYTES,
    FRAME_SCALE_RECORD_BYTES, GMM_RECORD_BYTES, GROUP_RECORD_BYTES, NO_STROKE, ROOT_PARENT,
    SUCCESSOR_RECORD_BYTES,
};
pub use quantize::{quantize_range, quantize_symmetric, Quantization, QUANT_MAX};
pub use records::{calibration_from_record, calibration_record, gmm_from_record, gmm_record};
pub use skeleton::{BvhChannel, Drive, DriveMode, SkeletonView, BODY_MEASURES, EULER_ORDERS};
pub use view::{Blob, ExitPoint, GmmComponents, SectionSizes, SegmentInfo, Successor, Successors};
