//! Model selection by held-out likelihood (docs/method.md, "Inference layer", step 5 used as
//! the criterion): what [`FitConfig`] leaves open is chosen on the speaker's own data, in this
//! order: the number of states S, then the number of prosody clusters K, then the CRF's L2
//! strength and lag penalty (per window).
//!
//! - **Criterion**: the mean log-likelihood per held-out step of the true kinematics under the
//!   CRF's *online* belief, `log sum_i b_t(i) N(y_t; mu_i, Sigma_i)` — the quantity the
//!   evaluation reports ([`super::eval`]), so a model is chosen for what it is used for. It is
//!   a density of the same normalized `y` for every S, so different S compare fairly; S = 1 is
//!   the state prior's score (one Gaussian, a certain belief).
//! - **Folds**: contiguous blocks of steps in corpus order (takes one after the other): five
//!   folds up to [`FOLD_LIMIT`] steps, otherwise one held-out block, the last third. Motion
//!   segments last longer than steps and every step's target averages the segments it
//!   overlaps, so the training steps that overlap any segment a held-out block touches are
//!   *purged* (dropped from training), or the held-out kinematics would leak into training.
//!   The kinematic normalization is the corpus-wide one (a per-dimension affine map).
//! - **One standard error**: each choice takes the simplest candidate whose score is within one
//!   standard error of the best: fewer states, fewer clusters, stronger L2, stronger lag
//!   penalty. The standard error is that of the *paired* difference to the best, over five
//!   contiguous blocks of the held-out steps (the folds, or five parts of the single block):
//!   blocks differ in level far more than candidates do, and that level is common to all. Data too small to tell models
//!   apart therefore gives a small, strongly regularized model, close to the prior rather than
//!   worse than it.
//! - At least two states are chosen: S = 1 is scored and shown but never chosen (a
//!   one-state model has nothing for the control layer to follow).
//! - Selection fits use at most [`SELECTION_RESTARTS`] HMM restarts; the final fit uses all.
//!
//! Deterministic for a given seed (the fits are). Allocates freely (host only).

use std::collections::HashMap;
use std::fmt;

use gesture_runtime::inference::{MAX_CLUSTERS, MAX_STATES};

use super::crf::{Crf, CrfConfig, TrainSeq};
use super::gaussian::log_sum_exp;
use super::gmm::Gmm;
use super::hmm::{Hmm, Seq};
use super::layers::{fit_gmm, fit_hmm, memberships, normalized, train_seqs, FitConfig, FitError};
use super::sequence::Sequence;
use crate::motion::Normalization;

/// Corpora up to this many steps get five folds; larger ones one held-out third.
pub const FOLD_LIMIT: usize = 1500;
/// HMM restarts per selection fit.
pub const SELECTION_RESTARTS: usize = 4;
/// Candidate numbers of states.
pub const STATE_GRID: [usize; 10] = [1, 2, 3, 4, 6, 8, 12, 16, 24, 32];
/// Candidate numbers of prosody clusters.
pub const CLUSTER_GRID: [usize; 7] = [2, 3, 4, 6, 8, 12, 16];
/// Candidate L2 strengths per training step, simplest (strongest) first.
pub const L2_GRID: [f64; 8] = [0.3, 0.1, 0.03, 0.01, 0.003, 0.001, 3e-4, 1e-4];
/// Candidate lag penalties, simplest (strongest) first.
pub const LAG_GRID: [f64; 3] = [100.0, 10.0, 1.0];
/// Clusters while S is chosen, when K is open too.
pub const DEFAULT_CLUSTERS: usize = 8;
/// L2 per step while S and K are chosen, when it is open too.
pub const DEFAULT_L2: f64 = 0.01;
/// Lag penalty while S and K are chosen, when it is open too.
pub const DEFAULT_LAG_PENALTY: f64 = 10.0;

