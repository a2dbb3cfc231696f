//! Why a blob was refused: one `Copy` variant per rule, grouped by the phase that checks it
//! (header, payload decoding, then each section's fields).

use core::fmt;

use super::field::{Field, Section};
use super::format::{
    FORMAT_VERSION, HEADER_LEN, MAX_CHANNELS, MAX_EXITS, MAX_FPS, MAX_FRAMES, MAX_JOINTS,
    MAX_SEGMENTS,
};
use crate::prosody::ConfigError;
use crate::rig::CalError;

/// Why [`Blob::parse`](super::Blob::parse) refused the bytes. Checks run in the order of
/// docs/blob-format.md, section 4 (header, decoding, then section by section), and the first
/// failure is reported; the variants below are grouped by phase and section, not in check
/// order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlobError {
    // --- header ---
    /// Fewer bytes than the 16-byte header.
    BlobTooShort {
        /// Bytes given.
        len: usize,
    },
    /// The first four bytes are not `GSTB`.
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
    /// The header promises more payload than the bytes hold.
    Truncated {
        /// Payload length in the header.
        declared: u32,
        /// Bytes after the header.
        available: usize,
    },
    /// Bytes follow the declared payload.
    TrailingBytes {
        /// Payload length in the header.
        declared: u32,
        /// Bytes after the header.
        available: usize,
    },
    /// The payload's CRC-32 differs from the header's.
    BadCrc {
        /// CRC in the header.
        stored: u32,
        /// CRC of the payload bytes.
        computed: u32,
    },
    // --- payload decoding ---
    /// A section does not decode as postcard (or bytes follow the last section).
    Malformed {
        /// The first section that failed.
        section: Section,
    },
    // --- front_end ---
    /// The front-end settings are refused by the front-end.
    FrontEnd(ConfigError),
    // --- dimensions ---
    /// A count that must be at least 1 is 0.
    ZeroCount {
        /// Which count.
        field: Field,
    },
    /// More hidden states than [`MAX_STATES`](crate::inference::MAX_STATES).
    StateCountTooLarge {
        /// States in the blob.
        found: u32,
    },
    /// More clusters than [`MAX_CLUSTERS`](crate::inference::MAX_CLUSTERS).
    ClusterCountTooLarge {
        /// Clusters in the blob.
        found: u32,
    },
    /// A longer window than [`MAX_WINDOW`](crate::inference::MAX_WINDOW).
    WindowTooLarge {
        /// Window in the blob.
        found: u32,
    },
    /// More segments than [`MAX_SEGMENTS`].
    TooManySegments {
        /// Segments in the blob.
        found: u32,
    },
    /// More exit points than [`MAX_EXITS`].
    TooManyExits {
        /// Exit points in the blob.
        found: u32,
    },
    /// More channels than [`MAX_CHANNELS`].
    TooManyChannels {
        /// Channels in the blob.
        found: u32,
    },
    /// More frames than [`MAX_FRAMES`].
    TooManyFrames {
        /// Frames in the blob.
        found: u32,
    },
    /// The policy's state count differs from the inference layer's.
    StateCountMismatch {
        /// `inference.states`.
        inference: u32,
        /// `policy.states`.
        policy: u32,
    },
    /// The policy's segment count differs from the library's.
    SegmentCountMismatch {
        /// `library.segments`.
        library: u32,
        /// `policy.segments`.
        policy: u32,
    },
    // --- tables ---
    /// A table's byte length does not match its dimensions.
    TableLength {
        /// The table.
        field: Field,
        /// Bytes its dimensions require.
        expected: usize,
        /// Bytes it has.
        found: usize,
    },
    /// A scale, offset or `f32` value of a table is NaN or infinite.
    NotFinite {
        /// The table.
        field: Field,
    },
    // --- library ---
    /// `library.fps` is not finite or outside `(0, MAX_FPS]`.
    BadFrameRate,
    /// A segment has length 0.
    EmptySegment {
        /// Segment index.
        segment: u32,
    },
    /// A segment's frames run past the frame table.
    SegmentOutOfFrames {
        /// Segment index.
        segment: u32,
    },
    /// A stroke frame is not within its segment.
    StrokeOutOfRange {
        /// Segment index.
        segment: u32,
    },
    /// A segment claims a continuation that is not the next segment stored right after it.
    BadContinuation {
        /// Segment index.
        segment: u32,
    },
    /// A rotation group's channels are out of range, overlap the previous group, or its
    /// order is unknown.
    BadGroup {
        /// Group record index.
        group: u32,
    },
    // --- rig ---
    /// `rig.period_us` is not finite, not above the longest pulse or above
    /// [`PERIOD_MAX_US`](crate::rig::PERIOD_MAX_US).
    BadPwmPeriod,
    /// A channel's calibration fails [`ChannelCal::validate`](crate::rig::ChannelCal::validate).
    BadCalibration {
        /// Channel index.
        channel: u32,
        /// What is wrong with it.
        error: CalError,
    },
    /// `rig.channel_names` does not hold one name per channel.
    ChannelNameCount {
        /// Channels.
        expected: u32,
        /// Names.
        found: u32,
    },
    // --- policy ---
    /// `policy.discount` is not in `[0, 1]`.
    BadDiscount,
    /// An exit point names a segment that does not exist.
    ExitSegmentOutOfRange {
        /// Exit index.
        exit: u32,
        /// Its segment.
        segment: u32,
    },
    /// An exit point's frame is not within its segment.
    ExitFrameOutOfRange {
        /// Exit index.
        exit: u32,
        /// Its frame.
        frame: u32,
    },
    /// Exit points are not strictly increasing by (segment, frame).
    ExitsNotSorted {
        /// First exit out of order.
        exit: u32,
    },
    /// A segment has no exit point at its last frame.
    MissingEndExit {
        /// Segment index.
        segment: u32,
    },
    /// `succ_offsets` does not start at 0 or decreases.
    SuccessorOffsetsNotMonotone {
        /// Exit index whose offset is wrong.
        exit: u32,
    },
    /// A successor names a segment that does not exist.
    SuccessorSegmentOutOfRange {
        /// Entry index.
        entry: u32,
        /// Its segment.
        segment: u32,
    },
    /// An exit point's successors are not strictly increasing by segment.
    SuccessorsNotSorted {
        /// Exit index.
        exit: u32,
    },
    /// An exit at its segment's last frame has no successor (playback could not go on).
    NoSuccessors {
        /// Exit index.
        exit: u32,
    },
    // --- control ---
    /// A controller setting is out of its documented range.
    BadControl {
        /// The setting.
        field: Field,
    },
    // --- skeleton ---
    /// More skeleton joints than [`MAX_JOINTS`].
    TooManyJoints {
        /// Joints in the blob.
        found: u32,
    },
    /// `skeleton.joint_names` does not hold one name per joint.
    JointNameCount {
        /// Joints.
        expected: u32,
        /// Names.
        found: u32,
    },
    /// A joint's parent does not precede it, or the joints are not in depth-first order.
    BadParent {
        /// Joint index.
        joint: u32,
    },
    /// A joint has more than 6 channels, an unknown channel code or a channel twice.
    BadJointChannels {
        /// Joint index.
        joint: u32,
    },
    /// An end site names a joint that does not exist or is out of order.
    BadEndSite {
        /// End-site record index.
        entry: u32,
    },
    /// A rig channel's drive record names a joint that does not exist, a chain top that is not
    /// the joint or one of its ancestors, or an unknown axis or mode.
    BadDrive {
        /// Rig channel index.
        channel: u32,
    },
    // --- styles ---
    /// More tones than [`MAX_TONES`](crate::policy::MAX_TONES).
    TooManyTones {
        /// Tones in the blob.
        found: u32,
    },
    /// `styles.names` does not hold one distinct, non-empty name per tone (or names a tone
    /// `neutral`, which is the policy's own tables).
    BadToneNames {
        /// The first tone whose name is wrong (or the tone count when names are missing or
        /// extra).
        tone: u32,
    },
    // --- labels ---
    /// More labels than [`MAX_LABELS`](crate::policy::MAX_LABELS).
    TooManyLabels {
        /// Labels in the blob.
        found: u32,
    },
    /// `labels.names` does not hold one distinct, non-empty name per label.
    BadLabelNames {
        /// The first bad label (or the label count when names are missing or extra).
        label: u32,
    },
    /// A segment's label is above the label count, or `labels.segments` is not the increasing
    /// list of exactly the labelled segments, each with a stroke.
    BadLabelledSegment {
        /// Segment index.
        segment: u32,
    },
    /// A semantic entry's frame is past its segment's stroke frame.
    EntryAfterStroke {
        /// Entry record index.
        entry: u32,
    },
}

