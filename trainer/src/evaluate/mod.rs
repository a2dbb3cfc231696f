//! Evaluations that run what the device runs: the model and library packed into blob bytes,
//! read back and driven through the runtime's device loop.
//!
//! - [`metrics`]: the motion-quality figures of one motion (variety, freezes, feet,
//!   smoothness, beats, hand speeds), from poses on the library's skeleton;
//! - [`trace`]: a motion as shown (hands, anchor, feet, rotations) and its segment entries;
//! - [`signals`]: hand speed, strokes, beat alignment, coupling and stillness, the signals
//!   behind the figures;
//! - [`motion`]: motion quality of the online controller on held-out audio against its
//!   ablations, random selection, the offline DP reference and the motion capture;
//! - [`playback`]: the device loop on audio and schedules through the player, as played;
//! - [`reference`](mod@reference): the hand-speed reference matched to the speech, as the character shows
//!   it;
//! - [`voice`]: whether the body follows the voice: the hands' speed in the speech's pauses
//!   against in speech, and how soon they settle and move again (part of [`metrics`]).
//! - [`style`]: what each style (tone mix) does to the played motion;
//! - [`table`]: the printed table of those figures;
//! - [`error`]: why an evaluation failed.

pub mod error;
pub mod metrics;
pub mod motion;
pub mod playback;
pub mod reference;
pub mod signals;
pub mod style;
pub mod table;
pub mod trace;
pub mod voice;
