//! The analysis frame: the 10 ms hop every stage of the front end counts in, and the cosine
//! its analysis windows are computed with (at configuration time, never per sample).

/// Frame hop in seconds.
pub const HOP_S: f64 = 0.01;

/// `cos(x)` for the analysis windows computed at configuration time, in `f32` like everything
/// else on the device: the argument reduced to `[-pi, pi]`, then the Taylor series to the 24th
/// power (error below 1e-6 for the windows' phases, which stay within `[0, 4 pi]`; reducing a
/// larger `f32` argument costs accuracy, 1.4e-6 at 40). Written here because `libm`'s sine and cosine with their argument reduction
/// cost kilobytes of code on a Cortex-M, and in `f32` because a board without a
/// double-precision unit (every Cortex-M4F and M33) would otherwise link the software `f64`
/// routines (about 3 KiB) for configuration alone.
pub(crate) fn window_cos(x: f32) -> f32 {
    let tau = 2.0 * core::f32::consts::PI;
    let mut r = x - tau * libm::floorf(x / tau + 0.5);
    if !r.is_finite() {
        r = 0.0;
    }
    let r2 = r * r;
    let (mut term, mut sum) = (1.0f32, 1.0f32);
    let mut k = 0.0f32;
    while k < 24.0 {
        term *= -r2 / ((k + 1.0) * (k + 2.0));
        sum += term;
        k += 2.0;
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_cos_agrees_with_libm() {
        let mut worst = 0.0f64;
        // The windows' phases lie in [0, 2 pi] (and twice that for the decimator's Blackman).
        for i in 0..4_000 {
            let x = -8.0 + i as f64 * 0.004;
            worst = worst.max((window_cos(x as f32) as f64 - libm::cos((x as f32) as f64)).abs());
        }
        assert!(worst < 1e-6, "{worst}");
    }
}
