//! The payload's wire structs: what postcard encodes after the header, one struct per section,
//! in declaration order (docs/blob-format.md is the normative description of every field).
//!
//! Every table is a borrowed `&[u8]` of little-endian values, so decoding copies nothing: the
//! structs point into the blob (which may sit in flash). These structs are *unvalidated*: only a
//! [`Blob`](super::Blob) guarantees that dimensions, lengths and indices agree. The trainer
//! builds them by borrowing its own vectors and serializes them with postcard, so there is one
//! definition of the format.

use serde::{Deserialize, Serialize};

use crate::prosody::{PitchParams, ProsodyConfig, SyllableParams};

/// Bytes of one GMM component record (13 little-endian `f32`, in
/// [`GmmComponent`](crate::inference::GmmComponent) field order).
pub const GMM_RECORD_BYTES: usize = 13 * 4;
/// Bytes of one exit-point record (`segment: u16`, `frame: u16`).
pub const EXIT_RECORD_BYTES: usize = 4;
/// Bytes of one successor record (`segment: u16`, `cost: i16`).
pub const SUCCESSOR_RECORD_BYTES: usize = 4;
/// Bytes of one channel's frame quantization (`scale: f32`, `offset: f32`).
pub const FRAME_SCALE_RECORD_BYTES: usize = 8;
/// Bytes of one channel's calibration record (7 little-endian `f32`).
pub const CALIBRATION_RECORD_BYTES: usize = 7 * 4;
/// Segment stroke value meaning "no stroke frame".
pub const NO_STROKE: u16 = 0xFFFF;
/// Bytes of one skeleton end-site record (`joint: u16`, then `x, y, z: f32`).
pub const END_SITE_RECORD_BYTES: usize = 2 + 3 * 4;
/// Bytes of one rotation-group record (`first: u16`, `order: u8`).
pub const GROUP_RECORD_BYTES: usize = 3;
/// Bytes of one skeleton drive record (`joint: u16`, `chain_top: u16`, `axis: u8`, `mode: u8`).
pub const DRIVE_RECORD_BYTES: usize = 6;
/// `skeleton.parents` value of a root joint.
pub const ROOT_PARENT: u16 = 0xFFFF;

/// The whole payload: the six device sections in this order, then the optional host-side
/// skeleton and the optional styles (tones).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Payload<'a> {
    /// Front-end settings.
    pub front_end: FrontEndSection,
    /// GMM and CRF.
    #[serde(borrow)]
    pub inference: InferenceSection<'a>,
    /// Value tables, exit points and successors.
    #[serde(borrow)]
    pub policy: PolicySection<'a>,
    /// Controller settings (decision timing).
    pub control: ControlSection,
    /// Gesture segments and their frames.
    #[serde(borrow)]
    pub library: LibrarySection<'a>,
    /// Output channels and their servo calibration.
    #[serde(borrow)]
    pub rig: RigSection<'a>,
    /// The library's skeleton, for host tools that rebuild BVH motion (the device ignores it).
    #[serde(borrow)]
    pub skeleton: Option<SkeletonSection<'a>>,
    /// Value tables per tone, mixed at run time with the user's style weights (absent: the
    /// neutral policy only).
    #[serde(borrow)]
    pub styles: Option<StylesSection<'a>>,
    /// Semantic labels: names, value tables while a label waits, entries before strokes
    /// (absent: no labels; `library.labels` is then ignored).
    #[serde(borrow)]
    pub labels: Option<LabelsSection<'a>>,
}

/// Bytes of one semantic entry record (`frame: u16`, `cost: i16`).
pub const ENTRY_RECORD_BYTES: usize = 4;

