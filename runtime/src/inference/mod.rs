//! The inference layer on the device: prosody features of each step, their memberships in the
//! prosody clusters (the GMM), and one CRF forward step per syllable giving the belief over the
//! hidden gesture-style states (docs/method.md, inference layer step 4).
//!
//! Parameters arrive from the blob: the GMM as a few `f32` per cluster, the CRF weights as
//! little-endian `i16` tables with one `f32` scale each ([`I16Table`]), read on access so they can
//! stay in flash. The state ([`Belief`]) is fixed-size: a belief vector and a ring of the last
//! `W` membership vectors.
//!
//! Numerics (checked against the trainer's `f64` forward pass in the trainer's tests):
//! memberships are a softmax of log-joints; the forward step computes
//! `alpha_j ~ (sum_i b_i exp(trans_ij - max trans)) * exp(phi_j - max phi)`, so every
//! exponent is <= 0 and nothing overflows; if everything underflows, the belief resets to
//! uniform. No panics, no allocation, outputs always a probability vector.

pub mod features;

pub use features::{StepFeatures, StepNormalizer};

/// Most hidden states a blob may have.
pub const MAX_STATES: usize = 32;
/// Most prosody clusters.
pub const MAX_CLUSTERS: usize = 16;
/// Longest CRF input window.
pub const MAX_WINDOW: usize = 8;

/// One prosody cluster, in the form the membership computation needs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GmmComponent {
    /// `ln(weight) + ln(P(voiced))`.
    pub log_voiced: f32,
    /// `ln(weight) + ln(P(unvoiced))`.
    pub log_unvoiced: f32,
    /// Mean of (intensity, length).
    pub mean: [f32; 2],
    /// Inverse Cholesky factor of their covariance, `[a, b, c]` for `[[a, 0], [b, c]]`.
    pub inv_chol: [f32; 3],
    /// `-ln(2 pi) - ln|Sigma| / 2`.
    pub log_norm: f32,
    /// F0 regression on (1, intensity, length).
    pub coef: [f32; 3],
    /// `1 / sigma` of the F0 residual.
    pub inv_sd: f32,
    /// `-ln(2 pi sigma^2) / 2`.
    pub log_norm_f0: f32,
}

impl GmmComponent {
    /// `ln p(x, k)`.
    pub fn log_joint(&self, x: &StepFeatures) -> f32 {
        let d0 = x.obs[0] - self.mean[0];
        let d1 = x.obs[1] - self.mean[1];
        let z0 = self.inv_chol[0] * d0;
        let z1 = self.inv_chol[1] * d0 + self.inv_chol[2] * d1;
        let lo = self.log_norm - 0.5 * (z0 * z0 + z1 * z1);
        match x.f0 {
            Some(f) => {
                let pred = self.coef[0] + self.coef[1] * x.obs[0] + self.coef[2] * x.obs[1];
                let r = (f - pred) * self.inv_sd;
                self.log_voiced + lo + self.log_norm_f0 - 0.5 * r * r
            }
            None => self.log_unvoiced + lo,
        }
    }
}

/// Cluster memberships `P(k | x)` of `comps` into `out[..comps.len()]` (softmax of log-joints).
pub fn memberships(comps: &[GmmComponent], x: &StepFeatures, out: &mut [f32; MAX_CLUSTERS]) {
    let k = comps.len().min(MAX_CLUSTERS);
    *out = [0.0; MAX_CLUSTERS];
    let mut max = f32::NEG_INFINITY;
    for (o, c) in out.iter_mut().zip(comps.iter()).take(k) {
        let v = c.log_joint(x);
        *o = if v.is_finite() { v } else { f32::NEG_INFINITY };
        if *o > max {
            max = *o;
        }
    }
    if !max.is_finite() {
        out[..k].iter_mut().for_each(|v| *v = 1.0 / k.max(1) as f32);
        return;
    }
    let mut z = 0.0;
    for v in out[..k].iter_mut() {
        *v = libm::expf(*v - max);
        z += *v;
    }
    for v in out[..k].iter_mut() {
        *v /= z;
    }
}

/// A table of little-endian `i16` values times a scale, read on access.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct I16Table<'a> {
    bytes: &'a [u8],
    scale: f32,
}

