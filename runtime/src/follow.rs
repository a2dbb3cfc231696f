//! The body follows the voice: rest in the pauses, start with the speech, energy with the
//! loudness (docs/method.md, "Beyond the paper: the body follows the voice").
//!
//! The paper's cost of showing segment `c` under belief `b` is `b . psi_c` plus the successor
//! cost (§6); the belief is all the controller knows of the speech. With a weak belief (two
//! states, a third of a nat per step above the prior on the shared takes) that is not enough:
//! the hands went on gesturing through silences at half to four fifths of their speaking speed
//! and started late when the speech returned, because the belief needs a syllable or two to
//! move and decisions waited for onsets that a pause does not have. Speakers rest in pauses
//! (their hands at 4-8 % of the speaking speed in the shared takes) and start with the speech.
//!
//! This module adds what the voice says directly, as one more term of the decision cost, the
//! way the style machinery (§8.2) adds a tone: an **energy weight per decision**, `w . E_c`,
//! where `E_c` is the segment's energy (the log of its hands' mean speed over the library's
//! median frame speed, computed by `pack`: `library.energy`) and `w` comes from the voice:
//!
//! - **resting** (the speech has been silent for `rest_ms`, counted in the front-end's pause
//!   steps): `w = rest_cost`, so the calmest segments cost least. The `REST_EXTRAS` calmest
//!   segments of the library are candidates at every exit point while resting (the pruned
//!   successor lists need not hold one), at the largest successor cost of that exit (an entry
//!   no better than the worst listed junction; the player's blend makes every cut seamless).
//!   Resting, every exit point decides at once (no onset is coming) and the moment resting
//!   begins the controller decides at the playing segment's next exit point without waiting
//!   for it: the cut then waits, as every mid-segment cut does, for the next pause of the hands
//!   (`defer_cut_ms`), so the playing gesture is left between strokes. The rest motion is the
//!   library's own: its calmest segments, breathing and drifting as the capture did; once one
//!   is entered it holds until the speech returns, played to and fro (the player turns at its
//!   ends: no cut, no freeze). A rest **holds the posture** the gesture paused in: it begins
//!   at its calm frame nearest the pose shown, plays to and fro among its calm frames (at
//!   least half a second of them), and the posture drifts into the rest's own at a twentieth
//!   of the library's speed cap ([`REST_BLEND`](crate::player::REST_BLEND)). Blended in at a
//!   gesture's pace, the rest's posture (arms lowered, or spread in a monologue's calmest
//!   segment) was a second movement a second into the pause, as fast as a gesture.
//! - **speaking**: `w = -energy_cost * clamp(level / VOICE_SPAN, -1, 1)`, `level` the last
//!   syllable's intensity relative to the speaker's running level (the CRF's own step feature,
//!   in 10 dB units): louder than usual favours energetic segments, quieter calm ones. And the
//!   rest segments cost `rest_cost` more (entering or continuing one): they are the capture's
//!   rests, which a speaker does not show while talking (on the 9-joint ZeroEGGS library the
//!   variety costs otherwise brought its nine-second rests into the middle of sentences).
//! - **the speech returns** (the first onset after resting): the controller decides at once,
//!   at the playing segment's next exit point; the cut waits for a pause of the hands like
//!   any mid-segment cut, which a rest's calm frames give at once (after a short silence the
//!   playing gesture may still be finishing its stroke: cutting it there would jump); the
//!   voice level counts as `+VOICE_SPAN` until the first syllable is measured (speech out of
//!   silence is as loud as it gets relative to it). The chosen segment is entered at its
//!   first frame: a preparation, not a stroke.
//! - **the rest's pace**: a library with no true rest (a monologue's capture: the calmest
//!   segments of the shared 067 take move at 0.4 of its median hand speed) would still gesture
//!   in the pauses. While resting, a segment faster than [`REST_SPEED`] of the library's median
//!   plays slower in proportion ([`rest_rate`]), at least at half its pace
//!   ([`REST_MIN_RATE`]), interpolated between frames: a calm motion at
//!   half speed reads as breathing and drift, not as slow motion.
//! - **a tone** the user chose (`policy::Style`) sets the body's energy while speaking: the
//!   speaking energy weight is scaled by the style's neutral weight plus the weights of the
//!   tones that lean energetic ([`energetic_tones`]; 1 by default, 0 under `sad=1`, 1 under a
//!   tone that leans energetic, as `active=1` does on the shared libraries). Under a calm tone it would override the tone (on new speech, sad motion kept
//!   0.96 of the neutral hand speed; scaled, 0.63); under an energetic one, switching it off
//!   took away more energy than the tone brought (the energy knob's `energetic=1` moved 0.96x
//!   as fast as neutral; kept, 1.02x). The rest penalty and resting stay the voice's: without
//!   the penalty every tone brought the rests into speech.
//!
//! - **the gesture's size** ([`Expressive`], [`Voice::gain`]): between decisions the player's
//!   expression stage ([`crate::player::expression`]) shows the quick part of the motion
//!   larger when the voice is louder, smaller when it is quieter (down to half size 15 dB
//!   under the speaker's level, [`QUIET_SPAN`]), and at half size from the
//!   first pause step of a silence, so the motion follows the voice within a syllable, not
//!   only at the next exit point. Resting, a gesture still playing (its cut into a rest waits
//!   for a pause of its hands, a second or more at the rest's pace) is shown at a quarter of
//!   its size ([`Expressive::caught`]): it settled sooner on every span measured. A rest
//!   segment, once it plays in a rest, is shown at its own size: it is the capture's own
//!   rest (breathing, drift), already calm; at half size a quiet one (the 9-joint take's
//!   opening) moved under 0.05 degrees a frame, still to the eye and to the freeze measure.
//!   Live, the loudness is the front-end's 10 ms frames ([`Voice::hear`]: a quick rise, a slower
//!   fall), not the syllables' levels: a syllable's level is known only once the syllable has
//!   ended and been confirmed (about 0.09 s later), and the hands' speed then trailed the
//!   voice by about 0.3 s (their correlation with the loudness was highest with the speech
//!   moved 0.3 s later). With look-ahead the syllables' levels take effect at their own time,
//!   and they set the size. The size follows the voice under every tone: scaled by the
//!   style's neutral weight like the energy weight, an `active` tone lost it and moved no
//!   faster than neutral speech (0.99x on new speech).
//!
//! The belief still chooses among segments of like energy, and the variety costs still apply
//! (among the rest segments too). `VoiceFollow::NONE` gives the paper's rule. All arithmetic is
//! `f32` on values read from the blob, the same on host and device; the state is a few bytes.

