//! The inference layer (DESIGN.md, "Inference layer"): an HMM over kinematic parameters, a
//! Gaussian mixture over prosody, and the remapped CRF trained from the HMM's posteriors.

pub mod crf;
pub mod gaussian;
pub mod gmm;
pub mod hmm;