impl<'a> I16Table<'a> {
    /// The table with no values.
    pub const EMPTY: I16Table<'static> = I16Table {
        bytes: &[],
        scale: 1.0,
    };

    /// A table of `len` values; `None` if `bytes` does not hold exactly that many or the scale
    /// is not finite.
    pub fn new(bytes: &'a [u8], scale: f32, len: usize) -> Option<Self> {
        (bytes.len() == 2 * len && scale.is_finite()).then_some(Self { bytes, scale })
    }

    /// Number of values.
    pub fn len(&self) -> usize {
        self.bytes.len() / 2
    }

    /// Whether the table is empty.
    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    /// `sum_k w[k] * value(start + k)` over `w` (in order, each value `i16 as f32 * scale` as
    /// [`get`](Self::get) gives it, so the result is bit for bit that of the same loop over
    /// `get`); values past the end count 0.
    #[inline]
    pub fn dot(&self, start: usize, w: &[f32]) -> f32 {
        let lo = start.saturating_mul(2);
        let hi = lo.saturating_add(w.len().saturating_mul(2));
        let mut acc = 0.0f32;
        match self.bytes.get(lo..hi) {
            Some(row) => {
                for (b, &wk) in row.chunks_exact(2).zip(w) {
                    acc += wk * (i16::from_le_bytes([b[0], b[1]]) as f32 * self.scale);
                }
            }
            None => {
                for (k, &wk) in w.iter().enumerate() {
                    acc += wk * self.get(start.saturating_add(k));
                }
            }
        }
        acc
    }

    /// Value `i` (0 past the end; validated tables are never indexed past the end).
    #[inline]
    pub fn get(&self, i: usize) -> f32 {
        let Some(lo) = i.checked_mul(2) else {
            return 0.0;
        };
        match self.bytes.get(lo..lo.saturating_add(2)) {
            Some(b) => i16::from_le_bytes([b[0], b[1]]) as f32 * self.scale,
            None => 0.0,
        }
    }
}

/// The CRF's weights: initial and transition (`S`, `S x S`, row-major from -> to) and
/// observation (`S x W x K`, index `(j * W + w) * K + k`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrfWeights<'a> {
    /// States S.
    pub states: usize,
    /// Clusters K.
    pub clusters: usize,
    /// Window W.
    pub window: usize,
    /// Initial weights.
    pub init: I16Table<'a>,
    /// Transition weights.
    pub trans: I16Table<'a>,
    /// Observation weights.
    pub obs: I16Table<'a>,
}

impl<'a> CrfWeights<'a> {
    /// No weights (0 states): the placeholder of an unconfigured controller.
    pub const EMPTY: CrfWeights<'static> = CrfWeights {
        states: 0,
        clusters: 0,
        window: 0,
        init: I16Table::EMPTY,
        trans: I16Table::EMPTY,
        obs: I16Table::EMPTY,
    };

    /// Checks dimensions against the capacities and the table lengths.
    pub fn new(
        states: usize,
        clusters: usize,
        window: usize,
        init: I16Table<'a>,
        trans: I16Table<'a>,
        obs: I16Table<'a>,
    ) -> Option<Self> {
        let ok = (1..=MAX_STATES).contains(&states)
            && (1..=MAX_CLUSTERS).contains(&clusters)
            && (1..=MAX_WINDOW).contains(&window)
            && init.len() == states
            && trans.len() == states * states
            && obs.len() == states * window * clusters;
        ok.then_some(Self {
            states,
            clusters,
            window,
            init,
            trans,
            obs,
        })
    }
}

/// The online belief: CRF forward vector plus the membership history it needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Belief {
    b: [f32; MAX_STATES],
    hist: [[f32; MAX_CLUSTERS]; MAX_WINDOW],
    steps: u32,
}

impl Belief {
    /// No steps seen yet.
    pub const fn new() -> Self {
        Self {
            b: [0.0; MAX_STATES],
            hist: [[0.0; MAX_CLUSTERS]; MAX_WINDOW],
            steps: 0,
        }
    }

    /// The belief over the `states` states (zeros before the first step).
    pub fn probs(&self, states: usize) -> &[f32] {
        &self.b[..states.min(MAX_STATES)]
    }

    /// Steps seen.
    pub fn steps(&self) -> u32 {
        self.steps
    }

