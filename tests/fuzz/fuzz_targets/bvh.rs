//! Arbitrary text as BVH: a motion or a typed error, never a panic; a motion writes back.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(m) = gesture_trainer::motion::parse_bvh(&text, "fuzz.bvh") {
        let mut out = Vec::new();
        gesture_trainer::motion::write_bvh(&m, &mut out).unwrap();
        let back = gesture_trainer::motion::parse_bvh(&String::from_utf8(out).unwrap(), "back");
        assert!(back.is_ok(), "{back:?}");
    }
});
