//! `gesture-sim run` end to end on a small synthetic setup built here with the trainer library
//! (synthetic corpus -> fit with 4 states -> pack, full-skeleton and puppet rigs), plus bad
//! inputs, the BVH round trip of the skeleton section, and the shared real recordings when
//! they are present.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

use gesture_runtime::blob::Blob;
use gesture_trainer::corpus::{load_corpus, LoadOptions};
use gesture_trainer::inference::train::{fit, sequences, FitConfig};
use gesture_trainer::motion::read_bvh;
use gesture_trainer::pack::{pack, PackOptions};
use gesture_trainer::rig::Rig;
use gesture_trainer::synth::{write_corpus, SynthParams};

/// The shared setup: a corpus, a model, two blobs and a new utterance.
struct Setup {
    _dir: tempfile::TempDir,
    root: PathBuf,
    full: PathBuf,
    puppet: PathBuf,
    wav: PathBuf,
    corpus: PathBuf,
}

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn setup() -> &'static Setup {
    static S: OnceLock<Setup> = OnceLock::new();
    S.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().to_path_buf();
        let corpus = root.join("corpus");
        std::fs::create_dir_all(&corpus).unwrap();
        let params = SynthParams {
            minutes: 1.5,
            seed: 11,
            take_seconds: 45.0,
        };
        write_corpus(&params, &corpus, |_, _| {}).unwrap();
        let c = load_corpus(std::slice::from_ref(&corpus), &LoadOptions::default()).unwrap();
        let (seqs, segs) = sequences(&c, None);
        let cfg = FitConfig {
            states: Some(4),
            clusters: Some(4),
            window: 4,
            restarts: 2,
            l2: Some(1e-3),
            ..FitConfig::default()
        };
        let (model, _) = fit(&seqs, &segs, &cfg, &|_| {}).unwrap();
        let model_path = root.join("model.json");
        model.save(&model_path).unwrap();
        let full = root.join("full.blob");
        pack(
            &model_path,
            std::slice::from_ref(&corpus),
            &PackOptions::default(),
            &full,
        )
        .unwrap();
        let puppet = root.join("puppet.blob");
        let opts = PackOptions {
            rig: Some(workspace().join("rigs/puppet-8ch.toml")),
            ..PackOptions::default()
        };
        pack(&model_path, std::slice::from_ref(&corpus), &opts, &puppet).unwrap();
        // A new utterance: another seed's speech.
        let utter = root.join("utterance");
        std::fs::create_dir_all(&utter).unwrap();
        let p = SynthParams {
            minutes: 0.25,
            seed: 99,
            take_seconds: 15.0,
        };
        write_corpus(&p, &utter, |_, _| {}).unwrap();
        Setup {
            wav: utter.join("take_000.wav"),
            _dir: dir,
            root,
            full,
            puppet,
            corpus,
        }
    })
}

fn sim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gesture-sim"))
        .args(args)
        .output()
        .expect("gesture-sim runs")
}