use crate::policy::{PolicyTables, Style};

/// How the character follows the voice (the blob's `control` section).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoiceFollow {
    /// Silence (ms, counted in pause steps) after which the character rests; 0: never.
    pub rest_ms: u32,
    /// Cost per unit of segment energy while resting.
    pub rest_cost: f32,
    /// Cost per unit of segment energy at full voice level while speaking.
    pub energy_cost: f32,
}

impl VoiceFollow {
    /// Not following the voice: the paper's rule.
    pub const NONE: Self = Self {
        rest_ms: 0,
        rest_cost: 0.0,
        energy_cost: 0.0,
    };
}

/// How much a gesture's size follows the voice: the player's expression stage
/// ([`crate::player::expression`]) shows the quick part of the motion `1 + span * v` times its
/// size while speaking (`v` the loudness heard over [`VOICE_SPAN`], clamped to -1..1; see
/// [`Voice::gain`]) and `pause` times from the first pause step of a silence until a rest
/// segment plays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Expressive {
    /// Gain above or below 1 at full voice level (each way).
    pub span: f32,
    /// Gain in a silence, until a rest segment plays.
    pub pause: f32,
    /// Gain of a gesture still playing once the character rests (until the cut into a rest
    /// segment, which waits for a pause of the hands).
    pub caught: f32,
}

impl Expressive {
    /// The frames as they are.
    pub const NONE: Self = Self {
        span: 0.0,
        pause: 1.0,
        caught: 1.0,
    };

    /// The expression of a blob that follows the voice as `follow` says: [`EXPRESSION`], or
    /// none under the paper's rule ([`VoiceFollow::NONE`]).
    pub fn of(follow: &VoiceFollow) -> Self {
        if *follow == VoiceFollow::NONE {
            Self::NONE
        } else {
            EXPRESSION
        }
    }
}

