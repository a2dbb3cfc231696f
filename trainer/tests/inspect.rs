//! `gesture-train inspect`: the summary of a valid blob, and one typed error line (exit 2) for
//! a corrupted, wrong-version, truncated or missing one.

use std::path::Path;
use std::process::{Command, Output};

use gesture_runtime::blob::encode::OwnedPayload;

fn write_blob(path: &Path, p: &OwnedPayload) -> usize {
    let bytes = p.encode().unwrap();
    std::fs::write(path, &bytes).unwrap();
    bytes.len()
}

fn inspect(path: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gesture-train"))
        .arg("inspect")
        .arg(path)
        .output()
        .unwrap()
}

fn refused(path: &Path, want: &str) {
    let out = inspect(path);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "{err}");
    let prefix = format!("gesture-train: {}: ", path.display());
    assert!(err.starts_with(&prefix), "{err}");
    assert!(err.contains(want), "{err}");
    assert!(out.stdout.is_empty());
}

#[test]
fn summarizes_a_valid_blob() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("example.blob");
    // The example with frames 1 and 4 marked as strokes.
    let mut p = OwnedPayload::example();
    p.library = p.library.with_peaks(&[1, 4]);
    let n = write_blob(&path, &p);
    let out = inspect(&path);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    for want in [
        format!(
            "blob: {n} bytes, format version 8, flags 0x0000, payload {} bytes",
            n - 16
        ),
        "sections (bytes): front_end ".to_string(),
        "front_end: 16000 Hz, pitch 75-600 Hz".to_string(),
        "control: decisions on syllable onsets (within 50 ms; a segment end waits up to 300 ms); \
         a cut decided mid-segment waits for the hands' calmest pause within 400 ms"
            .to_string(),
        "variety: recency cost 0 over 0 ms, usage cost 0 over 0 ms; cuts blended over 0 ms; \
         beat hold 0 ms"
            .to_string(),
        "voice: never rests; energy cost 0 at full voice level".to_string(),
        "segment energy (ln of mean hand speed over the median): 0.00 to 0.00; calmest: 0 \
         (0.00, 3 frames)"
            .to_string(),
        "inference: 2 states, 1 clusters, window 1".to_string(),
        "policy: 2 segments, 3 exit points (2 end, 1 interruption), 4 successor entries \
         (1.33 per exit point), discount 0.9"
            .to_string(),
        "library: 2 segments, 6 frames, 1 channels, 30 fps (0.20 s of frames), 2 stroke frames \
         (aimed at syllables with known audio), 1 labelled (1 with a stroke), 0 run on into \
         their recorded successor, 0 rotation groups"
            .to_string(),
        "rig: \"example\", PWM period 20000 us, 1 channels: head".to_string(),
        "styles: none (neutral only)".to_string(),
        "labels: none".to_string(),
    ] {
        assert!(text.contains(&want), "missing {want:?} in\n{text}");
    }
    // Section sizes add up to the payload.
    let sizes: usize = text
        .lines()
        .find(|l| l.starts_with("sections"))
        .unwrap()
        .split(", ")
        .map(|p| p.rsplit(' ').next().unwrap().parse::<usize>().unwrap())
        .sum();
    assert_eq!(sizes, n - 16);
}

#[test]
fn bad_blobs_give_one_typed_error_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = OwnedPayload::example().encode().unwrap();
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    };

    let mut b = good.clone();
    let last = b.len() - 1;
    b[last] ^= 1;
    refused(&write("flipped.blob", &b), "CRC-32 mismatch");

    let mut b = good.clone();
    b[4] = 1;
    refused(&write("v1.blob", &b), "unsupported blob format version 1");

    refused(
        &write("cut.blob", &good[..good.len() - 10]),
        "truncated blob",
    );
    refused(&write("tiny.blob", &good[..5]), "blob too short");
    refused(
        &write("text.blob", b"hello, world, not a blob"),
        "bad magic",
    );
    refused(&dir.path().join("missing.blob"), "No such file");
}
