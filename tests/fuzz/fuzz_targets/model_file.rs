//! Arbitrary JSON as a model file: a model or a typed error (dimensions checked with checked
//! arithmetic), never a panic.
#![no_main]

use gesture_trainer::inference::model::{InferenceModel, ModelFile};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(f) = serde_json::from_slice::<ModelFile>(data) {
        if let Ok(m) = InferenceModel::from_file(f, "fuzz.json") {
            let _ = m.states();
        }
    }
});
