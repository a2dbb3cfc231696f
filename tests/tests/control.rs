//! The control layer end to end: the packed blob's bytes through the runtime's controller
//! (quantized inference and policy) against the trainer's float, unpruned policy on real
//! audio from another speaker.

use std::path::PathBuf;

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, ControllerEvent, DecisionTiming};
use gesture_runtime::inference::StepNormalizer;
use gesture_runtime::policy::Choice;
use gesture_runtime::prosody::{ProsodyConfig, StepKind};
use gesture_trainer::control::Action;
use gesture_trainer::corpus::{load_corpus, LoadOptions};
use gesture_trainer::inference::train::{fit, prosody_point, sequences, FitConfig};
use gesture_trainer::pack::{pack_model, PackOptions};

fn data(test: &str) -> Option<PathBuf> {
    e2e_tests::shared_data(test, "beat-scott")?;
    e2e_tests::shared_data(test, "zeroeggs-067-speech2")?;
    Some(e2e_tests::shared_data_dir())
}

#[test]
fn runtime_decisions_agree_with_the_float_policy_on_another_speaker() {
    let Some(d) = data("runtime_decisions_agree_with_the_float_policy_on_another_speaker") else {
        return;
    };
    // Model and library from the ZeroEGGS take.
    let ze = d.join("zeroeggs-067-speech2");
    let corpus = load_corpus(std::slice::from_ref(&ze), &LoadOptions::default()).unwrap();
    let (seqs, segs) = sequences(&corpus, None);
    let (model, _) = fit(&seqs, &segs, &FitConfig::default(), &|_| {}).unwrap();
    let mut packed = Vec::new();
    for timing in [DecisionTiming::DEFAULT, DecisionTiming::IMMEDIATE] {
        let opts = PackOptions {
            timing,
            ..PackOptions::default()
        };
        packed.push(pack_model(&model, &[ze.join("067_Speech_2_first50s.bvh")], &opts).unwrap());
    }
    let (lib, cm) = (&packed[0].library, &packed[0].control);
    let pruned = 1.0 - cm.entries_kept() as f64 / cm.entries_total() as f64;
    eprintln!(
        "library {} segments, {} exits; pruned {:.1}%",
        lib.segments.len(),
        lib.exits.len(),
        100.0 * pruned
    );

    let (mut agree, mut total) = (0usize, 0usize);
    // Decisions on onsets (the default), and at every exit point (more decision points).
    for (wav, p) in [
        ("2_scott_0_1_1.wav", &packed[0]),
        ("2_scott_0_2_2.wav", &packed[0]),
        ("2_scott_0_1_1.wav", &packed[1]),
        ("2_scott_0_2_2.wav", &packed[1]),
    ] {
        let blob = Blob::parse(&p.bytes).unwrap();
        let timing = blob.timing();
        let pcm = gesture_trainer::audio::load_wav(d.join("beat-scott").join(wav)).unwrap();
        // Float beliefs after every step, from the trainer's float GMM and CRF.
        let (_, steps) =
            gesture_trainer::features::prosody_of(&pcm.samples, &ProsodyConfig::DEFAULT).unwrap();
        let mut norm = StepNormalizer::new();
        let m: Vec<Vec<f64>> = steps
            .iter()
            .map(|s| model.gmm.memberships(&prosody_point(&norm.push(s))))
            .collect();
        let float_beliefs = model.crf.beliefs(&m);
        // The device: the blob's bytes, quantized everything, through the runtime controller.
        let mut ctl = BlobController::from_blob(&blob).unwrap();
        let mut decisions = Vec::new();
        let mut seen_steps = 0usize;
        ctl.push(&pcm.samples, &mut |e| match e {
            ControllerEvent::Step { .. } => seen_steps += 1,
            ControllerEvent::Decision { decision, .. } => decisions.push((seen_steps, decision)),
            _ => {}
        });
        let s = model.states();
        for (k, d) in decisions {
            let b = if k == 0 {
                vec![1.0 / s as f64; s]
            } else {
                float_beliefs[k - 1].clone()
            };
            let float = cm.policy.decide(d.exit, &b, 0..lib.segments.len());
            let device = match d.choice {
                Choice::Continue => Action::Continue,
                Choice::Enter(c) => Action::Enter(c),
            };
            total += 1;
            // Equal choices, or exactly equal float costs (a tie the float policy breaks the
            // other way) count as agreement.
            if float == device
                || cm.policy.cost(d.exit, float, &b) == cm.policy.cost(d.exit, device, &b)
            {
                agree += 1;
            }
        }
        eprintln!(
            "{wav} ({timing:?}): {} steps ({} syllables)",
            steps.len(),
            steps
                .iter()
                .filter(|s| s.kind == StepKind::Syllable)
                .count()
        );
    }
    let rate = agree as f64 / total as f64;
    eprintln!("decisions: {agree} of {total} agree ({:.2}%)", 100.0 * rate);
    assert!(total > 300, "{total} decisions");
    assert!(rate >= 0.99, "agreement {rate}");
}