/// Semantic labels (docs/method.md "Semantic labels", the paper's section 8.1): while label
/// `w` waits to be shown, candidates that do not carry it cost `semantic_cost` more, the value
/// tables are `U^w` (the cost-to-go while `w` waits), and a segment carrying `w` may also be
/// entered at a frame before its stroke.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LabelsSection<'a> {
    /// Labels L (1..=[`MAX_LABELS`](crate::policy::MAX_LABELS)); `library.labels` holds
    /// `1..=L` (0: none).
    pub labels: u8,
    /// L label names separated by `'\n'` (non-empty, distinct).
    pub names: &'a str,
    /// Added to the cost of a candidate that does not carry the waiting label (cost units).
    pub semantic_cost: f32,
    /// A label not shown within this long is dropped (ms).
    pub timeout_ms: u16,
    /// `u16` per labelled segment N: the segments carrying a label, increasing; each has a
    /// stroke frame.
    #[serde(borrow)]
    pub segments: &'a [u8],
    /// U^w(a', s) of every label: L x segments x S, label-major then as `policy.u`.
    #[serde(borrow)]
    pub u: I16Section<'a>,
    /// U_cont^w(e, s) of every label: L x exit points x S.
    #[serde(borrow)]
    pub u_cont: I16Section<'a>,
    /// Per exit point, per labelled segment (in `segments` order): `frame: u16` (the entry frame,
    /// at most the stroke frame), `cost: i16` (cost = `i16 * entry_cost_scale`): E x N records.
    #[serde(borrow)]
    pub entries: &'a [u8],
    /// Multiplier of the entry costs.
    pub entry_cost_scale: f32,
}

/// The prosody front-end's settings ([`ProsodyConfig`], flattened).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrontEndSection {
    /// PCM rate fed to the front-end (Hz).
    pub sample_rate_hz: u32,
    /// Lowest F0 considered (Hz).
    pub pitch_floor_hz: f32,
    /// Highest F0 considered (Hz).
    pub pitch_ceiling_hz: f32,
    /// Relative amplitude below which a frame is silent.
    pub silence_threshold: f32,
    /// Minimum normalized autocorrelation for voicing.
    pub voicing_threshold: f32,
    /// Preference for higher candidates (per octave).
    pub octave_cost: f32,
    /// Path cost of an octave jump.
    pub octave_jump_cost: f32,
    /// Path cost of a voiced/unvoiced transition.
    pub voiced_unvoiced_cost: f32,
    /// Syllable peak margin above the troughs (dB).
    pub margin_db: f32,
    /// Frames this far below the running peak are silence (dB).
    pub range_db: f32,
    /// Frames below this level are silence (dB).
    pub floor_db: f32,
    /// Starting value of the running peak (dB).
    pub initial_peak_db: f32,
    /// Shortest syllable (frames of 10 ms).
    pub min_frames: u32,
    /// Length of a pause step (frames of 10 ms).
    pub pause_frames: u32,
}

impl FrontEndSection {
    /// The section holding `c`.
    pub const fn from_config(c: &ProsodyConfig) -> Self {
        Self {
            sample_rate_hz: c.sample_rate_hz,
            pitch_floor_hz: c.pitch.floor_hz,
            pitch_ceiling_hz: c.pitch.ceiling_hz,
            silence_threshold: c.pitch.silence_threshold,
            voicing_threshold: c.pitch.voicing_threshold,
            octave_cost: c.pitch.octave_cost,
            octave_jump_cost: c.pitch.octave_jump_cost,
            voiced_unvoiced_cost: c.pitch.voiced_unvoiced_cost,
            margin_db: c.syllables.margin_db,
            range_db: c.syllables.range_db,
            floor_db: c.syllables.floor_db,
            initial_peak_db: c.syllables.initial_peak_db,
            min_frames: c.syllables.min_frames,
            pause_frames: c.syllables.pause_frames,
        }
    }

