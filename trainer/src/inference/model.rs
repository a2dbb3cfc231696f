//! The trained inference model and its file: what `gesture-train fit` writes and `pack` reads.
//!
//! A JSON document with a format tag (`gesture-inference-model`) and a version; readers refuse
//! other versions with a message saying which they support. It holds everything needed to turn
//! prosody steps into beliefs and beliefs into expected kinematics: the front-end settings it was
//! trained with, the normalization of the log kinematic parameters, the HMM (its state
//! Gaussians give `P(y | state)`), the prosody mixture and the CRF. Written atomically.

use std::path::Path;

use gesture_runtime::prosody::{PitchParams, ProsodyConfig, SyllableParams};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::crf::Crf;
use super::gaussian::Gaussian;
use super::gmm::{Component, Gmm};
use super::hmm::Hmm;
use crate::motion::Normalization;

/// Format tag of the model file.
pub const FORMAT: &str = "gesture-inference-model";
/// Current version of the model file. Version 2 measures the kinematic parameters in body
/// units (limb lengths, height above the shoulder, derivatives over 1/30 s;
/// [`crate::motion::body`]); version 1 measured them in skeleton units with heights above the
/// floor, so its normalization and state Gaussians do not apply to today's kinematics.
/// Version 3 standardizes each training take by its own level and records the training
/// takes' typical level (`take_level`, required); version 2 files, without it, are still
/// read (their libraries are normalized as they were). An older build refuses a version 3
/// file rather than pack a library in the wrong terms.
pub const VERSION: u32 = 3;

/// The oldest version this build reads.
pub const OLDEST_VERSION: u32 = 2;

/// Why a model file of another version cannot be used.
pub fn version_reason(found: u32) -> &'static str {
    match found {
        1 => "version 1 measured kinematics in skeleton units (cm, height above the floor), this build in limb lengths above the shoulder",
        v if v > VERSION => "it was written by a newer build",
        _ => "its layout is unknown to this build",
    }
}

/// A Gaussian as stored (mean and row-major covariance).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct GaussianFile {
    /// Mean.
    pub mean: Vec<f64>,
    /// Covariance, row-major.
    pub cov: Vec<f64>,
}

impl GaussianFile {
    fn from(g: &Gaussian) -> Self {
        Self {
            mean: g.mean().as_slice().to_vec(),
            cov: g.cov().transpose().as_slice().to_vec(),
        }
    }
    fn to_gaussian(&self) -> Option<Gaussian> {
        let d = self.mean.len();
        if self.cov.len() != d * d {
            return None;
        }
        Gaussian::new(
            DVector::from_vec(self.mean.clone()),
            DMatrix::from_row_slice(d, d, &self.cov),
        )
    }
}

/// The HMM over kinematic parameters.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct HmmFile {
    /// Initial probabilities.
    pub init: Vec<f64>,
    /// Transition matrix, row-major.
    pub trans: Vec<f64>,
    /// State Gaussians over normalized kinematic parameters.
    pub states: Vec<GaussianFile>,
    /// Covariance floor used.
    pub eps: f64,
}

/// One prosody cluster.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ClusterFile {
    /// Mixing weight.
    pub weight: f64,
    /// P(voiced).
    pub voiced: f64,
    /// Gaussian over (intensity, length).
    pub obs: GaussianFile,
    /// F0 regression coefficients.
    pub coef: [f64; 3],
    /// F0 residual variance.
    pub f0_var: f64,
}

/// The CRF weights.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CrfFile {
    /// Window.
    pub window: usize,
    /// Initial weights.
    pub init: Vec<f64>,
    /// Transition weights (row-major from -> to).
    pub trans: Vec<f64>,
    /// Observation weights `[(j * W + w) * K + k]`.
    pub obs: Vec<f64>,
}

/// Front-end settings the model was trained with, all of them (`pack` writes exactly these
/// into the blob, so a later change of the defaults cannot silently change what an old model's
/// device computes). Field meanings: `gesture_runtime::prosody::{PitchParams, SyllableParams}`.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
pub struct FrontEndFile {
    /// Sample rate (Hz).
    pub sample_rate_hz: u32,
    /// Pitch floor (Hz).
    pub pitch_floor_hz: f32,
    /// Pitch ceiling (Hz).
    pub pitch_ceiling_hz: f32,
    /// Pitch silence threshold.
    pub silence_threshold: f32,
    /// Pitch voicing threshold.
    pub voicing_threshold: f32,
    /// Pitch octave cost.
    pub octave_cost: f32,
    /// Pitch octave-jump cost.
    pub octave_jump_cost: f32,
    /// Pitch voiced/unvoiced cost.
    pub voiced_unvoiced_cost: f32,
    /// Syllable margin (dB).
    pub margin_db: f32,
    /// Syllable range (dB).
    pub range_db: f32,
    /// Syllable floor (dB).
    pub floor_db: f32,
    /// Syllable initial peak (dB).
    pub initial_peak_db: f32,
    /// Shortest syllable (frames).
    pub min_frames: u32,
    /// Pause step length (frames).
    pub pause_frames: u32,
}

