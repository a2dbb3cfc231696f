//! Per-frame pitch candidates in integers: [`PitchAnalyzer`](super::pitch::PitchAnalyzer)'s
//! method for the fixed-point front-end ([`Fixed`](super::arith::Fixed)).
//!
//! The same steps as the `f32` analyzer (local mean, Hann window, autocorrelation with
//! Boersma's window correction, peaks above half the voicing threshold, parabolic refinement,
//! Praat's octave-cost ranking), with the costly part in integers:
//!
//! 1. the window (samples in quarter LSBs, `i32`) minus its local mean (rounded to the
//!    nearest quarter LSB) is shifted right until its largest magnitude fits 15 bits, and
//!    multiplied by a Q15 Hann table, rounding to nearest: an `i16` window;
//! 2. its energy (lag 0) is summed in `u64`; the window is shifted right again (rounding) until
//!    the energy is below 2^29, so that every lag's sum fits an `i32` (Cauchy-Schwarz: no lag
//!    exceeds lag 0) and the products are single 32-bit multiplies;
//! 3. the autocorrelation is summed directly, only at the lags the peak search reads
//!    (`min_lag - 1 ..= max_lag`, about 100 of them) instead of by two FFTs;
//! 4. the window correction multiplies each lag by `1 / r_w(lag)` in Q16, the window's own
//!    normalized autocorrelation computed exactly from the same Q15 table, into an `i64`;
//!    the peak test (`r > voicing_threshold / 2`, a local maximum) compares those integers
//!    with the threshold times the energy, so nothing is divided per lag;
//! 5. only at a peak are its three values turned into `f32` and handed to the same candidate
//!    code as the `f32` analyzer (`pitch::add_peak`), with the same unvoiced score
//!    (`pitch::unvoiced_score`).
//!
//! Where it differs from the `f32` analyzer: the window has 15 bits (the `f32` one 24), the
//! Hann table is rounded to Q15 and the window correction to Q16; the peak threshold is
//! rounded to Q16. The candidates' frequencies and strengths therefore differ in their last
//! digits, which can tip a path-finder decision where two candidates are nearly equal
//! (measured against the `f32` path and Praat by `gesture-sim eval-prosody --fixed`).
//!
//! Invariants: no allocation, no floating point per sample or per lag, no panics for any
//! sample values (sums are bounded as above; silent and zero-energy frames return early).

use super::decimate::SAMPLE_BITS;
use super::pitch::{
    add_peak, unvoiced_score, Candidates, GlobalPeak, PitchParams, Sizes, MAX_CANDIDATES, MAX_LAGS,
    MAX_WINDOW,
};

/// Fractional bits of the Hann table.
const HANN_BITS: u32 = 15;
/// Fractional bits of the window correction and the peak threshold.
const CORR_BITS: u32 = 16;
/// The window's energy is brought below this before the lags are summed in `i32`.
const ENERGY_LIMIT: u64 = 1 << 29;

/// Precomputed tables and sizes for one pitch rate; analyses integer windows.
#[derive(Clone, Debug)]
pub struct PitchAnalyzerQ {
    params: PitchParams,
    rate: f32,
    sizes: Sizes,
    /// Hann window, Q15.
    hann: [i16; MAX_WINDOW],
    /// `1 / r_w(lag)`, the window's normalized autocorrelation, Q16 (0 where `r_w` is ~0).
    inv_wr: [u32; MAX_LAGS],
    /// Half the voicing threshold, Q16.
    threshold: i64,
    silent_ratio: f32,
    /// `(log2 floor, log2 ceiling)`.
    log2_range: (f32, f32),
}

impl PitchAnalyzerQ {
    /// Sizes and tables for a pitch rate; `None` when the window does not fit the capacities.
    pub fn new(rate_hz: u32, params: PitchParams) -> Option<Self> {
        let mut me = Self::blank();
        me.configure(rate_hz, params)?;
        Some(me)
    }

