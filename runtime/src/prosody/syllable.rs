//! Syllables from the intensity contour, and pause steps during silence.
//!
//! As in the paper (section 5.2), syllable boundaries are intensity troughs separated by peaks.
//! A trough only counts when the contour rises at least `margin_db` above it afterwards, and a
//! syllable only ends at a trough when its peak rose at least `margin_db` above the trough it
//! started at: a peak must stand out from the troughs on both sides. This is a streaming
//! hysteresis detector, so a syllable is reported as soon as the rise after its closing trough
//! confirms it, with no look-ahead beyond that.
//!
//! Frames below a silence threshold are not speech: they end the current syllable, and every
//! `pause_frames` of continuous silence emit a [`StepKind::Pause`] step so that the controller
//! keeps deciding (the character settles) during long pauses. The threshold is
//! `max(floor_db, peak - range_db)`, where `peak` is a running peak of the intensity that
//! starts at `initial_peak_db` and decays slowly (1 dB per second), so it adapts to the speaker
//! and microphone level within a few syllables.
//!
//! **Long sounds.** A syllable that reaches [`MAX_STEP_FRAMES`] (1 s) without a trough is closed
//! there and a new one starts at once: stationary loud noise (a fan, music, a held vowel) then
//! gives a step a second instead of one step when it stops, so the belief keeps updating and
//! decisions keep coming. Speech syllables are far shorter, so speech is unaffected.
//!
//! Per step: first frame, end frame (exclusive), mean F0 over its voiced frames (or unvoiced when
//! none), mean intensity. Invariants: O(1) memory and time per frame, no allocation, no panics,
//! all outputs finite.

/// Longest step (frames of 10 ms): a syllable this long is closed and the next one starts.
pub const MAX_STEP_FRAMES: u32 = 100;

/// Tunables of the syllable detector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SyllableParams {
    /// A peak must rise this much (dB) above the troughs on both sides.
    pub margin_db: f32,
    /// Frames more than this far (dB) below the running peak are silence.
    pub range_db: f32,
    /// Frames below this level (dB) are always silence.
    pub floor_db: f32,
    /// Starting value of the running peak (dB).
    pub initial_peak_db: f32,
    /// Shortest syllable in frames; shorter ones are merged into the next.
    pub min_frames: u32,
    /// Length of a pause step in frames.
    pub pause_frames: u32,
}

impl SyllableParams {
    /// Defaults tuned on read and conversational English (see the evaluation report).
    pub const DEFAULT: Self = Self {
        margin_db: 2.0,
        range_db: 25.0,
        floor_db: 25.0,
        initial_peak_db: 70.0,
        min_frames: 6,
        pause_frames: 25,
    };
}

impl Default for SyllableParams {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What a step is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepKind {
    /// A syllable: intensity trough to trough (or to silence).
    Syllable,
    /// A stretch of silence (`pause_frames` long).
    Pause,
}

/// One time step of the controller: a syllable or a pause step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// Syllable or pause.
    pub kind: StepKind,
    /// First frame (frame `k` is centred at `k * 10 ms`).
    pub start_frame: u32,
    /// End frame, exclusive.
    pub end_frame: u32,
    /// Mean F0 over voiced frames (Hz), or `None` when no frame was voiced.
    pub f0_hz: Option<f32>,
    /// Mean intensity (dB).
    pub intensity_db: f32,
}

impl Step {
    /// Start time in seconds.
    pub fn start_s(&self) -> f64 {
        self.start_frame as f64 * super::frame::HOP_S
    }
    /// End time in seconds.
    pub fn end_s(&self) -> f64 {
        self.end_frame as f64 * super::frame::HOP_S
    }
    /// Length in seconds.
    pub fn length_s(&self) -> f32 {
        (self.end_frame.saturating_sub(self.start_frame)) as f32 * super::frame::HOP_S as f32
    }
}

/// Running means over a run of frames.
#[derive(Clone, Copy, Debug, Default)]
struct Acc {
    frames: u32,
    db_sum: f32,
    voiced: u32,
    f0_sum: f32,
}

