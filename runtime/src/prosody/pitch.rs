//! Per-frame pitch candidates: Boersma's autocorrelation method with window correction.
//!
//! This is the estimator of Praat's "To Pitch (ac)" (Boersma 1993, *Accurate short-term analysis
//! of the fundamental frequency and the harmonics-to-noise ratio of a sampled sound*), chosen
//! because Praat is the reference the project is measured against and because its candidate
//! set plus path finder ([`super::viterbi`]) is robust against octave errors, which matter more
//! for gesture timing than the last fraction of a percent of F0 accuracy. Per frame:
//!
//! 1. take `3 / floor` seconds of the (decimated) signal around the frame centre, subtract the
//!    local mean, apply a Hann window, zero-pad to [`FFT_LEN`];
//! 2. autocorrelation = inverse FFT of the power spectrum (done as a second forward real FFT of
//!    the even, real power spectrum), normalized by lag 0 and divided by the normalized
//!    autocorrelation of the window itself (the "window correction", which removes the taper's
//!    bias towards short lags);
//! 3. local maxima above `voicing_threshold / 2` between the ceiling and floor lags become
//!    voiced candidates, refined by parabolic interpolation; values above 1 (short-window
//!    artefacts) are reflected to `1/r` as in Praat; the strongest `MAX_VOICED` are kept, ranked
//!    with Praat's octave cost;
//! 4. the frame's local peak relative to the running global peak decides how strong the
//!    unvoiced candidate is (Praat's silence threshold).
//!
//! Departures from Praat, all for a fixed budget on a Cortex-M4: the analysis runs at half the
//! front-end rate; peaks are refined by parabolic rather than sinc interpolation; at most
//! [`MAX_VOICED`] candidates are kept; the global peak is a running maximum (a stream has no
//! "whole sound"), see [`GlobalPeak`]. The accuracy that results is measured against Praat by
//! `gesture-sim eval-prosody` and the tests in `tests/`.
//!
//! Invariants: no allocation; no panics for any sample values (silent frames short-circuit
//! before any division; all divisors are checked to be positive and finite).

use microfft::real::rfft_512;

/// FFT length of the autocorrelation (at most 8 kHz pitch rate: window 318 + half-window lags).
pub const FFT_LEN: usize = 512;
/// Capacity of the analysis window in samples (3 periods of 75 Hz at 8 kHz).
pub const MAX_WINDOW: usize = 320;
/// Capacity of the lag axis (half a window, as Praat's interpolation depth).
pub const MAX_LAGS: usize = MAX_WINDOW / 2 + 1;
/// Most voiced candidates kept per frame (Praat keeps 15; 8 loses nothing measurable).
pub const MAX_VOICED: usize = 8;
/// Candidates per frame, including the unvoiced one at index 0.
pub const MAX_CANDIDATES: usize = MAX_VOICED + 1;

/// Tunables of the pitch estimator (Praat's names and defaults).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PitchParams {
    /// Lowest F0 considered (Hz); also sets the window length (3 periods).
    pub floor_hz: f32,
    /// Highest F0 considered (Hz).
    pub ceiling_hz: f32,
    /// Relative amplitude below which a frame counts as silent.
    pub silence_threshold: f32,
    /// Minimum normalized autocorrelation for a frame to count as voiced.
    pub voicing_threshold: f32,
    /// Preference for higher candidates (per octave).
    pub octave_cost: f32,
    /// Path cost of an octave jump between consecutive frames.
    pub octave_jump_cost: f32,
    /// Path cost of a voiced/unvoiced transition.
    pub voiced_unvoiced_cost: f32,
}

impl PitchParams {
    /// Praat's defaults for "To Pitch (ac)" with a 75-600 Hz range.
    pub const PRAAT: Self = Self {
        floor_hz: 75.0,
        ceiling_hz: 600.0,
        silence_threshold: 0.03,
        voicing_threshold: 0.45,
        octave_cost: 0.01,
        octave_jump_cost: 0.35,
        voiced_unvoiced_cost: 0.14,
    };
}

impl Default for PitchParams {
    fn default() -> Self {
        Self::PRAAT
    }
}

