//! The inference-layer pipeline (docs/method.md, "Inference layer", steps 1-3): normalize the
//! kinematic targets, fit the HMM on them, fit the prosody mixture, then train the CRF on the
//! fixed HMM posteriors. What the settings leave open (S, K, the CRF's regularization) is
//! chosen first by held-out likelihood ([`super::select`]).

use std::collections::HashMap;
use std::time::Instant;

use gesture_runtime::inference::StepFeatures;

use super::crf::{Crf, CrfConfig, TrainSeq};
use super::gmm::{Gmm, GmmConfig, ProsodyPoint};
use super::hmm::{Hmm, HmmConfig, HmmError, Seq};
use super::model::{level_of, InferenceModel};
use super::select::{self, Selection};
use crate::corpus::Corpus;
use crate::motion::Normalization;

/// One training or test sequence: a take's steps (optionally a time span of it).
#[derive(Clone, Debug, Default)]
pub struct Sequence {
    /// The take's file stem.
    pub stem: String,
    /// Normalized prosody features per step (from the runtime).
    pub features: Vec<StepFeatures>,
    /// Log kinematic target per step, standardized by its take's level (see `level`), not yet
    /// by the model's normalization.
    pub y_raw: Vec<[f64; 6]>,
    /// Step start and end times (s).
    pub times: Vec<(f64, f64)>,
    /// Start and end times (s) of the take's motion segments (for purging held-out data,
    /// see [`super::select`]).
    pub segments: Vec<(f64, f64)>,
    /// The take's level: the mean and spread of its segments' log kinematic parameters (in
    /// the span used for training), which `y_raw` is standardized by
    /// ([`super::model::InferenceModel::take_level`]).
    pub level: Normalization,
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

    /// The steps in `range` (same take, same segments).
    pub fn slice(&self, range: std::ops::Range<usize>) -> Sequence {
        Sequence {
            stem: self.stem.clone(),
            features: self.features[range.clone()].to_vec(),
            y_raw: self.y_raw[range.clone()].to_vec(),
            times: self.times[range].to_vec(),
            segments: self.segments.clone(),
            level: self.level,
        }
    }
}

/// Whether the span `a..b` overlaps `lo..hi` (false when either bound is NaN).
fn overlaps(a: f64, b: f64, lo: f64, hi: f64) -> bool {
    a < hi && b > lo
}

/// The segments of a take inside `span` (by midpoint): `(start_s, end_s, raw vector)`.
fn take_segments(
    t: &crate::corpus::LoadedTake,
    inside: impl Fn(f64, f64) -> bool,
) -> Vec<(f64, f64, [f64; 6])> {
    let dt = t.motion.frame_time;
    t.motion
        .segments
        .iter()
        .zip(&t.motion.y_raw)
        .map(|(g, y)| (g.start_frame as f64 * dt, g.end_frame as f64 * dt, *y))
        .filter(|&(g0, g1, _)| inside(g0, g1))
        .collect()
}

fn in_span(span: Option<(f64, f64)>) -> impl Fn(f64, f64) -> bool {
    move |a: f64, b: f64| span.is_none_or(|(s0, s1)| (0.5 * (a + b)) >= s0 && (0.5 * (a + b)) < s1)
}

/// Each take's level ([`super::model::InferenceModel::take_level`]) from its segments inside
/// `span`; a take with too few takes the level of all of them together.
pub fn take_levels(corpus: &Corpus, span: Option<(f64, f64)>) -> HashMap<String, Normalization> {
    let inside = in_span(span);
    let per_take: Vec<(String, Vec<[f64; 6]>)> = corpus
        .takes
        .iter()
        .map(|t| {
            let raw = take_segments(t, &inside).into_iter().map(|g| g.2).collect();
            (t.stem.clone(), raw)
        })
        .collect();
    let all: Vec<[f64; 6]> = per_take
        .iter()
        .flat_map(|(_, r)| r.iter().copied())
        .collect();
    let pooled = level_of(&all, Normalization::identity());
    per_take
        .into_iter()
        .map(|(stem, raw)| (stem, level_of(&raw, pooled)))
        .collect()
}

