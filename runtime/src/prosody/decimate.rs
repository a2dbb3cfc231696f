//! Half-band decimation by two, in front of the pitch analysis.
//!
//! Pitch needs nothing above ~3 kHz, and autocorrelation cost grows with the rate, so the
//! pitch path runs at half the front-end rate (8 kHz for the 16 kHz default). The filter is
//! a 31-tap Blackman-windowed half-band FIR: every other tap is zero, the centre tap is 1/2,
//! so one output costs 9 multiply-adds. Its delay is 15 input samples; because 15 is odd, output
//! `j` is centred exactly on input sample `2 (j - 7)`, i.e. on decimated time index `j - 7`
//! ([`HalfBand::DELAY`]), which the front-end uses to keep pitch and intensity frames aligned.
//!
//! Invariants: no allocation, no panics (all indexing is on fixed arrays with masked indices),
//! state is a few hundred bytes.

/// Length of the ring the front-end keeps decimated samples in (a power of two, holding an
/// analysis window plus slack).
pub const PITCH_RING: usize = 512;

/// Number of taps of the half-band filter.
const TAPS: usize = 31;
/// Index of the centre tap.
const CENTRE: usize = TAPS / 2;
/// Number of distinct non-zero off-centre coefficients (odd offsets 1, 3, ..., 15).
const ODD: usize = CENTRE.div_ceil(2);

/// The half-band design: the windowed-sinc taps at odd offsets 1, 3, ..., 15 from the centre
/// and the scale that gives unity gain at DC (`1/2 + 2 * scale * sum(taps) = 1`).
fn design() -> ([f32; ODD], f32) {
    let mut taps = [0.0f32; ODD];
    let mut sum = 0.0f32;
    for (m, c) in taps.iter_mut().enumerate() {
        let k = (2 * m + 1) as f32;
        // sin(pi k / 2) for odd k = 2m + 1 is (-1)^m.
        let sign = if m % 2 == 0 { 1.0 } else { -1.0 };
        let sinc = sign / (core::f32::consts::PI * k);
        // Blackman window over 32 points so that the outermost taps are not zero.
        let phase = 2.0 * core::f32::consts::PI * k / (TAPS as f32 + 1.0);
        let w = 0.42
            + 0.5 * super::frame::window_cos(phase)
            + 0.08 * super::frame::window_cos(2.0 * phase);
        let h = sinc * w;
        *c = h;
        sum += 2.0 * h;
    }
    (taps, 0.5 / sum)
}

/// Streaming 2:1 decimator with a linear-phase half-band FIR.
#[derive(Clone, Debug)]
pub struct HalfBand {
    /// Coefficients at offsets 1, 3, 5, ... from the centre (symmetric).
    coef: [f32; ODD],
    /// History, written twice so the last `TAPS` samples are always contiguous.
    hist: [f32; 2 * TAPS],
    pos: usize,
    odd: bool,
}

impl HalfBand {
    /// Delay of the output in decimated samples (output `j` is centred on time index `j - DELAY`).
    pub const DELAY: usize = CENTRE.div_ceil(2) - 1;

    /// A decimator with zero history (the signal is taken as silent before its start).
    pub fn new() -> Self {
        let (taps, scale) = design();
        let mut coef = [0.0f32; ODD];
        for (c, &h) in coef.iter_mut().zip(taps.iter()) {
            *c = h * scale;
        }
        Self {
            coef,
            hist: [0.0; 2 * TAPS],
            pos: 0,
            odd: false,
        }
    }

    /// Feeds one input sample; returns an output sample after every second input.
    #[inline]
    pub fn push(&mut self, x: f32) -> Option<f32> {
        self.hist[self.pos] = x;
        self.hist[self.pos + TAPS] = x;
        self.pos += 1;
        if self.pos == TAPS {
            self.pos = 0;
        }
        self.odd = !self.odd;
        if self.odd {
            return None;
        }
        // The last TAPS samples, oldest first.
        let w = &self.hist[self.pos..self.pos + TAPS];
        let mut acc = 0.5 * w[CENTRE];
        for (m, c) in self.coef.iter().enumerate() {
            let k = 2 * m + 1;
            acc += c * (w[CENTRE - k] + w[CENTRE + k]);
        }
        Some(acc)
    }

    /// Input samples that the next `outputs` outputs take (`outputs` >= 1).
    #[inline]
    pub fn inputs_for(&self, outputs: u64) -> u64 {
        // An output comes on every second input; `odd` means the next input makes one.
        2 * outputs - self.odd as u64
    }