/// The candidates of one frame. Index 0 is always the unvoiced candidate (frequency 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidates {
    /// Number of valid entries (>= 1).
    pub len: usize,
    /// Frequency in Hz (0 for unvoiced).
    pub freq: [f32; MAX_CANDIDATES],
    /// log2 of the frequency (0 for unvoiced), precomputed for the path finder.
    pub log2f: [f32; MAX_CANDIDATES],
    /// Local score as used by the path finder (Praat's `delta`).
    pub score: [f32; MAX_CANDIDATES],
}

impl Candidates {
    /// A frame with only the unvoiced candidate.
    pub const UNVOICED: Self = Self {
        len: 1,
        freq: [0.0; MAX_CANDIDATES],
        log2f: [0.0; MAX_CANDIDATES],
        score: [0.0; MAX_CANDIDATES],
    };
}

/// Running estimate of the signal's absolute peak, for the silence threshold.
///
/// Praat divides each frame's local peak by the peak of the whole sound. A stream has no whole
/// sound, so this holds the largest local peak seen so far, decaying with a half-life of about
/// 30 s so that a microphone whose level drops is not judged silent forever, and never below a
/// floor of -60 dBFS so that a stream that starts with faint noise does not call it loud.
#[derive(Clone, Copy, Debug)]
pub struct GlobalPeak {
    value: f32,
}

impl GlobalPeak {
    /// Floor of the tracker, in full-scale units (-60 dBFS).
    pub const FLOOR: f32 = 1.0e-3;
    /// Per-frame decay factor (half-life 3000 frames of 10 ms).
    const DECAY: f32 = 0.999_769;

    /// A tracker at its floor.
    pub const fn new() -> Self {
        Self { value: Self::FLOOR }
    }

    /// Updates with a frame's local peak and returns the current global peak.
    pub fn update(&mut self, local_peak: f32) -> f32 {
        let decayed = self.value * Self::DECAY;
        let v = if local_peak > decayed {
            local_peak
        } else {
            decayed
        };
        self.value = if v > Self::FLOOR { v } else { Self::FLOOR };
        self.value
    }
}

impl Default for GlobalPeak {
    fn default() -> Self {
        Self::new()
    }
}

/// Precomputed tables and sizes for one pitch rate; analyses frames into [`Candidates`].
#[derive(Clone, Debug)]
pub struct PitchAnalyzer {
    params: PitchParams,
    rate: f32,
    window_len: usize,
    /// Samples either side of the centre for the local mean (one longest period).
    period: usize,
    /// Samples either side of the centre for the local peak (half a longest period).
    half_period: usize,
    min_lag: usize,
    max_lag: usize,
    hann: [f32; MAX_WINDOW],
    /// Normalized autocorrelation of the window, lags 0..MAX_LAGS.
    window_r: [f32; MAX_LAGS],
    /// Threshold on the local/global peak ratio below which voiced candidates cannot win.
    silent_ratio: f32,
}

impl PitchAnalyzer {
    /// Sizes for a pitch rate; returns `None` when the window does not fit the capacities.
    pub fn new(rate_hz: u32, params: PitchParams) -> Option<Self> {
        let mut me = Self::blank();
        me.configure(rate_hz, params)?;
        Some(me)
    }

    /// A placeholder to [`configure`](Self::configure) in place (tables zero; not usable as
    /// is). Cheap to build directly in its final place, unlike a finished analyzer returned by
    /// value.
    #[inline(always)]
    pub(crate) fn blank() -> Self {
        Self {
            params: PitchParams::PRAAT,
            rate: 0.0,
            window_len: 0,
            period: 0,
            half_period: 0,
            min_lag: 0,
            max_lag: 0,
            hann: [0.0; MAX_WINDOW],
            window_r: [0.0; MAX_LAGS],
            silent_ratio: 0.0,
        }
    }

