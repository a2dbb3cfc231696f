//! Tones (styles) of the body language (docs/method.md "Style control", the paper's section
//! 8.2): a transform of the kinematic parameters per tone, fitted from motion that shows it.
//!
//! **The transform.** A Gaussian `N(mu_0, Sigma_0)` is fitted to the normalized kinematic
//! vectors `y` (the space the inference layer models: log parameters in body units, normalized
//! by the model's `W`, `B`) of the segments of *neutral* motion, and one, `N(mu_1, Sigma_1)`,
//! to those of motion in the tone. The tone's transform is the affine map that carries the
//! first onto the second with the least displacement (the optimal-transport map between
//! Gaussians):
//!
//! ```text
//! T(y) = mu_1 + A (y - mu_0),   A = S0^-1/2 (S0^1/2 S1 S0^1/2)^1/2 S0^-1/2
//! ```
//!
//! symmetric and positive definite, so a tone that only shifts the parameters gives `A = I`
//! and a tone that spreads them gives a scale. Because it is a *relative* change (tone against
//! neutral of the same performer and skeleton), tone data can come from another character than
//! the library: Bandai Namco's styled clips applied to a ZeroEGGS library.
//!
//! **Shrinkage.** A tone often has a handful of segments (four clips of the Bandai data give
//! 10-20), too few for a 6x6 covariance. The map fitted from the sample covariances (each with
//! the same small ridge, 0.1 % of the neutral mean variance, so a rank-deficient estimate stays
//! invertible) is shrunk toward the identity, `A = (n A_hat + k I) / (n + k)` with `n` the
//! tone's segments and `k = `[`SHRINK_SEGMENTS`] (12, twice the dimension): with little data
//! the transform tends to a pure shift of the means, which a few segments estimate well.
//!
//! **Direction.** Under tone `m` the segments are scored as if their parameters were
//! `T^-1(y_a)`: a segment that moves like the tone (faster, for an active tone) is mapped back
//! to where neutral motion lies, where the states' Gaussians expect it, and so fits better. The
//! played motion therefore becomes *more* like the tone. (Applying `T` to the segments instead
//! would make it less like it; a test checks the direction with a planted tone.)
//!
//! **Energy** ([`ToneTransform::energy`]): a synthetic tone with no data: path length, speed and
//! acceleration times `f` (duration, curvature and height unchanged), as a shift of the log
//! parameters.

use nalgebra::{SMatrix, SVector};

use crate::motion::Normalization;

/// 6x6 matrices of the kinematic space.
type M6 = SMatrix<f64, 6, 6>;
/// Vectors of the kinematic space.
type V6 = SVector<f64, 6>;

/// Prior weight (in segments) of the reference covariance in the shrunk estimate.
pub const SHRINK_SEGMENTS: f64 = 12.0;

/// Fewest segments a tone (or the neutral motion) must have.
pub const MIN_SEGMENTS: usize = 2;

/// Names of the two tones [`ToneTransform::energy`] makes.
pub const ENERGY_TONES: [&str; 2] = ["energetic", "calm"];

/// Why a tone could not be fitted.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ToneError {
    /// Too few segments.
    #[error(
        "{what}: {found} motion segments, at least {MIN_SEGMENTS} are needed (give more or \
         longer clips)"
    )]
    TooFew {
        /// Which motion (`neutral` or the tone's name).
        what: String,
        /// Segments found.
        found: usize,
    },
    /// A non-finite parameter.
    #[error("{0}: a kinematic parameter is not finite")]
    NotFinite(String),
}

/// A tone's affine transform of the normalized kinematic vector: `T(y) = mu_1 + A (y - mu_0)`.
#[derive(Clone, Debug, PartialEq)]
pub struct ToneTransform {
    /// The tone's name.
    pub name: String,
    /// Neutral mean `mu_0`.
    pub mu0: [f64; 6],
    /// Tone mean `mu_1`.
    pub mu1: [f64; 6],
    /// `A`, row-major.
    pub a: [[f64; 6]; 6],
    /// Tone segments it was fitted on (0 for a synthetic tone).
    pub segments: usize,
}

