//! The streaming prosody front-end: PCM samples in; per 10 ms frame F0 and intensity; per
//! syllable (or pause) one [`Step`] with its features.
//!
//! ```text
//!  i16 samples ─┬─► 1 ms block sums ──────────────► intensity (dB, Praat's Kaiser window)
//!               └─► half-band ÷2 ─► 40 ms Hann ─► autocorrelation ─► candidates
//!                                                     ─► fixed-lag path finder ─► F0
//!  per frame (F0, dB) ─► SyllableDetector ─► Step { syllable | pause }, Onset
//! ```
//!
//! **Timing.** Frame `k` (k = 1, 2, ...) is centred at `k * 10 ms` after the first sample; the
//! signal is taken as silent before its start. A frame is final once the pitch path finder has
//! seen [`viterbi::LAG`] more frames, i.e. about `20 + 10 * LAG` ms after its centre (70 ms);
//! a syllable is reported when the rise after its closing trough confirms it.
//!
//! **Determinism.** Samples are processed one at a time into fixed rings; a frame is computed
//! when its last sample arrives. The chunking of the input therefore cannot change any result:
//! pushing 1, 7, 160 or 4096 samples at a time gives bit-identical frames and steps (tested).
//! The arithmetic is `f32` with `libm`, or with the `fixed` feature integers up to each
//! frame's candidates and intensity ([`arith`]); either way host and device agree bit for bit.
//!
//! **Safety.** No allocation, no recursion, no panics for any input; every output is finite
//! (intensity of exact silence is Praat's `-300 dB`). The state has a compile-time size
//! (about 9 KiB) and analysing a frame uses about 5 KiB of stack.
//!
//! Sample rates: 8 to 16 kHz in whole kHz (the pitch path runs at half the rate above 8 kHz).
//! Hosts resample other rates before feeding the front-end.

pub mod arith;
pub mod decimate;
mod frame;
pub mod intensity;
pub mod intensity_fixed;
pub mod pitch;
pub mod pitch_fixed;
pub mod syllable;
pub mod viterbi;

pub use pitch::PitchParams;
pub use syllable::{Step, StepKind, SyllableParams};

pub use frame::HOP_S;

use arith::{AnalyzePitch, Arith, Decimate, DefaultArith, MeasureIntensity};
use pitch::{Candidates, GlobalPeak, MAX_WINDOW};
use syllable::SyllableDetector;
use viterbi::PathFinder;

/// Lowest supported front-end rate (Hz).
pub const MIN_RATE_HZ: u32 = 8_000;
/// Highest supported front-end rate (Hz).
pub const MAX_RATE_HZ: u32 = 16_000;
/// Default front-end rate (Hz).
pub const DEFAULT_RATE_HZ: u32 = 16_000;

use decimate::PITCH_RING;
const _: () = assert!(PITCH_RING >= MAX_WINDOW + 64 && PITCH_RING.is_power_of_two());

/// Front-end settings; stored in the policy blob so training and device use the same ones.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProsodyConfig {
    /// Sample rate of the PCM fed to the front-end (Hz).
    pub sample_rate_hz: u32,
    /// Pitch estimator settings.
    pub pitch: PitchParams,
    /// Syllable detector settings.
    pub syllables: SyllableParams,
}

impl ProsodyConfig {
    /// 16 kHz, Praat's pitch defaults (75-600 Hz), default syllable detector.
    pub const DEFAULT: Self = Self {
        sample_rate_hz: DEFAULT_RATE_HZ,
        pitch: PitchParams::PRAAT,
        syllables: SyllableParams::DEFAULT,
    };

    /// Checks the settings without building a front-end (cheap, no large stack use).
    pub fn validate(&self) -> Result<(), ConfigError> {
        let rate = self.sample_rate_hz;
        if !(MIN_RATE_HZ..=MAX_RATE_HZ).contains(&rate) || rate % 1000 != 0 {
            return Err(ConfigError::UnsupportedSampleRate(rate));
        }
        let p = &self.pitch;
        let all_ok = [
            p.silence_threshold,
            p.voicing_threshold,
            p.octave_cost,
            p.octave_jump_cost,
            p.voiced_unvoiced_cost,
        ]
        .iter()
        .all(|&v| finite_nonneg(v));
        if !all_ok {
            return Err(ConfigError::PitchParams);
        }
        let pitch_rate = if rate > MIN_RATE_HZ { rate / 2 } else { rate };
        if !(p.floor_hz.is_finite() && p.ceiling_hz.is_finite())
            || p.floor_hz < 75.0
            || p.ceiling_hz <= 2.0 * p.floor_hz
            || p.ceiling_hz * 4.0 > pitch_rate as f32
        {
            return Err(ConfigError::PitchRange);
        }
        // The window sizes for these settings must fit the fixed capacities.
        let nominal = libm::floorf(3.0 * pitch_rate as f32 / p.floor_hz) as usize;
        if 2 * (nominal / 2).saturating_sub(1) > pitch::MAX_WINDOW
            || libm::ceilf(3.2e3 / p.floor_hz) as usize > intensity::MAX_HALF_BLOCKS
        {
            return Err(ConfigError::PitchRange);
        }
        let s = &self.syllables;
        let positive = |v: f32| v.is_finite() && v > 0.0;
        if !positive(s.margin_db)
            || !positive(s.range_db)
            || !s.floor_db.is_finite()
            || !s.initial_peak_db.is_finite()
            || s.min_frames == 0
            || s.pause_frames == 0
        {
            return Err(ConfigError::SyllableParams);
        }
        Ok(())
    }
}