    /// One forward step with the memberships `m` of the new step.
    pub fn step(&mut self, crf: &CrfWeights<'_>, m: &[f32; MAX_CLUSTERS]) {
        let (s, k, w_len) = (crf.states, crf.clusters, crf.window);
        // Shift the history: hist[0] is the newest.
        for w in (1..MAX_WINDOW).rev() {
            self.hist[w] = self.hist[w - 1];
        }
        self.hist[0] = *m;
        let avail = (self.steps as usize + 1).min(w_len);
        let mut phi = [0.0f32; MAX_STATES];
        let mut phi_max = f32::NEG_INFINITY;
        for (j, p) in phi.iter_mut().enumerate().take(s) {
            let mut acc = 0.0;
            for (w, h) in self.hist.iter().enumerate().take(avail) {
                let base = (j * w_len + w) * k;
                for (kk, &hv) in h.iter().enumerate().take(k) {
                    acc += crf.obs.get(base + kk) * hv;
                }
            }
            *p = acc;
            if acc > phi_max {
                phi_max = acc;
            }
        }
        let mut alpha = [0.0f32; MAX_STATES];
        if self.steps == 0 {
            let mut m0 = f32::NEG_INFINITY;
            for j in 0..s {
                let v = crf.init.get(j) + phi[j];
                alpha[j] = v;
                if v > m0 {
                    m0 = v;
                }
            }
            for a in alpha.iter_mut().take(s) {
                *a = libm::expf(*a - m0);
            }
        } else {
            let mut t_max = f32::NEG_INFINITY;
            for i in 0..s * s {
                let v = crf.trans.get(i);
                if v > t_max {
                    t_max = v;
                }
            }
            for (j, a) in alpha.iter_mut().enumerate().take(s) {
                let mut u = 0.0;
                for i in 0..s {
                    u += self.b[i] * libm::expf(crf.trans.get(i * s + j) - t_max);
                }
                *a = u * libm::expf(phi[j] - phi_max);
            }
        }
        let z: f32 = alpha[..s].iter().sum();
        if z > 0.0 && z.is_finite() {
            for (b, a) in self.b.iter_mut().zip(alpha.iter()).take(s) {
                *b = a / z;
            }
        } else {
            for b in self.b.iter_mut().take(s) {
                *b = 1.0 / s as f32;
            }
        }
        self.steps = self.steps.saturating_add(1);
    }
}

impl Default for Belief {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(vals: &[i16], buf: &mut [u8]) -> usize {
        for (i, v) in vals.iter().enumerate() {
            buf[2 * i..2 * i + 2].copy_from_slice(&v.to_le_bytes());
        }
        vals.len()
    }

    #[test]
    fn two_state_forward_matches_hand_computation() {
        // S=2, K=1, W=1; init (0, 0); trans [[ln 3, 0], [0, ln 3]] (scaled); obs (1, -1).
        let mut bi = [0u8; 4];
        let mut bt = [0u8; 8];
        let mut bo = [0u8; 4];
        let sc = 1e-3f32;
        let l3 = (3f32.ln() / sc).round() as i16;
        table(&[0, 0], &mut bi);
        table(&[l3, 0, 0, l3], &mut bt);
        table(&[1000, -1000], &mut bo);
        let crf = CrfWeights::new(
            2,
            1,
            1,
            I16Table::new(&bi, sc, 2).unwrap(),
            I16Table::new(&bt, sc, 4).unwrap(),
            I16Table::new(&bo, sc, 2).unwrap(),
        )
        .unwrap();
        let mut m = [0.0f32; MAX_CLUSTERS];
        m[0] = 1.0;
        let mut b = Belief::new();
        b.step(&crf, &m);
        // alpha0 ~ (e, 1/e)
        let e2 = core::f32::consts::E * core::f32::consts::E;
        let want0 = e2 / (e2 + 1.0);
        assert!((b.probs(2)[0] - want0).abs() < 1e-3);
        b.step(&crf, &m);
        // alpha1_j ~ sum_i alpha0_i T_ij * e^{phi_j}: (3 p + q) e, (p + 3 q) / e
        let (p, q) = (want0, 1.0 - want0);
        let a = (3.0 * p + q) * core::f32::consts::E;
        let c = (p + 3.0 * q) / core::f32::consts::E;
        assert!((b.probs(2)[0] - a / (a + c)).abs() < 1e-3);
    }

    #[test]
    fn rejects_inconsistent_tables() {
        let bytes = [0u8; 8];
        assert!(I16Table::new(&bytes, 1.0, 3).is_none());
        assert!(I16Table::new(&bytes, f32::NAN, 4).is_none());
        let t = I16Table::new(&bytes, 1.0, 4).unwrap();
        assert!(CrfWeights::new(2, 1, 1, t, t, t).is_none());
        assert_eq!(t.get(99), 0.0);
    }

    #[test]
    fn memberships_are_a_distribution_even_for_garbage() {
        let comps = [GmmComponent {
            log_voiced: -0.5,
            log_unvoiced: -1.0,
            inv_chol: [1.0, 0.0, 1.0],
            inv_sd: 1.0,
            ..GmmComponent::default()
        }; 3];
        let mut out = [0.0; MAX_CLUSTERS];
        for x in [
            StepFeatures {
                f0: Some(0.1),
                obs: [0.0, -1.5],
                pause: false,
            },
            StepFeatures {
                f0: Some(f32::NAN),
                obs: [f32::NAN, 0.0],
                pause: false,
            },
        ] {
            memberships(&comps, &x, &mut out);
            let s: f32 = out[..3].iter().sum();
            assert!((s - 1.0).abs() < 1e-5, "{out:?}");
        }
    }
}
