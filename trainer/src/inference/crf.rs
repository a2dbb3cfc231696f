//! The remapped CRF (DESIGN.md, inference layer steps 3-4): a linear-chain CRF over the hidden
//! states given the prosody cluster memberships, trained by maximum likelihood *of the fixed
//! HMM posteriors*.
//!
//! Score of a state path `q` given memberships `m_t` (K per step):
//!
//! ```text
//! s(q) = init[q_0] + sum_{t>=1} trans[q_{t-1}, q_t] + sum_t phi_t(q_t),
//! phi_t(j) = sum_{w < W} sum_k obs[j, w, k] * m_{t-w, k}      (causal window; m = 0 before t = 0)
//! p(q | x) = exp(s(q)) / Z(x)
//! ```
//!
//! Training maximizes `sum_t E_{gamma, xi}[log p(q | x)] - (l2 / 2) |theta|^2`; its gradient is
//! the expected features under the HMM posteriors minus those under the CRF (computed with the
//! same scaled forward-backward as the HMM). L-BFGS (argmin, More-Thuente line search) does
//! the optimization; sequences are evaluated in parallel.
//!
//! Online, the belief after step `t` is the normalized forward vector
//! `alpha_t(j) ~ sum_i alpha_{t-1}(i) exp(trans[i,j] + phi_t(j))` ([`Crf::beliefs`]); the runtime's
//! quantized forward step is checked against it.

use argmin::core::{CostFunction, Executor, Gradient, State};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::quasinewton::LBFGS;
use rayon::prelude::*;

use super::hmm::forward_backward;

/// Training settings.
#[derive(Clone, Copy, Debug)]
pub struct CrfConfig {
    /// Window W: memberships of steps `t, t-1, ..., t-W+1` feed step `t`.
    pub window: usize,
    /// L2 regularization strength.
    pub l2: f64,
    /// L-BFGS iteration cap.
    pub max_iter: u64,
}

impl Default for CrfConfig {
    fn default() -> Self {
        Self {
            window: 4,
            l2: 1e-2,
            max_iter: 200,
        }
    }
}

/// One training sequence: memberships and the fixed HMM posteriors.
#[derive(Clone, Debug)]
pub struct TrainSeq {
    /// `m[t][k]`: cluster memberships of step `t`.
    pub memberships: Vec<Vec<f64>>,
    /// HMM state posteriors `gamma[t][i]`.
    pub gamma: Vec<Vec<f64>>,
    /// HMM pairwise posteriors `xi[t][i * S + j]` for `t < T - 1`.
    pub xi: Vec<Vec<f64>>,
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
    /// Final objective (expected log-likelihood minus the L2 term).
    pub objective: f64,
    /// Why it stopped.
    pub termination: String,
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

    /// `phi[t][j]`, the observation score of state `j` at step `t`.
    pub fn observation_scores(&self, m: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let (s, w_len, k) = (self.states, self.window, self.clusters);
        (0..m.len())
            .map(|t| {
                (0..s)
                    .map(|j| {
                        let mut acc = 0.0;
                        for w in 0..w_len.min(t + 1) {
                            let mt = &m[t - w];
                            let base = (j * w_len + w) * k;
                            for kk in 0..k {
                                acc += self.obs[base + kk] * mt[kk];
                            }
                        }
                        acc
                    })
                    .collect()
            })
            .collect()
    }

    /// Posterior marginals and `log Z` under the CRF for one sequence.
    fn marginals(&self, m: &[Vec<f64>]) -> super::hmm::Posterior {
        let phi = self.observation_scores(m);
        let tmax = self.trans.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let imax = self.init.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let trans: Vec<f64> = self.trans.iter().map(|v| (v - tmax).exp()).collect();
        let init: Vec<f64> = self.init.iter().map(|v| (v - imax).exp()).collect();
        let mut post = forward_backward(&init, &trans, &phi);
        post.log_likelihood += imax + tmax * m.len().saturating_sub(1) as f64;
        post
    }

    /// Offline posteriors `P(q_t | x_1..T)` (forward-backward over the whole sequence): what
    /// the offline reference may use, seeing the future.
    pub fn posteriors(&self, m: &[Vec<f64>]) -> Vec<Vec<f64>> {
        self.marginals(m).gamma
    }

    /// Online beliefs: the normalized forward vector after each step.
    pub fn beliefs(&self, m: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let s = self.states;
        let phi = self.observation_scores(m);
        let mut out: Vec<Vec<f64>> = Vec::with_capacity(m.len());
        for (t, ph) in phi.iter().enumerate() {
            let mut logit = vec![0.0; s];
            for j in 0..s {
                logit[j] = if t == 0 {
                    self.init[j] + ph[j]
                } else {
                    let prev = &out[t - 1];
                    let terms: Vec<f64> = (0..s)
                        .map(|i| prev[i].max(1e-300).ln() + self.trans[i * s + j])
                        .collect();
                    super::gaussian::log_sum_exp(&terms) + ph[j]
                };
            }
            let z = super::gaussian::log_sum_exp(&logit);
            out.push(logit.iter().map(|v| (v - z).exp()).collect());
        }
        out
    }

