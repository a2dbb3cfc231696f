//! The inference-layer pipeline (DESIGN.md, inference layer steps 1-3): normalize the
//! kinematic targets, fit the HMM on them, fit the prosody mixture, then train the CRF on the
//! fixed HMM posteriors.

use std::time::Instant;

use gesture_runtime::inference::StepFeatures;

use super::crf::{Crf, CrfConfig, TrainSeq};
use super::gmm::{Gmm, GmmConfig, ProsodyPoint};
use super::hmm::{Hmm, HmmConfig, HmmError, Seq};
use super::model::InferenceModel;
use crate::corpus::Corpus;
use crate::motion::Normalization;

/// One training or test sequence: a take's steps (optionally a time span of it).
#[derive(Clone, Debug, Default)]
pub struct Sequence {
    /// The take's file stem.
    pub stem: String,
    /// Normalized prosody features per step (from the runtime).
    pub features: Vec<StepFeatures>,
    /// Log kinematic target per step (not normalized).
    pub y_raw: Vec<[f64; 6]>,
    /// Step start and end times (s).
    pub times: Vec<(f64, f64)>,
}

impl Sequence {
    /// Number of steps.
    pub fn len(&self) -> usize {
        self.features.len()
    }
    /// Whether empty.
    pub fn is_empty(&self) -> bool {
        self.features.is_empty()
    }
}

/// The sequences of a corpus, keeping steps whose midpoint lies in `span` (seconds), and the
/// log kinematic vectors of the segments inside the span (for the normalization).
pub fn sequences(corpus: &Corpus, span: Option<(f64, f64)>) -> (Vec<Sequence>, Vec<[f64; 6]>) {
    let inside =
        |a: f64, b: f64| span.is_none_or(|(s0, s1)| (0.5 * (a + b)) >= s0 && (0.5 * (a + b)) < s1);
    let mut seqs = Vec::new();
    let mut segs = Vec::new();
    for t in &corpus.takes {
        let mut s = Sequence {
            stem: t.stem.clone(),
            ..Sequence::default()
        };
        for a in &t.aligned {
            let (t0, t1) = (a.step.start_s(), a.step.end_s());
            if inside(t0, t1) {
                s.features.push(a.features);
                s.y_raw.push(a.y_raw);
                s.times.push((t0, t1));
            }
        }
        let dt = t.motion.frame_time;
        for (g, y) in t.motion.segments.iter().zip(&t.motion.y_raw) {
            if inside(g.start_frame as f64 * dt, g.end_frame as f64 * dt) {
                segs.push(*y);
            }
        }
        if !s.is_empty() {
            seqs.push(s);
        }
    }
    (seqs, segs)
}

/// The mixture's view of a step.
pub fn prosody_point(f: &StepFeatures) -> ProsodyPoint {
    ProsodyPoint {
        f0: f.f0.map(|v| v as f64),
        obs: [f.obs[0] as f64, f.obs[1] as f64],
    }
}

/// Settings of `fit`.
#[derive(Clone, Copy, Debug)]
pub struct FitConfig {
    /// Hidden states S.
    pub states: usize,
    /// Prosody clusters K.
    pub clusters: usize,
    /// CRF window W.
    pub window: usize,
    /// HMM restarts.
    pub restarts: usize,
    /// Seed.
    pub seed: u64,
    /// HMM stickiness (see [`HmmConfig::stickiness`]).
    pub stickiness: f64,
    /// CRF L2 strength per training step; `None` chooses it by validation (see [`choose_l2`]).
    pub l2: Option<f64>,
    /// Front-end rate the features came from.
    pub sample_rate_hz: u32,
}

