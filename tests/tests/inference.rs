//! The inference layer end to end: training on corpora, the model file, and the runtime's
//! quantized belief against the trainer's float forward pass.

use std::path::PathBuf;

use gesture_runtime::inference::{memberships, Belief, StepNormalizer, MAX_CLUSTERS};
use gesture_trainer::corpus::{load_corpus, LoadOptions};
use gesture_trainer::inference::model::InferenceModel;
use gesture_trainer::inference::quantize::inference_section;
use gesture_trainer::inference::train::{
    fit, memberships as float_memberships, sequences, FitConfig, Sequence,
};
use gesture_trainer::synth::{write_corpus, SynthParams};

fn zeroeggs(test: &str) -> Option<PathBuf> {
    e2e_tests::shared_data(test, "zeroeggs-067-speech2")
}

/// Runs the runtime's fixed-memory path (normalizer is already applied in the features) and
/// returns the L1 distance to the float beliefs at every step.
fn l1_per_step(model: &InferenceModel, seq: &Sequence) -> Vec<f64> {
    let q = inference_section(&model.gmm, &model.crf).expect("dimensions fit the blob");
    let w = q.crf_weights().expect("dimensions within capacities");
    let gmm = q.components();
    let float = model.crf.beliefs(&float_memberships(&model.gmm, seq));
    let mut belief = Belief::new();
    let mut m = [0.0f32; MAX_CLUSTERS];
    seq.features
        .iter()
        .zip(&float)
        .map(|(f, fb)| {
            memberships(&gmm, f, &mut m);
            belief.step(&w, &m);
            belief
                .probs(model.states())
                .iter()
                .zip(fb)
                .map(|(a, b)| (*a as f64 - b).abs())
                .sum::<f64>()
        })
        .collect()
}

#[test]
fn limbs_measure_the_same_arm_on_both_zeroeggs_skeletons_and_bandais_shorter_one() {
    use gesture_trainer::motion::{analyze, read_bvh, EffectorSpec, SegmentParams};
    let Some(root) = e2e_tests::shared_data(
        "limbs_measure_the_same_arm_on_both_zeroeggs_skeletons_and_bandais_shorter_one",
        "",
    ) else {
        return;
    };
    for (file, want) in [
        ("zeroeggs-067-speech2/067_Speech_2_first50s.bvh", 53.5),
        ("zeroeggs-001-neutral-9joint/001_Neutral_0_x_1_0.bvh", 53.5),
        (
            "bandai-namco-gestures/dataset-1/dataset-1_bow_active_001.bvh",
            46.6,
        ),
    ] {
        let m = read_bvh(root.join(file)).unwrap();
        let a = analyze(&m, &EffectorSpec::default(), &SegmentParams::default()).unwrap();
        let l = a.limb_length;
        assert!((l - want).abs() < 0.1, "{file}: limb {l} cm, want {want}");
        // Heights above the shoulder in limb units: hands between hanging and overhead.
        assert!(a.kinematics.iter().all(|k| (0.0..=2.0).contains(&k.h)));
    }
}

#[test]
fn runtime_belief_matches_float_on_every_step_of_the_real_take() {
    let Some(dir) = zeroeggs("runtime_belief_matches_float_on_every_step_of_the_real_take") else {
        return;
    };
    let corpus = load_corpus(&[dir], &LoadOptions::default()).unwrap();
    let (seqs, segs) = sequences(&corpus, None);
    for states in [4usize, 12] {
        let cfg = FitConfig {
            states: Some(states),
            ..FitConfig::default()
        };
        let (model, _) = fit(&seqs, &segs, &cfg, &|_| {}).unwrap();
        let l1 = l1_per_step(&model, &seqs[0]);
        let worst = l1.iter().cloned().fold(0.0, f64::max);
        eprintln!("S={states}: {} steps, worst L1 {worst:.2e}", l1.len());
        assert!(l1.len() > 150);
        assert!(worst <= 0.01, "S={states}: worst L1 {worst}");
    }
}

