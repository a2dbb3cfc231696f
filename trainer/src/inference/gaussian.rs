//! Multivariate Gaussians with full covariance, fitted from weighted data with a covariance
//! floor that is a proper prior (so EM stays monotone in the objective it reports).
//!
//! The floor is the MAP estimate under an inverse-Wishart-style prior: a weighted scatter `S`
//! with total weight `n` gives `Sigma = (S + eps I) / (n + 1)`, which maximizes
//! `-(n/2) log|Sigma| - tr(S Sigma^-1)/2 - log|Sigma|/2 - tr(eps Sigma^-1)/2`. Every Gaussian
//! is therefore positive definite, even for a state that owns one point, and [`log_prior`]
//! gives the term EM adds to its objective.
//!
//! More generally ([`CovPrior`]), the prior is an inverse Wishart with scale matrix `Psi` and
//! `nu` degrees of freedom (counted as pseudo-observations): `Sigma = (S + Psi) / (n + nu)`,
//! log prior `-(nu/2) log|Sigma| - tr(Psi Sigma^-1)/2`. The plain floor is `Psi = eps I`,
//! `nu = 1`; [`CovPrior::shrink_to`] adds `tau` pseudo-observations spread like a reference
//! covariance, which pulls a state's covariance toward it (docs/method.md, "Inference layer").
//!
//! [`log_prior`]: Gaussian::log_prior

use nalgebra::{Cholesky, DMatrix, DVector, Dyn};

/// An inverse-Wishart prior on a covariance (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct CovPrior {
    /// Scale matrix `Psi` (a scatter: pseudo-observations times a covariance).
    pub psi: DMatrix<f64>,
    /// Pseudo-observations `nu`.
    pub nu: f64,
}

impl CovPrior {
    /// The plain floor `Psi = eps I`, `nu = 1`.
    pub fn floor(dims: usize, eps: f64) -> Self {
        Self {
            psi: DMatrix::identity(dims, dims) * eps,
            nu: 1.0,
        }
    }

    /// The floor plus `tau` pseudo-observations with covariance
    /// `(1 - iso) reference + iso (tr(reference) / d) I`: a state that owns few distinct
    /// vectors keeps a covariance close to the reference instead of collapsing onto them, and
    /// the isotropic part keeps directions where the reference itself is nearly singular open.
    pub fn shrink_to(reference: &DMatrix<f64>, tau: f64, iso: f64, eps: f64) -> Self {
        let d = reference.nrows();
        let mean_var = reference.trace() / d.max(1) as f64;
        let target = reference * (1.0 - iso) + DMatrix::identity(d, d) * (iso * mean_var);
        Self {
            psi: target * tau + DMatrix::identity(d, d) * eps,
            nu: tau + 1.0,
        }
    }
}

/// A Gaussian `N(mean, cov)` with its Cholesky factor cached.
#[derive(Clone, Debug)]
pub struct Gaussian {
    mean: DVector<f64>,
    cov: DMatrix<f64>,
    /// Lower-triangular `L` with `cov = L L^T`.
    chol: Cholesky<f64, Dyn>,
    /// `-(d/2) log(2 pi) - (1/2) log|cov|`.
    log_norm: f64,
}

impl Gaussian {
    /// A Gaussian from a mean and a covariance; `None` if the covariance is not positive
    /// definite or not finite.
    pub fn new(mean: DVector<f64>, cov: DMatrix<f64>) -> Option<Self> {
        let d = mean.len();
        if cov.nrows() != d || cov.ncols() != d || !cov.iter().all(|v| v.is_finite()) {
            return None;
        }
        let sym = (&cov + cov.transpose()) * 0.5;
        let chol = Cholesky::new(sym.clone())?;
        let log_det = 2.0 * chol.l().diagonal().iter().map(|v| v.ln()).sum::<f64>();
        if !log_det.is_finite() {
            return None;
        }
        let log_norm = -0.5 * d as f64 * (2.0 * std::f64::consts::PI).ln() - 0.5 * log_det;
        Some(Self {
            mean,
            cov: sym,
            chol,
            log_norm,
        })
    }

    /// Dimension.
    pub fn dim(&self) -> usize {
        self.mean.len()
    }

    /// Mean vector.
    pub fn mean(&self) -> &DVector<f64> {
        &self.mean
    }

    /// Covariance matrix.
    pub fn cov(&self) -> &DMatrix<f64> {
        &self.cov
    }

    /// `log N(x; mean, cov)`. Allocation-free for dimensions up to 32 (forward substitution
    /// into a stack buffer).
    pub fn log_pdf(&self, x: &[f64]) -> f64 {
        let d = self.dim();
        let l = self.chol.l_dirty();
        let mut stack = [0.0f64; 32];
        let mut heap;
        let z: &mut [f64] = if d <= 32 {
            &mut stack[..d]
        } else {
            heap = vec![0.0; d];
            &mut heap
        };
        let mut q = 0.0;
        for i in 0..d {
            let mut v = x[i] - self.mean[i];
            for j in 0..i {
                v -= l[(i, j)] * z[j];
            }
            z[i] = v / l[(i, i)];
            q += z[i] * z[i];
        }
        self.log_norm - 0.5 * q
    }

