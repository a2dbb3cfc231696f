//! The remapped CRF (docs/method.md, "Inference layer", steps 3-4): a linear-chain CRF over the
//! hidden states given the prosody cluster memberships, trained by maximum likelihood *of the
//! fixed HMM posteriors*.
//!
//! Score of a state path `q` given memberships `m_t` (K per step):
//!
//! ```text
//! s(q) = init[q_0] + sum_{t>=1} trans[q_{t-1}, q_t] + sum_t phi_t(q_t),
//! phi_t(j) = sum_{w < W} sum_k obs[j, w, k] * m_{t-w, k}      (causal window; m = 0 before t = 0)
//! p(q | x) = exp(s(q)) / Z(x)
//! ```
//!
//! Training maximizes `sum_t E_{gamma, xi}[log p(q | x)] - penalty(theta)`; its gradient is the
//! expected features under the HMM posteriors minus those under the CRF (computed with the same
//! scaled forward-backward as the HMM, into reused buffers). L-BFGS (argmin, More-Thuente line
//! search) does the optimization; cost and gradient come from one pass over the data (cached
//! for the line search's paired calls); sequences are evaluated in parallel.
//!
//! ## Regularization: toward the prior, and harder on older window steps
//!
//! The penalty is `(l2 / 2) sum_p c_p (theta_p - theta0_p)^2`, where
//!
//! - `theta0` is [`Crf::prior`], the CRF that *learned nothing*: `init = ln pi`,
//!   `trans[i, j] = ln pi_j`, no observation weights, whose online belief is the state prior
//!   `pi` at every step. A plain L2 toward zero would pull an under-informed model toward the
//!   *uniform* belief, which scores worse than the prior; pulling toward `theta0` means that
//!   the more the data are regularized away, the closer the CRF gets to the prior, never below.
//! - `c_p = 1` for initial, transition and current-step (`w = 0`) observation weights, and
//!   `c_p = lag_penalty` (chosen from 1, 10, 100 on held-out data) for the older window steps
//!   `w >= 1`. Each extra window step adds `S x K` weights that mostly re-count evidence the
//!   forward chain already carries (the belief at `t - 1` was updated with `m_{t-1}`), so an
//!   equally regularized longer window fits the training posteriors with over-confident online
//!   beliefs and scores worse on held-out speech as `W` grows. Penalizing the lagged weights
//!   separately lets them carry only what the chain does not, and a longer window then does no
//!   worse than a short one.
//!
//! Online, the belief after step `t` is the normalized forward vector
//! `alpha_t(j) ~ sum_i alpha_{t-1}(i) exp(trans[i,j] + phi_t(j))` ([`Crf::beliefs`]); the runtime's
//! quantized forward step is checked against it.

use std::sync::Mutex;

use argmin::core::{CostFunction, Executor, Gradient, State};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::quasinewton::LBFGS;
use rayon::prelude::*;

use super::hmm::{forward_backward_into, FbWork, Posterior};

/// Training settings.
#[derive(Clone, Copy, Debug)]
pub struct CrfConfig {
    /// Window W: memberships of steps `t, t-1, ..., t-W+1` feed step `t`.
    pub window: usize,
    /// L2 strength toward [`Crf::prior`] (absolute: the objective is a sum over steps).
    pub l2: f64,
    /// Multiplier of `l2` on the observation weights of window steps `w >= 1`.
    pub lag_penalty: f64,
    /// L-BFGS iteration cap.
    pub max_iter: u64,
}

impl Default for CrfConfig {
    fn default() -> Self {
        Self {
            window: 4,
            l2: 1e-2,
            lag_penalty: 1.0,
            max_iter: 200,
        }
    }
}

/// One training sequence: memberships and the fixed HMM posteriors.
#[derive(Clone, Debug)]
pub struct TrainSeq {
    /// `m[t][k]`: cluster memberships of step `t`.
    pub memberships: Vec<Vec<f64>>,
    /// HMM state posteriors, flat `gamma[t * S + i]`.
    pub gamma: Vec<f64>,
    /// HMM expected transition counts `xi_sum[i * S + j]`.
    pub xi_sum: Vec<f64>,
}