    /// Objective (to maximize) and its gradient over the training sequences.
    pub fn objective_and_gradient(&self, seqs: &[TrainSeq], l2: f64) -> (f64, Vec<f64>) {
        let (s, w_len, k) = (self.states, self.window, self.clusters);
        let n = self.n_params();
        let per_seq: Vec<(f64, Vec<f64>)> = seqs
            .par_iter()
            .map(|q| {
                let mut g = vec![0.0; n];
                let t_len = q.memberships.len();
                if t_len == 0 {
                    return (0.0, g);
                }
                let post = self.marginals(&q.memberships);
                let phi = self.observation_scores(&q.memberships);
                // Expected score under the HMM posteriors.
                let mut e_score = 0.0;
                for j in 0..s {
                    e_score += q.gamma[0][j] * self.init[j];
                }
                for x in &q.xi {
                    for (a, b) in x.iter().zip(&self.trans) {
                        e_score += a * b;
                    }
                }
                for t in 0..t_len {
                    for j in 0..s {
                        e_score += q.gamma[t][j] * phi[t][j];
                    }
                }
                let obj = e_score - post.log_likelihood;
                // Gradient: HMM-expected minus CRF-expected features.
                for j in 0..s {
                    g[j] += q.gamma[0][j] - post.gamma[0][j];
                }
                for (xh, xc) in q.xi.iter().zip(&post.xi) {
                    for idx in 0..s * s {
                        g[s + idx] += xh[idx] - xc[idx];
                    }
                }
                let off = s + s * s;
                for t in 0..t_len {
                    for j in 0..s {
                        let d = q.gamma[t][j] - post.gamma[t][j];
                        if d == 0.0 {
                            continue;
                        }
                        for w in 0..w_len.min(t + 1) {
                            let mt = &q.memberships[t - w];
                            let base = off + (j * w_len + w) * k;
                            for kk in 0..k {
                                g[base + kk] += d * mt[kk];
                            }
                        }
                    }
                }
                (obj, g)
            })
            .collect();
        let theta = self.to_vec();
        let mut obj = -0.5 * l2 * theta.iter().map(|v| v * v).sum::<f64>();
        let mut grad: Vec<f64> = theta.iter().map(|v| -l2 * v).collect();
        for (o, g) in per_seq {
            obj += o;
            for (a, b) in grad.iter_mut().zip(g) {
                *a += b;
            }
        }
        (obj, grad)
    }

    /// Trains on `seqs` (all with `states` posteriors and `clusters` memberships).
    pub fn fit(
        seqs: &[TrainSeq],
        states: usize,
        clusters: usize,
        cfg: &CrfConfig,
    ) -> Result<(Crf, CrfReport), String> {
        let start = Crf::zeros(states, clusters, cfg.window.max(1));
        let steps: usize = seqs
            .iter()
            .map(|q| q.memberships.len())
            .sum::<usize>()
            .max(1);
        let problem = Problem {
            template: start.clone(),
            seqs,
            l2: cfg.l2,
            scale: 1.0 / steps as f64,
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
        let objective = crf.objective_and_gradient(seqs, cfg.l2).0;
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

/// argmin's view: minimize the negative objective per step (scaled for conditioning).
struct Problem<'a> {
    template: Crf,
    seqs: &'a [TrainSeq],
    l2: f64,
    scale: f64,
}

impl CostFunction for Problem<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, p: &Vec<f64>) -> Result<f64, argmin::core::Error> {
        let crf = self.template.with_params(p);
        Ok(-crf.objective_and_gradient(self.seqs, self.l2).0 * self.scale)
    }
}

impl Gradient for Problem<'_> {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;
    fn gradient(&self, p: &Vec<f64>) -> Result<Vec<f64>, argmin::core::Error> {
        let crf = self.template.with_params(p);
        let g = crf.objective_and_gradient(self.seqs, self.l2).1;
        Ok(g.iter().map(|v| -v * self.scale).collect())
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
        TrainSeq {
            memberships,
            gamma,
            xi,
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
        let (_, grad) = crf.objective_and_gradient(&seqs, 0.1);
        let h = 1e-6;
        for i in 0..theta.len() {
            let mut a = theta.clone();
            a[i] += h;
            let mut b = theta.clone();
            b[i] -= h;
            let fa = crf.with_params(&a).objective_and_gradient(&seqs, 0.1).0;
            let fb = crf.with_params(&b).objective_and_gradient(&seqs, 0.1).0;
            let fd = (fa - fb) / (2.0 * h);
            assert!(
                (fd - grad[i]).abs() < 1e-6 * (1.0 + fd.abs()),
                "param {i}: fd {fd} vs {}",
                grad[i]
            );
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
            let xi = (0..t_len - 1)
                .map(|t| {
                    let mut x = vec![0.0; s * s];
                    let i = gamma[t].iter().position(|&v| v == 1.0).unwrap();
                    let j = gamma[t + 1].iter().position(|&v| v == 1.0).unwrap();
                    x[i * s + j] = 1.0;
                    x
                })
                .collect();
            seqs.push(TrainSeq {
                memberships,
                gamma,
                xi,
            });
        }
        let (crf, report) = Crf::fit(
            &seqs,
            s,
            k,
            &CrfConfig {
                window: 2,
                ..CrfConfig::default()
            },
        )
        .unwrap();
        assert!(report.iterations > 0);
        let mut right = 0;
        let mut total = 0;
        for q in &seqs {
            for (b, g) in crf.beliefs(&q.memberships).iter().zip(&q.gamma) {
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