impl Default for ProsodyConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Why a [`ProsodyConfig`] was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfigError {
    /// The rate is outside 8-16 kHz or not a whole number of kHz.
    UnsupportedSampleRate(u32),
    /// The pitch range does not fit the analysis capacities (floor must be >= 75 Hz, the
    /// ceiling above twice the floor and below a quarter of the pitch analysis rate).
    PitchRange,
    /// A pitch cost or threshold is negative or not finite.
    PitchParams,
    /// A syllable parameter is out of range (margin and range must be positive and finite,
    /// frame counts at least 1).
    SyllableParams,
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::UnsupportedSampleRate(r) => write!(
                f,
                "unsupported front-end sample rate {r} Hz (use 8000-16000 in whole kHz)"
            ),
            Self::PitchRange => f.write_str(
                "pitch range does not fit the analysis window (floor >= 75 Hz, ceiling > 2x floor)",
            ),
            Self::PitchParams => f.write_str("pitch thresholds and costs must be finite and >= 0"),
            Self::SyllableParams => f.write_str(
                "syllable parameters out of range (margin, range > 0; min and pause frames >= 1)",
            ),
        }
    }
}

impl core::error::Error for ConfigError {}

/// One analysis frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Frame number, from 1; centred at `index * 10 ms`.
    pub index: u32,
    /// F0 in Hz, `None` when unvoiced.
    pub f0_hz: Option<f32>,
    /// Intensity in dB re 2e-5 with full scale = 1 (Praat's convention; -300 for exact silence).
    pub intensity_db: f32,
}

impl Frame {
    /// Centre time in seconds.
    pub fn time_s(&self) -> f64 {
        self.index as f64 * HOP_S
    }
}

/// What the front-end reports, in time order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// A finished frame.
    Frame(Frame),
    /// A finished syllable or pause step (reported after the frame that completed it).
    Step(Step),
    /// A syllable onset was detected (reported after the frame that revealed it, and after the
    /// step it closed, if any): the frame where the new syllable starts. See
    /// [`SyllableDetector::take_onset`](syllable::SyllableDetector::take_onset).
    Onset(u32),
}

fn finite_nonneg(v: f32) -> bool {
    v.is_finite() && v >= 0.0
}

/// The streaming front-end. See the module docs for timing and invariants. `A` is its
/// arithmetic ([`arith`]): by default `f32`, integers with the `fixed` feature.
#[derive(Clone, Debug)]
pub struct FrontEnd<A: Arith = DefaultArith> {
    config: ProsodyConfig,
    /// Input samples per frame hop.
    hop: u32,
    /// Decimated samples per frame hop.
    pitch_hop: u32,
    decimator: Option<A::Decimator>,
    /// Output delay of the decimator in decimated samples.
    delay: u64,
    ring: [A::Sample; PITCH_RING],
    /// Decimated samples produced so far (including the decimator's delay).
    produced: u64,
    analyzer: A::Analyzer,
    global: GlobalPeak,
    path: PathFinder,
    intensity: A::Intensity,
    syllables: SyllableDetector,
    /// Next frame to analyse for pitch.
    next_pitch: u32,
    /// Last frame to analyse (set at end of stream).
    limit: u32,
    /// Frames already reported.
    emitted: u32,
    /// Samples pushed since the start of the stream.
    samples: u64,
}

impl FrontEnd {
    /// A front-end for `config` with the build's arithmetic ([`DefaultArith`]), or why the
    /// config is refused.
    pub fn new(config: &ProsodyConfig) -> Result<Self, ConfigError> {
        Self::with_arith(config)
    }
}

