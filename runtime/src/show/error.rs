//! Why a show file was refused, or does not fit the blob it is played with: one `Copy`
//! variant per rule of docs/show-format.md, section 4, in the order they are checked.

use core::fmt;

use super::format::{SHOW_HEADER_LEN, SHOW_MAX_FPS_MILLI, SHOW_VERSION};

/// Why [`Show::parse`](super::Show::parse) refused the bytes, or why a show cannot be played
/// with a blob or library ([`Show::check_against`](super::Show::check_against),
/// [`ShowPlayer::new`](super::ShowPlayer::new)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShowError {
    // --- the bytes ---
    /// Fewer bytes than the 32-byte header and the 4-byte CRC.
    TooShort {
        /// Bytes given.
        len: usize,
    },
    /// The first four bytes are not `GSTS`.
    BadMagic,
    /// A format version this runtime does not read.
    UnsupportedVersion {
        /// Version in the header.
        found: u16,
    },
    /// Header flags this runtime does not know (version 2 defines none).
    UnsupportedFlags {
        /// Flags in the header.
        found: u16,
    },
    /// The header promises more record bytes than the file holds.
    Truncated {
        /// Record bytes in the header.
        declared: u32,
        /// Bytes after the header, the CRC's four included.
        available: usize,
    },
    /// Bytes follow the CRC.
    TrailingBytes {
        /// Record bytes in the header.
        declared: u32,
        /// Bytes after the header, the CRC's four included.
        available: usize,
    },
    /// The CRC-32 does not match the bytes before it.
    BadCrc {
        /// CRC stored in the file.
        stored: u32,
        /// CRC of the bytes.
        computed: u32,
    },
    /// The sample rate is outside 1000..=192000 Hz.
    BadSampleRate {
        /// Rate in the header (Hz).
        found: u32,
    },
    /// The frame rate is 0 or above 1000 fps.
    BadFrameRate {
        /// Frame rate in the header (thousandths of a frame per second).
        found: u32,
    },
    /// The show has no tick.
    NoTicks,
    /// A record runs past the records, or its head is not a 32-bit LEB128 number in its
    /// shortest form.
    BadRecord {
        /// Index of the record (0-based).
        command: u32,
    },
    /// A record's kind is not one of the six.
    UnknownKind {
        /// Index of the record.
        command: u32,
        /// The kind (0..=7).
        kind: u8,
    },
    /// A rate is not finite or outside the player's 0.3..=1.5.
    BadRate {
        /// Index of the record.
        command: u32,
    },
    /// A gain is not finite or outside the expression stage's 0..=2.
    BadGain {
        /// Index of the record.
        command: u32,
    },
    /// A command comes at or after the show's last tick (delta-coded ticks never decrease;
    /// past the end they precede no pose).
    TickOutOfRange {
        /// Index of the record.
        command: u32,
        /// Its tick (saturated at `u32::MAX`).
        tick: u32,
    },
    /// The records hold another number of commands than the header says.
    CommandCount {
        /// Commands in the header.
        declared: u32,
        /// Records found.
        found: u32,
    },
    // --- against a blob or library ---
    /// The show was baked against another blob (the blob's payload CRC differs).
    OtherBlob {
        /// Blob CRC in the show.
        show: u32,
        /// The blob's payload CRC.
        blob: u32,
    },
    /// The show is clocked at another sample rate than the blob's front-end.
    SampleRateMismatch {
        /// The show's rate (Hz).
        show: u32,
        /// The blob's rate (Hz).
        blob: u32,
    },
    /// The show ticks at another frame rate than the library's.
    FrameRateMismatch {
        /// The show's frame rate (thousandths).
        show: u32,
        /// The library's frame rate, rounded to thousandths.
        library: u32,
    },
    /// The library has more channels than a pose holds.
    TooManyChannels {
        /// The library's channels.
        found: usize,
    },
    /// An `Enter` names a segment the library does not have.
    SegmentOutOfRange {
        /// Index of the record.
        command: u32,
        /// The segment.
        segment: u16,
    },
    /// An `Enter` names a frame past its segment's end.
    FrameOutOfRange {
        /// Index of the record.
        command: u32,
        /// The frame.
        frame: u16,
    },
}

