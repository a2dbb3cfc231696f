//! When the controller decides at exit points: on syllable onsets or at once, how long it waits
//! for one, and how far a cut decided mid-segment looks ahead for the hands' next pause
//! (the rules are in [`crate::controller`]'s module docs).

/// When the controller decides at exit points (the rules are in [`crate::controller`]'s module
/// docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DecisionTiming {
    /// Whether decisions wait for syllable onsets; `false` decides at every exit at once.
    pub sync_to_onsets: bool,
    /// An onset detected this recently (ms) counts as "now".
    pub onset_window_ms: u32,
    /// Longest wait (ms) at a segment's end for an onset (running on meanwhile).
    pub max_wait_ms: u32,
    /// Longest hold (ms) at a motion beat waiting for an onset (0: no holds).
    pub beat_hold_ms: u32,
    /// How far ahead (ms of frames) a cut decided mid-segment looks for the playing segment's
    /// calmest next pause of the hands (a calm frame, else a motion beat, else its last frame;
    /// beyond it, the first that comes; 0: cut at once).
    pub defer_cut_ms: u32,
}

impl DecisionTiming {
    /// Decisions on onsets: an onset within 50 ms, a hold of at most 300 ms at segment ends, a
    /// cut decided mid-segment put off for at most 400 ms until the hands pause (chosen on
    /// tuning speech with `gesture-train eval-motion`; see docs/method.md).
    pub const DEFAULT: Self = Self {
        sync_to_onsets: true,
        onset_window_ms: 50,
        max_wait_ms: 300,
        beat_hold_ms: 0,
        defer_cut_ms: 400,
    };
    /// Every exit point decides as soon as it is reached.
    pub const IMMEDIATE: Self = Self {
        sync_to_onsets: false,
        onset_window_ms: 0,
        max_wait_ms: 0,
        beat_hold_ms: 0,
        defer_cut_ms: 0,
    };
}

impl Default for DecisionTiming {
    fn default() -> Self {
        Self::DEFAULT
    }
}
