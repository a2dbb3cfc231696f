//! Hidden Markov model with full-covariance Gaussian emissions over the kinematic parameters,
//! trained by EM (Baum-Welch) with seeded restarts (docs/method.md, "Inference layer", step 1).
//!
//! - Forward-backward is *scaled* (per-step normalization, emissions shifted by their per-step
//!   maximum in log space), so sequences of any length neither underflow nor overflow; and
//!   *flat* (`[t * S + i]` buffers reused between calls through [`FbWork`], so EM's E-step
//!   allocates nothing once warmed up); it returns the expected transition counts, not
//!   per-step pairwise posteriors.
//! - **Covariance shrinkage** ([`HmmConfig::shrinkage`], [`CovPrior::shrink_to`]): every step
//!   inside a motion segment carries that segment's kinematic vector, so a state sees few
//!   distinct vectors and a maximum-likelihood covariance collapses onto them; and
//!   `ln D - ln V - ln T` is nearly constant (path = speed x duration), so one direction of
//!   the data is nearly singular. Each state's covariance is therefore the MAP estimate under
//!   an inverse-Wishart prior worth 10 steps of the corpus covariance (3% of it isotropic).
//!   Held-out likelihood, not training likelihood, is what this buys.
//! - The covariance prior and a small Dirichlet pseudo-count on the initial and transition
//!   probabilities are priors, so EM is a MAP-EM: the reported objective (log-likelihood plus
//!   log-prior) never decreases from one iteration to the next (tested).
//! - Initialization: k-means++ seeding and a few Lloyd iterations from a seeded RNG, on the
//!   observations *smoothed over a few neighbouring steps* (moving average within each
//!   sequence, [`HmmConfig::init_smoothing`] steps either side). Hidden states are meant to be
//!   slow (a gesture style lasts many steps) while single steps also vary with fast gesture
//!   phases; clustering smoothed vectors seeds EM on the slow structure, and EM then refines on
//!   the raw observations. Each restart uses its own seed and restarts run in parallel (rayon).
//!   The best objective wins, ties broken by restart index, so results do not depend on thread
//!   timing.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::gaussian::{CovPrior, Gaussian};
use nalgebra::DMatrix;

/// A sequence of observation vectors (steps x dims).
pub type Seq = Vec<Vec<f64>>;

/// EM settings.
#[derive(Clone, Copy, Debug)]
pub struct HmmConfig {
    /// Number of hidden states.
    pub states: usize,
    /// Independent EM runs from different initializations.
    pub restarts: usize,
    /// Iteration cap per run.
    pub max_iter: usize,
    /// Stop when the objective improves by less than this per step.
    pub tol: f64,
    /// Covariance floor as a fraction of the mean per-dimension data variance.
    pub cov_floor: f64,
    /// Dirichlet pseudo-count on initial and transition probabilities.
    pub pseudo_count: f64,
    /// Seed of the first restart.
    pub seed: u64,
    /// Steps either side averaged for the k-means initialization (0 = raw observations).
    pub init_smoothing: usize,
    /// Extra Dirichlet pseudo-count on self-transitions, as a fraction of the steps per state
    /// (the "sticky" HMM prior of Fox et al. 2011): hidden states that should be slow (styles)
    /// are not spent on fast alternations (gesture phases). 0 = off.
    pub stickiness: f64,
    /// Pseudo-steps of the corpus covariance added to every state's covariance (see the
    /// module docs, "Covariance shrinkage"). 0 = the floor alone.
    pub shrinkage: f64,
    /// Isotropic share of the shrinkage target.
    pub isotropic: f64,
}

impl Default for HmmConfig {
    fn default() -> Self {
        Self {
            states: 8,
            restarts: 4,
            max_iter: 200,
            tol: 1e-6,
            cov_floor: 1e-3,
            pseudo_count: 1e-2,
            seed: 1,
            init_smoothing: 4,
            stickiness: 0.0,
            shrinkage: 10.0,
            isotropic: 0.03,
        }
    }
}