impl BlobError {
    /// The variant's name (`"BadCrc"`, `"TableLength"`, ...): what a firmware can log without
    /// pulling in formatting code.
    pub const fn name(&self) -> &'static str {
        match self {
            Self::BlobTooShort { .. } => "BlobTooShort",
            Self::BadMagic => "BadMagic",
            Self::UnsupportedVersion { .. } => "UnsupportedVersion",
            Self::UnsupportedFlags { .. } => "UnsupportedFlags",
            Self::Truncated { .. } => "Truncated",
            Self::TrailingBytes { .. } => "TrailingBytes",
            Self::BadCrc { .. } => "BadCrc",
            Self::Malformed { .. } => "Malformed",
            Self::FrontEnd(_) => "FrontEnd",
            Self::ZeroCount { .. } => "ZeroCount",
            Self::StateCountTooLarge { .. } => "StateCountTooLarge",
            Self::ClusterCountTooLarge { .. } => "ClusterCountTooLarge",
            Self::WindowTooLarge { .. } => "WindowTooLarge",
            Self::TooManySegments { .. } => "TooManySegments",
            Self::TooManyExits { .. } => "TooManyExits",
            Self::TooManyChannels { .. } => "TooManyChannels",
            Self::TooManyFrames { .. } => "TooManyFrames",
            Self::StateCountMismatch { .. } => "StateCountMismatch",
            Self::SegmentCountMismatch { .. } => "SegmentCountMismatch",
            Self::TableLength { .. } => "TableLength",
            Self::NotFinite { .. } => "NotFinite",
            Self::BadFrameRate => "BadFrameRate",
            Self::EmptySegment { .. } => "EmptySegment",
            Self::SegmentOutOfFrames { .. } => "SegmentOutOfFrames",
            Self::StrokeOutOfRange { .. } => "StrokeOutOfRange",
            Self::BadContinuation { .. } => "BadContinuation",
            Self::BadGroup { .. } => "BadGroup",
            Self::BadPwmPeriod => "BadPwmPeriod",
            Self::BadCalibration { .. } => "BadCalibration",
            Self::ChannelNameCount { .. } => "ChannelNameCount",
            Self::BadDiscount => "BadDiscount",
            Self::ExitSegmentOutOfRange { .. } => "ExitSegmentOutOfRange",
            Self::ExitFrameOutOfRange { .. } => "ExitFrameOutOfRange",
            Self::ExitsNotSorted { .. } => "ExitsNotSorted",
            Self::MissingEndExit { .. } => "MissingEndExit",
            Self::SuccessorOffsetsNotMonotone { .. } => "SuccessorOffsetsNotMonotone",
            Self::SuccessorSegmentOutOfRange { .. } => "SuccessorSegmentOutOfRange",
            Self::SuccessorsNotSorted { .. } => "SuccessorsNotSorted",
            Self::NoSuccessors { .. } => "NoSuccessors",
            Self::BadControl { .. } => "BadControl",
            Self::TooManyJoints { .. } => "TooManyJoints",
            Self::JointNameCount { .. } => "JointNameCount",
            Self::BadParent { .. } => "BadParent",
            Self::BadJointChannels { .. } => "BadJointChannels",
            Self::BadEndSite { .. } => "BadEndSite",
            Self::BadDrive { .. } => "BadDrive",
            Self::TooManyTones { .. } => "TooManyTones",
            Self::BadToneNames { .. } => "BadToneNames",
            Self::TooManyLabels { .. } => "TooManyLabels",
            Self::BadLabelNames { .. } => "BadLabelNames",
            Self::BadLabelledSegment { .. } => "BadLabelledSegment",
            Self::EntryAfterStroke { .. } => "EntryAfterStroke",
        }
    }
}

