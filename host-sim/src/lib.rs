//! # host-sim
//!
//! The desktop simulator: audio files in, exactly the runtime's computations out, so that what
//! a user sees on the desktop is what the board will do (DESIGN.md, "Who uses it"). `std`;
//! nothing here re-implements runtime behaviour: prosody comes from
//! [`gesture_trainer::features::prosody_of`], which calls the runtime front-end.
//!
//! ## Modules
//!
//! - [`eval`]: pure comparison functions (reference CSV parsing, frame matching, the metrics
//!   of `shared/tools/prosody_compare.py`, syllable counts).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod eval;