/// The expression of a blob that follows the voice: 30 % larger at full voice level (5 dB
/// above the speaker's running level), 30 % smaller 5 dB under it and on down to half size
/// 15 dB under ([`QUIET_SPAN`]), half size in a silence,
/// and half that for a gesture the rest caught in the middle. A third either way stays within
/// how much one speaker's strokes vary in size between calm and emphatic phrases; chosen on
/// tuning speech (docs/method.md).
pub const EXPRESSION: Expressive = Expressive {
    span: 0.3,
    pause: 0.5,
    caught: 0.25,
};

/// How fast a rest moves at most: this share of the library's median hand speed (a segment's
/// energy `ln(REST_SPEED)` or less plays at its own pace while resting).
pub const REST_SPEED: f32 = 0.2;

/// The slowest pace of a rest: half the library's. Calm motion at half speed still reads as
/// breathing and drift; slower, it reads as slow motion.
pub const REST_MIN_RATE: f32 = 0.5;

/// The playback rate of a segment of energy `energy` while resting: its own pace if it is
/// calm enough ([`REST_SPEED`]), else slower in proportion, down to [`REST_MIN_RATE`].
pub fn rest_rate(energy: f32) -> f32 {
    let r = REST_SPEED * libm::expf(-energy);
    if r.is_finite() {
        r.clamp(REST_MIN_RATE, 1.0)
    } else {
        1.0
    }
}

/// The calmest segments, candidates at every exit point while resting (re-exported from
/// [`crate::rest`]).
pub use crate::rest::{RestSet, REST_SET};

/// The rest segments of a character that follows the voice as `follow` says: the calmest
/// ([`RestSet::of`]), or none if it never rests.
pub fn rest_segments<T: PolicyTables + ?Sized>(
    t: &T,
    segments: usize,
    follow: &VoiceFollow,
) -> RestSet {
    if follow.rest_cost > 0.0 && follow.rest_ms > 0 {
        RestSet::of(t, segments)
    } else {
        RestSet::EMPTY
    }
}

/// The tones of `t` that lean energetic (bit `m` for tone `m`, at most 8): their value tables,
/// less the neutral ones, fall with the segments' energy over the first `segments` segments
/// and every state (a negative covariance). While speaking, the voice's energy term acts on
/// the neutral share of the style and on these tones' weights: an energetic tone adds to the
/// energy loud speech brings, a calm one (sad) is not overridden by it.
pub fn energetic_tones<T: PolicyTables + ?Sized>(t: &T, segments: usize) -> u8 {
    let states = t.states();
    if segments == 0 || states == 0 {
        return 0;
    }
    let mut mean = 0.0;
    for c in 0..segments {
        mean += t.energy(c);
    }
    mean /= segments as f32;
    let mut mask = 0u8;
    for m in 0..t.tones().min(8) {
        let mut cov = 0.0f32;
        for c in 0..segments {
            let de = t.energy(c) - mean;
            for s in 0..states {
                cov += (t.tone_u(m, c, s) - t.u(c, s)) * de;
            }
        }
        if cov < 0.0 {
            mask |= 1 << m;
        }
    }
    mask
}

/// The share of `style` the voice's energy weight acts on while speaking: its neutral weight
/// and the weights of the tones of `t` that lean energetic ([`energetic_tones`] over the
/// first `segments` segments); 1 for the neutral style.
// Not inlined: it runs once per style change, and the boards' code is near its budget.
#[inline(never)]
pub fn voice_share<T: PolicyTables + ?Sized>(t: &T, segments: usize, style: &Style) -> f32 {
    if style.is_neutral() {
        return 1.0;
    }
    let lean = energetic_tones(t, segments);
    let mut share = style.neutral();
    for (m, &w) in style.weights().iter().enumerate() {
        if m < 8 && lean >> m & 1 == 1 {
            share += w;
        }
    }
    share
}

/// The calmest of those, candidates at every exit point while resting: the selector's own
/// bound ([`crate::policy::REST_EXTRAS`]).
pub use crate::policy::REST_EXTRAS;

/// Voice level (the step feature, 10 dB units) at which the energy weight is full.
pub const VOICE_SPAN: f32 = 0.5;

/// Voice level under the speaker's running level (10 dB units) at which a gesture is shown
/// at the pause's size: between `VOICE_SPAN` and this far under it the gain falls on from
/// `1 - span` to `pause`, so the gaps between phrases, too short for a pause step (250 ms),
/// shrink the gesture as a pause does. Chosen on the tuning spans (30 runs, coupling +0.544
/// -> +0.550 on 9-joint 90-121 s, +0.610 -> +0.612 with the 067 library on the 001 take; 2.5
/// gave +0.548 and +0.612) and on the report spans +0.003 to +0.009.
pub const QUIET_SPAN: f32 = 1.5;