/// The per-step features as the runtime's module docs define them, in f64: relative log2 F0
/// against the running mean over voiced syllables, relative intensity / 10 dB against the
/// running mean over syllables (clamped to [-6, 2]), ln length; running means weighted
/// `1 / min(n, MEMORY)`.
fn features_by_definition(
    steps: &[gesture_runtime::prosody::Step],
) -> Vec<(Option<f64>, f64, f64)> {
    use gesture_runtime::inference::features::MEMORY;
    use gesture_runtime::prosody::StepKind;
    let (mut ref_f0, mut n_f0, mut ref_db, mut n_db) = (7.0f64, 0u32, 60.0f64, 0u32);
    steps
        .iter()
        .map(|s| {
            let pause = s.kind == StepKind::Pause;
            let f0 = s.f0_hz.filter(|f| *f > 1.0).map(|f| {
                let l = (f as f64).log2();
                if !pause {
                    n_f0 += 1;
                    ref_f0 += (l - ref_f0) / n_f0.min(MEMORY) as f64;
                }
                l - ref_f0
            });
            let db = s.intensity_db as f64;
            if !pause && db > -100.0 {
                n_db += 1;
                ref_db += (db - ref_db) / n_db.min(MEMORY) as f64;
            }
            let len = (s.length_s() as f64).max(0.01);
            (f0, ((db - ref_db) / 10.0).clamp(-6.0, 2.0), len.ln())
        })
        .collect()
}

#[test]
fn features_fed_to_the_trainer_match_their_definition() {
    use gesture_runtime::prosody::{Step, StepKind};
    // Known answer by hand: syllables at 100 Hz / 60 dB, 200 Hz / 70 dB, then a pause.
    let syl = |f0: f32, db: f32| Step {
        kind: StepKind::Syllable,
        start_frame: 0,
        end_frame: 20,
        f0_hz: Some(f0),
        intensity_db: db,
    };
    let mut n = StepNormalizer::new();
    let a = n.push(&syl(100.0, 60.0));
    let b = n.push(&syl(200.0, 70.0));
    assert_eq!(a.f0, Some(0.0)); // the first voiced syllable is its own reference
    assert!((b.f0.unwrap() - 0.5).abs() < 1e-6); // log2 200 - mean(log2 100, log2 200)
    assert!((b.obs[0] - 0.5).abs() < 1e-6); // (70 - 65) / 10
    assert!((b.obs[1] - 0.2f32.ln()).abs() < 1e-6); // 20 frames of 10 ms
                                                    // Every aligned step of a synthetic corpus carries the features the definition gives.
    let dir = tempfile::tempdir().unwrap();
    let params = SynthParams {
        minutes: 1.0,
        seed: 9,
        take_seconds: 60.0,
    };
    write_corpus(&params, dir.path(), |_, _| {}).unwrap();
    let corpus = load_corpus(&[dir.path().to_path_buf()], &LoadOptions::default()).unwrap();
    let t = &corpus.takes[0];
    let want = features_by_definition(&t.steps);
    assert!(t.aligned.len() > 100);
    for a in &t.aligned {
        let i = t
            .steps
            .iter()
            .position(|s| s.start_frame == a.step.start_frame)
            .unwrap();
        let (f0, rel, len) = want[i];
        match (a.features.f0, f0) {
            (Some(x), Some(y)) => assert!((x as f64 - y).abs() < 1e-4, "step {i}: f0 {x} vs {y}"),
            (None, None) => {}
            (x, y) => panic!("step {i}: voicing {x:?} vs {y:?}"),
        }
        assert!((a.features.obs[0] as f64 - rel).abs() < 1e-4, "step {i}");
        assert!((a.features.obs[1] as f64 - len).abs() < 1e-4, "step {i}");
    }
}

