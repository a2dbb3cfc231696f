//! The `Controller`: microphone samples in; at every animation tick a pose out; decisions at
//! exit points from the current belief (docs/method.md "The runtime").
//!
//! Per sample the prosody front-end runs; each finished step (syllable or pause) is
//! normalized, turned into cluster memberships and fed to the CRF forward step. Animation ticks
//! come at the library's frame rate, placed on the sample clock (tick `k` is due once
//! `ceil(k * rate / fps)` samples have arrived), and input is split at tick boundaries, so
//! the result does not depend on how samples are chunked. At a tick the player outputs the
//! current frame of the current segment; if that frame is the current exit point, the policy
//! decides with the belief as it stands.
//!
//! **Decisions on syllable onsets** ([`DecisionTiming`]). By default, decisions are timed
//! against the speech, so that new gestures start with syllables. An interruption exit is
//! decided only on a syllable onset: one detected within the last `onset_window_ms`, or one
//! that comes within `max_wait_ms` after the exit's frame while the segment plays on. Without
//! one (or once the segment's next exit point comes first) the segment plays on, as if the
//! policy had chosen to continue; so a long segment can be left on the speech, not only when
//! an onset happens to fall on one of its few interruption frames. At a segment's end the
//! controller waits for an onset, for at most `max_wait_ms`, before deciding. **The body never
//! stops while it waits**: the player runs on into the segment's recorded successor (the
//! frames that followed it in the capture); choosing that successor then simply continues it,
//! and choosing anything else cuts from where the body is. A segment without a recorded
//! successor (the end of a clip) does not wait: it decides at once. [`DecisionTiming::IMMEDIATE`]
//! decides at every exit point as soon as it is reached (the paper's controller). Onsets come
//! from the front-end ([`Event::Onset`]).
//!
//! **Cuts between strokes** (`defer_cut_ms`, 400 ms by default). A cut decided while the
//! playing segment is in the middle (not at its last frame) waits for a pause of the hands:
//! the first calm frame ([`LibraryFrames::is_calm`]) of the playing segment within
//! `defer_cut_ms` of frames ahead, else its first motion beat there
//! ([`LibraryFrames::is_beat`]: a local minimum of the hands' speed, which in a fast gesture
//! can still be fast), else its last frame if that comes within the window, else the first of
//! these that comes, however late; the segment plays on meanwhile and no exit point is
//! considered. (With a time limit instead, cuts at the limit fell mid-stroke: once the
//! voice made the chosen gestures more energetic, the hands' mean step at a cut rose above
//! random choices', 0.36 against 0.27 cm on beat-scott.) The decision, its belief and its event
//! stay at the onset; the entry (history, next exit point) counts from the cut. Cutting in the
//! middle of a stroke shows no jump (the blend keeps pose and velocity), but the hands leave at
//! the speed they had; between strokes they are slow. A decision while a semantic label waits
//! cuts at once. After a cut, the new segment's interruption exit points in the first quarter
//! of its blend are passed by ([`FRESH_BLEND`]): no cut follows another within 100 ms.
//!
//! **Beat holds** (`beat_hold_ms`, 0 by default): at a motion beat of the library (a hands'
//! speed minimum) the playback may hold, for at most that long, until a syllable onset.
//!
//! **Variety.** Every segment entry goes into a fixed-capacity history, from which each
//! decision charges recently entered and much-used candidates ([`Variety`], see
//! [`crate::policy`]). Cuts are inertialized by the player ([`crate::player`]).
//!
//! **Poses within the rig's limits.** Every pose is clamped to its channels' calibrated limits
//! (a non-finite value becomes the neutral angle) before it leaves the controller, whatever
//! the frames and the blends made of it, so a board that writes poses to its servos without
//! the rig's own clamp cannot drive one into its stop.
//!
//! Memory is fixed: the front-end (about 9 KiB), a belief, the player, the history and a few
//! counters. Nothing allocates or panics; poses are finite and within the limits.
//!
//! Building: [`Controller::new`] returns the controller (about 15 KiB) by value, which the
//! compiler copies through stack temporaries on its way; [`Controller::new_in`] builds the same
//! controller in place in a caller's `Option` (on the stack or in a `static`), the large tables
//! written where they stay, so construction needs only a few KiB of stack beyond the controller
//! itself (measured on a Cortex-M4F by `boards/qemu-m4/report`).