/// One scored candidate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// States S.
    pub states: usize,
    /// Clusters K.
    pub clusters: usize,
    /// CRF window W.
    pub window: usize,
    /// L2 per training step.
    pub l2: f64,
    /// Lag penalty.
    pub lag_penalty: f64,
    /// Mean held-out log-likelihood per step.
    pub mean: f64,
    /// Standard error of its difference to the best candidate of its curve.
    pub se: f64,
}

/// One choice: what varied, the candidates in simplicity order, and which was taken.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// "states", "clusters" or "regularization".
    pub what: &'static str,
    /// Candidates, simplest first.
    pub points: Vec<Point>,
    /// Index of the chosen candidate.
    pub chosen: usize,
}

/// Everything model selection measured.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Selection {
    /// Number of folds.
    pub folds: usize,
    /// Held-out steps scored per candidate.
    pub held_steps: usize,
    /// The curves, in the order the choices were made.
    pub curves: Vec<Curve>,
}

impl fmt::Display for Selection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "model selection: mean held-out log-likelihood per step +- standard error \
             (standard error of the difference to the best; {} fold(s), {} held-out steps); \
             * = chosen (simplest within one standard error)",
            self.folds, self.held_steps
        )?;
        for c in &self.curves {
            for (i, p) in c.points.iter().enumerate() {
                writeln!(
                    f,
                    "  {:<14} S={:<2} K={:<2} W={} l2={:<6} lag={:<4} {:>9.4} +- {:.4}{}",
                    c.what,
                    p.states,
                    p.clusters,
                    p.window,
                    p.l2,
                    p.lag_penalty,
                    p.mean,
                    p.se,
                    if i == c.chosen { "  *" } else { "" }
                )?;
            }
        }
        Ok(())
    }
}

/// The chosen settings.
#[derive(Clone, Debug)]
pub struct Choice {
    /// States S.
    pub states: usize,
    /// Clusters K.
    pub clusters: usize,
    /// `(l2 per step, lag penalty)` for each window asked for.
    pub regularization: Vec<(f64, f64)>,
    /// The curves (`None` when nothing was open).
    pub selection: Option<Selection>,
}

/// One fold: training pieces (purged) and held-out pieces, with normalized targets.
struct Fold {
    train: Vec<Sequence>,
    held: Vec<Sequence>,
    y_train: Vec<Seq>,
    y_held: Vec<Seq>,
}

/// Splits `seqs` into folds (see the module docs). Returns `(train, held)` per fold.
pub fn folds(seqs: &[Sequence]) -> Vec<(Vec<Sequence>, Vec<Sequence>)> {
    let n: usize = seqs.iter().map(Sequence::len).sum();
    let blocks: Vec<(usize, usize)> = if n <= FOLD_LIMIT {
        (0..5).map(|f| (f * n / 5, (f + 1) * n / 5)).collect()
    } else {
        vec![(n - n / 3, n)]
    };
    blocks
        .into_iter()
        .filter(|(a, b)| b > a)
        .map(|(a, b)| {
            let (mut train, mut held) = (Vec::new(), Vec::new());
            let mut first = 0;
            for s in seqs {
                let (lo, hi) = (a.max(first), b.min(first + s.len()));
                if lo >= hi {
                    if !s.is_empty() {
                        train.push(s.clone());
                    }
                    first += s.len();
                    continue;
                }
                let (h0, h1) = (lo - first, hi - first);
                held.push(s.slice(h0..h1));
                // Extend the held-out span to every segment it touches, then purge.
                let (mut t0, mut t1) = (s.times[h0].0, s.times[h1 - 1].1);
                for &(g0, g1) in &s.segments {
                    if g0 < t1 && g1 > t0 {
                        t0 = t0.min(g0);
                        t1 = t1.max(g1);
                    }
                }
                let keep =
                    |t: usize| !((h0..h1).contains(&t) || (s.times[t].0 < t1 && s.times[t].1 > t0));
                let mut run = None;
                for t in 0..=s.len() {
                    match (t < s.len() && keep(t), run) {
                        (true, None) => run = Some(t),
                        (false, Some(r)) => {
                            train.push(s.slice(r..t));
                            run = None;
                        }
                        _ => {}
                    }
                }
                first += s.len();
            }
            (train, held)
        })
        .collect()
}

