//! Known audio: the controller hears the speech `ms` milliseconds before it is played
//! ([`Lookahead`]; docs/method.md "Known audio").
//!
//! A robot that speaks with text-to-speech, a show that plays a recording, an animator with a
//! recorded line: the audio exists before anyone hears it. Fed `L` ms early (the board delays
//! its own playback by `L`, or the host feeds a file ahead), the controller plays each tick
//! `L` ms of samples after the audio it has heard (tick `k` is due once `due(k) + L` samples
//! have arrived), so what the front-end reports about the played moment comes early, not
//! about 0.09 s late. Three things use it, each at the speech's own time rather than when the
//! front-end reported it:
//!
//! - **Onsets** count for the decisions ([`crate::policy::DecisionTiming`]) from
//!   `decision_lead_ms` before the tick their syllable starts, so new gestures start with the
//!   syllables rather than a detection delay after them. A little before: a cut's blend and
//!   the new segment's first motion bring the hands' speed to a peak about 0.15-0.2 s after
//!   the cut, so a decision on the syllable itself put that peak between two syllables; a
//!   speaker's preparation, too, begins before the syllable its stroke meets.
//! - **The voice** ([`crate::follow`]: pause steps counting towards rest, the speech's return)
//!   acts `voice_lead_ms` before the speech does: the hands settle as the pause begins and
//!   prepare as a speaker's do, just before the first syllable.
//! - **Strokes land on syllables.** When the playing segment's next stroke (`library.peaks`)
//!   lies within the look-ahead, the syllable onset nearest to where it would fall (within
//!   [`NEAR_SHIFT_MS`]; within `stroke_shift_ms` for a stroke that waits, below) becomes its
//!   target, and the preparation is played at the rate that brings the stroke there, the
//!   stroke itself at the library's pace: the last [`STROKE_PACE_MS`] before the stroke's
//!   frame take their own time and the frames before them take the rest,
//!   `rate = (ahead - k) / (ticks - k)` with `ahead` the frames to the
//!   stroke, `ticks` the ticks to the target and `k` the stroke's own frames, recomputed
//!   every tick, within [`WARP_MIN`]..=[`WARP_MAX`]. A speaker does the same: the
//!   preparation stretches or shortens, or a pre-stroke hold waits, so the stroke meets the
//!   stressed syllable (McNeill's phonological synchrony rule), and the stroke keeps its
//!   speed.
//! - **A stroke waits for its syllable.** Onsets are known only as far ahead as the audio
//!   is heard (the look-ahead less the front-end's report delay). When the playing segment's
//!   next stroke would fall inside that known speech with no onset in reach, it would land in
//!   a gap of the speech; the preparation slows instead (to no less than [`WARP_MIN`]) to
//!   keep the stroke at the edge of what is heard, until a syllable comes in reach (then it is
//!   aimed at it), and at most until the tick at which all of the speech within the shift
//!   after the stroke's own time has been heard (with a look-ahead longer than the shift that
//!   tick comes before the stroke's own, and nothing waits). Without the wait, a stroke in a
//!   gap between two phrases played in the gap: on the 001 take with the 067 library at
//!   500 ms, 7 of 104 strokes, 0.2-0.6 s from any syllable.
//!
//! The belief steps as soon as a step is reported (the choice of segment uses what is known of
//! the coming speech). With `ms = 0` nothing is delayed and everything happens exactly as in
//! live mode. Memory is fixed: two small queues ([`PENDING`], [`ONSETS`]); when one is full the
//! oldest item takes effect at once, so nothing is lost.

use heapless::Deque;

use crate::player::{LibraryFrames, Player, MAX_RATE, MIN_RATE};

/// The longest look-ahead (ms): a second of speech.
pub const MAX_LOOKAHEAD_MS: u32 = 1000;

/// Voice effects (pause steps, onsets) waiting for their time.
pub const PENDING: usize = 24;

/// Syllable onsets known ahead of the played time.
pub const ONSETS: usize = 16;