fn run_into(blob: &Path, wav: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut a = vec![
        "run",
        "--blob",
        blob.to_str().unwrap(),
        "--audio",
        wav.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    a.extend_from_slice(extra);
    sim(&a)
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

const OUTPUTS: [&str; 5] = [
    "motion.bvh",
    "timeline.json",
    "servo.csv",
    "preview.png",
    "preview.gif",
];

/// Checks a run's folder against its blob: BVH frames = poses, decisions name real segments,
/// duties within each channel's limits and within its slew per tick.
fn check_outputs(blob_path: &Path, dir: &Path) {
    let bytes = std::fs::read(blob_path).unwrap();
    let blob = Blob::parse(&bytes).unwrap();
    for f in OUTPUTS {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    // No temporary file is left behind.
    for e in std::fs::read_dir(dir).unwrap() {
        let n = e.unwrap().file_name().into_string().unwrap();
        assert!(!n.starts_with('.'), "leftover {n}");
    }
    let tl: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("timeline.json")).unwrap()).unwrap();
    let ticks = tl["ticks"].as_u64().unwrap() as usize;
    assert!(ticks > 100, "{ticks}");
    let motion = read_bvh(dir.join("motion.bvh")).unwrap();
    assert_eq!(motion.frames(), ticks);
    assert!((motion.fps() - blob.fps() as f64).abs() < 1e-3);
    let sk = blob.skeleton().unwrap();
    assert_eq!(motion.skeleton().joints.len(), sk.joints());

    let decisions = tl["decisions"].as_array().unwrap();
    assert!(decisions.len() > 5);
    let mut entered = 0;
    for d in decisions {
        assert!((d["exit"].as_u64().unwrap() as usize) < blob.exit_points());
        assert!((d["exit_segment"].as_u64().unwrap() as usize) < blob.segments());
        match d["choice"].as_str().unwrap() {
            "enter" => {
                entered += 1;
                assert!((d["segment"].as_u64().unwrap() as usize) < blob.segments());
            }
            "continue" => assert!(d["segment"].is_null()),
            other => panic!("choice {other}"),
        }
        assert!(d["candidates"].as_u64().unwrap() >= 1);
        assert!(d["cost"].as_f64().unwrap().is_finite());
    }
    assert!(entered > 0);
    let steps = tl["steps"].as_array().unwrap();
    let states = blob.states();
    let mut syllables = 0;
    for s in steps {
        let b: Vec<f64> = s["belief"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(b.len(), states);
        assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-3);
        if s["flushed"].as_bool().unwrap() {
            assert!(s["latency_s"].is_null());
            continue;
        }
        let lat = s["latency_s"].as_f64().unwrap();
        if s["kind"] == "syllable" {
            syllables += 1;
            assert!((0.0..1.0).contains(&lat), "latency {lat} of {s}");
        }
    }
    assert!(syllables > 10);
    let med = tl["latency"]["median_s"].as_f64().unwrap();
    assert!(med > 0.0 && med < 0.5, "{med}");

    // servo.csv: header, one row per tick, limits and slew.
    let csv = std::fs::read_to_string(dir.join("servo.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let names: Vec<&str> = blob.channel_names().collect();
    assert_eq!(&header[..2], ["tick", "time_s"]);
    assert_eq!(&header[2..], &names[..]);
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse::<f64>().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), ticks);
    let period = blob.period_us() as f64;
    let dt = 1.0 / blob.fps() as f64;
    let duty = |us: f64| us / period * 65535.0;
    for ch in 0..blob.channels() {
        let cal = blob.calibration(ch).unwrap();
        let (pa, pb) = (
            cal.pulse_us(cal.min_deg) as f64,
            cal.pulse_us(cal.max_deg) as f64,
        );
        let (lo, hi) = (duty(pa.min(pb)) - 1.0, duty(pa.max(pb)) + 1.0);
        let slew =
            duty(cal.us_per_deg as f64 * cal.max_slew_deg_per_s as f64 * dt) - duty(0.0) + 1.0;
        let mut prev = duty(cal.pulse_neutral_us as f64).round();
        for (t, r) in rows.iter().enumerate() {
            assert_eq!(r[0] as usize, t);
            let d = r[2 + ch];
            assert!(
                (lo..=hi).contains(&d),
                "channel {ch} tick {t}: {d} not in {lo}..{hi}"
            );
            assert!(
                (d - prev).abs() <= slew,
                "channel {ch} tick {t}: step {} > {slew}",
                (d - prev).abs()
            );
            prev = d;
        }
    }

    // The previews are what they say.
    let png = std::fs::read(dir.join("preview.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let gif = std::fs::read(dir.join("preview.gif")).unwrap();
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::Indexed);
    let mut dec = opts.read_info(&gif[..]).unwrap();
    assert_eq!((dec.width(), dec.height()), (320, 240));
    let mut frames = 0;
    while dec.read_next_frame().unwrap().is_some() {
        frames += 1;
    }
    assert!((100..=300).contains(&frames), "{frames} frames");
}

#[test]
fn run_writes_every_output_full_skeleton() {
    let s = setup();
    let out = s.root.join("out-full");
    let o = run_into(&s.full, &s.wav, &out, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    for want in [
        "wrote ",
        "motion.bvh",
        "decisions:",
        "detection latency",
        "x real time",
    ] {
        assert!(stdout.contains(want), "{want:?} missing in\n{stdout}");
    }
    check_outputs(&s.full, &out);
}

#[test]
fn run_writes_every_output_puppet_rig_with_rig_override() {
    let s = setup();
    let out = s.root.join("out-puppet");
    let rig = workspace().join("rigs/puppet-8ch.toml");
    let o = run_into(
        &s.puppet,
        &s.wav,
        &out,
        &["--rig", rig.to_str().unwrap(), "--chunk-ms", "5"],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    check_outputs(&s.puppet, &out);
}

/// One line on stderr, exit 2, and no output file in the folder.
fn refused(o: &Output, dir: &Path, want: &str) {
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains(want), "{want:?} not in {err}");
    if dir.exists() {
        for f in OUTPUTS {
            assert!(!dir.join(f).exists(), "{f} written");
        }
        assert_eq!(std::fs::read_dir(dir).unwrap().count(), 0);
    }
}

#[test]
fn bad_inputs_give_one_line_exit_2_and_no_files() {
    let s = setup();
    let bad = s.root.join("bad");
    std::fs::create_dir_all(&bad).unwrap();
    let out = bad.join("out");

    // A blob of another format version.
    let mut b = std::fs::read(&s.full).unwrap();
    b[4] = 1;
    b[5] = 0;
    let v1 = bad.join("v1.blob");
    std::fs::write(&v1, &b).unwrap();
    refused(
        &run_into(&v1, &s.wav, &out, &[]),
        &out,
        "unsupported blob format version 1",
    );

    // A WAV that is not a WAV.
    let txt = bad.join("notes.wav");
    std::fs::write(&txt, "these are words, not samples").unwrap();
    refused(&run_into(&s.full, &txt, &out, &[]), &out, "not a WAV file");

    // A rig naming a joint the blob's skeleton does not have.
    let rig = std::fs::read_to_string(workspace().join("rigs/puppet-8ch.toml")).unwrap();
    let text_rig = rig.replacen("joint = [", "joint = [\"NoSuchJoint\"] # was [", 1);
    let rig_path = bad.join("missing-joint.toml");
    std::fs::write(&rig_path, text_rig).unwrap();
    assert!(Rig::load(&rig_path).is_ok(), "the rig file itself parses");
    refused(
        &run_into(
            &s.puppet,
            &s.wav,
            &out,
            &["--rig", rig_path.to_str().unwrap()],
        ),
        &out,
        "no joint named `NoSuchJoint`",
    );

    // A rig with other channel names than the blob.
    refused(
        &run_into(
            &s.full,
            &s.wav,
            &out,
            &[
                "--rig",
                workspace().join("rigs/puppet-8ch.toml").to_str().unwrap(),
            ],
        ),
        &out,
        "has no channel",
    );

    // A missing blob.
    refused(
        &run_into(&bad.join("nope.blob"), &s.wav, &out, &[]),
        &out,
        "cannot read the blob",
    );
    assert!(!out.exists());
}

#[test]
fn full_skeleton_blob_rebuilds_the_library_frames() {
    // The played frames of a full-skeleton blob are the library's own frames (up to the blob's
    // quantization), so the rebuilt BVH frame of a library frame equals the original frame.
    let s = setup();
    let bytes = std::fs::read(&s.full).unwrap();
    let blob = Blob::parse(&bytes).unwrap();
    let pose_sk = gesture_trainer::rig::PoseSkeleton::from_blob(&blob.skeleton().unwrap()).unwrap();
    let take = read_bvh(s.corpus.join("take_000.bvh")).unwrap();
    let mut pose = vec![0.0f32; blob.channels()];
    let wrap = |d: f64| (d + 180.0).rem_euclid(360.0) - 180.0;
    for f in [0usize, 17, 400] {
        // The frame table starts with take 0.
        blob.pose(f, &mut pose);
        let rebuilt = pose_sk.frame(&pose);
        let orig = take.frame(f).unwrap();
        let sk = take.skeleton();
        let mut k = 0;
        for j in &sk.joints {
            for c in &j.channels {
                if c.is_rotation() {
                    let d = wrap(rebuilt[k] - orig[k]).abs();
                    assert!(
                        d < 0.02,
                        "frame {f} {}.{c}: {} vs {}",
                        j.name,
                        rebuilt[k],
                        orig[k]
                    );
                }
                k += 1;
            }
        }
    }
}

#[test]
fn puppet_channels_read_back_from_the_rebuilt_frames() {
    // Reading the rig back from a rebuilt frame gives the pose again (the module's promise for
    // one twist channel per joint and for Euler gimbals).
    let s = setup();
    let bytes = std::fs::read(&s.puppet).unwrap();
    let blob = Blob::parse(&bytes).unwrap();
    let pose_sk = gesture_trainer::rig::PoseSkeleton::from_blob(&blob.skeleton().unwrap()).unwrap();
    let rig = Rig::load(workspace().join("rigs/puppet-8ch.toml")).unwrap();
    let bound = rig.bind(pose_sk.skeleton(), "test").unwrap();
    let mut pose = vec![0.0f32; blob.channels()];
    for f in [3usize, 250, 900] {
        blob.pose(f, &mut pose);
        let frame = pose_sk.frame(&pose);
        let m =
            gesture_trainer::motion::Motion::new(pose_sk.skeleton().clone(), 1.0 / 30.0, 1, frame)
                .unwrap();
        let back = bound.channel_values(&m, 0).unwrap();
        for (ch, (a, b)) in pose.iter().zip(&back).enumerate() {
            assert!(
                (a - b).abs() < 0.05,
                "frame {f} channel {}: {a} vs {b}",
                rig.channels[ch].name
            );
        }
    }
}

fn shared_data() -> Option<PathBuf> {
    e2e_tests::shared_data("run_on_the_shared_recordings", "zeroeggs-067-speech2")
        .and_then(|_| e2e_tests::shared_data("run_on_the_shared_recordings", "beat-scott"))
        .map(|_| e2e_tests::shared_data_dir())
}

#[test]
fn run_on_the_shared_recordings() {
    // A blob packed from the ZeroEGGS take with the synthetic model (the inference layer is
    // reused: "new library, same model"), run on the BEAT 32-bit float WAV and the ZeroEGGS
    // audio.
    let Some(data) = shared_data() else { return };
    let s = setup();
    let zeggs: Vec<PathBuf> = std::fs::read_dir(data.join("zeroeggs-067-speech2"))
        .map(|r| r.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    let bvh = zeggs
        .iter()
        .find(|p| p.extension().is_some_and(|e| e == "bvh"));
    let wav = zeggs
        .iter()
        .find(|p| p.extension().is_some_and(|e| e == "wav"));
    let (Some(bvh), Some(wav)) = (bvh, wav) else {
        e2e_tests::skip("run_on_the_shared_recordings", "no ZeroEGGS take");
        return;
    };
    let blob = s.root.join("zeggs.blob");
    let opts = PackOptions {
        rig: Some(workspace().join("rigs/puppet-8ch.toml")),
        ..PackOptions::default()
    };
    pack(
        &s.root.join("model.json"),
        std::slice::from_ref(bvh),
        &opts,
        &blob,
    )
    .unwrap();
    let beat = data.join("beat-scott/2_scott_0_1_1.wav");
    for (name, audio) in [("beat", beat), ("zeggs", wav.clone())] {
        if !audio.is_file() {
            e2e_tests::skip(
                "run_on_the_shared_recordings",
                &format!("{} is absent", audio.display()),
            );
            continue;
        }
        let out = s.root.join(format!("out-{name}"));
        let o = run_into(&blob, &audio, &out, &[]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        eprintln!("{name}:\n{}", text(&o.stdout));
        check_outputs(&blob, &out);
    }
}

// ----- live ---------------------------------------------------------------------------------

use host_sim::live::{live_loop, AudioSource, FakeSource, LiveError, LiveOptions};

/// The utterance at 44.1 kHz as a microphone would deliver it (full scale +-1).
fn mic_samples(s: &Setup) -> Vec<f32> {
    let pcm = gesture_trainer::audio::load_wav_at(&s.wav, 44_100).unwrap();
    pcm.samples.iter().map(|&v| v as f32 / 32768.0).collect()
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
    };
    let stats = live_loop(&blob, &mut src, opts, &mut Vec::new()).unwrap();
    assert!((stats.seconds - 2.0).abs() < 1e-9, "{stats:?}");
    let mut src = FakeSource::new(mic_samples(s), 44_100, 441).failing_after(50);
    let err = live_loop(&blob, &mut src, LiveOptions::default(), &mut Vec::new()).unwrap_err();
    assert!(matches!(err, LiveError::Backend(_)), "{err}");
    assert_eq!(err.exit_code(), 2);
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
        assert!(err.contains("no audio input device"), "{args:?}: {err}");
    }
}

// ----- demo ---------------------------------------------------------------------------------

#[test]
fn demo_runs_end_to_end_into_a_temp_dir() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo");
    let t = std::time::Instant::now();
    let o = sim(&["demo", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(t.elapsed().as_secs() < 180, "{:?}", t.elapsed());
    let stdout = text(&o.stdout);
    assert!(stdout.contains("done in"), "{stdout}");
    for f in [
        "model.json",
        "puppet-8ch.toml",
        "utterance.wav",
        "corpus/truth.json",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    check_outputs(&out.join("character.blob"), &out.join("run-character"));
    check_outputs(&out.join("puppet.blob"), &out.join("run-puppet"));
}
