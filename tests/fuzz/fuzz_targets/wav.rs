//! Arbitrary bytes as a WAV file: samples or a typed error, never a panic or a huge allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = gesture_trainer::audio::decode_wav(data, std::path::Path::new("fuzz.wav"), 16_000);
});