/// Per 10 ms frame heard live, how far the loudness a gesture's size follows moves towards a
/// louder frame (a time constant of 30 ms) and towards a quieter one (120 ms): it rises with a
/// syllable's onset and falls over the gaps between phrases, not between every two syllables.
pub const HEAR_ATTACK: f32 = 0.28;
/// See [`HEAR_ATTACK`].
pub const HEAR_RELEASE: f32 = 0.08;

/// What just changed in the voice.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VoiceChange {
    /// The silence reached `rest_ms`: rest.
    Rest,
    /// The speech returned after a rest.
    Speak,
}

/// The voice as the controller follows it: silence so far, the last syllable's level,
/// whether resting. A few bytes; no allocation, no panics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Voice {
    /// Pause steps since the last syllable or onset.
    silent_steps: u32,
    /// The last syllable's intensity relative to the running level (10 dB units).
    level: f32,
    resting: bool,
    change: Option<VoiceChange>,
    /// The loudness the gesture's size follows (relative to the running level, 10 dB
    /// units): the frames' ([`Voice::hear`]) once any is heard, else the last syllable's.
    now: f32,
    hearing: bool,
}

impl Voice {
    /// Speaking at the running level, not resting.
    pub const fn new() -> Self {
        Self {
            silent_steps: 0,
            level: 0.0,
            resting: false,
            change: None,
            now: 0.0,
            hearing: false,
        }
    }

    /// Before anyone has spoken: resting if `f` rests at all (so the first syllable is the
    /// speech's return, which decides at once, as after any pause), with no change to report.
    pub const fn silent(f: &VoiceFollow) -> Self {
        let mut v = Self::new();
        v.resting = f.rest_ms > 0 && f.rest_cost > 0.0;
        v
    }

    /// A step: a pause step of `pause_ms` (silence goes on) or a syllable at `level`.
    pub fn step(&mut self, f: &VoiceFollow, pause: bool, level: f32, pause_ms: u32) {
        if !pause {
            self.silent_steps = 0;
            self.level = if level.is_finite() { level } else { 0.0 };
            if !self.hearing {
                self.now = self.level;
            }
            return;
        }
        self.silent_steps = self.silent_steps.saturating_add(1);
        let rests = f.rest_ms > 0 && f.rest_cost > 0.0;
        if rests && !self.resting && self.silent_steps.saturating_mul(pause_ms) >= f.rest_ms {
            self.resting = true;
            self.change = Some(VoiceChange::Rest);
        }
    }

    /// A syllable onset: the silence ends; after a rest, the speech returns.
    pub fn onset(&mut self) {
        self.silent_steps = 0;
        if self.resting {
            self.resting = false;
            self.level = VOICE_SPAN;
            if !self.hearing {
                self.now = VOICE_SPAN;
            }
            self.change = Some(VoiceChange::Speak);
        }
    }

    /// A 10 ms frame of intensity `db` heard live, the speaker's running syllable level
    /// being `reference_db`: the loudness the gesture's size follows moves towards it
    /// ([`HEAR_ATTACK`] rising, [`HEAR_RELEASE`] falling).
    pub fn hear(&mut self, db: f32, reference_db: f32) {
        // 30 dB under the level is silence enough.
        let l = ((db - reference_db) / 10.0).clamp(-3.0, 2.0);
        if l.is_finite() {
            self.hearing = true;
            let k = if l > self.now {
                HEAR_ATTACK
            } else {
                HEAR_RELEASE
            };
            self.now += k * (l - self.now);
        }
    }

    /// Whether the character rests.
    pub fn resting(&self) -> bool {
        self.resting
    }

    /// What changed since the last call, once.
    pub fn take_change(&mut self) -> Option<VoiceChange> {
        self.change.take()
    }

