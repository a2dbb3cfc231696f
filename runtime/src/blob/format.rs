//! The format's fixed numbers (docs/blob-format.md): the header's magic, version and length,
//! and the capacities every section is checked against. A leaf: the reader, the writer and the
//! errors all name these, and this module names nothing of theirs.

/// The first four bytes of every blob.
pub const MAGIC: [u8; 4] = *b"GSTB";
/// The format version this runtime reads and writes.
pub const FORMAT_VERSION: u16 = 8;
/// Header length in bytes.
pub const HEADER_LEN: usize = 16;

/// Most library segments.
pub const MAX_SEGMENTS: usize = 4096;
/// Most exit points.
pub const MAX_EXITS: usize = 16384;
/// Most output channels (the servo rig's capacity).
pub const MAX_CHANNELS: usize = crate::rig::MAX_CHANNELS;
/// Most frames in the library's frame table.
pub const MAX_FRAMES: usize = 1 << 20;
/// Most joints a skeleton section may have.
pub const MAX_JOINTS: usize = 1024;
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
