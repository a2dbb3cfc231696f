//! The show format's example (docs/show-format.md, section 6): the bytes printed in the doc
//! parse to the commands it describes, the writer produces exactly them, they play against
//! the golden blob, and each validation rule refuses its own mutation of them.

mod common;

use common::{hex, Tiny};
use gesture_runtime::blob::Blob;
use gesture_runtime::player::PlayerCommand::{self, *};
use gesture_runtime::show::*;

/// The hex bytes of the ```text block after `<!-- show-golden -->` in the doc: on each line,
/// the two-digit hex tokens before the comment (which follows three spaces or more).
fn documented_bytes() -> Vec<u8> {
    let doc = include_str!("../../docs/show-format.md");
    let at = doc
        .find("<!-- show-golden -->")
        .expect("the doc marks its example");
    let block = doc[at..]
        .split("```text\n")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .expect("a text block follows the marker");
    let mut out = Vec::new();
    for line in block.lines() {
        let data = line.split("   ").next().unwrap_or("");
        for token in data.split_whitespace() {
            if token.len() != 2 {
                break;
            }
            match u8::from_str_radix(token, 16) {
                Ok(b) => out.push(b),
                Err(_) => break,
            }
        }
    }
    out
}

const PLAYS: [(u64, PlayerCommand); 6] = [
    (
        2,
        Enter {
            segment: 1,
            frame: 0,
        },
    ),
    (5, Rate(0.75)),
    (5, Hold),
    (7, Turn),
    (
        8,
        Enter {
            segment: 0,
            frame: 1,
        },
    ),
    (9, RunOn),
];

#[test]
fn the_documented_bytes_parse_to_the_documented_show() {
    let bytes = documented_bytes();
    assert_eq!(bytes.len(), 54, "{}", hex(&bytes));
    let show = Show::parse(&bytes).unwrap();
    let h = show.header();
    assert_eq!(
        (h.version, h.blob_crc, h.sample_rate_hz, h.fps_milli),
        (2, 0xea7c_7223, 16_000, 30_000)
    );
    assert_eq!((h.ticks, h.commands, h.records_len), (12, 6, 18));
    assert_eq!(show.commands().collect::<Vec<_>>(), PLAYS);
}

#[test]
fn the_writer_produces_the_documented_bytes() {
    let blob_bytes = Tiny::new().encode();
    let blob = Blob::parse(&blob_bytes).unwrap();
    assert_eq!(blob.header().crc, 0xea7c_7223);
    // A command stamped at the end precedes no pose: left out.
    let mut plays = PLAYS.to_vec();
    plays.push((12, Turn));
    let written = encode(12, &plays, &blob).unwrap();
    assert_eq!(hex(&written), hex(&documented_bytes()));
}

#[test]
fn the_example_plays_as_the_doc_says() {
    let blob_bytes = Tiny::new().encode();
    let blob = Blob::parse(&blob_bytes).unwrap();
    let bytes = documented_bytes();
    let show = Show::parse(&bytes).unwrap();
    let mut player = ShowPlayer::from_blob(&show, &blob).unwrap();
    let mut shown = Vec::new();
    // Tick 0 is due at once; 533.33 samples per tick at 16 kHz and 30 fps.
    player.push(0, &mut |t| shown.push((t.tick, t.segment, t.frame)));
    assert_eq!(shown, [(0, 0, 0)]);
    player.push(16_000, &mut |t| shown.push((t.tick, t.segment, t.frame)));
    let want = [
        (0, 0),
        (0, 1),
        (1, 0),
        (1, 1),
        (1, 2),
        (1, 2),
        (1, 2),
        (1, 2),
        (0, 1),
        (1, 0),
        (1, 0),
        (1, 1),
    ];
    let got: Vec<(usize, usize)> = shown.iter().map(|&(_, s, f)| (s, f)).collect();
    assert_eq!(got, want);
    assert!(player.finished());
    let last = player.pose().to_vec();
    player.push(100_000, &mut |_| panic!("no tick after the end"));
    assert_eq!(player.pose(), last, "the last pose is held");
}

/// `bytes` with `f` applied and the CRC made right again.
fn mutated(f: impl Fn(&mut Vec<u8>)) -> Vec<u8> {
    let mut b = documented_bytes();
    f(&mut b);
    let n = b.len() - 4;
    let crc = gesture_runtime::blob::crc32(&b[..n]);
    b[n..].copy_from_slice(&crc.to_le_bytes());
    b
}

