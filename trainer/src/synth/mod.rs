//! A synthetic corpus with planted truth: speech-like audio and gesture motion, both driven by
//! hidden style states (see [`styles`]), deterministic per seed.
//!
//! Every learning step needs data with a known answer, in any amount, without a download. A
//! take is a WAV (16 kHz, 16-bit) and a BVH (upper-body skeleton, 30 fps) of the same length;
//! `truth.json` records the state of every syllable, every gesture segment and every state run.

pub mod gesture;
pub mod speech;
pub mod styles;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// Front-end rate of the synthetic audio (Hz).
pub const AUDIO_RATE: u32 = 16_000;

/// What to generate.
#[derive(Clone, Copy, Debug)]
pub struct SynthParams {
    /// Total length (minutes).
    pub minutes: f64,
    /// Seed: the same seed gives the same corpus, byte for byte.
    pub seed: u64,
    /// Length of one take (seconds); the last take may be shorter.
    pub take_seconds: f64,
}

impl Default for SynthParams {
    fn default() -> Self {
        Self {
            minutes: 2.0,
            seed: 1,
            take_seconds: 60.0,
        }
    }
}

/// One generated take: audio, motion and their truth.
#[derive(Clone, Debug)]
pub struct Take {
    /// File stem (`take_000`, ...).
    pub stem: String,
    /// Length (s).
    pub duration_s: f64,
    /// 16 kHz mono PCM.
    pub audio: Vec<i16>,
    /// Motion frames (at [`gesture::FPS`]).
    pub frames: usize,
    /// `frames x gesture::CHANNELS` BVH channel values.
    pub motion: Vec<f64>,
    /// Planted truth.
    pub truth: TakeTruth,
}

/// Planted truth of one take.
#[derive(Clone, Debug, Serialize)]
pub struct TakeTruth {
    /// File stem.
    pub stem: String,
    /// Length (s).
    pub duration_s: f64,
    /// The state runs tiling the take.
    pub state_runs: Vec<styles::StateRun>,
    /// Every planted syllable with its state.
    pub syllables: Vec<speech::Syllable>,
    /// Every planted gesture segment with its state.
    pub segments: Vec<gesture::Segment>,
}

/// Planted truth of a whole corpus (`truth.json`).
#[derive(Clone, Debug, Serialize)]
pub struct Truth {
    /// Format tag.
    pub format: &'static str,
    /// Seed used.
    pub seed: u64,
    /// The synthetic speaker.
    pub speaker: speech::Speaker,
    /// The planted states, by index.
    pub states: Vec<styles::Style>,
    /// Per-take truth.
    pub takes: Vec<TakeTruth>,
}

/// Generates take `index` of a corpus (independent of the other takes).
pub fn generate_take(seed: u64, index: usize, duration_s: f64, speaker: &speech::Speaker) -> Take {
    let styles = styles::styles();
    let mut rng = take_rng(seed, index, 1);
    let track = styles::StateTrack::draw(&mut rng, duration_s, styles.len());
    let syllables = speech::plan(&mut rng, &track, &styles, speaker, duration_s);
    let audio = speech::render(&mut rng, &syllables, duration_s, AUDIO_RATE);
    let mut grng = take_rng(seed, index, 2);
    let (segments, frames, motion) = gesture::generate(&mut grng, &track, &styles, duration_s);
    let stem = format!("take_{index:03}");
    Take {
        stem: stem.clone(),
        duration_s,
        audio,
        frames,
        motion,
        truth: TakeTruth {
            stem,
            duration_s,
            state_runs: track.runs,
            syllables,
            segments,
        },
    }
}

/// The speaker of a corpus seed.
pub fn speaker_for(seed: u64) -> speech::Speaker {
    let mut rng = take_rng(seed, usize::MAX, 0);
    speech::Speaker::draw(&mut rng)
}

/// Generates a whole corpus in memory, takes in order, calling `progress` after each.
pub fn generate(
    params: &SynthParams,
    mut progress: impl FnMut(usize, usize),
) -> (Vec<Take>, Truth) {
    let total = (params.minutes * 60.0).max(0.0);
    let n = (total / params.take_seconds).ceil().max(1.0) as usize;
    let speaker = speaker_for(params.seed);
    let mut takes = Vec::with_capacity(n);
    for i in 0..n {
        let dur = (total - i as f64 * params.take_seconds).min(params.take_seconds);
        takes.push(generate_take(params.seed, i, dur.max(1.0), &speaker));
        progress(i + 1, n);
    }
    let truth = Truth {
        format: "gesture-synth-truth/1",
        seed: params.seed,
        speaker,
        states: styles::styles().to_vec(),
        takes: takes.iter().map(|t| t.truth.clone()).collect(),
    };
    (takes, truth)
}

/// Seed for take `index` of a corpus seeded with `seed`: takes are independent streams, so a
/// take's content does not depend on how many takes are generated.
pub fn take_rng(seed: u64, index: usize, stream: u64) -> ChaCha8Rng {
    let mut rng =
        ChaCha8Rng::seed_from_u64(seed ^ (index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    rng.set_stream(stream);
    rng
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::prosody_of;
    use gesture_runtime::prosody::{ProsodyConfig, StepKind};

    #[test]
    fn front_end_finds_the_planted_syllables() {
        let mut total_true = 0usize;
        let mut total_found = 0usize;
        let speaker = speaker_for(42);
        for index in 0..3 {
            let take = generate_take(42, index, 60.0, &speaker);
            let syl = &take.truth.syllables;
            let audio = &take.audio;
            let (_frames, steps) = prosody_of(audio, &ProsodyConfig::DEFAULT).unwrap();
            let found = steps
                .iter()
                .filter(|s| s.kind == StepKind::Syllable)
                .count();
            eprintln!("take {index}: planted {} found {found}", syl.len());
            total_true += syl.len();
            total_found += found;
        }
        let err = (total_found as f64 - total_true as f64).abs() / total_true as f64;
        assert!(err < 0.10, "found {total_found} of {total_true}");
    }
}