    /// [`push`](Self::push) for each of `xs` (i16 samples, scaled by 1/32768 as the
    /// front-end does), handing each output to `out`: the same arithmetic in a tight loop.
    // Out of line: its own registers (inlined into a large caller, its state spills).
    #[inline(never)]
    pub fn push_slice(&mut self, xs: &[i16], out: &mut impl FnMut(f32)) {
        let mut pos = self.pos;
        let mut odd = self.odd;
        for &s in xs {
            let x = s as f32 * (1.0 / 32768.0);
            self.hist[pos] = x;
            self.hist[pos + TAPS] = x;
            pos += 1;
            if pos == TAPS {
                pos = 0;
            }
            odd = !odd;
            if odd {
                continue;
            }
            // The last TAPS samples, oldest first.
            let Some(w) = self.hist.get(pos..pos + TAPS) else {
                continue;
            };
            let mut acc = 0.5 * w[CENTRE];
            for (m, c) in self.coef.iter().enumerate() {
                let k = 2 * m + 1;
                acc += c * (w[CENTRE - k] + w[CENTRE + k]);
            }
            out(acc);
        }
        self.pos = pos;
        self.odd = odd;
    }

    /// [`push_slice`](Self::push_slice) into `ring` at sample count `produced` (slot
    /// `produced % PITCH_RING`); returns the new count. Not generic, so it is compiled (and
    /// optimized) with the runtime whatever crate calls it.
    pub fn push_into(&mut self, xs: &[i16], ring: &mut [f32; PITCH_RING], produced: u64) -> u64 {
        let mut produced = produced;
        self.push_slice(xs, &mut |y| {
            ring[(produced % PITCH_RING as u64) as usize] = y;
            produced += 1;
        });
        produced
    }
}

impl Default for HalfBand {
    fn default() -> Self {
        Self::new()
    }
}

/// Fractional bits of [`HalfBandQ`]'s coefficients (Q15: the centre tap 1/2 is 16384).
const COEF_BITS: u32 = 15;
/// Fractional bits of the integer pitch path's samples: quarter LSBs of the `i16` input.
pub const SAMPLE_BITS: u32 = 2;

/// [`HalfBand`] in integers, for the fixed-point front-end: the same design with Q15
/// coefficients, the largest adjusted so that the gain at DC is exactly 1, an `i32`
/// accumulator, and outputs in quarter LSBs of the input ([`SAMPLE_BITS`]), rounded to
/// nearest. The accumulator cannot overflow: `|acc| <= 32768 * sum |h_q| < 2^31` because the
/// taps' absolute sum is below 2 (checked when the taps are made, and tested).
#[derive(Clone, Debug)]
pub struct HalfBandQ {
    /// Coefficients at offsets 1, 3, 5, ... from the centre, Q15.
    coef: [i32; ODD],
    /// History, written twice so the last `TAPS` samples are always contiguous.
    hist: [i16; 2 * TAPS],
    pos: usize,
    odd: bool,
}

impl HalfBandQ {
    /// A decimator with zero history.
    pub fn new() -> Self {
        let (taps, scale) = design();
        let one = 1i32 << COEF_BITS;
        let mut coef = [0i32; ODD];
        for (c, &h) in coef.iter_mut().zip(taps.iter()) {
            *c = libm::roundf(h * scale * one as f32) as i32;
        }
        // Unity gain at DC exactly: one/2 + 2 sum(coef) = one (the error lands on the
        // largest tap, where it is relatively smallest).
        let sum: i32 = coef.iter().sum();
        coef[0] += (one / 2 - 2 * sum) / 2;
        Self {
            coef,
            hist: [0; 2 * TAPS],
            pos: 0,
            odd: false,
        }
    }

    /// Input samples that the next `outputs` outputs take (`outputs` >= 1).
    #[inline]
    pub fn inputs_for(&self, outputs: u64) -> u64 {
        2 * outputs - self.odd as u64
    }

    /// Feeds one input sample; returns an output (quarter LSBs) after every second input.
    #[inline]
    pub fn push(&mut self, s: i16) -> Option<i32> {
        let mut y = None;
        self.push_slice(&[s], &mut |v| y = Some(v));
        y
    }

    /// [`push`](Self::push) for each of `xs`, handing each output to `out`.
    #[inline(never)]
    pub fn push_slice(&mut self, xs: &[i16], out: &mut impl FnMut(i32)) {
        let mut pos = self.pos;
        let mut odd = self.odd;
        for &s in xs {
            self.hist[pos] = s;
            self.hist[pos + TAPS] = s;
            pos += 1;
            if pos == TAPS {
                pos = 0;
            }
            odd = !odd;
            if odd {
                continue;
            }
            let Some(w) = self.hist.get(pos..pos + TAPS) else {
                continue;
            };
            let mut acc = (w[CENTRE] as i32) << (COEF_BITS - 1);
            for (m, &c) in self.coef.iter().enumerate() {
                let k = 2 * m + 1;
                let pair = w[CENTRE - k] as i32 + w[CENTRE + k] as i32;
                acc = acc.wrapping_add(c.wrapping_mul(pair));
            }
            let shift = COEF_BITS - SAMPLE_BITS;
            out(acc.wrapping_add(1 << (shift - 1)) >> shift);
        }
        self.pos = pos;
        self.odd = odd;
    }

