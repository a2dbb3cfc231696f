//! Gaussian mixture over per-step prosody, with unvoiced F0 marginalized out (docs/method.md,
//! "Inference layer", step 2).
//!
//! A step's prosody is `x = (f0, o)`: `f0` the (normalized) log pitch, missing when the step is
//! unvoiced, and `o = (intensity, log length)`, always present. Component `k` is
//!
//! ```text
//! p(x | k) = v_k     N(o; mu_k, Sigma_k) N(f0; a_k + b_k . o, s_k^2)   (voiced)
//!          = (1-v_k) N(o; mu_k, Sigma_k)                               (unvoiced)
//! ```
//!
//! i.e. a full-covariance Gaussian over `(o, f0)` factored as marginal times conditional, plus
//! a voicing probability. For an unvoiced step the unknown F0 integrates out exactly (the paper
//! models it as a uniform unknown, which contributes the same constant to every component), so
//! memberships of unvoiced steps depend only on what was observed. This factorization also
//! keeps every M-step closed-form and every covariance valid: the marginal is a weighted
//! Gaussian fit over all steps, the conditional a weighted least-squares regression over voiced
//! steps. Priors (covariance floor, pseudo-counts, a ridge on the regression) make it MAP-EM.

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::gaussian::{log_sum_exp, Gaussian};

/// One step's prosody for the mixture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProsodyPoint {
    /// Normalized log F0, `None` when unvoiced.
    pub f0: Option<f64>,
    /// Always-observed part: (normalized intensity, log length).
    pub obs: [f64; 2],
}

/// EM settings.
#[derive(Clone, Copy, Debug)]
pub struct GmmConfig {
    /// Number of clusters K.
    pub clusters: usize,
    /// Iteration cap.
    pub max_iter: usize,
    /// Relative tolerance on the objective per point.
    pub tol: f64,
    /// Covariance floor (absolute, in the units of the features).
    pub cov_floor: f64,
    /// Seed.
    pub seed: u64,
}

impl Default for GmmConfig {
    fn default() -> Self {
        Self {
            clusters: 8,
            max_iter: 300,
            tol: 1e-7,
            cov_floor: 1e-3,
            seed: 1,
        }
    }
}

/// One mixture component.
#[derive(Clone, Debug)]
pub struct Component {
    /// Mixing weight.
    pub weight: f64,
    /// Probability that a step of this cluster is voiced.
    pub voiced: f64,
    /// Marginal over `o`.
    pub obs: Gaussian,
    /// Regression of f0 on `o`: `f0 ~ coef[0] + coef[1] o[0] + coef[2] o[1]`.
    pub coef: [f64; 3],
    /// Residual variance of f0.
    pub f0_var: f64,
}

/// A fitted mixture.
#[derive(Clone, Debug)]
pub struct Gmm {
    /// Components.
    pub components: Vec<Component>,
}

impl Gmm {
    /// `log p(x, k)` for every component.
    pub fn log_joint(&self, x: &ProsodyPoint) -> Vec<f64> {
        self.components
            .iter()
            .map(|c| {
                let lo = c.obs.log_pdf(&x.obs);
                let lw = c.weight.max(1e-300).ln();
                match x.f0 {
                    Some(f) => {
                        let pred = c.coef[0] + c.coef[1] * x.obs[0] + c.coef[2] * x.obs[1];
                        let r = f - pred;
                        let lf = -0.5 * (2.0 * std::f64::consts::PI * c.f0_var).ln()
                            - 0.5 * r * r / c.f0_var;
                        lw + c.voiced.max(1e-300).ln() + lo + lf
                    }
                    None => lw + (1.0 - c.voiced).max(1e-300).ln() + lo,
                }
            })
            .collect()
    }

    /// Cluster memberships `P(k | x)`.
    pub fn memberships(&self, x: &ProsodyPoint) -> Vec<f64> {
        let lj = self.log_joint(x);
        let z = log_sum_exp(&lj);
        lj.iter().map(|v| (v - z).exp()).collect()
    }

    /// `log p(x)`.
    pub fn log_likelihood(&self, x: &ProsodyPoint) -> f64 {
        log_sum_exp(&self.log_joint(x))
    }