/// The slowest pace of a stroke's preparation: a stroke is moved to an onset only if a steady
/// rate within [`WARP_MIN`]..=[`WARP_MAX`], before the stroke's own [`STROKE_PACE_MS`],
/// brings it there. The preparation is where a speaker's timing gives: it stretches, down to
/// a pre-stroke hold, so that the stroke meets its syllable (McNeill). On the 001 take with
/// the 067 library at 500 ms look-ahead (30 runs) the beat lift was +0.099 with 0.6-1.5 and
/// +0.134 with 0.3-1.5, against the capture's +0.128. It costs coupling on some speech (the
/// 9-joint tuning span: +0.614 to +0.534, the capture's +0.545; docs/method.md). A
/// preparation that waits for a syllable not yet heard slows as deep: on speech not used
/// before (the 001 take's first minute with the 067 library, 067's two halves with the 9-joint
/// library) a floor of 0.5 for the wait left the lift at +0.147 against the capture's +0.166
/// on the first of them, where this floor gives +0.164 (docs/method.md).
pub const WARP_MIN: f32 = 0.3;
/// The fastest pace of a stroke's preparation. A preparation hurried to 2x lifted the beat
/// lift further (+0.140 on that span) but moved the hands faster than the capture ever did:
/// on 067's last ten seconds the 99th percentile of the hands' step per frame rose from 8.2
/// to 10.9 against the capture's 7.6; at 1.5 it is 7.8.
pub const WARP_MAX: f32 = 1.5;

/// How far (ms) from where it would fall a stroke is moved to a syllable it can reach; a
/// stroke that waits for a syllable not yet heard takes one up to
/// [`Lookahead::stroke_shift_ms`] after it.
pub const NEAR_SHIFT_MS: u32 = 300;

/// How long before its frame a stroke plays at the library's pace (ms): the stroke's rise
/// keeps its own speed, and only the preparation before it is stretched or hurried.
pub const STROKE_PACE_MS: u32 = 200;

/// How fast the stroke's playback rate changes (rate units per second): an abrupt change of
/// pace is a kick in the hands' acceleration; at this slew the preparation's pace is back at
/// the library's within a few ticks of the stroke's own [`STROKE_PACE_MS`].
pub const RATE_SLEW_PER_S: f32 = 6.0;

/// How the controller uses audio it hears before it is played.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lookahead {
    /// How long before it is played the audio arrives (ms, 0..=[`MAX_LOOKAHEAD_MS`]; 0: live).
    pub ms: u32,
    /// How long before the speech the voice acts (ms; at most `ms`).
    pub voice_lead_ms: u32,
    /// How far a stroke may be moved to meet a syllable onset (ms; 0: strokes are not moved).
    pub stroke_shift_ms: u32,
    /// How long before its syllable an onset counts for decisions (ms; at most `ms`).
    pub decision_lead_ms: u32,
}

impl Lookahead {
    /// Live: the audio is played as it is heard.
    pub const LIVE: Self = Self {
        ms: 0,
        voice_lead_ms: 0,
        stroke_shift_ms: 0,
        decision_lead_ms: 0,
    };

    /// `ms` of look-ahead (clamped to [`MAX_LOOKAHEAD_MS`]) with the default voice lead
    /// (250 ms), stroke shift (600 ms: how far after its own time a stroke that would fall in
    /// a gap of the speech, with no syllable heard near it, may wait for the next one, a
    /// pre-stroke hold; any other stroke is moved at most [`NEAR_SHIFT_MS`], 300 ms, the gap
    /// between two syllables at 3-4 per second, so nearly every stroke finds one: 200 ms left
    /// more strokes off the syllables on tuning speech) and decision lead (100 ms: on tuning
    /// speech the hands' speed followed the voice best there, among 0, 50, 100, 150 and
    /// 200 ms; docs/method.md).
    pub const fn ms(ms: u32) -> Self {
        let ms = if ms > MAX_LOOKAHEAD_MS {
            MAX_LOOKAHEAD_MS
        } else {
            ms
        };
        Self {
            ms,
            voice_lead_ms: 250,
            stroke_shift_ms: 600,
            decision_lead_ms: 100,
        }
    }
}

impl Default for Lookahead {
    fn default() -> Self {
        Self::LIVE
    }
}

/// A voice effect waiting for its tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum VoiceItem {
    /// A step: pause or syllable, and the syllable's level.
    Step { pause: bool, level: f32 },
    /// A syllable onset.
    Onset,
}

/// A stroke aimed at an onset.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Aim {
    segment: usize,
    stroke: usize,
    /// Tick at which it falls at the library's pace, seen when it came in reach.
    natural: f32,
    /// Tick the stroke is to be shown at (`None`: no onset in reach yet).
    at: Option<u64>,
    /// Whether its preparation has waited for a syllable not yet heard.
    waited: bool,
}

