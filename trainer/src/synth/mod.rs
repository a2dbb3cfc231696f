//! A synthetic corpus with planted truth: speech-like audio and gesture motion, both driven by
//! hidden style states (see [`styles`]), deterministic per seed.
//!
//! Every learning step needs data with a known answer, in any amount, without a download. A
//! take is a WAV (16 kHz, 16-bit) and a BVH (upper-body skeleton, 30 fps) of the same length;
//! `truth.json` records the state of every syllable, every gesture segment and every state run.

pub mod gesture;
pub mod speech;
pub mod styles;

use std::path::{Path, PathBuf};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use crate::motion::{Channel, Joint, Motion, Skeleton};

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

/// What [`write_corpus`] wrote.
#[derive(Clone, Debug)]
pub struct Written {
    /// Takes written.
    pub takes: usize,
    /// Planted syllables.
    pub syllables: usize,
    /// Planted gesture segments.
    pub segments: usize,
    /// The truth (also in `truth.json`).
    pub truth: Truth,
}

/// Generates and writes a corpus take by take (so memory stays at one take), then
/// `truth.json`; calls `progress(done, total)` after each take.
pub fn write_corpus(
    params: &SynthParams,
    dir: &Path,
    mut progress: impl FnMut(usize, usize),
) -> Result<Written, WriteError> {
    let (mut takes, mut syllables, mut segments) = (0, 0, 0);
    let truth = for_each_take(params, |take, done, total| {
        write_take(&take, dir)?;
        takes += 1;
        syllables += take.truth.syllables.len();
        segments += take.truth.segments.len();
        progress(done, total);
        Ok(())
    })?;
    write_truth(&truth, dir)?;
    Ok(Written {
        takes,
        syllables,
        segments,
        truth,
    })
}

/// Generates a whole corpus in memory, takes in order, calling `progress` after each.
pub fn generate(
    params: &SynthParams,
    mut progress: impl FnMut(usize, usize),
) -> (Vec<Take>, Truth) {
    let mut takes = Vec::new();
    let truth = for_each_take(params, |take, done, total| {
        takes.push(take);
        progress(done, total);
        Ok::<_, std::convert::Infallible>(())
    })
    .unwrap_or_else(|e| match e {});
    (takes, truth)
}

/// Generates the takes of `params` one after the other, handing each to `visit`, and
/// returns the corpus truth.
fn for_each_take<E>(
    params: &SynthParams,
    mut visit: impl FnMut(Take, usize, usize) -> Result<(), E>,
) -> Result<Truth, E> {
    let total = (params.minutes * 60.0).max(0.0);
    let n = (total / params.take_seconds).ceil().max(1.0) as usize;
    let speaker = speaker_for(params.seed);
    let mut truths = Vec::with_capacity(n);
    for i in 0..n {
        let dur = (total - i as f64 * params.take_seconds).min(params.take_seconds);
        let take = generate_take(params.seed, i, dur.max(1.0), &speaker);
        truths.push(take.truth.clone());
        visit(take, i + 1, n)?;
    }
    Ok(Truth {
        format: "gesture-synth-truth/1",
        seed: params.seed,
        speaker,
        states: styles::styles().to_vec(),
        takes: truths,
    })
}

/// Seed for take `index` of a corpus seeded with `seed`: takes are independent streams, so a
/// take's content does not depend on how many takes are generated.
pub fn take_rng(seed: u64, index: usize, stream: u64) -> ChaCha8Rng {
    let mut rng =
        ChaCha8Rng::seed_from_u64(seed ^ (index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    rng.set_stream(stream);
    rng
}

/// The synthetic skeleton as a BVH skeleton.
pub fn skeleton() -> Skeleton {
    use Channel::*;
    let joints = gesture::SKELETON
        .iter()
        .enumerate()
        .map(|(i, j)| Joint {
            name: j.name.to_string(),
            parent: j.parent,
            offset: j.offset,
            channels: if j.parent.is_none() {
                vec![
                    Xposition, Yposition, Zposition, Zrotation, Yrotation, Xrotation,
                ]
            } else if gesture::is_upper_arm(i) {
                vec![Yrotation, Zrotation, Xrotation]
            } else {
                vec![Zrotation, Yrotation, Xrotation]
            },
            end_site: j.end_site,
        })
        .collect();
    Skeleton { joints }
}

impl Take {
    /// The take's motion as a BVH motion.
    pub fn motion(&self) -> Motion {
        Motion::new(
            skeleton(),
            1.0 / gesture::FPS,
            self.frames,
            self.motion.clone(),
        )
        .expect("the synthetic skeleton and its channel data are consistent")
        .with_source(format!("{}.bvh", self.stem))
    }
}

/// Why a corpus could not be written.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// A file could not be written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The WAV encoder failed.
    #[error("{}: {source}", path.display())]
    Wav {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: hound::Error,
    },
}

/// Writes `path` through [`crate::output::write_atomic_with`] (a distinct temporary file beside
/// it, renamed at the end, removed on error or Ctrl-C).
fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut std::fs::File) -> std::io::Result<()>,
) -> Result<(), WriteError> {
    crate::output::write_atomic_with(path, |t| write(t.as_file_mut())).map_err(|e| WriteError::Io {
        path: e.path,
        source: e.source,
    })
}