/// Mean and covariance of `ys`.
fn moments(ys: &[[f64; 6]]) -> (V6, M6) {
    let n = ys.len().max(1) as f64;
    let mut mean = V6::zeros();
    for y in ys {
        mean += V6::from_row_slice(y);
    }
    mean /= n;
    let mut cov = M6::zeros();
    for y in ys {
        let d = V6::from_row_slice(y) - mean;
        cov += d * d.transpose();
    }
    (mean, cov / n)
}

/// `f(M)` for symmetric `M`, applied to its eigenvalues (clamped at `floor`).
fn sym_fn(m: &M6, floor: f64, f: impl Fn(f64) -> f64) -> M6 {
    let sym = (m + m.transpose()) * 0.5;
    let eig = sym.symmetric_eigen();
    let d = eig.eigenvalues.map(|v| f(v.max(floor)));
    eig.eigenvectors * M6::from_diagonal(&d) * eig.eigenvectors.transpose()
}

fn check(what: &str, ys: &[[f64; 6]]) -> Result<(), ToneError> {
    if ys.len() < MIN_SEGMENTS {
        return Err(ToneError::TooFew {
            what: what.into(),
            found: ys.len(),
        });
    }
    if ys.iter().flatten().any(|v| !v.is_finite()) {
        return Err(ToneError::NotFinite(what.into()));
    }
    Ok(())
}

impl ToneTransform {
    /// Fits the transform from the normalized vectors of neutral segments to those of the
    /// tone's segments (see the module docs for the estimate and its shrinkage).
    pub fn fit(name: &str, neutral: &[[f64; 6]], tone: &[[f64; 6]]) -> Result<Self, ToneError> {
        check("neutral", neutral)?;
        check(name, tone)?;
        let (mu0, s0) = moments(neutral);
        let (mu1, s1) = moments(tone);
        let ridge = M6::identity() * (1e-3 * s0.trace() / 6.0).max(1e-12);
        let (s0, s1) = (s0 + ridge, s1 + ridge);
        // Eigenvalues floored so a degenerate direction maps to itself.
        let floor = 1e-12;
        let r = sym_fn(&s0, floor, f64::sqrt);
        let r_inv = sym_fn(&s0, floor, |v| 1.0 / v.sqrt());
        let mid = sym_fn(&(r * s1 * r), floor, f64::sqrt);
        let a_hat = r_inv * mid * r_inv;
        let (n, k) = (tone.len() as f64, SHRINK_SEGMENTS);
        let a = (a_hat * n + M6::identity() * k) / (n + k);
        let a = (a + a.transpose()) * 0.5;
        Ok(Self {
            name: name.into(),
            mu0: mu0.into(),
            mu1: mu1.into(),
            a: std::array::from_fn(|i| std::array::from_fn(|j| a[(i, j)])),
            segments: tone.len(),
        })
    }

    /// A pure shift of the normalized parameters by `delta` (`A = I`).
    pub fn shift(name: &str, delta: [f64; 6]) -> Self {
        Self {
            name: name.into(),
            mu0: [0.0; 6],
            mu1: delta,
            a: std::array::from_fn(|i| std::array::from_fn(|j| (i == j) as u8 as f64)),
            segments: 0,
        }
    }

    /// The two energy tones (`energetic`, `calm`) for a factor `f > 1`: the same motion `f`
    /// times larger and `f` times smaller (see the module docs), in `norm`'s units.
    pub fn energy(f: f64, norm: &Normalization) -> [Self; 2] {
        // T, D, V, A, C, H: log D, V, A grow by ln f. Curvature is left alone: in a larger
        // copy of a motion it would fall by f, but across a library it follows the shape of a
        // gesture more than its size, and shifting it too picked slower segments on the
        // synthetic character (measured: `energetic` x0.99 hand speed).
        let raw = [0.0, 1.0, 1.0, 1.0, 0.0, 0.0];
        let delta = |sign: f64| std::array::from_fn(|d| sign * raw[d] * f.ln() / norm.scale[d]);
        [
            Self::shift(ENERGY_TONES[0], delta(1.0)),
            Self::shift(ENERGY_TONES[1], delta(-1.0)),
        ]
    }

    fn matrix(&self) -> M6 {
        M6::from_fn(|i, j| self.a[i][j])
    }