    /// A placeholder to [`configure`](Self::configure) in place (not usable as is).
    #[inline(always)]
    pub(crate) fn blank() -> Self {
        Self {
            params: PitchParams::PRAAT,
            rate: 0.0,
            sizes: Sizes {
                window_len: 0,
                period: 0,
                half_period: 0,
                min_lag: 0,
                max_lag: 0,
            },
            hann: [0; MAX_WINDOW],
            inv_wr: [0; MAX_LAGS],
            threshold: 0,
            silent_ratio: 0.0,
            log2_range: (0.0, 0.0),
        }
    }

    /// Sets every field as [`new`](Self::new) would, in place.
    pub(crate) fn configure(&mut self, rate_hz: u32, params: PitchParams) -> Option<()> {
        let sizes = Sizes::new(rate_hz, &params)?;
        let n = sizes.window_len;
        self.hann.fill(0);
        let one = (1i32 << HANN_BITS) as f32;
        for (i, h) in self.hann.iter_mut().take(n).enumerate() {
            let phase = (i + 1) as f32 * 2.0 * core::f32::consts::PI / (n + 1) as f32;
            let v = (0.5 - 0.5 * super::frame::window_cos(phase)) * one;
            *h = libm::roundf(v).min(i16::MAX as f32) as i16;
        }
        // The window's autocorrelation, exactly, from the same table.
        let lag_sum = |lag: usize| -> i64 {
            let h = &self.hann[..n];
            h.iter()
                .zip(h.iter().skip(lag))
                .map(|(&a, &b)| a as i64 * b as i64)
                .sum()
        };
        let r0 = lag_sum(0);
        if r0 <= 0 {
            return None;
        }
        self.inv_wr.fill(0);
        for lag in 0..MAX_LAGS.min(n) {
            let r = lag_sum(lag);
            // r / r0 > 1e-6, as the f32 analyzer's cut-off.
            if r > r0 / 1_000_000 {
                let q = ((r0 as u64) << CORR_BITS) / r as u64;
                self.inv_wr[lag] = q.min(u32::MAX as u64) as u32;
            }
        }
        self.params = params;
        self.rate = rate_hz as f32;
        self.sizes = sizes;
        // At most 2^32, so that the peak test's threshold times the energy (below 2^30) fits
        // an i64 whatever a blob says; a threshold that large already passes no peak, as the
        // f32 analyzer's would (a normalized autocorrelation is at most 1).
        self.threshold = (libm::roundf(0.5 * params.voicing_threshold * (1u32 << CORR_BITS) as f32)
            as i64)
            .min(1 << 32);
        self.silent_ratio = params.silence_threshold / (1.0 + params.voicing_threshold);
        self.log2_range = (libm::log2f(params.floor_hz), libm::log2f(params.ceiling_hz));
        Some(())
    }

    /// Window length in samples (even).
    pub fn window_len(&self) -> usize {
        self.sizes.window_len
    }

