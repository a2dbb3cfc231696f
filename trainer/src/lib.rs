//! # gesture-trainer
//!
//! Host-side learning for the gesture controller (DESIGN.md, "The method"): corpus ingestion,
//! model fitting and packing of the policy blob. `std`, allocates freely; every parser of outside
//! bytes returns a typed error instead of panicking.
//!
//! ## Modules
//!
//! - [`audio`]: WAV files (8-48 kHz, any common PCM/float encoding) to mono `i16` at the
//!   front-end rate, band-limited resampling with timing and length preserved.
//! - [`blob`]: writing policy blobs: owned payload sections, table layout and quantization,
//!   header + postcard encoding checked by the runtime's loader, atomic file write.
//! - [`features`]: prosody frames and syllable steps, computed by calling the runtime's
//!   front-end (never re-implemented here).
//! - [`motion`]: BVH reading/writing, forward kinematics, end effectors, segmentation into
//!   gesture phases and the six kinematic parameters per segment with their normalization.
//! - [`rig`]: TOML rig files (output channels mapped to joint rotations by name aliases, with
//!   servo calibration), binding to a skeleton, per-frame channel angles, the full-skeleton rig.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod audio;
pub mod cli;
pub mod control;
pub mod corpus;
pub mod evaluate;
pub mod features;
pub mod inference;
pub mod motion;
pub mod output;
pub mod pack;
pub mod rig;
pub mod synth;
