//! Known audio: `gesture-sim run --lookahead-ms`, and the controller's look-ahead on a packed
//! blob (strokes on syllables, every tick played).

mod common;

use common::*;
use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, ControllerEvent, Lookahead};
use gesture_runtime::player::LibraryFrames;
use gesture_trainer::audio::load_wav_at;

/// Runs the blob's controller on `samples` with `ahead`; returns the ticks played, and per
/// library stroke shown (`library.peaks`, the tick it is first shown) the distance (s) to the
/// nearest syllable onset.
fn strokes(blob: &Blob<'_>, samples: &[i16], ahead: Lookahead) -> (u64, Vec<f64>) {
    let fps = blob.fps() as f64;
    let (mut onsets, mut shown, mut ticks) = (Vec::new(), Vec::new(), 0u64);
    let mut last = (usize::MAX, 0);
    let mut sink = |e: ControllerEvent<'_>| match e {
        ControllerEvent::Onset(f) => onsets.push(f as f64 * 0.01),
        ControllerEvent::Pose {
            tick,
            segment,
            frame,
            ..
        } => {
            ticks = tick + 1;
            // Each stroke once, when first shown (slower playback shows a frame twice).
            if blob.is_peak(segment, frame) && last != (segment, frame) {
                shown.push(tick as f64 / fps);
            }
            last = (segment, frame);
        }
        _ => {}
    };
    run(blob, samples, ahead, &mut sink);
    let d = shown
        .iter()
        .map(|s| {
            onsets
                .iter()
                .map(|o| (o - s).abs())
                .fold(f64::MAX, f64::min)
        })
        .collect();
    (ticks, d)
}

/// With half a second of look-ahead the library's strokes land on syllable onsets (within a
/// frame) more often than live, and the run plays exactly as many ticks as a live one.
#[test]
fn look_ahead_lands_strokes_on_onsets_and_plays_every_tick() {
    let s = setup();
    let bytes = std::fs::read(&s.full).unwrap();
    let blob = Blob::parse(&bytes).unwrap();
    let pcm = load_wav_at(&s.wav, blob.prosody_config().sample_rate_hz).unwrap();
    let frame = 1.0 / blob.fps() as f64;
    let on = |d: &[f64]| d.iter().filter(|&&x| x <= frame).count() as f64 / d.len().max(1) as f64;
    let (live_ticks, live) = strokes(&blob, &pcm.samples, Lookahead::LIVE);
    let (ahead_ticks, ahead) = strokes(&blob, &pcm.samples, Lookahead::ms(500));
    println!(
        "strokes within a frame of an onset: live {:.2} of {}, 500 ms look-ahead {:.2} of {}",
        on(&live),
        live.len(),
        on(&ahead),
        ahead.len()
    );
    assert_eq!(live_ticks, ahead_ticks);
    assert!(ahead.len() >= 10, "{} strokes", ahead.len());
    // (On the shared 9-joint take, 90-121 s: 0.71 of the strokes within 20 ms of an onset
    // at 500 ms, against 0.28 live; this synthetic speech has fewer syllables to land on.)
    assert!(
        on(&ahead) >= on(&live) + 0.1,
        "{} vs {}",
        on(&ahead),
        on(&live)
    );
}

/// `--lookahead-ms` takes 0-1000 or `all`; anything else is one line and exit 2, and a run
/// with look-ahead writes every output for the whole audio.
#[test]
fn run_takes_a_look_ahead_and_refuses_a_bad_one() {
    let s = setup();
    let dir = tempfile::tempdir().unwrap();
    for bad in ["1001", "soon", "-5"] {
        let out = dir.path().join(format!("bad-{bad}"));
        let flag = format!("--lookahead-ms={bad}");
        let o = run_into(&s.full, &s.wav, &out, &[&flag, "--no-video"]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", text(&o.stderr));
        assert!(
            text(&o.stderr).contains("look-ahead"),
            "{}",
            text(&o.stderr)
        );
    }
    let mut ticks = Vec::new();
    for l in ["0", "500", "all"] {
        let out = dir.path().join(format!("run-{l}"));
        let o = run_into(&s.full, &s.wav, &out, &["--lookahead-ms", l, "--no-video"]);
        assert!(o.status.success(), "{l}: {}", text(&o.stderr));
        check_outputs(&s.full, &out);
        let t: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("timeline.json")).unwrap())
                .unwrap();
        ticks.push(t["ticks"].as_u64().unwrap());
    }
    assert!(ticks.iter().all(|&t| t == ticks[0]), "{ticks:?}");
}

