//! The paper's Fig. 4 comparison (docs/method.md, "Inference layer", step 5): how well each
//! method's *online* belief over states explains held-out kinematics. [`evaluate`] is the
//! whole of `gesture-train eval-inference`: fit on a training corpus (choosing what is left
//! open, see [`super::select`]), score each window on a test corpus, report the CRF's gain
//! over the prior.
//!
//! Score of a test step: `log sum_i b_t(i) N(y_t; mu_i, Sigma_i)`, `y_t` the step's normalized
//! kinematic target and `N(.; mu_i, Sigma_i)` the kinematic HMM's state Gaussians; reported as
//! the mean over test steps. Beliefs `b_t`:
//!
//! - **CRF**: the normalized forward vector from prosody memberships (causal);
//! - **HMM (Brand's remapping)**: the kinematic HMM's states and transitions, each state's
//!   emission re-fitted as a full-covariance Gaussian over the *windowed prosody vector*
//!   (per step of the window: relative log F0 with 0 when unvoiced, a voiced flag, relative
//!   intensity, log length), weighted by the kinematic posteriors; beliefs by its forward pass;
//! - **prior**: the state frequencies, no input;
//! - **take prior**: the state frequencies of the test step's own take on its training steps
//!   (the prior for a take the model was not trained on). With several training takes whose
//!   kinematics differ, telling one take from another is most of what speech can tell about
//!   the states (it can be told from the style of the speech), and the gain over the prior
//!   counts it; the gain over the take prior counts only what speech says within a take.
//!
//! Per window, besides each score: the CRF's gain over the prior and over the take prior, and
//! `crf - hmm`, each with the standard error of the per-step differences. The scores are
//! densities of the normalized targets, which depend on the training corpus and on how takes
//! are standardized; `raw_offset` turns them into densities of the log kinematic parameters
//! themselves, which compare models trained on different corpora on the same test steps.
//!
//! Also the adjusted Rand index between two labelings (hand-written: a dozen lines of
//! contingency counting, not worth a dependency).

use std::collections::HashMap;
use std::time::Instant;

use gesture_runtime::inference::{StepFeatures, MAX_WINDOW};
use serde::Serialize;

use super::crf::{Crf, TrainSeq};
use super::gaussian::{log_sum_exp, Gaussian};
use super::hmm::Seq;
use super::select::{self, Selection};
use super::train::{
    fit_base, fit_crf, memberships, normalized, FitBase, FitConfig, FitError, FitReport, Sequence,
};

/// One row of the comparison (mean log-likelihood per test step).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Row {
    /// Window W.
    pub window: usize,
    /// CRF.
    pub crf: f64,
    /// Brand's remapped HMM.
    pub hmm: f64,
    /// State prior.
    pub prior: f64,
    /// `crf - prior`: what the CRF's belief knows beyond the prior (nats per step).
    pub gain: f64,
    /// Standard error of `gain`: the standard deviation of the per-step differences over the
    /// square root of the test steps (steps are correlated in time, so this is a lower bound
    /// on the uncertainty).
    pub gain_se: f64,
    /// Standard error of `crf - hmm`, per step paired like `gain_se`: Fig. 4's ordering on
    /// these test steps is `crf - hmm` in units of it.
    pub crf_hmm_se: f64,
    /// The take prior: the belief fixed at the state frequencies of the test step's own take
    /// on its training steps (the model's prior for a take it was not trained on). The gain
    /// over the model's prior also counts telling one training take's states from another's,
    /// which speech can do across recordings of different style; over the take prior it
    /// counts only what speech says within a take.
    pub take_prior: f64,
    /// `crf - take_prior` (nats per step).
    pub take_gain: f64,
    /// Standard error of `take_gain`, per step paired.
    pub take_gain_se: f64,
    /// CRF L2 strength per training step used for this window.
    pub l2: f64,
    /// CRF lag penalty used for this window.
    pub lag_penalty: f64,
}

/// Planted state runs `(start_s, end_s, state)` per take stem (a synthetic corpus's truth).
pub type PlantedRuns = HashMap<String, Vec<(f64, f64, usize)>>;