#[test]
fn model_file_round_trips_and_refuses_other_versions() {
    let dir = tempfile::tempdir().unwrap();
    let params = SynthParams {
        minutes: 2.0,
        seed: 4,
        take_seconds: 60.0,
    };
    write_corpus(&params, dir.path(), |_, _| {}).unwrap();
    let corpus = load_corpus(&[dir.path().to_path_buf()], &LoadOptions::default()).unwrap();
    let (seqs, segs) = sequences(&corpus, None);
    let (model, _) = fit(
        &seqs,
        &segs,
        &FitConfig {
            states: Some(4),
            ..FitConfig::default()
        },
        &|_| {},
    )
    .unwrap();
    let path = dir.path().join("model.json");
    model.save(&path).unwrap();
    let back = InferenceModel::load(&path).unwrap();
    assert_eq!(back.to_file(), model.to_file());
    // Same beliefs after the round trip.
    let m = float_memberships(&back.gmm, &seqs[0]);
    assert_eq!(
        back.crf.beliefs(&m),
        model.crf.beliefs(&float_memberships(&model.gmm, &seqs[0]))
    );
    // Another version is refused with a message saying what to do.
    let current = format!(
        "\"version\": {}",
        gesture_trainer::inference::model::VERSION
    );
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains(&current));
    std::fs::write(&path, text.replace(&current, "\"version\": 99")).unwrap();
    let err = InferenceModel::load(&path).unwrap_err().to_string();
    assert!(
        err.contains("version 99") && err.contains("retrain"),
        "{err}"
    );
    // Version 1 (skeleton units) is refused with the reason.
    std::fs::write(&path, text.replace(&current, "\"version\": 1")).unwrap();
    let err = InferenceModel::load(&path).unwrap_err().to_string();
    assert!(
        err.contains("limb lengths") && err.contains("retrain"),
        "{err}"
    );
    std::fs::write(&path, b"{ not json").unwrap();
    assert!(InferenceModel::load(&path).is_err());
    // The training takes' level goes with the model; a file from before it loads without
    // one (and packs libraries as it did).
    assert!(model.take_level.is_some() && back.take_level == model.take_level);
    let mut old = serde_json::to_value(model.to_file()).unwrap();
    old.as_object_mut().unwrap().remove("take_level");
    std::fs::write(&path, old.to_string()).unwrap();
    let err = InferenceModel::load(&path).unwrap_err().to_string();
    assert!(err.contains("take_level"), "{err}");
    old["version"] = 2.into();
    std::fs::write(&path, old.to_string()).unwrap();
    let back = InferenceModel::load(&path).unwrap();
    assert_eq!(back.take_level, None);
    let raw = [[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]; 10];
    assert_eq!(back.library_normalization(&raw), back.normalization);
}

#[test]
fn each_take_is_standardized_by_its_own_level_and_a_library_by_its_own() {
    use gesture_trainer::inference::train::take_levels;
    use gesture_trainer::motion::Normalization;
    let dir = tempfile::tempdir().unwrap();
    let params = SynthParams {
        minutes: 2.0,
        seed: 5,
        take_seconds: 60.0,
    };
    write_corpus(&params, dir.path(), |_, _| {}).unwrap();
    let corpus = load_corpus(&[dir.path().to_path_buf()], &LoadOptions::default()).unwrap();
    assert_eq!(corpus.takes.len(), 2);
    let (seqs, segs) = sequences(&corpus, None);
    let levels = take_levels(&corpus, None);
    for (t, s) in corpus.takes.iter().zip(&seqs) {
        // A take's level is its segments' mean and spread, and its steps are in its terms.
        let level = Normalization::fit(&t.motion.y_raw).unwrap();
        assert_eq!(levels[&t.stem], level);
        assert_eq!(s.level, level);
        for (a, y) in t.aligned.iter().zip(&s.y_raw) {
            assert_eq!(*y, level.apply(&a.y_raw));
        }
    }
    // So every take's segments have mean 0 and spread 1, and so do all of them together.
    let n = segs.len() as f64;
    for d in 0..6 {
        let m = segs.iter().map(|y| y[d]).sum::<f64>() / n;
        let v = segs.iter().map(|y| (y[d] - m).powi(2)).sum::<f64>() / n;
        assert!(m.abs() < 1e-9 && (v - 1.0).abs() < 1e-9, "dim {d}: {m} {v}");
    }
    // A library moved to another level (every parameter shifted and scaled, as a more
    // energetic recording or another character would be) lands where the original does.
    let (model, _) = fit(
        &seqs,
        &segs,
        &FitConfig {
            states: Some(3),
            ..FitConfig::default()
        },
        &|_| {},
    )
    .unwrap();
    let raw: Vec<[f64; 6]> = corpus.takes[0].motion.y_raw.clone();
    let moved: Vec<[f64; 6]> = raw
        .iter()
        .map(|y| std::array::from_fn(|d| 0.7 + 2.5 * y[d]))
        .collect();
    let (a, b) = (
        model.library_normalization(&raw),
        model.library_normalization(&moved),
    );
    for (y, z) in raw.iter().zip(&moved) {
        let (p, q) = (a.apply(y), b.apply(z));
        for d in 0..6 {
            assert!((p[d] - q[d]).abs() < 1e-9, "{p:?} {q:?}");
        }
    }
    // Composition: the library's level, then the model's normalization.
    let level = Normalization::fit(&raw).unwrap();
    let y = raw[3];
    let (p, q) = (a.apply(&y), model.normalization.apply(&level.apply(&y)));
    for d in 0..6 {
        assert!((p[d] - q[d]).abs() < 1e-12);
    }
    // A library of fewer than MIN_LEVEL_SEGMENTS segments takes the training takes' level.
    let few = &raw[..gesture_trainer::inference::model::MIN_LEVEL_SEGMENTS - 1];
    let typical = model.take_level.unwrap();
    assert_eq!(
        model.library_normalization(few),
        typical.then(&model.normalization)
    );
}