impl TrainSeq {
    /// From memberships and an HMM posterior.
    pub fn new(memberships: Vec<Vec<f64>>, post: Posterior) -> Self {
        Self {
            memberships,
            gamma: post.gamma,
            xi_sum: post.xi_sum,
        }
    }
}

/// A trained CRF.
#[derive(Clone, Debug, PartialEq)]
pub struct Crf {
    /// States S.
    pub states: usize,
    /// Clusters K.
    pub clusters: usize,
    /// Window W.
    pub window: usize,
    /// Initial weights (S).
    pub init: Vec<f64>,
    /// Transition weights, row-major S x S (`trans[i * S + j]`, from i to j).
    pub trans: Vec<f64>,
    /// Observation weights `obs[(j * W + w) * K + k]`.
    pub obs: Vec<f64>,
}

/// What training did.
#[derive(Clone, Debug)]
pub struct CrfReport {
    /// L-BFGS iterations.
    pub iterations: u64,
    /// Final objective (expected log-likelihood minus the penalty).
    pub objective: f64,
    /// Why it stopped.
    pub termination: String,
}

/// Per-thread scratch of the objective.
#[derive(Default)]
struct Scratch {
    phi: Vec<f64>,
    init: Vec<f64>,
    trans: Vec<f64>,
    work: FbWork,
    post: Posterior,
}

impl Crf {
    /// All-zero weights.
    pub fn zeros(states: usize, clusters: usize, window: usize) -> Self {
        Self {
            states,
            clusters,
            window,
            init: vec![0.0; states],
            trans: vec![0.0; states * states],
            obs: vec![0.0; states * window * clusters],
        }
    }

    /// The CRF whose online belief is `prior` at every step (see the module docs).
    pub fn prior(prior: &[f64], clusters: usize, window: usize) -> Self {
        let s = prior.len();
        let ln: Vec<f64> = prior.iter().map(|p| p.max(1e-6).ln()).collect();
        let mut c = Self::zeros(s, clusters, window);
        c.init.copy_from_slice(&ln);
        for i in 0..s {
            c.trans[i * s..(i + 1) * s].copy_from_slice(&ln);
        }
        c
    }

    fn n_params(&self) -> usize {
        self.init.len() + self.trans.len() + self.obs.len()
    }

    fn to_vec(&self) -> Vec<f64> {
        let mut v = Vec::with_capacity(self.n_params());
        v.extend_from_slice(&self.init);
        v.extend_from_slice(&self.trans);
        v.extend_from_slice(&self.obs);
        v
    }

    fn with_params(&self, v: &[f64]) -> Self {
        let s = self.states;
        Self {
            states: s,
            clusters: self.clusters,
            window: self.window,
            init: v[..s].to_vec(),
            trans: v[s..s + s * s].to_vec(),
            obs: v[s + s * s..].to_vec(),
        }
    }

    /// The same weights in a window of `window` steps (extra lags zero, missing ones dropped):
    /// a warm start for another window.
    pub fn rewindowed(&self, window: usize) -> Self {
        let (s, k) = (self.states, self.clusters);
        let mut c = Self::zeros(s, k, window);
        c.init.copy_from_slice(&self.init);
        c.trans.copy_from_slice(&self.trans);
        for j in 0..s {
            for w in 0..window.min(self.window) {
                let (a, b) = ((j * window + w) * k, (j * self.window + w) * k);
                c.obs[a..a + k].copy_from_slice(&self.obs[b..b + k]);
            }
        }
        c
    }

    /// Penalty multiplier of every parameter (1, or `lag_penalty` for lagged observation
    /// weights), in [`Crf::to_vec`] order.
    fn penalty_scale(&self, lag_penalty: f64) -> Vec<f64> {
        let (s, w_len, k) = (self.states, self.window, self.clusters);
        let mut c = vec![1.0; self.n_params()];
        let off = s + s * s;
        for j in 0..s {
            for w in 1..w_len {
                let base = off + (j * w_len + w) * k;
                c[base..base + k].fill(lag_penalty);
            }
        }
        c
    }

