//! Quantizing the inference layer into the runtime's form: the prosody clusters as `f32`
//! ([`GmmComponent`], a few dozen bytes each) and the CRF weights as little-endian `i16` tables,
//! one `f32` scale per table (`scale = max |w| / 32767`, so the rounding error of a weight is at
//! most `scale / 2`). The runtime reads exactly these bytes from the blob.

use gesture_runtime::inference::{CrfWeights, GmmComponent, I16Table};

use super::crf::Crf;
use super::gmm::Gmm;

/// A little-endian `i16` table and its scale.
#[derive(Clone, Debug, PartialEq)]
pub struct QTable {
    /// `2 * len` bytes.
    pub bytes: Vec<u8>,
    /// Value = `i16 * scale`.
    pub scale: f32,
}

impl QTable {
    /// Quantizes `w` symmetrically to `i16`.
    pub fn quantize(w: &[f64]) -> Self {
        let max = w.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let scale = if max > 0.0 { max / 32767.0 } else { 1.0 };
        let mut bytes = Vec::with_capacity(2 * w.len());
        for v in w {
            let q = (v / scale).round().clamp(-32767.0, 32767.0) as i16;
            bytes.extend_from_slice(&q.to_le_bytes());
        }
        Self {
            bytes,
            scale: scale as f32,
        }
    }

    /// The runtime view.
    pub fn view(&self) -> Option<I16Table<'_>> {
        I16Table::new(&self.bytes, self.scale, self.bytes.len() / 2)
    }
}

/// The runtime form of the GMM and CRF.
#[derive(Clone, Debug, PartialEq)]
pub struct QuantizedInference {
    /// Prosody clusters.
    pub gmm: Vec<GmmComponent>,
    /// States S.
    pub states: usize,
    /// Window W.
    pub window: usize,
    /// CRF initial weights.
    pub init: QTable,
    /// CRF transition weights.
    pub trans: QTable,
    /// CRF observation weights.
    pub obs: QTable,
}

impl QuantizedInference {
    /// Quantizes a fitted mixture and CRF.
    pub fn new(gmm: &Gmm, crf: &Crf) -> Self {
        let comps = gmm
            .components
            .iter()
            .map(|c| {
                let cov = c.obs.cov();
                let (s00, s10, s11) = (cov[(0, 0)], cov[(1, 0)], cov[(1, 1)]);
                let l00 = s00.sqrt();
                let l10 = s10 / l00;
                let l11 = (s11 - l10 * l10).max(1e-300).sqrt();
                let log_det = 2.0 * (l00.ln() + l11.ln());
                GmmComponent {
                    log_voiced: (c.weight.max(1e-300).ln() + c.voiced.max(1e-300).ln()) as f32,
                    log_unvoiced: (c.weight.max(1e-300).ln() + (1.0 - c.voiced).max(1e-300).ln())
                        as f32,
                    mean: [c.obs.mean()[0] as f32, c.obs.mean()[1] as f32],
                    inv_chol: [
                        (1.0 / l00) as f32,
                        (-l10 / (l00 * l11)) as f32,
                        (1.0 / l11) as f32,
                    ],
                    log_norm: (-(2.0 * std::f64::consts::PI).ln() - 0.5 * log_det) as f32,
                    coef: [c.coef[0] as f32, c.coef[1] as f32, c.coef[2] as f32],
                    inv_sd: (1.0 / c.f0_var.sqrt()) as f32,
                    log_norm_f0: (-0.5 * (2.0 * std::f64::consts::PI * c.f0_var).ln()) as f32,
                }
            })
            .collect();
        Self {
            gmm: comps,
            states: crf.states,
            window: crf.window,
            init: QTable::quantize(&crf.init),
            trans: QTable::quantize(&crf.trans),
            obs: QTable::quantize(&crf.obs),
        }
    }

    /// The runtime's CRF view over the tables (`None` only if dimensions exceed capacities).
    pub fn weights(&self) -> Option<CrfWeights<'_>> {
        CrfWeights::new(
            self.states,
            self.gmm.len(),
            self.window,
            self.init.view()?,
            self.trans.view()?,
            self.obs.view()?,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantization_error_is_at_most_half_a_step() {
        let w: Vec<f64> = (0..100).map(|i| ((i as f64) * 0.37).sin() * 3.0).collect();
        let q = QTable::quantize(&w);
        let v = q.view().unwrap();
        for (i, x) in w.iter().enumerate() {
            assert!((v.get(i) as f64 - x).abs() <= 0.5001 * q.scale as f64 + 1e-6);
        }
    }
}
