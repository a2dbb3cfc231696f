//! What a pack is asked for ([`PackOptions`], [`StyleOptions`]) and the defaults a blob gets:
//! the device's variety, how it follows the voice, and its inertialization at cuts. Plain
//! data, read by every stage of the pipeline.

use std::path::PathBuf;

use gesture_runtime::controller::DecisionTiming;
use gesture_runtime::follow::VoiceFollow;
use gesture_runtime::policy::Variety;

use crate::control::build::ControlParams;
use crate::control::semantic::{LabelParams, LabelSpec};
use crate::motion::EffectorSpec;

/// Variety costs a blob gets by default (see `gesture_runtime::policy`): chosen with
/// `gesture-train eval-motion` on tuning speech (067's 50 s twice and the six CMU Arctic
/// sentences, 119 s) with the default models and libraries of both ZeroEGGS takes, never on
/// the speech the README reports (docs/method.md, "Variety"). A usage window of a minute
/// (bounded by the 32 remembered entries) spreads the motion over the library in the
/// proportions the capture has; a shorter one let a few segments come back every half minute.
/// The usage cost went from 12 to 24 once continuing paid only a quarter of it
/// (`gesture_runtime::policy::CONTINUE_USAGE_SHARE`): more of the library is entered without
/// leaving segments in the middle of their motion; 48 took a third of the tones' effect away.
pub const DEFAULT_VARIETY: Variety = Variety {
    recency_cost: 1.0,
    recency_ms: 8000,
    usage_cost: 24.0,
    usage_ms: 45000,
};

/// How a blob follows the voice by default (see `gesture_runtime::follow`): chosen with
/// `gesture-train eval-motion` on tuning speech (the 9-joint ZeroEGGS model and library on
/// its held-out 90-121 s, the 067 model and library on the first 60 s of the 9-joint take's
/// speech; 10 device runs each), never on the speech the README reports. The energy cost
/// brought the pause/speech hand-speed ratio from 0.17-0.28 (at 1) to 0.05-0.10 and the
/// speech coupling from 0.30/0.58 to 0.52/0.65 (the captures: 0.55/0.62); 3 and 4 gave no
/// more. Resting after two pause steps (500 ms) leaves the short breaths of a sentence alone.
pub const DEFAULT_FOLLOW: VoiceFollow = VoiceFollow {
    rest_ms: 500,
    rest_cost: 4.0,
    energy_cost: 2.0,
};

/// Inertialization time at cuts a blob gets by default (ms).
pub const DEFAULT_BLEND_MS: u32 = 400;

/// Settings of a pack.
#[derive(Clone, Debug)]
pub struct PackOptions {
    /// Rig file (default: every rotation channel of the library's skeleton).
    pub rig: Option<PathBuf>,
    /// Largest blob in bytes.
    pub budget_bytes: Option<usize>,
    /// Control-layer settings.
    pub control: ControlParams,
    /// When the device decides (the blob's `control` section).
    pub timing: DecisionTiming,
    /// How the device varies its choices (the blob's `control` section).
    pub variety: Variety,
    /// How the device follows the voice (the blob's `control` section).
    pub follow: VoiceFollow,
    /// Inertialization time at cuts (ms; the blob's `control` section).
    pub blend_ms: u32,
    /// Hold the lower body of a skeleton with legs in a standing pose (see `plant`).
    pub plant_feet: bool,
    /// End effectors for segmenting the library.
    pub effectors: EffectorSpec,
    /// Leave out the host-side skeleton section.
    pub no_skeleton: bool,
    /// Tones (none by default).
    pub styles: StyleOptions,
    /// Semantic labels by library file name (none by default).
    pub labels: Vec<LabelSpec>,
    /// How labels are served.
    pub label_params: LabelParams,
}

/// Tones to pack (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct StyleOptions {
    /// BVH files of neutral motion (needed with `tones`).
    pub neutral: Vec<PathBuf>,
    /// Per tone: its name and the BVH files that show it.
    pub tones: Vec<(String, Vec<PathBuf>)>,
    /// Add the energy knob's tones (`energetic`, `calm`) with this factor (> 1).
    pub energy: Option<f64>,
}

impl Default for PackOptions {
    fn default() -> Self {
        Self {
            rig: None,
            budget_bytes: None,
            control: ControlParams::default(),
            timing: DecisionTiming::default(),
            variety: DEFAULT_VARIETY,
            follow: DEFAULT_FOLLOW,
            blend_ms: DEFAULT_BLEND_MS,
            plant_feet: true,
            effectors: EffectorSpec::default(),
            no_skeleton: false,
            styles: StyleOptions::default(),
            labels: Vec::new(),
            label_params: LabelParams::default(),
        }
    }
}