#[test]
fn too_little_data_for_the_states_says_what_to_change() {
    let dir = tempfile::tempdir().unwrap();
    let params = SynthParams {
        minutes: 0.2,
        seed: 4,
        take_seconds: 60.0,
    };
    write_corpus(&params, dir.path(), |_, _| {}).unwrap();
    let corpus = load_corpus(&[dir.path().to_path_buf()], &LoadOptions::default()).unwrap();
    let (seqs, segs) = sequences(&corpus, None);
    let err = fit(
        &seqs,
        &segs,
        &FitConfig {
            states: Some(25),
            ..FitConfig::default()
        },
        &|_| {},
    )
    .unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("fewer states") && msg.contains("more data"),
        "{msg}"
    );
}

fn eval_args(train: &str, test: &str) -> gesture_trainer::cli::eval_inference::EvalArgs {
    use clap::Parser;
    #[derive(clap::Parser)]
    struct W {
        #[command(flatten)]
        a: gesture_trainer::cli::eval_inference::EvalArgs,
    }
    W::parse_from(["x", "--train", train, "--test", test]).a
}

#[test]
fn fig4_on_synthetic_data_crf_beats_hmm_and_prior_and_states_are_recovered() {
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    for (dir, minutes, seed) in [(a.path(), 10.0, 101), (b.path(), 5.0, 202)] {
        let params = SynthParams {
            minutes,
            seed,
            take_seconds: 60.0,
        };
        write_corpus(&params, dir, |_, _| {}).unwrap();
    }
    let mut args = eval_args(a.path().to_str().unwrap(), b.path().to_str().unwrap());
    args.model.states = Some(4);
    let report = gesture_trainer::cli::eval_inference::evaluate(&args).unwrap();
    assert_eq!(report.rows.len(), 5);
    for r in &report.rows {
        eprintln!(
            "W={}: crf {:.3} hmm {:.3} prior {:.3}",
            r.window, r.crf, r.hmm, r.prior
        );
        assert!(
            r.crf > r.hmm && r.crf > r.prior,
            "window {}: {r:?}",
            r.window
        );
    }
    // The HMM's states on the training corpus recover the planted ones.
    let (ari, _) = report
        .ari
        .expect("truth.json is next to the training corpus");
    assert!(ari >= 0.7, "ARI {ari}");
}

#[test]
fn fig4_on_the_real_take_crf_beats_hmm_and_prior_for_every_window() {
    let Some(dir) = zeroeggs("fig4_on_the_real_take_crf_beats_hmm_and_prior_for_every_window")
    else {
        return;
    };
    let d = dir.to_str().unwrap();
    let mut args = eval_args(d, d);
    args.train_span = Some((0.0, 40.0));
    args.test_span = Some((40.0, 50.0));
    // The model selection's choice (S = 2, K = 2: the CRF near the prior; W = 1: crf -4.931,
    // hmm -5.023, prior -5.000) and more states given.
    for states in [None, Some(4usize), Some(8)] {
        args.model.states = states;
        let report = gesture_trainer::cli::eval_inference::evaluate(&args).unwrap();
        for r in &report.rows {
            eprintln!(
                "  W={}: crf {:.3} hmm {:.3} prior {:.3}",
                r.window, r.crf, r.hmm, r.prior
            );
            assert!(
                r.crf > r.hmm && r.crf > r.prior,
                "S={states:?} window {}: {r:?}",
                r.window
            );
        }
    }
}