    /// The expression gain the voice asks for now ([`Expressive`]), `rest_plays` whether a
    /// rest segment is playing: resting, `e.caught` while a gesture still plays (the cut into
    /// a rest waits for a pause of its hands), 1 once a rest plays (a rest is shown at its own
    /// size); not resting, `e.pause` from the first pause step of a silence; else
    /// `1 + e.span * min(level / VOICE_SPAN, 1)` down to `1 - e.span` at `-VOICE_SPAN`, and
    /// from there down to `e.pause` at `-QUIET_SPAN` ([`QUIET_SPAN`]; `level` the loudness
    /// heard, [`Voice::hear`], or without frames the last syllable's); within the player's
    /// [`GAIN_RANGE`](crate::player::expression::GAIN_RANGE), 1 if not finite. Under
    /// every tone alike: a tone chooses which gestures are played and how energetic they are,
    /// the voice how large they are shown.
    pub fn gain(&self, e: &Expressive, rest_plays: bool) -> f32 {
        let g = if self.resting {
            if rest_plays {
                1.0
            } else {
                e.caught
            }
        } else if self.silent_steps > 0 {
            e.pause
        } else if self.now < -VOICE_SPAN {
            // Quieter still, down to the pause's size at `QUIET_SPAN` under the level.
            let s = ((-self.now - VOICE_SPAN) / (QUIET_SPAN - VOICE_SPAN)).min(1.0);
            (1.0 - e.span) + (e.pause - (1.0 - e.span)) * s
        } else {
            1.0 + e.span * (self.now / VOICE_SPAN).min(1.0)
        };
        let (lo, hi) = crate::player::expression::GAIN_RANGE;
        if g.is_finite() {
            g.clamp(lo, hi)
        } else {
            1.0
        }
    }

    /// The energy weight `w` of a decision now (see the module docs).
    pub fn weight(&self, f: &VoiceFollow) -> f32 {
        if self.resting {
            f.rest_cost
        } else {
            -f.energy_cost * (self.level / VOICE_SPAN).clamp(-1.0, 1.0)
        }
    }
}

impl Default for Voice {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const F: VoiceFollow = VoiceFollow {
        rest_ms: 500,
        rest_cost: 4.0,
        energy_cost: 2.0,
    };

    /// Known answer: heard live, the loudness the size follows rises by `HEAR_ATTACK` and
    /// falls by `HEAR_RELEASE` of the way per frame (`1 - (1 - k)^n` after `n` frames), in
    /// level units relative to the speaker's running level, bounded to -3..2; a syllable's
    /// level no longer sets it, and a non-finite frame leaves it.
    #[test]
    fn heard_frames_set_the_gain_with_a_quick_rise_and_a_slow_fall() {
        let e = EXPRESSION;
        let mut v = Voice::new();
        // Before any frame is heard (look-ahead), the last syllable's level sets the gain.
        v.step(&F, false, 0.25, 250);
        assert!((v.gain(&e, false) - (1.0 + e.span * 0.5)).abs() < 1e-6);
        // 5 dB above the level (0.5 units) for 4 frames: the rise from 0.25.
        for _ in 0..4 {
            v.hear(65.0, 60.0);
        }
        let now = 0.5 - 0.25 * (1.0 - HEAR_ATTACK).powi(4);
        let want = 1.0 + e.span * (now / VOICE_SPAN);
        assert!(
            (v.gain(&e, false) - want).abs() < 1e-5,
            "{}",
            v.gain(&e, false)
        );
        // A syllable's level, reported a syllable late, does not override what is heard.
        v.step(&F, false, -0.5, 250);
        assert!((v.gain(&e, false) - want).abs() < 1e-5);
        // Silence (-300 dB counts as 30 dB under the level) for 4 frames: the slow fall, to
        // between 5 and 15 dB under the level, where the gain goes on down towards the pause's.
        for _ in 0..4 {
            v.hear(-300.0, 60.0);
        }
        let fall = -3.0 + (now + 3.0) * (1.0 - HEAR_RELEASE).powi(4);
        assert!(fall < -VOICE_SPAN && fall > -QUIET_SPAN, "{fall}");
        let share = (-fall - VOICE_SPAN) / (QUIET_SPAN - VOICE_SPAN);
        let want = (1.0 - e.span) + (e.pause - (1.0 - e.span)) * share;
        assert!(
            (v.gain(&e, false) - want).abs() < 1e-5,
            "{}",
            v.gain(&e, false)
        );
        // Six frames more: over 15 dB under, the pause's size.
        for _ in 0..6 {
            v.hear(-300.0, 60.0);
        }
        assert!((v.gain(&e, false) - e.pause).abs() < 1e-6);
        let g = v.gain(&e, false);
        v.hear(f32::NAN, 60.0);
        v.hear(70.0, f32::INFINITY);
        assert_eq!(v.gain(&e, false), g);
        // A pause step still brings the pause's gain.
        v.step(&F, true, -3.0, 250);
        assert_eq!(v.gain(&e, false), e.pause);
    }

