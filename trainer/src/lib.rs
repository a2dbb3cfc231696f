//! # gesture-trainer
//!
//! Host-side learning for the gesture controller.
