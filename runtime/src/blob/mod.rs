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
mod header;
mod payload;
mod quantize;
mod records;
mod skeleton;
mod tables;
mod validate;
mod view;

pub use crc::{crc32, Crc32};
pub use error::{BlobError, Field, Section};
pub use header::{Header, FORMAT_VERSION, HEADER_LEN, MAGIC};
pub use payload::{
    ControlSection, FrontEndSection, I16Section, InferenceSection, LabelsSection, LibrarySection,
    Payload, PolicySection, RigSection, SkeletonSection, StylesSection, CALIBRATION_RECORD_BYTES,
    DRIVE_RECORD_BYTES, END_SITE_RECORD_BYTES, ENTRY_RECORD_BYTES, EXIT_RECORD_BYTES,
    FRAME_SCALE_RECORD_BYTES, GMM_RECORD_BYTES, GROUP_RECORD_BYTES, NO_STROKE, ROOT_PARENT,
    SUCCESSOR_RECORD_BYTES,
};
pub use quantize::{quantize_range, quantize_symmetric, Quantization, QUANT_MAX};
pub use records::{calibration_from_record, calibration_record, gmm_from_record, gmm_record};
pub use skeleton::{BvhChannel, Drive, DriveMode, SkeletonView, EULER_ORDERS, MAX_JOINTS};
pub use view::{Blob, ExitPoint, GmmComponents, SectionSizes, SegmentInfo, Successor, Successors};

/// Most library segments.
pub const MAX_SEGMENTS: usize = 4096;
/// Most exit points.
pub const MAX_EXITS: usize = 16384;
/// Most output channels (the servo rig's capacity).
pub const MAX_CHANNELS: usize = crate::rig::MAX_CHANNELS;
/// Most frames in the library's frame table.
pub const MAX_FRAMES: usize = 1 << 20;
/// Highest library frame rate (frames per second).
pub const MAX_FPS: f32 = 1000.0;
/// Longest onset window of the `control` section (ms).
pub const MAX_ONSET_WINDOW_MS: u16 = 1000;
/// Longest wait for an onset at a segment's end in the `control` section (ms).
pub const MAX_WAIT_MS: u16 = 5000;
/// Largest recency or usage cost of the `control` section (cost units).
pub const MAX_VARIETY_COST: f32 = 1.0e6;
/// Longest inertialization time of the `control` section (ms).
pub const MAX_BLEND_MS: u16 = 5000;
/// Longest hold at a motion beat of the `control` section (ms).
pub const MAX_BEAT_HOLD_MS: u16 = 1000;
/// Longest delay of a cut until the hands pause, of the `control` section (ms).
pub const MAX_DEFER_CUT_MS: u16 = 1000;
/// Longest silence before resting, of the `control` section (ms).
pub const MAX_REST_MS: u16 = 10_000;
/// `library.energy` holds a segment's energy times this, rounded (an `i8`: energies within
/// +-8, a 1/16 step).
pub const ENERGY_SCALE: f32 = 16.0;