impl<A: Arith> FrontEnd<A> {
    /// A front-end for `config` with the arithmetic `A` (host tools compare both paths with
    /// `FrontEnd::<Float>::with_arith` and `FrontEnd::<Fixed>::with_arith`).
    pub fn with_arith(config: &ProsodyConfig) -> Result<Self, ConfigError> {
        let mut me = Self::blank();
        me.configure(config)?;
        Ok(me)
    }

    /// A placeholder to [`configure`](Self::configure) in place (not usable as is). Cheap to
    /// build directly in its final place (a front-end is about 9 KiB; one returned by value is
    /// copied on the stack on its way).
    #[inline(always)]
    pub(crate) fn blank() -> Self {
        Self {
            config: ProsodyConfig::DEFAULT,
            hop: 0,
            pitch_hop: 0,
            decimator: None,
            delay: 0,
            ring: [A::ZERO; PITCH_RING],
            produced: 0,
            analyzer: A::Analyzer::blank(),
            global: GlobalPeak::new(),
            path: PathFinder::new(&ProsodyConfig::DEFAULT.pitch),
            intensity: A::Intensity::blank(),
            syllables: SyllableDetector::new(ProsodyConfig::DEFAULT.syllables),
            next_pitch: 1,
            limit: u32::MAX,
            emitted: 0,
            samples: 0,
        }
    }

    /// Makes `self` what [`new`](Self::new) returns for `config`, in place; on an error `self`
    /// is left unusable.
    pub(crate) fn configure(&mut self, config: &ProsodyConfig) -> Result<(), ConfigError> {
        config.validate()?;
        let rate = config.sample_rate_hz;
        let p = &config.pitch;
        let decimate = rate > MIN_RATE_HZ;
        let pitch_rate = if decimate { rate / 2 } else { rate };
        self.analyzer
            .configure(pitch_rate, *p)
            .ok_or(ConfigError::PitchRange)?;
        self.intensity
            .configure(rate, p.floor_hz)
            .ok_or(ConfigError::PitchRange)?;
        let s = &config.syllables;
        self.config = *config;
        self.hop = rate / 100;
        self.pitch_hop = pitch_rate / 100;
        self.decimator = if decimate {
            Some(A::Decimator::fresh())
        } else {
            None
        };
        self.delay = if decimate {
            <A::Decimator as Decimate<A::Sample>>::DELAY as u64
        } else {
            0
        };
        self.ring.fill(A::ZERO);
        self.produced = 0;
        self.global = GlobalPeak::new();
        self.path = PathFinder::new(p);
        self.syllables = SyllableDetector::new(*s);
        self.next_pitch = 1;
        self.limit = u32::MAX;
        self.emitted = 0;
        self.samples = 0;
        Ok(())
    }

    /// The configuration in use.
    pub fn config(&self) -> &ProsodyConfig {
        &self.config
    }

    /// Forgets all input: the next sample starts a new stream at time 0.
    pub fn reset(&mut self) {
        self.decimator = self.decimator.as_ref().map(|_| A::Decimator::fresh());
        self.ring = [A::ZERO; PITCH_RING];
        self.produced = 0;
        self.global = GlobalPeak::new();
        self.path.reset();
        self.intensity.reset();
        self.syllables.reset();
        self.next_pitch = 1;
        self.limit = u32::MAX;
        self.emitted = 0;
        self.samples = 0;
    }

    /// Feeds samples (any count); reports finished frames and steps through `sink`, in order.
    ///
    /// Exactly `push_one` (the per-sample step) per sample, done in runs: up to the sample whose
    /// decimated output completes the next pitch window, the intensity blocks and the
    /// decimator take the whole run in tight loops (same arithmetic, same order), then that
    /// frame is analysed. This is most of the front-end's per-sample cost on a Cortex-M4.
    pub fn push(&mut self, samples: &[i16], sink: &mut impl FnMut(Event)) {
        let mut rest = samples;
        while !rest.is_empty() {
            // Decimated samples until the next window is complete (at least one, as
            // `push_one` checks only after producing one).
            let outputs = self.needed().saturating_sub(self.produced).max(1);
            let inputs = match &self.decimator {
                Some(d) => d.inputs_for(outputs),
                None => outputs,
            };
            let n = inputs.min(rest.len() as u64) as usize;
            let (run, later) = rest.split_at(n);
            self.intensity.push_slice(run);
            self.pitch_input(run);
            if n as u64 == inputs && self.produced >= self.needed() && self.next_pitch <= self.limit
            {
                self.analyse_frame(sink);
            }
            rest = later;
        }
        self.samples += samples.len() as u64;
    }

