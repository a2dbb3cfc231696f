//! One fit of each layer with its sizes given, as [`super::train::fit`] and the model
//! selection ([`super::select`]) both run them: the settings ([`FitConfig`]) and errors
//! ([`FitError`]) of a fit, the kinematic HMM ([`fit_hmm`]), the prosody mixture
//! ([`fit_gmm`]) and the CRF's training sequences ([`train_seqs`]).

use super::crf::TrainSeq;
use super::gmm::{Gmm, GmmConfig, ProsodyPoint};
use super::hmm::{Hmm, HmmConfig, HmmError, Seq};
use super::sequence::{prosody_point, Sequence};
use crate::motion::Normalization;

/// Settings of `fit`. `None` means "choose from the data" (see [`super::select`]).
#[derive(Clone, Copy, Debug)]
pub struct FitConfig {
    /// Hidden states S (`None`: by held-out likelihood).
    pub states: Option<usize>,
    /// Prosody clusters K (`None`: by held-out likelihood).
    pub clusters: Option<usize>,
    /// CRF window W.
    pub window: usize,
    /// HMM restarts.
    pub restarts: usize,
    /// Seed.
    pub seed: u64,
    /// HMM stickiness (see [`HmmConfig::stickiness`]).
    pub stickiness: f64,
    /// CRF L2 strength per training step (`None`: by held-out likelihood).
    pub l2: Option<f64>,
    /// Multiplier of the L2 strength on the CRF's lagged window weights (`None`: by held-out
    /// likelihood; see [`super::crf`]).
    pub lag_penalty: Option<f64>,
    /// Front-end rate the features came from.
    pub sample_rate_hz: u32,
    /// The front-end settings the features were computed with (recorded in the model; the
    /// sample rate is `sample_rate_hz`).
    pub prosody: gesture_runtime::prosody::ProsodyConfig,
}

impl Default for FitConfig {
    fn default() -> Self {
        Self {
            states: None,
            clusters: None,
            window: 4,
            restarts: 16,
            seed: 1,
            stickiness: 0.0,
            l2: None,
            lag_penalty: None,
            sample_rate_hz: gesture_runtime::prosody::DEFAULT_RATE_HZ,
            prosody: gesture_runtime::prosody::ProsodyConfig::DEFAULT,
        }
    }
}

/// Why fitting failed.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// No steps at all.
    #[error(
        "the corpus has no time steps to train on (no syllables or pauses aligned with motion)"
    )]
    NoData,
    /// The HMM refused.
    #[error(transparent)]
    Hmm(#[from] HmmError),
    /// Too few steps for the mixture.
    #[error("{steps} steps are too few for {clusters} prosody clusters: use fewer (--clusters) or more data")]
    Gmm {
        /// Steps.
        steps: usize,
        /// Clusters asked for.
        clusters: usize,
    },
    /// The normalization could not be fitted.
    #[error("kinematic normalization: {0}")]
    Normalization(String),
    /// The optimizer failed.
    #[error("CRF training: {0}")]
    Crf(String),
    /// A setting is out of range.
    #[error("{0}")]
    Settings(String),
}

/// Normalized kinematic sequences.
pub fn normalized(seqs: &[Sequence], norm: &Normalization) -> Vec<Seq> {
    seqs.iter()
        .map(|s| s.y_raw.iter().map(|y| norm.apply(y).to_vec()).collect())
        .collect()
}

/// Memberships of every step.
pub fn memberships(gmm: &Gmm, s: &Sequence) -> Vec<Vec<f64>> {
    s.features
        .iter()
        .map(|f| gmm.memberships(&prosody_point(f)))
        .collect()
}

/// Fits the kinematic HMM on normalized sequences `y`.
pub fn fit_hmm(
    y: &[Seq],
    states: usize,
    cfg: &FitConfig,
    progress: impl Fn(usize, usize, f64) + Sync,
) -> Result<(Hmm, Vec<super::hmm::RunReport>), FitError> {
    let hcfg = HmmConfig {
        states,
        restarts: cfg.restarts,
        seed: cfg.seed,
        stickiness: cfg.stickiness,
        ..HmmConfig::default()
    };
    Ok(Hmm::fit(y, &hcfg, progress)?)
}

/// Fits the prosody mixture on the steps of `seqs`; returns it and its objective per iteration.
pub fn fit_gmm(seqs: &[Sequence], clusters: usize, seed: u64) -> Result<(Gmm, Vec<f64>), FitError> {
    let points: Vec<ProsodyPoint> = seqs
        .iter()
        .flat_map(|s| s.features.iter().map(prosody_point))
        .collect();
    Gmm::fit(
        &points,
        &GmmConfig {
            clusters,
            seed,
            ..GmmConfig::default()
        },
    )
    .ok_or(FitError::Gmm {
        steps: points.len(),
        clusters,
    })
}

/// CRF training sequences: memberships under `gmm`, posteriors under `hmm`.
pub fn train_seqs(hmm: &Hmm, gmm: &Gmm, seqs: &[Sequence], y: &[Seq]) -> Vec<TrainSeq> {
    seqs.iter()
        .zip(y)
        .map(|(s, ys)| TrainSeq::new(memberships(gmm, s), hmm.posterior(ys)))
        .collect()
}
