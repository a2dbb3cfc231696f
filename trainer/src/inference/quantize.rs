//! The inference layer in the runtime's form: the prosody clusters as `f32`
//! [`GmmComponent`]s (Cholesky factors and log normalizers precomputed, a few dozen bytes
//! each) and the CRF weights as the blob's `inference` section, quantized by the runtime's
//! one quantizer ([`OwnedInference::new`]). The device reads exactly these values.

use gesture_runtime::blob::encode::{EncodeError, OwnedInference};
use gesture_runtime::inference::GmmComponent;

use super::crf::Crf;
use super::gmm::Gmm;

/// The device's form of each mixture component.
pub fn gmm_components(gmm: &Gmm) -> Vec<GmmComponent> {
    gmm.components
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
        .collect()
}

/// The blob's `inference` section for a fitted mixture and CRF.
pub fn inference_section(gmm: &Gmm, crf: &Crf) -> Result<OwnedInference, EncodeError> {
    OwnedInference::new(
        &gmm_components(gmm),
        crf.window,
        &crf.init,
        &crf.trans,
        &crf.obs,
    )
}