/// Every take's level as one: the level of all takes' segments inside `span` together (each
/// take standardized alike, so the corpus normalization alone puts them in the model's
/// terms, as before takes had levels of their own; `eval-inference --take-level pooled`).
pub fn pooled_levels(corpus: &Corpus, span: Option<(f64, f64)>) -> HashMap<String, Normalization> {
    let inside = in_span(span);
    let all: Vec<[f64; 6]> = corpus
        .takes
        .iter()
        .flat_map(|t| take_segments(t, &inside).into_iter().map(|g| g.2))
        .collect();
    let pooled = level_of(&all, Normalization::identity());
    corpus
        .takes
        .iter()
        .map(|t| (t.stem.clone(), pooled))
        .collect()
}

/// The sequences of a corpus, keeping steps whose midpoint lies in `span` (seconds), and the
/// log kinematic vectors of the segments inside the span (for the normalization), each take
/// standardized by its level ([`take_levels`] over the same span).
pub fn sequences(corpus: &Corpus, span: Option<(f64, f64)>) -> (Vec<Sequence>, Vec<[f64; 6]>) {
    sequences_with_levels(corpus, span, &take_levels(corpus, span))
}

/// [`sequences`] with given take levels: a take named in `levels` is standardized by that
/// level (a test span of a training take, by the training span's), any other by its own
/// segments inside `span`.
pub fn sequences_with_levels(
    corpus: &Corpus,
    span: Option<(f64, f64)>,
    levels: &HashMap<String, Normalization>,
) -> (Vec<Sequence>, Vec<[f64; 6]>) {
    let own = if corpus.takes.iter().all(|t| levels.contains_key(&t.stem)) {
        HashMap::new()
    } else {
        take_levels(corpus, span)
    };
    let inside = in_span(span);
    let mut seqs = Vec::new();
    let mut segs = Vec::new();
    for t in &corpus.takes {
        let level = levels
            .get(&t.stem)
            .or_else(|| own.get(&t.stem))
            .copied()
            .unwrap_or_else(Normalization::identity);
        let mut s = Sequence {
            stem: t.stem.clone(),
            level,
            ..Sequence::default()
        };
        for a in &t.aligned {
            let (t0, t1) = (a.step.start_s(), a.step.end_s());
            if inside(t0, t1) {
                s.features.push(a.features);
                s.y_raw.push(level.apply(&a.y_raw));
                s.times.push((t0, t1));
            }
        }
        let dt = t.motion.frame_time;
        for g in &t.motion.segments {
            s.segments
                .push((g.start_frame as f64 * dt, g.end_frame as f64 * dt));
        }
        segs.extend(take_segments(t, &inside).iter().map(|g| level.apply(&g.2)));
        if !s.is_empty() {
            seqs.push(s);
        }
    }
    (seqs, segs)
}

/// One fold of a cross-validation over time ([`cv_split`]).
#[derive(Clone, Debug, Default)]
pub struct CvSplit {
    /// Training sequences: every step of the takes not held out, and the steps of the held-out
    /// takes before and after the held-out span (separate sequences), less the steps that
    /// share a motion segment with it.
    pub train: Vec<Sequence>,
    /// Log kinematic vectors of the training segments (for the normalization).
    pub segments: Vec<[f64; 6]>,
    /// The held-out steps.
    pub test: Vec<Sequence>,
}

/// Fold `fold` of `folds` over time: each take whose stem `held` accepts has the span
/// `[fold, fold + 1) / folds` of its motion held out (steps by their midpoint); training
/// keeps the rest of the corpus, less every step and segment that overlaps a motion segment
/// reaching into the held-out span (purged, as model selection's folds are: a segment spans
/// several steps, so its neighbours would carry the held-out motion into training).
pub fn cv_split(
    corpus: &Corpus,
    fold: usize,
    folds: usize,
    held: impl Fn(&str) -> bool,
) -> CvSplit {
    cv_split_levels(corpus, fold, folds, held, true)
}

