//! Deterministic speech-like test audio, generated in memory (for benchmarks and smoke tests).
//!
//! Not speech, but it exercises every path of the front-end the way speech does: phrases of
//! 3-9 syllables (120-320 ms each, ~4 per second) separated by 150-700 ms pauses, some
//! digitally silent and some with a faint noise floor; a voiced harmonic source (harmonics up
//! to 4 kHz, 1/k amplitude) whose F0 glides down each phrase between 250 and 90 Hz with a
//! small accent per syllable; a raised-cosine amplitude envelope per syllable; and 20-60 ms
//! noise bursts (fricatives/plosives) before about a third of the syllables.
//!
//! Same `(seconds, rate, seed)`, same samples, on every platform. The random numbers come from
//! a hand-written SplitMix64 (eight lines) so that host-sim does not need `rand` for a
//! benchmark signal. Allocates the output; never panics for finite `seconds` >= 0.

use std::f64::consts::PI;

/// SplitMix64 (Steele, Lea and Flood 2014): tiny, fast, good enough for test signals.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator for `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// `seconds` of speech-like audio at `rate_hz`, peak about half full scale.
pub fn speech_like(seconds: f64, rate_hz: u32, seed: u64) -> Vec<i16> {
    let rate = rate_hz as f64;
    let n = (seconds.max(0.0) * rate).round() as usize;
    let mut out = vec![0i16; n];
    let mut rng = SplitMix64::new(seed);
    let mut pos = (rng.range(0.05, 0.3) * rate) as usize; // leading silence
    let mut phase = 0.0f64; // source phase in cycles, continuous across a phrase
    while pos < n {
        // One phrase.
        let syllables = 3 + (rng.unit() * 7.0) as usize;
        let f0_start = rng.range(170.0, 250.0);
        let f0_end = rng.range(90.0, 130.0);
        let level = rng.range(0.25, 0.5);
        let lens: Vec<usize> = (0..syllables)
            .map(|_| (rng.range(0.12, 0.32) * rate) as usize)
            .collect();
        let phrase_len: usize = lens.iter().sum();
        let mut t0 = pos;
        for &len in &lens {
            let accent = rng.range(0.9, 1.15);
            let gain = level * rng.range(0.6, 1.0);
            let burst = if rng.unit() < 0.35 {
                (rng.range(0.02, 0.06) * rate) as usize
            } else {
                0
            };
            for i in 0..len {
                let k = t0 + i;
                if k >= n {
                    break;
                }
                let along = (k - pos) as f64 / phrase_len.max(1) as f64;
                let f0 = (f0_start + (f0_end - f0_start) * along) * accent;
                phase += f0 / rate;
                phase -= phase.floor();
                let env = 0.5 - 0.5 * (2.0 * PI * (i as f64 + 0.5) / len as f64).cos();
                let harmonics = ((4000.0 / f0) as usize).clamp(1, 40);
                let mut v = 0.0;
                for h in 1..=harmonics {
                    v += (2.0 * PI * h as f64 * phase).sin() / h as f64;
                }
                let mut x = gain * env * v * 0.5;
                if i < burst {
                    x += gain * 0.6 * (rng.unit() - 0.5);
                }
                out[k] = (x * 32767.0).round().clamp(-32768.0, 32767.0) as i16;
            }
            t0 += len;
        }
        pos = t0;
        // Pause: digital silence or a faint noise floor.
        let pause = (rng.range(0.15, 0.7) * rate) as usize;
        let floor = if rng.unit() < 0.5 { 0.0 } else { 30.0 };
        for v in out.iter_mut().take((pos + pause).min(n)).skip(pos) {
            *v = (floor * (rng.unit() - 0.5)).round() as i16;
        }
        pos += pause;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use gesture_runtime::prosody::ProsodyConfig;

    #[test]
    fn deterministic_and_seed_dependent() {
        let a = speech_like(2.0, 16_000, 7);
        assert_eq!(a.len(), 32_000);
        assert_eq!(a, speech_like(2.0, 16_000, 7));
        assert_ne!(a, speech_like(2.0, 16_000, 8));
        assert!(speech_like(0.0, 16_000, 1).is_empty());
    }

    #[test]
    fn looks_like_speech_to_the_front_end() {
        let x = speech_like(10.0, 16_000, 1);
        let (frames, steps) =
            gesture_trainer::features::prosody_of(&x, &ProsodyConfig::DEFAULT).unwrap();
        let voiced: Vec<f32> = frames.iter().filter_map(|f| f.f0_hz).collect();
        let share = voiced.len() as f64 / frames.len() as f64;
        assert!((0.3..0.9).contains(&share), "voiced share {share}");
        assert!(voiced.iter().all(|&f| (80.0..300.0).contains(&f)));
        let syl = crate::eval::count_syllables(&steps);
        // About 4 syllables per second of speech, speech about 70 % of the time.
        assert!((15..=50).contains(&syl), "{syl} syllables");
    }
}