    /// Analyses one window of `window_len()` samples (quarter LSBs, as
    /// [`HalfBandQ`](super::decimate::HalfBandQ) gives them). `global` tracks the running peak.
    #[inline(never)]
    pub fn analyze(&self, x: &[i32], global: &mut GlobalPeak, out: &mut Candidates) {
        *out = Candidates::UNVOICED;
        let Sizes {
            window_len: n,
            period,
            half_period,
            min_lag,
            max_lag,
        } = self.sizes;
        if x.len() != n || n > MAX_WINDOW || max_lag + 1 >= n {
            return;
        }
        // Local mean over one longest period either side of the centre, to the nearest
        // quarter LSB (samples are below 2^18 in magnitude: the sum fits an i32).
        let c = n / 2;
        let seg = &x[c - period..c + period];
        let sum: i32 = seg.iter().fold(0i32, |a, &v| a.wrapping_add(v));
        let count = 2 * period as i32;
        let mean = sum.wrapping_add(if sum >= 0 { count / 2 } else { -count / 2 }) / count;
        // Shift until the largest deviation fits 15 bits.
        let largest = x
            .iter()
            .fold(0u32, |m, &v| m.max(v.wrapping_sub(mean).unsigned_abs()));
        let shift = (32 - largest.leading_zeros()).saturating_sub(15);
        let mut buf = [0i16; MAX_WINDOW];
        let round = 1i32 << (HANN_BITS - 1);
        for ((b, &v), &h) in buf.iter_mut().zip(x.iter()).zip(self.hann.iter()) {
            let d = v.wrapping_sub(mean) >> shift;
            *b = ((d * h as i32 + round) >> HANN_BITS) as i16;
        }
        let buf = &mut buf[..n];
        let lo = c.saturating_sub(half_period);
        let hi = (c + half_period).min(n);
        let peak = buf[lo..hi]
            .iter()
            .fold(0u32, |m, &v| m.max(v.unsigned_abs() as u32));
        // In full-scale units, as the f32 analyzer's: quarter LSBs times 2^shift over 2^17.
        let local_peak =
            peak as f32 * ((1u64 << shift) as f32 / (1u32 << (15 + SAMPLE_BITS)) as f32);
        let p = &self.params;
        let silent;
        (out.score[0], silent) = unvoiced_score(p, self.silent_ratio, local_peak, global);
        if silent {
            return;
        }
        // Energy below ENERGY_LIMIT, so that every lag's sum fits an i32.
        let energy: u64 = buf.iter().map(|&v| (v as i32 * v as i32) as u64).sum();
        let mut down = 0u32;
        while (energy >> (2 * down)) >= ENERGY_LIMIT {
            down += 1;
        }
        if down > 0 {
            let half = 1i32 << (down - 1);
            for v in buf.iter_mut() {
                *v = ((*v as i32 + half) >> down) as i16;
            }
        }
        let r0 = lag_sum(buf, 0);
        if r0 <= 0 {
            return;
        }
        // Window-corrected lags min_lag - 1 ..= max_lag, Q16 (index lag - first).
        let first = min_lag.max(2) - 1;
        let mut rc = [0i64; MAX_LAGS];
        for lag in first..=max_lag {
            rc[lag - first] = lag_sum(buf, lag) as i64 * self.inv_wr[lag] as i64;
        }
        let threshold = self.threshold * r0 as i64;
        let to_f32 = 1.0 / (r0 as f32 * (1u32 << CORR_BITS) as f32);
        let mut rank = [0.0f32; MAX_CANDIDATES];
        let mut count = 1usize;
        for i in first + 1..max_lag {
            let k = i - first;
            let (a, b, c) = (rc[k - 1], rc[k], rc[k + 1]);
            if !(b > threshold && b > a && b >= c) {
                continue;
            }
            let r = [a as f32 * to_f32, b as f32 * to_f32, c as f32 * to_f32];
            add_peak(
                p,
                self.rate,
                self.log2_range,
                i,
                r,
                &mut rank,
                &mut count,
                out,
            );
        }
        out.len = count;
    }
}

