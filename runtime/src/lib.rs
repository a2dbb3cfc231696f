//! # gesture-runtime
//!
//! The part of the gesture controller that runs on the board: microphone samples in, a belief
//! over gesture-style states per syllable, a gesture choice at each segment exit, and poses and
//! servo duty cycles out (Levine et al., *Gesture Controllers*, SIGGRAPH 2010; the design is
//! restated in `docs/method.md`).
//!
//! ## Contract
//!
//! - `#![no_std]`, no `alloc`: every buffer has a compile-time capacity and every state type has
//!   a size known at compile time. (The blob *writer*, for host tools, needs `alloc` and is
//!   behind the `encode` feature; a firmware never enables it.)
//! - No panics on any input: arbitrary samples (silence, clipping, DC) and, once loaded, arbitrary
//!   blob bytes give correct output or a typed error. Outputs are always finite.
//! - Deterministic: `f32` arithmetic with `libm`, so the same input gives the same decisions on
//!   the host and on a Cortex-M4F, and no result depends on how the input is chunked.
//! - One runtime for chips with and without an FPU: the `fixed` feature makes the front-end's
//!   per-sample and per-frame work integer ([`prosody::arith`]); the blob and every decision
//!   after the front-end are the same code.
//! - The trainer computes its features by calling this crate, so training and device features
//!   cannot drift apart.
//!
//! ## Modules
//!
//! - [`prosody`]: the streaming front-end: per 10 ms frame F0 (Praat-style autocorrelation with
//!   a fixed-lag path finder) and intensity (Praat's window); syllables from intensity troughs
//!   and pause steps during silence.
//! - [`inference`]: speaker-normalized step features, prosody-cluster memberships and the CRF
//!   forward step: the belief over hidden gesture-style states.
//! - [`blob`]: the policy blob format (header, CRC-32, postcard payload): the reader, validated
//!   once at load into a typed error (accessors are infallible afterwards), and, with the
//!   `encode` feature, the writer and its quantizer.
//! - [`policy`]: the choice of the next segment at an exit point from the belief, with the
//!   variety costs, the user's style (tone weights mixing the value tables) and, while a
//!   semantic label waits, the label's tables and entries before its stroke.
//! - [`follow`]: the body follows the voice: rest in the pauses, start with the speech, an
//!   energy weight per decision from the voice's loudness.
//! - [`player`]: segment playback as rig poses with a short blend at cuts.
//! - [`controller`]: samples in, poses out: front-end, belief, decisions and playback on one
//!   sample clock; built from a validated blob.
//! - [`show`]: show files: a run's player commands baked against its blob, validated once,
//!   played back by a bare player with the controller's poses and no inference.
//! - [`device`]: the one device loop: a blob's controller and its servo rig, samples in, poses,
//!   duty cycles and events out; what boards, the simulator and evaluations run.
//! - [`rig`]: servo calibration and the `ServoRig`: pose angles to clamped, slew-limited PWM
//!   duty cycles through `embedded_hal::pwm::SetDutyCycle`; neutral pose on fault.
//! - [`rotation`]: rotation matrices, quaternions and Euler angles in `f32` or `f64`, shared by
//!   the device and the host tools.
//! - `pca9685` (feature `pca9685`): the rig's servos on a PCA9685 16-channel I2C board.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

#[cfg(feature = "encode")]
extern crate alloc;

pub mod blob;
pub mod controller;
pub mod device;
pub mod follow;
pub mod inference;
pub mod mic;
#[cfg(feature = "pca9685")]
pub mod pca9685;
pub mod player;
pub mod policy;
pub mod prosody;
pub mod rest;
pub mod rig;
pub mod rotation;
pub mod show;
#[cfg(test)]
mod testing;