    /// The configuration this section describes (not validated here).
    pub const fn config(&self) -> ProsodyConfig {
        ProsodyConfig {
            sample_rate_hz: self.sample_rate_hz,
            pitch: PitchParams {
                floor_hz: self.pitch_floor_hz,
                ceiling_hz: self.pitch_ceiling_hz,
                silence_threshold: self.silence_threshold,
                voicing_threshold: self.voicing_threshold,
                octave_cost: self.octave_cost,
                octave_jump_cost: self.octave_jump_cost,
                voiced_unvoiced_cost: self.voiced_unvoiced_cost,
            },
            syllables: SyllableParams {
                margin_db: self.margin_db,
                range_db: self.range_db,
                floor_db: self.floor_db,
                initial_peak_db: self.initial_peak_db,
                min_frames: self.min_frames,
                pause_frames: self.pause_frames,
            },
        }
    }
}

/// A table of little-endian `i16`: value `i` is `i16 * scale`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct I16Section<'a> {
    /// Multiplier of every value.
    pub scale: f32,
    /// `2 * len` bytes.
    #[serde(borrow)]
    pub bytes: &'a [u8],
}

/// The inference layer: prosody clusters and CRF weights.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct InferenceSection<'a> {
    /// Hidden states S.
    pub states: u8,
    /// Prosody clusters K.
    pub clusters: u8,
    /// CRF input window W (syllables).
    pub window: u8,
    /// K records of 13 `f32` in [`GmmComponent`](crate::inference::GmmComponent) field order.
    #[serde(borrow)]
    pub gmm: &'a [u8],
    /// CRF initial weights (S).
    #[serde(borrow)]
    pub crf_init: I16Section<'a>,
    /// CRF transition weights (S x S, from-major).
    #[serde(borrow)]
    pub crf_trans: I16Section<'a>,
    /// CRF observation weights (S x W x K, index `(j * W + w) * K + k`).
    #[serde(borrow)]
    pub crf_obs: I16Section<'a>,
}

/// The control layer in factorized form (docs/method.md, "It factorizes; store it that way").
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PolicySection<'a> {
    /// Hidden states S (equals the inference section's).
    pub states: u8,
    /// Library segments (equals the library section's).
    pub segments: u16,
    /// Exit points.
    pub exit_points: u16,
    /// Discount gamma of the value iteration (informational; in `[0, 1]`).
    pub discount: f32,
    /// U(a', s): cost-to-go of entering segment a' in state s (segments x S, segment-major).
    #[serde(borrow)]
    pub u: I16Section<'a>,
    /// U_cont(e, s): cost-to-go of continuing past exit point e in state s (exit points x S).
    #[serde(borrow)]
    pub u_cont: I16Section<'a>,
    /// Per exit point: `segment: u16`, `frame: u16` (frame within the segment), sorted.
    #[serde(borrow)]
    pub exits: &'a [u8],
    /// `u32` per exit point plus one: exit e's successors are entries
    /// `succ_offsets[e]..succ_offsets[e + 1]`.
    #[serde(borrow)]
    pub succ_offsets: &'a [u8],
    /// Per entry: `segment: u16`, `cost: i16` (cost = `i16 * succ_cost_scale`).
    #[serde(borrow)]
    pub succ: &'a [u8],
    /// Multiplier of the successor costs.
    pub succ_cost_scale: f32,
}

/// Tones (styles): one pair of value tables per tone, the policy's successor lists shared
/// (docs/method.md "Style"). The `policy` section's `u` and `u_cont` are the neutral tone.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StylesSection<'a> {
    /// Tones M (1..=[`MAX_TONES`](crate::policy::MAX_TONES)).
    pub tones: u8,
    /// M tone names separated by `'\n'` (non-empty, distinct, none named `neutral`).
    pub names: &'a str,
    /// U^m(a', s) of every tone: M x segments x S, tone-major then as `policy.u`.
    #[serde(borrow)]
    pub u: I16Section<'a>,
    /// U_cont^m(e, s) of every tone: M x exit points x S, tone-major then as `policy.u_cont`.
    #[serde(borrow)]
    pub u_cont: I16Section<'a>,
}

