//! `gesture-sim demo [--out DIR] [--audio WAV]`: the whole pipeline in one command on a fresh
//! clone, with nothing but the repository, then a real voice driving a real human body.
//!
//! 1. **The chain, on synthetic data**: a synthetic speech+motion corpus, an inference model
//!    trained on it, two policy blobs (the full skeleton for BVH output and the 8-servo puppet
//!    rig, whose rig file is built into the binary), a new utterance the model has never heard,
//!    and `gesture-sim run` on it with both blobs.
//! 2. **Real speech, real motion**: the same model packed with a library of real motion
//!    capture (CMU 18_08 and 19_08, the two sides of a conversation, explaining with both
//!    hands), driven by recorded speech (LJ Speech, or the user's `--audio` file). No recording
//!    of speech with its gestures may be shipped (none exists under a licence that allows it),
//!    so the model's prosody -> state mapping comes from the synthetic corpus, where speech and
//!    motion are aligned by construction; `pack` solves the control layer anew for the real
//!    library (docs/method.md, "New library, same model"), so what the character plays is the
//!    capture. The material is built into the binary (`host-sim/assets`, with its licences).
//!
//! Layout of `DIR` (default `gesture-demo`):
//!
//! ```text
//! corpus/            take_NNN.wav + take_NNN.bvh, truth.json   (3 minutes, seed 1)
//! model.json         the inference model (8 states, 8 clusters, window 4)
//! character.blob     full-skeleton rig (BVH output), puppet.blob: rigs/puppet-8ch.toml
//! puppet-8ch.toml    the rig file used
//! utterance.wav      20 s of new synthetic speech (another seed and speaker)
//! run-character/     motion.bvh, timeline.json, servo.csv, preview.png, preview.gif, viewer.html
//! run-puppet/        the same for the puppet blob
//! real/              host-sim/assets: cmu/*.bvh (the library), speech/*.wav, licences, README.md
//! real-character.blob, real-puppet.blob   the model with the real library
//! run-real/          the real speech through real-character.blob (and preview.mp4 with ffmpeg)
//! run-real-puppet/   the same through real-puppet.blob (servo.csv: the 8 servos)
//! ```
//!
//! `--audio` is read first: a file that is not usable speech is one line naming it, exit 2,
//! before anything is written.
//!
//! Progress bars go to stderr (hidden when it is not a terminal); the summary to stdout.
//! Every step is seeded, so two demos write the same files (but for timings).

use gesture_trainer::progress::{progress_bar as bar, spinner};
use std::io::Write;
use std::path::Path;
use std::time::Instant;

use gesture_trainer::audio::load_wav;
use gesture_trainer::corpus::{load_corpus, LoadOptions};
use gesture_trainer::inference::train::{fit, sequences, FitConfig};
use gesture_trainer::pack::{pack, PackOptions};
use gesture_trainer::synth::{write_corpus, SynthParams};

use crate::run::{self as run_cmd, RunConfig};

/// The sample rig, built in so the demo runs from any folder.
pub const PUPPET_RIG: &str = include_str!("../../rigs/puppet-8ch.toml");

/// `host-sim/assets`, built in: the real speech and motion with their licences
/// (`real/` of the demo's folder).
pub const REAL_ASSETS: [(&str, &[u8]); 7] = [
    ("README.md", include_bytes!("../assets/README.md")),
    (
        "cmu/LICENSE.txt",
        include_bytes!("../assets/cmu/LICENSE.txt"),
    ),
    (
        "cmu/18_08-listening.bvh",
        include_bytes!("../assets/cmu/18_08-listening.bvh"),
    ),
    (
        "cmu/18_08-explaining.bvh",
        include_bytes!("../assets/cmu/18_08-explaining.bvh"),
    ),
    ("cmu/19_08.bvh", include_bytes!("../assets/cmu/19_08.bvh")),
    (
        "speech/LICENSE.txt",
        include_bytes!("../assets/speech/LICENSE.txt"),
    ),
    (
        "speech/lj001-0001-0003.wav",
        include_bytes!("../assets/speech/lj001-0001-0003.wav"),
    ),
];

/// Demo settings (the command uses the defaults; tests may shrink them).
#[derive(Clone, Copy, Debug)]
pub struct DemoParams {
    /// Corpus length (minutes).
    pub corpus_minutes: f64,
    /// Utterance length (s).
    pub utterance_s: f64,
    /// Hidden states.
    pub states: usize,
}

impl Default for DemoParams {
    fn default() -> Self {
        Self {
            corpus_minutes: 3.0,
            utterance_s: 20.0,
            states: 8,
        }
    }
}

/// Why the demo failed (one line; the step is named).
#[derive(Debug, thiserror::Error)]
#[error("demo, {step}: {reason}")]
pub struct DemoError {
    step: &'static str,
    reason: String,
    /// The user's input is at fault (an output folder that cannot be made, an unusable
    /// `--audio` file).
    input: bool,
}

impl DemoError {
    /// The process exit status: 2 for an unusable output folder or `--audio` file, 1
    /// otherwise.
    pub fn exit_code(&self) -> u8 {
        if self.input {
            2
        } else {
            1
        }
    }
}

