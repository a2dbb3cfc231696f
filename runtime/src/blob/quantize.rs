//! The one quantizer of the blob's `i16` tables (docs/blob-format.md, "scaled i16 table" and
//! `library.frame_scales`): a value is stored as `q: i16` in `-QUANT_MAX..=QUANT_MAX` and read
//! back as `offset + scale * q`.
//!
//! - [`quantize_symmetric`]: `offset = 0`, `scale = max |v| / QUANT_MAX` (cost tables, CRF
//!   weights);
//! - [`quantize_range`]: `offset` the middle of the values' range, `scale` half the range over
//!   `QUANT_MAX` (library frames, whose channels sit far from zero).
//!
//! The scale is rounded to `f32` first and the values are quantized against that rounded
//! scale, the one the reader multiplies by, so every value comes back within half a step
//! (`scale / 2`, up to `f32` rounding of the product). Non-finite inputs are the caller's to
//! refuse; here they map to 0 (NaN) or the ends (infinities) and never panic.

/// Largest stored magnitude (`-32768` is never written, so the tables are symmetric).
pub const QUANT_MAX: i16 = i16::MAX;

/// A table's quantization: value = `offset + scale * q`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantization {
    /// Step between neighbouring codes (> 0).
    pub scale: f32,
    /// Value of code 0.
    pub offset: f32,
}

impl Quantization {
    /// Symmetric around 0 for values up to `max_abs` in magnitude (`scale = 1` for an all-zero
    /// table).
    pub fn symmetric(max_abs: f64) -> Self {
        let scale = if max_abs > 0.0 && max_abs.is_finite() {
            (max_abs / QUANT_MAX as f64) as f32
        } else {
            1.0
        };
        // A scale that underflows f32 would divide by zero below.
        let scale = if scale > 0.0 && scale.is_finite() {
            scale
        } else {
            1.0
        };
        Self { scale, offset: 0.0 }
    }

    /// Centred on the range `lo..=hi` (`scale = 1` for a constant channel).
    pub fn range(lo: f64, hi: f64) -> Self {
        let offset = ((lo + hi) / 2.0) as f32;
        let sym = Self::symmetric((hi - lo) / 2.0);
        Self {
            scale: sym.scale,
            offset: if offset.is_finite() { offset } else { 0.0 },
        }
    }

    /// The code of `v`: `round((v - offset) / scale)`, clamped to `+-QUANT_MAX`.
    pub fn code(&self, v: f64) -> i16 {
        let x = (v - self.offset as f64) / self.scale as f64;
        if x.is_nan() {
            return 0;
        }
        let m = QUANT_MAX as f64;
        let r = libm::round(x);
        (if r > m {
            m
        } else if r < -m {
            -m
        } else {
            r
        }) as i16
    }

    /// The value of code `q` as the reader computes it.
    pub fn value(&self, q: i16) -> f32 {
        self.offset + self.scale * q as f32
    }
}

/// Quantizes `values` symmetrically into `out` (as many as both hold); returns the scale.
pub fn quantize_symmetric(values: &[f64], out: &mut [i16]) -> f32 {
    let max = values
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let q = Quantization::symmetric(max);
    for (o, &v) in out.iter_mut().zip(values) {
        *o = q.code(v);
    }
    q.scale
}

/// The range quantization of `values` (finite ones; `scale = 1, offset = 0` if none).
pub fn quantize_range(values: impl IntoIterator<Item = f64>) -> Quantization {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return Quantization::symmetric(0.0);
    }
    Quantization::range(lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn symmetric_round_trip_is_within_half_a_step() {
        let w: [f64; 7] = [-3.0, -1.25, 0.0, 0.1, 1.0, 2.9, 3.0];
        let mut q = [0i16; 7];
        let scale = quantize_symmetric(&w, &mut q);
        assert_eq!(q[0], -QUANT_MAX);
        assert_eq!(q[6], QUANT_MAX);
        let t = Quantization { scale, offset: 0.0 };
        for (x, c) in w.iter().zip(q) {
            assert!((t.value(c) as f64 - x).abs() <= 0.5 * scale as f64 * 1.0001);
        }
    }

    #[test]
    fn range_round_trip_is_within_half_a_step_far_from_zero() {
        let v: [f64; 50] = core::array::from_fn(|i| 170.0 + i as f64 * 0.2);
        let t = quantize_range(v.iter().copied());
        assert!((t.offset - 174.9).abs() < 1e-4);
        for &x in &v {
            let back = t.value(t.code(x)) as f64;
            // Half a step plus f32 rounding of a value near 180.
            assert!(
                (back - x).abs() <= 0.5 * t.scale as f64 + 2e-5,
                "{x} -> {back}"
            );
        }
    }

    #[test]
    fn degenerate_tables_do_not_divide_by_zero() {
        let mut q = [7i16; 3];
        assert_eq!(quantize_symmetric(&[0.0, 0.0, 0.0], &mut q), 1.0);
        assert_eq!(q, [0, 0, 0]);
        let t = quantize_range([5.0, 5.0]);
        assert_eq!((t.scale, t.offset, t.code(5.0)), (1.0, 5.0, 0));
        assert_eq!(Quantization::symmetric(1e-300).scale, 1.0);
        assert_eq!(t.code(f64::NAN), 0);
        assert_eq!(t.code(f64::INFINITY), QUANT_MAX);
    }
}
