//! # gesture-trainer
//!
//! Host-side learning for the gesture controller (docs/method.md, "The method"): corpus
//! ingestion, model fitting, packing of the policy blob and the evaluations that run it.
//! `std`, allocates freely; every parser of outside bytes returns a typed error instead of
//! panicking, and every output file is written atomically ([`output`]).
//!
//! The trainer computes prosody features by calling the runtime's front-end and writes blobs
//! with the runtime's writer, so training, packing and the device share one implementation of
//! each.
//!
//! ## Modules
//!
//! - [`audio`]: WAV files (8-48 kHz, any common PCM/float encoding) to mono `i16` at the
//!   front-end rate, band-limited resampling with timing and length preserved.
//! - [`features`]: prosody frames and syllable steps, computed by calling the runtime's
//!   front-end (never re-implemented here).
//! - [`motion`]: BVH reading/writing, forward kinematics, end effectors, segmentation into
//!   gesture phases and the six kinematic parameters per segment with their normalization.
//! - [`corpus`]: finding speech+motion takes, loading and aligning them, per-take statistics.
//! - [`synth`]: a synthetic speech+motion corpus with planted hidden states, for tests and the
//!   demo.
//! - [`inference`]: the inference layer: HMM, prosody mixture, remapped CRF, the model file,
//!   Fig. 4's comparison, and the inference section of the blob.
//! - [`control`]: the control layer: library, costs, value iteration, pruning, the offline DP
//!   reference and the motion-quality metrics.
//! - [`rig`]: TOML rig files (output channels mapped to body measures of any humanoid skeleton
//!   or to joint rotations by name aliases, with servo calibration), binding to a skeleton, per-frame channel angles, the full-skeleton
//!   rig, and rig poses back on the skeleton.
//! - [`pack`]: model + library + rig into a policy blob (in memory or to a file), with its
//!   report.
//! - [`evaluate`]: evaluations that run the packed bytes through the runtime's device loop.
//! - [`output`]: atomic output files (temporary file beside the target, then rename).
//! - [`progress`]: progress bars on stderr for long work.
//! - [`cli`]: the `gesture-train` command line (parsing, printing, exit codes only).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod audio;
pub mod bake;
pub mod cli;
pub mod control;
pub mod corpus;
pub mod evaluate;
pub mod features;
pub mod inference;
pub mod motion;
pub mod output;
pub mod pack;
pub mod progress;
pub mod rig;
pub mod synth;