    /// `phi[t * S + j]`, the observation score of state `j` at step `t`, into `out`.
    fn observation_scores_into(&self, m: &[Vec<f64>], out: &mut Vec<f64>) {
        let (s, w_len, k) = (self.states, self.window, self.clusters);
        out.clear();
        out.resize(m.len() * s, 0.0);
        for t in 0..m.len() {
            let row = &mut out[t * s..(t + 1) * s];
            for (j, r) in row.iter_mut().enumerate() {
                let mut acc = 0.0;
                for w in 0..w_len.min(t + 1) {
                    let mt = &m[t - w];
                    let wts = &self.obs[(j * w_len + w) * k..(j * w_len + w + 1) * k];
                    for kk in 0..k {
                        acc += wts[kk] * mt[kk];
                    }
                }
                *r = acc;
            }
        }
    }

    /// `phi[t][j]`, the observation score of state `j` at step `t`.
    pub fn observation_scores(&self, m: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let mut flat = Vec::new();
        self.observation_scores_into(m, &mut flat);
        flat.chunks_exact(self.states.max(1))
            .map(<[f64]>::to_vec)
            .collect()
    }

    /// Posterior marginals and `log Z` under the CRF for one sequence, into `sc.post` (the
    /// observation scores stay in `sc.phi`).
    fn marginals_into(&self, m: &[Vec<f64>], sc: &mut Scratch) {
        self.observation_scores_into(m, &mut sc.phi);
        let tmax = self.trans.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let imax = self.init.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        sc.trans.clear();
        sc.trans.extend(self.trans.iter().map(|v| (v - tmax).exp()));
        sc.init.clear();
        sc.init.extend(self.init.iter().map(|v| (v - imax).exp()));
        forward_backward_into(&sc.init, &sc.trans, &sc.phi, &mut sc.work, &mut sc.post);
        sc.post.log_likelihood += imax + tmax * m.len().saturating_sub(1) as f64;
    }

    fn marginals(&self, m: &[Vec<f64>]) -> Posterior {
        let mut sc = Scratch::default();
        self.marginals_into(m, &mut sc);
        sc.post
    }

    /// Offline posteriors `P(q_t | x_1..T)` (forward-backward over the whole sequence): what
    /// the offline reference may use, seeing the future.
    pub fn posteriors(&self, m: &[Vec<f64>]) -> Vec<Vec<f64>> {
        self.marginals(m)
            .gamma_rows()
            .map(<[f64]>::to_vec)
            .collect()
    }

    /// Online beliefs: the normalized forward vector after each step.
    pub fn beliefs(&self, m: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let s = self.states;
        let mut phi = Vec::new();
        self.observation_scores_into(m, &mut phi);
        let mut out: Vec<Vec<f64>> = Vec::with_capacity(m.len());
        let mut logit = vec![0.0; s];
        let mut terms = vec![0.0; s];
        for t in 0..m.len() {
            let ph = &phi[t * s..(t + 1) * s];
            for j in 0..s {
                logit[j] = if t == 0 {
                    self.init[j] + ph[j]
                } else {
                    let prev = &out[t - 1];
                    for i in 0..s {
                        terms[i] = prev[i].max(1e-300).ln() + self.trans[i * s + j];
                    }
                    super::gaussian::log_sum_exp(&terms) + ph[j]
                };
            }
            let z = super::gaussian::log_sum_exp(&logit);
            out.push(logit.iter().map(|v| (v - z).exp()).collect());
        }
        out
    }

