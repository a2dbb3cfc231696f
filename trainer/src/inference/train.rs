//! The inference-layer pipeline (docs/method.md, "Inference layer", steps 1-3): normalize the
//! kinematic targets, fit the HMM on them, fit the prosody mixture, then train the CRF on the
//! fixed HMM posteriors. What the settings leave open (S, K, the CRF's regularization) is
//! chosen first by held-out likelihood ([`super::select`]).

use std::time::Instant;

use super::crf::{Crf, CrfConfig, TrainSeq};
use super::gmm::Gmm;
use super::hmm::{Hmm, Seq};
use super::model::InferenceModel;
use super::select::{self, Selection};
use crate::motion::Normalization;

pub use super::layers::{
    fit_gmm, fit_hmm, memberships, normalized, train_seqs, FitConfig, FitError,
};
pub use super::sequence::{
    cv_split, cv_split_levels, pooled_levels, prosody_point, sequences, sequences_with_levels,
    take_levels, CvSplit, Sequence,
};

/// What fitting did, for the report.
#[derive(Clone, Debug, Default)]
pub struct FitReport {
    /// Training steps.
    pub steps: usize,
    /// Sequences.
    pub sequences: usize,
    /// Best HMM log-likelihood.
    pub hmm_log_likelihood: f64,
    /// EM iterations of each restart.
    pub hmm_iterations: Vec<usize>,
    /// GMM iterations.
    pub gmm_iterations: usize,
    /// CRF L-BFGS iterations.
    pub crf_iterations: u64,
    /// CRF objective per step.
    pub crf_objective: f64,
    /// CRF L2 used (per step).
    pub l2: f64,
    /// CRF lag penalty used.
    pub lag_penalty: f64,
    /// The model selection, when anything was chosen from the data.
    pub selection: Option<Selection>,
    /// Seconds per stage: model selection, HMM, GMM, CRF.
    pub seconds: [f64; 4],
}

/// The window-independent part of the model: normalization, HMM and prosody mixture, with the
/// normalized training targets and the HMM posteriors the CRF is trained on.
#[derive(Clone, Debug)]
pub struct FitBase {
    /// Kinematic normalization.
    pub normalization: Normalization,
    /// HMM.
    pub hmm: Hmm,
    /// Prosody mixture.
    pub gmm: Gmm,
    /// Normalized kinematic training sequences.
    pub y: Vec<Seq>,
    /// CRF training sequences (memberships and HMM posteriors).
    pub train: Vec<TrainSeq>,
    /// State frequencies on the training data.
    pub state_prior: Vec<f64>,
}

fn check(cfg: &FitConfig) -> Result<(), FitError> {
    use gesture_runtime::inference::{MAX_CLUSTERS, MAX_STATES, MAX_WINDOW};
    let bad =
        |what: &str, max: usize| Err(FitError::Settings(format!("--{what} must be 1 to {max}")));
    if cfg.states.is_some_and(|s| !(1..=MAX_STATES).contains(&s)) {
        return bad("states", MAX_STATES);
    }
    if cfg
        .clusters
        .is_some_and(|k| !(1..=MAX_CLUSTERS).contains(&k))
    {
        return bad("clusters", MAX_CLUSTERS);
    }
    if !(1..=MAX_WINDOW).contains(&cfg.window) {
        return bad("window", MAX_WINDOW);
    }
    for (name, v) in [("l2", cfg.l2), ("lag-penalty", cfg.lag_penalty)] {
        if v.is_some_and(|v| !(v.is_finite() && v >= 0.0)) {
            return Err(FitError::Settings(format!(
                "--{name} must be a finite number >= 0"
            )));
        }
    }
    Ok(())
}

/// Fits normalization, HMM (`states`) and mixture (`clusters`): everything but the CRF.
pub fn fit_base(
    seqs: &[Sequence],
    segment_y: &[[f64; 6]],
    states: usize,
    clusters: usize,
    cfg: &FitConfig,
    report: &mut FitReport,
    log: &(dyn Fn(&str) + Sync),
) -> Result<FitBase, FitError> {
    check(&FitConfig {
        states: Some(states),
        clusters: Some(clusters),
        ..*cfg
    })?;
    let steps: usize = seqs.iter().map(Sequence::len).sum();
    if steps == 0 {
        return Err(FitError::NoData);
    }
    report.steps = steps;
    report.sequences = seqs.len();
    let norm = Normalization::fit(segment_y).map_err(|e| FitError::Normalization(e.to_string()))?;
    let y = normalized(seqs, &norm);

    let t0 = Instant::now();
    let (hmm, runs) = fit_hmm(&y, states, cfg, |r, it, obj| {
        if it % 10 == 0 {
            log(&format!(
                "hmm restart {r} iteration {it}: objective {:.3} per step",
                obj / steps as f64
            ));
        }
    })?;
    report.hmm_iterations = runs.iter().map(|r| r.objective.len()).collect();
    report.hmm_log_likelihood = runs
        .iter()
        .map(|r| r.log_likelihood)
        .fold(f64::NEG_INFINITY, f64::max);
    report.seconds[1] = t0.elapsed().as_secs_f64();
    log(&format!(
        "hmm: {states} states, {} restarts, best log-likelihood {:.3} per step, {:.2} s",
        runs.len(),
        report.hmm_log_likelihood / steps as f64,
        report.seconds[1]
    ));

    let t1 = Instant::now();
    let (gmm, gobj) = fit_gmm(seqs, clusters, cfg.seed)?;
    report.gmm_iterations = gobj.len();
    report.seconds[2] = t1.elapsed().as_secs_f64();
    log(&format!(
        "gmm: {clusters} clusters, {} iterations, log-likelihood {:.3} per step, {:.2} s",
        gobj.len(),
        gobj.last().copied().unwrap_or(0.0) / steps as f64,
        report.seconds[2]
    ));
    let train = train_seqs(&hmm, &gmm, seqs, &y);
    let state_prior = hmm.state_frequencies(&y);
    Ok(FitBase {
        normalization: norm,
        hmm,
        gmm,
        y,
        train,
        state_prior,
    })
}