fn synthetic_takes(minutes: f64) -> (tempfile::TempDir, gesture_trainer::corpus::Corpus) {
    let dir = tempfile::tempdir().unwrap();
    let params = SynthParams {
        minutes,
        seed: 7,
        take_seconds: 60.0,
    };
    write_corpus(&params, dir.path(), |_, _| {}).unwrap();
    let corpus = load_corpus(&[dir.path().to_path_buf()], &LoadOptions::default()).unwrap();
    (dir, corpus)
}

#[test]
fn cross_validation_holds_each_span_out_once_and_purges_the_segments_reaching_into_it() {
    use gesture_trainer::inference::train::cv_split;
    let (_dir, corpus) = synthetic_takes(2.0);
    assert_eq!(corpus.takes.len(), 2);
    let (take, other) = (&corpus.takes[0], &corpus.takes[1]);
    let dt = take.motion.frame_time;
    let mut tested = Vec::new();
    for k in 0..3 {
        let split = cv_split(&corpus, k, 3, |s| s == take.stem);
        let len = take.motion_s();
        let lo = len * k as f64 / 3.0;
        let hi = if k == 2 {
            f64::INFINITY
        } else {
            len * (k + 1) as f64 / 3.0
        };
        // Only the named take is held out, and only steps whose midpoint is in the span.
        assert_eq!(split.test.len(), 1);
        assert_eq!(split.test[0].stem, take.stem);
        for &(a, b) in &split.test[0].times {
            let mid = 0.5 * (a + b);
            assert!(mid >= lo && mid < hi, "fold {k}: step {a}-{b}");
        }
        tested.extend(split.test[0].times.iter().copied());
        // The other take trains whole, as one sequence.
        let others: Vec<_> = split
            .train
            .iter()
            .filter(|s| s.stem == other.stem)
            .collect();
        assert_eq!(others.len(), 1);
        assert_eq!(others[0].len(), other.aligned.len());
        // No training step of the held-out take overlaps a motion segment that reaches into
        // the span; a middle span leaves two pieces, the first and last one piece.
        let reaching: Vec<(f64, f64)> = take
            .motion
            .segments
            .iter()
            .map(|g| (g.start_frame as f64 * dt, g.end_frame as f64 * dt))
            .filter(|&(g0, g1)| g0 < hi && g1 > lo)
            .collect();
        assert!(!reaching.is_empty());
        let pieces: Vec<_> = split.train.iter().filter(|s| s.stem == take.stem).collect();
        assert_eq!(pieces.len(), if k == 1 { 2 } else { 1 }, "fold {k}");
        for p in &pieces {
            for &(a, b) in &p.times {
                for &(g0, g1) in &reaching {
                    assert!(!(a < g1 && b > g0), "fold {k}: step {a}-{b} in {g0}-{g1}");
                }
            }
        }
        if k == 1 {
            assert!(pieces[0].times.last().unwrap().1 <= pieces[1].times[0].0);
        }
        // Training steps plus held-out steps are fewer than the take's (some purged), and
        // the normalization sees only training segments: the other take's and fewer of this.
        let trained: usize = pieces.iter().map(|p| p.len()).sum();
        assert!(trained + split.test[0].len() < take.aligned.len());
        assert!(split.segments.len() < take.motion.segments.len() + other.motion.segments.len());
        assert!(split.segments.len() >= other.motion.segments.len());
    }
    // With pooled levels every take, trained or held out, is standardized alike, by the level
    // of all training segments together; with their own, the two takes differ.
    use gesture_trainer::inference::train::cv_split_levels;
    let level_of = |s: &Sequence| (s.level.mean, s.level.scale);
    for own in [false, true] {
        let split = cv_split_levels(&corpus, 1, 3, |s| s == take.stem, own);
        let first = level_of(&split.train[0]);
        let alike = split
            .train
            .iter()
            .chain(&split.test)
            .all(|s| level_of(s) == first);
        assert_eq!(alike, !own, "own levels: {own}");
        // Either way the standardized training segments have zero mean and unit spread.
        let n = gesture_trainer::motion::Normalization::fit(&split.segments).unwrap();
        for d in 0..6 {
            assert!(
                n.mean[d].abs() < 1e-9 && (n.scale[d] - 1.0).abs() < 1e-9,
                "{n:?}"
            );
        }
    }
    // Every step of the take is held out exactly once over the folds.
    let all: Vec<(f64, f64)> = take
        .aligned
        .iter()
        .map(|a| (a.step.start_s(), a.step.end_s()))
        .collect();
    assert_eq!(tested, all);
}