/// What [`evaluate`] measured.
#[derive(Debug, Clone, Serialize)]
pub struct EvalReport {
    /// One row per window.
    pub rows: Vec<Row>,
    /// States S used.
    pub states: usize,
    /// Clusters K used.
    pub clusters: usize,
    /// Training steps.
    pub train_steps: usize,
    /// Test steps.
    pub test_steps: usize,
    /// What to add to the `crf`, `hmm` and `prior` scores for the log-density of the test
    /// steps' log kinematic parameters themselves, before their take's level and the model's
    /// normalization (the mean over test steps of the log-determinant of that affine map).
    /// The normalized targets depend on the training corpus and on how takes are
    /// standardized; these log-densities do not, so they compare models trained on different
    /// corpora on the same test steps.
    pub raw_offset: f64,
    /// Adjusted Rand index of the HMM's states against planted ones on the training and test
    /// data, when known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ari: Option<(f64, Option<f64>)>,
    /// Model selection curves.
    #[serde(skip)]
    pub selection: Option<Selection>,
    /// Wall time (s).
    #[serde(skip)]
    pub seconds: f64,
}

/// One window's figures over the folds of a cross-validation ([`cross_validate`]).
#[derive(Debug, Clone, Serialize)]
pub struct CvRow {
    /// Window W.
    pub window: usize,
    /// CRF, mean log-likelihood per test step over every fold's test steps.
    pub crf: f64,
    /// Brand's remapped HMM, likewise.
    pub hmm: f64,
    /// State prior, likewise.
    pub prior: f64,
    /// `crf - prior` (nats per step).
    pub gain: f64,
    /// Standard error of `gain` from the folds: the standard deviation of the folds' gains
    /// over the square root of their number.
    pub gain_se: f64,
    /// Each fold's gain.
    pub fold_gains: Vec<f64>,
    /// `crf - hmm` over all test steps.
    pub crf_hmm: f64,
    /// Its standard error from the folds' differences.
    pub crf_hmm_se: f64,
    /// Each fold's `crf - hmm`.
    pub fold_crf_hmm: Vec<f64>,
    /// The take prior (see [`Row::take_prior`]) over all test steps.
    pub take_prior: f64,
    /// `crf - take_prior` over all test steps.
    pub take_gain: f64,
    /// Its standard error from the folds' take gains.
    pub take_gain_se: f64,
}

/// A cross-validation over time: every fold's report and the windows' figures over all.
#[derive(Debug, Clone, Serialize)]
pub struct CvReport {
    /// One row per window.
    pub rows: Vec<CvRow>,
    /// [`EvalReport::raw_offset`] over all folds' test steps.
    pub raw_offset: f64,
    /// Each fold's evaluation (its model selection included).
    pub folds: Vec<EvalReport>,
    /// Wall time (s).
    #[serde(skip)]
    pub seconds: f64,
}