mod ahead;
mod build;
mod event;
mod labels;
mod rest_entry;
mod resting;
mod settings;

use crate::blob::Blob;
use crate::follow::{Expressive, RestSet, Voice, VoiceChange, VoiceFollow};
use crate::inference::{
    memberships, Belief, CrfWeights, GmmComponent, StepNormalizer, MAX_CLUSTERS, MAX_STATES,
};
use crate::player::{within_limits, LibraryFrames, Player, PlayerCommand, MAX_CHANNELS};
use crate::policy::{
    select_labelled, select_styled, Choice, History, Penalties, PolicyTables, Style, Variety, Visit,
};

pub use crate::policy::{DecisionTiming, MAX_LABELLED, MAX_LABELS};
use ahead::{Ahead, VoiceItem};
pub use ahead::{Lookahead, MAX_LOOKAHEAD_MS, NEAR_SHIFT_MS, STROKE_PACE_MS, WARP_MAX, WARP_MIN};
pub use event::{ControllerError, ControllerEvent, LabelOutcome};
use labels::Labels;
pub use labels::{LabelError, LABEL_QUEUE};
pub use rest_entry::{rest_entry, span_ends, RestEntry, REST_PROBES, REST_SPAN};

use crate::prosody::arith::{Arith, DefaultArith};
use crate::prosody::{Event, FrontEnd, ProsodyConfig};

/// An interruption exit point of the segment just entered by a cut, in the first
/// `1 / FRESH_BLEND` of the cut's blend time, is passed by: a decision there cut again from
/// the blend a few frames in (a segment
/// with an exit point 3 frames after its start), adding a second offset, with the velocity the
/// first was closing at, to the first; on beat-scott the hands' largest step at a cut over 30
/// runs was 2.29 cm (the capture's 99th-percentile step: 2.23), and 1.40 cm with a quarter
/// (100 ms of a 400 ms blend). Half a blend also delayed decisions enough to lose coupling
/// with the 067 library (-0.012).
pub const FRESH_BLEND: u32 = 4;

/// A cut decided and waiting for the hands to pause.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Deferred {
    /// The segment to cut to and its entry frame.
    segment: usize,
    frame: usize,
    /// The playing segment's frame where its hands next pause, if one comes within the
    /// window (else: the first beat, calm or last frame that comes).
    at: Option<(usize, usize)>,
}

/// A controller over a blob's tables: what every host tool and board runs (built by
/// [`Controller::from_blob`] or [`Controller::from_blob_in`]; `A`: the front-end's
/// arithmetic, the build's by default).
pub type BlobController<'a, A = DefaultArith> = Controller<'a, Blob<'a>, Blob<'a>, A>;

/// The whole on-device controller over validated tables `T` (policy) and `L` (library), with
/// the front-end arithmetic `A` (the build's by default; `prosody::arith`).
pub struct Controller<
    'a,
    T: PolicyTables + ?Sized,
    L: LibraryFrames + ?Sized,
    A: Arith = DefaultArith,
