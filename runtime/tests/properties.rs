//! Properties of the runtime on arbitrary input, in the normal test suite (the fuzz targets in
//! `tests/fuzz` search much longer): arbitrary blob bytes never panic the parser, and any blob
//! that parses drives a controller whose poses stay finite and within the rig's limits, on any
//! samples, in any chunking.

mod common;

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, Controller, ControllerEvent};
use gesture_runtime::player::LibraryFrames;
use gesture_runtime::prosody::arith::{Arith, Fixed, Float};
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
    let (poses, bad) = push_checked(&mut ctl, &blob, samples, chunk);
    prop_assert!(bad.is_none(), "pose out of limits: {bad:?}");
    Ok(poses)
}

/// Pushes `samples` into `ctl` in `chunk`-sized pieces; the poses played and the last channel
/// and value that was not finite or outside the blob's limits, if any.
fn push_checked<A: Arith>(
    ctl: &mut Controller<'_, Blob<'_>, Blob<'_>, A>,
    blob: &Blob<'_>,
    samples: &[i16],
    chunk: usize,
) -> (usize, Option<(usize, f32)>) {
    let (mut poses, mut bad) = (0, None);
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
    (poses, bad)
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

/// Drives a controller with arithmetic `A` over `blob` through a loud tone, silence, noise and
/// a square wave at full scale; every pose must be finite and within the limits.
fn drive_arith<A: Arith>(blob: &Blob<'_>) -> Result<usize, String> {
    let Ok(mut ctl) = Controller::<'_, Blob<'_>, Blob<'_>, A>::from_blob_arith(blob) else {
        return Ok(0);
    };
    let mut samples = Vec::with_capacity(32_000);
    let mut seed = 0x2545_f491u32;
    for i in 0..32_000u32 {
        let t = i as f32 / 16_000.0;
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        samples.push(match i / 8_000 {
            0 => (30_000.0 * libm::sinf(2.0 * std::f32::consts::PI * 180.0 * t)) as i16,
            1 => 0,
            2 => seed as i16,
            _ if (i / 40) % 2 == 0 => i16::MAX,
            _ => i16::MIN,
        });
    }
    match push_checked(&mut ctl, blob, &samples, 160) {
        (_, Some(b)) => Err(format!("pose out of limits: {b:?}")),
        (poses, None) => Ok(poses),
    }
}

/// Every front-end setting at the extremes the validator may accept (each field in turn, from
/// zero and the smallest positive float to the largest) either is refused or runs the `f32`
/// and the integer front-end without overflow, with finite poses within the limits. (A random
/// mutation once found a voicing threshold large enough to overflow the integer peak test.)
#[test]
fn every_front_end_setting_the_validator_accepts_runs_without_overflow() {
    let values = [
        0.0,
        f32::MIN_POSITIVE,
        1e-30,
        0.03,
        0.45,
        1.0,
        75.0,
        1e6,
        1e30,
        f32::MAX,
        -1.0,
        f32::MIN,
    ];
    let mut accepted = 0;
    for field in 0..11 {
        for v in values {
            let mut t = common::Tiny::new();
            let f = &mut t.front_end;
            *[
                &mut f.pitch_floor_hz,
                &mut f.pitch_ceiling_hz,
                &mut f.silence_threshold,
                &mut f.voicing_threshold,
                &mut f.octave_cost,
                &mut f.octave_jump_cost,
                &mut f.voiced_unvoiced_cost,
                &mut f.margin_db,
                &mut f.range_db,
                &mut f.floor_db,
                &mut f.initial_peak_db,
            ][field] = v;
            let bytes = t.encode();
            let Ok(blob) = Blob::parse(&bytes) else {
                continue;
            };
            accepted += 1;
            for (arith, r) in [
                ("f32", drive_arith::<Float>(&blob)),
                ("fixed", drive_arith::<Fixed>(&blob)),
            ] {
                assert!(r.is_ok(), "field {field} = {v:e}, {arith}: {r:?}");
                assert!(r.unwrap() > 50, "field {field} = {v:e}, {arith}: no poses");
            }
        }
    }
    // Most fields take most values: the extremes are reached, not all refused.
    assert!(accepted >= 50, "only {accepted} settings accepted");
}