/// Runs [`evaluate`] on each fold of `splits` (from [`super::train::cv_split`]; model
/// selection inside each fold, on its training data only) and pools the folds: per window
/// the mean scores over all test steps, the gain's standard error from the spread of the
/// folds' gains. A fold without test steps is an error naming it.
pub fn cross_validate(
    splits: &[super::train::CvSplit],
    cfg: &FitConfig,
    windows: &[usize],
    log: &(dyn Fn(&str) + Sync),
) -> Result<CvReport, FitError> {
    let start = Instant::now();
    let mut folds = Vec::with_capacity(splits.len());
    for (k, split) in splits.iter().enumerate() {
        log(&format!("fold {} of {}", k + 1, splits.len()));
        let r = evaluate(
            (&split.train, &split.segments),
            &split.test,
            cfg,
            windows,
            (None, None),
            log,
        )
        .map_err(|e| match e {
            FitError::Settings(m) => FitError::Settings(format!("fold {}: {m}", k + 1)),
            other => other,
        })?;
        folds.push(r);
    }
    let steps: f64 = folds
        .iter()
        .map(|f| f.test_steps as f64)
        .sum::<f64>()
        .max(1.0);
    let rows = windows
        .iter()
        .enumerate()
        .map(|(i, &window)| {
            let pooled = |v: fn(&Row) -> f64| {
                folds
                    .iter()
                    .map(|f| v(&f.rows[i]) * f.test_steps as f64)
                    .sum::<f64>()
                    / steps
            };
            let per_fold =
                |v: fn(&Row) -> f64| -> Vec<f64> { folds.iter().map(|f| v(&f.rows[i])).collect() };
            let fold_gains = per_fold(|r| r.gain);
            let fold_crf_hmm = per_fold(|r| r.crf - r.hmm);
            let (crf, hmm, prior) = (pooled(|r| r.crf), pooled(|r| r.hmm), pooled(|r| r.prior));
            let take_prior = pooled(|r| r.take_prior);
            CvRow {
                window,
                crf,
                hmm,
                prior,
                gain: crf - prior,
                gain_se: spread_se(&fold_gains),
                crf_hmm: crf - hmm,
                crf_hmm_se: spread_se(&fold_crf_hmm),
                fold_crf_hmm,
                take_prior,
                take_gain: crf - take_prior,
                take_gain_se: spread_se(&per_fold(|r| r.take_gain)),
                fold_gains,
            }
        })
        .collect();
    let raw_offset = folds
        .iter()
        .map(|f| f.raw_offset * f.test_steps as f64)
        .sum::<f64>()
        / steps;
    Ok(CvReport {
        rows,
        raw_offset,
        folds,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// The standard error of the mean of `v` from its spread (0 with fewer than two values).
fn spread_se(v: &[f64]) -> f64 {
    if v.len() < 2 {
        return 0.0;
    }
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    (v.iter().map(|g| (g - m).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt()
}

/// Fits on `train` (S and K chosen once with window `cfg.window` when open), then for each of
/// `windows` fits the CRF (regularization chosen per window when open) and Brand's remapped
/// HMM, and scores their online beliefs and the prior on `test`.
pub fn evaluate(
    train: (&[Sequence], &[[f64; 6]]),
    test: &[Sequence],
    cfg: &FitConfig,
    windows: &[usize],
    planted: (Option<&PlantedRuns>, Option<&PlantedRuns>),
    log: &(dyn Fn(&str) + Sync),
) -> Result<EvalReport, FitError> {
    let start = Instant::now();
    let (train_seqs, segs) = train;
    let test_steps: usize = test.iter().map(Sequence::len).sum();
    if test_steps == 0 {
        return Err(FitError::Settings(
            "the test set has no time steps (check --test and --test-span)".into(),
        ));
    }
    if let Some(w) = windows.iter().find(|w| !(1..=MAX_WINDOW).contains(w)) {
        return Err(FitError::Settings(format!(
            "window {w} out of range 1-{MAX_WINDOW}"
        )));
    }
    let choice = select::choose(train_seqs, segs, cfg, windows, log)?;
    let mut report = FitReport::default();
    let base = fit_base(
        train_seqs,
        segs,
        choice.states,
        choice.clusters,
        cfg,
        &mut report,
        log,
    )?;
    let y_test = normalized(test, &base.normalization);
    let prior_steps = step_scores(&base, &y_test, &prior_beliefs(&base, test));
    let prior = mean(&prior_steps);
    let take_steps = step_scores(&base, &y_test, &take_prior_beliefs(&base, train_seqs, test));
    let take_prior = mean(&take_steps);
    let mut rows = Vec::new();
    for (&w, &(l2, lag)) in windows.iter().zip(&choice.regularization) {
        let crf = fit_crf(&base, w, l2, lag, &mut report, log)?;
        let crf_steps = step_scores(&base, &y_test, &crf_beliefs(&base, &crf, test));
        let crf_score = mean(&crf_steps);
        let brand = RemappedHmm::fit(&base, train_seqs, w);
        let hb: Vec<Vec<Vec<f64>>> = test.iter().map(|s| brand.beliefs(&base, s)).collect();
        let hmm_steps = step_scores(&base, &y_test, &hb);
        rows.push(Row {
            window: w,
            crf: crf_score,
            hmm: mean(&hmm_steps),
            prior,
            gain: crf_score - prior,
            gain_se: standard_error(&crf_steps, &prior_steps),
            crf_hmm_se: standard_error(&crf_steps, &hmm_steps),
            take_prior,
            take_gain: crf_score - take_prior,
            take_gain_se: standard_error(&crf_steps, &take_steps),
            l2,
            lag_penalty: lag,
        });
    }
    let ari = planted.0.and_then(|runs| {
        let train_ari = planted_ari(&base, train_seqs, &base.y, runs)?;
        let test_ari = planted.1.and_then(|r| planted_ari(&base, test, &y_test, r));
        Some((train_ari, test_ari))
    });
    Ok(EvalReport {
        rows,
        states: choice.states,
        clusters: choice.clusters,
        train_steps: report.steps,
        test_steps,
        raw_offset: raw_offset(&base, test),
        ari,
        selection: choice.selection,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// [`EvalReport::raw_offset`]: the mean over the steps of `seqs` of `ln |det|` of the map from
/// log kinematic parameters to the model's targets (each take's level, then the model's
/// normalization: `-sum_d ln(level_scale_d * scale_d)`).
pub fn raw_offset(base: &FitBase, seqs: &[Sequence]) -> f64 {
    let steps: usize = seqs.iter().map(Sequence::len).sum();
    let sum: f64 = seqs
        .iter()
        .map(|s| {
            let log_det: f64 = s
                .level
                .scale
                .iter()
                .zip(&base.normalization.scale)
                .map(|(a, b)| -(a * b).ln())
                .sum();
            log_det * s.len() as f64
        })
        .sum();
    sum / steps.max(1) as f64
}

/// ARI between the HMM's states (argmax posterior) and the planted states at step midpoints.
pub fn planted_ari(
    base: &FitBase,
    seqs: &[Sequence],
    y: &[Seq],
    runs: &PlantedRuns,
) -> Option<f64> {
    let (mut found, mut planted) = (Vec::new(), Vec::new());
    for (s, ys) in seqs.iter().zip(y) {
        let r = runs.get(&s.stem)?;
        let post = base.hmm.posterior(ys);
        for (g, &(a, b)) in post.gamma_rows().zip(&s.times) {
            let mid = 0.5 * (a + b);
            let Some(&(_, _, state)) = r.iter().find(|(s0, s1, _)| mid >= *s0 && mid < *s1) else {
                continue;
            };
            let best = (0..g.len())
                .max_by(|&i, &j| g[i].total_cmp(&g[j]))
                .unwrap_or(0);
            found.push(best);
            planted.push(state);
        }
    }
    (!found.is_empty()).then(|| adjusted_rand_index(&found, &planted))
}

/// Mean per-step score of `y` (normalized) under beliefs `b` and the HMM state Gaussians.
pub fn mean_score(base: &FitBase, y: &[Seq], beliefs: &[Vec<Vec<f64>>]) -> f64 {
    mean(&step_scores(base, y, beliefs))
}

/// The score of every step of `y` (normalized) under beliefs `b` and the HMM state
/// Gaussians: `log sum_i b_t(i) N(y_t; mu_i, Sigma_i)`.
pub fn step_scores(base: &FitBase, y: &[Seq], beliefs: &[Vec<Vec<f64>>]) -> Vec<f64> {
    let mut out = Vec::new();
    for (ys, bs) in y.iter().zip(beliefs) {
        for (yt, bt) in ys.iter().zip(bs) {
            let terms: Vec<f64> = base
                .hmm
                .emit
                .iter()
                .zip(bt)
                .map(|(g, &b)| b.max(1e-300).ln() + g.log_pdf(yt))
                .collect();
            out.push(log_sum_exp(&terms));
        }
    }
    out
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// Standard error of the mean of `a[t] - b[t]` (0 with fewer than two steps).
pub fn standard_error(a: &[f64], b: &[f64]) -> f64 {
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    if d.len() < 2 {
        return 0.0;
    }
    let m = mean(&d);
    let var = d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (d.len() - 1) as f64;
    (var / d.len() as f64).sqrt()
}

/// CRF beliefs for every test sequence.
pub fn crf_beliefs(base: &FitBase, crf: &Crf, seqs: &[Sequence]) -> Vec<Vec<Vec<f64>>> {
    seqs.iter()
        .map(|s| crf.beliefs(&memberships(&base.gmm, s)))
        .collect()
}

/// The prior belief at every step.
pub fn prior_beliefs(base: &FitBase, seqs: &[Sequence]) -> Vec<Vec<Vec<f64>>> {
    seqs.iter()
        .map(|s| vec![base.state_prior.clone(); s.len()])
        .collect()
}

/// Each training take's state frequencies: the mean HMM posterior over its training steps
/// (`posteriors` holds one [`TrainSeq`] per sequence of `train`, as [`FitBase::train`] does).
pub fn take_state_frequencies(
    train: &[Sequence],
    posteriors: &[TrainSeq],
    states: usize,
) -> HashMap<String, Vec<f64>> {
    let mut sums: HashMap<String, (Vec<f64>, f64)> = HashMap::new();
    for (s, q) in train.iter().zip(posteriors) {
        let (f, n) = sums
            .entry(s.stem.clone())
            .or_insert_with(|| (vec![0.0; states], 0.0));
        for g in q.gamma.chunks_exact(states.max(1)) {
            f.iter_mut().zip(g).for_each(|(a, b)| *a += b);
            *n += 1.0;
        }
    }
    sums.into_iter()
        .filter(|(_, (_, n))| *n > 0.0)
        .map(|(stem, (f, n))| (stem, f.iter().map(|v| v / n).collect()))
        .collect()
}

/// The take prior at every step ([`Row::take_prior`]): the state frequencies of the training
/// steps of the sequence's own take, or the model's prior for a take without training steps.
pub fn take_prior_beliefs(
    base: &FitBase,
    train: &[Sequence],
    seqs: &[Sequence],
) -> Vec<Vec<Vec<f64>>> {
    let freq = take_state_frequencies(train, &base.train, base.hmm.states());
    seqs.iter()
        .map(|s| {
            let b = freq
                .get(&s.stem)
                .cloned()
                .unwrap_or_else(|| base.state_prior.clone());
            vec![b; s.len()]
        })
        .collect()
}

/// The windowed prosody vector of step `t` (4 values per step of the window, zeros before 0).
pub fn windowed_prosody(f: &[StepFeatures], t: usize, window: usize) -> Vec<f64> {
    let mut v = Vec::with_capacity(4 * window);
    for w in 0..window {
        match t.checked_sub(w).and_then(|i| f.get(i)) {
            Some(x) => {
                v.push(x.f0.unwrap_or(0.0) as f64);
                v.push(if x.f0.is_some() { 1.0 } else { 0.0 });
                v.push(x.obs[0] as f64);
                v.push(x.obs[1] as f64);
            }
            None => v.extend_from_slice(&[0.0; 4]),
        }
    }
    v
}

/// Brand's remapped HMM: the kinematic HMM's chain with emissions over windowed prosody.
#[derive(Clone, Debug)]
pub struct RemappedHmm {
    window: usize,
    emit: Vec<Gaussian>,
}

impl RemappedHmm {
    /// Re-fits every state's emission on the training prosody, weighted by the kinematic
    /// posteriors of the base HMM.
    pub fn fit(base: &FitBase, train: &[Sequence], window: usize) -> Self {
        let xs: Vec<Vec<f64>> = train
            .iter()
            .flat_map(|s| (0..s.len()).map(move |t| windowed_prosody(&s.features, t, window)))
            .collect();
        let dims = 4 * window;
        let n = xs.len().max(1) as f64;
        let var: f64 = (0..dims)
            .map(|d| {
                let m = xs.iter().map(|x| x[d]).sum::<f64>() / n;
                xs.iter().map(|x| (x[d] - m).powi(2)).sum::<f64>() / n
            })
            .sum::<f64>()
            / dims as f64;
        let eps = (1e-3 * var).max(1e-6);
        let mean0 = vec![0.0; dims];
        let k = base.hmm.states();
        let emit = (0..base.hmm.states())
            .map(|i| {
                let w: Vec<f64> = base
                    .train
                    .iter()
                    .flat_map(|q| q.gamma.chunks_exact(k).map(move |g| g[i]))
                    .collect();
                Gaussian::fit_weighted(&xs, &w, eps, &mean0)
            })
            .collect();
        Self { window, emit }
    }

    /// Online (forward, normalized) beliefs for a sequence.
    pub fn beliefs(&self, base: &FitBase, s: &Sequence) -> Vec<Vec<f64>> {
        let k = base.hmm.states();
        let mut out: Vec<Vec<f64>> = Vec::with_capacity(s.len());
        for t in 0..s.len() {
            let x = windowed_prosody(&s.features, t, self.window);
            let logit: Vec<f64> = (0..k)
                .map(|j| {
                    let prior = if t == 0 {
                        base.hmm.init[j].max(1e-300).ln()
                    } else {
                        let terms: Vec<f64> = (0..k)
                            .map(|i| {
                                out[t - 1][i].max(1e-300).ln()
                                    + base.hmm.trans[i * k + j].max(1e-300).ln()
                            })
                            .collect();
                        log_sum_exp(&terms)
                    };
                    prior + self.emit[j].log_pdf(&x)
                })
                .collect();
            let z = log_sum_exp(&logit);
            out.push(logit.iter().map(|v| (v - z).exp()).collect());
        }
        out
    }
}

/// Adjusted Rand index of two labelings of the same items (1 = identical partitions,
/// ~0 = chance).
pub fn adjusted_rand_index(a: &[usize], b: &[usize]) -> f64 {
    let n = a.len().min(b.len());
    if n < 2 {
        return 1.0;
    }
    let ka = a.iter().max().map_or(0, |m| m + 1);
    let kb = b.iter().max().map_or(0, |m| m + 1);
    let mut table = vec![vec![0u64; kb]; ka];
    for i in 0..n {
        table[a[i]][b[i]] += 1;
    }
    let c2 = |x: u64| (x * x.saturating_sub(1)) as f64 / 2.0;
    let sum_ij: f64 = table.iter().flatten().map(|&x| c2(x)).sum();
    let sum_a: f64 = table.iter().map(|r| c2(r.iter().sum())).sum();
    let sum_b: f64 = (0..kb).map(|j| c2(table.iter().map(|r| r[j]).sum())).sum();
    let total = c2(n as u64);
    let expected = sum_a * sum_b / total;
    let max = 0.5 * (sum_a + sum_b);
    if (max - expected).abs() < 1e-12 {
        return 1.0;
    }
    (sum_ij - expected) / (max - expected)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_error_known_values() {
        // Differences 1, 2, 3, 4: sample sd sqrt(5/3), over sqrt(4).
        let se = standard_error(&[2.0, 4.0, 6.0, 8.0], &[1.0, 2.0, 3.0, 4.0]);
        assert!((se - (5.0f64 / 3.0).sqrt() / 2.0).abs() < 1e-12, "{se}");
        assert_eq!(standard_error(&[1.0], &[0.0]), 0.0);
    }

    #[test]
    fn ari_known_values() {
        // Identical up to relabeling.
        assert!(
            (adjusted_rand_index(&[0, 0, 1, 1, 2, 2], &[2, 2, 0, 0, 1, 1]) - 1.0).abs() < 1e-12
        );
        // Hubert & Arabie's example: a = {0,0,0,1,1,1}, b = {0,0,1,1,2,2}.
        // Pairs: sum_ij = C(2,2)+C(1,2)+C(1,2)+C(2,2) = 2; sum_a = 6; sum_b = 3; total = 15;
        // expected = 18/15 = 1.2; max = 4.5; ARI = 0.8 / 3.3.
        let v = adjusted_rand_index(&[0, 0, 0, 1, 1, 1], &[0, 0, 1, 1, 2, 2]);
        assert!((v - 0.8 / 3.3).abs() < 1e-12, "{v}");
    }

    #[test]
    fn take_frequencies_average_each_takes_posteriors() {
        let seq = |stem: &str, n: usize| Sequence {
            stem: stem.into(),
            features: vec![
                StepFeatures {
                    f0: None,
                    obs: [0.0, 0.0],
                    pause: false,
                };
                n
            ],
            ..Sequence::default()
        };
        let post = |gamma: Vec<f64>| TrainSeq {
            memberships: Vec::new(),
            gamma,
            xi_sum: Vec::new(),
        };
        // Take a in two pieces (3 steps, 1 step), take b in one; two states.
        let train = [seq("a", 3), seq("b", 2), seq("a", 1)];
        let posts = [
            post(vec![1.0, 0.0, 1.0, 0.0, 0.5, 0.5]),
            post(vec![0.0, 1.0, 0.2, 0.8]),
            post(vec![0.5, 0.5]),
        ];
        let f = take_state_frequencies(&train, &posts, 2);
        assert_eq!(f.len(), 2);
        assert!((f["a"][0] - 3.0 / 4.0).abs() < 1e-12, "{f:?}");
        assert!((f["a"][1] - 1.0 / 4.0).abs() < 1e-12, "{f:?}");
        assert!((f["b"][0] - 0.1).abs() < 1e-12 && (f["b"][1] - 0.9).abs() < 1e-12);
    }

    #[test]
    fn windowed_prosody_pads_before_the_start() {
        let f = StepFeatures {
            f0: None,
            obs: [1.0, -1.0],
            pause: false,
        };
        let v = windowed_prosody(&[f, f], 0, 3);
        assert_eq!(
            v,
            vec![0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        );
    }
}
