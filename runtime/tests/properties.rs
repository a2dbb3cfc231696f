//! Properties of the runtime on arbitrary input, in the normal test suite (the fuzz targets in
//! `tests/fuzz` search much longer): arbitrary blob bytes never panic the parser, and any blob
//! that parses drives a controller whose poses stay finite and within the rig's limits, on any
//! samples, in any chunking.

mod common;

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, ControllerEvent};
use gesture_runtime::player::LibraryFrames;
use proptest::prelude::*;

fn golden() -> Vec<u8> {
    let hex: String = common::GOLDEN
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect();
    (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap())
        .collect()
}

/// The golden blob with two tones.
fn styled() -> Vec<u8> {
    let mut t = common::Tiny::new();
    t.styles = Some(common::TinyStyles::two(4, 6));
    t.encode()
}

/// Drives the controller of `bytes` (if they parse) with `samples` in `chunk`-sized pieces;
/// every pose must be finite and within the limits.
fn drive(bytes: &[u8], samples: &[i16], chunk: usize) -> Result<usize, TestCaseError> {
    drive_styled(bytes, samples, chunk, &[])
}

/// [`drive`] with the style `weights` set first (refused weights keep the neutral style).
fn drive_styled(
    bytes: &[u8],
    samples: &[i16],
    chunk: usize,
    weights: &[f32],
) -> Result<usize, TestCaseError> {
    let Ok(blob) = Blob::parse(bytes) else {
        return Ok(0);
    };
    let Ok(mut ctl) = BlobController::from_blob(&blob) else {
        return Ok(0);
    };
    if ctl.set_style(weights).is_err() {
        prop_assert!(ctl.style().is_neutral());
    }
    let mut poses = 0;
    let mut bad = None;
    for c in samples.chunks(chunk.max(1)) {
        ctl.push(c, &mut |e| {
            if let ControllerEvent::Pose { pose, .. } = e {
                poses += 1;
                for (ch, v) in pose.iter().enumerate() {
                    let (lo, hi, _) = blob.limits(ch);
                    if !(v.is_finite() && *v >= lo && *v <= hi) {
                        bad = Some((ch, *v));
                    }
                }
            }
        });
    }
    prop_assert!(bad.is_none(), "pose out of limits: {bad:?}");
    Ok(poses)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_samples_give_finite_poses_within_the_limits(
        samples in proptest::collection::vec(any::<i16>(), 0..12_000),
        chunk in 1usize..2000,
    ) {
        let n = drive(&golden(), &samples, chunk)?;
        // One pose per 1/30 s of audio (the golden library runs at 30 fps).
        prop_assert!((n as i64 - (samples.len() as i64 * 30 / 16_000)).abs() <= 1);
    }

    #[test]
    fn mutated_blobs_parse_or_refuse_and_never_misbehave(
        edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..8),
        fix_crc in any::<bool>(),
        samples in proptest::collection::vec(any::<i16>(), 0..4000),
    ) {
        let mut b = golden();
        for (at, v) in edits {
            let i = at % b.len();
            b[i] = v;
        }
        if fix_crc {
            // Reach the validation behind the checksum too.
            let crc = gesture_runtime::blob::crc32(&b[16..]);
            b[12..16].copy_from_slice(&crc.to_le_bytes());
        }
        drive(&b, &samples, 160)?;
    }

    #[test]
    fn arbitrary_styles_and_mutated_styled_blobs_never_misbehave(
        weights in proptest::collection::vec(any::<f32>(), 0..4),
        edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 0..4),
        samples in proptest::collection::vec(any::<i16>(), 0..6000),
    ) {
        let mut b = styled();
        let n = b.len();
        for (at, v) in edits {
            // The styles section sits at the end: edit there.
            let i = n - 1 - at % 40;
            b[i] = v;
        }
        let crc = gesture_runtime::blob::crc32(&b[16..]);
        b[12..16].copy_from_slice(&crc.to_le_bytes());
        drive_styled(&b, &samples, 160, &weights)?;
    }

    #[test]
    fn arbitrary_bytes_never_panic_the_parser(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        let _ = Blob::parse(&bytes);
    }
}