fn at<E: std::fmt::Display>(step: &'static str) -> impl Fn(E) -> DemoError {
    move |e| DemoError {
        step,
        reason: e.to_string(),
        input: false,
    }
}

/// Creates `dir`; an error names it and is the user's to fix.
fn make_dir(dir: &Path) -> Result<(), DemoError> {
    std::fs::create_dir_all(dir).map_err(|e| DemoError {
        step: "creating the output folder",
        reason: format!("{}: {e}", dir.display()),
        input: true,
    })
}

/// Runs the demo into `dir`, printing what it did to `out`; `audio` replaces the shipped
/// speech of the real-motion runs.
pub fn demo(
    dir: &Path,
    params: DemoParams,
    audio: Option<&Path>,
    out: &mut impl Write,
) -> Result<(), DemoError> {
    let start = Instant::now();
    // The user's file first: a bad one stops the demo before anything is written.
    let user_speech = match audio {
        Some(p) => Some((
            p,
            load_wav(p)
                .map_err(|e| DemoError {
                    step: "reading --audio",
                    reason: e.to_string(),
                    input: true,
                })?
                .duration_s(),
        )),
        None => None,
    };
    make_dir(dir)?;
    let corpus = dir.join("corpus");
    make_dir(&corpus)?;

    // 1. Corpus.
    let t = Instant::now();
    let synth = SynthParams {
        minutes: params.corpus_minutes,
        seed: 1,
        take_seconds: 60.0,
    };
    let takes = (synth.minutes * 60.0 / synth.take_seconds).ceil() as u64;
    let pb = bar(takes, "corpus");
    let written = write_corpus(&synth, &corpus, |done, _| pb.set_position(done as u64))
        .map_err(at("synthesizing the corpus"))?;
    pb.finish_and_clear();
    let line = |out: &mut dyn Write, s: String| writeln!(out, "{s}").map_err(at("printing"));
    line(
        out,
        format!(
            "1. corpus: {} takes, {:.1} min of synthetic speech and upper-body motion, {} \
             syllables, {} gesture segments -> {} ({:.1} s)",
            written.takes,
            synth.minutes,
            written.syllables,
            written.segments,
            corpus.display(),
            t.elapsed().as_secs_f64()
        ),
    )?;

    // 2. Model.
    let t = Instant::now();
    let sp = spinner("fitting the HMM, the prosody GMM and the CRF");
    let c = load_corpus(std::slice::from_ref(&corpus), &LoadOptions::default())
        .map_err(at("loading the corpus"))?;
    let (seqs, segs) = sequences(&c, None);
    let cfg = FitConfig {
        states: Some(params.states),
        clusters: Some(8),
        window: 4,
        restarts: 8,
        ..FitConfig::default()
    };
    let (model, _) = fit(&seqs, &segs, &cfg, &|_| {}).map_err(at("fitting the model"))?;
    let model_path = dir.join("model.json");
    model.save(&model_path).map_err(at("writing the model"))?;
    sp.finish_and_clear();
    line(
        out,
        format!(
            "2. model: {} -> {} ({:.1} s)",
            model.summary,
            model_path.display(),
            t.elapsed().as_secs_f64()
        ),
    )?;

    // 3. Blobs.
    let t = Instant::now();
    let rig_path = dir.join("puppet-8ch.toml");
    std::fs::write(&rig_path, PUPPET_RIG).map_err(at("writing the rig file"))?;
    let pb = bar(2, "packing");
    let character = dir.join("character.blob");
    let r1 = pack(
        &model_path,
        std::slice::from_ref(&corpus),
        &PackOptions::default(),
        &character,
    )
    .map_err(at("packing the full-skeleton blob"))?;
    pb.inc(1);
    let puppet = dir.join("puppet.blob");
    let opts = PackOptions {
        rig: Some(rig_path.clone()),
        ..PackOptions::default()
    };
    let r2 = pack(&model_path, std::slice::from_ref(&corpus), &opts, &puppet)
        .map_err(at("packing the puppet blob"))?;
    pb.finish_and_clear();
    line(
        out,
        format!(
            "3. blobs: {} ({} bytes, {} channels, {} segments, {:.1}% of successors pruned), \
             {} ({} bytes, {} servos) ({:.1} s)",
            character.display(),
            r1.blob_bytes,
            r1.channels,
            r1.segments,
            100.0 * r1.pruned_fraction,
            puppet.display(),
            r2.blob_bytes,
            r2.channels,
            t.elapsed().as_secs_f64()
        ),
    )?;

    // 4. A new utterance (another seed: another speaker and sentence).
    let utter_dir = dir.join(".utterance");
    make_dir(&utter_dir)?;
    let up = SynthParams {
        minutes: params.utterance_s / 60.0,
        seed: 2024,
        take_seconds: params.utterance_s,
    };
    write_corpus(&up, &utter_dir, |_, _| {}).map_err(at("synthesizing the utterance"))?;
    let wav = dir.join("utterance.wav");
    std::fs::rename(utter_dir.join("take_000.wav"), &wav).map_err(at("moving the utterance"))?;
    let _ = std::fs::remove_dir_all(&utter_dir);
    line(
        out,
        format!(
            "4. utterance: {} ({:.0} s of new synthetic speech)",
            wav.display(),
            params.utterance_s
        ),
    )?;

    // 5. Simulate with both blobs.
    let runs = [
        ("run-character", character.as_path(), true),
        ("run-puppet", puppet.as_path(), false),
    ];
    for (step, (name, blob, video)) in (5..).zip(runs) {
        simulate(step, blob, &wav, &dir.join(name), video, out)?;
    }

    // 7. Real speech through the same model packed with a library of real motion.
    let t = Instant::now();
    let real = dir.join("real");
    for (name, bytes) in REAL_ASSETS {
        let path = real.join(name);
        make_dir(path.parent().unwrap_or(&real))?;
        std::fs::write(&path, bytes).map_err(at("writing the real speech and motion"))?;
    }
    let library = real.join("cmu");
    let (speech, speech_s, what) = match user_speech {
        Some((p, seconds)) => (p.to_path_buf(), seconds, "your recording"),
        None => {
            let p = real.join("speech/lj001-0001-0003.wav");
            let seconds = load_wav(&p)
                .map_err(at("reading the real speech"))?
                .duration_s();
            (
                p,
                seconds,
                "LJ Speech LJ001-0001..0003, one reader, public domain",
            )
        }
    };
    line(
        out,
        format!(
            "7. real speech, real motion -> {}: no recording of speech with its gestures may be \
             shipped (none exists under a licence that allows it), so the model above keeps the \
             prosody -> state mapping it learnt where speech and motion are aligned (the \
             synthetic corpus), and pack solves the choices anew for a library of real motion \
             capture: CMU 18_08 + 19_08, two people explaining to each other with both hands \
             (34.8 s). The speech: {} ({speech_s:.1} s, {what}).",
            real.display(),
            speech.display(),
        ),
    )?;
    let real_character = dir.join("real-character.blob");
    let r1 = pack(
        &model_path,
        std::slice::from_ref(&library),
        &PackOptions::default(),
        &real_character,
    )
    .map_err(at("packing the real library"))?;
    let real_puppet = dir.join("real-puppet.blob");
    let r2 = pack(
        &model_path,
        std::slice::from_ref(&library),
        &opts,
        &real_puppet,
    )
    .map_err(at("packing the real library for the puppet"))?;
    line(
        out,
        format!(
            "8. blobs: {} ({} bytes, {} channels, {} segments), {} ({} bytes, {} servos) \
             ({:.1} s)",
            real_character.display(),
            r1.blob_bytes,
            r1.channels,
            r1.segments,
            real_puppet.display(),
            r2.blob_bytes,
            r2.channels,
            t.elapsed().as_secs_f64()
        ),
    )?;
    let runs = [
        ("run-real", real_character.as_path(), true),
        ("run-real-puppet", real_puppet.as_path(), false),
    ];
    for (step, (name, blob, video)) in (9..).zip(runs) {
        simulate(step, blob, &speech, &dir.join(name), video, out)?;
    }
    let d = dir.display();
    line(
        out,
        format!(
            "done in {:.1} s. Synthetic runs: {d}/run-character, {d}/run-puppet. Open \
             {d}/run-real/viewer.html in a browser: a real voice driving a real human body \
             (also preview.png, preview.mp4 with ffmpeg, motion.bvh for Blender; \
             {d}/run-real-puppet/servo.csv is what 8 servos would be sent).",
            start.elapsed().as_secs_f64(),
        ),
    )?;
    Ok(())
}

