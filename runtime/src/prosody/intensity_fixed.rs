//! Intensity in integers: [`Intensity`](super::intensity::Intensity)'s method for the
//! fixed-point front-end ([`Fixed`](super::arith::Fixed)).
//!
//! Per sample, a 1 ms block adds the sample to an `i32` sum and its square to a `u64` sum:
//! exact, so no reference level is needed against a large DC offset (the `f32` blocks need
//! one). Per frame, the blocks are weighted with Praat's Kaiser window sampled at block
//! centres (as the `f32` path) rounded to Q20, into `i64` sums, and the mean-removed power is
//! formed exactly in `i128`:
//!
//! `n^2 sum w (x - m)^2 = n^2 S2w - 2 n S1 S1w + S1^2 Sw`, with `m = S1 / n`,
//!
//! then divided (one `f32` division) and turned into dB with `libm::log10f`, once per frame.
//! Ranges: a block's square sum is at most `16 * 2^30 = 2^34`, a weighted sum at most
//! `2^20 * 88 * 2^34 < 2^61`, and the terms of the power at most about `2^82`.
//!
//! Where it differs from the `f32` path: the window weights are rounded to Q20 (the far tails,
//! below `2^-21`, are raised to `2^-20` so that no block counts for nothing); the power is
//! exact where the `f32` sums round, which matters only in near-silent windows with a DC
//! offset, where the `f32` difference of sums cancels. Elsewhere the two agree far within
//! 0.01 dB (tested against the `f32` path below).
//!
//! Invariants: fixed memory ([`MAX_BLOCKS`] blocks), no allocation, no panics, finite output.

use super::intensity::{block_weights, MAX_BLOCKS, MAX_HALF_BLOCKS, SILENT_DB};

/// Highest rate (the front-end's): 16-sample blocks keep a block's square sum below 2^34.
const MAX_RATE_HZ: u32 = 16_000;
/// Fractional bits of the window weights.
const WEIGHT_BITS: u32 = 20;

#[derive(Clone, Copy, Debug)]
struct Block {
    sum: i32,
    sum_sq: u64,
    min: i16,
    max: i16,
}

impl Block {
    /// Silence (before the stream's start).
    const ZERO: Self = Self {
        sum: 0,
        sum_sq: 0,
        min: 0,
        max: 0,
    };
    const EMPTY: Self = Self {
        sum: 0,
        sum_sq: 0,
        min: i16::MAX,
        max: i16::MIN,
    };
}

/// Integer block accumulator and windowed intensity.
#[derive(Clone, Debug)]
pub struct IntensityQ {
    block_len: u32,
    half_blocks: usize,
    /// Window weight of the block whose centre is `(i + 0.5)` ms from the frame centre, Q20.
    weights: [u32; MAX_HALF_BLOCKS],
    /// Sum of the weights over both sides, times the block length (Q20).
    weight_sum: i64,
    ring: [Block; MAX_BLOCKS],
    blocks: u64,
    cur: Block,
    cur_n: u32,
    /// Scale from squared i16 units to Pa^2 re (2e-5 Pa)^2.
    scale: f32,
}

impl IntensityQ {
    /// Sizes for a sample rate (a multiple of 1000 Hz) and a pitch floor.
    pub fn new(rate_hz: u32, floor_hz: f32) -> Option<Self> {
        let mut me = Self::blank();
        me.configure(rate_hz, floor_hz)?;
        Some(me)
    }

    /// A placeholder to [`configure`](Self::configure) in place (not usable as is).
    #[inline(always)]
    pub(crate) fn blank() -> Self {
        Self {
            block_len: 0,
            half_blocks: 0,
            weights: [0; MAX_HALF_BLOCKS],
            weight_sum: 0,
            ring: [Block::ZERO; MAX_BLOCKS],
            blocks: 0,
            cur: Block::ZERO,
            cur_n: 0,
            scale: 0.0,
        }
    }

    /// Sets every field as [`new`](Self::new) would, in place.
    pub(crate) fn configure(&mut self, rate_hz: u32, floor_hz: f32) -> Option<()> {
        if rate_hz % 1000 != 0 || rate_hz == 0 || rate_hz > MAX_RATE_HZ {
            return None;
        }
        let (half_blocks, weights) = block_weights(floor_hz)?;
        self.weights.fill(0);
        let mut sum = 0i64;
        for (w, v) in self.weights.iter_mut().zip(weights) {
            // At least 1: a tail weight rounded to 0 would make a window whose only change
            // lies in its tails silent (-300 dB) where the f32 path and Praat see a level.
            *w = (libm::roundf(v * (1u32 << WEIGHT_BITS) as f32) as u32).max(1);
            sum += 2 * *w as i64;
        }
        let block_len = rate_hz / 1000;
        self.block_len = block_len;
        self.half_blocks = half_blocks;
        self.weight_sum = sum * block_len as i64;
        self.ring.fill(Block::ZERO);
        self.blocks = 0;
        self.cur = Block::EMPTY;
        self.cur_n = 0;
        self.scale = 1.0 / (32768.0f32 * 32768.0 * 4.0e-10);
        Some(())
    }