impl From<&ProsodyConfig> for FrontEndFile {
    fn from(c: &ProsodyConfig) -> Self {
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
}

impl FrontEndFile {
    /// The front-end configuration (not yet validated).
    pub fn config(&self) -> ProsodyConfig {
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

/// The whole model file.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ModelFile {
    /// [`FORMAT`].
    pub format: String,
    /// [`VERSION`].
    pub version: u32,
    /// Front-end settings.
    pub front_end: FrontEndFile,
    /// Normalization of the log kinematic parameters (T, D, V, A, C, H).
    pub normalization: Normalization,
    /// Present when the training takes' kinematics were standardized each by its own level
    /// (see [`InferenceModel::take_level`]): the training takes' typical level. Absent in
    /// models from before it (their libraries are normalized as they were).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub take_level: Option<Normalization>,
    /// HMM.
    pub hmm: HmmFile,
    /// Prosody mixture.
    pub gmm: Vec<ClusterFile>,
    /// CRF.
    pub crf: CrfFile,
    /// State frequencies on the training data (the "prior" baseline).
    pub state_prior: Vec<f64>,
    /// Human-readable training summary.
    pub summary: String,
}

/// A model in memory.
#[derive(Clone, Debug)]
pub struct InferenceModel {
    /// Front-end rate (`prosody.sample_rate_hz`).
    pub sample_rate_hz: u32,
    /// The front-end settings the features were computed with.
    pub prosody: ProsodyConfig,
    /// Kinematic normalization (of the kinematics standardized per take, when `take_level`
    /// is set).
    pub normalization: Normalization,
    /// Each training take's log kinematic parameters were standardized by that take's own
    /// mean and spread (its *level*: how energetic that recording is) before anything else, so
    /// the states describe how a performance varies, not which recording it is, and takes of
    /// one speaker in other sessions, styles or skeletons pool. A library is then put in the
    /// same terms by its own level ([`InferenceModel::library_normalization`]). This is the
    /// training takes' typical level (the step-weighted mean of their levels), for a library
    /// too small to have one. `None` for models from before it.
    pub take_level: Option<Normalization>,
    /// HMM.
    pub hmm: Hmm,
    /// Prosody mixture.
    pub gmm: Gmm,
    /// CRF.
    pub crf: Crf,
    /// State frequencies on the training data.
    pub state_prior: Vec<f64>,
    /// Training summary.
    pub summary: String,
}

/// Why a model file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// I/O.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// Not JSON, or not this format.
    #[error("{path}: not a gesture inference model ({reason})")]
    Format {
        /// The file.
        path: String,
        /// What was wrong.
        reason: String,
    },
    /// Another version.
    #[error("{path}: model format version {found}, this build reads versions {OLDEST_VERSION} to {VERSION} ({reason}): retrain with `gesture-train fit`")]
    Version {
        /// The file.
        path: String,
        /// Version found.
        found: u32,
        /// Why that version cannot be used.
        reason: &'static str,
    },
}

/// Fewest segments a take or library needs to be standardized by its own level; a smaller
/// one takes a fallback level.
pub const MIN_LEVEL_SEGMENTS: usize = 8;

/// The level of a take or library from the log kinematic parameters `raw` of its segments:
/// their mean and spread, or `fallback` with fewer than [`MIN_LEVEL_SEGMENTS`] of them.
pub fn level_of(raw: &[[f64; 6]], fallback: Normalization) -> Normalization {
    if raw.len() >= MIN_LEVEL_SEGMENTS {
        Normalization::fit(raw).unwrap_or(fallback)
    } else {
        fallback
    }
}

impl InferenceModel {
    /// Number of hidden states.
    pub fn states(&self) -> usize {
        self.hmm.states()
    }

    /// The normalization of a library whose segments' log kinematic parameters are `raw`
    /// (all of its segments, every take): with a per-take model, the library's own level
    /// (its segments' mean and spread; the model's training level when it has fewer than
    /// [`MIN_LEVEL_SEGMENTS`]) followed by the model's normalization; otherwise the model's
    /// normalization alone. A library is one performance: a take, or one character's clips.
    pub fn library_normalization(&self, raw: &[[f64; 6]]) -> Normalization {
        match &self.take_level {
            None => self.normalization,
            Some(reference) => level_of(raw, *reference).then(&self.normalization),
        }
    }