#[test]
fn cross_validated_fig4_pools_the_folds_and_the_crf_beats_the_prior() {
    use clap::Parser;
    #[derive(clap::Parser)]
    struct W {
        #[command(flatten)]
        a: gesture_trainer::cli::eval_inference::EvalArgs,
    }
    let (dir, _) = synthetic_takes(6.0);
    let d = dir.path().to_str().unwrap();
    let mut args = W::parse_from(["x", "--train", d, "--folds", "3", "--windows", "1,4"]).a;
    // Fixed S, K and regularization: the folds' model selection is `fit`'s, tested elsewhere.
    args.model.states = Some(4);
    args.model.clusters = Some(4);
    args.model.l2 = Some(0.01);
    args.model.lag_penalty = Some(1.0);
    args.model.restarts = 4;
    let r = gesture_trainer::cli::eval_inference::cross_validate(&args).unwrap();
    assert_eq!(r.folds.len(), 3);
    let steps: usize = r.folds.iter().map(|f| f.test_steps).sum();
    let all = all_steps(d);
    assert_eq!(steps, all, "every step held out once");
    for (i, row) in r.rows.iter().enumerate() {
        // Pooled over the held-out steps, and the folds' gains with their standard error.
        let crf: f64 = r
            .folds
            .iter()
            .map(|f| f.rows[i].crf * f.test_steps as f64)
            .sum::<f64>()
            / steps as f64;
        let prior: f64 = r
            .folds
            .iter()
            .map(|f| f.rows[i].prior * f.test_steps as f64)
            .sum::<f64>()
            / steps as f64;
        assert!((row.crf - crf).abs() < 1e-9 && (row.gain - (crf - prior)).abs() < 1e-9);
        let g: Vec<f64> = r.folds.iter().map(|f| f.rows[i].gain).collect();
        assert_eq!(row.fold_gains, g);
        let m = g.iter().sum::<f64>() / 3.0;
        let se = (g.iter().map(|x| (x - m).powi(2)).sum::<f64>() / 2.0 / 3.0).sqrt();
        assert!((row.gain_se - se).abs() < 1e-12);
        // The planted states are audible: the CRF beats the prior on held-out spans.
        assert!(row.gain > 0.1, "window {}: {row:?}", row.window);
    }
    // --test must name training takes; spans and folds exclude each other.
    let other = tempfile::tempdir().unwrap();
    for ext in ["bvh", "wav"] {
        std::fs::copy(
            dir.path().join(format!("take_000.{ext}")),
            other.path().join(format!("elsewhere.{ext}")),
        )
        .unwrap();
    }
    let bad = W::parse_from([
        "x",
        "--train",
        d,
        "--test",
        other.path().to_str().unwrap(),
        "--folds",
        "3",
    ])
    .a;
    let err = gesture_trainer::cli::eval_inference::cross_validate(&bad).unwrap_err();
    assert!(
        err.to_string()
            .contains("elsewhere is not among the --train takes"),
        "{err}"
    );
    assert!(
        W::try_parse_from(["x", "--train", d, "--folds", "3", "--train-span", "0:30"]).is_err()
    );
    assert!(
        W::try_parse_from(["x", "--train", d]).is_err(),
        "--test or --folds"
    );
}

fn all_steps(d: &str) -> usize {
    load_corpus(&[PathBuf::from(d)], &LoadOptions::default())
        .unwrap()
        .takes
        .iter()
        .map(|t| t.aligned.len())
        .sum()
}