/// Mean of `scores` and the standard error of that mean from five contiguous blocks.
fn mean_se(scores: &[f64]) -> (f64, f64) {
    let n = scores.len();
    if n == 0 {
        return (f64::NEG_INFINITY, 0.0);
    }
    let mean = scores.iter().sum::<f64>() / n as f64;
    let blocks: Vec<f64> = (0..5)
        .map(|b| (b * n / 5, (b + 1) * n / 5))
        .filter(|(a, c)| c > a)
        .map(|(a, c)| scores[a..c].iter().sum::<f64>() / (c - a) as f64)
        .collect();
    let m = blocks.len() as f64;
    if m < 2.0 {
        return (mean, 0.0);
    }
    let bm = blocks.iter().sum::<f64>() / m;
    let var = blocks.iter().map(|v| (v - bm).powi(2)).sum::<f64>() / (m - 1.0);
    (mean, (var / m).sqrt())
}

/// Chooses among `points` (simplest first) with their per-step held-out scores: the simplest
/// eligible point whose mean is within one standard error of the best eligible one. The
/// standard error is that of the *paired* difference to the best (blocks differ in level far
/// more than candidates do, and the level is common to all). Sets every point's `se` to that
/// of its difference to the best.
fn one_se(points: &mut [Point], scores: &[Vec<f64>], eligible: impl Fn(&Point) -> bool) -> usize {
    let best = points
        .iter()
        .enumerate()
        .filter(|(_, p)| eligible(p) && p.mean.is_finite())
        .max_by(|a, b| a.1.mean.total_cmp(&b.1.mean))
        .map(|(i, _)| i);
    let Some(best) = best else {
        return points.iter().position(&eligible).unwrap_or(0);
    };
    for (i, p) in points.iter_mut().enumerate() {
        let diff: Vec<f64> = scores[i]
            .iter()
            .zip(&scores[best])
            .map(|(a, b)| a - b)
            .collect();
        p.se = mean_se(&diff).1;
    }
    points
        .iter()
        .position(|p| eligible(p) && p.mean >= points[best].mean - p.se)
        .unwrap_or(best)
}

/// Per-step `log sum_i b_t(i) N(y_t; state i)`.
pub fn step_scores(hmm: &Hmm, y: &[Seq], beliefs: &[Vec<Vec<f64>>], out: &mut Vec<f64>) {
    let mut terms = vec![0.0; hmm.states()];
    for (ys, bs) in y.iter().zip(beliefs) {
        for (yt, bt) in ys.iter().zip(bs) {
            for ((tm, g), &b) in terms.iter_mut().zip(&hmm.emit).zip(bt) {
                *tm = b.max(1e-300).ln() + g.log_pdf(yt);
            }
            out.push(log_sum_exp(&terms));
        }
    }
}

/// Fold models, cached across candidates.
struct Selector<'a> {
    folds: Vec<Fold>,
    cfg: FitConfig,
    hmms: HashMap<(usize, usize), (Hmm, Vec<f64>)>,
    gmms: HashMap<(usize, usize), Gmm>,
    log: &'a (dyn Fn(&str) + Sync),
}