    /// The file form.
    pub fn to_file(&self) -> ModelFile {
        ModelFile {
            format: FORMAT.into(),
            // A model read from a version 2 file (no take level) is written as one.
            version: if self.take_level.is_some() {
                VERSION
            } else {
                OLDEST_VERSION
            },
            front_end: FrontEndFile::from(&self.prosody),
            normalization: self.normalization,
            take_level: self.take_level,
            hmm: HmmFile {
                init: self.hmm.init.clone(),
                trans: self.hmm.trans.clone(),
                states: self.hmm.emit.iter().map(GaussianFile::from).collect(),
                eps: self.hmm.eps,
            },
            gmm: self
                .gmm
                .components
                .iter()
                .map(|c| ClusterFile {
                    weight: c.weight,
                    voiced: c.voiced,
                    obs: GaussianFile::from(&c.obs),
                    coef: c.coef,
                    f0_var: c.f0_var,
                })
                .collect(),
            crf: CrfFile {
                window: self.crf.window,
                init: self.crf.init.clone(),
                trans: self.crf.trans.clone(),
                obs: self.crf.obs.clone(),
            },
            state_prior: self.state_prior.clone(),
            summary: self.summary.clone(),
        }
    }

    /// From the file form, checking every dimension.
    pub fn from_file(f: ModelFile, path: &str) -> Result<Self, ModelError> {
        let bad = |reason: String| ModelError::Format {
            path: path.into(),
            reason,
        };
        if f.format != FORMAT {
            return Err(bad(format!("format tag `{}`", f.format)));
        }
        if !(OLDEST_VERSION..=VERSION).contains(&f.version) {
            return Err(ModelError::Version {
                path: path.into(),
                found: f.version,
                reason: version_reason(f.version),
            });
        }
        // Version 3 standardizes per take and must say by what; version 2 did not.
        let take_level = match (f.version, f.take_level) {
            (2, _) => None,
            (_, Some(level)) => Some(level),
            (_, None) => return Err(bad("no take_level (version 3 records it)".into())),
        };
        if let Some(level) = take_level {
            if !level.mean.iter().chain(&level.scale).all(|v| v.is_finite())
                || level.scale.iter().any(|&v| v <= 0.0)
            {
                return Err(bad("take_level is not finite and positive".into()));
            }
        }
        let prosody = f.front_end.config();
        prosody
            .validate()
            .map_err(|e| bad(format!("front-end settings: {e}")))?;
        let s = f.hmm.init.len();
        let k = f.gmm.len();
        let w = f.crf.window;
        // Checked products: a file's dimensions must not wrap around.
        let square = s.checked_mul(s);
        if s == 0
            || Some(f.hmm.trans.len()) != square
            || f.hmm.states.len() != s
            || f.state_prior.len() != s
        {
            return Err(bad("inconsistent HMM dimensions".into()));
        }
        if k == 0
            || w == 0
            || f.crf.init.len() != s
            || Some(f.crf.trans.len()) != square
            || Some(f.crf.obs.len()) != s.checked_mul(w).and_then(|x| x.checked_mul(k))
        {
            return Err(bad("inconsistent CRF dimensions".into()));
        }
        let emit = f
            .hmm
            .states
            .iter()
            .map(|g| g.to_gaussian().filter(|g| g.dim() == 6))
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| bad("a state Gaussian is not a valid 6-D Gaussian".into()))?;
        let components = f
            .gmm
            .iter()
            .map(|c| {
                Some(Component {
                    weight: c.weight,
                    voiced: c.voiced,
                    obs: c.obs.to_gaussian().filter(|g| g.dim() == 2)?,
                    coef: c.coef,
                    f0_var: c.f0_var,
                })
            })
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| bad("a prosody cluster is not valid".into()))?;
        Ok(Self {
            sample_rate_hz: prosody.sample_rate_hz,
            prosody,
            normalization: f.normalization,
            take_level,
            hmm: Hmm {
                init: f.hmm.init,
                trans: f.hmm.trans,
                cov_prior: super::gaussian::CovPrior::floor(6, f.hmm.eps),
                emit,
                eps: f.hmm.eps,
            },
            gmm: Gmm { components },
            crf: Crf {
                states: s,
                clusters: k,
                window: w,
                init: f.crf.init,
                trans: f.crf.trans,
                obs: f.crf.obs,
            },
            state_prior: f.state_prior,
            summary: f.summary,
        })
    }

    /// Writes the model atomically (temporary file, then rename).
    pub fn save(&self, path: &Path) -> Result<(), ModelError> {
        let io = |source| ModelError::Io {
            path: path.display().to_string(),
            source,
        };
        let text = serde_json::to_string_pretty(&self.to_file()).expect("model serializes");
        let tmp = path.with_extension("partial");
        std::fs::write(&tmp, text).map_err(io)?;
        std::fs::rename(&tmp, path).map_err(io)
    }

    /// Reads a model file.
    pub fn load(path: &Path) -> Result<Self, ModelError> {
        let p = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| ModelError::Io {
            path: p.clone(),
            source,
        })?;
        let f: ModelFile = serde_json::from_str(&text).map_err(|e| ModelError::Format {
            path: p.clone(),
            reason: e.to_string(),
        })?;
        Self::from_file(f, &p)
    }
}