    /// `T(y)`: where a neutral vector lies in the tone.
    pub fn apply(&self, y: &[f64; 6]) -> [f64; 6] {
        let v = V6::from(self.mu1) + self.matrix() * (V6::from_row_slice(y) - V6::from(self.mu0));
        v.into()
    }

    /// `T^-1(y)`: where a vector of the tone lies in neutral motion (what a library segment is
    /// scored as under this tone).
    pub fn invert(&self, y: &[f64; 6]) -> [f64; 6] {
        let inv = self.matrix().try_inverse().unwrap_or_else(M6::identity);
        let v = V6::from(self.mu0) + inv * (V6::from_row_slice(y) - V6::from(self.mu1));
        v.into()
    }

    /// The change of the means in raw units: `exp(mu_1 - mu_0)` per parameter through `norm`,
    /// i.e. the factor by which the tone multiplies T, D, V, A, C and H on average.
    pub fn factors(&self, norm: &Normalization) -> [f64; 6] {
        std::array::from_fn(|d| ((self.mu1[d] - self.mu0[d]) * norm.scale[d]).exp())
    }
}

/// The tone names of a blob plus `neutral`, for messages.
pub fn known_tones(tones: &[&str]) -> String {
    if tones.is_empty() {
        "the blob has no tones (pack it with --style or --energy)".into()
    } else {
        format!("the blob's tones: neutral, {}", tones.join(", "))
    }
}

/// The weight vector of `spec` (`NAME=W` items separated by `,` or `;`) for a blob with
/// `tones`; `what` names the flag or file line for errors. Tones not named weigh 0; `neutral`
/// may be named; weights summing to more than 1 are divided by their sum (with `neutral`'s),
/// and the neutral tables get what is left of 1.
pub fn parse_weights(spec: &str, tones: &[&str], what: &str) -> Result<Vec<f32>, String> {
    let mut w = vec![0.0f64; tones.len()];
    let mut neutral = 0.0f64;
    let mut seen: Vec<&str> = Vec::new();
    for item in spec.split([',', ';']).map(str::trim) {
        if item.is_empty() {
            continue;
        }
        // `neutral` alone is the neutral style.
        let item = if item == "neutral" { "neutral=1" } else { item };
        let (name, value) = item
            .split_once('=')
            .ok_or_else(|| format!("{what}: `{item}`: expected NAME=WEIGHT (e.g. active=0.5)"))?;
        let name = name.trim();
        let v: f64 = value
            .trim()
            .parse()
            .map_err(|_| format!("{what}: `{item}`: the weight is not a number"))?;
        if !v.is_finite() || v < 0.0 {
            return Err(format!(
                "{what}: `{item}`: a weight must be a finite number of at least 0"
            ));
        }
        if seen.contains(&name) {
            return Err(format!("{what}: the tone `{name}` is given twice"));
        }
        seen.push(name);
        if name == "neutral" {
            neutral = v;
        } else if let Some(k) = tones.iter().position(|t| *t == name) {
            w[k] = v;
        } else {
            return Err(format!(
                "{what}: no tone `{name}` in the blob ({})",
                known_tones(tones)
            ));
        }
    }
    Ok(normalized_weights(&w, neutral))
}