> {
    tables: &'a T,
    lib: &'a L,
    crf: CrfWeights<'a>,
    gmm: [GmmComponent; MAX_CLUSTERS],
    clusters: usize,
    front_end: FrontEnd<A>,
    normalizer: StepNormalizer,
    belief: Belief,
    uniform: [f32; MAX_STATES],
    player: Player,
    exit: usize,
    pose: [f32; MAX_CHANNELS],
    rate: u64,
    fps_milli: u64,
    samples: u64,
    ticks: u64,
    timing: DecisionTiming,
    variety: Variety,
    history: History,
    /// The user's tone weights (neutral by default).
    style: Style,
    /// The style's share the voice's energy weight acts on while speaking: its neutral
    /// weight and those of the tones that lean energetic ([`crate::follow::energetic_tones`]).
    voice_share: f32,
    /// The label being served, and those waiting behind it.
    labels: Labels,
    /// A label not served within this long is dropped (ms; 0: never).
    label_timeout_ms: u32,
    /// Belief the policy decides with instead of the CRF's (an evaluation's ablation).
    held_belief: Option<[f32; MAX_STATES]>,
    /// Ticks held at the current motion beat, waiting for an onset.
    holding: u64,
    /// Tick at which the last onset was detected (the tick due next when it arrived).
    last_onset: Option<u64>,
    /// The exit the controller is waiting at for an onset: an end exit (running on into the
    /// recorded successor meanwhile) or an interruption exit (playing on in the segment).
    waiting: Option<usize>,
    /// Ticks waited at it.
    waited: u64,
    /// A cut decided and waiting for the hands to pause.
    deferred: Option<Deferred>,
    /// How the character follows the voice.
    follow: VoiceFollow,
    /// How a gesture's size follows the voice (the player's expression stage).
    expression: Expressive,
    /// The voice as followed: silence, level, rest.
    voice: Voice,
    /// The calmest segments (candidates while resting).
    rest: RestSet,
    /// The tick the last rest began.
    rest_since: u32,
    /// The frames of the rest segment entered last that a rest plays to and fro between.
    rest_span: (u16, u16),
    /// Length of a pause step (ms).
    pause_ms: u32,
    /// The segment and frame shown at the last tick.
    last_shown: (usize, usize),
    /// Audio heard before it is played (see [`Lookahead`]).
    ahead: Ahead,
}