impl Selector<'_> {
    fn hmm(&mut self, f: usize, s: usize) -> Result<(Hmm, Vec<f64>), FitError> {
        if let Some(h) = self.hmms.get(&(f, s)) {
            return Ok(h.clone());
        }
        let fold = &self.folds[f];
        let (hmm, _) = fit_hmm(&fold.y_train, s, &self.cfg, |_, _, _| {})?;
        let prior = hmm.state_frequencies(&fold.y_train);
        self.hmms.insert((f, s), (hmm.clone(), prior.clone()));
        Ok((hmm, prior))
    }

    fn gmm(&mut self, f: usize, k: usize) -> Result<Gmm, FitError> {
        if let Some(g) = self.gmms.get(&(f, k)) {
            return Ok(g.clone());
        }
        let (gmm, _) = fit_gmm(&self.folds[f].train, k, self.cfg.seed)?;
        self.gmms.insert((f, k), gmm.clone());
        Ok(gmm)
    }

    /// Scores `(l2, lag)` candidates for S, K, W, in the order given, warm-starting each fit
    /// from the previous one of the same fold.
    fn score(
        &mut self,
        s: usize,
        k: usize,
        w: usize,
        regs: &[(f64, f64)],
    ) -> Result<(Vec<Point>, Vec<Vec<f64>>), FitError> {
        let mut scores: Vec<Vec<f64>> = vec![Vec::new(); regs.len()];
        for f in 0..self.folds.len() {
            let (hmm, prior) = self.hmm(f, s)?;
            let gmm = self.gmm(f, k)?;
            let fold = &self.folds[f];
            let train: Vec<TrainSeq> = train_seqs(&hmm, &gmm, &fold.train, &fold.y_train);
            let steps: usize = train.iter().map(|q| q.memberships.len()).sum();
            let held_m: Vec<Vec<Vec<f64>>> =
                fold.held.iter().map(|h| memberships(&gmm, h)).collect();
            let center = Crf::prior(&prior, k, w);
            let mut warm: Option<Crf> = None;
            for (r, &(l2, lag)) in regs.iter().enumerate() {
                let cfg = CrfConfig {
                    window: w,
                    l2: l2 * steps.max(1) as f64,
                    lag_penalty: lag,
                    ..CrfConfig::default()
                };
                let (crf, _) =
                    Crf::fit(&train, &center, warm.as_ref(), &cfg).map_err(FitError::Crf)?;
                let beliefs: Vec<Vec<Vec<f64>>> = held_m.iter().map(|m| crf.beliefs(m)).collect();
                step_scores(&hmm, &fold.y_held, &beliefs, &mut scores[r]);
                warm = Some(crf);
            }
        }
        let points = regs
            .iter()
            .zip(&scores)
            .map(|(&(l2, lag_penalty), sc)| Point {
                states: s,
                clusters: k,
                window: w,
                l2,
                lag_penalty,
                mean: mean_se(sc).0,
                se: 0.0,
            })
            .collect();
        Ok((points, scores))
    }

    fn log_curve(&self, c: &Curve) {
        for (i, p) in c.points.iter().enumerate() {
            (self.log)(&format!(
                "select {}: S={} K={} W={} l2={} lag={}: {:.4} +- {:.4}{}",
                c.what,
                p.states,
                p.clusters,
                p.window,
                p.l2,
                p.lag_penalty,
                p.mean,
                p.se,
                if i == c.chosen { " *" } else { "" }
            ));
        }
    }
}