    /// Expected log-likelihood of the HMM posteriors and its gradient, summed over `seqs`
    /// (no penalty).
    fn data_term(&self, seqs: &[TrainSeq]) -> (f64, Vec<f64>) {
        let (s, w_len, k) = (self.states, self.window, self.clusters);
        let n = self.n_params();
        let off = s + s * s;
        let zero = || (0.0, vec![0.0; n]);
        seqs.par_iter()
            .fold(
                || (zero(), Scratch::default()),
                |((mut obj, mut g), mut sc), q| {
                    let t_len = q.memberships.len();
                    if t_len == 0 {
                        return ((obj, g), sc);
                    }
                    self.marginals_into(&q.memberships, &mut sc);
                    let (post, phi) = (&sc.post, &sc.phi);
                    // Expected score under the HMM posteriors.
                    let mut e_score = 0.0;
                    for j in 0..s {
                        e_score += q.gamma[j] * self.init[j];
                        g[j] += q.gamma[j] - post.gamma[j];
                    }
                    for idx in 0..s * s {
                        e_score += q.xi_sum[idx] * self.trans[idx];
                        g[s + idx] += q.xi_sum[idx] - post.xi_sum[idx];
                    }
                    for t in 0..t_len {
                        for j in 0..s {
                            let gh = q.gamma[t * s + j];
                            e_score += gh * phi[t * s + j];
                            let d = gh - post.gamma[t * s + j];
                            if d == 0.0 {
                                continue;
                            }
                            for w in 0..w_len.min(t + 1) {
                                let mt = &q.memberships[t - w];
                                let base = off + (j * w_len + w) * k;
                                for (gv, mv) in g[base..base + k].iter_mut().zip(mt) {
                                    *gv += d * mv;
                                }
                            }
                        }
                    }
                    obj += e_score - post.log_likelihood;
                    ((obj, g), sc)
                },
            )
            .map(|(acc, _)| acc)
            .reduce(zero, |(oa, mut ga), (ob, gb)| {
                for (a, b) in ga.iter_mut().zip(&gb) {
                    *a += b;
                }
                (oa + ob, ga)
            })
    }

    /// Objective (to maximize) and its gradient over the training sequences, with the L2
    /// penalty of strength `l2` toward `center` (lagged observation weights times
    /// `lag_penalty`; see the module docs). `center = None` penalizes toward zero.
    pub fn objective_and_gradient(
        &self,
        seqs: &[TrainSeq],
        l2: f64,
        lag_penalty: f64,
        center: Option<&Crf>,
    ) -> (f64, Vec<f64>) {
        let (mut obj, mut grad) = self.data_term(seqs);
        if l2 > 0.0 {
            let theta = self.to_vec();
            let c0 = center.map(Crf::to_vec);
            let scale = self.penalty_scale(lag_penalty);
            for p in 0..theta.len() {
                let d = theta[p] - c0.as_ref().map_or(0.0, |c| c[p]);
                obj -= 0.5 * l2 * scale[p] * d * d;
                grad[p] -= l2 * scale[p] * d;
            }
        }
        (obj, grad)
    }

    /// Expected log-likelihood of held-out HMM posteriors (no penalty).
    pub fn expected_log_likelihood(&self, seqs: &[TrainSeq]) -> f64 {
        self.data_term(seqs).0
    }

    /// Trains on `seqs` (all with `states` posteriors and `clusters` memberships), penalized
    /// toward `center` (see the module docs) and starting from `start` (a warm start; the
    /// center when `None`).
    pub fn fit(
        seqs: &[TrainSeq],
        center: &Crf,
        start: Option<&Crf>,
        cfg: &CrfConfig,
    ) -> Result<(Crf, CrfReport), String> {
        let start = start.unwrap_or(center).clone();
        let steps: usize = seqs
            .iter()
            .map(|q| q.memberships.len())
            .sum::<usize>()
            .max(1);
        let problem = Problem {
            template: start.clone(),
            seqs,
            l2: cfg.l2,
            lag_penalty: cfg.lag_penalty,
            center,
            scale: 1.0 / steps as f64,
            cache: Mutex::new(None),
        };
        let linesearch = MoreThuenteLineSearch::new();
        let solver = LBFGS::new(linesearch, 10)
            .with_tolerance_grad(1e-6)
            .map_err(|e| e.to_string())?
            .with_tolerance_cost(1e-10)
            .map_err(|e| e.to_string())?;
        let res = Executor::new(problem, solver)
            .configure(|st| st.param(start.to_vec()).max_iters(cfg.max_iter))
            .run()
            .map_err(|e| e.to_string())?;
        let state = res.state();
        let best = state
            .get_best_param()
            .cloned()
            .unwrap_or_else(|| start.to_vec());
        let crf = start.with_params(&best);
        let objective = -state.get_best_cost() * steps as f64;
        Ok((
            crf,
            CrfReport {
                iterations: state.get_iter(),
                objective,
                termination: state.get_termination_status().to_string(),
            },
        ))
    }
}

