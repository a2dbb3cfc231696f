//! The paper's Fig. 4 comparison (DESIGN.md, inference layer step 5): how well each method's
//! *online* belief over states explains held-out kinematics.
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
//! - **prior**: the state frequencies, no input.
//!
//! Also the adjusted Rand index between two labelings (hand-written: a dozen lines of
//! contingency counting, not worth a dependency).

use gesture_runtime::inference::StepFeatures;

use super::crf::Crf;
use super::gaussian::{log_sum_exp, Gaussian};
use super::hmm::Seq;
use super::train::{memberships, FitBase, Sequence};

/// Mean per-step score of `y` (normalized) under beliefs `b` and the HMM state Gaussians.
pub fn mean_score(base: &FitBase, y: &[Seq], beliefs: &[Vec<Vec<f64>>]) -> f64 {
    let mut total = 0.0;
    let mut n = 0usize;
    for (ys, bs) in y.iter().zip(beliefs) {
        for (yt, bt) in ys.iter().zip(bs) {
            let terms: Vec<f64> = base
                .hmm
                .emit
                .iter()
                .zip(bt)
                .map(|(g, &b)| b.max(1e-300).ln() + g.log_pdf(yt))
                .collect();
            total += log_sum_exp(&terms);
            n += 1;
        }
    }
    total / n.max(1) as f64
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
