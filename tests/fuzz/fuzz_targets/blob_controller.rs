//! Arbitrary bytes as a blob: parse, and when it is valid, build the controller and feed it
//! samples made of the same bytes, under a style made of them too. Never a panic; every pose
//! finite and within the rig's limits.
#![no_main]

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, ControllerEvent};
use gesture_runtime::player::LibraryFrames;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(blob) = Blob::parse(data) else {
        return;
    };
    let Ok(mut ctl) = BlobController::from_blob(&blob) else {
        return;
    };
    // A style from the bytes (any weights, some refused): the mixed tables drive the choice.
    let weights: Vec<f32> = data
        .iter()
        .rev()
        .take(blob.tones())
        .map(|&b| f32::from(b) / 64.0 - 0.5)
        .collect();
    let _ = ctl.set_style(&weights);
    // Labels from the bytes too (some unknown, some queued behind others).
    for &b in data.iter().take(6) {
        let _ = ctl.push_label(usize::from(b % 4));
    }
    let samples: Vec<i16> = data
        .chunks(2)
        .cycle()
        .take(16_000)
        .map(|c| i16::from_le_bytes([c[0], *c.get(1).unwrap_or(&0)]))
        .collect();
    ctl.push(&samples, &mut |e| {
        if let ControllerEvent::Pose { pose, .. } = e {
            for (ch, v) in pose.iter().enumerate() {
                let (lo, hi, _) = blob.limits(ch);
                assert!(v.is_finite() && *v >= lo && *v <= hi, "channel {ch}: {v}");
            }
        }
    });
});