/// Parameters, cost and gradient of the last evaluation.
type Evaluated = (Vec<f64>, f64, Vec<f64>);

/// argmin's view: minimize the negative objective per step (scaled for conditioning). Cost
/// and gradient are computed together and cached for the parameters last seen.
struct Problem<'a> {
    template: Crf,
    seqs: &'a [TrainSeq],
    l2: f64,
    lag_penalty: f64,
    center: &'a Crf,
    scale: f64,
    cache: Mutex<Option<Evaluated>>,
}

impl Problem<'_> {
    fn eval(&self, p: &[f64]) -> (f64, Vec<f64>) {
        let mut cache = self.cache.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((q, c, g)) = cache.as_ref() {
            if q.as_slice() == p {
                return (*c, g.clone());
            }
        }
        let crf = self.template.with_params(p);
        let (obj, grad) =
            crf.objective_and_gradient(self.seqs, self.l2, self.lag_penalty, Some(self.center));
        let c = -obj * self.scale;
        let g: Vec<f64> = grad.iter().map(|v| -v * self.scale).collect();
        *cache = Some((p.to_vec(), c, g.clone()));
        (c, g)
    }
}

impl CostFunction for Problem<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, p: &Vec<f64>) -> Result<f64, argmin::core::Error> {
        Ok(self.eval(p).0)
    }
}

