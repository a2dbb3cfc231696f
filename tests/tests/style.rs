//! Style control end to end on real motion: tones fitted on Bandai Namco's styled clips
//! (another character and skeleton) and the energy knob's synthetic tones restyle a ZeroEGGS
//! library driven by speech the model and library never saw. (Without the shared data the
//! plumbing is tested on the synthetic character by host-sim's `style` tests, and the
//! transform and the mixing by the trainer's and the runtime's unit tests.)

use std::path::PathBuf;

use gesture_trainer::corpus::{load_corpus, LoadOptions};
use gesture_trainer::evaluate::motion::MotionEval;
use gesture_trainer::evaluate::style::{evaluate_styles, StyleEvaluation};
use gesture_trainer::inference::train::{fit, sequences, FitConfig};
use gesture_trainer::pack::{PackOptions, StyleOptions};

fn bvh(dir: &std::path::Path, contains: &[&str]) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let n = p.file_name().unwrap().to_string_lossy();
            n.ends_with(".bvh") && contains.iter().any(|c| n.contains(c))
        })
        .collect();
    v.sort();
    v
}

fn ratio(ev: &StyleEvaluation, style: &str) -> f64 {
    ev.rows
        .iter()
        .find(|r| r.style == style)
        .unwrap()
        .hand_speed_ratio
}

#[test]
fn bandai_tones_restyle_a_zeroeggs_library_on_new_speech() {
    let test = "bandai_tones_restyle_a_zeroeggs_library_on_new_speech";
    let (Some(nine), Some(bandai), Some(scott)) = (
        e2e_tests::shared_data(test, "zeroeggs-001-neutral-9joint"),
        e2e_tests::shared_data(test, "bandai-namco-gestures"),
        e2e_tests::shared_data(test, "beat-scott"),
    ) else {
        return;
    };
    // The model from the first 90 s of the 9-joint take; the library is the take; the speech
    // is another speaker's.
    let corpus = load_corpus(std::slice::from_ref(&nine), &LoadOptions::default()).unwrap();
    let (seqs, segs) = sequences(&corpus, Some((0.0, 90.0)));
    let (model, _) = fit(&seqs, &segs, &FitConfig::default(), &|_| {}).unwrap();
    let d1 = bandai.join("dataset-1");
    let styles = StyleOptions {
        neutral: bvh(
            &d1,
            &[
                "_bow_normal",
                "_bye_normal",
                "_byebye_normal",
                "_guide_normal",
            ],
        ),
        tones: vec![
            ("active".into(), bvh(&d1, &["_active_"])),
            ("sad".into(), bvh(&d1, &["_sad_"])),
        ],
        energy: Some(1.5),
    };
    assert_eq!(
        (
            styles.neutral.len(),
            styles.tones[0].1.len(),
            styles.tones[1].1.len()
        ),
        (4, 4, 4)
    );
    let e = MotionEval {
        library: vec![nine],
        audio: vec![scott.join("2_scott_0_1_1.wav")],
        mocap: None,
        span: None,
        random_runs: 1,
        device_runs: gesture_trainer::evaluate::motion::DEFAULT_DEVICE_RUNS,
        pack: PackOptions {
            styles,
            ..PackOptions::default()
        },
        lookahead: Vec::new(),
    };
    let specs: Vec<String> = [
        "neutral",
        "active=1",
        "sad=1",
        "active=0.5,sad=0.5",
        "energetic=1",
        "calm=1",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let ev = evaluate_styles(&model, &e, &specs).unwrap();
    for r in &ev.rows {
        eprintln!(
            "{:<20} hand {:.2} x{:.3} T,D,V,A,C,H x{:.3?}",
            r.style, r.hand_speed, r.hand_speed_ratio, r.kinematics_ratio
        );
    }
    let (active, sad, mix) = (
        ratio(&ev, "active=1"),
        ratio(&ev, "sad=1"),
        ratio(&ev, "active=0.5,sad=0.5"),
    );
    // Means of 30 delayed runs (a single run's ratio moved by 0.2 between settings): active
    // x1.06, sad x0.65, the mix x0.99, energetic x1.04, calm x0.86 with the default timing,
    // the voice followed and the default variety (before the voice: x1.11, x0.50, x0.85,
    // x1.07, x0.91). The neutral style follows the voice's energy (loud syllables bring
    // energetic segments, and no rest is shown while speaking), which is much of what an
    // active tone adds: the tones still order the motion, but active and energetic add little
    // over the voice. (With the voice's energy term on the neutral share alone, energetic was
    // x0.95: slower than neutral.)
    assert!(active > 1.0, "active x{active}");
    assert!(sad <= 0.87, "sad x{sad}");
    assert!(
        sad < mix && mix < active,
        "mix x{mix} not between {sad} and {active}"
    );
    // The energy knob (no tone data): calm slower than neutral, energetic faster than calm.
    let (up, down) = (ratio(&ev, "energetic=1"), ratio(&ev, "calm=1"));
    assert!(
        up > down + 0.1 && down < 0.95,
        "energetic x{up}, calm x{down}"
    );
    // An energetic tone keeps the voice's energy: it is not slower than neutral.
    assert!(
        up >= 1.0 && active >= 1.0,
        "energetic x{up}, active x{active}"
    );
}
