//! What the trainer's integration tests share: a small synthetic corpus and a small model
//! fitted on it.

use std::path::{Path, PathBuf};

use gesture_trainer::corpus::{load_corpus, LoadOptions};
use gesture_trainer::inference::model::InferenceModel;
use gesture_trainer::inference::train::{fit, sequences, FitConfig};
use gesture_trainer::synth::{write_corpus, SynthParams};

/// Half a minute of synthetic takes (30 s each) drawn with `seed`, written to `dir/corpus`.
pub fn small_corpus(dir: &Path, seed: u64) -> PathBuf {
    let c = dir.join("corpus");
    std::fs::create_dir_all(&c).unwrap();
    let p = SynthParams {
        minutes: 0.5,
        seed,
        take_seconds: 30.0,
    };
    write_corpus(&p, &c, |_, _| {}).unwrap();
    c
}

/// A model of 2 states, 2 clusters and window 2 fitted on `corpus`.
pub fn small_model(corpus: &Path) -> InferenceModel {
    let c = load_corpus(&[corpus.to_path_buf()], &LoadOptions::default()).unwrap();
    let (seqs, segs) = sequences(&c, None);
    let cfg = FitConfig {
        states: Some(2),
        clusters: Some(2),
        window: 2,
        restarts: 2,
        l2: Some(0.01),
        ..FitConfig::default()
    };
    fit(&seqs, &segs, &cfg, &|_| {}).unwrap().0
}