/// The look-ahead's state (see the module docs).
#[derive(Clone, Debug)]
pub(super) struct Ahead {
    settings: Lookahead,
    /// Samples of look-ahead.
    pub(super) lead_samples: u64,
    /// Ticks the voice acts early, ticks a stroke may move, ticks ahead a stroke is looked for.
    voice_lead: u64,
    shift: u64,
    horizon: usize,
    /// Frames ahead a stroke is looked for: the look-ahead and the shift.
    reach: usize,
    /// Ticks within which any stroke is moved to a syllable ([`NEAR_SHIFT_MS`]).
    near: f32,
    /// Frames before a stroke played at the library's pace ([`STROKE_PACE_MS`]).
    stroke_pace: f32,
    pending: Deque<(u64, VoiceItem), PENDING>,
    onsets: Deque<u64, ONSETS>,
    aim: Option<Aim>,
    /// The rate given last (slewed towards the next), and the largest change per tick.
    rate: f32,
    slew: f32,
    /// Ticks before its syllable an onset counts for decisions.
    decision_lead: u64,
}

/// The tick at which 10 ms frame `frame` starts, at `fps_milli` thousandths of a frame per
/// second (rounded to the nearest tick).
fn frame_tick(frame: u32, fps_milli: u64) -> u64 {
    (frame as u64 * fps_milli + 50_000) / 100_000
}

/// Ticks in `ms` (rounded down).
fn ms_ticks(ms: u32, fps_milli: u64) -> u64 {
    ms as u64 * fps_milli / 1_000_000
}

impl Ahead {
    pub(super) const fn new() -> Self {
        Self {
            settings: Lookahead::LIVE,
            lead_samples: 0,
            voice_lead: 0,
            shift: 0,
            horizon: 0,
            reach: 0,
            near: 0.0,
            stroke_pace: 0.0,
            pending: Deque::new(),
            onsets: Deque::new(),
            aim: None,
            rate: 1.0,
            slew: 0.0,
            decision_lead: 0,
        }
    }

    pub(super) fn settings(&self) -> Lookahead {
        self.settings
    }

    /// Sets the look-ahead for `rate` Hz and `fps_milli`; what was pending stays pending.
    pub(super) fn set(&mut self, l: Lookahead, rate: u64, fps_milli: u64) {
        let ms = l.ms.min(MAX_LOOKAHEAD_MS);
        let l = Lookahead {
            ms,
            voice_lead_ms: l.voice_lead_ms.min(ms),
            stroke_shift_ms: l.stroke_shift_ms.min(MAX_LOOKAHEAD_MS),
            decision_lead_ms: l.decision_lead_ms.min(ms),
        };
        self.settings = l;
        self.lead_samples = l.ms as u64 * rate / 1000;
        self.voice_lead = ms_ticks(l.voice_lead_ms, fps_milli);
        self.decision_lead = ms_ticks(l.decision_lead_ms, fps_milli);
        self.shift = if l.ms > 0 {
            ms_ticks(l.stroke_shift_ms, fps_milli)
        } else {
            0
        };
        // A stroke is looked for as far ahead as onsets are known: the look-ahead less the
        // front-end's report delay (about 0.1 s).
        self.horizon = ms_ticks(l.ms.saturating_sub(100), fps_milli) as usize;
        self.reach = ms_ticks(l.ms.saturating_add(l.stroke_shift_ms), fps_milli) as usize;
        self.stroke_pace = ms_ticks(STROKE_PACE_MS, fps_milli) as f32;
        self.near = ms_ticks(NEAR_SHIFT_MS, fps_milli) as f32;
        self.aim = None;
        self.rate = 1.0;
        self.slew = RATE_SLEW_PER_S * 1000.0 / fps_milli.max(1) as f32;
    }

    /// Whether the audio is played as it is heard (no look-ahead).
    pub(super) fn live(&self) -> bool {
        self.lead_samples == 0
    }

    /// An onset at 10 ms frame `frame` reported while tick `now` is due next: returns whether
    /// it counts for decisions now and whether the voice hears it now (else it is queued).
    pub(super) fn onset(&mut self, frame: u32, now: u64, fps_milli: u64) -> (bool, bool) {
        if self.lead_samples == 0 {
            return (true, true);
        }
        let t = frame_tick(frame, fps_milli);
        let sync_now = t <= now || {
            if self.onsets.is_full() {
                self.onsets.pop_front();
            }
            self.onsets.push_back(t).is_err()
        };
        let voice_now = !self.queue(t.saturating_sub(self.voice_lead), now, VoiceItem::Onset);
        (sync_now, voice_now)
    }

