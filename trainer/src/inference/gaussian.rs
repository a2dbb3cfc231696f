//! Multivariate Gaussians with full covariance, fitted from weighted data with a covariance
//! floor that is a proper prior (so EM stays monotone in the objective it reports).
//!
//! The floor is the MAP estimate under an inverse-Wishart-style prior: a weighted scatter `S`
//! with total weight `n` gives `Sigma = (S + eps I) / (n + 1)`, which maximizes
//! `-(n/2) log|Sigma| - tr(S Sigma^-1)/2 - log|Sigma|/2 - tr(eps Sigma^-1)/2`. Every Gaussian
//! is therefore positive definite, even for a state that owns one point, and [`log_prior`]
//! gives the term EM adds to its objective.
//!
//! [`log_prior`]: Gaussian::log_prior

use nalgebra::{Cholesky, DMatrix, DVector, Dyn};

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

    /// `log N(x; mean, cov)`.
    pub fn log_pdf(&self, x: &[f64]) -> f64 {
        let d = DVector::from_iterator(
            self.dim(),
            x.iter().zip(self.mean.iter()).map(|(a, m)| a - m),
        );
        let z = self
            .chol
            .l_dirty()
            .solve_lower_triangular(&d)
            .unwrap_or_else(|| DVector::from_element(self.dim(), f64::INFINITY));
        self.log_norm - 0.5 * z.norm_squared()
    }

    /// MAP fit from rows `xs` with weights `w` (covariance floor `eps`, see the module docs).
    /// With zero total weight, the result is `N(fallback_mean, eps I)`.
    pub fn fit_weighted(xs: &[Vec<f64>], w: &[f64], eps: f64, fallback_mean: &[f64]) -> Self {
        let d = fallback_mean.len();
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
        let mut scatter = DMatrix::<f64>::identity(d, d) * eps;
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
        let cov = scatter / (n + 1.0);
        // Positive definite by construction (eps I plus a scatter); the fallback covers eps = 0.
        Self::new(mean.clone(), cov).unwrap_or_else(|| {
            Self::new(mean, DMatrix::identity(d, d) * eps.max(1e-9))
                .expect("eps I is positive definite")
        })
    }

    /// The log prior term of the covariance floor: `-(log|Sigma| + tr(eps Sigma^-1)) / 2`.
    pub fn log_prior(&self, eps: f64) -> f64 {
        let d = self.dim();
        let inv = self.chol.inverse();
        let tr: f64 = (0..d).map(|i| inv[(i, i)]).sum();
        // log|Sigma| = -2 (log_norm + d/2 log 2pi)
        let log_det = -2.0 * (self.log_norm + 0.5 * d as f64 * (2.0 * std::f64::consts::PI).ln());
        -0.5 * (log_det + eps * tr)
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
