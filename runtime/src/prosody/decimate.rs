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

/// Number of taps of the half-band filter.
const TAPS: usize = 31;
/// Index of the centre tap.
const CENTRE: usize = TAPS / 2;
/// Number of distinct non-zero off-centre coefficients (odd offsets 1, 3, ..., 15).
const ODD: usize = CENTRE.div_ceil(2);

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
        let mut coef = [0.0f32; ODD];
        let mut sum = 0.0f64;
        for (m, c) in coef.iter_mut().enumerate() {
            let k = (2 * m + 1) as f64;
            // sin(pi k / 2) for odd k = 2m + 1 is (-1)^m.
            let sign = if m % 2 == 0 { 1.0 } else { -1.0 };
            let sinc = sign / (core::f64::consts::PI * k);
            // Blackman window over 32 points so that the outermost taps are not zero.
            let phase = 2.0 * core::f64::consts::PI * k / (TAPS as f64 + 1.0);
            let w = 0.42
                + 0.5 * super::frame::window_cos(phase)
                + 0.08 * super::frame::window_cos(2.0 * phase);
            let h = sinc * w;
            *c = h as f32;
            sum += 2.0 * h;
        }
        // Unity gain at DC: 1/2 (centre) + sum of off-centre taps = 1.
        let scale = 0.5 / sum;
        for c in coef.iter_mut() {
            *c = (*c as f64 * scale) as f32;
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
}

impl Default for HalfBand {
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