/// Why a model could not be fitted.
#[derive(Debug, thiserror::Error)]
pub enum HmmError {
    /// Too few steps for the requested states.
    #[error(
        "{steps} time steps are too few for {states} states of {dims}-dimensional Gaussians \
         (need at least {need}): use fewer states (--states) or more data"
    )]
    TooLittleData {
        /// Steps available.
        steps: usize,
        /// States requested.
        states: usize,
        /// Dimension.
        dims: usize,
        /// Minimum steps.
        need: usize,
    },
    /// Observation vectors of different lengths or non-finite values.
    #[error("observations must be finite vectors of one dimension")]
    BadData,
    /// Zero states requested.
    #[error("the number of states must be at least 1")]
    NoStates,
}

/// Posteriors of one sequence, flat: `gamma[t * S + i] = P(q_t = i | y)`.
#[derive(Clone, Debug, Default)]
pub struct Posterior {
    /// States S.
    pub states: usize,
    /// `gamma[t * S + i] = P(q_t = i | y)` (T x S, row-major).
    pub gamma: Vec<f64>,
    /// `xi_sum[i * S + j] = sum_t P(q_t = i, q_{t+1} = j | y)`: the expected transition
    /// counts (all that EM and the CRF gradient need of the pairwise posteriors).
    pub xi_sum: Vec<f64>,
    /// `log p(y)`.
    pub log_likelihood: f64,
}

impl Posterior {
    /// Steps T.
    pub fn steps(&self) -> usize {
        self.gamma.len() / self.states.max(1)
    }

    /// `P(q_t = . | y)`.
    pub fn gamma_at(&self, t: usize) -> &[f64] {
        &self.gamma[t * self.states..(t + 1) * self.states]
    }

    /// The rows of `gamma`, one per step.
    pub fn gamma_rows(&self) -> std::slice::ChunksExact<'_, f64> {
        self.gamma.chunks_exact(self.states.max(1))
    }
}

/// Scratch buffers of [`forward_backward_into`], reused between calls so the E-step and the
/// CRF gradient allocate nothing once warmed up.
#[derive(Clone, Debug, Default)]
pub struct FbWork {
    b: Vec<f64>,
    alpha: Vec<f64>,
    beta: Vec<f64>,
    scale: Vec<f64>,
}

/// A fitted HMM.
#[derive(Clone, Debug)]
pub struct Hmm {
    /// Initial state probabilities.
    pub init: Vec<f64>,
    /// Transition matrix, row-major `S x S`.
    pub trans: Vec<f64>,
    /// Emission Gaussians.
    pub emit: Vec<Gaussian>,
    /// Covariance floor used (absolute).
    pub eps: f64,
    /// The covariance prior EM used (the floor alone for a model read from a file).
    pub cov_prior: CovPrior,
}

/// What one EM run did.
#[derive(Clone, Debug)]
pub struct RunReport {
    /// Restart index.
    pub restart: usize,
    /// Objective (log-likelihood + log-prior) after each iteration.
    pub objective: Vec<f64>,
    /// Final log-likelihood.
    pub log_likelihood: f64,
}

/// Scaled forward-backward for a generic chain: `init`, row-major `trans` (S x S) and flat log
/// emission scores `log_b[t * S + i]`.
pub fn forward_backward(init: &[f64], trans: &[f64], log_b: &[f64]) -> Posterior {
    let mut post = Posterior::default();
    forward_backward_into(init, trans, log_b, &mut FbWork::default(), &mut post);
    post
}