#[derive(clap::Parser)]
struct FitCli {
    #[command(flatten)]
    args: gesture_trainer::cli::fit::FitArgs,
}

#[derive(clap::Parser)]
struct EvalCli {
    #[command(flatten)]
    args: gesture_trainer::cli::eval_motion::EvalMotionArgs,
}

/// The motion-quality requirement of the control layer, with the command-line defaults: a model fitted
/// on ZeroEGGS 0-40 s, the take's own library, the device's online controller (quantized,
/// decisions on syllable onsets) against random selection from the same library, on held-out
/// speech: ZeroEGGS 40-50 s and both beat-scott monologues (another speaker).
#[test]
fn online_controller_beats_random_on_jumps_and_beat_alignment_on_held_out_speech() {
    use clap::Parser;
    let Some(d) = data("online_controller_beats_random_on_jumps_and_beat_alignment") else {
        return;
    };
    let ze = d.join("zeroeggs-067-speech2");
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model.json");
    let fit = FitCli::parse_from([
        "fit".as_ref(),
        "--corpus".as_ref(),
        ze.as_os_str(),
        "--span".as_ref(),
        "0:40".as_ref(),
        "--out".as_ref(),
        model.as_os_str(),
    ]);
    gesture_trainer::cli::fit::run(&fit.args).unwrap();
    let wav = ze.join("067_Speech_2_first50s.wav");
    let bvh = ze.join("067_Speech_2_first50s.bvh");
    let scott = d.join("beat-scott");
    let (s1, s2) = (
        scott.join("2_scott_0_1_1.wav"),
        scott.join("2_scott_0_2_2.wav"),
    );
    let cases: Vec<(Vec<&std::ffi::OsStr>, &str)> = vec![
        (
            vec![
                "--audio".as_ref(),
                wav.as_os_str(),
                "--mocap".as_ref(),
                bvh.as_os_str(),
                "--span".as_ref(),
                "40:50".as_ref(),
            ],
            "zeroeggs 40-50 s",
        ),
        (vec!["--audio".as_ref(), s1.as_os_str()], "2_scott_0_1_1"),
        (vec!["--audio".as_ref(), s2.as_os_str()], "2_scott_0_2_2"),
    ];
    for (extra, name) in cases {
        let mut argv: Vec<&std::ffi::OsStr> = vec![
            "eval-motion".as_ref(),
            "--model".as_ref(),
            model.as_os_str(),
            "--library".as_ref(),
            ze.as_os_str(),
        ];
        argv.extend(extra);
        let rows =
            gesture_trainer::cli::eval_motion::evaluate(&EvalCli::parse_from(argv).args).unwrap();
        let get = |m: &str| rows.rows.iter().find(|r| r.method == m).unwrap().metrics;
        let (online, random) = (get("online"), get("random"));
        eprintln!(
            "{name}: jump at cuts {:.2} vs random {:.2}; beat alignment {:.3} vs random {:.3}; \
             cuts/s {:.2} vs {:.2}",
            online.jump_at_cuts,
            random.jump_at_cuts,
            online.beat_alignment,
            random.beat_alignment,
            online.cuts_per_s,
            random.cuts_per_s
        );
        // The online controller must make cuts (following the recorded order would win on
        // jumps by never cutting), and make them smaller than random ones.
        assert!(online.cuts_per_s > 0.1, "{name}: {online:?}");
        assert!(
            online.jump_at_cuts < random.jump_at_cuts,
            "{name}: {online:?} vs {random:?}"
        );
        assert!(
            online.beat_alignment > random.beat_alignment,
            "{name}: {online:?} vs {random:?}"
        );
    }
}