#[test]
fn every_rule_refuses_its_mutation_of_the_example() {
    let good = documented_bytes();
    let cases: Vec<(Vec<u8>, ShowError)> = vec![
        (good[..35].to_vec(), ShowError::TooShort { len: 35 }),
        (mutated(|b| b[3] = b'B'), ShowError::BadMagic),
        (
            mutated(|b| b[4] = 1),
            ShowError::UnsupportedVersion { found: 1 },
        ),
        (
            mutated(|b| b[6] = 1),
            ShowError::UnsupportedFlags { found: 1 },
        ),
        (
            good[..53].to_vec(),
            ShowError::Truncated {
                declared: 18,
                available: 21,
            },
        ),
        (
            [&good[..], &[0]].concat(),
            ShowError::TrailingBytes {
                declared: 18,
                available: 23,
            },
        ),
        (
            mutated(|b| b[12..16].copy_from_slice(&999u32.to_le_bytes())),
            ShowError::BadSampleRate { found: 999 },
        ),
        (
            mutated(|b| b[16..20].copy_from_slice(&0u32.to_le_bytes())),
            ShowError::BadFrameRate { found: 0 },
        ),
        (
            mutated(|b| b[20..24].copy_from_slice(&0u32.to_le_bytes())),
            ShowError::NoTicks,
        ),
        // The last head's continuation bit set: it runs past the records.
        (
            mutated(|b| b[49] = 0x89),
            ShowError::BadRecord { command: 5 },
        ),
        (
            mutated(|b| b[42] = 0x06),
            ShowError::UnknownKind {
                command: 2,
                kind: 6,
            },
        ),
        (
            mutated(|b| b[38..42].copy_from_slice(&1.75f32.to_le_bytes())),
            ShowError::BadRate { command: 1 },
        ),
        // The rate record made a gain (kind 5) of 2.5.
        (
            mutated(|b| {
                b[37] = 3 << 3 | 5;
                b[38..42].copy_from_slice(&2.5f32.to_le_bytes());
            }),
            ShowError::BadGain { command: 1 },
        ),
        (
            mutated(|b| b[20..24].copy_from_slice(&9u32.to_le_bytes())),
            ShowError::TickOutOfRange {
                command: 5,
                tick: 9,
            },
        ),
        (
            mutated(|b| b[24] = 7),
            ShowError::CommandCount {
                declared: 7,
                found: 6,
            },
        ),
    ];
    for (bytes, want) in cases {
        assert_eq!(Show::parse(&bytes), Err(want), "{}", hex(&bytes));
    }
    let mut bad_crc = good.clone();
    bad_crc[40] ^= 1;
    assert!(matches!(
        Show::parse(&bad_crc),
        Err(ShowError::BadCrc { .. })
    ));
}

#[test]
fn a_show_is_refused_by_another_blob_or_library() {
    let tiny = Tiny::new();
    let blob_bytes = tiny.encode();
    let blob = Blob::parse(&blob_bytes).unwrap();
    let check = |bytes: &[u8]| Show::parse(bytes).unwrap().check_against(&blob);
    assert_eq!(check(&documented_bytes()), Ok(()));
    let other = mutated(|b| b[8] ^= 1);
    assert_eq!(
        check(&other),
        Err(ShowError::OtherBlob {
            show: 0xea7c_7222,
            blob: 0xea7c_7223
        })
    );
    let rate = mutated(|b| b[12..16].copy_from_slice(&8000u32.to_le_bytes()));
    assert_eq!(
        check(&rate),
        Err(ShowError::SampleRateMismatch {
            show: 8000,
            blob: 16_000
        })
    );
    let fps = mutated(|b| b[16..20].copy_from_slice(&25_000u32.to_le_bytes()));
    assert_eq!(
        check(&fps),
        Err(ShowError::FrameRateMismatch {
            show: 25_000,
            library: 30_000
        })
    );
    let segment = mutated(|b| b[33] = 2);
    assert_eq!(
        check(&segment),
        Err(ShowError::SegmentOutOfRange {
            command: 0,
            segment: 2
        })
    );
    let frame = mutated(|b| b[35] = 3);
    assert_eq!(
        check(&frame),
        Err(ShowError::FrameOutOfRange {
            command: 0,
            frame: 3
        })
    );
    assert!(ShowPlayer::from_blob(&Show::parse(&frame).unwrap(), &blob).is_err());
}

/// The `show` fuzz target starts from the documented example (`tests/fuzz/seeds/show`).
#[test]
fn the_show_fuzz_seed_is_the_documented_example() {
    let seed = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fuzz/seeds/show/golden.show");
    assert_eq!(
        hex(&std::fs::read(&seed).unwrap()),
        hex(&documented_bytes()),
        "{} is out of date: write the bytes of docs/show-format.md, section 6, to it",
        seed.display()
    );
}