/// [`forward_backward`] into reused buffers: allocates only when a sequence is longer than
/// any seen before by `work` and `out`. Flat loops over `t * S + i`.
pub fn forward_backward_into(
    init: &[f64],
    trans: &[f64],
    log_b: &[f64],
    work: &mut FbWork,
    out: &mut Posterior,
) {
    let s = init.len();
    let t_len = log_b.len().checked_div(s).unwrap_or(0);
    out.states = s;
    out.gamma.clear();
    out.gamma.resize(t_len * s, 0.0);
    out.xi_sum.clear();
    out.xi_sum.resize(s * s, 0.0);
    out.log_likelihood = 0.0;
    if t_len == 0 {
        return;
    }
    let FbWork {
        b,
        alpha,
        beta,
        scale,
    } = work;
    b.clear();
    b.resize(t_len * s, 0.0);
    alpha.clear();
    alpha.resize(t_len * s, 0.0);
    beta.clear();
    beta.resize(t_len * s, 1.0);
    scale.clear();
    scale.resize(t_len, 0.0);
    let mut offset_sum = 0.0;
    for t in 0..t_len {
        let row = &log_b[t * s..(t + 1) * s];
        let m = row.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let m = if m.is_finite() { m } else { 0.0 };
        offset_sum += m;
        for (bi, &l) in b[t * s..(t + 1) * s].iter_mut().zip(row) {
            *bi = (l - m).exp();
        }
    }
    for i in 0..s {
        alpha[i] = init[i] * b[i];
    }
    for t in 0..t_len {
        if t > 0 {
            let (prev, cur) = alpha.split_at_mut(t * s);
            let prev = &prev[(t - 1) * s..];
            let cur = &mut cur[..s];
            cur.fill(0.0);
            for i in 0..s {
                let a = prev[i];
                if a == 0.0 {
                    continue;
                }
                let row = &trans[i * s..(i + 1) * s];
                for j in 0..s {
                    cur[j] += a * row[j];
                }
            }
            for j in 0..s {
                cur[j] *= b[t * s + j];
            }
        }
        let row = &mut alpha[t * s..(t + 1) * s];
        let c = row.iter().sum::<f64>().max(f64::MIN_POSITIVE);
        scale[t] = c;
        row.iter_mut().for_each(|a| *a /= c);
    }
    // beta[t] = sum_j trans[i, j] b[t+1, j] beta[t+1, j] / scale[t+1]; `tmp` (the product
    // b * beta of step t + 1) lives in gamma's row t + 1 until gamma is written.
    for t in (0..t_len - 1).rev() {
        let c = scale[t + 1];
        for j in 0..s {
            out.gamma[(t + 1) * s + j] = b[(t + 1) * s + j] * beta[(t + 1) * s + j];
        }
        let tmp = &out.gamma[(t + 1) * s..(t + 2) * s];
        for i in 0..s {
            let row = &trans[i * s..(i + 1) * s];
            let mut acc = 0.0;
            for j in 0..s {
                acc += row[j] * tmp[j];
            }
            beta[t * s + i] = acc / c;
        }
        // Pairwise posteriors of (t, t + 1): alpha[t, i] trans[i, j] tmp[j] / scale[t + 1]
        // already sum to 1 with scaled alpha and beta.
        for i in 0..s {
            let a = alpha[t * s + i] / c;
            if a == 0.0 {
                continue;
            }
            let row = &trans[i * s..(i + 1) * s];
            let xs = &mut out.xi_sum[i * s..(i + 1) * s];
            for j in 0..s {
                xs[j] += a * row[j] * tmp[j];
            }
        }
    }
    for t in 0..t_len {
        let g = &mut out.gamma[t * s..(t + 1) * s];
        let mut z = 0.0;
        for i in 0..s {
            g[i] = alpha[t * s + i] * beta[t * s + i];
            z += g[i];
        }
        if z > 0.0 {
            g.iter_mut().for_each(|v| *v /= z);
        }
    }
    out.log_likelihood = scale.iter().map(|c| c.ln()).sum::<f64>() + offset_sum;
}

impl Hmm {
    /// Number of states.
    pub fn states(&self) -> usize {
        self.init.len()
    }

    /// `log N(y_t; state i)` for every step and state, flat (`[t * S + i]`).
    pub fn log_emissions(&self, seq: &[Vec<f64>]) -> Vec<f64> {
        let mut out = Vec::with_capacity(seq.len() * self.states());
        self.log_emissions_into(seq, &mut out);
        out
    }

    /// [`Hmm::log_emissions`] into a reused buffer.
    pub fn log_emissions_into(&self, seq: &[Vec<f64>], out: &mut Vec<f64>) {
        out.clear();
        for y in seq {
            out.extend(self.emit.iter().map(|g| g.log_pdf(y)));
        }
    }

    /// Posteriors of a sequence.
    pub fn posterior(&self, seq: &[Vec<f64>]) -> Posterior {
        forward_backward(&self.init, &self.trans, &self.log_emissions(seq))
    }