impl Gradient for Problem<'_> {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;
    fn gradient(&self, p: &Vec<f64>) -> Result<Vec<f64>, argmin::core::Error> {
        Ok(self.eval(p).1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_seq(rng: &mut ChaCha8Rng, t_len: usize, s: usize, k: usize) -> TrainSeq {
        let norm = |v: Vec<f64>| {
            let z: f64 = v.iter().sum();
            v.into_iter().map(|x| x / z).collect::<Vec<f64>>()
        };
        let memberships = (0..t_len)
            .map(|_| norm((0..k).map(|_| rng.random::<f64>() + 0.01).collect()))
            .collect();
        let xi: Vec<Vec<f64>> = (0..t_len - 1)
            .map(|_| norm((0..s * s).map(|_| rng.random::<f64>() + 0.01).collect()))
            .collect();
        // Marginals consistent with xi (row sums for t < T-1, column sums for the last).
        let mut gamma: Vec<Vec<f64>> = xi
            .iter()
            .map(|x| (0..s).map(|i| (0..s).map(|j| x[i * s + j]).sum()).collect())
            .collect();
        let last = &xi[t_len - 2];
        gamma.push(
            (0..s)
                .map(|j| (0..s).map(|i| last[i * s + j]).sum())
                .collect(),
        );
        let mut xi_sum = vec![0.0; s * s];
        for x in &xi {
            for (a, b) in xi_sum.iter_mut().zip(x) {
                *a += b;
            }
        }
        TrainSeq {
            memberships,
            gamma: gamma.concat(),
            xi_sum,
        }
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let (s, k, w) = (3, 4, 2);
        let seqs: Vec<TrainSeq> = (0..2).map(|_| random_seq(&mut rng, 7, s, k)).collect();
        let mut crf = Crf::zeros(s, k, w);
        let mut theta = crf.to_vec();
        for v in theta.iter_mut() {
            *v = rng.random_range(-1.0..1.0);
        }
        crf = crf.with_params(&theta);
        let center = Crf::prior(&[0.5, 0.3, 0.2], k, w);
        let obj = |c: &Crf| c.objective_and_gradient(&seqs, 0.1, 7.0, Some(&center));
        let (_, grad) = obj(&crf);
        let h = 1e-6;
        for i in 0..theta.len() {
            let mut a = theta.clone();
            a[i] += h;
            let mut b = theta.clone();
            b[i] -= h;
            let fa = obj(&crf.with_params(&a)).0;
            let fb = obj(&crf.with_params(&b)).0;
            let fd = (fa - fb) / (2.0 * h);
            assert!(
                (fd - grad[i]).abs() < 1e-6 * (1.0 + fd.abs()),
                "param {i}: fd {fd} vs {}",
                grad[i]
            );
        }
    }

    #[test]
    fn the_prior_crf_believes_the_prior_and_heavy_l2_stays_there() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let (s, k, w) = (3, 4, 3);
        let prior = [0.6, 0.3, 0.1];
        let center = Crf::prior(&prior, k, w);
        let q = random_seq(&mut rng, 30, s, k);
        for b in center.beliefs(&q.memberships) {
            for (x, p) in b.iter().zip(&prior) {
                assert!((x - p).abs() < 1e-12, "{b:?}");
            }
        }
        // An overwhelming penalty toward the prior CRF leaves the belief at the prior (a
        // penalty toward zero would leave it uniform).
        let seqs = vec![random_seq(&mut rng, 40, s, k)];
        let cfg = CrfConfig {
            window: w,
            l2: 1e9,
            lag_penalty: 10.0,
            ..CrfConfig::default()
        };
        let (crf, _) = Crf::fit(&seqs, &center, None, &cfg).unwrap();
        for b in crf.beliefs(&q.memberships) {
            for (x, p) in b.iter().zip(&prior) {
                assert!((x - p).abs() < 1e-6, "{b:?}");
            }
        }
    }

    #[test]
    fn log_partition_matches_enumeration() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let (s, k, w) = (2, 3, 2);
        let q = random_seq(&mut rng, 4, s, k);
        let mut crf = Crf::zeros(s, k, w);
        let theta: Vec<f64> = (0..crf.n_params())
            .map(|_| rng.random_range(-2.0..2.0))
            .collect();
        crf = crf.with_params(&theta);
        let phi = crf.observation_scores(&q.memberships);
        let mut z = 0.0;
        for code in 0..s.pow(4) {
            let path: Vec<usize> = (0..4).map(|t| (code / s.pow(t as u32)) % s).collect();
            let mut sc = crf.init[path[0]] + phi[0][path[0]];
            for t in 1..4 {
                sc += crf.trans[path[t - 1] * s + path[t]] + phi[t][path[t]];
            }
            z += f64::exp(sc);
        }
        let post = crf.marginals(&q.memberships);
        assert!((post.log_likelihood - z.ln()).abs() < 1e-10);
    }

    #[test]
    fn learns_states_that_prosody_predicts() {
        // Planted: state = argmax cluster of the current step (with noise); the CRF trained on
        // one-hot "posteriors" must put most belief on the right state online.
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let (s, k) = (3, 3);
        let mut seqs = Vec::new();
        let mut truth = Vec::new();
        for _ in 0..6 {
            let t_len = 80;
            let mut state = 0usize;
            let mut memberships = Vec::new();
            let mut gamma = Vec::new();
            for _ in 0..t_len {
                if rng.random_bool(0.2) {
                    state = rng.random_range(0..s);
                }
                let mut m = vec![0.1; k];
                m[if rng.random_bool(0.85) {
                    state
                } else {
                    rng.random_range(0..k)
                }] = 0.8;
                memberships.push(m);
                let mut g = vec![0.0; s];
                g[state] = 1.0;
                gamma.push(g);
            }
            let mut xi_sum = vec![0.0; s * s];
            for t in 0..t_len - 1 {
                let i = gamma[t].iter().position(|&v| v == 1.0).unwrap();
                let j = gamma[t + 1].iter().position(|&v| v == 1.0).unwrap();
                xi_sum[i * s + j] += 1.0;
            }
            truth.push(gamma.clone());
            seqs.push(TrainSeq {
                memberships,
                gamma: gamma.concat(),
                xi_sum,
            });
        }
        let center = Crf::prior(&[1.0 / 3.0; 3], k, 2);
        let (crf, report) = Crf::fit(
            &seqs,
            &center,
            None,
            &CrfConfig {
                window: 2,
                ..CrfConfig::default()
            },
        )
        .unwrap();
        assert!(report.iterations > 0);
        let mut right = 0;
        let mut total = 0;
        for (q, tr) in seqs.iter().zip(&truth) {
            for (b, g) in crf.beliefs(&q.memberships).iter().zip(tr) {
                let best = (0..s)
                    .max_by(|&a, &c| b[a].partial_cmp(&b[c]).unwrap())
                    .unwrap();
                right += (g[best] == 1.0) as usize;
                total += 1;
            }
        }
        assert!(right as f64 > 0.8 * total as f64, "{right}/{total}");
    }
}