impl Default for FitConfig {
    fn default() -> Self {
        Self {
            states: 12,
            clusters: 12,
            window: 4,
            restarts: 16,
            seed: 1,
            stickiness: 0.0,
            l2: None,
            sample_rate_hz: gesture_runtime::prosody::DEFAULT_RATE_HZ,
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
    /// Seconds per stage: HMM, GMM, CRF.
    pub seconds: [f64; 3],
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
    if !(1..=MAX_STATES).contains(&cfg.states) {
        return bad("states", MAX_STATES);
    }
    if !(1..=MAX_CLUSTERS).contains(&cfg.clusters) {
        return bad("clusters", MAX_CLUSTERS);
    }
    if !(1..=MAX_WINDOW).contains(&cfg.window) {
        return bad("window", MAX_WINDOW);
    }
    Ok(())
}

/// Fits normalization, HMM and mixture (everything but the CRF).
pub fn fit_base(
    seqs: &[Sequence],
    segment_y: &[[f64; 6]],
    cfg: &FitConfig,
    report: &mut FitReport,
    log: &(dyn Fn(&str) + Sync),
) -> Result<FitBase, FitError> {
    check(cfg)?;
    let steps: usize = seqs.iter().map(Sequence::len).sum();
    if steps == 0 {
        return Err(FitError::NoData);
    }
    report.steps = steps;
    report.sequences = seqs.len();
    let norm = Normalization::fit(segment_y).map_err(|e| FitError::Normalization(e.to_string()))?;
    let y = normalized(seqs, &norm);

    let t0 = Instant::now();
    let hcfg = HmmConfig {
        states: cfg.states,
        restarts: cfg.restarts,
        seed: cfg.seed,
        stickiness: cfg.stickiness,
        ..HmmConfig::default()
    };
    let (hmm, runs) = Hmm::fit(&y, &hcfg, |r, it, obj| {
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
    report.seconds[0] = t0.elapsed().as_secs_f64();
    log(&format!(
        "hmm: {} states, {} restarts, best log-likelihood {:.3} per step, {:.2} s",
        cfg.states,
        runs.len(),
        report.hmm_log_likelihood / steps as f64,
        report.seconds[0]
    ));

    let t1 = Instant::now();
    let points: Vec<ProsodyPoint> = seqs
        .iter()
        .flat_map(|s| s.features.iter().map(prosody_point))
        .collect();
    let (gmm, gobj) = Gmm::fit(
        &points,
        &GmmConfig {
            clusters: cfg.clusters,
            seed: cfg.seed,
            ..GmmConfig::default()
        },
    )
    .ok_or(FitError::Gmm {
        steps,
        clusters: cfg.clusters,
    })?;
    report.gmm_iterations = gobj.len();
    report.seconds[1] = t1.elapsed().as_secs_f64();
    log(&format!(
        "gmm: {} clusters, {} iterations, log-likelihood {:.3} per step, {:.2} s",
        cfg.clusters,
        gobj.len(),
        gobj.last().copied().unwrap_or(0.0) / steps as f64,
        report.seconds[1]
    ));
    let train: Vec<TrainSeq> = seqs
        .iter()
        .zip(&y)
        .map(|(s, ys)| TrainSeq::new(memberships(&gmm, s), hmm.posterior(ys)))
        .collect();
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

/// Candidate L2 strengths (per step) tried by [`choose_l2`].
pub const L2_GRID: [f64; 4] = [1e-3, 1e-2, 0.1, 0.3];

/// Chooses the CRF's L2 strength by validation: trains on the first 80% of every training
/// sequence and scores the last 20% with the CRF's own objective (expected log-likelihood of
/// the HMM posteriors, no penalty), for each value of [`L2_GRID`]. How much to regularize
/// depends on how much data there is and how predictable the states are from prosody, so it
/// is measured rather than fixed. Returns the best value and its held-out score per step.
pub fn choose_l2(
    base: &FitBase,
    window: usize,
    log: &(dyn Fn(&str) + Sync),
) -> Result<(f64, f64), FitError> {
    let (fit_part, held): (Vec<TrainSeq>, Vec<TrainSeq>) = base
        .train
        .iter()
        .zip(&base.y)
        .filter(|(q, _)| q.memberships.len() >= 10)
        .map(|(q, y)| {
            let cut = q.memberships.len() * 4 / 5;
            let part = |r: std::ops::Range<usize>| {
                TrainSeq::new(q.memberships[r.clone()].to_vec(), base.hmm.posterior(&y[r]))
            };
            (part(0..cut), part(cut..q.memberships.len()))
        })
        .unzip();
    let held_steps: usize = held.iter().map(|q| q.memberships.len()).sum();
    let fit_steps: usize = fit_part.iter().map(|q| q.memberships.len()).sum();
    if held_steps == 0 {
        return Ok((1e-2, f64::NAN));
    }
    let k = base.gmm.components.len();
    let center = Crf::prior(&base.state_prior, k, window);
    let mut best = (L2_GRID[0], f64::NEG_INFINITY);
    for &l2 in &L2_GRID {
        let cfg = CrfConfig {
            window,
            l2: l2 * fit_steps as f64,
            ..CrfConfig::default()
        };
        let (crf, _) = Crf::fit(&fit_part, &center, None, &cfg).map_err(FitError::Crf)?;
        let score = crf.expected_log_likelihood(&held) / held_steps as f64;
        log(&format!(
            "crf: window {window}, l2 {l2}: held-out objective {score:.4} per step"
        ));
        if score > best.1 {
            best = (l2, score);
        }
    }
    Ok(best)
}

/// Trains the CRF for window `window` on a fitted base (`l2` per step; `None`: by validation).
pub fn fit_crf(
    base: &FitBase,
    window: usize,
    l2: Option<f64>,
    report: &mut FitReport,
    log: &(dyn Fn(&str) + Sync),
) -> Result<Crf, FitError> {
    let t2 = Instant::now();
    let l2 = match l2 {
        Some(v) => v,
        None => choose_l2(base, window, log)?.0,
    };
    report.l2 = l2;
    // `l2` is per training step: the objective is a sum over steps, so the penalty scales
    // with them and the regularization strength does not depend on the corpus size.
    let center = Crf::prior(&base.state_prior, base.gmm.components.len(), window);
    let (crf, crep) = Crf::fit(
        &base.train,
        &center,
        None,
        &CrfConfig {
            window,
            l2: l2 * report.steps.max(1) as f64,
            ..CrfConfig::default()
        },
    )
    .map_err(FitError::Crf)?;
    report.crf_iterations = crep.iterations;
    report.crf_objective = crep.objective / report.steps.max(1) as f64;
    report.seconds[2] = t2.elapsed().as_secs_f64();
    log(&format!(
        "crf: window {window}, l2 {l2}, {} L-BFGS iterations ({}), objective {:.4} per step, {:.2} s",
        crep.iterations, crep.termination, report.crf_objective, report.seconds[2]
    ));
    Ok(crf)
}

/// Fits the whole inference layer. `log` receives progress lines.
pub fn fit(
    seqs: &[Sequence],
    segment_y: &[[f64; 6]],
    cfg: &FitConfig,
    log: &(dyn Fn(&str) + Sync),
) -> Result<(InferenceModel, FitReport), FitError> {
    let mut report = FitReport::default();
    let base = fit_base(seqs, segment_y, cfg, &mut report, log)?;
    let crf = fit_crf(&base, cfg.window, cfg.l2, &mut report, log)?;
    let summary = format!(
        "{} steps in {} sequences; S={} K={} W={} l2={}; HMM ll/step {:.3}; CRF objective/step {:.4}",
        report.steps,
        seqs.len(),
        cfg.states,
        cfg.clusters,
        cfg.window,
        report.l2,
        report.hmm_log_likelihood / report.steps as f64,
        report.crf_objective
    );
    Ok((
        InferenceModel {
            sample_rate_hz: cfg.sample_rate_hz,
            normalization: base.normalization,
            hmm: base.hmm,
            gmm: base.gmm,
            crf,
            state_prior: base.state_prior,
            summary,
        },
        report,
    ))
}