    /// Stationary-ish state frequencies: mean posterior over the given sequences.
    pub fn state_frequencies(&self, seqs: &[Seq]) -> Vec<f64> {
        let mut f = vec![0.0; self.states()];
        let mut n = 0.0f64;
        for s in seqs {
            let post = self.posterior(s);
            for g in post.gamma_rows() {
                for (a, b) in f.iter_mut().zip(g) {
                    *a += b;
                }
                n += 1.0;
            }
        }
        f.iter_mut().for_each(|v| *v /= n.max(1.0));
        f
    }

    /// Log-prior of the parameters (the priors described in the module docs); `sticky` is the
    /// absolute extra pseudo-count on self-transitions.
    pub fn log_prior(&self, pseudo_count: f64, sticky: f64) -> f64 {
        let s = self.states();
        let lp_pi: f64 = self
            .init
            .iter()
            .map(|p| pseudo_count * p.max(1e-300).ln())
            .sum();
        let lp_a: f64 = self
            .trans
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let c = pseudo_count + if k / s == k % s { sticky } else { 0.0 };
                c * p.max(1e-300).ln()
            })
            .sum();
        let lp_g: f64 = self
            .emit
            .iter()
            .map(|g| g.log_prior_under(&self.cov_prior))
            .sum();
        lp_pi + lp_a + lp_g
    }

    /// Fits by MAP-EM with restarts. `progress(restart, iteration, objective)` is called from
    /// worker threads after every iteration.
    pub fn fit(
        seqs: &[Seq],
        cfg: &HmmConfig,
        progress: impl Fn(usize, usize, f64) + Sync,
    ) -> Result<(Hmm, Vec<RunReport>), HmmError> {
        if cfg.states == 0 {
            return Err(HmmError::NoStates);
        }
        let all: Vec<&Vec<f64>> = seqs.iter().flatten().collect();
        let dims = all.first().map_or(0, |v| v.len());
        if dims == 0
            || all
                .iter()
                .any(|v| v.len() != dims || !v.iter().all(|x| x.is_finite()))
        {
            return Err(HmmError::BadData);
        }
        let need = cfg.states * (dims + 2);
        if all.len() < need {
            return Err(HmmError::TooLittleData {
                steps: all.len(),
                states: cfg.states,
                dims,
                need,
            });
        }
        // Absolute floor from the mean per-dimension variance.
        let n = all.len() as f64;
        let mut var = 0.0;
        for d in 0..dims {
            let m = all.iter().map(|v| v[d]).sum::<f64>() / n;
            var += all.iter().map(|v| (v[d] - m).powi(2)).sum::<f64>() / n;
        }
        let eps = (cfg.cov_floor * var / dims as f64).max(1e-9);
        let mut cov = DMatrix::<f64>::zeros(dims, dims);
        let mean: Vec<f64> = (0..dims)
            .map(|d| all.iter().map(|v| v[d]).sum::<f64>() / n)
            .collect();
        for v in &all {
            for a in 0..dims {
                for b in 0..dims {
                    cov[(a, b)] += (v[a] - mean[a]) * (v[b] - mean[b]) / n;
                }
            }
        }
        let prior = if cfg.shrinkage > 0.0 {
            CovPrior::shrink_to(&cov, cfg.shrinkage, cfg.isotropic, eps)
        } else {
            CovPrior::floor(dims, eps)
        };
        let runs: Vec<(Hmm, RunReport)> = (0..cfg.restarts.max(1))
            .into_par_iter()
            .map(|r| {
                let seed = cfg.seed.wrapping_add(r as u64 * 0x9E37_79B9);
                em_run(seqs, cfg, eps, &prior, seed, r, &progress)
            })
            .collect();
        let mut best = 0;
        for (i, (_, rep)) in runs.iter().enumerate() {
            let a = rep.objective.last().copied().unwrap_or(f64::NEG_INFINITY);
            let b = runs[best]
                .1
                .objective
                .last()
                .copied()
                .unwrap_or(f64::NEG_INFINITY);
            if a > b {
                best = i;
            }
        }
        let reports = runs.iter().map(|(_, r)| r.clone()).collect();
        let hmm = runs
            .into_iter()
            .nth(best)
            .map(|(h, _)| h)
            .ok_or(HmmError::NoStates)?;
        Ok((hmm, reports))
    }
}

