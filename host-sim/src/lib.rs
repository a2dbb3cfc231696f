//! # host-sim
//!
//! The desktop simulator: audio files in, exactly the runtime's computations out, so that what
//! a user sees on the desktop is what the board will do (docs/method.md, "Who uses it"). `std`;
//! nothing here re-implements runtime behaviour: prosody comes from
//! [`gesture_trainer::features::prosody_of`], which calls the runtime front-end.
//!
//! ## Modules
//!
//! - [`cli`]: the `gesture-sim` command line, exit codes and error lines.
//! - [`prosody_cmd`]: `gesture-sim prosody`: per-frame or per-syllable CSV of a WAV file.
//! - [`eval`]: pure comparison functions (reference CSV parsing, frame matching, the metrics
//!   of the Praat comparison: voicing, gross and fine pitch error, intensity correlation;
//!   syllable counts).
//! - [`eval_cmd`]: `gesture-sim eval-prosody`: the comparison over the shared recordings.
//! - [`bench`](mod@bench): `gesture-sim bench-prosody`: front-end speed.
//! - [`run`](mod@run): `gesture-sim run`: a WAV file through the runtime's device loop, with
//!   BVH, timeline, servo trace and previews written to a folder; with `--show`, its show
//!   file ([`run::show`]).
//! - [`play_show`]: `gesture-sim play-show`: a show file played with the runtime's
//!   `ShowPlayer` (no inference), `servo.csv` and `motion.bvh` as a run writes them.
//! - [`metrics_cmd`]: `gesture-sim metrics`: the motion-quality figures of a `run` folder.
//! - [`live`]: `gesture-sim live` and `devices`: the microphone (cpal) behind the
//!   [`live::AudioSource`] trait, with a fake source for tests.
//! - [`error`]: [`error::SimError`], the error of every command, and its exit status.
//! - [`demo`]: `gesture-sim demo`: synth, fit, pack, a new utterance and `run`, in one command,
//!   then the model driving the shipped real motion capture with real recorded speech.
//! - [`servo`]: virtual PWM pins under the runtime's `ServoRig`.
//! - [`soak`]: `gesture-sim soak`: hours of hostile audio through a blob's device loop (drift,
//!   limits, memory).
//! - [`vmc`]: the played poses to avatar apps over the VMC protocol (OSC over UDP).
//! - [`ros2`]: robots through ROS 2: `sensor_msgs/JointState` over DDS (`--ros2`, feature
//!   `ros2`), in an MCAP file (`--mcap`), and the character as a URDF.
//! - [`urdf_cmd`]: `gesture-sim urdf`: that URDF written alone.
//! - [`style`]: `--style`, `--energy`, `--style-track`: the tone weights of a run.
//! - [`labels`]: `--labels`: semantic labels at audio times.
//! - [`kws`]: `--keywords`: keyword spotting with CMU PocketSphinx (feature `kws`), the only
//!   `unsafe` code of the crate (its FFI module).
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod bench;
pub mod cli;
pub mod demo;
pub mod error;
pub mod eval;
pub mod eval_cmd;
pub mod kws;
pub mod labels;
pub mod live;
pub mod metrics_cmd;
pub mod play_show;
pub mod prosody_cmd;
pub mod ros2;
pub mod run;
pub mod servo;
pub mod soak;
pub mod style;
pub mod urdf_cmd;
pub mod vmc;