/// Writes one take as `DIR/<stem>.wav` and `DIR/<stem>.bvh`.
pub fn write_take(take: &Take, dir: &Path) -> Result<(), WriteError> {
    let wav = dir.join(format!("{}.wav", take.stem));
    write_atomic(&wav, |f| {
        let spec = hound::WavSpec {
            channels: 1,
            sample_rate: AUDIO_RATE,
            bits_per_sample: 16,
            sample_format: hound::SampleFormat::Int,
        };
        let wrap = |e: hound::Error| std::io::Error::other(e.to_string());
        let mut w = hound::WavWriter::new(std::io::BufWriter::new(f), spec).map_err(wrap)?;
        for &s in &take.audio {
            w.write_sample(s).map_err(wrap)?;
        }
        w.finalize().map_err(wrap)
    })?;
    let bvh = dir.join(format!("{}.bvh", take.stem));
    write_atomic(&bvh, |f| {
        let mut w = std::io::BufWriter::new(f);
        crate::motion::write_bvh(&take.motion(), &mut w)?;
        std::io::Write::flush(&mut w)
    })
}

/// Writes `truth.json`.
pub fn write_truth(truth: &Truth, dir: &Path) -> Result<(), WriteError> {
    let path = dir.join("truth.json");
    let text = serde_json::to_string_pretty(truth).expect("truth serializes");
    write_atomic(&path, |f| std::io::Write::write_all(f, text.as_bytes()))
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

    #[test]
    fn motion_is_plausible_and_states_shape_hand_height() {
        use crate::motion::{analyze, EffectorSpec, SegmentParams};
        let speaker = speaker_for(3);
        let take = generate_take(3, 0, 60.0, &speaker);
        let m = take.motion();
        assert_eq!(m.frames(), 1800);
        let a = analyze(&m, &EffectorSpec::default(), &SegmentParams::default()).unwrap();
        // Hands stay between the floor and above the head, on the body's scale (cm).
        for f in 0..m.frames() {
            for p in a.positions.frame(f) {
                assert!(p[1] > 20.0 && p[1] < 230.0, "hand height {}", p[1]);
            }
        }
        // Mean right-hand height per planted state follows the states' elevations:
        // subdued < calm < emphatic < animated.
        let mut sum = [0.0f64; 4];
        let mut n = [0usize; 4];
        for f in 0..m.frames() {
            let st = take
                .truth
                .state_runs
                .iter()
                .find(|r| (f as f64 / 30.0) < r.end_s)
                .unwrap()
                .state;
            sum[st] += a.positions.get(f, 1)[1];
            n[st] += 1;
        }
        let mean: Vec<f64> = (0..4).map(|s| sum[s] / n[s].max(1) as f64).collect();
        eprintln!("mean right-hand height by state: {mean:?}");
        assert!(
            mean[3] < mean[0] && mean[0] < mean[1] && mean[1] < mean[2],
            "{mean:?}"
        );
    }

    #[test]
    fn written_corpus_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let (takes, truth) = generate(
            &SynthParams {
                minutes: 0.25,
                seed: 5,
                take_seconds: 60.0,
            },
            |_, _| {},
        );
        for t in &takes {
            write_take(t, dir.path()).unwrap();
        }
        write_truth(&truth, dir.path()).unwrap();
        let m = crate::motion::read_bvh(dir.path().join("take_000.bvh")).unwrap();
        assert_eq!(m.frames(), takes[0].frames);
        let pcm = crate::audio::load_wav(dir.path().join("take_000.wav")).unwrap();
        assert_eq!(pcm.samples, takes[0].audio);
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("truth.json")).unwrap())
                .unwrap();
        assert_eq!(
            json["takes"][0]["syllables"].as_array().unwrap().len(),
            takes[0].truth.syllables.len()
        );
        // Same seed, same bytes.
        let (again, _) = generate(
            &SynthParams {
                minutes: 0.25,
                seed: 5,
                take_seconds: 60.0,
            },
            |_, _| {},
        );
        assert_eq!(again[0].audio, takes[0].audio);
        assert_eq!(again[0].motion, takes[0].motion);
    }
}
