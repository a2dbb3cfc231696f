//! `pack --rig` with the shipped puppet rigs, unchanged, on a library of every skeleton the
//! project meets: the synthetic character, ZeroEGGS (75 and 9 joints), Bandai Namco, CMU and
//! ReActIdle (no hands: its wrists are the forearms' end sites). The model is one fitted on a
//! small synthetic corpus (as the simulator's tests do); what is checked is the rig's side:
//! the pack succeeds, says per channel what it reads (or that it holds its neutral), and its
//! blob carries body drives that the simulator can put back on the skeleton.
//! Tests on `../shared/data` print "skipping: ..." and pass when it is absent.

use std::path::{Path, PathBuf};

use gesture_runtime::blob::{Blob, DriveMode};
use gesture_trainer::corpus::{load_corpus, LoadOptions};
use gesture_trainer::inference::train::{fit, sequences, FitConfig};
use gesture_trainer::motion::EffectorSpec;
use gesture_trainer::pack::{pack, PackOptions};
use gesture_trainer::rig::PoseSkeleton;
use gesture_trainer::synth::{write_corpus, SynthParams};

fn rig(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../rigs")
        .join(name)
}

/// Packs `library` with both shipped rigs; returns the puppet-8ch report's channel lines.
fn pack_both(
    model: &Path,
    out: &Path,
    label: &str,
    library: &[PathBuf],
    hands: Option<[&str; 2]>,
) -> Vec<String> {
    let mut lines = Vec::new();
    for r in ["puppet-8ch.toml", "puppet-pca9685.toml"] {
        let mut opts = PackOptions {
            rig: Some(rig(r)),
            ..PackOptions::default()
        };
        if let Some(h) = hands {
            opts.effectors = EffectorSpec::joints(h);
        }
        let blob = out.join(format!("{label}-{r}.blob"));
        let report =
            pack(model, library, &opts, &blob).unwrap_or_else(|e| panic!("{label}, {r}: {e}"));
        assert_eq!(report.rig_channels.len(), 8, "{label}");
        if lines.is_empty() {
            eprintln!("{label} ({r}): {} frames", report.frames);
            for l in &report.rig_channels {
                eprintln!("  {l}");
            }
            lines = report.rig_channels.clone();
        } else {
            // The two rigs differ only in their PWM period and name.
            assert_eq!(report.rig_channels, lines, "{label}");
        }
        let bytes = std::fs::read(&blob).unwrap();
        let b = Blob::parse(&bytes).unwrap();
        let sk = b.skeleton().expect("a skeleton section");
        assert!((0..sk.drives()).all(|c| matches!(sk.drive(c).unwrap().mode, DriveMode::Body(_))));
        // The simulator's inverse: a played pose read back from the rebuilt frame.
        let pose_sk = PoseSkeleton::from_blob(&sk).unwrap();
        let mut pose = vec![0.0f32; b.channels()];
        b.pose(b.frames() / 2, &mut pose);
        assert!(pose_sk.frame(&pose).iter().all(|v| v.is_finite()));
    }
    lines
}

/// (label, files or folders, effectors when the skeleton has no hands).
type Library = (&'static str, Vec<PathBuf>, Option<[&'static str; 2]>);

#[test]
fn shipped_puppet_rigs_pack_every_library() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    let corpus = root.join("corpus");
    std::fs::create_dir_all(&corpus).unwrap();
    let params = SynthParams {
        minutes: 1.0,
        seed: 5,
        take_seconds: 30.0,
    };
    write_corpus(&params, &corpus, |_, _| {}).unwrap();
    let c = load_corpus(std::slice::from_ref(&corpus), &LoadOptions::default()).unwrap();
    let (seqs, segs) = sequences(&c, None);
    let cfg = FitConfig {
        states: Some(3),
        clusters: Some(3),
        window: 3,
        restarts: 1,
        l2: Some(1e-3),
        ..FitConfig::default()
    };
    let (model, _) = fit(&seqs, &segs, &cfg, &|_| {}).unwrap();
    let model_path = root.join("model.json");
    model.save(&model_path).unwrap();

    let synth = pack_both(
        &model_path,
        root,
        "synthetic",
        std::slice::from_ref(&corpus),
        None,
    );
    assert!(synth.iter().all(|l| !l.contains("held")), "{synth:#?}");

    let Some(data) = e2e_tests::shared_data("rig_pack", "") else {
        return;
    };
    let libraries: [Library; 5] = [
        (
            "zeroeggs-067",
            vec![data.join("zeroeggs-067-speech2")],
            None,
        ),
        (
            "zeroeggs-9joint",
            vec![data.join("zeroeggs-001-neutral-9joint")],
            None,
        ),
        (
            "bandai",
            vec![data.join("bandai-namco-gestures/dataset-2")],
            None,
        ),
        (
            "cmu",
            vec![
                data.join("shippable/cmu-mocap/18_08.bvh"),
                data.join("shippable/cmu-mocap/19_08.bvh"),
            ],
            None,
        ),
        (
            "reactidle",
            vec![data.join("shippable/reactidle")],
            Some(["forearm.L/end", "forearm.R/end"]),
        ),
    ];
    for (label, lib, hands) in &libraries {
        let lines = pack_both(&model_path, root, label, lib, *hands);
        let held: Vec<&String> = lines.iter().filter(|l| l.contains("held")).collect();
        if *label == "zeroeggs-9joint" {
            // No head: the two head channels hold their neutral, and pack says why.
            assert_eq!(held.len(), 2, "{lines:#?}");
            assert!(held.iter().all(|l| l.contains("no head")), "{held:#?}");
        } else {
            assert!(held.is_empty(), "{label}: {lines:#?}");
        }
        if *label == "reactidle" {
            assert!(lines[6].contains("`forearm.L`'s end site"), "{}", lines[6]);
        }
    }
}