/// [`cv_split`], with `own_levels` false every take standardized by the level of all training
/// segments together ([`pooled_levels`]) instead of its own.
pub fn cv_split_levels(
    corpus: &Corpus,
    fold: usize,
    folds: usize,
    held: impl Fn(&str) -> bool,
    own_levels: bool,
) -> CvSplit {
    let mut out = CvSplit::default();
    let folds = folds.max(1);
    // Each take is standardized by the level of its training segments (the held-out span's
    // own kinematics are not looked at); a take with too few, by all training segments'.
    let mut parts = Vec::with_capacity(corpus.takes.len());
    for t in &corpus.takes {
        let segs = take_segments(t, |_, _| true);
        let (lo, hi, plo, phi) = if held(&t.stem) {
            let len = t.motion_s();
            // The last span takes whatever lies past the motion's end too (audio a little
            // longer than the motion), so every step is held out once.
            let hi = if fold + 1 >= folds {
                f64::INFINITY
            } else {
                len * (fold + 1) as f64 / folds as f64
            };
            let lo = len * fold as f64 / folds as f64;
            let (mut plo, mut phi) = (lo, hi);
            for &(g0, g1, _) in &segs {
                if overlaps(g0, g1, lo, hi) {
                    plo = plo.min(g0);
                    phi = phi.max(g1);
                }
            }
            (lo, hi, plo, phi)
        } else {
            (f64::NAN, f64::NAN, f64::NAN, f64::NAN)
        };
        parts.push((t, segs, lo, hi, plo, phi));
    }
    // The segments left for training, as raw vectors.
    let trained = |segs: &[(f64, f64, [f64; 6])], plo: f64, phi: f64| -> Vec<[f64; 6]> {
        segs.iter()
            .filter(|g| !overlaps(g.0, g.1, plo, phi))
            .map(|g| g.2)
            .collect()
    };
    let all: Vec<[f64; 6]> = parts
        .iter()
        .flat_map(|(_, segs, _, _, plo, phi)| trained(segs, *plo, *phi))
        .collect();
    let pooled = level_of(&all, Normalization::identity());
    for (t, segs, lo, hi, plo, phi) in parts {
        let train_segs = trained(&segs, plo, phi);
        let level = if own_levels {
            level_of(&train_segs, pooled)
        } else {
            pooled
        };
        let is_held = |a: f64, b: f64| {
            let mid = 0.5 * (a + b);
            mid >= lo && mid < hi
        };
        let times: Vec<(f64, f64)> = segs.iter().map(|g| (g.0, g.1)).collect();
        let empty = || Sequence {
            stem: t.stem.clone(),
            segments: times.clone(),
            level,
            ..Sequence::default()
        };
        let (mut before, mut after, mut test) = (empty(), empty(), empty());
        for a in &t.aligned {
            let (t0, t1) = (a.step.start_s(), a.step.end_s());
            let into = if is_held(t0, t1) {
                &mut test
            } else if overlaps(t0, t1, plo, phi) {
                continue;
            } else if t0 >= phi {
                &mut after
            } else {
                &mut before
            };
            into.features.push(a.features);
            into.y_raw.push(level.apply(&a.y_raw));
            into.times.push((t0, t1));
        }
        out.segments
            .extend(train_segs.iter().map(|y| level.apply(y)));
        out.train
            .extend([before, after].into_iter().filter(|s| !s.is_empty()));
        if !test.is_empty() {
            out.test.push(test);
        }
    }
    out
}

/// The mixture's view of a step.
pub fn prosody_point(f: &StepFeatures) -> ProsodyPoint {
    ProsodyPoint {
        f0: f.f0.map(|v| v as f64),
        obs: [f.obs[0] as f64, f.obs[1] as f64],
    }
}

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
