//! Arbitrary bytes behind a repaired header: the header's length and CRC-32 are rewritten to
//! match the bytes, so the fuzzer reaches the section decoding and validation behind the
//! checksum (which random bytes almost never pass), then drives the controller as
//! `blob_controller` does: never a panic; every pose finite and within the rig's limits.
#![no_main]

use gesture_runtime::blob::{crc32, Blob, FORMAT_VERSION, HEADER_LEN, MAGIC};
use gesture_runtime::controller::{BlobController, ControllerEvent};
use gesture_runtime::player::LibraryFrames;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let payload = data.get(HEADER_LEN..).unwrap_or(&[]);
    let mut bytes = Vec::with_capacity(HEADER_LEN + payload.len());
    bytes.extend_from_slice(&MAGIC);
    bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&0u16.to_le_bytes());
    bytes.extend_from_slice(&(payload.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&crc32(payload).to_le_bytes());
    bytes.extend_from_slice(payload);
    let Ok(blob) = Blob::parse(&bytes) else {
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
    let samples: Vec<i16> = (0..8000)
        .map(|i| ((i * 7919) % 65536) as u16 as i16)
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
