//! Where in a blob: the payload's sections and their fields, named as docs/blob-format.md
//! names them, for [`BlobError`](super::BlobError) to point at.

use core::fmt;

/// A section of the payload.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Section {
    /// Front-end settings.
    FrontEnd,
    /// GMM and CRF.
    Inference,
    /// Value tables and successors.
    Policy,
    /// Controller settings.
    Control,
    /// Gesture segments and frames.
    Library,
    /// Output channels.
    Rig,
    /// The optional host-side skeleton.
    Skeleton,
    /// The optional tones (styles).
    Styles,
    /// The optional semantic labels.
    Labels,
}

impl Section {
    /// The section's name in docs/blob-format.md.
    pub const fn name(self) -> &'static str {
        match self {
            Self::FrontEnd => "front_end",
            Self::Inference => "inference",
            Self::Policy => "policy",
            Self::Control => "control",
            Self::Library => "library",
            Self::Rig => "rig",
            Self::Skeleton => "skeleton",
            Self::Styles => "styles",
            Self::Labels => "labels",
        }
    }
}

impl fmt::Display for Section {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A field of the payload, as named in docs/blob-format.md.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// `inference.states`.
    States,
    /// `inference.clusters`.
    Clusters,
    /// `inference.window`.
    Window,
    /// `inference.gmm`.
    Gmm,
    /// `inference.crf_init`.
    CrfInit,
    /// `inference.crf_trans`.
    CrfTrans,
    /// `inference.crf_obs`.
    CrfObs,
    /// `policy.segments`.
    Segments,
    /// `policy.exit_points`.
    ExitPoints,
    /// `policy.u`.
    U,
    /// `policy.u_cont`.
    UCont,
    /// `policy.exits`.
    Exits,
    /// `policy.succ_offsets`.
    SuccOffsets,
    /// `policy.succ` (and `policy.succ_cost_scale`).
    Succ,
    /// `control.sync_to_onsets`.
    SyncToOnsets,
    /// `control.onset_window_ms`.
    OnsetWindow,
    /// `control.max_wait_ms`.
    MaxWait,
    /// `control.recency_cost` / `control.recency_ms`.
    Recency,
    /// `control.usage_cost` / `control.usage_ms`.
    Usage,
    /// `control.blend_ms`.
    Blend,
    /// `control.beat_hold_ms`.
    BeatHold,
    /// `control.defer_cut_ms`.
    DeferCut,
    /// `control.rest_ms`.
    RestAfter,
    /// `control.rest_cost`.
    RestCost,
    /// `control.energy_cost`.
    EnergyCost,
    /// `library.channels`.
    Channels,
    /// `library.frames`.
    Frames,
    /// `library.seg_start`.
    SegStart,
    /// `library.seg_len`.
    SegLen,
    /// `library.frame_scales`.
    FrameScales,
    /// `library.frame_values`.
    FrameValues,
    /// `library.strokes`.
    Strokes,
    /// `library.labels`.
    Labels,
    /// `library.continues`.
    Continues,
    /// `library.beats`.
    Beats,
    /// `library.calm`.
    Calm,
    /// `library.energy`.
    Energy,
    /// `library.peaks`.
    Peaks,
    /// `library.groups`.
    Groups,
    /// `rig.calibration`.
    Calibration,
    /// `skeleton.joints`.
    Joints,
    /// `skeleton.parents`.
    Parents,
    /// `skeleton.offsets`.
    Offsets,
    /// `skeleton.channel_counts`.
    ChannelCounts,
    /// `skeleton.channel_codes`.
    ChannelCodes,
    /// `skeleton.rest`.
    Rest,
    /// `skeleton.end_sites`.
    EndSites,
    /// `skeleton.drives`.
    Drives,
    /// `styles.tones`.
    Tones,
    /// `styles.names`.
    ToneNames,
    /// `styles.u`.
    ToneU,
    /// `styles.u_cont`.
    ToneUCont,
    /// `labels.labels`.
    LabelCount,
    /// `labels.segments`.
    LabelSegments,
    /// `labels.u`.
    LabelU,
    /// `labels.u_cont`.
    LabelUCont,
    /// `labels.entries`.
    LabelEntries,
    /// `labels.semantic_cost`.
    SemanticCost,
}

impl Field {
    /// `section.field`, as in docs/blob-format.md.
    pub const fn name(self) -> &'static str {
        match self {
            Self::States => "inference.states",
            Self::Clusters => "inference.clusters",
            Self::Window => "inference.window",
            Self::Gmm => "inference.gmm",
            Self::CrfInit => "inference.crf_init",
            Self::CrfTrans => "inference.crf_trans",
            Self::CrfObs => "inference.crf_obs",
            Self::Segments => "policy.segments",
            Self::ExitPoints => "policy.exit_points",
            Self::U => "policy.u",
            Self::UCont => "policy.u_cont",
            Self::Exits => "policy.exits",
            Self::SuccOffsets => "policy.succ_offsets",
            Self::Succ => "policy.succ",
            Self::SyncToOnsets => "control.sync_to_onsets",
            Self::OnsetWindow => "control.onset_window_ms",
            Self::MaxWait => "control.max_wait_ms",
            Self::Recency => "control.recency_cost",
            Self::Usage => "control.usage_cost",
            Self::Blend => "control.blend_ms",
            Self::BeatHold => "control.beat_hold_ms",
            Self::DeferCut => "control.defer_cut_ms",
            Self::RestAfter => "control.rest_ms",
            Self::RestCost => "control.rest_cost",
            Self::EnergyCost => "control.energy_cost",
            Self::Channels => "library.channels",
            Self::Frames => "library.frames",
            Self::SegStart => "library.seg_start",
            Self::SegLen => "library.seg_len",
            Self::FrameScales => "library.frame_scales",
            Self::FrameValues => "library.frame_values",
            Self::Strokes => "library.strokes",
            Self::Labels => "library.labels",
            Self::Continues => "library.continues",
            Self::Beats => "library.beats",
            Self::Calm => "library.calm",
            Self::Energy => "library.energy",
            Self::Peaks => "library.peaks",
            Self::Groups => "library.groups",
            Self::Calibration => "rig.calibration",
            Self::Joints => "skeleton.joints",
            Self::Parents => "skeleton.parents",
            Self::Offsets => "skeleton.offsets",
            Self::ChannelCounts => "skeleton.channel_counts",
            Self::ChannelCodes => "skeleton.channel_codes",
            Self::Rest => "skeleton.rest",
            Self::EndSites => "skeleton.end_sites",
            Self::Drives => "skeleton.drives",
            Self::Tones => "styles.tones",
            Self::ToneNames => "styles.names",
            Self::ToneU => "styles.u",
            Self::ToneUCont => "styles.u_cont",
            Self::LabelCount => "labels.labels",
            Self::LabelSegments => "labels.segments",
            Self::LabelU => "labels.u",
            Self::LabelUCont => "labels.u_cont",
            Self::LabelEntries => "labels.entries",
            Self::SemanticCost => "labels.semantic_cost",
        }
    }
}

impl fmt::Display for Field {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