/// How the controller runs the policy: when it decides
/// ([`DecisionTiming`](crate::policy::DecisionTiming)), how it varies its choices
/// ([`Variety`](crate::policy::Variety)) and how the player blends at cuts.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ControlSection {
    /// 1: decisions wait for syllable onsets; 0: every exit point decides at once.
    pub sync_to_onsets: u8,
    /// An onset detected this recently counts as "now" (ms, <= 1000).
    pub onset_window_ms: u16,
    /// Longest wait for an onset at a segment's end (ms, <= 5000).
    pub max_wait_ms: u16,
    /// Cost added to a candidate entered just now, falling linearly to 0 at `recency_ms`.
    pub recency_cost: f32,
    /// Recency window (ms).
    pub recency_ms: u16,
    /// Cost per unit of a candidate's share of the frames played in the last `usage_ms`.
    pub usage_cost: f32,
    /// Usage window (ms).
    pub usage_ms: u16,
    /// Inertialization time at cuts (ms): the pose offset decays over this time.
    pub blend_ms: u16,
    /// Longest hold at a motion beat waiting for a syllable onset (ms; 0: no holds).
    pub beat_hold_ms: u16,
    /// How far ahead (ms) a cut decided mid-segment looks for the hands' calmest next pause
    /// (0: cut at once).
    pub defer_cut_ms: u16,
    /// Silence (ms) after which the character rests ([`VoiceFollow::rest_ms`](crate::follow::VoiceFollow::rest_ms); 0: never).
    pub rest_ms: u16,
    /// Cost per unit of segment energy while resting (cost units, >= 0).
    pub rest_cost: f32,
    /// Cost per unit of segment energy and voice level while speaking (cost units, >= 0).
    pub energy_cost: f32,
}

impl ControlSection {
    /// The section for timing `t`, variety `v`, following the voice `f` and blend time `blend_ms` (durations saturate
    /// at `u16::MAX`).
    pub fn new(
        t: &crate::policy::DecisionTiming,
        v: &crate::policy::Variety,
        f: &crate::follow::VoiceFollow,
        blend_ms: u32,
    ) -> Self {
        let ms = |v: u32| u16::try_from(v).unwrap_or(u16::MAX);
        Self {
            sync_to_onsets: t.sync_to_onsets as u8,
            onset_window_ms: ms(t.onset_window_ms),
            max_wait_ms: ms(t.max_wait_ms),
            recency_cost: v.recency_cost,
            recency_ms: ms(v.recency_ms),
            usage_cost: v.usage_cost,
            usage_ms: ms(v.usage_ms),
            blend_ms: ms(blend_ms),
            beat_hold_ms: ms(t.beat_hold_ms),
            defer_cut_ms: ms(t.defer_cut_ms),
            rest_ms: ms(f.rest_ms),
            rest_cost: f.rest_cost,
            energy_cost: f.energy_cost,
        }
    }
}

