//! `live` without a sound card: the loop on a fake microphone, poses handed to a VMC sender at
//! their tick times, and the one-line errors without an audio device or the `mic` feature.

mod common;

use common::*;
use gesture_runtime::blob::Blob;

use host_sim::live::{live_loop, AudioSource, FakeSource, LiveError, LiveOptions};

/// The utterance at 44.1 kHz as a microphone would deliver it (full scale +-1).
fn mic_samples(s: &Setup) -> Vec<f32> {
    let pcm = gesture_trainer::audio::load_wav_at(&s.wav, 44_100).unwrap();
    pcm.samples.iter().map(|&v| v as f32 / 32768.0).collect()
}

/// `live --vmc` hands every played pose to the sender at its tick time; a sender that fails
/// stops the loop with its error.
#[test]
fn live_loop_hands_every_pose_on_at_its_time() {
    let s = setup();
    let bytes = std::fs::read(&s.full).unwrap();
    let blob = Blob::parse(&bytes).unwrap();
    let mut src = FakeSource::new(mic_samples(s), 44_100, 441 * 4);
    let mut times = Vec::new();
    let stats = host_sim::live::live_loop_with(
        &blob,
        &mut src,
        LiveOptions::default(),
        &mut Vec::new(),
        &mut |t| {
            assert_eq!(t.pose.len(), blob.channels());
            // A full-skeleton blob's calibration limits nothing: the servos follow the pose.
            assert_eq!(t.angles, t.pose);
            times.push(t.time_s);
            Ok(())
        },
    )
    .unwrap();
    assert_eq!(times.len() as u64, stats.ticks);
    for (k, t) in times.iter().enumerate() {
        assert!((t - k as f64 / blob.fps() as f64).abs() < 1e-9);
    }
    let mut src = FakeSource::new(mic_samples(s), 44_100, 441 * 4);
    let err = host_sim::live::live_loop_with(
        &blob,
        &mut src,
        LiveOptions::default(),
        &mut Vec::new(),
        &mut |_| Err("receiver gone".into()),
    )
    .unwrap_err();
    assert!(err.to_string().contains("receiver gone"), "{err}");
}

#[test]
fn live_loop_runs_a_fake_microphone() {
    let s = setup();
    let bytes = std::fs::read(&s.puppet).unwrap();
    let blob = Blob::parse(&bytes).unwrap();
    let samples = mic_samples(s);
    let seconds = samples.len() as f64 / 44_100.0;
    let mut src = FakeSource::new(samples, 44_100, 441 * 4);
    assert_eq!(src.rate_hz(), 44_100);
    let mut out = Vec::new();
    let stats = live_loop(&blob, &mut src, LiveOptions::default(), &mut out).unwrap();
    let printed = text(&out);
    assert!(stats.decisions > 5 && stats.syllables > 10, "{stats:?}");
    // Resampled to the blob's 16 kHz: the same duration, one tick per 1/30 s.
    assert!((stats.seconds - seconds).abs() < 0.05, "{stats:?}");
    assert!(
        (stats.ticks as f64 - seconds * 30.0).abs() <= 2.0,
        "{stats:?}"
    );
    assert_eq!(
        printed.matches("decision at exit").count(),
        stats.decisions,
        "{printed}"
    );
    assert!(printed.contains("top state"), "{printed}");
    assert!(printed.lines().last().unwrap().starts_with("stopped after"));

    // A time limit stops it early; a failing device is an error, not a panic.
    let mut src = FakeSource::new(mic_samples(s), 44_100, 441);
    let opts = LiveOptions {
        seconds: Some(2.0),
        redraw: true,
        ..Default::default()
    };
    let stats = live_loop(&blob, &mut src, opts, &mut Vec::new()).unwrap();
    assert!((stats.seconds - 2.0).abs() < 1e-9, "{stats:?}");
    let mut src = FakeSource::new(mic_samples(s), 44_100, 441).failing_after(50);
    let err = live_loop(&blob, &mut src, LiveOptions::default(), &mut Vec::new()).unwrap_err();
    assert!(matches!(err, LiveError::Backend(_)), "{err}");
    assert_eq!(err.exit_code(), 2);
}

