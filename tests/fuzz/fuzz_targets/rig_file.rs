//! Arbitrary text as a rig file: a rig or a typed error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let _ = gesture_trainer::rig::Rig::parse(&text, "fuzz.toml");
});