    /// A step ending at 10 ms frame `end` reported while tick `now` is due next: returns it if
    /// the voice takes it now, else queues it.
    pub(super) fn step(
        &mut self,
        end: u32,
        now: u64,
        fps_milli: u64,
        item: VoiceItem,
    ) -> Option<VoiceItem> {
        if self.lead_samples == 0 {
            return Some(item);
        }
        let at = frame_tick(end, fps_milli).saturating_sub(self.voice_lead);
        (!self.queue(at, now, item)).then_some(item)
    }

    /// Queues `item` for tick `at` if that is after `now`; returns whether it was queued (with
    /// the queue full it is not: the caller takes it now).
    fn queue(&mut self, at: u64, now: u64, item: VoiceItem) -> bool {
        if at <= now || self.pending.is_full() {
            return false;
        }
        self.pending.push_back((at, item)).is_ok()
    }

    /// The next voice effect due by tick `now`, oldest first.
    pub(super) fn due_voice(&mut self, now: u64) -> Option<VoiceItem> {
        match self.pending.front() {
            Some(&(at, _)) if at <= now => self.pending.pop_front().map(|(_, v)| v),
            _ => None,
        }
    }

    /// The latest onset that counts for decisions by tick `now`: due by `now` (removing those)
    /// or the next within the decision lead (which stays queued: a stroke may still aim at it).
    pub(super) fn due_onset(&mut self, now: u64) -> Option<u64> {
        let mut last = None;
        while let Some(&t) = self.onsets.front() {
            if t > now {
                if t <= now + self.decision_lead {
                    last = Some(t);
                }
                break;
            }
            last = Some(t);
            self.onsets.pop_front();
        }
        last
    }

    /// The playback rate that lands the playing segment's next stroke on a syllable onset
    /// (1 when there is none in reach, or without look-ahead).
    pub(super) fn stroke_rate<L: LibraryFrames + ?Sized>(
        &mut self,
        lib: &L,
        player: &Player,
        now: u64,
    ) -> f32 {
        if self.shift == 0 || self.horizon == 0 || player.backward() {
            self.aim = None;
            self.rate = 1.0;
            return 1.0;
        }
        let want = self.wanted_rate(lib, player, now);
        // (max and min, not clamp: clamp with bounds not known at build time links float
        // formatting for its panic message, kilobytes on a board.)
        self.rate = want.max(self.rate - self.slew).min(self.rate + self.slew);
        self.rate
    }

    /// The rate that lands the aimed stroke on its onset, before the slew.
    fn wanted_rate<L: LibraryFrames + ?Sized>(
        &mut self,
        lib: &L,
        player: &Player,
        now: u64,
    ) -> f32 {
        let seg = player.segment();
        let pos = player.position();
        let mut aim = match self.aim {
            Some(a) if a.segment == seg && a.stroke as f32 > pos => a,
            _ => match self.next_stroke(lib, seg, player.frame(), pos, now) {
                Some(a) => a,
                None => {
                    self.aim = None;
                    return 1.0;
                }
            },
        };
        if aim.at.is_some_and(|at| at <= now) {
            // Its tick has come before the stroke (the slew or the player's bounds held the
            // pace back): the aim ends. No pace is held past a stroke either: the next
            // stroke's approach begins at once (docs/method.md).
            self.aim = None;
            return self.rate;
        }
        // The onset nearest to where the stroke first fell, among those known by now (more
        // become known as it comes closer) and reachable at a steady rate within the bounds.
        let ahead = aim.stroke as f32 - pos;
        let mut best: Option<(u64, f32)> = None;
        for &t in self.onsets.iter() {
            if t <= now {
                continue;
            }
            let d = (t as f32 - aim.natural).abs();
            let rate = self.approach_rate(ahead, (t - now) as f32);
            // Farther than the near shift only for a stroke that waits for its syllable.
            let within = if aim.waited {
                self.shift as f32
            } else {
                self.near
            };
            if d <= within
                && (WARP_MIN..=WARP_MAX).contains(&rate)
                && best.is_none_or(|(_, bd)| d < bd)
            {
                best = Some((t, d));
            }
        }
        // Once aimed, the target holds unless a nearer onset is reachable.
        aim.at = match (aim.at, best) {
            (Some(at), Some((_, d))) if (at as f32 - aim.natural).abs() <= d => Some(at),
            (Some(at), None) => Some(at),
            (_, b) => b.map(|(t, _)| t),
        };
        self.aim = Some(aim);
        // Closed loop: the rate that brings the stroke to its tick from where playback stands.
        match aim.at {
            Some(at) => self
                .approach_rate(ahead, (at - now) as f32)
                .clamp(MIN_RATE, MAX_RATE),
            None => {
                let rate = self.wait_rate(&aim, ahead, now);
                if rate < 1.0 {
                    aim.waited = true;
                    self.aim = Some(aim);
                }
                rate
            }
        }
    }