impl fmt::Display for BlobError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::BlobTooShort { len } => write!(
                f,
                "blob too short: {len} bytes, the header alone is {HEADER_LEN} (not a policy blob?)"
            ),
            Self::BadMagic => f.write_str("bad magic: not a policy blob (expected `GSTB`)"),
            Self::UnsupportedVersion { found } => write!(
                f,
                "unsupported blob format version {found}: this runtime reads version \
                 {FORMAT_VERSION} (repack with a matching gesture-train)"
            ),
            Self::UnsupportedFlags { found } => write!(
                f,
                "unsupported header flags {found:#06x}: this runtime knows none \
                 (repack with a matching gesture-train)"
            ),
            Self::Truncated {
                declared,
                available,
            } => write!(
                f,
                "truncated blob: header declares {declared} payload bytes, only {available} \
                 follow (incomplete copy or flash write?)"
            ),
            Self::TrailingBytes {
                declared,
                available,
            } => write!(
                f,
                "trailing bytes: header declares {declared} payload bytes, {available} follow \
                 (pass exactly the blob's bytes)"
            ),
            Self::BadCrc { stored, computed } => write!(
                f,
                "payload CRC-32 mismatch: header {stored:#010x}, payload {computed:#010x} \
                 (corrupted blob: copy or flash it again)"
            ),
            Self::Malformed { section } => write!(
                f,
                "malformed payload: section `{section}` does not decode (written by another \
                 format revision? repack it)"
            ),
            Self::FrontEnd(e) => write!(f, "front_end: {e}"),
            Self::ZeroCount { field } => write!(f, "{field} is 0 (must be at least 1)"),
            Self::StateCountTooLarge { found } => write!(
                f,
                "{found} hidden states, the runtime holds at most {} (train with fewer states)",
                crate::inference::MAX_STATES
            ),
            Self::ClusterCountTooLarge { found } => write!(
                f,
                "{found} prosody clusters, the runtime holds at most {} (train with fewer)",
                crate::inference::MAX_CLUSTERS
            ),
            Self::WindowTooLarge { found } => write!(
                f,
                "CRF window {found}, the runtime holds at most {} (train a shorter window)",
                crate::inference::MAX_WINDOW
            ),
            Self::TooManySegments { found } => write!(
                f,
                "{found} segments, the runtime holds at most {} (use a smaller library)",
                MAX_SEGMENTS
            ),
            Self::TooManyExits { found } => write!(
                f,
                "{found} exit points, the runtime holds at most {} (fewer interruption frames \
                 or a smaller library)",
                MAX_EXITS
            ),
            Self::TooManyChannels { found } => write!(
                f,
                "{found} channels, the runtime drives at most {} (use a smaller rig)",
                MAX_CHANNELS
            ),
            Self::TooManyFrames { found } => write!(
                f,
                "{found} library frames, the runtime holds at most {} (use a smaller library)",
                MAX_FRAMES
            ),
            Self::StateCountMismatch { inference, policy } => write!(
                f,
                "policy has {policy} states but the inference layer {inference} \
                 (pack the policy with the same model)"
            ),
            Self::SegmentCountMismatch { library, policy } => write!(
                f,
                "policy has {policy} segments but the library {library} \
                 (pack the policy with the same library)"
            ),
            Self::TableLength {
                field,
                expected,
                found,
            } => write!(
                f,
                "{field} has {found} bytes, its dimensions need {expected}"
            ),
            Self::NotFinite { field } => write!(f, "{field} holds a NaN or infinite number"),
            Self::BadFrameRate => write!(
                f,
                "library.fps must be finite, positive and at most {}",
                MAX_FPS
            ),
            Self::EmptySegment { segment } => write!(f, "library segment {segment} has no frames"),
            Self::SegmentOutOfFrames { segment } => write!(
                f,
                "library segment {segment} runs past the end of the frame table"
            ),
            Self::StrokeOutOfRange { segment } => write!(
                f,
                "library segment {segment}: stroke frame is not within the segment"
            ),
            Self::BadContinuation { segment } => write!(
                f,
                "segment {segment} claims a continuation, but the next segment does not start \
                 right after it"
            ),
            Self::BadGroup { group } => write!(
                f,
                "rotation group {group} names channels out of range or overlapping, or an \
                 unknown order"
            ),
            Self::BadPwmPeriod => f.write_str(
                "rig.period_us must be finite, above 2500 us and at most 100000 us \
                 (20000 us is standard for hobby servos)",
            ),
            Self::BadCalibration { channel, error } => {
                write!(f, "rig channel {channel}: {error}")
            }
            Self::ChannelNameCount { expected, found } => write!(
                f,
                "rig.channel_names has {found} names for {expected} channels"
            ),
            Self::BadDiscount => f.write_str("policy.discount must be in [0, 1]"),
            Self::ExitSegmentOutOfRange { exit, segment } => write!(
                f,
                "exit point {exit} names segment {segment}, which does not exist"
            ),
            Self::ExitFrameOutOfRange { exit, frame } => write!(
                f,
                "exit point {exit} is at frame {frame}, past the end of its segment"
            ),
            Self::ExitsNotSorted { exit } => write!(
                f,
                "exit point {exit} is out of order (exits must increase by segment, then frame)"
            ),
            Self::MissingEndExit { segment } => {
                write!(f, "segment {segment} has no exit point at its last frame")
            }
            Self::SuccessorOffsetsNotMonotone { exit } => write!(
                f,
                "policy.succ_offsets[{exit}] is out of order (must start at 0 and never decrease)"
            ),
            Self::SuccessorSegmentOutOfRange { entry, segment } => write!(
                f,
                "successor entry {entry} names segment {segment}, which does not exist"
            ),
            Self::SuccessorsNotSorted { exit } => write!(
                f,
                "exit point {exit}: successors must be sorted by segment, without repeats"
            ),
            Self::NoSuccessors { exit } => {
                write!(f, "exit point {exit} ends its segment but has no successor")
            }
            Self::BadControl { field } => write!(
                f,
                "{field} is out of range (see docs/blob-format.md; repack the blob)"
            ),
            Self::TooManyJoints { found } => write!(
                f,
                "{found} skeleton joints, a blob holds at most {} (use a smaller skeleton)",
                MAX_JOINTS
            ),
            Self::JointNameCount { expected, found } => write!(
                f,
                "skeleton.joint_names has {found} names for {expected} joints"
            ),
            Self::BadParent { joint } => write!(
                f,
                "skeleton joint {joint}: its parent does not precede it in depth-first order"
            ),
            Self::BadJointChannels { joint } => write!(
                f,
                "skeleton joint {joint}: more than 6 channels, an unknown channel or a repeat"
            ),
            Self::BadEndSite { entry } => write!(
                f,
                "skeleton end site {entry} names a missing joint or is out of order"
            ),
            Self::BadDrive { channel } => write!(
                f,
                "skeleton drive of rig channel {channel}: joint, chain top, axis or mode out \
                 of range"
            ),
            Self::TooManyTones { found } => write!(
                f,
                "{found} tones, the runtime mixes at most {} (pack fewer styles)",
                crate::policy::MAX_TONES
            ),
            Self::BadToneNames { tone } => write!(
                f,
                "styles.names: tone {tone} has no name, a repeated one or the reserved \
                 `neutral` (one distinct name per tone)"
            ),
            Self::TooManyLabels { found } => write!(
                f,
                "{found} labels, the runtime holds at most {} (pack fewer labels)",
                crate::policy::MAX_LABELS
            ),
            Self::BadLabelNames { label } => write!(
                f,
                "labels.names: label {label} has no name or a repeated one (one distinct name \
                 per label)"
            ),
            Self::BadLabelledSegment { segment } => write!(
                f,
                "segment {segment}: its label is out of range, or labels.segments does not list \
                 exactly the labelled segments with strokes, in order"
            ),
            Self::EntryAfterStroke { entry } => write!(
                f,
                "labels.entries[{entry}] enters its segment after the stroke"
            ),
        }
    }
}

impl core::error::Error for BlobError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::FrontEnd(e) => Some(e),
            Self::BadCalibration { error, .. } => Some(error),
            _ => None,
        }
    }
}

impl From<ConfigError> for BlobError {
    fn from(e: ConfigError) -> Self {
        Self::FrontEnd(e)
    }
}
