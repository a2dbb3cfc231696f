//! Per-step prosody features, normalized to the speaker as the stream goes.
//!
//! A model trained on one voice must work on another: a deep male voice and a high female
//! voice differ by an octave in F0 and a microphone's gain shifts every intensity. So each
//! step's features are taken relative to running references of the *current* speaker:
//!
//! - `f0`: `log2(F0) - ref_f0` (octaves), `ref_f0` the running mean of `log2 F0` over voiced
//!   syllables; `None` for unvoiced steps (the mixture marginalizes it);
//! - `obs[0]`: `(intensity - ref_db) / 10`, `ref_db` the running mean intensity of syllables,
//!   clamped to [-6, 2] (pauses of digital silence are -300 dB);
//! - `obs[1]`: `ln(length in s)`.
//!
//! Running means use weight `1 / min(n, MEMORY)`: a plain average over the first `MEMORY` steps,
//! then an exponential average with that memory, so references settle within a few syllables and
//! then follow slow drifts. The first voiced syllable therefore has `f0 = 0`.
//!
//! This is the one implementation: the trainer calls it on the front-end's steps, so training
//! and device features are identical. O(1) state, no allocation, no panics, finite outputs.

use crate::prosody::{Step, StepKind};

/// Memory of the running references, in steps.
pub const MEMORY: u32 = 100;

/// Normalized features of one step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepFeatures {
    /// Relative log2 F0, `None` when unvoiced.
    pub f0: Option<f32>,
    /// (relative intensity / 10 dB, ln length).
    pub obs: [f32; 2],
    /// Whether the step is a pause step.
    pub pause: bool,
}

/// Running speaker references.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepNormalizer {
    ref_f0: f32,
    n_f0: u32,
    ref_db: f32,
    n_db: u32,
}

impl StepNormalizer {
    /// No references yet (they start from the first syllables).
    pub const fn new() -> Self {
        Self {
            ref_f0: 7.0,
            n_f0: 0,
            ref_db: 60.0,
            n_db: 0,
        }
    }

    /// Updates the references with `step` and returns its normalized features.
    pub fn push(&mut self, step: &Step) -> StepFeatures {
        let pause = step.kind == StepKind::Pause;
        let f0 = match step.f0_hz {
            Some(f) if f.is_finite() && f > 1.0 => {
                let l = libm::log2f(f);
                if !pause {
                    self.n_f0 = self.n_f0.saturating_add(1);
                    let w = 1.0 / self.n_f0.min(MEMORY) as f32;
                    self.ref_f0 += w * (l - self.ref_f0);
                }
                Some(l - self.ref_f0)
            }
            _ => None,
        };
        let db = if step.intensity_db.is_finite() {
            step.intensity_db
        } else {
            -300.0
        };
        if !pause && db > -100.0 {
            self.n_db = self.n_db.saturating_add(1);
            let w = 1.0 / self.n_db.min(MEMORY) as f32;
            self.ref_db += w * (db - self.ref_db);
        }
        let rel = ((db - self.ref_db) / 10.0).clamp(-6.0, 2.0);
        let len = step.length_s();
        let len = if len > 0.01 { len } else { 0.01 };
        StepFeatures {
            f0,
            obs: [rel, libm::logf(len)],
            pause,
        }
    }

    /// The speaker's running syllable intensity (dB).
    pub fn reference_db(&self) -> f32 {
        self.ref_db
    }
}

impl Default for StepNormalizer {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn syl(f0: Option<f32>, db: f32, frames: u32) -> Step {
        Step {
            kind: StepKind::Syllable,
            start_frame: 10,
            end_frame: 10 + frames,
            f0_hz: f0,
            intensity_db: db,
        }
    }

    #[test]
    fn an_octave_higher_voice_gives_the_same_features() {
        let mut a = StepNormalizer::new();
        let mut b = StepNormalizer::new();
        for i in 0..50 {
            let f = 100.0 + 20.0 * (i % 5) as f32;
            let db = 60.0 + (i % 3) as f32;
            let fa = a.push(&syl(Some(f), db, 20));
            // Twice the pitch and 12 dB more gain.
            let fb = b.push(&syl(Some(2.0 * f), db + 12.0, 20));
            let (x, y) = (fa.f0.unwrap(), fb.f0.unwrap());
            assert!((x - y).abs() < 1e-5, "{x} vs {y}");
            assert!((fa.obs[0] - fb.obs[0]).abs() < 1e-5);
        }
    }

    #[test]
    fn silence_and_garbage_stay_finite() {
        let mut n = StepNormalizer::new();
        for s in [
            syl(None, -300.0, 25),
            syl(Some(f32::NAN), f32::NAN, 0),
            syl(Some(f32::INFINITY), f32::INFINITY, 1),
        ] {
            let f = n.push(&s);
            assert!(f.obs.iter().all(|v| v.is_finite()));
            assert!(f.f0.is_none_or(|v| v.is_finite()));
        }
        let f = n.push(&syl(Some(150.0), 60.0, 20));
        assert_eq!(f.f0, Some(0.0));
        assert!((f.obs[1] - libm::logf(0.2)).abs() < 1e-6);
    }
}
