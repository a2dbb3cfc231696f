//! Intensity in dB, as Praat's "To Intensity" (minimum pitch 75 Hz, subtract mean), streamed.
//!
//! Praat squares the mean-removed signal and weights it with a Kaiser window
//! `I0((2 pi^2 + 0.5) sqrt(1 - x^2))` spanning `6.4 / floor` seconds (85 ms at 75 Hz), then
//! reports `10 log10(mean / (2e-5)^2)`, i.e. dB re the hearing threshold with full scale = 1 Pa.
//!
//! Doing that per frame costs a weighted sum over ~1400 samples. Instead, samples are summed
//! into 1 ms blocks (sum and sum of squares, O(1) per sample), and a frame is a weighted sum of
//! ~86 blocks with the window sampled at block centres; the window is so smooth over 1 ms that
//! this changes the result by far less than 0.01 dB (tested against the direct sum below).
//! Praat's plain-mean subtraction is exact from the block sums:
//! `sum w (x-m)^2 = sum w x^2 - 2 m sum w x + m^2 sum w`.
//!
//! Numerics: a large DC offset under a faint signal would make that difference cancel
//! catastrophically in f32. So each block stores its sums relative to its own first sample
//! (an exact integer), and a frame re-references every block exactly to the centre block's
//! reference before combining; the sums that meet in the subtraction are then of the size of
//! the signal around its local level, not of the DC. A window of constant samples (digital
//! silence, pure DC) has zero power, reported as Praat does: -300 dB.
//!
//! Invariants: fixed memory ([`MAX_BLOCKS`] blocks), no allocation, no panics, finite output.

/// Ring capacity in blocks (1 ms each). Must hold the window plus the decision lag.
pub const MAX_BLOCKS: usize = 256;
/// Most blocks on either side of the centre (42.7 ms at 75 Hz).
pub const MAX_HALF_BLOCKS: usize = 44;
/// Reported level of a window with zero power (Praat's convention).
pub const SILENT_DB: f32 = -300.0;

#[derive(Clone, Copy, Debug, Default)]
struct Block {
    /// Reference level: the block's first sample.
    reference: i16,
    /// Sum of `x - reference`.
    sum: f32,
    /// Sum of `(x - reference)^2`.
    sum_sq: f32,
    min: i16,
    max: i16,
}

impl Block {
    /// All zero (`Block::default()`), as a constant.
    const ZERO: Self = Self {
        reference: 0,
        sum: 0.0,
        sum_sq: 0.0,
        min: 0,
        max: 0,
    };
    const EMPTY: Self = Self {
        reference: 0,
        sum: 0.0,
        sum_sq: 0.0,
        min: i16::MAX,
        max: i16::MIN,
    };
}

/// Block accumulator and windowed intensity.
#[derive(Clone, Debug)]
pub struct Intensity {
    block_len: u32,
    half_blocks: usize,
    /// Window weight of the block whose centre is `(i + 0.5)` ms from the frame centre.
    weights: [f32; MAX_HALF_BLOCKS],
    weight_sum: f32,
    ring: [Block; MAX_BLOCKS],
    /// Blocks completed so far.
    blocks: u64,
    cur: Block,
    cur_n: u32,
    /// Scale from squared i16 units to Pa^2 re (2e-5 Pa)^2.
    scale: f32,
}

/// Praat's window for a pitch floor, in 1 ms blocks: the blocks either side of a frame's
/// centre (its half length, 3.2 / floor s, rounded up) and the Kaiser weight (1 at the
/// centre) of each, the block whose centre is `(i + 0.5)` ms from the frame's centre first.
/// `None` when the half length is 0 or over [`MAX_HALF_BLOCKS`]. Both front-ends' intensity
/// take their weights from here.
pub(crate) fn block_weights(floor_hz: f32) -> Option<(usize, impl Iterator<Item = f32>)> {
    let half_ms = 3.2e3 / floor_hz;
    if !(half_ms > 0.0 && half_ms <= MAX_HALF_BLOCKS as f32) {
        return None;
    }
    let half_blocks = libm::ceilf(half_ms) as usize;
    let beta = 2.0 * core::f32::consts::PI * core::f32::consts::PI + 0.5;
    let peak = bessel_i0(beta);
    Some((
        half_blocks,
        (0..half_blocks).map(move |i| {
            let x = (i as f32 + 0.5) / half_ms;
            let root = libm::sqrtf((1.0 - x * x).max(0.0));
            bessel_i0(beta * root) / peak
        }),
    ))
}