/// `sum_i x[i] x[i + lag]` in `i32`; the caller keeps `sum x^2` below 2^30, which bounds every
/// lag (wrapping arithmetic only so that no input can panic).
#[inline(always)]
fn lag_sum(x: &[i16], lag: usize) -> i32 {
    let Some(tail) = x.get(lag..) else {
        return 0;
    };
    let mut acc = 0i32;
    for (&a, &b) in x.iter().zip(tail.iter()) {
        acc = acc.wrapping_add((a as i32).wrapping_mul(b as i32));
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::super::pitch::PitchAnalyzer;
    use super::*;

    /// A tone in quarter LSBs and the same in full-scale units.
    fn tone(freq: f64, amp: f64, n: usize) -> ([i32; MAX_WINDOW], [f32; MAX_WINDOW]) {
        let mut q = [0i32; MAX_WINDOW];
        let mut f = [0.0f32; MAX_WINDOW];
        for i in 0..n {
            let v = amp * libm::sin(2.0 * core::f64::consts::PI * freq * i as f64 / 8000.0);
            let s = libm::round(v * 131072.0) as i32;
            q[i] = s;
            f[i] = s as f32 / 131072.0;
        }
        (q, f)
    }

    fn best(c: &Candidates) -> usize {
        (1..c.len)
            .max_by(|&a, &b| c.score[a].partial_cmp(&c.score[b]).unwrap())
            .unwrap()
    }

    #[test]
    fn candidates_match_the_f32_analyzer_on_tones() {
        let q = PitchAnalyzerQ::new(8000, PitchParams::PRAAT).unwrap();
        let f = PitchAnalyzer::new(8000, PitchParams::PRAAT).unwrap();
        let n = q.window_len();
        assert_eq!(n, f.window_len());
        for freq in [80.0, 120.0, 200.0, 333.0, 550.0] {
            for amp in [0.9, 0.01, 0.0005] {
                let (xq, xf) = tone(freq, amp, n);
                let (mut gq, mut gf) = (GlobalPeak::new(), GlobalPeak::new());
                let (mut cq, mut cf) = (Candidates::UNVOICED, Candidates::UNVOICED);
                q.analyze(&xq[..n], &mut gq, &mut cq);
                f.analyze(&xf[..n], &mut gf, &mut cf);
                let (bq, bf) = (best(&cq), best(&cf));
                let err = (cq.freq[bq] as f64 - freq).abs() / freq;
                assert!(err < 0.005, "{freq} Hz at {amp}: {} Hz", cq.freq[bq]);
                assert!((cq.freq[bq] - cf.freq[bf]).abs() < 0.002 * cf.freq[bf]);
                assert!((cq.score[bq] - cf.score[bf]).abs() < 0.01, "{freq} {amp}");
                assert!((cq.score[0] - cf.score[0]).abs() < 1e-3, "{freq} {amp}");
                assert!(cq.score[bq] > cq.score[0], "{freq} Hz should be voiced");
            }
        }
    }

    #[test]
    fn any_voicing_threshold_gives_the_f32_analyzer_s_answer_without_overflow() {
        // Every threshold a blob may hold (finite, not negative), up to the largest f32.
        for t in [0.0, 0.45, 1.0, 1e6, 1e20, f32::MAX] {
            let params = PitchParams {
                voicing_threshold: t,
                ..PitchParams::PRAAT
            };
            let (Some(q), Some(f)) = (
                PitchAnalyzerQ::new(8000, params),
                PitchAnalyzer::new(8000, params),
            ) else {
                continue;
            };
            let n = q.window_len();
            let (xq, xf) = tone(200.0, 0.9, n);
            let (mut gq, mut gf) = (GlobalPeak::new(), GlobalPeak::new());
            let (mut cq, mut cf) = (Candidates::UNVOICED, Candidates::UNVOICED);
            q.analyze(&xq[..n], &mut gq, &mut cq);
            f.analyze(&xf[..n], &mut gf, &mut cf);
            // The same candidates at the same lags.
            assert_eq!(cq.len, cf.len, "threshold {t}");
            for i in 1..cq.len {
                assert!((cq.freq[i] - cf.freq[i]).abs() <= 0.002 * cf.freq[i], "{t}");
            }
        }
    }

    #[test]
    fn full_scale_square_wave_and_silence_do_not_overflow() {
        let q = PitchAnalyzerQ::new(8000, PitchParams::PRAAT).unwrap();
        let n = q.window_len();
        let mut x = [0i32; MAX_WINDOW];
        for (i, v) in x.iter_mut().take(n).enumerate() {
            // Beyond full scale (the decimator's overshoot): +-1.2 in quarter LSBs.
            *v = if (i / 20) % 2 == 0 { 157_286 } else { -157_286 };
        }
        let mut g = GlobalPeak::new();
        let mut c = Candidates::UNVOICED;
        q.analyze(&x[..n], &mut g, &mut c);
        let b = best(&c);
        assert!((c.freq[b] - 200.0).abs() < 2.0, "{}", c.freq[b]);
        // Any i32 window (far beyond what the decimator gives) runs without a panic.
        let wild: [i32; MAX_WINDOW] = core::array::from_fn(|i| {
            if i % 3 == 0 {
                i32::MAX
            } else {
                i32::MIN + i as i32
            }
        });
        q.analyze(&wild[..n], &mut g, &mut c);
        assert!(c.len >= 1 && c.score[..c.len].iter().all(|v| v.is_finite()));
        let silent = [0i32; MAX_WINDOW];
        q.analyze(&silent[..n], &mut g, &mut c);
        assert_eq!(c.len, 1);
        assert!(c.score[0] > 1.0);
    }
}