/// Trains the CRF for window `window` on a fitted base with L2 strength `l2` per training
/// step and lag penalty `lag_penalty` (see [`super::crf`]).
pub fn fit_crf(
    base: &FitBase,
    window: usize,
    l2: f64,
    lag_penalty: f64,
    report: &mut FitReport,
    log: &(dyn Fn(&str) + Sync),
) -> Result<Crf, FitError> {
    let t2 = Instant::now();
    report.l2 = l2;
    report.lag_penalty = lag_penalty;
    let steps = base
        .train
        .iter()
        .map(|q| q.memberships.len())
        .sum::<usize>();
    let center = Crf::prior(&base.state_prior, base.gmm.components.len(), window);
    // `l2` is per training step: the objective is a sum over steps, so the penalty scales
    // with them and the regularization strength does not depend on the corpus size.
    let (crf, crep) = Crf::fit(
        &base.train,
        &center,
        None,
        &CrfConfig {
            window,
            l2: l2 * steps.max(1) as f64,
            lag_penalty,
            ..CrfConfig::default()
        },
    )
    .map_err(FitError::Crf)?;
    report.crf_iterations = crep.iterations;
    report.crf_objective = crep.objective / steps.max(1) as f64;
    report.seconds[3] = t2.elapsed().as_secs_f64();
    log(&format!(
        "crf: window {window}, l2 {l2}, lag penalty {lag_penalty}, {} L-BFGS iterations ({}), \
         objective {:.4} per step, {:.2} s",
        crep.iterations, crep.termination, report.crf_objective, report.seconds[3]
    ));
    Ok(crf)
}

/// The training takes' typical level: their levels' means and spreads averaged, each
/// sequence weighted by its steps.
fn typical_level(seqs: &[Sequence]) -> Normalization {
    let steps: f64 = seqs.iter().map(|s| s.len() as f64).sum();
    if steps <= 0.0 {
        return Normalization::identity();
    }
    let avg = |f: &dyn Fn(&Normalization) -> [f64; 6]| -> [f64; 6] {
        std::array::from_fn(|d| {
            seqs.iter()
                .map(|s| f(&s.level)[d] * s.len() as f64)
                .sum::<f64>()
                / steps
        })
    };
    Normalization {
        mean: avg(&|n| n.mean),
        scale: avg(&|n| n.scale),
    }
}

/// Fits the whole inference layer, choosing what `cfg` leaves open by held-out likelihood
/// ([`super::select`]). `log` receives progress lines.
pub fn fit(
    seqs: &[Sequence],
    segment_y: &[[f64; 6]],
    cfg: &FitConfig,
    log: &(dyn Fn(&str) + Sync),
) -> Result<(InferenceModel, FitReport), FitError> {
    check(cfg)?;
    let mut report = FitReport::default();
    let t0 = Instant::now();
    let choice = select::choose(seqs, segment_y, cfg, &[cfg.window], log)?;
    report.seconds[0] = t0.elapsed().as_secs_f64();
    let (states, clusters) = (choice.states, choice.clusters);
    let (l2, lag_penalty) = choice.regularization[0];
    report.selection = choice.selection;
    let base = fit_base(seqs, segment_y, states, clusters, cfg, &mut report, log)?;
    let crf = fit_crf(&base, cfg.window, l2, lag_penalty, &mut report, log)?;
    let summary = format!(
        "{} steps in {} sequence{}; S={states} K={clusters} W={} l2={l2} lag penalty={lag_penalty}; \
         HMM ll/step {:.3}; CRF objective/step {:.4}",
        report.steps,
        seqs.len(),
        if seqs.len() == 1 { "" } else { "s" },
        cfg.window,
        report.hmm_log_likelihood / report.steps as f64,
        report.crf_objective
    );
    Ok((
        InferenceModel {
            sample_rate_hz: cfg.sample_rate_hz,
            prosody: gesture_runtime::prosody::ProsodyConfig {
                sample_rate_hz: cfg.sample_rate_hz,
                ..cfg.prosody
            },
            normalization: base.normalization,
            take_level: Some(typical_level(seqs)),
            hmm: base.hmm,
            gmm: base.gmm,
            crf,
            state_prior: base.state_prior,
            summary,
        },
        report,
    ))
}
