//! Makes `host-sim/assets/` (the demo's real speech and motion) from the shippable originals,
//! with the repository's own WAV and BVH code. Run once; its output is committed:
//!
//! ```sh
//! cargo run --release -p host-sim --example demo_assets -- ../shared/data/shippable host-sim/assets
//! ```
//!
//! - `speech/lj001-0001-0003.wav`: the first 22.1 s of the LJ Speech concatenation (sentences
//!   LJ001-0001 to 0003 and the 0.3 s pauses the concatenation put between them), resampled
//!   from 22.05 kHz to 16 kHz mono 16-bit by the trainer's resampler (what `gesture-sim run`
//!   does to any WAV file), so the demo loads it without converting;
//! - `cmu/18_08-*.bvh`, `cmu/19_08.bvh`: CMU's conversation clips without their first frame
//!   (the T-pose the BVH converter added), one frame in four (120 -> 30 fps, the rate the
//!   library is played at), every value rounded to 0.01 (degrees, or CMU units of 0.056 m:
//!   0.6 mm), with their own skeletons (the two performers' bone lengths differ; `pack` plays
//!   the library on the first file's). 18_08 is cut in two where its hands start moving again
//!   after seven seconds of listening (9.9 s, a pause of the hands and the segmenter's own cut
//!   there): the segmenter's threshold is the median hand speed of a take, and over the whole
//!   clip the listening held it so low that the explaining after it came out as one 4.9 s
//!   segment; cut, the explaining gives 9 segments at its strokes' pauses and the listening
//!   stays a rest for the library (5 + 25 segments from the two clips whole, 4 + 9 + 25 cut).

use std::path::{Path, PathBuf};

use gesture_trainer::audio::load_wav_at;
use gesture_trainer::motion::{read_bvh, write_bvh_file, Motion};

/// LJ001-0001 (9.655 s), 0.3 s, LJ001-0002 (1.900 s), 0.3 s, LJ001-0003 (9.667 s), 0.3 s.
const SPEECH_S: f64 = 9.655 + 0.3 + 1.900 + 0.3 + 9.667 + 0.3;
const RATE_HZ: u32 = 16_000;
/// 120 fps -> 30 fps.
const FRAME_STEP: usize = 4;
/// Where 18_08 is cut (frames at 30 fps after the T-pose: 9.9 s).
const CUT_18_08: usize = 297;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let [from, to] = args.as_slice() else {
        return Err("usage: demo_assets SHIPPABLE_DIR ASSETS_DIR".into());
    };
    speech(
        &from.join("ljspeech/LJ001-0001_to_0008_concat.wav"),
        &to.join("speech/lj001-0001-0003.wav"),
    )?;
    let cmu = |clip: &str| from.join(format!("cmu-mocap/{clip}.bvh"));
    motion(
        &cmu("18_08"),
        &to.join("cmu/18_08-listening.bvh"),
        0..CUT_18_08,
    )?;
    motion(
        &cmu("18_08"),
        &to.join("cmu/18_08-explaining.bvh"),
        CUT_18_08..usize::MAX,
    )?;
    motion(&cmu("19_08"), &to.join("cmu/19_08.bvh"), 0..usize::MAX)?;
    Ok(())
}

fn speech(from: &Path, to: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let pcm = load_wav_at(from, RATE_HZ)?;
    let n = ((SPEECH_S * RATE_HZ as f64).round() as usize).min(pcm.samples.len());
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: RATE_HZ,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    std::fs::create_dir_all(to.parent().unwrap_or(Path::new(".")))?;
    let mut w = hound::WavWriter::create(to, spec)?;
    for &s in &pcm.samples[..n] {
        w.write_sample(s)?;
    }
    w.finalize()?;
    println!("{}: {:.2} s at {RATE_HZ} Hz", to.display(), n as f64 / 16e3);
    Ok(())
}

/// `frames` counts 30 fps frames after the T-pose.
fn motion(
    from: &Path,
    to: &Path,
    range: std::ops::Range<usize>,
) -> Result<(), Box<dyn std::error::Error>> {
    let m = read_bvh(from)?;
    let (skeleton, _, frames, data) = m.into_parts();
    let n = skeleton.channel_count();
    let keep: Vec<usize> = (1..frames)
        .step_by(FRAME_STEP)
        .skip(range.start)
        .take(range.len())
        .collect();
    let mut out = Vec::with_capacity(keep.len() * n);
    for &f in &keep {
        out.extend(
            data[f * n..(f + 1) * n]
                .iter()
                .map(|v| (v * 100.0).round() / 100.0),
        );
    }
    // The source says 0.0083333 s (120 fps); its quarter is written as exactly 1/30 s.
    let m = Motion::new(skeleton, 1.0 / 30.0, keep.len(), out)?;
    std::fs::create_dir_all(to.parent().unwrap_or(Path::new(".")))?;
    write_bvh_file(&m, to)?;
    println!(
        "{}: {} frames at {:.2} fps ({:.2} s)",
        to.display(),
        m.frames(),
        m.fps(),
        m.duration()
    );
    Ok(())
}