    /// [`push_slice`](Self::push_slice) into `ring` at sample count `produced`; returns the
    /// new count (as [`HalfBand::push_into`]).
    pub fn push_into(&mut self, xs: &[i16], ring: &mut [i32; PITCH_RING], produced: u64) -> u64 {
        let mut produced = produced;
        self.push_slice(xs, &mut |y| {
            ring[(produced % PITCH_RING as u64) as usize] = y;
            produced += 1;
        });
        produced
    }
}

impl Default for HalfBandQ {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gain_at(freq_over_rate: f64) -> f64 {
        let mut hb = HalfBand::new();
        let n = 4000;
        let mut peak = 0.0f64;
        for i in 0..n {
            let x = libm::sin(2.0 * core::f64::consts::PI * freq_over_rate * i as f64) as f32;
            if let Some(y) = hb.push(x) {
                if i > 200 {
                    peak = peak.max((y as f64).abs());
                }
            }
        }
        peak
    }

    #[test]
    fn unity_dc_gain() {
        let mut hb = HalfBand::new();
        let mut last = 0.0;
        for _ in 0..100 {
            if let Some(y) = hb.push(1.0) {
                last = y;
            }
        }
        assert!((last - 1.0).abs() < 1e-5, "dc gain {last}");
    }

    #[test]
    fn passband_and_stopband() {
        // 1 kHz at 16 kHz passes nearly untouched; 6 kHz is strongly attenuated.
        let pass = gain_at(1000.0 / 16000.0);
        let stop = gain_at(6000.0 / 16000.0);
        assert!((pass - 1.0).abs() < 0.01, "passband gain {pass}");
        assert!(stop < 0.01, "stopband gain {stop}");
    }

    #[test]
    fn fixed_taps_sum_below_two_and_unity_dc() {
        let hb = HalfBandQ::new();
        let abs: i32 = (1 << 14) + 2 * hb.coef.iter().map(|c| c.abs()).sum::<i32>();
        assert!(abs < 2 << 15, "sum |h| = {}", abs as f64 / 32768.0);
        let mut q = HalfBandQ::new();
        let mut last = 0;
        for _ in 0..100 {
            if let Some(y) = q.push(-32768) {
                last = y;
            }
        }
        assert_eq!(last, -32768 * 4);
    }

    #[test]
    fn fixed_equals_float_within_three_lsbs() {
        // A chirp plus noise at full scale: the integer outputs (quarter LSBs) against the
        // f32 filter's, scaled to the same unit.
        let mut f = HalfBand::new();
        let mut q = HalfBandQ::new();
        let mut seed = 1u32;
        let mut worst = 0.0f64;
        for i in 0..8000 {
            seed = seed.wrapping_mul(1664525).wrapping_add(1013904223);
            let t = i as f64 / 16000.0;
            let v = 20000.0 * libm::sin(2.0 * core::f64::consts::PI * (100.0 + 2000.0 * t) * t)
                + ((seed >> 20) as f64 - 2048.0) * 4.0;
            let s = v as i16;
            let a = f.push(s as f32 / 32768.0);
            let b = q.push(s);
            assert_eq!(a.is_some(), b.is_some());
            if let (Some(a), Some(b)) = (a, b) {
                worst = worst.max((a as f64 * 131072.0 - b as f64).abs());
            }
        }
        // Each Q15 tap is within 2^-16 of its f32 value: at most 8 * 2^-16 times a pair of
        // samples (here below 2 * 24 300) in error, i.e. 6 LSBs, plus the output's rounding;
        // measured 1.75 LSBs (-81 dB re this signal).
        assert!(worst < 12.0, "{worst} quarter LSBs");
    }

    #[test]
    fn delay_is_integral_in_output_samples() {
        // An impulse at input 2*t0 must produce the largest output at j = t0 + DELAY.
        let t0 = 20;
        let mut hb = HalfBand::new();
        let mut best = (0usize, 0.0f32);
        let mut j = 0;
        for i in 0..200 {
            let x = if i == 2 * t0 { 1.0 } else { 0.0 };
            if let Some(y) = hb.push(x) {
                if y > best.1 {
                    best = (j, y);
                }
                j += 1;
            }
        }
        assert_eq!(best.0, t0 + HalfBand::DELAY);
        assert!((best.1 - 0.5).abs() < 1e-6);
    }
}
