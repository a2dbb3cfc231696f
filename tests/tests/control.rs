//! The control layer end to end: the runtime Controller (quantized inference and policy)
//! against the trainer's float, unpruned policy on real audio from another speaker.

use std::path::PathBuf;

use gesture_runtime::controller::{Controller, ControllerEvent};
use gesture_runtime::inference::StepNormalizer;
use gesture_runtime::player::LibraryFrames;
use gesture_runtime::policy::Choice;
use gesture_runtime::prosody::{ProsodyConfig, StepKind};
use gesture_trainer::control::build::{build, ControlParams, QuantizedPolicy};
use gesture_trainer::control::{Action, Library};
use gesture_trainer::corpus::{load_corpus, LoadOptions};
use gesture_trainer::inference::quantize::QuantizedInference;
use gesture_trainer::inference::train::{fit, prosody_point, sequences, FitConfig};
use gesture_trainer::motion::{EffectorSpec, SegmentParams};

fn data() -> Option<PathBuf> {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/data");
    d.join("beat-scott").is_dir().then_some(d)
}

/// Segment lengths only: decisions do not depend on the poses.
struct Lengths(Vec<usize>, f32);

impl LibraryFrames for Lengths {
    fn channels(&self) -> usize {
        0
    }
    fn fps(&self) -> f32 {
        self.1
    }
    fn segment_count(&self) -> usize {
        self.0.len()
    }
    fn segment_len(&self, c: usize) -> usize {
        self.0[c]
    }
    fn value(&self, _: usize, _: usize, _: usize) -> f32 {
        0.0
    }
}

#[test]
fn runtime_decisions_agree_with_the_float_policy_on_another_speaker() {
    let Some(d) = data() else {
        eprintln!("skipping: ../shared/data is absent, nothing measured");
        return;
    };
    // Model and library from the ZeroEGGS take.
    let ze = d.join("zeroeggs-067-speech2");
    let corpus = load_corpus(std::slice::from_ref(&ze), &LoadOptions::default()).unwrap();
    let (seqs, segs) = sequences(&corpus, None);
    let (model, _) = fit(&seqs, &segs, &FitConfig::default(), &|_| {}).unwrap();
    let lib = Library::from_files(
        &[ze.join("067_Speech_2_first50s.bvh")],
        &model.normalization,
        &EffectorSpec::default(),
        &SegmentParams::default(),
        3,
    )
    .unwrap();
    let cm = build(&model, &lib, &ControlParams::default());
    let qp = QuantizedPolicy::new(&lib, &cm);
    let qi = QuantizedInference::new(&model.gmm, &model.crf);
    let lengths = Lengths(
        lib.segments.iter().map(|s| s.len()).collect(),
        lib.fps as f32,
    );
    let pruned = 1.0 - cm.entries_kept() as f64 / cm.entries_total() as f64;
    eprintln!(
        "library {} segments, {} exits; pruned {:.1}%",
        lib.segments.len(),
        lib.exits.len(),
        100.0 * pruned
    );

    let (mut agree, mut total) = (0usize, 0usize);
    for wav in ["2_scott_0_1_1.wav", "2_scott_0_2_2.wav"] {
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
        // The device: quantized everything, through the runtime Controller.
        let mut ctl = Controller::new(
            &ProsodyConfig::DEFAULT,
            &qi.gmm,
            qi.weights().unwrap(),
            &qp,
            &lengths,
        )
        .unwrap();
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
            "{wav}: {} steps ({} syllables)",
            steps.len(),
            steps
                .iter()
                .filter(|s| s.kind == StepKind::Syllable)
                .count()
        );
    }
    let rate = agree as f64 / total as f64;
    eprintln!("decisions: {agree} of {total} agree ({:.2}%)", 100.0 * rate);
    assert!(total > 150, "{total} decisions");
    assert!(rate >= 0.99, "agreement {rate}");
}
