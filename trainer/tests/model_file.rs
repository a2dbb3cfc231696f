//! The model file: it records the whole front end its features came from and `pack` writes
//! exactly that into the blob; dimensions that do not fit (including products that would wrap)
//! and impossible front-end settings are refused with the file's name, never a panic.

mod common;

use std::path::{Path, PathBuf};

use gesture_runtime::blob::Blob;
use gesture_trainer::inference::model::InferenceModel;
use gesture_trainer::pack::{pack_model, PackOptions};

fn edit(path: &Path, f: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    f(&mut v);
    let out = path.with_extension("edited.json");
    std::fs::write(&out, serde_json::to_string(&v).unwrap()).unwrap();
    out
}

#[test]
fn the_front_end_goes_from_model_file_to_blob_and_bad_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let c = common::small_corpus(dir.path(), 5);
    let m = common::small_model(&c);
    let path = dir.path().join("model.json");
    m.save(&path).unwrap();
    let back = InferenceModel::load(&path).unwrap();
    assert_eq!(back.prosody, m.prosody);

    // A model trained with other settings: the blob carries them, not today's defaults.
    let other = edit(&path, |v| {
        v["front_end"]["pitch_floor_hz"] = 100.0.into();
        v["front_end"]["pause_frames"] = 30.into();
    });
    let m2 = InferenceModel::load(&other).unwrap();
    let packed = pack_model(&m2, std::slice::from_ref(&c), &PackOptions::default()).unwrap();
    let cfg = Blob::parse(&packed.bytes).unwrap().prosody_config();
    assert_eq!(cfg.pitch.floor_hz, 100.0);
    assert_eq!(cfg.syllables.pause_frames, 30);
    assert_eq!(cfg, m2.prosody);

    // Impossible front-end settings.
    let bad = edit(&path, |v| v["front_end"]["pitch_ceiling_hz"] = 50.0.into());
    let e = InferenceModel::load(&bad).unwrap_err().to_string();
    assert!(
        e.contains("model.edited.json") && e.contains("front-end"),
        "{e}"
    );

    // A window whose product with the states and clusters wraps around: refused, no panic.
    let huge = edit(&path, |v| {
        v["crf"]["window"] = (usize::MAX / 2 + 1).into();
    });
    let e = InferenceModel::load(&huge).unwrap_err().to_string();
    assert!(e.contains("CRF dimensions"), "{e}");
}