    /// Sets every field as [`new`](Self::new) would, in place; `None` (with `self` left
    /// unusable) when the window does not fit the capacities.
    pub(crate) fn configure(&mut self, rate_hz: u32, params: PitchParams) -> Option<()> {
        let rate = rate_hz as f32;
        let Sizes {
            window_len,
            period,
            half_period,
            min_lag,
            max_lag,
        } = Sizes::new(rate_hz, &params)?;
        self.hann.fill(0.0);
        for (i, h) in self.hann.iter_mut().take(window_len).enumerate() {
            let phase = (i + 1) as f32 * 2.0 * core::f32::consts::PI / (window_len + 1) as f32;
            *h = 0.5 - 0.5 * super::frame::window_cos(phase);
        }
        self.params = params;
        self.rate = rate;
        self.window_len = window_len;
        self.period = period;
        self.half_period = half_period;
        self.min_lag = min_lag;
        self.max_lag = max_lag;
        self.silent_ratio = params.silence_threshold / (1.0 + params.voicing_threshold);
        let mut buf = [0.0f32; FFT_LEN];
        buf[..window_len].copy_from_slice(&self.hann[..window_len]);
        let mut r = [0.0f32; MAX_LAGS];
        autocorrelation(&mut buf, &mut r);
        if r[0] <= 0.0 {
            return None;
        }
        for (wr, &v) in self.window_r.iter_mut().zip(r.iter()) {
            *wr = v / r[0];
        }
        Some(())
    }

    /// Window length in samples (even).
    pub fn window_len(&self) -> usize {
        self.window_len
    }

    /// The parameters in use.
    pub fn params(&self) -> &PitchParams {
        &self.params
    }

    /// Mean over one longest period either side of the centre (Praat's local mean).
    fn local_mean(&self, x: &[f32]) -> f32 {
        let c = self.window_len / 2;
        let seg = &x[c - self.period..c + self.period];
        let mut s = 0.0f32;
        for &v in seg {
            s += v;
        }
        s / (2 * self.period) as f32
    }

    /// Analyses one window of `window_len()` samples. `global` tracks the running peak.
    /// Returns the candidates with their path-finder scores.
    // Out of line: once per frame, and its 3 KiB of buffers then stay off the caller's frame.
    #[inline(never)]
    pub fn analyze(&self, x: &[f32], global: &mut GlobalPeak, out: &mut Candidates) {
        *out = Candidates::UNVOICED;
        if x.len() != self.window_len {
            return;
        }
        let mean = self.local_mean(x);
        let mut buf = [0.0f32; FFT_LEN];
        for ((b, &v), &w) in buf.iter_mut().zip(x.iter()).zip(self.hann.iter()) {
            *b = (v - mean) * w;
        }
        let c = self.window_len / 2;
        let lo = c.saturating_sub(self.half_period);
        let hi = (c + self.half_period).min(self.window_len);
        let mut local_peak = 0.0f32;
        for &v in &buf[lo..hi] {
            let a = v.abs();
            if a > local_peak {
                local_peak = a;
            }
        }
        let p = &self.params;
        let silent;
        (out.score[0], silent) = unvoiced_score(p, self.silent_ratio, local_peak, global);
        if silent {
            return;
        }
        let mut r = [0.0f32; MAX_LAGS];
        autocorrelation(&mut buf, &mut r);
        if r[0].is_nan() || r[0] <= 0.0 || !r[0].is_finite() {
            return;
        }
        let inv0 = 1.0 / r[0];
        for (rv, &wr) in r.iter_mut().zip(self.window_r.iter()).skip(1) {
            *rv = if wr > 1e-6 { *rv * inv0 / wr } else { 0.0 };
        }
        r[0] = 1.0;
        let threshold = 0.5 * p.voicing_threshold;
        // Candidates ranked by Praat's "strength - octaveCost * log2(floor / f)".
        let mut rank = [0.0f32; MAX_CANDIDATES];
        let mut n = 1usize;
        let log2_range = (libm::log2f(p.floor_hz), libm::log2f(p.ceiling_hz));
        for i in self.min_lag.max(2)..self.max_lag {
            let (r0, r1, r2) = (r[i - 1], r[i], r[i + 1]);
            if !(r1 > threshold && r1 > r0 && r1 >= r2) {
                continue;
            }
            add_peak(
                p,
                self.rate,
                log2_range,
                i,
                [r0, r1, r2],
                &mut rank,
                &mut n,
                out,
            );
        }
        out.len = n;
    }
}

/// The analysis sizes for a pitch rate, the same for both arithmetics.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Sizes {
    /// Window length (even, at most [`MAX_WINDOW`]).
    pub window_len: usize,
    /// Samples either side of the centre for the local mean (one longest period).
    pub period: usize,
    /// Samples either side of the centre for the local peak.
    pub half_period: usize,
    /// Shortest lag searched.
    pub min_lag: usize,
    /// Lag past the longest searched.
    pub max_lag: usize,
}