#[test]
fn cross_validated_on_the_9_joint_take_the_crf_beats_hmm_and_prior_alone_and_pooled() {
    use clap::Parser;
    #[derive(clap::Parser)]
    struct W {
        #[command(flatten)]
        a: gesture_trainer::cli::eval_inference::EvalArgs,
    }
    let test = "cross_validated_on_the_9_joint_take_the_crf_beats_hmm_and_prior_alone_and_pooled";
    let (Some(nine), Some(other)) = (
        e2e_tests::shared_data(test, "zeroeggs-001-neutral-9joint"),
        zeroeggs(test),
    ) else {
        return;
    };
    let (nine, other) = (nine.to_str().unwrap(), other.to_str().unwrap());
    // Default options (model selection in every fold), each quarter of the 9-joint take
    // held out in turn; pooled, the 067 take trains in every fold.
    let runs = [
        vec!["x", "--train", nine, "--folds", "4", "--windows", "1,4"],
        vec![
            "x",
            "--train",
            nine,
            other,
            "--test",
            nine,
            "--folds",
            "4",
            "--windows",
            "1,4",
        ],
    ];
    for (argv, pooled) in runs.iter().zip([false, true]) {
        let a = W::parse_from(argv).a;
        let r = gesture_trainer::cli::eval_inference::cross_validate(&a).unwrap();
        for row in &r.rows {
            eprintln!("{argv:?} {row:?}");
            assert!(row.crf > row.hmm, "{row:?}");
            assert!(row.gain > 0.2 && row.gain > 3.0 * row.gain_se, "{row:?}");
            if pooled {
                // Part of the gain over the pooled prior is telling the takes apart (the
                // pooled states are partly one take's or the other's): over the 9-joint
                // take's own state frequencies the CRF gains less (+0.319/+0.309 against
                // +0.426/+0.417), and less than the take alone (+0.372/+0.380).
                assert!(row.take_gain < row.gain, "{row:?}");
                assert!(row.take_gain > 0.2, "{row:?}");
            } else {
                // One take: its own state frequencies are the model's prior.
                assert!((row.take_gain - row.gain).abs() < 1e-9, "{row:?}");
            }
        }
    }
}

#[test]
fn cross_validated_on_the_067_take_the_crf_is_not_below_the_hmm_alone_or_pooled() {
    use clap::Parser;
    #[derive(clap::Parser)]
    struct W {
        #[command(flatten)]
        a: gesture_trainer::cli::eval_inference::EvalArgs,
    }
    let test = "cross_validated_on_the_067_take_the_crf_is_not_below_the_hmm_alone_or_pooled";
    let (Some(nine), Some(other)) = (
        e2e_tests::shared_data(test, "zeroeggs-001-neutral-9joint"),
        zeroeggs(test),
    ) else {
        return;
    };
    let (nine, other) = (nine.to_str().unwrap(), other.to_str().unwrap());
    let runs = [
        vec!["x", "--train", other, "--folds", "4"],
        vec!["x", "--train", other, nine, "--test", other, "--folds", "4"],
    ];
    for (argv, pooled) in runs.iter().zip([false, true]) {
        let a = W::parse_from(argv).a;
        let r = gesture_trainer::cli::eval_inference::cross_validate(&a).unwrap();
        for row in &r.rows {
            eprintln!("{argv:?} {row:?}");
            // Fig. 4's ordering over all held-out steps, at every window. Alone, 50 s of
            // speech leave the CRF at the prior (gain +0.018) and the HMM just below it
            // (W = 1: crf - hmm +0.075 +- 0.104): the CRF may not fall below the HMM by more
            // than a standard error.
            assert!(row.crf_hmm > -row.crf_hmm_se, "{row:?}");
            if pooled {
                // Pooled, the CRF's gain over the pooled prior (+0.285 at W = 1) is telling
                // the takes apart: over the 067 take's own state frequencies it is -0.394.
                assert!(row.crf > row.hmm, "{row:?}");
                assert!(row.gain > 0.1 && row.take_gain < row.gain, "{row:?}");
            }
        }
    }
}

