//! What a controller reports while it runs (its events, and what became of each semantic
//! label), and why one could not be built.

use crate::player::PlayerCommand;
use crate::policy::Decision;
use crate::prosody::{ConfigError, Frame, Step};

/// What the controller reports, in time order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ControllerEvent<'a> {
    /// A prosody frame.
    Frame(Frame),
    /// A step and the belief after it.
    Step {
        /// The step.
        step: Step,
        /// Belief over states after the step.
        belief: &'a [f32],
    },
    /// A decision at an exit point.
    Decision {
        /// Animation tick of the decision.
        tick: u64,
        /// The decision.
        decision: Decision,
    },
    /// The pose of an animation tick (one value per rig channel, degrees).
    Pose {
        /// Tick number from 0.
        tick: u64,
        /// Channel values.
        pose: &'a [f32],
        /// Library segment played (the target of a blend during one).
        segment: usize,
        /// Frame of that segment played.
        frame: usize,
    },
    /// What the controller asked of its player before the pose of `tick` (a cut, a run-on, a
    /// turn, a change of playback rate, a hold): with the blob's library, these alone replay
    /// the poses (a show file).
    Play {
        /// The tick whose pose the command precedes.
        tick: u64,
        /// The command.
        command: PlayerCommand,
    },
    /// A syllable onset was detected (its start frame, 10 ms frames as in [`Frame`]).
    Onset(u32),
    /// A semantic label was received, answered by a segment, shown or dropped.
    Label {
        /// Animation tick (the tick due next, for `Received`).
        tick: u64,
        /// Label index (0-based).
        label: usize,
        /// What happened.
        outcome: LabelOutcome,
    },
}

/// Why a controller could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ControllerError {
    /// The front-end settings are invalid.
    FrontEnd(ConfigError),
    /// The blob's dimensions disagree (GMM clusters vs CRF, states vs policy, channels).
    Dimensions,
}

impl core::fmt::Display for ControllerError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::FrontEnd(e) => write!(f, "front-end: {e}"),
            Self::Dimensions => {
                f.write_str("inconsistent dimensions between inference, policy and library")
            }
        }
    }
}

impl core::error::Error for ControllerError {}

/// What became of a label ([`ControllerEvent::Label`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LabelOutcome {
    /// The label reached the controller (it waits for the next exit point).
    Received,
    /// A segment carrying it was entered (at `frame`), or was already playing before its
    /// stroke.
    Entered {
        /// The segment.
        segment: usize,
        /// The frame it was entered at.
        frame: usize,
    },
    /// The stroke frame of that segment played: the label is served.
    Stroke,
    /// It waited longer than the blob's timeout and was dropped.
    TimedOut,
}