impl Sizes {
    /// The sizes for `rate_hz`, or `None` when the window does not fit the capacities.
    pub(crate) fn new(rate_hz: u32, params: &PitchParams) -> Option<Self> {
        let rate = rate_hz as f32;
        let nominal = libm::floorf(3.0 * rate / params.floor_hz) as usize;
        let half = (nominal / 2).checked_sub(1)?;
        let window_len = 2 * half;
        if !(8..=MAX_WINDOW).contains(&window_len) {
            return None;
        }
        let period = libm::floorf(rate / params.floor_hz) as usize;
        let half_period = period / 2 + 1;
        let min_lag = (libm::ceilf(rate / params.ceiling_hz) as usize).max(2);
        let max_lag = (window_len / 3 + 2).min(MAX_LAGS - 2);
        if min_lag + 2 >= max_lag || period > half {
            return None;
        }
        Some(Self {
            window_len,
            period,
            half_period,
            min_lag,
            max_lag,
        })
    }
}

/// Praat's unvoiced strength for a frame with this local peak (the voicing threshold, plus a
/// bonus that grows as the frame falls below the silence threshold), updating the running
/// global peak; and whether the frame is silent, i.e. no voiced candidate can win it.
///
/// Below the silence ratio the unvoiced score exceeds 1.45 while a voiced score is at most
/// ~1.03, and staying voiced through this frame saves at most two voiced/unvoiced transitions
/// (2 x 0.14): the path finder can never choose a voiced candidate there, so the analysis
/// skips the autocorrelation. This is exact, not an approximation.
#[inline(always)]
pub(crate) fn unvoiced_score(
    p: &PitchParams,
    silent_ratio: f32,
    local_peak: f32,
    global: &mut GlobalPeak,
) -> (f32, bool) {
    let global_peak = global.update(local_peak);
    let ratio = if local_peak > global_peak {
        1.0
    } else {
        local_peak / global_peak
    };
    let silence_bonus = 2.0 - ratio / silent_ratio;
    let score = p.voicing_threshold
        + if silence_bonus > 0.0 {
            silence_bonus
        } else {
            0.0
        };
    let silent = local_peak == 0.0 || ratio < silent_ratio || !(local_peak.is_finite());
    (score, silent)
}

/// Adds the autocorrelation peak at lag `i` (normalized values `r` at lags `i - 1`, `i`,
/// `i + 1`) to the candidates: parabolic refinement, Praat's reflection of strengths above 1,
/// its octave-cost ranking (the weakest of a full set is replaced) and the path-finder score.
/// `log2_range` is `(log2 floor, log2 ceiling)`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn add_peak(
    p: &PitchParams,
    rate: f32,
    log2_range: (f32, f32),
    i: usize,
    r: [f32; 3],
    rank: &mut [f32; MAX_CANDIDATES],
    n: &mut usize,
    out: &mut Candidates,
) {
    let [r0, r1, r2] = r;
    let dr = 0.5 * (r2 - r0);
    let d2r = 2.0 * r1 - r0 - r2;
    let (lag, mut strength) = if d2r > 0.0 {
        (i as f32 + dr / d2r, r1 + 0.5 * dr * dr / d2r)
    } else {
        (i as f32, r1)
    };
    if strength > 1.0 {
        strength = 1.0 / strength;
    }
    let freq = rate / lag;
    if !(freq >= p.floor_hz * 0.5 && freq <= p.ceiling_hz) {
        return;
    }
    let l2 = libm::log2f(freq);
    let local_rank = strength + p.octave_cost * (l2 - log2_range.0);
    let place = if *n < MAX_CANDIDATES {
        *n += 1;
        *n - 1
    } else {
        let mut weakest = 1;
        for k in 2..MAX_CANDIDATES {
            if rank[k] < rank[weakest] {
                weakest = k;
            }
        }
        if local_rank <= rank[weakest] {
            return;
        }
        weakest
    };
    rank[place] = local_rank;
    out.freq[place] = freq;
    out.log2f[place] = l2;
    // Path-finder score: strength minus octave cost relative to the ceiling.
    out.score[place] = strength - p.octave_cost * (log2_range.1 - l2);
}