/// k-means++ seeding plus Lloyd iterations; returns a hard assignment of every point.
fn kmeans(points: &[&Vec<f64>], k: usize, rng: &mut ChaCha8Rng) -> Vec<usize> {
    let dist = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>();
    let mut centres: Vec<Vec<f64>> = vec![points[rng.random_range(0..points.len())].clone()];
    let mut d2: Vec<f64> = points.iter().map(|p| dist(p, &centres[0])).collect();
    while centres.len() < k {
        let total: f64 = d2.iter().sum();
        let next = if total > 0.0 {
            let mut u = rng.random::<f64>() * total;
            let mut idx = points.len() - 1;
            for (i, &w) in d2.iter().enumerate() {
                if u < w {
                    idx = i;
                    break;
                }
                u -= w;
            }
            idx
        } else {
            rng.random_range(0..points.len())
        };
        centres.push(points[next].clone());
        for (i, p) in points.iter().enumerate() {
            d2[i] = d2[i].min(dist(p, &centres[centres.len() - 1]));
        }
    }
    let mut assign = vec![0usize; points.len()];
    for _ in 0..10 {
        for (i, p) in points.iter().enumerate() {
            let mut best = (f64::INFINITY, 0);
            for (c, cen) in centres.iter().enumerate() {
                let dd = dist(p, cen);
                if dd < best.0 {
                    best = (dd, c);
                }
            }
            assign[i] = best.1;
        }
        for (c, cen) in centres.iter_mut().enumerate() {
            let members: Vec<&&Vec<f64>> = points
                .iter()
                .zip(&assign)
                .filter(|(_, &a)| a == c)
                .map(|(p, _)| p)
                .collect();
            if members.is_empty() {
                continue;
            }
            for (d, v) in cen.iter_mut().enumerate() {
                *v = members.iter().map(|m| m[d]).sum::<f64>() / members.len() as f64;
            }
        }
    }
    assign
}

/// Moving average of a sequence over `half` steps either side (truncated at the ends).
fn smooth(q: &[Vec<f64>], half: usize) -> Vec<Vec<f64>> {
    (0..q.len())
        .map(|t| {
            let (a, b) = (t.saturating_sub(half), (t + half + 1).min(q.len()));
            let n = (b - a) as f64;
            (0..q[t].len())
                .map(|d| q[a..b].iter().map(|v| v[d]).sum::<f64>() / n)
                .collect()
        })
        .collect()
}