/// Two planted takes whose speech tells them apart but says nothing about the state within
/// either: take `a` sits in state 0 nine steps in ten, take `b` in state 1, each with its own
/// prosody throughout. The state prior of the pooled model is half and half; a belief that
/// only recognizes the take gains over it, not over each take's own state frequencies.
fn planted_takes(steps: usize, seed: u64) -> Vec<Sequence> {
    use gesture_runtime::inference::StepFeatures;
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut normal = move |sd: f64| -> f64 {
        // Box-Muller.
        let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-12), rng.random::<f64>());
        sd * (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    let mut out = Vec::new();
    for (stem, home, pitch) in [("a", 0usize, 0.8f64), ("b", 1, -0.8)] {
        let mut s = Sequence {
            stem: stem.into(),
            ..Sequence::default()
        };
        let mut state = home;
        for t in 0..steps {
            // Runs: redraw the state one step in six, the take's own state nine times in ten.
            if normal(1.0).abs() > 1.38 {
                state = if normal(1.0).abs() < 1.645 {
                    home
                } else {
                    1 - home
                };
            }
            let level = if state == 0 { 1.5 } else { -1.5 };
            s.y_raw.push(std::array::from_fn(|_| level + normal(0.3)));
            s.features.push(StepFeatures {
                f0: Some((pitch + normal(0.3)) as f32),
                obs: [
                    (pitch + normal(0.3)) as f32,
                    (0.5 * pitch + normal(0.3)) as f32,
                ],
                pause: false,
            });
            let t0 = t as f64 * 0.3;
            s.times.push((t0, t0 + 0.3));
            s.segments.push((t0, t0 + 0.3));
        }
        out.push(s);
    }
    out
}

#[test]
fn the_take_gain_does_not_count_telling_the_takes_apart() {
    use gesture_trainer::inference::eval::evaluate;
    let train = planted_takes(400, 11);
    let test = planted_takes(200, 12);
    let segs: Vec<[f64; 6]> = train.iter().flat_map(|s| s.y_raw.clone()).collect();
    let cfg = FitConfig {
        states: Some(2),
        clusters: Some(2),
        l2: Some(1e-3),
        lag_penalty: Some(1.0),
        restarts: 4,
        ..FitConfig::default()
    };
    let r = evaluate((&train, &segs), &test, &cfg, &[1, 4], (None, None), &|_| {}).unwrap();
    for row in &r.rows {
        eprintln!("{row:?}");
        // Recognizing the take is worth what the take's own state frequencies are worth over
        // the pooled prior (+0.21 nats per step here) ...
        assert!(row.take_prior > row.prior + 0.1, "{row:?}");
        assert!(row.gain > 0.1 && row.gain > 5.0 * row.gain_se, "{row:?}");
        // ... and nothing over them.
        assert!(row.take_gain.abs() < 0.05, "{row:?}");
    }
    // The offset to log-densities of the unnormalized targets: the log-determinant of the
    // model's normalization (the takes' levels are the identity here), and a take at twice
    // the spread has 6 ln 2 less density per step.
    let norm = gesture_trainer::motion::Normalization::fit(&segs).unwrap();
    let log_det: f64 = norm.scale.iter().map(|s| -s.ln()).sum();
    assert!(
        (r.raw_offset - log_det).abs() < 1e-9,
        "{} {log_det}",
        r.raw_offset
    );
    let mut wide = test.clone();
    wide.iter_mut().for_each(|s| s.level.scale = [2.0; 6]);
    let r2 = evaluate((&train, &segs), &wide, &cfg, &[1], (None, None), &|_| {}).unwrap();
    assert!((r2.raw_offset - (log_det - 6.0 * 2f64.ln())).abs() < 1e-9);
    // A take the model was not trained on has no frequencies of its own: the take prior is
    // the model's prior.
    let mut other = test.clone();
    other
        .iter_mut()
        .for_each(|s| s.stem = format!("new-{}", s.stem));
    let r = evaluate((&train, &segs), &other, &cfg, &[1], (None, None), &|_| {}).unwrap();
    assert_eq!(r.rows[0].take_prior, r.rows[0].prior);
    assert_eq!(r.rows[0].take_gain, r.rows[0].gain);
}