    /// No onset in reach of the aimed stroke yet. Where the stroke would fall inside the
    /// speech already heard (before the horizon) with no syllable near it, the preparation
    /// waits at the edge of what is heard (a pre-stroke hold) for a syllable to come in reach,
    /// but no longer than until all of the speech within the shift after the stroke's own time
    /// has been heard: with a look-ahead longer than the shift that is before the stroke is
    /// due, and nothing waits.
    fn wait_rate(&self, aim: &Aim, ahead: f32, now: u64) -> f32 {
        let k = self.stroke_pace;
        let horizon = self.horizon as f32;
        // Ticks until the last onset that could still be aimed at has been heard.
        let all_heard = aim.natural + self.shift as f32 - horizon - now as f32;
        let ticks = horizon.min(all_heard);
        if ahead > k && ticks > ahead {
            self.approach_rate(ahead, ticks).max(WARP_MIN)
        } else {
            1.0
        }
    }

    /// The pace that shows a stroke `ahead` frames on in `ticks` ticks, its last
    /// [`STROKE_PACE_MS`] at the library's pace: `(ahead - k) / (ticks - k)`, or
    /// `ahead / ticks` once the stroke is nearer than that (or due sooner).
    fn approach_rate(&self, ahead: f32, ticks: f32) -> f32 {
        let k = self.stroke_pace;
        if ahead > k && ticks > k {
            (ahead - k) / (ticks - k)
        } else {
            ahead / ticks
        }
    }