    /// Decimated samples needed before frame `next_pitch` can be analysed (its window is
    /// complete): the decimated time index of the newest sample is `produced - 1 - delay`.
    #[inline]
    fn needed(&self) -> u64 {
        let half = (self.analyzer.window_len() / 2) as u64;
        self.next_pitch as u64 * self.pitch_hop as u64 + half + self.delay
    }

    /// Decimates `run` into the pitch ring (no analysis).
    fn pitch_input(&mut self, run: &[i16]) {
        match &mut self.decimator {
            Some(d) => self.produced = d.push_into(run, &mut self.ring, self.produced),
            None => {
                for &s in run {
                    self.ring[(self.produced % PITCH_RING as u64) as usize] = A::sample(s);
                    self.produced += 1;
                }
            }
        }
    }

    #[inline]
    fn push_one(&mut self, s: i16, sink: &mut impl FnMut(Event)) {
        self.intensity.push(s);
        let y = match &mut self.decimator {
            Some(d) => match d.push_sample(s) {
                Some(y) => y,
                None => return,
            },
            None => A::sample(s),
        };
        self.ring[(self.produced % PITCH_RING as u64) as usize] = y;
        self.produced += 1;
        if self.produced >= self.needed() && self.next_pitch <= self.limit {
            self.analyse_frame(sink);
        }
    }

    /// Analyses pitch frame `next_pitch` (its window is complete) and reports what became final.
    fn analyse_frame(&mut self, sink: &mut impl FnMut(Event)) {
        let k = self.next_pitch as u64;
        let half = (self.analyzer.window_len() / 2) as u64;
        let len = self.analyzer.window_len();
        // Window covers decimated time indices [k*hop - half, k*hop + half), stored at
        // ring position (time index + delay).
        // Indices before the stream's start wrap to ring slots that still hold zeros.
        let first = (k * self.pitch_hop as u64 + self.delay) as i64 - half as i64;
        let mut win = [A::ZERO; MAX_WINDOW];
        // At most two contiguous pieces of the ring (len <= MAX_WINDOW < PITCH_RING).
        let start = first.rem_euclid(PITCH_RING as i64) as usize;
        let len = len.min(MAX_WINDOW);
        let head = (PITCH_RING - start).min(len);
        win[..head].copy_from_slice(&self.ring[start..start + head]);
        win[head..len].copy_from_slice(&self.ring[..len - head]);
        let mut cand = Candidates::UNVOICED;
        self.analyzer
            .analyze(&win[..len], &mut self.global, &mut cand);
        self.next_pitch += 1;
        if let Some(d) = self.path.push(&cand) {
            self.emit(d.f0_hz, sink);
        }
    }

    /// Reports the next frame with its decided F0.
    fn emit(&mut self, f0: f32, sink: &mut impl FnMut(Event)) {
        let index = self.emitted + 1;
        self.emitted = index;
        let db = self
            .intensity
            .frame_db(index as u64 * 10)
            .unwrap_or(intensity::SILENT_DB);
        let f0_hz = if f0 > 0.0 { Some(f0) } else { None };
        sink(Event::Frame(Frame {
            index,
            f0_hz,
            intensity_db: db,
        }));
        if let Some(step) = self.syllables.push(index, f0_hz, db) {
            sink(Event::Step(step));
        }
        if let Some(frame) = self.syllables.take_onset() {
            sink(Event::Onset(frame));
        }
    }

