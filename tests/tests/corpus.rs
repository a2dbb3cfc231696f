//! Corpus ingestion end to end: the synthetic corpus through the real loader (files on disk),
//! the planted prosody-kinematics link, and bad input giving clear errors.

use std::path::Path;

use gesture_trainer::corpus::{load_corpus, CorpusError, LoadOptions};
use gesture_trainer::synth::{write_corpus, SynthParams};
use rand::seq::SliceRandom;
use rand::SeedableRng;

fn synth_corpus(dir: &Path, minutes: f64, seed: u64) {
    let params = SynthParams {
        minutes,
        seed,
        take_seconds: 60.0,
    };
    write_corpus(&params, dir, |_, _| {}).unwrap();
}

fn pearson(xy: &[(f64, f64)]) -> f64 {
    let n = xy.len() as f64;
    let mx = xy.iter().map(|p| p.0).sum::<f64>() / n;
    let my = xy.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = xy.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = xy.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let syy: f64 = xy.iter().map(|p| (p.1 - my).powi(2)).sum();
    sxy / (sxx * syy).sqrt()
}

#[test]
fn planted_prosody_kinematics_link_is_measurable_and_shuffling_destroys_it() {
    let dir = tempfile::tempdir().unwrap();
    synth_corpus(dir.path(), 10.0, 7);
    let corpus = load_corpus(&[dir.path().to_path_buf()], &LoadOptions::default()).unwrap();
    assert_eq!(corpus.takes.len(), 10);
    // Voiced steps: relative F0 against log hand height H (index 5).
    let pairs: Vec<(f64, f64)> = corpus
        .takes
        .iter()
        .flat_map(|t| t.aligned.iter())
        .filter_map(|s| s.features.f0.map(|f| (f as f64, s.y_raw[5])))
        .collect();
    assert!(pairs.len() > 1000, "{} voiced steps", pairs.len());
    let r = pearson(&pairs);
    eprintln!("r(F0, H) = {r:.3} over {} steps", pairs.len());
    assert!(r > 0.3, "planted link too weak: r = {r}");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let mut ys: Vec<f64> = pairs.iter().map(|p| p.1).collect();
    for _ in 0..20 {
        ys.shuffle(&mut rng);
        let shuffled: Vec<(f64, f64)> = pairs.iter().zip(&ys).map(|(p, &y)| (p.0, y)).collect();
        let rs = pearson(&shuffled);
        assert!(
            rs.abs() < 0.1,
            "shuffled data should have no link, r = {rs}"
        );
    }
}

#[test]
fn front_end_finds_the_synthetic_syllables_within_10_percent() {
    let dir = tempfile::tempdir().unwrap();
    synth_corpus(dir.path(), 3.0, 11);
    let corpus = load_corpus(&[dir.path().to_path_buf()], &LoadOptions::default()).unwrap();
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("truth.json")).unwrap())
            .unwrap();
    let planted: usize = truth["takes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["syllables"].as_array().unwrap().len())
        .sum();
    let found: usize = corpus
        .takes
        .iter()
        .map(|t| {
            t.steps
                .iter()
                .filter(|s| s.kind == gesture_runtime::prosody::StepKind::Syllable)
                .count()
        })
        .sum();
    eprintln!("syllables: planted {planted}, found {found}");
    assert!((found as f64 - planted as f64).abs() <= 0.1 * planted as f64);
}

fn write_wav(path: &Path, samples: &[i16]) {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: 16_000,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut w = hound::WavWriter::create(path, spec).unwrap();
    for &s in samples {
        w.write_sample(s).unwrap();
    }
    w.finalize().unwrap();
}

#[test]
fn audio_shorter_than_motion_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    synth_corpus(dir.path(), 1.0, 3);
    let wav = dir.path().join("take_000.wav");
    let pcm = gesture_trainer::audio::load_wav(&wav).unwrap();
    write_wav(&wav, &pcm.samples[..pcm.samples.len() / 2]);
    let err = load_corpus(&[dir.path().to_path_buf()], &LoadOptions::default())
        .map(|c| c.takes.len())
        .expect_err("a short WAV must be refused");
    assert!(matches!(err, CorpusError::LengthMismatch { .. }), "{err}");
    let msg = err.to_string();
    assert!(
        msg.contains("take_000.wav") && msg.contains("30.00 s") && msg.contains("60.00 s"),
        "{msg}"
    );
}

#[test]
fn no_effector_and_bad_bvh_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    synth_corpus(dir.path(), 1.0, 3);
    let bvh = dir.path().join("take_000.bvh");
    let text = std::fs::read_to_string(&bvh).unwrap();
    // Rename the hands: no effector can be found.
    std::fs::write(
        &bvh,
        text.replace("LeftHand", "LeftPaw")
            .replace("RightHand", "RightPaw"),
    )
    .unwrap();
    let msg = load_corpus(&[dir.path().to_path_buf()], &LoadOptions::default())
        .map(|c| c.takes.len())
        .expect_err("no hands must be refused")
        .to_string();
    assert!(
        msg.contains("take_000.bvh") && msg.contains("hand"),
        "{msg}"
    );
    // Naming the effectors explicitly fixes it.
    let opts = LoadOptions {
        effectors: gesture_trainer::motion::EffectorSpec::joints(["LeftPaw", "RightPaw"]),
        ..LoadOptions::default()
    };
    assert!(load_corpus(&[dir.path().to_path_buf()], &opts).is_ok());
    // A NaN channel value, then a truncated file: errors name the file and the line.
    let lines: Vec<&str> = text.lines().collect();
    let motion_line = lines
        .iter()
        .position(|l| l.starts_with("Frame Time"))
        .unwrap()
        + 3;
    let mut bad = lines.clone();
    let broken = lines[motion_line].replacen("100", "nan", 1);
    assert_ne!(broken, lines[motion_line]);
    bad[motion_line] = &broken;
    std::fs::write(&bvh, bad.join("\n")).unwrap();
    let load = || {
        load_corpus(&[dir.path().to_path_buf()], &LoadOptions::default())
            .err()
            .map(|e| e.to_string())
    };
    let msg = load().expect("a NaN channel must be refused");
    assert!(
        msg.contains(&format!("take_000.bvh:{}", motion_line + 1)),
        "{msg}"
    );
    std::fs::write(&bvh, &text[..text.len() / 2]).unwrap();
    let msg = load().expect("a truncated file must be refused");
    assert!(msg.contains("take_000.bvh"), "{msg}");
}