impl Acc {
    fn add(&mut self, f0: Option<f32>, db: f32) {
        self.frames += 1;
        self.db_sum += db;
        if let Some(f) = f0 {
            self.voiced += 1;
            self.f0_sum += f;
        }
    }
    fn merge(&mut self, o: &Acc) {
        self.frames += o.frames;
        self.db_sum += o.db_sum;
        self.voiced += o.voiced;
        self.f0_sum += o.f0_sum;
    }
    fn step(&self, kind: StepKind, start: u32, end: u32) -> Step {
        Step {
            kind,
            start_frame: start,
            end_frame: end,
            f0_hz: if self.voiced > 0 {
                Some(self.f0_sum / self.voiced as f32)
            } else {
                None
            },
            intensity_db: if self.frames > 0 {
                self.db_sum / self.frames as f32
            } else {
                0.0
            },
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    Silence,
    /// Looking for the peak.
    Rising,
    /// Past a peak by at least the margin; looking for the trough.
    Falling,
}

/// Streaming syllable and pause detector over finished frames.
#[derive(Clone, Debug)]
pub struct SyllableDetector {
    p: SyllableParams,
    peak_db: f32,
    phase: Phase,
    seg_start: u32,
    start_level: f32,
    max_db: f32,
    min_db: f32,
    min_frame: u32,
    max_since_min: f32,
    /// Frames `[seg_start, min_frame)`.
    a: Acc,
    /// Frames `[min_frame, now]` (Falling phase only).
    b: Acc,
    silent_run: u32,
    pause: Acc,
    /// Start frame of a syllable that began at the last pushed frame, until taken.
    onset: Option<u32>,
}

impl SyllableDetector {
    /// A detector in silence.
    pub fn new(p: SyllableParams) -> Self {
        Self {
            p,
            peak_db: p.initial_peak_db,
            phase: Phase::Silence,
            seg_start: 0,
            start_level: 0.0,
            max_db: 0.0,
            min_db: 0.0,
            min_frame: 0,
            max_since_min: 0.0,
            a: Acc::default(),
            b: Acc::default(),
            silent_run: 0,
            pause: Acc::default(),
            onset: None,
        }
    }

    /// Forgets everything (new utterance).
    pub fn reset(&mut self) {
        *self = Self::new(self.p);
    }

    /// Current silence threshold in dB.
    pub fn threshold_db(&self) -> f32 {
        let t = self.peak_db - self.p.range_db;
        if t > self.p.floor_db {
            t
        } else {
            self.p.floor_db
        }
    }

    /// The start frame of a syllable onset detected by the last [`push`](Self::push), once:
    /// speech rising out of silence (the frame itself), or a confirmed trough that begins a new
    /// syllable (the trough's frame, which is the new syllable's `start_frame`). An onset out
    /// of silence is reported as soon as it is seen, before the syllable proves prominent.
    pub fn take_onset(&mut self) -> Option<u32> {
        self.onset.take()
    }

    /// Feeds frame `k` (consecutive). At most one step completes per frame.
    pub fn push(&mut self, k: u32, f0: Option<f32>, db: f32) -> Option<Step> {
        self.onset = None;
        let db = if db.is_finite() { db } else { -300.0 };
        // Running peak: jumps up, decays 0.01 dB per frame.
        let decayed = self.peak_db - 0.01;
        self.peak_db = if db > decayed { db } else { decayed };
        if self.peak_db < self.p.floor_db + self.p.range_db {
            self.peak_db = self.p.floor_db + self.p.range_db;
        }
        if db < self.threshold_db() {
            let out = self.end_speech(k);
            self.silent_run += 1;
            self.pause.add(f0, db);
            if self.silent_run % self.p.pause_frames.max(1) == 0 {
                let start = k + 1 - self.p.pause_frames.max(1);
                let step = self.pause.step(StepKind::Pause, start, k + 1);
                self.pause = Acc::default();
                // A syllable ending here and a pause step at once cannot happen: a pause step
                // needs pause_frames >= 1 silent frames after the speech ended.
                return out.or(Some(step));
            }
            return out;
        }
        self.silent_run = 0;
        self.pause = Acc::default();
        if self.phase != Phase::Silence && k - self.seg_start >= MAX_STEP_FRAMES {
            // A second of sound without a trough: close it here (see the module docs).
            self.a.merge(&self.b);
            let step = self.a.step(StepKind::Syllable, self.seg_start, k);
            self.phase = Phase::Rising;
            self.seg_start = k;
            self.onset = Some(k);
            self.start_level = self.threshold_db();
            self.max_db = db;
            self.a = Acc::default();
            self.b = Acc::default();
            self.a.add(f0, db);
            return Some(step);
        }
        match self.phase {
            Phase::Silence => {
                self.phase = Phase::Rising;
                self.seg_start = k;
                self.onset = Some(k);
                // Speech rises out of silence: the opening "trough" is the silence threshold,
                // so a syllable that starts abruptly at its plateau still counts.
                self.start_level = self.threshold_db();
                self.max_db = db;
                self.a = Acc::default();
                self.a.add(f0, db);
                None
            }
            Phase::Rising => {
                self.a.add(f0, db);
                if db > self.max_db {
                    self.max_db = db;
                } else if db <= self.max_db - self.p.margin_db {
                    self.phase = Phase::Falling;
                    self.min_db = db;
                    self.min_frame = k;
                    self.max_since_min = db;
                    // Frame k moves from `a` to `b`: rebuild b from this frame alone.
                    self.a.frames -= 1;
                    self.a.db_sum -= db;
                    if let Some(f) = f0 {
                        self.a.voiced -= 1;
                        self.a.f0_sum -= f;
                    }
                    self.b = Acc::default();
                    self.b.add(f0, db);
                }
                None
            }
            Phase::Falling => {
                if db < self.min_db {
                    self.a.merge(&self.b);
                    self.b = Acc::default();
                    self.b.add(f0, db);
                    self.min_db = db;
                    self.min_frame = k;
                    self.max_since_min = db;
                    return None;
                }
                self.b.add(f0, db);
                if db > self.max_since_min {
                    self.max_since_min = db;
                }
                if db < self.min_db + self.p.margin_db {
                    return None;
                }
                // The trough at min_frame is confirmed.
                let prominent = self.max_db - self.start_level >= self.p.margin_db;
                let long_enough = self.min_frame - self.seg_start >= self.p.min_frames;
                self.phase = Phase::Rising;
                if prominent && long_enough {
                    let step = self
                        .a
                        .step(StepKind::Syllable, self.seg_start, self.min_frame);
                    self.seg_start = self.min_frame;
                    self.onset = Some(self.min_frame);
                    self.start_level = self.min_db;
                    self.a = self.b;
                    self.b = Acc::default();
                    self.max_db = self.max_since_min;
                    Some(step)
                } else {
                    // Not a syllable of its own: the dip stays inside the current one.
                    self.a.merge(&self.b);
                    self.b = Acc::default();
                    if self.max_since_min > self.max_db {
                        self.max_db = self.max_since_min;
                    }
                    None
                }
            }
        }
    }

    /// Ends the current syllable at frame `k` (exclusive), if speech was going on.
    fn end_speech(&mut self, k: u32) -> Option<Step> {
        if self.phase == Phase::Silence {
            return None;
        }
        self.a.merge(&self.b);
        self.b = Acc::default();
        self.phase = Phase::Silence;
        let prominent = self.max_db - self.start_level >= self.p.margin_db
            && self.max_db - self.threshold_db() >= self.p.margin_db;
        let long_enough = k - self.seg_start >= self.p.min_frames;
        if prominent && long_enough {
            Some(self.a.step(StepKind::Syllable, self.seg_start, k))
        } else {
            None
        }
    }

    /// End of stream after frame `k - 1`: closes a syllable still open.
    pub fn flush(&mut self, k: u32) -> Option<Step> {
        let out = self.end_speech(k);
        self.silent_run = 0;
        self.pause = Acc::default();
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(contour: &[f32]) -> ([Option<Step>; 64], usize) {
        let mut d = SyllableDetector::new(SyllableParams::DEFAULT);
        let mut out = [None; 64];
        let mut n = 0;
        for (k, &db) in contour.iter().enumerate() {
            if let Some(s) = d.push(k as u32 + 1, Some(100.0), db) {
                out[n] = Some(s);
                n += 1;
            }
        }
        if let Some(s) = d.flush(contour.len() as u32 + 1) {
            out[n] = Some(s);
            n += 1;
        }
        (out, n)
    }

    /// Three humps of 8 frames with 6 dB dips, then silence long enough for two pause steps.
    #[test]
    fn a_minute_of_steady_loud_sound_gives_a_step_a_second() {
        let mut d = SyllableDetector::new(SyllableParams::DEFAULT);
        let mut steps = alloc_free_steps();
        for k in 0..6000u32 {
            if let Some(s) = d.push(k, Some(200.0), 75.0) {
                steps.push(s).unwrap();
            }
        }
        // 60 s: 59 complete one-second steps (the 60th is still open).
        assert_eq!(steps.len(), 59);
        for (i, s) in steps.iter().enumerate() {
            assert_eq!(s.kind, StepKind::Syllable);
            assert_eq!(
                (s.start_frame, s.end_frame),
                (100 * i as u32, 100 * (i as u32 + 1))
            );
            assert!((s.intensity_db - 75.0).abs() < 1e-4);
        }
        assert_eq!(d.flush(6000).map(|s| s.end_frame), Some(6000));
    }

    fn alloc_free_steps() -> heapless::Vec<Step, 64> {
        heapless::Vec::new()
    }

    #[test]
    fn humps_become_syllables_then_pauses() {
        let mut c = [20.0f32; 24 + 60];
        for (k, v) in c.iter_mut().take(24).enumerate() {
            let phase = (k % 8) as f32 / 8.0;
            *v = 64.0 + 6.0 * libm::sinf(core::f32::consts::PI * phase);
        }
        let (out, n) = run(&c);
        let syl: usize = out[..n]
            .iter()
            .filter(|s| s.unwrap().kind == StepKind::Syllable)
            .count();
        let pauses: usize = out[..n]
            .iter()
            .filter(|s| s.unwrap().kind == StepKind::Pause)
            .count();
        assert_eq!(syl, 3, "{:?}", &out[..n]);
        assert_eq!(pauses, 2);
        // Syllables tile the speech: each starts where the previous ended.
        let s: [Step; 3] = [out[0].unwrap(), out[1].unwrap(), out[2].unwrap()];
        assert_eq!(s[0].start_frame, 1);
        assert_eq!(s[0].end_frame, s[1].start_frame);
        assert_eq!(s[1].end_frame, s[2].start_frame);
        assert_eq!(s[2].end_frame, 25);
        assert_eq!(s[0].f0_hz, Some(100.0));
    }

    #[test]
    fn small_ripples_do_not_split() {
        let mut c = [20.0f32; 60];
        for (k, v) in c.iter_mut().take(40).enumerate() {
            *v = 66.0 + 0.8 * libm::sinf(k as f32);
        }
        let (out, n) = run(&c);
        let syl = out[..n]
            .iter()
            .filter(|s| s.unwrap().kind == StepKind::Syllable)
            .count();
        assert_eq!(syl, 1);
    }

    #[test]
    fn non_finite_levels_are_silence() {
        let mut d = SyllableDetector::new(SyllableParams::DEFAULT);
        for k in 1..100 {
            let s = d.push(k, None, f32::NAN);
            if let Some(s) = s {
                assert_eq!(s.kind, StepKind::Pause);
                assert!(s.intensity_db.is_finite());
            }
        }
    }
}
