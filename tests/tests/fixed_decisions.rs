//! The fixed-point controller (the front-end of boards without an FPU) against the `f32` one
//! on the same blob and the shared speech: the same decisions on at least 95 % of them.
//!
//! One model and library from the ZeroEGGS take, packed as `gesture-train pack` does by
//! default (variety, following the voice), run by `BlobController::<Float>` and
//! `BlobController::<Fixed>` over every speech recording of the shared data that was not
//! used for training. A decision counts as equal when both controllers took it at the same
//! tick and exit with the same choice. Once two runs choose differently they play different
//! segments and reach different exits, so every later decision may count as different until
//! they meet again; the report says where each file first diverged and how the two front-ends'
//! steps differed before it (the only input of the decisions that the arithmetic changes).
//! Skips, saying so, when the data folder is absent.

use std::path::PathBuf;

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, ControllerEvent};
use gesture_runtime::policy::Choice;
use gesture_runtime::prosody::arith::{Arith, Fixed, Float};
use gesture_runtime::prosody::Step;
use gesture_trainer::corpus::{load_corpus, LoadOptions};
use gesture_trainer::inference::train::{fit, sequences, FitConfig};
use gesture_trainer::pack::{pack_model, PackOptions};

fn data(test: &str) -> Option<PathBuf> {
    e2e_tests::shared_data(test, "beat-scott")?;
    e2e_tests::shared_data(test, "zeroeggs-067-speech2")?;
    e2e_tests::shared_data(test, "zeroeggs-001-neutral-9joint")?;
    e2e_tests::shared_data(test, "cmu-arctic")?;
    Some(e2e_tests::shared_data_dir())
}

/// What one controller did on one recording.
struct Run {
    /// `(tick, exit, choice)` of every decision (their costs differ with the belief).
    decisions: Vec<(u64, usize, Choice)>,
    steps: Vec<Step>,
}

fn run<A: Arith>(blob: &Blob<'_>, samples: &[i16]) -> Run {
    let mut ctl = BlobController::<A>::from_blob_arith(blob).unwrap();
    let mut out = Run {
        decisions: Vec::new(),
        steps: Vec::new(),
    };
    let mut sink = |e: ControllerEvent<'_>| match e {
        ControllerEvent::Decision { tick, decision } => {
            out.decisions.push((tick, decision.exit, decision.choice))
        }
        ControllerEvent::Step { step, .. } => out.steps.push(step),
        _ => {}
    };
    ctl.push(samples, &mut sink);
    ctl.finish(&mut sink);
    out
}

#[test]
fn fixed_point_controller_decides_as_the_f32_one() {
    const TEST: &str = "fixed_point_controller_decides_as_the_f32_one";
    let Some(d) = data(TEST) else {
        return;
    };
    let ze = d.join("zeroeggs-067-speech2");
    let corpus = load_corpus(std::slice::from_ref(&ze), &LoadOptions::default()).unwrap();
    let (seqs, segs) = sequences(&corpus, None);
    let (model, _) = fit(&seqs, &segs, &FitConfig::default(), &|_| {}).unwrap();
    let packed = pack_model(
        &model,
        &[ze.join("067_Speech_2_first50s.bvh")],
        &PackOptions::default(),
    )
    .unwrap();
    let blob = Blob::parse(&packed.bytes).unwrap();
    let mut wavs: Vec<PathBuf> = vec![
        d.join("beat-scott/2_scott_0_1_1.wav"),
        d.join("beat-scott/2_scott_0_2_2.wav"),
        d.join("zeroeggs-001-neutral-9joint/001_Neutral_0_x_1_0.wav"),
    ];
    for folder in ["cmu-arctic", "shippable/librispeech", "shippable/ljspeech"] {
        let Ok(entries) = std::fs::read_dir(d.join(folder)) else {
            continue;
        };
        let mut more: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "wav"))
            .collect();
        more.sort();
        wavs.extend(more);
    }
    let (mut equal, mut total) = (0usize, 0usize);
    for wav in &wavs {
        let pcm = gesture_trainer::audio::load_wav_at(wav, 16_000).unwrap();
        let a = run::<Float>(&blob, &pcm.samples);
        let b = run::<Fixed>(&blob, &pcm.samples);
        let same = a
            .decisions
            .iter()
            .filter(|x| b.decisions.contains(x))
            .count();
        let first = a
            .decisions
            .iter()
            .zip(b.decisions.iter())
            .position(|(x, y)| x != y);
        // The steps the two front-ends reported before the first divergence, and how many of
        // them differ in their boundaries or their voicing.
        let until = first
            .and_then(|k| a.decisions.get(k))
            .map_or(u64::MAX, |(t, _, _)| *t);
        let ms_per_tick = 1000.0 / blob.fps() as f64;
        let before = |s: &&Step| (s.end_s() * 1000.0) < until as f64 * ms_per_tick;
        let (sa, sb): (Vec<&Step>, Vec<&Step>) = (
            a.steps.iter().filter(before).collect(),
            b.steps.iter().filter(before).collect(),
        );
        let differing = sa
            .iter()
            .zip(sb.iter())
            .filter(|(x, y)| {
                x.start_frame != y.start_frame
                    || x.end_frame != y.end_frame
                    || x.f0_hz.is_some() != y.f0_hz.is_some()
            })
            .count()
            + sa.len().abs_diff(sb.len());
        eprintln!(
            "{}: {} of {} decisions equal; steps {} (f32) {} (fixed); first divergence: {}",
            wav.file_name().unwrap().to_string_lossy(),
            same,
            a.decisions.len(),
            a.steps.len(),
            b.steps.len(),
            match first {
                None => "none".to_string(),
                Some(k) => format!(
                    "decision {k} at tick {until}, after {} steps of which {differing} differ in \
                     boundaries or voicing",
                    sa.len()
                ),
            }
        );
        equal += same;
        total += a.decisions.len();
    }
    let rate = equal as f64 / total.max(1) as f64;
    eprintln!(
        "fixed-point vs f32 controller: {equal} of {total} decisions equal ({:.2}%)",
        100.0 * rate
    );
    assert!(total > 300, "{total} decisions");
    assert!(rate >= 0.95, "equal decisions {rate}");
}