/// The tone weights for raw weights `w` and a neutral weight: divided by the total when it is
/// above 1 (the neutral tables keep the rest).
pub fn normalized_weights(w: &[f64], neutral: f64) -> Vec<f32> {
    let total = neutral + w.iter().sum::<f64>();
    let div = if total > 1.0 { total } else { 1.0 };
    w.iter().map(|v| (v / div) as f32).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    fn cloud(n: usize, seed: u64) -> Vec<[f64; 6]> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let z: [f64; 6] = std::array::from_fn(|_| StandardNormal.sample(&mut rng));
                // Correlated: a fixed mixing of the draws.
                std::array::from_fn(|d| z[d] + 0.5 * z[(d + 1) % 6] + 0.1 * d as f64)
            })
            .collect()
    }

    fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
    }

    /// A tone that is the neutral motion shifted by a known vector gives exactly that shift
    /// and `A = I`, whatever the shrinkage (the shrunk covariances stay equal).
    #[test]
    fn a_planted_shift_is_recovered_exactly() {
        let neutral = cloud(40, 1);
        let delta = [0.0, 0.4, 0.8, -0.3, 0.0, 0.2];
        let tone: Vec<[f64; 6]> = neutral
            .iter()
            .map(|y| std::array::from_fn(|d| y[d] + delta[d]))
            .collect();
        let t = ToneTransform::fit("active", &neutral, &tone).unwrap();
        let shift: Vec<f64> = (0..6).map(|d| t.mu1[d] - t.mu0[d]).collect();
        assert!(close(&shift, &delta, 1e-12), "{shift:?}");
        for i in 0..6 {
            for j in 0..6 {
                let want = (i == j) as u8 as f64;
                assert!(
                    (t.a[i][j] - want).abs() < 1e-6,
                    "A[{i}][{j}] = {}",
                    t.a[i][j]
                );
            }
        }
        // T maps a neutral vector onto its tone counterpart; T^-1 back.
        let y = neutral[3];
        assert!(close(&t.apply(&y), &tone[3], 1e-6));
        assert!(close(&t.invert(&tone[3]), &y, 1e-6));
    }

    /// A tone that spreads the neutral motion by 1.5 about its mean: the sample covariance is
    /// 2.25 times the neutral one, `A_hat = 1.5 I`, shrunk: `A = (1.5 n + k) / (n + k) I`
    /// (within the ridge's effect, 0.1 % of the variance).
    #[test]
    fn a_planted_scale_gives_the_known_shrunk_map() {
        let neutral = cloud(30, 2);
        let (mu, _) = moments(&neutral);
        let tone: Vec<[f64; 6]> = neutral
            .iter()
            .map(|y| std::array::from_fn(|d| mu[d] + 1.5 * (y[d] - mu[d])))
            .collect();
        let t = ToneTransform::fit("wide", &neutral, &tone).unwrap();
        let n = 30.0;
        let want = (1.5 * n + SHRINK_SEGMENTS) / (n + SHRINK_SEGMENTS);
        for i in 0..6 {
            for j in 0..6 {
                let w = if i == j { want } else { 0.0 };
                assert!(
                    (t.a[i][j] - w).abs() < 2e-3,
                    "A[{i}][{j}] = {} vs {w}",
                    t.a[i][j]
                );
            }
        }
    }

    /// The direction: under a faster tone, a fast segment is scored as a neutral-speed one
    /// (closer to where neutral motion lies), a slow one as slower still.
    #[test]
    fn a_faster_tone_makes_fast_segments_look_neutral() {
        let neutral = cloud(50, 3);
        let t = ToneTransform::shift("active", [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
        let (mu, _) = moments(&neutral);
        let fast = std::array::from_fn(|d| mu[d] + if d == 2 { 1.0 } else { 0.0 });
        let slow = std::array::from_fn(|d| mu[d] - if d == 2 { 1.0 } else { 0.0 });
        let dist = |y: [f64; 6]| (y[2] - mu[2]).abs();
        assert!(dist(t.invert(&fast)) < 1e-12);
        assert!(dist(t.invert(&slow)) > dist(slow));
    }

    #[test]
    fn energy_scales_speed_and_amplitude() {
        let norm = Normalization {
            mean: [0.0; 6],
            scale: [1.0, 2.0, 0.5, 1.0, 1.0, 1.0],
        };
        let [up, down] = ToneTransform::energy(1.5, &norm);
        let f = up.factors(&norm);
        let want = [1.0, 1.5, 1.5, 1.5, 1.0, 1.0];
        assert!(close(&f, &want, 1e-12), "{f:?}");
        let g = down.factors(&norm);
        assert!(close(&g, &want.map(|v| 1.0 / v), 1e-12), "{g:?}");
        assert_eq!(
            (up.name.as_str(), down.name.as_str()),
            ("energetic", "calm")
        );
    }

    #[test]
    fn too_little_motion_is_an_error() {
        let one = cloud(1, 4);
        let many = cloud(10, 5);
        assert_eq!(
            ToneTransform::fit("sad", &many, &one),
            Err(ToneError::TooFew {
                what: "sad".into(),
                found: 1
            })
        );
        assert!(ToneTransform::fit("sad", &one, &many).is_err());
        let mut bad = many.clone();
        bad[0][1] = f64::NAN;
        assert_eq!(
            ToneTransform::fit("sad", &many, &bad),
            Err(ToneError::NotFinite("sad".into()))
        );
    }
}