/// Modified Bessel function of the first kind, order 0 (power series; converges for all x;
/// within 1e-6 of the `f64` series, relative, for the window's arguments, 0 to 20.2).
pub(crate) fn bessel_i0(x: f32) -> f32 {
    let q = 0.25 * x * x;
    let mut term = 1.0f32;
    let mut sum = 1.0f32;
    let mut k = 1.0f32;
    while term > 1e-9 * sum {
        term *= q / (k * k);
        sum += term;
        k += 1.0;
    }
    sum
}

impl Intensity {
    /// Sizes for a sample rate (must be a multiple of 1000 Hz) and a pitch floor.
    /// Returns `None` when the window does not fit the capacities.
    pub fn new(rate_hz: u32, floor_hz: f32) -> Option<Self> {
        let mut me = Self::blank();
        me.configure(rate_hz, floor_hz)?;
        Some(me)
    }

    /// A placeholder to [`configure`](Self::configure) in place (not usable as is). Cheap to
    /// build directly in its final place, unlike a finished value returned by value.
    #[inline(always)]
    pub(crate) fn blank() -> Self {
        Self {
            block_len: 0,
            half_blocks: 0,
            weights: [0.0; MAX_HALF_BLOCKS],
            weight_sum: 0.0,
            ring: [Block::ZERO; MAX_BLOCKS],
            blocks: 0,
            cur: Block::ZERO,
            cur_n: 0,
            scale: 0.0,
        }
    }

    /// Sets every field as [`new`](Self::new) would, in place; `None` (with `self` left
    /// unusable) when the window does not fit the capacities.
    pub(crate) fn configure(&mut self, rate_hz: u32, floor_hz: f32) -> Option<()> {
        if rate_hz % 1000 != 0 || rate_hz == 0 {
            return None;
        }
        let (half_blocks, weights) = block_weights(floor_hz)?;
        self.weights.fill(0.0);
        let mut weight_sum = 0.0f32;
        for (w, v) in self.weights.iter_mut().zip(weights) {
            *w = v;
            weight_sum += 2.0 * v;
        }
        let block_len = rate_hz / 1000;
        let full_scale = 32768.0f32;
        self.block_len = block_len;
        self.half_blocks = half_blocks;
        self.weight_sum = weight_sum * block_len as f32;
        self.ring.fill(Block::ZERO);
        self.blocks = 0;
        self.cur = Block::EMPTY;
        self.cur_n = 0;
        self.scale = 1.0 / (full_scale * full_scale * 4.0e-10);
        Some(())
    }

    /// Samples either side of the centre that a frame needs, in whole blocks.
    pub fn half_blocks(&self) -> usize {
        self.half_blocks
    }

    /// Blocks completed so far.
    pub fn blocks(&self) -> u64 {
        self.blocks
    }

    /// Forgets all input.
    pub fn reset(&mut self) {
        self.blocks = 0;
        self.cur = Block::EMPTY;
        self.cur_n = 0;
    }

    /// Adds one sample.
    #[inline]
    pub fn push(&mut self, s: i16) {
        if self.cur_n == 0 {
            self.cur.reference = s;
        }
        let x = (s as i32 - self.cur.reference as i32) as f32;
        self.cur.sum += x;
        self.cur.sum_sq += x * x;
        if s < self.cur.min {
            self.cur.min = s;
        }
        if s > self.cur.max {
            self.cur.max = s;
        }
        self.cur_n += 1;
        if self.cur_n == self.block_len {
            self.ring[(self.blocks % MAX_BLOCKS as u64) as usize] = self.cur;
            self.blocks += 1;
            self.cur = Block::EMPTY;
            self.cur_n = 0;
        }
    }