    /// Known answers of the size against the loudness: 1.3 at 5 dB or more above the level,
    /// 0.7 at 5 dB under it, then on down to the pause's 0.5 at 15 dB under (0.6 halfway).
    #[test]
    fn quieter_than_the_level_the_gesture_shrinks_to_the_pause_s_size() {
        let e = EXPRESSION;
        for (level, want) in [
            (1.0, 1.3),
            (0.5, 1.3),
            (0.0, 1.0),
            (-0.25, 0.85),
            (-0.5, 0.7),
            (-1.0, 0.6),
            (-1.5, 0.5),
            (-3.0, 0.5),
        ] {
            let mut v = Voice::new();
            v.step(&F, false, level, 250);
            assert!(
                (v.gain(&e, false) - want).abs() < 1e-6,
                "{level}: {}",
                v.gain(&e, false)
            );
        }
    }

    #[test]
    fn rest_begins_after_rest_ms_of_pause_steps_and_ends_at_an_onset() {
        let e = EXPRESSION;
        let mut v = Voice::new();
        v.step(&F, false, 0.3, 250);
        assert_eq!(v.weight(&F), -2.0 * 0.6);
        v.step(&F, true, -6.0, 250);
        assert!(!v.resting());
        assert_eq!(v.take_change(), None);
        // A silence not yet a rest: the pause's gain, whatever plays.
        assert_eq!((v.gain(&e, false), v.gain(&e, true)), (e.pause, e.pause));
        v.step(&F, true, -6.0, 250);
        assert!(v.resting());
        assert_eq!(v.take_change(), Some(VoiceChange::Rest));
        assert_eq!(v.take_change(), None);
        assert_eq!(v.weight(&F), 4.0);
        // Resting: a gesture still playing shrinks further until a rest segment plays, and
        // the rest plays at its own size.
        assert_eq!((v.gain(&e, false), v.gain(&e, true)), (e.caught, 1.0));
        assert!(e.caught < e.pause);
        // More silence changes nothing.
        v.step(&F, true, -6.0, 250);
        assert_eq!(v.take_change(), None);
        v.onset();
        assert!(!v.resting());
        assert_eq!(v.take_change(), Some(VoiceChange::Speak));
        // The returning voice counts as full level until its first syllable is measured.
        assert_eq!(v.weight(&F), -2.0);
        v.step(&F, false, -0.25, 250);
        assert_eq!(v.weight(&F), 1.0);
        // Speaking again, the voice's gain, whatever plays.
        let g = 1.0 + e.span * (-0.25 / VOICE_SPAN);
        assert!((v.gain(&e, false) - g).abs() < 1e-6 && v.gain(&e, true) == v.gain(&e, false));
    }

    #[test]
    fn before_anyone_speaks_the_voice_rests_and_the_first_onset_is_its_return() {
        let mut v = Voice::silent(&F);
        assert!(v.resting());
        assert_eq!(v.take_change(), None);
        v.onset();
        assert!(!v.resting());
        assert_eq!(v.take_change(), Some(VoiceChange::Speak));
        // Without rests (the paper's rule) it does not.
        let mut n = Voice::silent(&VoiceFollow::NONE);
        assert!(!n.resting());
        n.onset();
        assert_eq!(n.take_change(), None);
    }

    #[test]
    fn a_syllable_between_pause_steps_restarts_the_count_and_none_never_rests() {
        let mut v = Voice::new();
        v.step(&F, true, -6.0, 250);
        v.step(&F, false, 0.0, 250);
        v.step(&F, true, -6.0, 250);
        assert!(!v.resting());
        let mut n = Voice::new();
        for _ in 0..100 {
            n.step(&VoiceFollow::NONE, true, -6.0, 250);
        }
        assert!(!n.resting());
        assert_eq!(n.weight(&VoiceFollow::NONE), 0.0);
        // An onset without a rest is no change.
        n.onset();
        assert_eq!(n.take_change(), None);
    }

    use crate::testing::Energies;