fn em_run(
    seqs: &[Seq],
    cfg: &HmmConfig,
    eps: f64,
    prior: &CovPrior,
    seed: u64,
    restart: usize,
    progress: &(impl Fn(usize, usize, f64) + Sync),
) -> (Hmm, RunReport) {
    let s = cfg.states;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let owned: Vec<Vec<f64>> = seqs.iter().flatten().cloned().collect();
    let dims = owned[0].len();
    let centre_mean: Vec<f64> = (0..dims)
        .map(|d| owned.iter().map(|v| v[d]).sum::<f64>() / owned.len() as f64)
        .collect();
    let smoothed: Vec<Vec<f64>> = seqs
        .iter()
        .flat_map(|q| smooth(q, cfg.init_smoothing))
        .collect();
    let points: Vec<&Vec<f64>> = smoothed.iter().collect();
    let assign = kmeans(&points, s, &mut rng);
    let emit: Vec<Gaussian> = (0..s)
        .map(|k| {
            let w: Vec<f64> = assign
                .iter()
                .map(|&a| if a == k { 1.0 } else { 0.0 })
                .collect();
            Gaussian::fit_map(&owned, &w, prior, &centre_mean)
        })
        .collect();
    let mut trans = vec![0.0; s * s];
    for i in 0..s {
        for j in 0..s {
            trans[i * s + j] = if i == j {
                0.5
            } else {
                0.5 / (s - 1).max(1) as f64
            };
        }
        if s == 1 {
            trans[0] = 1.0;
        }
    }
    let mut hmm = Hmm {
        init: vec![1.0 / s as f64; s],
        trans,
        emit,
        eps,
        cov_prior: prior.clone(),
    };
    let mut objective = Vec::new();
    let mut last_ll = f64::NEG_INFINITY;
    let total_steps = owned.len() as f64;
    let sticky = cfg.stickiness * total_steps / s as f64;
    let mut work = FbWork::default();
    let mut log_b = Vec::new();
    let mut post = Posterior::default();
    let mut gamma_all = vec![0.0; owned.len() * s];
    let mut w = vec![0.0; owned.len()];
    for it in 0..cfg.max_iter {
        // E-step, accumulating the expected counts.
        let a = cfg.pseudo_count;
        let mut init = vec![a; s];
        let mut trans = vec![a; s * s];
        for i in 0..s {
            trans[i * s + i] += sticky;
        }
        let mut ll = 0.0;
        let mut row0 = 0;
        for q in seqs {
            hmm.log_emissions_into(q, &mut log_b);
            forward_backward_into(&hmm.init, &hmm.trans, &log_b, &mut work, &mut post);
            ll += post.log_likelihood;
            if !q.is_empty() {
                for i in 0..s {
                    init[i] += post.gamma[i];
                }
            }
            for (t, v) in trans.iter_mut().zip(&post.xi_sum) {
                *t += v;
            }
            gamma_all[row0 * s..(row0 + q.len()) * s].copy_from_slice(&post.gamma);
            row0 += q.len();
        }
        let obj = ll + hmm.log_prior(cfg.pseudo_count, sticky);
        objective.push(obj);
        progress(restart, it, obj);
        last_ll = ll;
        if it > 0 {
            let prev = objective[it - 1];
            if (obj - prev).abs() < cfg.tol * total_steps {
                break;
            }
        }
        // M-step.
        let z: f64 = init.iter().sum();
        init.iter_mut().for_each(|v| *v /= z);
        for i in 0..s {
            let z: f64 = trans[i * s..(i + 1) * s].iter().sum();
            trans[i * s..(i + 1) * s].iter_mut().for_each(|v| *v /= z);
        }
        let emit = (0..s)
            .map(|k| {
                for (wt, g) in w.iter_mut().zip(gamma_all.chunks_exact(s)) {
                    *wt = g[k];
                }
                Gaussian::fit_map(&owned, &w, prior, hmm.emit[k].mean().as_slice())
            })
            .collect();
        hmm = Hmm {
            init,
            trans,
            emit,
            eps,
            cov_prior: prior.clone(),
        };
    }
    let report = RunReport {
        restart,
        objective,
        log_likelihood: last_ll,
    };
    (hmm, report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_distr::{Distribution, StandardNormal};

    /// Brute-force p(y) and P(q_t = i | y) by enumerating every state path.
    fn brute(init: &[f64], trans: &[f64], log_b: &[Vec<f64>]) -> (f64, Vec<Vec<f64>>) {
        let s = init.len();
        let t_len = log_b.len();
        let mut total = 0.0;
        let mut marg = vec![vec![0.0; s]; t_len];
        let paths = s.pow(t_len as u32);
        for code in 0..paths {
            let mut c = code;
            let mut q = vec![0; t_len];
            for v in q.iter_mut() {
                *v = c % s;
                c /= s;
            }
            let mut p = init[q[0]] * log_b[0][q[0]].exp();
            for t in 1..t_len {
                p *= trans[q[t - 1] * s + q[t]] * log_b[t][q[t]].exp();
            }
            total += p;
            for t in 0..t_len {
                marg[t][q[t]] += p;
            }
        }
        for m in marg.iter_mut() {
            m.iter_mut().for_each(|v| *v /= total);
        }
        (total.ln(), marg)
    }

    #[test]
    fn forward_backward_matches_enumeration() {
        let init = [0.5, 0.3, 0.2];
        let trans = [0.7, 0.2, 0.1, 0.1, 0.8, 0.1, 0.3, 0.3, 0.4];
        let log_b: Vec<Vec<f64>> = (0..5)
            .map(|t| {
                (0..3)
                    .map(|i| -0.5 * ((t as f64) - 2.0 * i as f64).powi(2) - 3.0)
                    .collect()
            })
            .collect();
        let flat: Vec<f64> = log_b.iter().flatten().copied().collect();
        let post = forward_backward(&init, &trans, &flat);
        let (ll, marg) = brute(&init, &trans, &log_b);
        assert!(
            (post.log_likelihood - ll).abs() < 1e-10,
            "{} vs {ll}",
            post.log_likelihood
        );
        for t in 0..5 {
            for i in 0..3 {
                assert!((post.gamma_at(t)[i] - marg[t][i]).abs() < 1e-10);
            }
        }
        // Expected transition counts: rows sum to the marginals of steps 0..T-1, columns to
        // those of steps 1..T.
        for i in 0..3 {
            let row: f64 = (0..3).map(|j| post.xi_sum[i * 3 + j]).sum();
            let col: f64 = (0..3).map(|j| post.xi_sum[j * 3 + i]).sum();
            let g_from: f64 = (0..4).map(|t| post.gamma_at(t)[i]).sum();
            let g_to: f64 = (1..5).map(|t| post.gamma_at(t)[i]).sum();
            assert!((row - g_from).abs() < 1e-10, "{row} vs {g_from}");
            assert!((col - g_to).abs() < 1e-10, "{col} vs {g_to}");
        }
    }

    fn planted(seed: u64, steps: usize) -> (Vec<Seq>, Vec<Vec<usize>>) {
        let means = [[-3.0, 0.0], [3.0, 0.0], [0.0, 3.0]];
        let trans = [[0.9, 0.05, 0.05], [0.05, 0.9, 0.05], [0.1, 0.1, 0.8]];
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut seqs = Vec::new();
        let mut truth = Vec::new();
        for _ in 0..4 {
            let mut q = rng.random_range(0..3);
            let mut seq = Vec::new();
            let mut tq = Vec::new();
            for _ in 0..steps {
                let u: f64 = rng.random();
                let mut acc = 0.0;
                for (j, p) in trans[q].iter().enumerate() {
                    acc += p;
                    if u < acc {
                        q = j;
                        break;
                    }
                }
                let n1: f64 = StandardNormal.sample(&mut rng);
                let n2: f64 = StandardNormal.sample(&mut rng);
                seq.push(vec![means[q][0] + 0.7 * n1, means[q][1] + 0.7 * n2]);
                tq.push(q);
            }
            seqs.push(seq);
            truth.push(tq);
        }
        (seqs, truth)
    }

    #[test]
    fn em_objective_never_decreases_and_recovers_planted_states() {
        let (seqs, truth) = planted(3, 150);
        let cfg = HmmConfig {
            states: 3,
            restarts: 2,
            ..HmmConfig::default()
        };
        let (hmm, reports) = Hmm::fit(&seqs, &cfg, |_, _, _| {}).unwrap();
        for r in &reports {
            for w in r.objective.windows(2) {
                assert!(
                    w[1] >= w[0] - 1e-7 * w[0].abs().max(1.0),
                    "objective fell: {w:?}"
                );
            }
        }
        // Each true state maps to one fitted state on almost every step.
        let mut confusion = [[0usize; 3]; 3];
        for (s, t) in seqs.iter().zip(&truth) {
            for (g, &q) in hmm.posterior(s).gamma_rows().zip(t) {
                let best = (0..3)
                    .max_by(|&a, &b| g[a].partial_cmp(&g[b]).unwrap())
                    .unwrap();
                confusion[q][best] += 1;
            }
        }
        let correct: usize = confusion.iter().map(|row| *row.iter().max().unwrap()).sum();
        assert!(correct as f64 > 0.95 * 600.0, "{confusion:?}");
        // Self-transition probabilities near the planted 0.9 / 0.9 / 0.8.
        let diag: Vec<f64> = (0..3).map(|i| hmm.trans[i * 3 + i]).collect();
        assert!(diag.iter().all(|&d| d > 0.7), "{diag:?}");
    }

    #[test]
    fn too_little_data_says_what_to_change() {
        let seqs = vec![vec![vec![0.0; 6]; 20]];
        let err = Hmm::fit(
            &seqs,
            &HmmConfig {
                states: 25,
                ..HmmConfig::default()
            },
            |_, _, _| {},
        )
        .unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("fewer states"), "{msg}");
    }
}