/// The gesture library as output-channel frames.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LibrarySection<'a> {
    /// Output channels per frame (equals the rig's).
    pub channels: u16,
    /// Frame rate (frames per second).
    pub fps: f32,
    /// Frames in the frame table.
    pub frames: u32,
    /// Segments.
    pub segments: u16,
    /// `u32` per segment: index of its first frame in the frame table.
    #[serde(borrow)]
    pub seg_start: &'a [u8],
    /// `u16` per segment: its length in frames (>= 1).
    #[serde(borrow)]
    pub seg_len: &'a [u8],
    /// Per channel: `scale: f32`, `offset: f32`; value = `offset + scale * i16` (degrees).
    #[serde(borrow)]
    pub frame_scales: &'a [u8],
    /// `i16` values, frames x channels, frame-major.
    #[serde(borrow)]
    pub frame_values: &'a [u8],
    /// `u16` per segment: stroke frame within the segment, [`NO_STROKE`] if none.
    #[serde(borrow)]
    pub strokes: &'a [u8],
    /// `u8` per segment: semantic label, 0 = none.
    #[serde(borrow)]
    pub labels: &'a [u8],
    /// `u8` per segment: 1 if the next segment's frames continue it (the recorded successor,
    /// stored right after it), else 0.
    #[serde(borrow)]
    pub continues: &'a [u8],
    /// Motion beats: a bit per frame of the frame table (bit `f % 8` of byte `f / 8`), set on
    /// the frames where the hands' speed has a local minimum.
    #[serde(borrow)]
    pub beats: &'a [u8],
    /// Calm frames: a bit per frame of the frame table (as `beats`), set where the hands'
    /// smoothed speed is at most the library's 30th percentile. A cut decided mid-segment may
    /// fall on a calm frame or a beat ([`DecisionTiming::defer_cut_ms`](crate::policy::DecisionTiming::defer_cut_ms)).
    #[serde(borrow)]
    pub calm: &'a [u8],
    /// `i8` per segment: its energy, the log of its hands' mean speed over the library's
    /// median frame speed, in units of 1/[`ENERGY_SCALE`](super::ENERGY_SCALE)
    /// ([`crate::follow`]).
    #[serde(borrow)]
    pub energy: &'a [u8],
    /// Strokes: a bit per frame of the frame table (as `beats`), set on the frames where the
    /// hands' smoothed speed has a prominent peak (a gesture's stroke; the look-ahead lands
    /// them on syllables).
    #[serde(borrow)]
    pub peaks: &'a [u8],
    /// Rotation groups: records `{first: u16, order: u8}`, three channels
    /// `first..first + 3` holding one joint rotation as Euler angles in that order
    /// ([`EULER_ORDERS`](super::EULER_ORDERS) index), blended as rotations; sorted, disjoint.
    #[serde(borrow)]
    pub groups: &'a [u8],
}

/// The output rig: channel names and servo calibration.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RigSection<'a> {
    /// Rig name.
    pub name: &'a str,
    /// PWM period (microseconds).
    pub period_us: f32,
    /// Per channel 7 `f32`, in [`ChannelCal`](crate::rig::ChannelCal) field order.
    #[serde(borrow)]
    pub calibration: &'a [u8],
    /// Channel names separated by `'\n'`, one per channel.
    pub channel_names: &'a str,
}

/// The gesture library's BVH skeleton and how the rig's channels drive it: host-side data
/// (simulator BVH output and previews). The runtime validates it but never reads it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkeletonSection<'a> {
    /// Joints J, in BVH file (depth-first) order.
    pub joints: u16,
    /// J joint names separated by `'\n'`.
    pub joint_names: &'a str,
    /// `u16` per joint: parent index, [`ROOT_PARENT`] for a root.
    pub parents: &'a [u8],
    /// `3 f32` per joint: BVH `OFFSET` in the parent's frame.
    #[serde(borrow)]
    pub offsets: &'a [u8],
    /// `u8` per joint: its number of BVH channels (0..=6).
    #[serde(borrow)]
    pub channel_counts: &'a [u8],
    /// `u8` per channel, joint after joint in file order: 0..=5 = `Xposition`, `Yposition`,
    /// `Zposition`, `Xrotation`, `Yrotation`, `Zrotation`.
    #[serde(borrow)]
    pub channel_codes: &'a [u8],
    /// `f32` per channel: the rest pose (first frame of the library's first take), in BVH
    /// units (degrees, skeleton units).
    #[serde(borrow)]
    pub rest: &'a [u8],
    /// End sites: records `{joint: u16, x: f32, y: f32, z: f32}`, strictly increasing joint.
    #[serde(borrow)]
    pub end_sites: &'a [u8],
    /// One record per rig channel: `{joint: u16, chain_top: u16, axis: u8, mode: u8}` (see
    /// docs/blob-format.md).
    #[serde(borrow)]
    pub drives: &'a [u8],
}
