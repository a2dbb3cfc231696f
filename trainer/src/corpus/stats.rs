//! What a user checks about their data before training (`gesture-train corpus-stats`):
//! durations, frames, effectors, segments and their duration quantiles, kinematic
//! parameters, syllables. Speech+motion pairs get the full report; a BVH alone (a gesture
//! library) gets the motion part, a WAV alone the speech part.

use gesture_runtime::prosody::{ProsodyConfig, StepKind};
use serde::Serialize;

use super::{load_take, CorpusError, LoadOptions, Take};
use crate::motion::{analyze, read_bvh, TakeAnalysis};

/// Why a take's statistics could not be computed.
#[derive(Debug, thiserror::Error)]
pub enum StatsError {
    /// Loading a speech+motion pair.
    #[error(transparent)]
    Corpus(#[from] CorpusError),
    /// Reading a BVH file.
    #[error(transparent)]
    Bvh(#[from] crate::motion::BvhError),
    /// Reading a WAV file.
    #[error(transparent)]
    Audio(#[from] crate::audio::AudioError),
    /// Analysing motion or speech.
    #[error("{0}")]
    Analysis(String),
}

/// Summary statistics of one take.
#[derive(Debug, Serialize)]
pub struct TakeStats {
    /// File stem.
    pub stem: String,
    /// Files read.
    pub files: Vec<String>,
    /// Motion length (s), if any motion.
    pub motion_s: Option<f64>,
    /// Audio length (s), if any audio.
    pub audio_s: Option<f64>,
    /// Motion frames.
    pub frames: Option<usize>,
    /// Motion frame rate.
    pub fps: Option<f64>,
    /// Effector joints used.
    pub effectors: Vec<String>,
    /// Segment count.
    pub segments: Option<usize>,
    /// Segment duration quantiles (min, 25%, median, 75%, max), seconds.
    pub segment_s: Option<[f64; 5]>,
    /// Speed threshold used for segmentation (units/s).
    pub threshold: Option<f64>,
    /// Mean and standard deviation of T, D, V, A, C, H (physical units).
    pub kinematics: Option<[[f64; 2]; 6]>,
    /// Syllables found by the front-end.
    pub syllables: Option<usize>,
    /// Pause steps.
    pub pauses: Option<usize>,
    /// Log-scale kinematic vectors of the segments (for the corpus normalization).
    #[serde(skip)]
    pub y_raw: Vec<[f64; 6]>,
}

fn quantiles(mut v: Vec<f64>) -> [f64; 5] {
    v.sort_by(|a, b| a.total_cmp(b));
    let q = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
    [q(0.0), q(0.25), q(0.5), q(0.75), q(1.0)]
}

fn motion_part(s: &mut TakeStats, a: &TakeAnalysis, frames: usize) {
    s.frames = Some(frames);
    s.fps = Some(1.0 / a.frame_time);
    s.motion_s = Some(frames as f64 * a.frame_time);
    s.effectors = a.effectors.names.clone();
    s.segments = Some(a.segments.len());
    s.y_raw = a.y_raw.clone();
    s.threshold = Some(a.threshold);
    if !a.segments.is_empty() {
        s.segment_s = Some(quantiles(
            a.segments
                .iter()
                .map(|g| g.len() as f64 * a.frame_time)
                .collect(),
        ));
    }
    if !a.kinematics.is_empty() {
        let n = a.kinematics.len() as f64;
        let mut out = [[0.0; 2]; 6];
        for (d, o) in out.iter_mut().enumerate() {
            let vals: Vec<f64> = a.kinematics.iter().map(|k| k.to_array()[d]).collect();
            let m = vals.iter().sum::<f64>() / n;
            let sd = (vals.iter().map(|v| (v - m).powi(2)).sum::<f64>() / n).sqrt();
            *o = [m, sd];
        }
        s.kinematics = Some(out);
    }
}

/// The statistics of one take (a BVH+WAV pair, a BVH alone or a WAV alone).
pub fn take_stats(t: &Take, opts: &LoadOptions) -> Result<TakeStats, StatsError> {
    let mut s = TakeStats {
        stem: t.stem.clone(),
        files: [&t.bvh, &t.wav]
            .iter()
            .filter_map(|p| p.as_ref().map(|p| p.display().to_string()))
            .collect(),
        motion_s: None,
        audio_s: None,
        frames: None,
        fps: None,
        effectors: vec![],
        segments: None,
        segment_s: None,
        threshold: None,
        kinematics: None,
        syllables: None,
        pauses: None,
        y_raw: vec![],
    };
    let count = |steps: &[gesture_runtime::prosody::Step], k: StepKind| {
        steps.iter().filter(|x| x.kind == k).count()
    };
    match (&t.bvh, &t.wav) {
        (Some(b), Some(w)) => {
            let l = load_take(&t.stem, b, w, opts)?;
            motion_part(&mut s, &l.motion, l.motion_frames);
            s.audio_s = Some(l.audio_s);
            s.syllables = Some(count(&l.steps, StepKind::Syllable));
            s.pauses = Some(count(&l.steps, StepKind::Pause));
        }
        (Some(b), None) => {
            let m = read_bvh(b)?;
            let a = analyze(&m, &opts.effectors, &opts.segment)
                .map_err(|e| StatsError::Analysis(format!("{}: {e}", b.display())))?;
            motion_part(&mut s, &a, m.frames());
        }
        (None, Some(w)) => {
            let pcm = crate::audio::load_wav_at(w, ProsodyConfig::DEFAULT.sample_rate_hz)?;
            let (_, steps) = crate::features::prosody_of(&pcm.samples, &ProsodyConfig::DEFAULT)
                .map_err(|e| StatsError::Analysis(format!("{}: {e}", w.display())))?;
            s.audio_s = Some(pcm.duration_s());
            s.syllables = Some(count(&steps, StepKind::Syllable));
            s.pauses = Some(count(&steps, StepKind::Pause));
        }
        (None, None) => {}
    }
    Ok(s)
}