impl<'a, T: PolicyTables + ?Sized, L: LibraryFrames + ?Sized, A: Arith> Controller<'a, T, L, A> {
    /// [`new_in`](Controller::new_in) with the front-end arithmetic `A`.
    pub fn new_arith_in<'s>(
        slot: &'s mut Option<Self>,
        config: &ProsodyConfig,
        gmm: &[GmmComponent],
        crf: CrfWeights<'a>,
        tables: &'a T,
        lib: &'a L,
    ) -> Result<&'s mut Self, ControllerError> {
        let me = slot.insert(Self {
            tables,
            lib,
            crf,
            gmm: [GmmComponent::default(); MAX_CLUSTERS],
            clusters: 0,
            front_end: FrontEnd::blank(),
            normalizer: StepNormalizer::new(),
            belief: Belief::new(),
            uniform: [0.0; MAX_STATES],
            player: Player::new(),
            exit: 0,
            pose: [0.0; MAX_CHANNELS],
            rate: 0,
            fps_milli: 0,
            samples: 0,
            ticks: 0,
            timing: DecisionTiming::DEFAULT,
            variety: Variety::NONE,
            history: History::new(),
            style: Style::NEUTRAL,
            voice_share: 1.0,
            labels: Labels::default(),
            label_timeout_ms: 0,
            held_belief: None,
            holding: 0,
            last_onset: None,
            waiting: None,
            waited: 0,
            deferred: None,
            follow: VoiceFollow::NONE,
            expression: Expressive::NONE,
            voice: Voice::new(),
            rest: RestSet::EMPTY,
            rest_since: 0,
            rest_span: (0, u16::MAX),
            pause_ms: config.syllables.pause_frames.saturating_mul(10),
            ahead: Ahead::new(),
            last_shown: (0, 0),
        });
        if let Err(e) = me.front_end.configure(config) {
            *slot = None;
            return Err(ControllerError::FrontEnd(e));
        }
        let s = tables.states();
        let fps = lib.fps();
        if gmm.len() != crf.clusters
            || gmm.len() > MAX_CLUSTERS
            || s != crf.states
            || s == 0
            || tables.exit_count() == 0
            || lib.segment_count() == 0
            || lib.channels() > MAX_CHANNELS
            || !(fps.is_finite() && fps > 0.0 && fps <= 1000.0)
        {
            *slot = None;
            return Err(ControllerError::Dimensions);
        }
        me.gmm[..gmm.len()].copy_from_slice(gmm);
        me.clusters = gmm.len();
        me.uniform[..s].iter_mut().for_each(|v| *v = 1.0 / s as f32);
        me.exit = tables.first_exit(0);
        me.rate = config.sample_rate_hz as u64;
        me.fps_milli = libm::roundf(fps * 1000.0) as u64;
        // Re-borrow through the slot: `me` ends here.
        match slot {
            Some(me) => Ok(me),
            None => Err(ControllerError::Dimensions),
        }
    }

    /// Whether `ticks` ticks last at least `ms` milliseconds.
    fn ticks_reach_ms(&self, ticks: u64, ms: u32) -> bool {
        // ticks / (fps_milli / 1000) * 1000 >= ms
        ticks.saturating_mul(1_000_000) >= (ms as u64).saturating_mul(self.fps_milli)
    }

    /// Samples needed before tick `k` is due.
    fn due(&self, k: u64) -> u64 {
        // ceil(k * rate / fps) with fps in thousandths.
        (k * self.rate * 1000).div_ceil(self.fps_milli.max(1))
    }

    /// Feeds samples; reports frames, steps with beliefs, decisions and poses through `sink`.
    pub fn push(&mut self, samples: &[i16], sink: &mut impl FnMut(ControllerEvent<'_>)) {
        let mut rest = samples;
        let lead = self.ahead.lead_samples;
        while !rest.is_empty() {
            let due = self.due(self.ticks) + lead;
            if self.samples >= due {
                self.tick(sink);
                continue;
            }
            let n = ((due - self.samples) as usize).min(rest.len());
            let (now, later) = rest.split_at(n);
            self.feed(now, sink);
            rest = later;
        }
        if self.samples >= self.due(self.ticks) + lead {
            self.tick(sink);
        }
    }

    /// Plays the ticks still due for the audio heard so far, which look-ahead holds back (at
    /// the end of a known recording, after [`finish`](Self::finish)); without look-ahead
    /// there are none.
    pub fn drain(&mut self, sink: &mut impl FnMut(ControllerEvent<'_>)) {
        while self.samples >= self.due(self.ticks) && self.ticks < u64::MAX {
            self.tick(sink);
        }
    }

    /// Ends the input stream: the front-end reports the frames still in its windows and closes
    /// an open syllable (as [`FrontEnd::finish`] does), each step updating the belief as
    /// usual. No tick is played. Pushing more samples afterwards starts a new front-end stream
    /// (the belief, playback and sample clock go on).
    pub fn finish(&mut self, sink: &mut impl FnMut(ControllerEvent<'_>)) {
        self.front_end_run(None, sink);
    }

    fn feed(&mut self, samples: &[i16], sink: &mut impl FnMut(ControllerEvent<'_>)) {
        self.front_end_run(Some(samples), sink);
        self.samples += samples.len() as u64;
    }

    /// Pushes `samples` through the front-end (or finishes it with `None`), stepping the belief.
    fn front_end_run(
        &mut self,
        samples: Option<&[i16]>,
        sink: &mut impl FnMut(ControllerEvent<'_>),
    ) {
        let (normalizer, belief, gmm, clusters, crf, states) = (
            &mut self.normalizer,
            &mut self.belief,
            &self.gmm,
            self.clusters,
            &self.crf,
            self.tables.states(),
        );
        let (last_onset, now) = (&mut self.last_onset, self.ticks);
        let (voice, follow, pause_ms) = (&mut self.voice, &self.follow, self.pause_ms);
        let (ahead, fps_milli) = (&mut self.ahead, self.fps_milli);
        let mut on_event = |ev| match ev {
            Event::Frame(f) => {
                // Live, the size of the gestures follows the loudness frame by frame (a
                // syllable's own level comes a syllable late); with look-ahead the syllables'
                // levels take effect at their own time.
                if ahead.live() {
                    voice.hear(f.intensity_db, normalizer.reference_db());
                }
                sink(ControllerEvent::Frame(f))
            }
            Event::Onset(frame) => {
                let (sync, hear) = ahead.onset(frame, now, fps_milli);
                if sync {
                    *last_onset = Some(now);
                }
                if hear {
                    voice.onset();
                }
                sink(ControllerEvent::Onset(frame));
            }
            Event::Step(step) => {
                let x = normalizer.push(&step);
                let item = VoiceItem::Step {
                    pause: x.pause,
                    level: x.obs[0],
                };
                if let Some(VoiceItem::Step { pause, level }) =
                    ahead.step(step.end_frame, now, fps_milli, item)
                {
                    voice.step(follow, pause, level, pause_ms);
                }
                let mut m = [0.0f32; MAX_CLUSTERS];
                memberships(&gmm[..clusters], &x, &mut m);
                belief.step(crf, &m);
                sink(ControllerEvent::Step {
                    step,
                    belief: belief.probs(states),
                });
            }
        };
        match samples {
            Some(s) => self.front_end.push(s, &mut on_event),
            None => self.front_end.finish(&mut on_event),
        }
    }

    /// Ticks in `ms` milliseconds (rounded up).
    fn ms_ticks(&self, ms: u32) -> u32 {
        let t = (ms as u64 * self.fps_milli).div_ceil(1_000_000);
        t.min(u32::MAX as u64) as u32
    }

    fn tick(&mut self, sink: &mut impl FnMut(ControllerEvent<'_>)) {
        // What the look-ahead heard for this tick takes effect now.
        while let Some(item) = self.ahead.due_voice(self.ticks) {
            match item {
                VoiceItem::Step { pause, level } => {
                    self.voice.step(&self.follow, pause, level, self.pause_ms)
                }
                VoiceItem::Onset => self.voice.onset(),
            }
        }
        if let Some(t) = self.ahead.due_onset(self.ticks) {
            self.last_onset = Some(t);
        }
        let segment = self.player.segment();
        let t = self.timing;
        let fresh = !t.sync_to_onsets
            || self.labels.waiting().is_some()
            || self.last_onset.is_some_and(|o| {
                !self.ticks_reach_ms(self.ticks.saturating_sub(o), t.onset_window_ms)
            });
        // At a motion beat, hold the frame until an onset (for at most beat_hold_ms), so the
        // hands' pauses fall on syllables.
        let at_beat = t.sync_to_onsets
            && t.beat_hold_ms > 0
            && self.lib.is_beat(segment, self.player.frame());
        let hold = at_beat && !fresh && !self.ticks_reach_ms(self.holding + 1, t.beat_hold_ms);
        self.holding = if hold { self.holding + 1 } else { 0 };
        let rate = self.player.rate();
        let new_rate = if self.voice.resting() {
            crate::follow::rest_rate(self.tables.energy(segment))
        } else {
            self.ahead.stroke_rate(self.lib, &self.player, self.ticks)
        };
        self.player.set_rate(new_rate);
        if self.player.rate() != rate {
            let command = PlayerCommand::Rate(self.player.rate());
            sink(ControllerEvent::Play {
                tick: self.ticks,
                command,
            });
        }
        let gain = self
            .voice
            .gain(&self.expression, self.rest.contains(segment));
        if gain != self.player.gain_aim() {
            self.player.set_gain(gain);
            sink(ControllerEvent::Play {
                tick: self.ticks,
                command: PlayerCommand::Gain(self.player.gain_aim()),
            });
        }
        if hold {
            sink(ControllerEvent::Play {
                tick: self.ticks,
                command: PlayerCommand::Hold,
            });
        }
        let played = self.player.tick_advancing(self.lib, &mut self.pose, !hold);
        // What leaves the controller is within the rig's limits and finite.
        within_limits(self.lib, &mut self.pose);
        let tick = self.ticks;
        self.ticks += 1;
        let last_shown = core::mem::replace(&mut self.last_shown, (segment, played));
        if self.ticks == 1 {
            self.history.write(Visit {
                segment: segment.min(u16::MAX as usize) as u16,
                tick: 0,
            });
        }
        sink(ControllerEvent::Pose {
            tick,
            pose: &self.pose[..self.lib.channels().min(MAX_CHANNELS)],
            segment,
            frame: played,
        });
        let timeout = self.ms_ticks(self.label_timeout_ms) as u64;
        self.labels
            .after_tick(self.tables, (tick, segment, played), timeout, sink);
        if self.follow_voice(segment, tick, sink) {
            return;
        }
        if self.voice.resting() && self.rest.contains(segment) && self.deferred.is_none() {
            if self.labels.waiting().is_some() {
                // A label asked for while the body rests (a button, a chat bot) is answered at
                // once, as the speech's return is: a rest has no exit point it must reach.
                self.decide_now(tick, sink);
            } else {
                self.hold_rest(segment, tick, sink);
            }
            return;
        }
        let t = self.timing;
        if let Some(d) = self.deferred {
            let pause = match d.at {
                Some((s, f)) if s == segment => played >= f,
                // Faster playback may pass a frame by: any pause since the last tick counts.
                _ => {
                    let (s, f) = last_shown;
                    let from = if s == segment && f < played {
                        f + 1
                    } else {
                        played
                    };
                    (from..=played).any(|g| self.hands_pause(segment, g))
                }
            };
            if pause {
                self.deferred = None;
                self.cut(d.segment, d.frame, tick, sink);
            }
            return;
        }
        // A waiting label decides at the next exit point, onset or not; so does every exit
        // point while resting (no onset is coming).
        let fresh = !t.sync_to_onsets
            || self.labels.waiting().is_some()
            || self.voice.resting()
            || self
                .last_onset
                .is_some_and(|o| !self.ticks_reach_ms(tick.saturating_sub(o), t.onset_window_ms));
        if let Some(e) = self.waiting {
            if !self.tables.exit_is_end(e) {
                // Past an interruption frame, armed for an onset: decide on one that comes
                // before the wait runs out or the segment's next exit point is reached;
                // otherwise play on, as if the policy had chosen to continue.
                let next_frame = if e + 1 < self.tables.exit_count() {
                    self.tables.exit_frame(e + 1)
                } else {
                    usize::MAX
                };
                if fresh {
                    self.waiting = None;
                    self.waited = 0;
                    self.decide(e, tick, sink);
                } else if self.ticks_reach_ms(self.waited, t.max_wait_ms)
                    || self.player.segment() != segment
                    || played + 1 >= next_frame
                {
                    self.waiting = None;
                    self.waited = 0;
                    if e + 1 < self.tables.exit_count() {
                        self.exit = e + 1;
                    }
                } else {
                    self.waited += 1;
                }
                return;
            }
            // Running on into the successor while waiting for an onset.
            if fresh
                || self.ticks_reach_ms(self.waited, t.max_wait_ms)
                || self.player.at_end(self.lib)
            {
                self.waiting = None;
                self.waited = 0;
                self.decide(e, tick, sink);
            } else {
                self.waited += 1;
            }
            return;
        }
        let e = self.exit;
        if self.tables.exit_segment(e) != segment || played < self.tables.exit_frame(e) {
            return;
        }
        if !fresh {
            if !self.tables.exit_is_end(e) {
                // No onset now: play on past this interruption frame, armed for an onset
                // within `max_wait_ms` (see above).
                if t.max_wait_ms > 0 {
                    self.waiting = Some(e);
                    self.waited = 1;
                } else if e + 1 < self.tables.exit_count() {
                    self.exit = e + 1;
                }
                return;
            }
            if t.max_wait_ms > 0 && self.lib.continues(segment) {
                // Wait for an onset, the body moving on into the recorded successor.
                self.player.run_on(self.lib);
                self.play(PlayerCommand::RunOn, sink);
                self.waiting = Some(e);
                self.waited = 1;
                return;
            }
        }
        self.decide(e, tick, sink);
    }

    /// Whether frame `f` of segment `c` is a pause of the hands where a deferred cut may
    /// fall: a motion beat, a calm frame or the segment's last frame.
    fn hands_pause(&self, c: usize, f: usize) -> bool {
        self.lib.is_beat(c, f) || self.lib.is_calm(c, f) || f + 1 >= self.lib.segment_len(c)
    }

    /// Where the hands of segment `c`, now past frame `f`, next pause within the deferral
    /// window: its first calm frame there, else its first motion beat, else its last frame
    /// if that comes within the window (`None`: none does). A beat is a local minimum of the
    /// hands' speed, which in a fast gesture can still be fast; a calm frame is slow.
    fn pause_ahead(&self, c: usize, f: usize) -> Option<usize> {
        let len = self.lib.segment_len(c);
        let window = self.ms_ticks(self.timing.defer_cut_ms) as usize;
        let last = f.saturating_add(window).min(len.saturating_sub(1));
        let mut beat = None;
        for g in f + 1..=last {
            let (calm, is_beat) = self.lib.calm_beat(c, g);
            if calm {
                return Some(g);
            }
            if beat.is_none() && is_beat {
                beat = Some(g);
            }
        }
        beat.or((last + 1 >= len && last > f).then_some(last))
    }

    /// Reports a player command given after the pose of the last tick (it precedes the next).
    fn play(&self, command: PlayerCommand, sink: &mut impl FnMut(ControllerEvent<'_>)) {
        sink(ControllerEvent::Play {
            tick: self.ticks,
            command,
        });
    }

    /// Cuts to segment `c` at frame `f` now.
    fn cut(&mut self, c: usize, f: usize, tick: u64, sink: &mut impl FnMut(ControllerEvent<'_>)) {
        let f = if self.voice.resting() && self.rest.contains(c) && f == 0 {
            self.begin_rest(c)
        } else {
            f
        };
        self.player.enter_at(self.lib, c, f);
        let command = PlayerCommand::Enter {
            segment: self.player.segment().min(u16::MAX as usize) as u16,
            frame: self.player.frame().min(u16::MAX as usize) as u16,
        };
        self.play(command, sink);
        // An interruption exit point early in the cut's blend is passed by (`FRESH_BLEND`).
        let fresh = (self.player.blend_ticks() / FRESH_BLEND) as usize;
        self.record_entry(c, tick.min(u32::MAX as u64) as u32, fresh);
    }

    /// Remembers entering `c` at tick `now` and finds its first exit point not yet passed,
    /// nor within `fresh` frames.
    fn record_entry(&mut self, c: usize, now: u32, fresh: usize) {
        self.history.write(Visit {
            segment: c.min(u16::MAX as usize) as u16,
            tick: now,
        });
        let mut x = self.tables.first_exit(c);
        let frame = self.player.frame() + fresh;
        while !self.tables.exit_is_end(x)
            && self.tables.exit_frame(x) < frame
            && x + 1 < self.tables.exit_count()
        {
            x += 1;
        }
        self.exit = x;
    }

    /// Acts on what just changed in the voice (see [`crate::follow`]): when resting begins
    /// (and the playing segment is not one of the calmest) or the speech returns after a rest,
    /// decides at once at the exit point the controller is at or heading for; returns whether
    /// it did.
    fn follow_voice(
        &mut self,
        segment: usize,
        tick: u64,
        sink: &mut impl FnMut(ControllerEvent<'_>),
    ) -> bool {
        let Some(change) = self.voice.take_change() else {
            return false;
        };
        if change == VoiceChange::Rest {
            self.rest_since = tick.min(u32::MAX as u64) as u32;
        }
        if self.labels.waiting().is_some()
            || (change == VoiceChange::Rest && self.rest.contains(segment))
        {
            return false;
        }
        // A cut still waiting for the hands was decided for the speech: decide again.
        self.deferred = None;
        self.decide_now(tick, sink);
        true
    }

    /// Decides at once at the exit point the controller is armed at (waiting for an onset) or
    /// heading for.
    fn decide_now(&mut self, tick: u64, sink: &mut impl FnMut(ControllerEvent<'_>)) {
        let (e, reached) = match self.waiting.take() {
            Some(e) => (e, true),
            None => (self.exit, false),
        };
        self.waited = 0;
        self.decide_with(e, tick, reached, sink);
    }

    /// Decides at exit `e` (reached) and acts on it.
    fn decide(&mut self, e: usize, tick: u64, sink: &mut impl FnMut(ControllerEvent<'_>)) {
        self.decide_with(e, tick, true, sink);
    }

    /// Decides at exit `e` and acts on it; `reached` whether the playback has come to `e`
    /// (choosing to continue at one not yet reached leaves it the next exit point).
    fn decide_with(
        &mut self,
        e: usize,
        tick: u64,
        reached: bool,
        sink: &mut impl FnMut(ControllerEvent<'_>),
    ) {
        let now = tick.min(u32::MAX as u64) as u32;
        let mut penalties = Penalties::new(
            &self.variety.under_style(self.voice_share),
            &self.history,
            now,
            self.ms_ticks(self.variety.recency_ms),
            self.ms_ticks(self.variety.usage_ms),
        );
        // While speaking, a tone the user chose sets the body's energy: the voice's energy
        // weight acts on the neutral share of the style (all of it by default) and on the
        // tones that lean energetic.
        let share = if self.voice.resting() {
            1.0
        } else {
            self.voice_share
        };
        penalties.set_voice(
            share * self.voice.weight(&self.follow),
            self.rest.extras(),
            self.rest.energy(),
            self.voice.resting(),
            self.follow.rest_cost,
        );
        let s = self.tables.states();
        let b = match &self.held_belief {
            Some(h) => &h[..s],
            None => self.belief(),
        };
        let waiting = self.labels.waiting();
        let decision = match waiting {
            Some(w) => select_labelled(self.tables, e, b, &penalties, w as usize),
            None => select_styled(self.tables, e, b, &penalties, &self.style),
        };
        match decision.choice {
            Choice::Continue => {
                if reached && e + 1 < self.tables.exit_count() {
                    self.exit = e + 1;
                }
            }
            Choice::Enter(c) => {
                // The player ran on into the recorded successor while waiting: choosing it
                // goes on without a cut; anything else (or no run-on) is a cut.
                let ran_on = self.player.segment() != self.tables.exit_segment(e);
                let seamless = ran_on && c == self.player.segment() && decision.entry_frame == 0;
                if let Some(w) = waiting {
                    if self.tables.label_of(c) == w + 1 {
                        if let Some(stroke) = self.tables.stroke_of(c) {
                            self.labels.serve(c, stroke);
                            sink(ControllerEvent::Label {
                                tick,
                                label: w as usize,
                                outcome: LabelOutcome::Entered {
                                    segment: c,
                                    frame: decision.entry_frame,
                                },
                            });
                        }
                    }
                }
                // The frame just shown (the player has moved past it), or the last frame once
                // the player stands at it (having shown it or the one before): a pause.
                let shown = if self.player.at_end(self.lib) {
                    self.player.frame()
                } else {
                    self.player.frame().saturating_sub(1)
                };
                let defer = !seamless
                    && waiting.is_none()
                    && self.timing.defer_cut_ms > 0
                    && !self.hands_pause(self.player.segment(), shown);
                if defer {
                    let playing = self.player.segment();
                    self.deferred = Some(Deferred {
                        segment: c,
                        frame: decision.entry_frame,
                        at: self.pause_ahead(playing, shown).map(|f| (playing, f)),
                    });
                } else if seamless {
                    self.record_entry(c, now, 0);
                } else {
                    self.cut(c, decision.entry_frame, tick, sink);
                }
            }
        }
        sink(ControllerEvent::Decision { tick, decision });
    }
}