/// `gesture-sim run` of `blob` on `audio` into `out_dir`, its summary indented under a step line.
fn simulate(
    step: usize,
    blob: &Path,
    audio: &Path,
    out_dir: &Path,
    video: bool,
    out: &mut impl Write,
) -> Result<(), DemoError> {
    let cfg = RunConfig {
        blob: blob.to_path_buf(),
        audio: audio.to_path_buf(),
        out: out_dir.to_path_buf(),
        rig: None,
        realtime: false,
        chunk_ms: 10.0,
        lookahead: gesture_trainer::evaluate::motion::Horizon::Ms(0),
        // The video of the characters (with ffmpeg); the puppets' would show the same runs.
        video,
        vmc: None,
        bone_map: None,
        show: None,
        blender: false,
        ros2: false,
        ros2_topic: None,
        mcap: None,
        style: Default::default(),
        labels: None,
        keywords: None,
    };
    writeln!(
        out,
        "{step}. gesture-sim run --blob {} --audio {} --out {}:",
        blob.display(),
        audio.display(),
        out_dir.display()
    )
    .map_err(at("printing"))?;
    let mut text = Vec::new();
    run_cmd::run(&cfg, &mut text).map_err(at("simulating"))?;
    for l in String::from_utf8_lossy(&text).lines() {
        writeln!(out, "   {l}").map_err(at("printing"))?;
    }
    Ok(())
}