/// Autocorrelation `r[l] = sum_i x[i] x[i+l]` of `buf` (zero-padded signal, destroyed) for lags
/// `0..r.len()`, via two real FFTs: the power spectrum is real and even, so its forward
/// transform equals `FFT_LEN` times its inverse transform.
///
/// The power spectrum is built in `buf` itself (the FFT's output is `buf` seen as complex
/// bins): power `2j` and `2j + 1` go into bin `j`, whose own values were used two steps of `j`
/// earlier, so no second 2 KiB buffer is needed.
fn autocorrelation(buf: &mut [f32; FFT_LEN], r: &mut [f32]) {
    let half = FFT_LEN / 2;
    let nyquist = {
        let spec = rfft_512(buf);
        let power = |c: &microfft::Complex32| c.re * c.re + c.im * c.im;
        // Bin 0 packs DC (re) and Nyquist (im).
        let dc = spec[0].re * spec[0].re;
        let nyquist = spec[0].im * spec[0].im;
        spec[0].re = dc;
        spec[0].im = power(&spec[1]);
        for j in 1..half / 2 {
            let (lo, hi) = (power(&spec[2 * j]), power(&spec[2 * j + 1]));
            spec[j].re = lo;
            spec[j].im = hi;
        }
        nyquist
    };
    buf[half] = nyquist;
    for k in 1..half {
        buf[FFT_LEN - k] = buf[k];
    }
    let ac = rfft_512(buf);
    let scale = 1.0 / FFT_LEN as f32;
    for (rv, c) in r.iter_mut().zip(ac.iter()) {
        *rv = c.re * scale;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tone(freq: f32, rate: f32, n: usize, amp: f32) -> [f32; MAX_WINDOW] {
        let mut x = [0.0f32; MAX_WINDOW];
        for (i, v) in x.iter_mut().take(n).enumerate() {
            *v = amp * libm::sinf(2.0 * core::f32::consts::PI * freq * i as f32 / rate);
        }
        x
    }

    #[test]
    fn autocorrelation_matches_direct_sum() {
        let mut buf = [0.0f32; FFT_LEN];
        for (i, b) in buf.iter_mut().take(300).enumerate() {
            *b = libm::sinf(i as f32 * 0.3) + 0.1 * (i % 7) as f32;
        }
        let orig = buf;
        let mut r = [0.0f32; MAX_LAGS];
        autocorrelation(&mut buf, &mut r);
        for lag in [0usize, 1, 5, 40, 120, 160] {
            let direct: f32 = (0..300 - lag).map(|i| orig[i] * orig[i + lag]).sum();
            assert!(
                (r[lag] - direct).abs() <= 1e-3 * direct.abs().max(1.0),
                "lag {lag}: fft {} direct {direct}",
                r[lag]
            );
        }
    }

    #[test]
    fn pure_tone_best_candidate_is_its_frequency() {
        let an = PitchAnalyzer::new(8000, PitchParams::PRAAT).unwrap();
        for f in [80.0f32, 120.0, 200.0, 333.0, 550.0] {
            let x = tone(f, 8000.0, an.window_len(), 0.5);
            let mut g = GlobalPeak::new();
            let mut c = Candidates::UNVOICED;
            an.analyze(&x[..an.window_len()], &mut g, &mut c);
            let best = (1..c.len)
                .max_by(|&a, &b| c.score[a].partial_cmp(&c.score[b]).unwrap())
                .unwrap();
            let err = (c.freq[best] - f).abs() / f;
            assert!(err < 0.005, "{f} Hz -> {} Hz", c.freq[best]);
            assert!(c.score[best] > c.score[0], "{f} Hz should be voiced");
        }
    }

    #[test]
    fn silence_and_nan_free() {
        let an = PitchAnalyzer::new(8000, PitchParams::PRAAT).unwrap();
        let x = [0.0f32; MAX_WINDOW];
        let mut g = GlobalPeak::new();
        let mut c = Candidates::UNVOICED;
        an.analyze(&x[..an.window_len()], &mut g, &mut c);
        assert_eq!(c.len, 1);
        assert!(c.score[0] > 1.0);
    }

    #[test]
    fn rejects_windows_beyond_capacity() {
        assert!(PitchAnalyzer::new(16000, PitchParams::PRAAT).is_none());
        assert!(PitchAnalyzer::new(8000, PitchParams::PRAAT).is_some());
    }
}