    /// [`push`](Self::push) for each of `xs`, with the open block kept in registers.
    // Out of line: its own registers (inlined into a large caller, its state spills).
    #[inline(never)]
    pub fn push_slice(&mut self, xs: &[i16]) {
        let mut cur = self.cur;
        let mut n = self.cur_n;
        for &s in xs {
            if n == 0 {
                cur.reference = s;
            }
            let x = (s as i32 - cur.reference as i32) as f32;
            cur.sum += x;
            cur.sum_sq += x * x;
            if s < cur.min {
                cur.min = s;
            }
            if s > cur.max {
                cur.max = s;
            }
            n += 1;
            if n == self.block_len {
                self.ring[(self.blocks % MAX_BLOCKS as u64) as usize] = cur;
                self.blocks += 1;
                cur = Block::EMPTY;
                n = 0;
            }
        }
        self.cur = cur;
        self.cur_n = n;
    }

    /// Intensity (dB) of the frame centred on the boundary before block `centre`.
    /// Blocks before the stream's start count as silence. Returns `None` if a needed block is
    /// not complete yet or has left the ring.
    pub fn frame_db(&self, centre: u64) -> Option<f32> {
        let h = self.half_blocks as u64;
        if centre + h > self.blocks || self.blocks > centre.saturating_sub(h) + MAX_BLOCKS as u64 {
            return None;
        }
        let reference = if centre < self.blocks {
            self.ring[(centre % MAX_BLOCKS as u64) as usize].reference
        } else {
            0
        };
        let n_b = self.block_len as f32;
        let mut s1 = 0.0f32;
        let mut s1w = 0.0f32;
        let mut s2w = 0.0f32;
        let mut lo = i16::MAX;
        let mut hi = i16::MIN;
        let mut n_blocks = 0u32;
        for i in 0..self.half_blocks {
            let w = self.weights[i];
            // Block right of centre at offset i, and left at offset i (wraps below the start).
            for b in [centre + i as u64, centre.wrapping_sub(i as u64 + 1)] {
                let blk = if b < self.blocks {
                    self.ring[(b % MAX_BLOCKS as u64) as usize]
                } else {
                    // Before the start of the stream: silence.
                    Block::default()
                };
                // Exact change of reference: x - R = (x - r_b) + (r_b - R).
                let d = (blk.reference as i32 - reference as i32) as f32;
                let b1 = blk.sum + n_b * d;
                let b2 = blk.sum_sq + 2.0 * d * blk.sum + n_b * d * d;
                s1 += b1;
                s1w += w * b1;
                s2w += w * b2;
                lo = lo.min(blk.min);
                hi = hi.max(blk.max);
                n_blocks += 1;
            }
        }
        if lo >= hi {
            return Some(SILENT_DB);
        }
        let n = (n_blocks * self.block_len) as f32;
        let m = s1 / n;
        let sw = self.weight_sum;
        let power = (s2w - 2.0 * m * s1w + m * m * sw) / sw;
        let p = power * self.scale;
        if p.is_nan() || p <= 1.0e-30 || !p.is_finite() {
            return Some(SILENT_DB);
        }
        Some(10.0 * libm::log10f(p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Bessel series in `f64` (the reference's).
    fn bessel_i0_f64(x: f64) -> f64 {
        let q = 0.25 * x * x;
        let (mut term, mut sum, mut k) = (1.0f64, 1.0f64, 1.0f64);
        while term > 1e-17 * sum {
            term *= q / (k * k);
            sum += term;
            k += 1.0;
        }
        sum
    }

    #[test]
    fn the_f32_bessel_series_is_the_f64_one_to_single_precision() {
        for i in 0..=210 {
            let x = i as f64 * 0.1;
            let (a, b) = (bessel_i0(x as f32) as f64, bessel_i0_f64((x as f32) as f64));
            assert!((a - b).abs() <= 1e-6 * b, "I0({x}) = {a}, f64 {b}");
        }
        // Known values: I0(0) = 1, I0(1) = 1.2660658777520082.
        assert_eq!(bessel_i0(0.0), 1.0);
        assert!((bessel_i0(1.0) as f64 - 1.266_065_877_752_008_2).abs() < 2e-7);
    }

    /// Praat's direct formula on a slice of samples around a centre (f64 reference).
    fn direct_db(x: &[i16], centre: usize, rate: usize) -> f64 {
        let half_s = 3.2 / 75.0;
        let half = (half_s * rate as f64).floor() as usize;
        let beta = 2.0 * core::f64::consts::PI * core::f64::consts::PI + 0.5;
        let seg: [f64; 2048] = {
            let mut a = [0.0f64; 2048];
            for (k, i) in (centre - half..=centre + half).enumerate() {
                a[k] = x[i] as f64 / 32768.0;
            }
            a
        };
        let n = 2 * half + 1;
        let mean: f64 = seg[..n].iter().sum::<f64>() / n as f64;
        let (mut sxw, mut sw) = (0.0, 0.0);
        for (k, v) in seg[..n].iter().enumerate() {
            let xx = (k as f64 - half as f64) / (half_s * rate as f64);
            let w = bessel_i0_f64(beta * (1.0 - xx * xx).max(0.0).sqrt());
            sxw += (v - mean) * (v - mean) * w;
            sw += w;
        }
        10.0 * (sxw / sw / 4.0e-10).log10()
    }

    #[test]
    fn block_window_matches_direct_kaiser_sum() {
        let rate = 16000usize;
        let mut x = [0i16; 8000];
        let mut seed = 12345u32;
        for (i, v) in x.iter_mut().enumerate() {
            seed = seed.wrapping_mul(1664525).wrapping_add(1013904223);
            let noise = ((seed >> 16) as f32 / 65536.0 - 0.5) * 2000.0;
            let env = 1.0 + 0.8 * libm::sinf(i as f32 * 0.002);
            let tone = 6000.0 * libm::sinf(i as f32 * 0.09);
            *v = ((tone + noise) * env + 500.0) as i16;
        }
        let mut it = Intensity::new(rate as u32, 75.0).unwrap();
        for &s in &x {
            it.push(s);
        }
        for centre_block in [60u64, 100, 200, 250, 400] {
            let got = it.frame_db(centre_block);
            let want = direct_db(&x, centre_block as usize * 16, rate);
            if centre_block + 44 > 500 || it.blocks() > centre_block - 44 + MAX_BLOCKS as u64 {
                assert!(got.is_none());
                continue;
            }
            let got = got.unwrap() as f64;
            assert!(
                (got - want).abs() < 0.02,
                "block {centre_block}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn digital_silence_and_dc_are_silent() {
        for level in [0i16, 1000, -32768] {
            let mut it = Intensity::new(16000, 75.0).unwrap();
            for _ in 0..16000 {
                it.push(level);
            }
            assert_eq!(it.frame_db(900), Some(SILENT_DB));
        }
    }

    #[test]
    fn full_scale_sine_level() {
        // A full-scale sine has mean square 1/2 Pa^2: 10 log10(0.5 / 4e-10) = 90.97 dB.
        let mut it = Intensity::new(16000, 75.0).unwrap();
        for i in 0..16000 {
            let v = 32767.0 * libm::sinf(2.0 * core::f32::consts::PI * 440.0 * i as f32 / 16000.0);
            it.push(v as i16);
        }
        let db = it.frame_db(900).unwrap();
        assert!((db - 90.97).abs() < 0.05, "{db}");
    }

    #[test]
    fn faint_tone_under_large_dc_is_measured() {
        // 0.5 FS of DC under a 20-LSB tone: f32 cancellation would ruin a naive sum.
        let mut it = Intensity::new(16000, 75.0).unwrap();
        for i in 0..32000 {
            let v = 16384.0 + 20.0 * libm::sinf(i as f32 * 0.1);
            it.push(v as i16);
        }
        let db = it.frame_db(1900).unwrap();
        // RMS of a 20-LSB sine: 20/sqrt(2)/32768 Pa -> 10 log10(...) ~ 24.7 dB; i16 truncation
        // adds up to ~1/12 LSB^2 of noise.
        let want = 10.0 * libm::log10f((200.0 + 1.0 / 12.0) / (32768.0 * 32768.0) / 4.0e-10);
        assert!((db - want).abs() < 0.5, "{db} vs {want}");
    }
}