    /// Ends the stream: reports every frame centred within the input, closes an open syllable,
    /// and resets the front-end for a new stream.
    pub fn finish(&mut self, sink: &mut impl FnMut(Event)) {
        let last = (self.samples / self.hop as u64).min(u32::MAX as u64 - 1) as u32;
        self.limit = last;
        let need_blocks = last as u64 * 10 + self.intensity.half_blocks() as u64;
        // Append silence until the last frame's pitch window and intensity window are complete.
        let mut guard = 0u32;
        while (self.next_pitch <= last || self.intensity.blocks() < need_blocks) && guard < 100_000
        {
            self.push_one(0, sink);
            guard += 1;
        }
        let mut decided = [0.0f32; viterbi::LAG + 1];
        let mut n = 0usize;
        self.path.flush(|d| {
            if n < decided.len() {
                decided[n] = d.f0_hz;
                n += 1;
            }
        });
        for &f0 in &decided[..n] {
            if self.emitted < last {
                self.emit(f0, sink);
            }
        }
        if let Some(step) = self.syllables.flush(self.emitted + 1) {
            sink(Event::Step(step));
        }
        self.reset();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use arith::{Fixed, Float};

    #[test]
    fn rejects_bad_configs() {
        let mut c = ProsodyConfig::DEFAULT;
        c.sample_rate_hz = 44_100;
        assert_eq!(
            FrontEnd::new(&c).err(),
            Some(ConfigError::UnsupportedSampleRate(44_100))
        );
        let mut c = ProsodyConfig::DEFAULT;
        c.pitch.floor_hz = 50.0;
        assert_eq!(FrontEnd::new(&c).err(), Some(ConfigError::PitchRange));
        let mut c = ProsodyConfig::DEFAULT;
        c.pitch.voicing_threshold = f32::NAN;
        assert_eq!(FrontEnd::new(&c).err(), Some(ConfigError::PitchParams));
        let mut c = ProsodyConfig::DEFAULT;
        c.syllables.pause_frames = 0;
        assert_eq!(FrontEnd::new(&c).err(), Some(ConfigError::SyllableParams));
        for rate in [8000, 12000, 16000] {
            let mut c = ProsodyConfig::DEFAULT;
            c.sample_rate_hz = rate;
            assert!(FrontEnd::new(&c).is_ok(), "{rate}");
        }
    }

    #[test]
    fn frame_count_covers_input() {
        let mut fe = FrontEnd::new(&ProsodyConfig::DEFAULT).unwrap();
        let samples = [0i16; 16_000 + 50];
        let mut frames = 0u32;
        let mut last = 0;
        fe.push(&samples, &mut |e| {
            if let Event::Frame(f) = e {
                frames += 1;
                assert_eq!(f.index, last + 1);
                last = f.index;
            }
        });
        fe.finish(&mut |e| {
            if let Event::Frame(f) = e {
                frames += 1;
                assert_eq!(f.index, last + 1);
                last = f.index;
            }
        });
        assert_eq!(frames, 100);
    }

    fn frames<A: Arith>(x: &[i16]) -> [Option<Frame>; 200] {
        let mut fe = FrontEnd::<A>::with_arith(&ProsodyConfig::DEFAULT).unwrap();
        let mut out = [None; 200];
        let mut sink = |e: Event| {
            if let Event::Frame(f) = e {
                if let Some(slot) = out.get_mut(f.index as usize) {
                    *slot = Some(f);
                }
            }
        };
        fe.push(x, &mut sink);
        fe.finish(&mut sink);
        out
    }

    #[test]
    fn fixed_front_end_tracks_the_f32_one_on_a_gliding_tone() {
        // 1.5 s at 16 kHz: a tone gliding 110 -> 260 Hz at a planted level (-12 dBFS), then
        // 0.3 s of a faint one (-60 dBFS).
        let mut x = [0i16; 24_000];
        let mut phase = 0.0f64;
        for (i, v) in x.iter_mut().enumerate() {
            let t = i as f64 / 16_000.0;
            let (f, amp) = if t < 1.2 {
                (110.0 + 125.0 * t, 0.25)
            } else {
                (200.0, 0.001)
            };
            phase += 2.0 * core::f64::consts::PI * f / 16_000.0;
            *v = libm::round(32767.0 * amp * libm::sin(phase)) as i16;
        }
        let (a, b) = (frames::<Float>(&x), frames::<Fixed>(&x));
        let mut voiced = 0;
        for k in 10..145 {
            let (Some(fa), Some(fb)) = (a[k], b[k]) else {
                panic!("frame {k} missing");
            };
            let t = k as f64 * 0.01;
            if (0.1..1.1).contains(&t) {
                // The planted pitch, within 0.5 % on both paths, and the paths within 0.1 %.
                let want = 110.0 + 125.0 * t;
                let (pa, pb) = (fa.f0_hz.unwrap() as f64, fb.f0_hz.unwrap() as f64);
                assert!(
                    (pb - want).abs() < 0.005 * want,
                    "frame {k}: {pb} vs {want}"
                );
                assert!((pa - pb).abs() < 0.001 * pa, "frame {k}: {pa} vs {pb}");
                // Mean square amp^2 / 2 at full scale 1: 10 log10(0.25^2 / 2 / 4e-10).
                let level = 10.0 * libm::log10(0.25 * 0.25 / 2.0 / 4.0e-10);
                assert!((fb.intensity_db as f64 - level).abs() < 0.1, "frame {k}");
                voiced += 1;
            }
            assert_eq!(fa.f0_hz.is_some(), fb.f0_hz.is_some(), "frame {k}");
            assert!(
                (fa.intensity_db - fb.intensity_db).abs() < 0.01,
                "frame {k}"
            );
        }
        assert_eq!(voiced, 100);
    }
}