/// `--lookahead-ms all` plans the whole file and plays it from its show: the show it writes,
/// played by `play-show` with the same audio, gives the run's servo trace and motion byte for
/// byte; a style or labels with `all` are one line and exit 2, nothing written.
#[test]
fn a_baked_run_is_its_show_and_refuses_a_style() {
    let s = setup();
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("baked");
    let show = dir.path().join("baked.show");
    let o = run_into(
        &s.full,
        &s.wav,
        &run,
        &[
            "--lookahead-ms",
            "all",
            "--no-video",
            "--show",
            show.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let played = dir.path().join("played");
    let o = sim(&[
        "play-show",
        "--blob",
        s.full.to_str().unwrap(),
        "--show",
        show.to_str().unwrap(),
        "--audio",
        s.wav.to_str().unwrap(),
        "--out",
        played.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    for f in ["servo.csv", "motion.bvh"] {
        let (a, b) = (
            std::fs::read(run.join(f)).unwrap(),
            std::fs::read(played.join(f)).unwrap(),
        );
        assert!(a == b, "{f} differs between the baked run and its show");
    }
    let styled = styled_blob();
    let out = dir.path().join("styled");
    let o = run_into(
        &styled,
        &s.wav,
        &out,
        &["--lookahead-ms", "all", "--no-video", "--energy", "0.5"],
    );
    refused(&o, &out, "neutral style");
}

/// Runs the blob's controller with `ahead` on `samples` in 10 ms chunks to the end, every
/// event into `sink`.
fn run(
    blob: &Blob<'_>,
    samples: &[i16],
    ahead: Lookahead,
    sink: &mut impl FnMut(ControllerEvent<'_>),
) {
    let mut slot = Box::new(None);
    let c = BlobController::from_blob_in(&mut slot, blob).unwrap();
    c.set_lookahead(ahead);
    for ch in samples.chunks(160) {
        c.push(ch, sink);
    }
    c.finish(sink);
    c.drain(sink);
}

/// Times (s) of the decisions and the onsets of a run of the blob's controller with `ahead`.
fn decisions(blob: &Blob<'_>, samples: &[i16], ahead: Lookahead) -> (Vec<f64>, Vec<f64>) {
    let fps = blob.fps() as f64;
    let (mut onsets, mut decided) = (Vec::new(), Vec::new());
    let mut sink = |e: ControllerEvent<'_>| match e {
        ControllerEvent::Onset(f) => onsets.push(f as f64 * 0.01),
        ControllerEvent::Decision { tick, .. } => decided.push(tick as f64 / fps),
        _ => {}
    };
    run(blob, samples, ahead, &mut sink);
    (decided, onsets)
}

/// With look-ahead an onset counts for decisions from `decision_lead_ms` before its syllable:
/// decisions then fall in the 100 ms before an onset, which without the lead only a decision
/// at a segment's end or in a rest does.
#[test]
fn look_ahead_decides_a_little_before_the_syllable() {
    let s = setup();
    let bytes = std::fs::read(&s.full).unwrap();
    let blob = Blob::parse(&bytes).unwrap();
    let pcm = load_wav_at(&s.wav, blob.prosody_config().sample_rate_hz).unwrap();
    // The speech three times, each meeting the front-end's 10 ms frames at another point (a
    // few dozen decisions each: one pass's shares move by several points with any change of
    // the choices).
    let rate = blob.prosody_config().sample_rate_hz as usize;
    let mut samples = pcm.samples.clone();
    for shift in [rate * 37 / 10_000, rate * 71 / 10_000] {
        samples.extend(std::iter::repeat_n(0i16, rate + shift));
        samples.extend_from_slice(&pcm.samples);
    }
    let before = |lead: u32| {
        let ahead = Lookahead {
            decision_lead_ms: lead,
            ..Lookahead::ms(500)
        };
        let (decided, onsets) = decisions(&blob, &samples, ahead);
        let n = decided
            .iter()
            .filter(|&&d| onsets.iter().any(|&o| o > d + 1e-6 && o <= d + 0.1 + 1e-6))
            .count();
        (n, decided.len())
    };
    let (with, n_with) = before(100);
    let (without, n_without) = before(0);
    println!("decisions in the 100 ms before an onset: {with} of {n_with} with the lead, {without} of {n_without} without");
    assert_eq!(Lookahead::ms(500).decision_lead_ms, 100);
    assert!(n_with >= 10 && n_without >= 10);
    // (On this synthetic speech, three times over: 58 of 130 against 33 of 127.)
    let share = |k: usize, n: usize| k as f64 / n as f64;
    assert!(
        share(with, n_with) >= share(without, n_without) + 0.1,
        "{with} of {n_with} against {without} of {n_without}"
    );
}
