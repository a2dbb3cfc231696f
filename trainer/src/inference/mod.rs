//! The inference layer (docs/method.md, "Inference layer"): an HMM over kinematic parameters, a
//! Gaussian mixture over prosody, and the remapped CRF trained from the HMM's posteriors.

// Index loops mirror the equations (alpha[t][i], xi[t][i * S + j]) and are kept on purpose.
#![allow(clippy::needless_range_loop)]

pub mod crf;
pub mod eval;
pub mod gaussian;
pub mod gmm;
pub mod hmm;
pub mod layers;
pub mod model;
pub mod quantize;
pub mod select;
pub mod sequence;
pub mod train;
