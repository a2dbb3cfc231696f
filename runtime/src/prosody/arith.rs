//! The front-end's arithmetic, chosen at build time: `f32` ([`Float`], the reference, for
//! chips with an FPU) or integers ([`Fixed`], for chips without one: Cortex-M0+, RISC-V IMC).
//!
//! The per-sample and per-frame work of the front-end (the half-band decimator, the pitch
//! autocorrelation and the intensity blocks) is what a core without an FPU cannot afford in
//! soft-float: about 110 instructions per `f32` add or multiply on ARMv6-M. [`Fixed`] does that
//! work in integers; everything after it (the candidates' parabolic peak, the pitch path
//! finder, the syllable detector, the step features, the GMM memberships, the CRF belief and
//! the policy) is the same `f32` code on both paths, run a few hundred times a second at most.
//! The formats, ranges and roundings of [`Fixed`] are in `docs/method.md` ("The fixed-point
//! front-end").
//!
//! [`DefaultArith`] is [`Fixed`] when the crate's `fixed` feature is on and [`Float`]
//! otherwise; [`FrontEnd`](super::FrontEnd) and the controller use it. Host tools can run
//! either path in one build through [`FrontEnd::with_arith`](super::FrontEnd::with_arith)
//! (the simulator's `eval-prosody --fixed` compares both with Praat).
//!
//! Both are deterministic: integer arithmetic, and `f32` with `libm`, give the same bits on
//! every target.

use super::decimate::{HalfBand, HalfBandQ, PITCH_RING};
use super::intensity::Intensity;
use super::intensity_fixed::IntensityQ;
use super::pitch::{Candidates, GlobalPeak, PitchAnalyzer, PitchParams};
use super::pitch_fixed::PitchAnalyzerQ;

/// The arithmetic of the front-end's per-sample and per-frame stages.
pub trait Arith: Clone + core::fmt::Debug {
    /// A sample of the pitch path (after the decimator).
    type Sample: Copy + core::fmt::Debug + PartialEq;
    /// The zero sample (the signal before its start).
    const ZERO: Self::Sample;
    /// The 2:1 decimator in front of the pitch analysis.
    type Decimator: Decimate<Self::Sample>;
    /// The pitch candidates of one frame.
    type Analyzer: AnalyzePitch<Self::Sample>;
    /// The intensity blocks and the windowed intensity of a frame.
    type Intensity: MeasureIntensity;
    /// An input sample as a pitch-path sample (when the rate needs no decimation).
    fn sample(s: i16) -> Self::Sample;
}

/// A streaming 2:1 decimator.
pub trait Decimate<S>: Clone + core::fmt::Debug {
    /// Delay of the output in decimated samples.
    const DELAY: usize;
    /// A decimator with zero history.
    fn fresh() -> Self;
    /// Input samples that the next `outputs` outputs take (`outputs` >= 1).
    fn inputs_for(&self, outputs: u64) -> u64;
    /// Feeds one input sample; an output after every second input.
    fn push_sample(&mut self, s: i16) -> Option<S>;
    /// [`push_sample`](Self::push_sample) for each of `xs`, the outputs into `ring` from
    /// sample count `produced` on (slot `count % PITCH_RING`); returns the new count.
    fn push_into(&mut self, xs: &[i16], ring: &mut [S; PITCH_RING], produced: u64) -> u64;
}

/// Pitch candidates of one analysis window.
pub trait AnalyzePitch<S>: Clone + core::fmt::Debug {
    /// A placeholder to [`configure`](Self::configure) (not usable as is).
    fn blank() -> Self;
    /// Sizes and tables for a pitch rate; `None` when the window does not fit the capacities.
    fn configure(&mut self, rate_hz: u32, params: PitchParams) -> Option<()>;
    /// Window length in samples (even).
    fn window_len(&self) -> usize;
    /// The candidates of one window of [`window_len`](Self::window_len) samples.
    fn analyze(&self, x: &[S], global: &mut GlobalPeak, out: &mut Candidates);
}

/// Intensity: samples into 1 ms blocks, frames from the blocks.
pub trait MeasureIntensity: Clone + core::fmt::Debug {
    /// A placeholder to [`configure`](Self::configure) (not usable as is).
    fn blank() -> Self;
    /// Sizes for a rate and a pitch floor; `None` when the window does not fit.
    fn configure(&mut self, rate_hz: u32, floor_hz: f32) -> Option<()>;
    /// Blocks either side of a frame's centre.
    fn half_blocks(&self) -> usize;
    /// Blocks completed so far.
    fn blocks(&self) -> u64;
    /// Forgets all input.
    fn reset(&mut self);
    /// Adds one sample.
    fn push(&mut self, s: i16);
    /// Adds samples.
    fn push_slice(&mut self, xs: &[i16]);
    /// Intensity (dB) of the frame centred before block `centre`, once its blocks are there.
    fn frame_db(&self, centre: u64) -> Option<f32>;
}

/// The `f32` front-end: the reference, for chips with an FPU.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Float;

/// The integer front-end, for chips without an FPU (docs/method.md, "The fixed-point
/// front-end").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Fixed;

/// The arithmetic the controller's front-end uses: [`Fixed`] with the `fixed` feature.
#[cfg(feature = "fixed")]
pub type DefaultArith = Fixed;
/// The arithmetic the controller's front-end uses: [`Fixed`] with the `fixed` feature.
#[cfg(not(feature = "fixed"))]
pub type DefaultArith = Float;