impl ShowError {
    /// The variant's name, without formatting code (for firmware logs).
    pub const fn name(&self) -> &'static str {
        match self {
            Self::TooShort { .. } => "TooShort",
            Self::BadMagic => "BadMagic",
            Self::UnsupportedVersion { .. } => "UnsupportedVersion",
            Self::UnsupportedFlags { .. } => "UnsupportedFlags",
            Self::Truncated { .. } => "Truncated",
            Self::TrailingBytes { .. } => "TrailingBytes",
            Self::BadCrc { .. } => "BadCrc",
            Self::BadSampleRate { .. } => "BadSampleRate",
            Self::BadFrameRate { .. } => "BadFrameRate",
            Self::NoTicks => "NoTicks",
            Self::BadRecord { .. } => "BadRecord",
            Self::UnknownKind { .. } => "UnknownKind",
            Self::BadRate { .. } => "BadRate",
            Self::BadGain { .. } => "BadGain",
            Self::TickOutOfRange { .. } => "TickOutOfRange",
            Self::CommandCount { .. } => "CommandCount",
            Self::OtherBlob { .. } => "OtherBlob",
            Self::SampleRateMismatch { .. } => "SampleRateMismatch",
            Self::FrameRateMismatch { .. } => "FrameRateMismatch",
            Self::TooManyChannels { .. } => "TooManyChannels",
            Self::SegmentOutOfRange { .. } => "SegmentOutOfRange",
            Self::FrameOutOfRange { .. } => "FrameOutOfRange",
        }
    }
}

impl fmt::Display for ShowError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::TooShort { len } => write!(
                f,
                "{len} bytes is too short for a show file (header and CRC are {} bytes)",
                SHOW_HEADER_LEN + 4
            ),
            Self::BadMagic => f.write_str("not a show file (the magic is not GSTS)"),
            Self::UnsupportedVersion { found } => write!(
                f,
                "show format version {found}, this runtime reads version {SHOW_VERSION}: \
                 bake the show again with this version's gesture-sim"
            ),
            Self::UnsupportedFlags { found } => {
                write!(f, "unknown show flags {found:#06x} (none are defined)")
            }
            Self::Truncated {
                declared,
                available,
            } => write!(
                f,
                "truncated: the header promises {declared} record bytes and a CRC, \
                 {available} bytes follow it"
            ),
            Self::TrailingBytes {
                declared,
                available,
            } => write!(
                f,
                "{} bytes follow the CRC ({declared} record bytes declared)",
                available.saturating_sub(declared as usize + 4)
            ),
            Self::BadCrc { stored, computed } => write!(
                f,
                "CRC mismatch (stored {stored:08x}, computed {computed:08x}): the file is damaged"
            ),
            Self::BadSampleRate { found } => {
                write!(f, "sample rate {found} Hz is outside 1000..=192000")
            }
            Self::BadFrameRate { found } => write!(
                f,
                "frame rate {found} thousandths of a frame per second is outside 1..={SHOW_MAX_FPS_MILLI}"
            ),
            Self::NoTicks => f.write_str("the show has no tick"),
            Self::BadRecord { command } => write!(f, "command {command}: malformed record"),
            Self::UnknownKind { command, kind } => {
                write!(f, "command {command}: unknown kind {kind}")
            }
            Self::BadRate { command } => {
                write!(f, "command {command}: rate not finite or outside 0.3..=1.5")
            }
            Self::BadGain { command } => {
                write!(f, "command {command}: gain not finite or outside 0..=2")
            }
            Self::TickOutOfRange { command, tick } => write!(
                f,
                "command {command}: tick {tick} is at or past the show's end"
            ),
            Self::CommandCount { declared, found } => write!(
                f,
                "the header says {declared} commands, the records hold {found}"
            ),
            Self::OtherBlob { show, blob } => write!(
                f,
                "the show was baked against another blob (its CRC {show:08x}, this blob's \
                 {blob:08x}): play it with the blob it was made from"
            ),
            Self::SampleRateMismatch { show, blob } => write!(
                f,
                "the show runs at {show} Hz, the blob's front-end at {blob} Hz"
            ),
            Self::FrameRateMismatch { show, library } => write!(
                f,
                "the show ticks at {show} thousandths fps, the library at {library}"
            ),
            Self::TooManyChannels { found } => {
                write!(f, "the library has {found} channels, more than a pose holds")
            }
            Self::SegmentOutOfRange { command, segment } => write!(
                f,
                "command {command}: segment {segment} is not in the library"
            ),
            Self::FrameOutOfRange { command, frame } => write!(
                f,
                "command {command}: frame {frame} is past its segment's end"
            ),
        }
    }
}

impl core::error::Error for ShowError {}
