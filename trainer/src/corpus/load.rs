//! Loading a corpus: each speech+motion take's motion analysis (effectors, segments, kinematic
//! parameters) and prosody (frames and steps from the runtime front-end), in parallel.
//!
//! Audio and motion must cover the same time: when their lengths differ by more than
//! [`LoadOptions::max_mismatch_s`] the take is refused with both lengths in the message (a
//! common slip is pairing a trimmed WAV with an untrimmed BVH). Within the tolerance, steps are
//! aligned on the part both cover.

use std::path::{Path, PathBuf};
use std::time::Instant;

use gesture_runtime::prosody::{Frame, ProsodyConfig, Step};
use rayon::prelude::*;

use super::align::{align, AlignedStep};
use super::discover::{discover, DiscoverError, Take};
use crate::audio::{load_wav_at, AudioError};
use crate::motion::{
    analyze, read_bvh, AnalysisError, BvhError, EffectorSpec, SegmentParams, TakeAnalysis,
};

/// How to load a corpus.
#[derive(Clone, Debug)]
pub struct LoadOptions {
    /// End effectors (both hands by default).
    pub effectors: EffectorSpec,
    /// Motion segmentation.
    pub segment: SegmentParams,
    /// Prosody front-end settings.
    pub prosody: ProsodyConfig,
    /// Largest accepted difference between audio and motion length (s).
    pub max_mismatch_s: f64,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            effectors: EffectorSpec::default(),
            segment: SegmentParams::default(),
            prosody: ProsodyConfig::DEFAULT,
            max_mismatch_s: 0.5,
        }
    }
}

/// Why a corpus could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum CorpusError {
    /// Listing the inputs failed.
    #[error(transparent)]
    Discover(#[from] DiscoverError),
    /// A BVH file is bad.
    #[error(transparent)]
    Bvh(#[from] BvhError),
    /// A WAV file is bad.
    #[error(transparent)]
    Audio(#[from] AudioError),
    /// The motion could not be analysed (e.g. no effector found).
    #[error("{}: {source}", path.display())]
    Analysis {
        /// The BVH file.
        path: PathBuf,
        /// The cause.
        source: AnalysisError,
    },
    /// Audio and motion lengths differ.
    #[error(
        "{}: audio is {audio_s:.2} s but motion is {motion_s:.2} s (more than {tolerance_s} s apart): \
         trim them to the same take",
        path.display()
    )]
    LengthMismatch {
        /// The WAV file.
        path: PathBuf,
        /// Audio length.
        audio_s: f64,
        /// Motion length.
        motion_s: f64,
        /// Tolerance.
        tolerance_s: f64,
    },
    /// No take had both files.
    #[error("no speech+motion pairs (a .bvh and a .wav with the same stem) in {0}")]
    NoPairs(String),
    /// The front-end configuration is invalid.
    #[error("prosody settings: {0}")]
    Prosody(gesture_runtime::prosody::ConfigError),
}

/// One loaded speech+motion take.
#[derive(Clone, Debug)]
pub struct LoadedTake {
    /// File stem.
    pub stem: String,
    /// The BVH file.
    pub bvh: PathBuf,
    /// The WAV file.
    pub wav: PathBuf,
    /// Audio length (s).
    pub audio_s: f64,
    /// Motion analysis.
    pub motion: TakeAnalysis,
    /// Motion frames.
    pub motion_frames: usize,
    /// Prosody frames.
    pub frames: Vec<Frame>,
    /// Prosody steps (syllables and pauses).
    pub steps: Vec<Step>,
    /// Steps with their features and kinematic targets.
    pub aligned: Vec<AlignedStep>,
}

impl LoadedTake {
    /// Motion length (s).
    pub fn motion_s(&self) -> f64 {
        self.motion_frames as f64 * self.motion.frame_time
    }
}

/// A loaded corpus.
#[derive(Clone, Debug)]
pub struct Corpus {
    /// The takes, sorted by stem.
    pub takes: Vec<LoadedTake>,
    /// Inputs that were not pairs (listed so commands can say what they ignored).
    pub ignored: Vec<Take>,
    /// Wall time of loading (s).
    pub load_s: f64,
}

/// Loads one take.
pub fn load_take(
    stem: &str,
    bvh: &Path,
    wav: &Path,
    opts: &LoadOptions,
) -> Result<LoadedTake, CorpusError> {
    let motion = read_bvh(bvh)?;
    let pcm = load_wav_at(wav, opts.prosody.sample_rate_hz)?;
    let audio_s = pcm.duration_s();
    let motion_s = motion.duration();
    if (audio_s - motion_s).abs() > opts.max_mismatch_s {
        return Err(CorpusError::LengthMismatch {
            path: wav.to_path_buf(),
            audio_s,
            motion_s,
            tolerance_s: opts.max_mismatch_s,
        });
    }
    let analysis = analyze(&motion, &opts.effectors, &opts.segment).map_err(|source| {
        CorpusError::Analysis {
            path: bvh.to_path_buf(),
            source,
        }
    })?;
    let (frames, steps) =
        crate::features::prosody_of(&pcm.samples, &opts.prosody).map_err(CorpusError::Prosody)?;
    let aligned = align(&steps, &analysis, motion.frames());
    Ok(LoadedTake {
        stem: stem.to_string(),
        bvh: bvh.to_path_buf(),
        wav: wav.to_path_buf(),
        audio_s,
        motion_frames: motion.frames(),
        motion: analysis,
        frames,
        steps,
        aligned,
    })
}

/// Loads every speech+motion pair in `inputs` (files or folders), in parallel.
pub fn load_corpus(inputs: &[PathBuf], opts: &LoadOptions) -> Result<Corpus, CorpusError> {
    let start = Instant::now();
    let all = discover(inputs)?;
    let (pairs, ignored): (Vec<Take>, Vec<Take>) = all.into_iter().partition(Take::is_pair);
    let pairs: Vec<(String, PathBuf, PathBuf)> = pairs
        .into_iter()
        .filter_map(|t| Some((t.stem, t.bvh?, t.wav?)))
        .collect();
    if pairs.is_empty() {
        let names: Vec<String> = inputs.iter().map(|p| p.display().to_string()).collect();
        return Err(CorpusError::NoPairs(names.join(", ")));
    }
    let takes = pairs
        .par_iter()
        .map(|(stem, bvh, wav)| load_take(stem, bvh, wav, opts))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Corpus {
        takes,
        ignored,
        load_s: start.elapsed().as_secs_f64(),
    })
}