    /// The next stroke of segment `seg` after position `pos` (frame `frame` next) that comes
    /// within the look-ahead and the shift, not yet aimed.
    fn next_stroke<L: LibraryFrames + ?Sized>(
        &self,
        lib: &L,
        seg: usize,
        frame: usize,
        pos: f32,
        now: u64,
    ) -> Option<Aim> {
        let len = lib.segment_len(seg);
        let last = frame.saturating_add(self.reach).min(len);
        let stroke = (frame..last).find(|&f| f as f32 > pos && lib.is_peak(seg, f))?;
        Some(Aim {
            segment: seg,
            stroke,
            natural: now as f32 + (stroke as f32 - pos),
            at: None,
            waited: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One segment of 100 frames at 30 fps whose strokes are the frames listed.
    struct Strokes(&'static [usize]);
    impl LibraryFrames for Strokes {
        fn channels(&self) -> usize {
            1
        }
        fn fps(&self) -> f32 {
            30.0
        }
        fn segment_count(&self) -> usize {
            1
        }
        fn segment_len(&self, _: usize) -> usize {
            100
        }
        fn value(&self, _: usize, f: usize, _: usize) -> f32 {
            f as f32
        }
        fn is_peak(&self, _: usize, f: usize) -> bool {
            self.0.contains(&f)
        }
    }

    /// The stroke at frame 40.
    const STROKE: Strokes = Strokes(&[40]);
    /// Strokes at frames 40 and 48 (0.27 s apart).
    const TWO_STROKES: Strokes = Strokes(&[40, 48]);

    /// Plays [`STROKE`] from tick 0 with `ahead` steering the rate, calling `hear` before each
    /// tick (to feed onsets as they are heard): the rates given up to the tick at which the
    /// stroke frame is first reached (inclusive), and that tick.
    fn play_stroke(
        ahead: &mut Ahead,
        mut hear: impl FnMut(&mut Ahead, u64),
    ) -> (heapless::Vec<f32, 100>, u64) {
        let mut player = Player::new();
        let mut out = [0.0; crate::player::MAX_CHANNELS];
        let mut rates = heapless::Vec::new();
        for now in 0..100u64 {
            hear(ahead, now);
            let r = ahead.stroke_rate(&STROKE, &player, now);
            let _ = rates.push(r);
            player.set_rate(r);
            player.tick(&STROKE, &mut out);
            if out[0] >= 40.0 - 1e-3 {
                return (rates, now);
            }
        }
        (rates, u64::MAX)
    }

    /// The tick at which [`STROKE`]'s frame is first reached ([`play_stroke`], onsets fed
    /// beforehand).
    fn stroke_tick(ahead: &mut Ahead) -> u64 {
        play_stroke(ahead, |_, _| {}).1
    }

    #[test]
    fn a_stroke_lands_on_the_onset_in_reach_and_live_mode_leaves_it_alone() {
        const FPS_MILLI: u64 = 30_000;
        // Live: onsets count at once and the stroke plays at its own time, tick 40.
        let mut live = Ahead::new();
        live.set(Lookahead::LIVE, 16_000, FPS_MILLI);
        assert_eq!(live.onset(153, 0, FPS_MILLI), (true, true));
        assert_eq!(stroke_tick(&mut live), 40);
        // A second of look-ahead: an onset at 1.53 s (tick 46), 200 ms after where the
        // stroke would fall, is known from the start; the stroke lands on it.
        let mut ahead = Ahead::new();
        ahead.set(Lookahead::ms(1000), 16_000, FPS_MILLI);
        assert_eq!(ahead.onset(153, 0, FPS_MILLI), (false, false));
        let t = stroke_tick(&mut ahead);
        assert!(t.abs_diff(46) <= 1, "{t}");
        // The onset counts for decisions from 100 ms (3 ticks) before its own tick and stays
        // queued for the strokes until then; the voice hears it 250 ms before.
        assert_eq!(ahead.due_onset(42), None);
        assert_eq!(ahead.due_onset(43), Some(46));
        assert_eq!(ahead.onsets.len(), 1);
        assert_eq!(ahead.due_onset(46), Some(46));
        assert!(ahead.onsets.is_empty());
        assert_eq!(ahead.due_onset(47), None);
        let mut early = Ahead::new();
        early.set(Lookahead::ms(1000), 16_000, FPS_MILLI);
        early.onset(153, 0, FPS_MILLI);
        assert_eq!(early.due_voice(38), None);
        assert_eq!(early.due_voice(39), Some(VoiceItem::Onset));
        // An onset further than the shift from the stroke leaves it where it is: with a
        // second of look-ahead all of the speech within the shift is heard before the stroke
        // is due, and nothing waits.
        let mut far = Ahead::new();
        far.set(Lookahead::ms(1000), 16_000, FPS_MILLI);
        far.onset(203, 0, FPS_MILLI); // tick 61: 700 ms late
        assert_eq!(stroke_tick(&mut far), 40);
    }

    #[test]
    fn the_next_stroke_is_aimed_as_soon_as_one_is_shown() {
        const FPS_MILLI: u64 = 30_000;
        let mut ahead = Ahead::new();
        ahead.set(Lookahead::ms(1000), 16_000, FPS_MILLI);
        // Onsets at ticks 40 (the first stroke's own time) and 51 (three ticks after the
        // second stroke's): the second is reached only by slowing at once to about 0.7x.
        ahead.onset(133, 0, FPS_MILLI);
        ahead.onset(170, 0, FPS_MILLI);
        let mut player = Player::new();
        let mut out = [0.0; crate::player::MAX_CHANNELS];
        let (mut first, mut second) = (None, None);
        for now in 0..100u64 {
            let r = ahead.stroke_rate(&TWO_STROKES, &player, now);
            player.set_rate(r);
            player.tick(&TWO_STROKES, &mut out);
            if first.is_none() && out[0] >= 40.0 - 1e-3 {
                first = Some(now);
            }
            if second.is_none() && out[0] >= 48.0 - 1e-3 {
                second = Some(now);
            }
        }
        assert_eq!(first, Some(40));
        // Holding the pace past the first stroke for 150 ms left the second out of reach
        // (tick 48).
        let second = second.unwrap_or(u64::MAX);
        assert!(second.abs_diff(51) <= 1, "{second}");
    }

    /// The rates `ahead` gives while [`STROKE`] plays ([`play_stroke`], onsets fed
    /// beforehand), and the tick its frame is reached.
    fn stroke_rates(ahead: &mut Ahead) -> (heapless::Vec<f32, 100>, u64) {
        play_stroke(ahead, |_, _| {})
    }

    #[test]
    fn the_preparation_waits_or_hurries_and_the_stroke_keeps_its_pace() {
        const FPS_MILLI: u64 = 30_000;
        // The stroke's own 200 ms are 6 ticks at 30 fps.
        let k = ms_ticks(STROKE_PACE_MS, FPS_MILLI) as usize;
        assert_eq!(k, 6);
        for (onset_frame, tick) in [(160u32, 48u64), (117, 35)] {
            // An onset 8 ticks after the stroke's own time (tick 48, 267 ms) or 5 before
            // (tick 35): the preparation plays at about 34/42 = 0.81x or 34/29 = 1.17x once
            // the onset is known, and the stroke's last six frames at the library's pace (one
            // steady pace would play them at 40/48 = 0.83x or 40/35 = 1.14x).
            let mut ahead = Ahead::new();
            ahead.set(Lookahead::ms(1000), 16_000, FPS_MILLI);
            ahead.onset(onset_frame, 0, FPS_MILLI);
            let (rates, t) = stroke_rates(&mut ahead);
            assert!(t.abs_diff(tick) <= 1, "stroke at {t}, onset at {tick}");
            let stroke = &rates[rates.len() - k..];
            assert!(
                stroke.iter().all(|r| (r - 1.0).abs() <= 0.05),
                "the stroke's own frames at {stroke:?}"
            );
            let early = rates[5];
            let want = if tick > 40 { 34.0 / 42.0 } else { 34.0 / 29.0 };
            assert!(
                (early - want).abs() < 0.05,
                "preparation at {early}, not {want}"
            );
        }
    }

    /// Plays [`STROKE`] from tick 0 at 500 ms of look-ahead with one onset at tick `onset`,
    /// heard (reported) as the audio arrives, 400 ms (12 ticks) before it is played: the
    /// tick at which the stroke frame is first reached and the rates given until then.
    fn heard_late(onset: Option<u64>) -> (u64, heapless::Vec<f32, 100>) {
        const FPS_MILLI: u64 = 30_000;
        let mut ahead = Ahead::new();
        ahead.set(Lookahead::ms(500), 16_000, FPS_MILLI);
        assert_eq!(ahead.horizon, 12);
        let (rates, t) = play_stroke(&mut ahead, |ahead, now| {
            if let Some(t) = onset.filter(|&t| now + 12 == t) {
                // The 10 ms frame that starts at tick t.
                ahead.onset((t * 100_000 / FPS_MILLI) as u32, now, FPS_MILLI);
            }
        });
        (t, rates)
    }

    #[test]
    fn a_stroke_in_a_gap_of_the_speech_waits_for_the_next_syllable() {
        // No syllable near the stroke (tick 40) in what is heard: the preparation slows at the
        // edge of what is heard (12 ticks ahead), to no less than WARP_MIN, and the stroke
        // comes no later than tick 46, when the speech up to the shift (600 ms, 18 ticks)
        // after its own time has been heard.
        let (t, rates) = heard_late(None);
        assert!((43..=47).contains(&t), "stroke at {t}");
        assert!(rates.iter().all(|&r| r >= WARP_MIN - 1e-3), "{rates:?}");
        assert!(rates.iter().any(|&r| r < 0.6), "no wait: {rates:?}");
        // A syllable at tick 52 is heard only at tick 40, when the stroke would have been
        // shown at the library's pace (where it stayed before the wait): the waiting stroke
        // is still to come then, takes it and lands on it. It is 400 ms after the stroke's
        // own time, beyond the 300 ms a stroke that does not wait is moved: the preparation
        // that waited slows further, below 0.6x, to meet it.
        let (t, rates) = heard_late(Some(52));
        assert!(t.abs_diff(52) <= 1, "stroke at {t}");
        assert!(rates.iter().any(|&r| r < 0.6), "{rates:?}");
        // One heard too late even for the wait (tick 56, heard at 44) leaves the stroke
        // where the wait brought it.
        let (t, _) = heard_late(Some(56));
        assert!((42..=47).contains(&t), "stroke at {t}");
    }
}
