//! Arbitrary bytes as a show file: parsed as they are, then with the header repaired (the
//! golden blob's CRC, 16 kHz, 30 fps, the records' length, their count and the CRC rewritten
//! to match), so the fuzzer reaches the records behind the checksum; a show that parses and
//! fits the golden blob (`seeds/blob_controller/golden.blob`) is played for at most 2000
//! ticks. Never a panic; every pose finite and within the rig's limits.
#![no_main]

use gesture_runtime::blob::{crc32, Blob};
use gesture_runtime::player::LibraryFrames;
use gesture_runtime::show::{Show, ShowError, ShowPlayer, SHOW_HEADER_LEN};
use libfuzzer_sys::fuzz_target;

static BLOB: &[u8] = include_bytes!("../seeds/blob_controller/golden.blob");

/// A show whose header is `GSTS` v1 for `blob_crc`, 16 kHz, 30 fps, `ticks`, `commands` and
/// `records`, with its CRC.
fn repaired(blob_crc: u32, ticks: u32, commands: u32, records: &[u8]) -> Vec<u8> {
    let mut b = Vec::with_capacity(SHOW_HEADER_LEN + records.len() + 4);
    b.extend_from_slice(b"GSTS");
    b.extend_from_slice(&1u16.to_le_bytes());
    b.extend_from_slice(&0u16.to_le_bytes());
    for v in [
        blob_crc,
        16_000,
        30_000,
        ticks,
        commands,
        records.len() as u32,
    ] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(records);
    let crc = crc32(&b);
    b.extend_from_slice(&crc.to_le_bytes());
    b
}

fn play(bytes: &[u8], blob: &Blob<'_>) {
    let Ok(show) = Show::parse(bytes) else {
        return;
    };
    let Ok(mut player) = ShowPlayer::from_blob(&show, blob) else {
        return;
    };
    let mut ticks = 0;
    while ticks < 2000 && !player.finished() {
        player.push(533, &mut |t| {
            ticks += 1;
            for (ch, v) in t.pose.iter().enumerate() {
                let (lo, hi, _) = blob.limits(ch);
                assert!(v.is_finite() && *v >= lo && *v <= hi, "channel {ch}: {v}");
            }
        });
    }
}

fuzz_target!(|data: &[u8]| {
    let blob = Blob::parse(BLOB).expect("the golden blob seed is valid");
    play(data, &blob);
    // Ticks from the first two bytes, records from the rest.
    let ticks = u16::from_le_bytes([
        data.first().copied().unwrap_or(1),
        data.get(1).copied().unwrap_or(0),
    ]);
    let records = data.get(2..).unwrap_or(&[]);
    let crc = blob.header().crc;
    let mut bytes = repaired(crc, ticks as u32, 0, records);
    if let Err(ShowError::CommandCount { found, .. }) = Show::parse(&bytes) {
        bytes = repaired(crc, ticks as u32, found, records);
    }
    play(&bytes, &blob);
});
