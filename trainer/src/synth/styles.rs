//! The planted hidden style states of the synthetic corpus, and the state track over time.
//!
//! Each state shapes *both* the speech (pitch level and excursion, loudness, syllable rate,
//! pauses) and the gestures (where the hands go, how far, how fast, how curved, how often they
//! hold). Nothing else links the two, so every correlation between prosody and kinematics in a
//! synthetic corpus comes through these states, with noise on both sides: the link is real but
//! imperfect, as in human data, and the states are the ground truth the inference layer should
//! recover.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// One planted style state.
#[derive(Clone, Debug, Serialize)]
pub struct Style {
    /// Human-readable name.
    pub name: &'static str,
    // --- speech ---
    /// F0 relative to the speaker's base.
    pub f0_mult: f64,
    /// Relative F0 rise on stressed syllables.
    pub accent: f64,
    /// Vowel peak level in dB re full scale.
    pub level_dbfs: f64,
    /// Mean syllable duration (s).
    pub syllable_s: f64,
    /// Syllables per phrase (inclusive range).
    pub phrase_len: (u32, u32),
    /// Mean pause between phrases (s).
    pub pause_s: f64,
    // --- gesture (angles in degrees; see `gesture`) ---
    /// Mean arm elevation (-90 down .. +30 above shoulder).
    pub elevation: f64,
    /// Mean forward swing of the upper arm.
    pub swing: f64,
    /// Mean elbow flexion.
    pub flexion: f64,
    /// Spread of stroke targets around the means (same units).
    pub spread: f64,
    /// Half the distance between the home and the extended pose (degrees): strokes go out
    /// and back, as gesture strokes and retractions do, so speed dips between strokes.
    pub reach: f64,
    /// Mean stroke duration (s).
    pub stroke_s: f64,
    /// Sideways bow of a stroke's path (degrees at mid-stroke): the path's curvature.
    pub bow: f64,
    /// Probability of a hold after a stroke.
    pub hold_prob: f64,
    /// Mean hold duration (s).
    pub hold_s: f64,
    /// Whether the non-dominant hand mirrors the strokes.
    pub two_handed: bool,
}

/// The planted states: calm, emphatic, animated, subdued.
pub fn styles() -> [Style; 4] {
    [
        Style {
            name: "calm",
            f0_mult: 1.0,
            accent: 0.12,
            level_dbfs: -18.0,
            syllable_s: 0.24,
            phrase_len: (4, 8),
            pause_s: 0.5,
            elevation: -30.0,
            swing: 25.0,
            flexion: 30.0,
            spread: 4.0,
            stroke_s: 1.1,
            reach: 20.0,
            bow: 4.0,
            hold_prob: 1.0,
            hold_s: 0.6,
            two_handed: true,
        },
        Style {
            name: "emphatic",
            f0_mult: 1.25,
            accent: 0.3,
            level_dbfs: -9.0,
            syllable_s: 0.19,
            phrase_len: (5, 10),
            pause_s: 0.35,
            elevation: -5.0,
            swing: 45.0,
            flexion: 30.0,
            spread: 5.0,
            stroke_s: 0.35,
            reach: 10.0,
            bow: 2.0,
            hold_prob: 1.0,
            hold_s: 0.6,
            two_handed: true,
        },
        Style {
            name: "animated",
            f0_mult: 1.5,
            accent: 0.2,
            level_dbfs: -13.0,
            syllable_s: 0.21,
            phrase_len: (4, 9),
            pause_s: 0.4,
            elevation: 65.0,
            swing: 50.0,
            flexion: 30.0,
            spread: 4.0,
            stroke_s: 0.8,
            reach: 22.0,
            bow: 30.0,
            hold_prob: 1.0,
            hold_s: 0.6,
            two_handed: true,
        },
        Style {
            name: "subdued",
            f0_mult: 0.85,
            accent: 0.06,
            level_dbfs: -24.0,
            syllable_s: 0.28,
            phrase_len: (2, 5),
            pause_s: 0.9,
            elevation: -78.0,
            swing: 8.0,
            flexion: 20.0,
            spread: 3.0,
            stroke_s: 0.8,
            reach: 2.0,
            bow: 3.0,
            hold_prob: 1.0,
            hold_s: 1.0,
            two_handed: false,
        },
    ]
}

/// A run of one state.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct StateRun {
    /// Start (s).
    pub start_s: f64,
    /// End (s).
    pub end_s: f64,
    /// Planted state index.
    pub state: usize,
}

/// Piecewise-constant state over a take: runs of 8-16 s, each followed by a different state
/// chosen uniformly (a semi-Markov chain).
#[derive(Clone, Debug, Serialize)]
pub struct StateTrack {
    /// The runs, tiling `[0, duration)`.
    pub runs: Vec<StateRun>,
}

impl StateTrack {
    /// Draws a track of `duration_s` over `n_states` states.
    pub fn draw(rng: &mut ChaCha8Rng, duration_s: f64, n_states: usize) -> Self {
        let mut runs = Vec::new();
        let mut t = 0.0;
        let mut state = rng.random_range(0..n_states);
        while t < duration_s {
            let len = rng.random_range(8.0..16.0);
            let end = (t + len).min(duration_s);
            runs.push(StateRun {
                start_s: t,
                end_s: end,
                state,
            });
            t = end;
            let step = rng.random_range(1..n_states);
            state = (state + step) % n_states;
        }
        Self { runs }
    }

    /// The state at time `t` (the last run's state past the end).
    pub fn at(&self, t: f64) -> usize {
        match self.runs.iter().find(|r| t < r.end_s) {
            Some(r) => r.state,
            None => self.runs.last().map_or(0, |r| r.state),
        }
    }

    /// The state covering most of `[a, b)`.
    pub fn majority(&self, a: f64, b: f64) -> usize {
        let mut best = (0.0, self.at(a));
        for r in &self.runs {
            let overlap = (b.min(r.end_s) - a.max(r.start_s)).max(0.0);
            if overlap > best.0 {
                best = (overlap, r.state);
            }
        }
        best.1
    }
}