impl Arith for Float {
    type Sample = f32;
    const ZERO: f32 = 0.0;
    type Decimator = HalfBand;
    type Analyzer = PitchAnalyzer;
    type Intensity = Intensity;
    #[inline]
    fn sample(s: i16) -> f32 {
        s as f32 * (1.0 / 32768.0)
    }
}

impl Arith for Fixed {
    /// Samples in quarter LSBs of the input (`i16` times 4, see [`HalfBandQ`]).
    type Sample = i32;
    const ZERO: i32 = 0;
    type Decimator = HalfBandQ;
    type Analyzer = PitchAnalyzerQ;
    type Intensity = IntensityQ;
    #[inline]
    fn sample(s: i16) -> i32 {
        (s as i32) << 2
    }
}

impl Decimate<f32> for HalfBand {
    const DELAY: usize = HalfBand::DELAY;
    #[inline(always)]
    fn fresh() -> Self {
        HalfBand::new()
    }
    #[inline(always)]
    fn inputs_for(&self, outputs: u64) -> u64 {
        HalfBand::inputs_for(self, outputs)
    }
    #[inline(always)]
    fn push_sample(&mut self, s: i16) -> Option<f32> {
        self.push(Float::sample(s))
    }
    #[inline(always)]
    fn push_into(&mut self, xs: &[i16], ring: &mut [f32; PITCH_RING], produced: u64) -> u64 {
        HalfBand::push_into(self, xs, ring, produced)
    }
}

impl AnalyzePitch<f32> for PitchAnalyzer {
    #[inline(always)]
    fn blank() -> Self {
        PitchAnalyzer::blank()
    }
    #[inline(always)]
    fn configure(&mut self, rate_hz: u32, params: PitchParams) -> Option<()> {
        PitchAnalyzer::configure(self, rate_hz, params)
    }
    #[inline(always)]
    fn window_len(&self) -> usize {
        PitchAnalyzer::window_len(self)
    }
    #[inline(always)]
    fn analyze(&self, x: &[f32], global: &mut GlobalPeak, out: &mut Candidates) {
        PitchAnalyzer::analyze(self, x, global, out)
    }
}

impl MeasureIntensity for Intensity {
    #[inline(always)]
    fn blank() -> Self {
        Intensity::blank()
    }
    #[inline(always)]
    fn configure(&mut self, rate_hz: u32, floor_hz: f32) -> Option<()> {
        Intensity::configure(self, rate_hz, floor_hz)
    }
    #[inline(always)]
    fn half_blocks(&self) -> usize {
        Intensity::half_blocks(self)
    }
    #[inline(always)]
    fn blocks(&self) -> u64 {
        Intensity::blocks(self)
    }
    #[inline(always)]
    fn reset(&mut self) {
        Intensity::reset(self)
    }
    #[inline(always)]
    fn push(&mut self, s: i16) {
        Intensity::push(self, s)
    }
    #[inline(always)]
    fn push_slice(&mut self, xs: &[i16]) {
        Intensity::push_slice(self, xs)
    }
    #[inline(always)]
    fn frame_db(&self, centre: u64) -> Option<f32> {
        Intensity::frame_db(self, centre)
    }
}

impl Decimate<i32> for HalfBandQ {
    const DELAY: usize = HalfBand::DELAY;
    #[inline(always)]
    fn fresh() -> Self {
        HalfBandQ::new()
    }
    #[inline(always)]
    fn inputs_for(&self, outputs: u64) -> u64 {
        HalfBandQ::inputs_for(self, outputs)
    }
    #[inline(always)]
    fn push_sample(&mut self, s: i16) -> Option<i32> {
        self.push(s)
    }
    #[inline(always)]
    fn push_into(&mut self, xs: &[i16], ring: &mut [i32; PITCH_RING], produced: u64) -> u64 {
        HalfBandQ::push_into(self, xs, ring, produced)
    }
}

impl AnalyzePitch<i32> for PitchAnalyzerQ {
    #[inline(always)]
    fn blank() -> Self {
        PitchAnalyzerQ::blank()
    }
    #[inline(always)]
    fn configure(&mut self, rate_hz: u32, params: PitchParams) -> Option<()> {
        PitchAnalyzerQ::configure(self, rate_hz, params)
    }
    #[inline(always)]
    fn window_len(&self) -> usize {
        PitchAnalyzerQ::window_len(self)
    }
    #[inline(always)]
    fn analyze(&self, x: &[i32], global: &mut GlobalPeak, out: &mut Candidates) {
        PitchAnalyzerQ::analyze(self, x, global, out)
    }
}

impl MeasureIntensity for IntensityQ {
    #[inline(always)]
    fn blank() -> Self {
        IntensityQ::blank()
    }
    #[inline(always)]
    fn configure(&mut self, rate_hz: u32, floor_hz: f32) -> Option<()> {
        IntensityQ::configure(self, rate_hz, floor_hz)
    }
    #[inline(always)]
    fn half_blocks(&self) -> usize {
        IntensityQ::half_blocks(self)
    }
    #[inline(always)]
    fn blocks(&self) -> u64 {
        IntensityQ::blocks(self)
    }
    #[inline(always)]
    fn reset(&mut self) {
        IntensityQ::reset(self)
    }
    #[inline(always)]
    fn push(&mut self, s: i16) {
        IntensityQ::push(self, s)
    }
    #[inline(always)]
    fn push_slice(&mut self, xs: &[i16]) {
        IntensityQ::push_slice(self, xs)
    }
    #[inline(always)]
    fn frame_db(&self, centre: u64) -> Option<f32> {
        IntensityQ::frame_db(self, centre)
    }
}