/// Chooses what `cfg` leaves open (see the module docs): S and K once (with window
/// `cfg.window`), then the regularization for each of `windows`.
pub fn choose(
    seqs: &[Sequence],
    segment_y: &[[f64; 6]],
    cfg: &FitConfig,
    windows: &[usize],
    log: &(dyn Fn(&str) + Sync),
) -> Result<Choice, FitError> {
    let open = cfg.states.is_none()
        || cfg.clusters.is_none()
        || cfg.l2.is_none()
        || cfg.lag_penalty.is_none();
    if !open {
        return Ok(Choice {
            states: cfg.states.unwrap_or(2),
            clusters: cfg.clusters.unwrap_or(DEFAULT_CLUSTERS),
            regularization: vec![
                (cfg.l2.unwrap_or(DEFAULT_L2), cfg.lag_penalty.unwrap_or(1.0));
                windows.len()
            ],
            selection: None,
        });
    }
    let steps: usize = seqs.iter().map(Sequence::len).sum();
    if steps == 0 {
        return Err(FitError::NoData);
    }
    let norm = Normalization::fit(segment_y).map_err(|e| FitError::Normalization(e.to_string()))?;
    let folds: Vec<Fold> = folds(seqs)
        .into_iter()
        .map(|(train, held)| Fold {
            y_train: normalized(&train, &norm),
            y_held: normalized(&held, &norm),
            train,
            held,
        })
        .filter(|f| !f.train.is_empty() && !f.held.is_empty())
        .collect();
    if folds.is_empty() {
        return Err(FitError::NoData);
    }
    let min_train = folds
        .iter()
        .map(|f| f.train.iter().map(Sequence::len).sum::<usize>())
        .min()
        .unwrap_or(0);
    let held_steps: usize = folds
        .iter()
        .map(|f| f.held.iter().map(Sequence::len).sum::<usize>())
        .sum();
    log(&format!(
        "model selection: {} fold(s), {held_steps} held-out steps, at least {min_train} training steps per fold",
        folds.len()
    ));
    let mut sel = Selector {
        folds,
        cfg: FitConfig {
            restarts: cfg.restarts.clamp(1, SELECTION_RESTARTS),
            ..*cfg
        },
        hmms: HashMap::new(),
        gmms: HashMap::new(),
        log,
    };
    let mut selection = Selection {
        folds: sel.folds.len(),
        held_steps,
        curves: Vec::new(),
    };
    let default_reg = (
        cfg.l2.unwrap_or(DEFAULT_L2),
        cfg.lag_penalty.unwrap_or(DEFAULT_LAG_PENALTY),
    );
    // S: an HMM needs S * (dims + 2) steps; ask for 10 per state per fold.
    let states = match cfg.states {
        Some(s) => s,
        None => {
            let k = cfg.clusters.unwrap_or(DEFAULT_CLUSTERS);
            let (mut points, mut scores) = (Vec::new(), Vec::new());
            for &s in STATE_GRID
                .iter()
                .filter(|&&s| s <= MAX_STATES && (s == 1 || min_train >= 10 * s.max(1)))
            {
                let (p, sc) = sel.score(s, k, cfg.window, &[default_reg])?;
                points.extend(p);
                scores.extend(sc);
            }
            let chosen = one_se(&mut points, &scores, |p| p.states >= 2);
            let c = Curve {
                what: "states",
                points,
                chosen,
            };
            sel.log_curve(&c);
            let s = c.points[chosen].states;
            selection.curves.push(c);
            s.max(2)
        }
    };
    let clusters = match cfg.clusters {
        Some(k) => k,
        None => {
            let (mut points, mut scores) = (Vec::new(), Vec::new());
            for &k in CLUSTER_GRID
                .iter()
                .filter(|&&k| k <= MAX_CLUSTERS && min_train >= 20 * k)
            {
                let (p, sc) = sel.score(states, k, cfg.window, &[default_reg])?;
                points.extend(p);
                scores.extend(sc);
            }
            let chosen = one_se(&mut points, &scores, |_| true);
            let c = Curve {
                what: "clusters",
                points,
                chosen,
            };
            sel.log_curve(&c);
            let k = c.points.get(chosen).map_or(2, |p| p.clusters);
            selection.curves.push(c);
            k
        }
    };
    let mut regularization = Vec::new();
    for &w in windows {
        let l2s: Vec<f64> = cfg.l2.map_or(L2_GRID.to_vec(), |v| vec![v]);
        // A one-step window has no lagged weights: its lag penalty is moot.
        let lags: Vec<f64> = match cfg.lag_penalty {
            Some(v) => vec![v],
            None if w == 1 => vec![1.0],
            None => LAG_GRID.to_vec(),
        };
        // Simplest first: strongest L2, then strongest lag penalty.
        let regs: Vec<(f64, f64)> = l2s
            .iter()
            .flat_map(|&l| lags.iter().map(move |&g| (l, g)))
            .collect();
        if regs.len() == 1 {
            regularization.push(regs[0]);
            continue;
        }
        let (mut points, scores) = sel.score(states, clusters, w, &regs)?;
        let chosen = one_se(&mut points, &scores, |_| true);
        let c = Curve {
            what: "regularization",
            points,
            chosen,
        };
        sel.log_curve(&c);
        regularization.push((c.points[chosen].l2, c.points[chosen].lag_penalty));
        selection.curves.push(c);
    }
    Ok(Choice {
        states,
        clusters,
        regularization,
        selection: Some(selection),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use gesture_runtime::inference::StepFeatures;

    fn seq(n: usize, seg_len: f64) -> Sequence {
        let f = StepFeatures {
            f0: None,
            obs: [0.0, 0.0],
            pause: false,
        };
        let times: Vec<(f64, f64)> = (0..n).map(|t| (t as f64, t as f64 + 1.0)).collect();
        let segs = (0..)
            .map(|i| (i as f64 * seg_len, (i + 1) as f64 * seg_len))
            .take_while(|s| s.0 < n as f64)
            .collect();
        Sequence {
            stem: "a".into(),
            features: vec![f; n],
            y_raw: vec![[0.0; 6]; n],
            times,
            segments: segs,
            ..Sequence::default()
        }
    }

    #[test]
    fn folds_hold_out_contiguous_blocks_and_purge_touched_segments() {
        // 100 one-second steps, segments of 3 s: fold 2 holds out steps 40..60, which touch
        // segments [39, 42) and [57, 60); steps 39 (before) are purged, 60 onward kept.
        let s = seq(100, 3.0);
        let f = folds(std::slice::from_ref(&s));
        assert_eq!(f.len(), 5);
        let (train, held) = &f[2];
        assert_eq!(held.len(), 1);
        assert_eq!(held[0].times.first().unwrap().0, 40.0);
        assert_eq!(held[0].times.last().unwrap().1, 60.0);
        let kept: Vec<f64> = train
            .iter()
            .flat_map(|q| q.times.iter().map(|t| t.0))
            .collect();
        assert!(!kept.contains(&39.0), "step in a touched segment kept");
        assert!(kept.contains(&38.0) && kept.contains(&60.0));
        assert_eq!(kept.len(), 100 - 20 - 1);
        // Big corpora: one block, the last third.
        let big = seq(3000, 3.0);
        let f = folds(std::slice::from_ref(&big));
        assert_eq!(f.len(), 1);
        assert_eq!(f[0].1[0].len(), 1000);
    }

    #[test]
    fn one_se_takes_the_simplest_close_candidate() {
        let p = |states, mean| Point {
            states,
            clusters: 2,
            window: 1,
            l2: 0.1,
            lag_penalty: 1.0,
            mean,
            se: 0.0,
        };
        let mut pts = [p(1, 0.0), p(2, 1.0), p(3, 1.27), p(4, 1.3)];
        // Per-step scores: S=3 is 0.03 below S=4 on average with a spread of +-0.1 between
        // blocks, so within one standard error; S=2 is 0.3 below everywhere.
        let noise = [0.1, 0.1, -0.1, -0.1, 0.1, 0.1, -0.1, -0.1, 0.1, 0.1];
        let scores: Vec<Vec<f64>> = pts
            .iter()
            .map(|q| {
                (0..10)
                    .map(|i| q.mean + if q.states == 3 { noise[i] } else { 0.0 })
                    .collect()
            })
            .collect();
        let chosen = one_se(&mut pts, &scores, |q| q.states >= 2);
        assert_eq!(pts[chosen].states, 3, "{pts:?}");
        assert_eq!(pts[3].se, 0.0);
        assert_eq!(mean_se(&[1.0; 10]), (1.0, 0.0));
    }
}