    /// Two states, four segments of energy -1, 0, 1, 2 and three tones: the first's values
    /// fall with the energy, the second's rise, the third's are the neutral ones shifted.
    struct Toned;
    impl PolicyTables for Toned {
        fn states(&self) -> usize {
            2
        }
        fn exit_count(&self) -> usize {
            1
        }
        fn exit_segment(&self, _: usize) -> usize {
            0
        }
        fn exit_frame(&self, _: usize) -> usize {
            0
        }
        fn exit_is_end(&self, _: usize) -> bool {
            true
        }
        fn first_exit(&self, _: usize) -> usize {
            0
        }
        fn u(&self, c: usize, s: usize) -> f32 {
            [0.5, -0.25, 1.0, 0.0][c] + s as f32
        }
        fn u_cont(&self, _: usize, _: usize) -> f32 {
            0.0
        }
        fn successor_count(&self, _: usize) -> usize {
            0
        }
        fn successor(&self, _: usize, _: usize) -> (usize, f32) {
            (0, 0.0)
        }
        fn tones(&self) -> usize {
            3
        }
        fn energy(&self, c: usize) -> f32 {
            c as f32 - 1.0
        }
        fn tone_u(&self, m: usize, c: usize, s: usize) -> f32 {
            let e = self.energy(c);
            self.u(c, s) + [-0.1 * e, 0.2 * e, 3.0][m]
        }
    }

    #[test]
    fn a_tone_leans_energetic_when_its_values_fall_with_the_energy() {
        // Tone 0 prefers energetic segments, tone 1 calm ones, tone 2 neither.
        assert_eq!(energetic_tones(&Toned, 4), 0b001);
        // No segments, or only one (no spread of energy): none leans either way.
        assert_eq!(energetic_tones(&Toned, 0), 0);
        assert_eq!(energetic_tones(&Toned, 1), 0);
    }

    #[test]
    fn the_rest_rate_slows_what_is_faster_than_a_rest_down_to_half() {
        assert_eq!(rest_rate(-3.0), 1.0);
        assert_eq!(rest_rate(REST_SPEED.ln()), 1.0);
        let r = rest_rate(REST_SPEED.ln() + 0.5);
        assert!((r - (-0.5f32).exp()).abs() < 1e-6, "{r}");
        assert_eq!(rest_rate(2.0), REST_MIN_RATE);
        assert_eq!(rest_rate(f32::NAN), 1.0);
    }

    #[test]
    fn the_rest_set_is_the_calmest_segments_in_order() {
        let t = Energies(&[0.5, -1.0, 2.0, -2.0, -1.0, 0.0, 1.0, -0.5]);
        let r = RestSet::of(&t, 8);
        assert_eq!(r.segments(), &[3, 1, 4, 7]);
        assert_eq!(r.energy(), -0.5);
        assert_eq!(RestSet::EMPTY.energy(), f32::NEG_INFINITY);
        assert!(r.contains(7) && !r.contains(5));
        let small = RestSet::of(&t, 2);
        assert_eq!(small.segments(), &[1]);
        assert_eq!(RestSet::of(&t, 1).segments(), &[0]);
        let big = Energies(&[
            0.5, -1.0, 2.0, -2.0, -1.0, 0.0, 1.0, -0.5, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0,
        ]);
        let r = RestSet::of(&big, 14);
        assert_eq!(r.segments(), &[3, 1, 4, 7, 5, 0]);
        assert_eq!((r.extras(), r.energy()), (&[3u16, 1, 4][..], 0.5));
        assert_eq!(RestSet::of(&t, 0).segments(), &[] as &[u16]);
    }

    #[test]
    fn a_long_rest_hands_over_to_the_least_used_other_rest() {
        let t = Energies(&[0.5, -1.0, 2.0, -2.0, -1.0, 0.0, 1.0, -0.5]);
        let r = RestSet::of(&t, 8);
        // The rests 3, 1, 4, 7 have played these shares of the recent frames.
        let used = |c: usize| match c {
            3 => 0.2,
            1 => 0.1,
            4 => 0.05,
            7 => 0.3,
            _ => 1.0,
        };
        assert_eq!(r.hand_over(3, used), Some(4));
        assert_eq!(r.hand_over(4, used), Some(1));
        // A tie goes to the calmer (3 before 1 before 4).
        assert_eq!(r.hand_over(7, |_| 0.0), Some(3));
        assert_eq!(r.hand_over(3, |_| 0.0), Some(1));
        // With one rest there is no other.
        assert_eq!(RestSet::of(&t, 2).hand_over(1, used), None);
        assert_eq!(RestSet::EMPTY.hand_over(0, used), None);
    }
}