    /// Fits by MAP-EM. Returns the model and the objective after every iteration.
    pub fn fit(points: &[ProsodyPoint], cfg: &GmmConfig) -> Option<(Gmm, Vec<f64>)> {
        let k = cfg.clusters;
        if k == 0 || points.len() < 2 * k {
            return None;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
        // Initialize responsibilities from random centres on the observed part (k-means++ like).
        let obs: Vec<Vec<f64>> = points.iter().map(|p| p.obs.to_vec()).collect();
        let mut centres: Vec<[f64; 2]> = vec![points[rng.random_range(0..points.len())].obs];
        while centres.len() < k {
            let d2: Vec<f64> = points
                .iter()
                .map(|p| {
                    centres
                        .iter()
                        .map(|c| (p.obs[0] - c[0]).powi(2) + (p.obs[1] - c[1]).powi(2))
                        .fold(f64::INFINITY, f64::min)
                })
                .collect();
            let total: f64 = d2.iter().sum();
            let mut u = rng.random::<f64>() * total;
            let mut idx = rng.random_range(0..points.len());
            if total > 0.0 {
                for (i, &w) in d2.iter().enumerate() {
                    if u < w {
                        idx = i;
                        break;
                    }
                    u -= w;
                }
            }
            centres.push(points[idx].obs);
        }
        let mut resp: Vec<Vec<f64>> = points
            .iter()
            .map(|p| {
                let mut best = (f64::INFINITY, 0);
                for (c, cen) in centres.iter().enumerate() {
                    let d = (p.obs[0] - cen[0]).powi(2) + (p.obs[1] - cen[1]).powi(2);
                    if d < best.0 {
                        best = (d, c);
                    }
                }
                (0..k)
                    .map(|c| if c == best.1 { 1.0 } else { 0.0 })
                    .collect()
            })
            .collect();
        let mut objective = Vec::new();
        let mut gmm = m_step(points, &obs, &resp, cfg, None);
        for it in 0..cfg.max_iter {
            // E-step and objective.
            let mut ll = 0.0;
            for (p, r) in points.iter().zip(resp.iter_mut()) {
                let lj = gmm.log_joint(p);
                let z = log_sum_exp(&lj);
                ll += z;
                for (rv, l) in r.iter_mut().zip(&lj) {
                    *rv = (l - z).exp();
                }
            }
            let obj = ll + log_prior(&gmm, cfg);
            objective.push(obj);
            if it > 0 && (obj - objective[it - 1]).abs() < cfg.tol * points.len() as f64 {
                break;
            }
            gmm = m_step(points, &obs, &resp, cfg, Some(&gmm));
        }
        Some((gmm, objective))
    }
}

const PSEUDO: f64 = 1e-2;
const RIDGE: f64 = 1e-3;

fn log_prior(g: &Gmm, cfg: &GmmConfig) -> f64 {
    g.components
        .iter()
        .map(|c| {
            PSEUDO * c.weight.max(1e-300).ln()
                + PSEUDO * (c.voiced.max(1e-300).ln() + (1.0 - c.voiced).max(1e-300).ln())
                + c.obs.log_prior(cfg.cov_floor)
                // Ridge on the slopes, scaled by the residual variance, and an
                // inverse-gamma-style prior on that variance (both match the M-step).
                - 0.5 * RIDGE * (c.coef[1].powi(2) + c.coef[2].powi(2)) / c.f0_var
                - 0.5 * c.f0_var.ln()
                - 0.5 * cfg.cov_floor / c.f0_var
        })
        .sum()
}

fn m_step(
    points: &[ProsodyPoint],
    obs: &[Vec<f64>],
    resp: &[Vec<f64>],
    cfg: &GmmConfig,
    prev: Option<&Gmm>,
) -> Gmm {
    let k = cfg.clusters;
    let n = points.len() as f64;
    let mean_obs = [
        obs.iter().map(|o| o[0]).sum::<f64>() / n,
        obs.iter().map(|o| o[1]).sum::<f64>() / n,
    ];
    let components = (0..k)
        .map(|c| {
            let w: Vec<f64> = resp.iter().map(|r| r[c]).collect();
            let nk: f64 = w.iter().sum();
            let nv: f64 = points
                .iter()
                .zip(&w)
                .filter(|(p, _)| p.f0.is_some())
                .map(|(_, w)| w)
                .sum();
            let fallback = prev
                .map(|g| g.components[c].obs.mean().as_slice().to_vec())
                .unwrap_or_else(|| mean_obs.to_vec());
            let gauss = Gaussian::fit_weighted(obs, &w, cfg.cov_floor, &fallback);
            // Weighted ridge regression of f0 on [1, o] over voiced points.
            let mut xtx = DMatrix::<f64>::zeros(3, 3);
            let mut xty = DVector::<f64>::zeros(3);
            for (p, &wi) in points.iter().zip(&w) {
                if let Some(f) = p.f0 {
                    let row = [1.0, p.obs[0], p.obs[1]];
                    for a in 0..3 {
                        xty[a] += wi * row[a] * f;
                        for b in 0..3 {
                            xtx[(a, b)] += wi * row[a] * row[b];
                        }
                    }
                }
            }
            xtx[(1, 1)] += RIDGE;
            xtx[(2, 2)] += RIDGE;
            let coef = xtx
                .clone()
                .cholesky()
                .map(|ch| ch.solve(&xty))
                .map(|v| [v[0], v[1], v[2]])
                .unwrap_or([0.0, 0.0, 0.0]);
            let mut ss = cfg.cov_floor + RIDGE * (coef[1].powi(2) + coef[2].powi(2));
            for (p, &wi) in points.iter().zip(&w) {
                if let Some(f) = p.f0 {
                    let r = f - (coef[0] + coef[1] * p.obs[0] + coef[2] * p.obs[1]);
                    ss += wi * r * r;
                }
            }
            Component {
                weight: (nk + PSEUDO) / (n + k as f64 * PSEUDO),
                voiced: (nv + PSEUDO) / (nk + 2.0 * PSEUDO),
                obs: gauss,
                coef,
                f0_var: ss / (nv + 1.0),
            }
        })
        .collect();
    Gmm { components }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_distr::{Distribution, StandardNormal};

    fn sample(seed: u64, n: usize) -> (Vec<ProsodyPoint>, Vec<usize>) {
        // Three planted clusters: loud/high voiced, quiet/long mostly unvoiced, mid voiced.
        let centres = [
            ([2.0, -1.5], 1.0, 0.95),
            ([-2.0, 0.5], -0.5, 0.1),
            ([0.0, -0.5], 0.0, 0.9),
        ];
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut pts = Vec::new();
        let mut truth = Vec::new();
        for _ in 0..n {
            let c = rng.random_range(0..3);
            let (o, f, v) = centres[c];
            let g = |r: &mut ChaCha8Rng| -> f64 { StandardNormal.sample(r) };
            let obs = [o[0] + 0.4 * g(&mut rng), o[1] + 0.3 * g(&mut rng)];
            let voiced = rng.random_bool(v);
            pts.push(ProsodyPoint {
                f0: if voiced {
                    Some(f + 0.2 * g(&mut rng))
                } else {
                    None
                },
                obs,
            });
            truth.push(c);
        }
        (pts, truth)
    }

    #[test]
    fn recovers_planted_clusters_and_voicing() {
        let (pts, truth) = sample(4, 1500);
        let (gmm, obj) = Gmm::fit(
            &pts,
            &GmmConfig {
                clusters: 3,
                ..GmmConfig::default()
            },
        )
        .unwrap();
        for w in obj.windows(2) {
            assert!(
                w[1] >= w[0] - 1e-6 * w[0].abs().max(1.0),
                "objective fell {w:?}"
            );
        }
        let mut confusion = [[0usize; 3]; 3];
        for (p, &t) in pts.iter().zip(&truth) {
            let m = gmm.memberships(p);
            let best = (0..3)
                .max_by(|&a, &b| m[a].partial_cmp(&m[b]).unwrap())
                .unwrap();
            confusion[t][best] += 1;
        }
        let correct: usize = confusion.iter().map(|r| *r.iter().max().unwrap()).sum();
        assert!(correct as f64 > 0.9 * pts.len() as f64, "{confusion:?}");
        // Voicing probabilities recovered (one cluster near 0.1).
        let mut v: Vec<f64> = gmm.components.iter().map(|c| c.voiced).collect();
        v.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert!((v[0] - 0.1).abs() < 0.06, "{v:?}");
    }

    #[test]
    fn unvoiced_membership_ignores_f0_entirely() {
        let (pts, _) = sample(5, 600);
        let (gmm, _) = Gmm::fit(
            &pts,
            &GmmConfig {
                clusters: 3,
                ..GmmConfig::default()
            },
        )
        .unwrap();
        let x = ProsodyPoint {
            f0: None,
            obs: [0.3, -0.2],
        };
        let m = gmm.memberships(&x);
        // Equals the posterior under the marginal model with weights w_k (1 - v_k).
        let lj: Vec<f64> = gmm
            .components
            .iter()
            .map(|c| c.weight.ln() + (1.0 - c.voiced).ln() + c.obs.log_pdf(&x.obs))
            .collect();
        let z = log_sum_exp(&lj);
        for (a, l) in m.iter().zip(&lj) {
            assert!((a - (l - z).exp()).abs() < 1e-12);
        }
        assert!((m.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }
}