    /// Blocks either side of a frame's centre.
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
        self.push_slice(&[s]);
    }

    /// Adds samples, with the open block kept in registers.
    #[inline(never)]
    pub fn push_slice(&mut self, xs: &[i16]) {
        let mut cur = self.cur;
        let mut n = self.cur_n;
        for &s in xs {
            let x = s as i32;
            cur.sum = cur.sum.wrapping_add(x);
            cur.sum_sq = cur.sum_sq.wrapping_add((x * x) as u32 as u64);
            cur.min = cur.min.min(s);
            cur.max = cur.max.max(s);
            n += 1;
            if n >= self.block_len {
                self.ring[(self.blocks % MAX_BLOCKS as u64) as usize] = cur;
                self.blocks += 1;
                cur = Block::EMPTY;
                n = 0;
            }
        }
        self.cur = cur;
        self.cur_n = n;
    }

    /// Intensity (dB) of the frame centred on the boundary before block `centre`; `None`
    /// until its blocks are complete or once they have left the ring.
    pub fn frame_db(&self, centre: u64) -> Option<f32> {
        let h = self.half_blocks as u64;
        if centre + h > self.blocks || self.blocks > centre.saturating_sub(h) + MAX_BLOCKS as u64 {
            return None;
        }
        let (mut s1, mut s1w, mut s2w) = (0i64, 0i64, 0i64);
        let mut lo = i16::MAX;
        let mut hi = i16::MIN;
        let mut n_blocks = 0i64;
        for i in 0..self.half_blocks {
            let w = self.weights[i] as i64;
            for b in [centre + i as u64, centre.wrapping_sub(i as u64 + 1)] {
                let blk = if b < self.blocks {
                    self.ring[(b % MAX_BLOCKS as u64) as usize]
                } else {
                    Block::ZERO
                };
                s1 += blk.sum as i64;
                s1w += w * blk.sum as i64;
                s2w += w * blk.sum_sq as i64;
                lo = lo.min(blk.min);
                hi = hi.max(blk.max);
                n_blocks += 1;
            }
        }
        if lo >= hi {
            return Some(SILENT_DB);
        }
        let n = (n_blocks * self.block_len as i64) as i128;
        let sw = self.weight_sum as i128;
        let (s1, s1w, s2w) = (s1 as i128, s1w as i128, s2w as i128);
        let num = n * n * s2w - 2 * n * s1 * s1w + s1 * s1 * sw;
        let den = n * n * sw;
        if num <= 0 || den <= 0 {
            return Some(SILENT_DB);
        }
        let p = num as f32 / den as f32 * self.scale;
        if p.is_nan() || p <= 1.0e-30 || !p.is_finite() {
            return Some(SILENT_DB);
        }
        Some(10.0 * libm::log10f(p))
    }
}

#[cfg(test)]
mod tests {
    use super::super::intensity::Intensity;
    use super::*;

    fn both(x: &[i16]) -> (IntensityQ, Intensity) {
        let mut q = IntensityQ::new(16000, 75.0).unwrap();
        let mut f = Intensity::new(16000, 75.0).unwrap();
        q.push_slice(x);
        f.push_slice(x);
        (q, f)
    }

    #[test]
    fn planted_levels_match_the_f32_path_and_the_formula() {
        // Sines at planted levels (dB re full scale) with a DC offset and a little noise.
        let mut seed = 7u32;
        for level_db in [-3.0f64, -20.0, -45.0, -70.0] {
            let amp = 32768.0 * libm::pow(10.0, level_db / 20.0);
            let mut x = [0i16; 16000];
            for (i, v) in x.iter_mut().enumerate() {
                seed = seed.wrapping_mul(1664525).wrapping_add(1013904223);
                let noise = ((seed >> 24) as f64 - 128.0) / 256.0;
                let s = amp * libm::sin(i as f64 * 0.137) + 300.0 + noise;
                *v = libm::round(s) as i16;
            }
            let (q, f) = both(&x);
            for centre in [300u64, 600, 900] {
                let (a, b) = (q.frame_db(centre), f.frame_db(centre));
                let (Some(a), Some(b)) = (a, b) else {
                    assert_eq!(a.is_some(), b.is_some());
                    continue;
                };
                assert!(
                    (a - b).abs() < 0.01,
                    "{level_db} dB at {centre}: {a} vs {b}"
                );
                // Mean square amp^2 / 2 in Pa re 2e-5.
                let want = 10.0 * libm::log10(amp * amp / 2.0 / (32768.0 * 32768.0) / 4.0e-10);
                assert!((a as f64 - want).abs() < 0.1, "{level_db}: {a} vs {want}");
            }
        }
    }

    #[test]
    fn silence_dc_and_extremes_are_finite() {
        for level in [0i16, 1000, -32768] {
            let (q, _) = both(&[level; 16000]);
            assert_eq!(q.frame_db(900), Some(SILENT_DB));
        }
        let mut x = [0i16; 16000];
        for (i, v) in x.iter_mut().enumerate() {
            *v = if i % 2 == 0 { i16::MAX } else { i16::MIN };
        }
        let (q, f) = both(&x);
        let (a, b) = (q.frame_db(900).unwrap(), f.frame_db(900).unwrap());
        assert!(a.is_finite() && (a - b).abs() < 0.01, "{a} vs {b}");
    }
}