/// Number keys typed while listening ask for the blob's labels; a number that is not a label
/// says so.
#[test]
fn typed_numbers_fire_the_blobs_labels() {
    let s = setup();
    let bytes = std::fs::read(labelled_blob()).unwrap();
    let blob = Blob::parse(&bytes).unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    tx.send(1).unwrap();
    tx.send(9).unwrap();
    drop(tx);
    let mut src = FakeSource::new(mic_samples(s), 44_100, 441);
    let opts = LiveOptions {
        keys: Some(rx),
        ..Default::default()
    };
    let mut out = Vec::new();
    live_loop(&blob, &mut src, opts, &mut out).unwrap();
    let printed = String::from_utf8(out).unwrap();
    for want in [
        "labels: 1 wave (type a number and Enter)",
        "asked for label 1",
        "label wave: received",
        "label wave: answered by segment",
        "label wave: stroke",
        "label 9: label 8 is not one of the blob's 1 labels",
    ] {
        assert!(printed.contains(want), "{want:?} not in\n{printed}");
    }
    // The terminal reader: numbers from 1 up, anything else ignored.
    let rx = host_sim::live::read_keys(std::io::Cursor::new("2\nhello\n0\n 3 \n"));
    let got: Vec<usize> = rx.iter().collect();
    assert_eq!(got, [2, 3]);
}

#[test]
fn without_an_audio_device_live_and_devices_fail_in_one_line() {
    let s = setup();
    match host_sim::live::input_devices() {
        Ok(d) if !d.is_empty() => {
            eprintln!("skipping: this machine has input devices {d:?}");
            return;
        }
        _ => {}
    }
    for args in [
        vec!["devices"],
        vec!["live", "--blob", s.puppet.to_str().unwrap()],
        vec![
            "live",
            "--blob",
            s.puppet.to_str().unwrap(),
            "--device",
            "hw:9",
        ],
    ] {
        let o = sim(&args);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        if cfg!(feature = "mic") {
            assert!(err.contains("no audio input device"), "{args:?}: {err}");
        } else {
            assert!(
                err.contains("without microphone support") && err.contains("--features mic"),
                "{args:?}: {err}"
            );
        }
    }
}

/// With keyword spotting (feature `kws`) and the shared recordings: BEAT's second monologue
/// through a fake microphone at 44.1 kHz; "fashion" brings the label `wave`.
#[cfg(feature = "kws")]
#[test]
fn keywords_heard_on_the_microphone_bring_their_labels() {
    let Some(d) = e2e_tests::shared_data(
        "keywords_heard_on_the_microphone_bring_their_labels",
        "beat-scott",
    ) else {
        return;
    };
    let s = setup();
    let bytes = std::fs::read(labelled_blob()).unwrap();
    let blob = Blob::parse(&bytes).unwrap();
    let kw = s.root.join("kw-live.tsv");
    std::fs::write(&kw, "fashion\twave\n").unwrap();
    let (words, index) = host_sim::run::keyword_labels(&kw, &["wave"]).unwrap();
    let pcm = gesture_trainer::audio::load_wav_at(d.join("2_scott_0_2_2.wav"), 44_100).unwrap();
    let mic: Vec<f32> = pcm.samples[..44_100 * 25]
        .iter()
        .map(|&v| v as f32 / 32768.0)
        .collect();
    let mut src = FakeSource::new(mic, 44_100, 441 * 4);
    let opts = LiveOptions {
        keywords: Some((host_sim::kws::Stream::new(&words).unwrap(), index)),
        ..Default::default()
    };
    let mut out = Vec::new();
    live_loop(&blob, &mut src, opts, &mut out).unwrap();
    let printed = String::from_utf8(out).unwrap();
    // Six times in the first 22 s (PocketSphinx's own full decoder).
    let heard = printed.matches("keyword heard: label wave").count();
    assert!((5..=8).contains(&heard), "{heard} in\n{printed}");
    assert!(printed.contains("label wave: stroke"), "{printed}");
}
