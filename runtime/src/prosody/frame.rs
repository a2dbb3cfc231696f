//! The analysis frame: the 10 ms hop every stage of the front end counts in, and the cosine
//! its analysis windows are computed with (at configuration time, never per sample).

/// Frame hop in seconds.
pub const HOP_S: f64 = 0.01;

/// `cos(x)` in `f64` for the analysis windows computed at configuration time: the argument
/// reduced to `[-pi, pi]`, then the Taylor series to the 30th power (error below 1e-15, as
/// `libm::cos` for these arguments). Written here because `libm`'s `f64` sine and cosine with
/// their argument reduction are about 3.7 KiB of code on a Cortex-M4, and nothing else on the
/// device needs them.
pub(crate) fn window_cos(x: f64) -> f64 {
    let tau = 2.0 * core::f64::consts::PI;
    let mut r = x - tau * libm::floor(x / tau + 0.5);
    if !r.is_finite() {
        r = 0.0;
    }
    let r2 = r * r;
    let (mut term, mut sum) = (1.0f64, 1.0f64);
    let mut k = 0.0f64;
    while k < 30.0 {
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
        for i in 0..20_000 {
            let x = -40.0 + i as f64 * 0.004;
            worst = worst.max((window_cos(x) - libm::cos(x)).abs());
        }
        assert!(worst < 1e-14, "{worst}");
    }
}