    /// MAP fit from rows `xs` with weights `w` (covariance floor `eps`, see the module docs).
    /// With zero total weight, the result is `N(fallback_mean, eps I)`.
    pub fn fit_weighted(xs: &[Vec<f64>], w: &[f64], eps: f64, fallback_mean: &[f64]) -> Self {
        let prior = CovPrior::floor(fallback_mean.len(), eps);
        Self::fit_map(xs, w, &prior, fallback_mean)
    }

    /// MAP fit from rows `xs` with weights `w` under `prior`: `Sigma = (S + Psi) / (n + nu)`.
    /// With zero total weight, the result is `N(fallback_mean, Psi / nu)`.
    pub fn fit_map(xs: &[Vec<f64>], w: &[f64], prior: &CovPrior, fallback_mean: &[f64]) -> Self {
        let d = fallback_mean.len();
        let eps = prior.psi.trace() / (d.max(1) as f64 * prior.nu.max(1e-12));
        let n: f64 = w.iter().sum();
        let mut mean = DVector::<f64>::zeros(d);
        if n > 0.0 {
            for (x, &wi) in xs.iter().zip(w) {
                for j in 0..d {
                    mean[j] += wi * x[j];
                }
            }
            mean /= n;
        } else {
            mean.copy_from_slice(fallback_mean);
        }
        let mut scatter = prior.psi.clone();
        for (x, &wi) in xs.iter().zip(w) {
            if wi == 0.0 {
                continue;
            }
            for a in 0..d {
                let da = x[a] - mean[a];
                for b in a..d {
                    scatter[(a, b)] += wi * da * (x[b] - mean[b]);
                }
            }
        }
        for a in 0..d {
            for b in 0..a {
                scatter[(a, b)] = scatter[(b, a)];
            }
        }
        let cov = scatter / (n + prior.nu);
        // Positive definite by construction (eps I plus a scatter); the fallback covers eps = 0.
        Self::new(mean.clone(), cov).unwrap_or_else(|| {
            Self::new(mean, DMatrix::identity(d, d) * eps.max(1e-9))
                .expect("eps I is positive definite")
        })
    }

    /// The log prior term of the covariance floor: `-(log|Sigma| + tr(eps Sigma^-1)) / 2`.
    pub fn log_prior(&self, eps: f64) -> f64 {
        self.log_prior_under(&CovPrior::floor(self.dim(), eps))
    }

    /// The log prior term of `prior`: `-(nu log|Sigma| + tr(Psi Sigma^-1)) / 2`.
    pub fn log_prior_under(&self, prior: &CovPrior) -> f64 {
        let d = self.dim();
        let inv = self.chol.inverse();
        let tr: f64 = (0..d)
            .flat_map(|i| (0..d).map(move |j| (i, j)))
            .map(|(i, j)| prior.psi[(i, j)] * inv[(j, i)])
            .sum();
        // log|Sigma| = -2 (log_norm + d/2 log 2pi)
        let log_det = -2.0 * (self.log_norm + 0.5 * d as f64 * (2.0 * std::f64::consts::PI).ln());
        -0.5 * (prior.nu * log_det + tr)
    }
}

/// `log(sum(exp(v)))` without overflow; `-inf` for an empty or all `-inf` slice.
pub fn log_sum_exp(v: &[f64]) -> f64 {
    let m = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    if !m.is_finite() {
        return m;
    }
    m + v.iter().map(|x| (x - m).exp()).sum::<f64>().ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_pdf_matches_the_formula_in_2d() {
        let g = Gaussian::new(
            DVector::from_vec(vec![1.0, -2.0]),
            DMatrix::from_row_slice(2, 2, &[2.0, 0.6, 0.6, 1.0]),
        )
        .unwrap();
        // det = 2 - 0.36 = 1.64; inverse = [1, -0.6; -0.6, 2] / 1.64
        let (dx, dy) = (0.5, 0.3);
        let q = (dx * dx * 1.0 - 2.0 * 0.6 * dx * dy + 2.0 * dy * dy) / 1.64;
        let want = -(2.0 * std::f64::consts::PI).ln() - 0.5 * 1.64f64.ln() - 0.5 * q;
        assert!((g.log_pdf(&[1.5, -1.7]) - want).abs() < 1e-12);
    }

    #[test]
    fn weighted_fit_recovers_moments() {
        let xs: Vec<Vec<f64>> = vec![
            vec![0.0, 0.0],
            vec![2.0, 0.0],
            vec![0.0, 2.0],
            vec![2.0, 2.0],
        ];
        let g = Gaussian::fit_weighted(&xs, &[1.0; 4], 0.0, &[0.0, 0.0]);
        assert!((g.mean()[0] - 1.0).abs() < 1e-12 && (g.mean()[1] - 1.0).abs() < 1e-12);
        // scatter = diag(4, 4), divided by n + 1 = 5
        assert!((g.cov()[(0, 0)] - 0.8).abs() < 1e-12);
        assert!(g.cov()[(0, 1)].abs() < 1e-12);
        // A single point still gives a positive-definite Gaussian with the floor.
        let g = Gaussian::fit_weighted(&xs[..1], &[1.0], 0.1, &[0.0, 0.0]);
        assert!(g.log_pdf(&[0.0, 0.0]).is_finite());
    }

    #[test]
    fn log_sum_exp_is_stable() {
        assert!((log_sum_exp(&[1000.0, 1000.0]) - (1000.0 + 2f64.ln())).abs() < 1e-9);
        assert_eq!(log_sum_exp(&[]), f64::NEG_INFINITY);
    }
}
