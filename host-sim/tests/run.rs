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

const OUTPUTS: [&str; 6] = [
    "motion.bvh",
    "timeline.json",
    "servo.csv",
    "preview.png",
    "preview.gif",
    "viewer.html",
];

/// `viewer.html` holds the speech (a WAV as long as the run) and a skeleton frame per 1/30 s
/// whose bones index its points; one script, no network.
fn check_viewer(dir: &Path, seconds: f64) {
    use base64::Engine;
    let html = std::fs::read_to_string(dir.join("viewer.html")).unwrap();
    assert_eq!(html.matches("<script").count(), 1);
    assert!(!html.contains("http://") && !html.contains("https://"));
    let data = html.split("const DATA = ").nth(1).unwrap();
    let data = &data[..data.find(";\nconst audio").unwrap()];
    let v: serde_json::Value = serde_json::from_str(data).unwrap();
    let frames = v["frames"].as_array().unwrap();
    let points = v["points"].as_u64().unwrap() as usize;
    assert!(points > 0);
    assert!(
        ((frames.len() as f64) - seconds * 30.0).abs() <= 1.0,
        "{}",
        frames.len()
    );
    assert!(frames
        .iter()
        .all(|f| f.as_array().unwrap().len() == 3 * points));
    for b in v["bones"].as_array().unwrap() {
        assert!(b[0].as_u64().unwrap() < points as u64 && b[1].as_u64().unwrap() < points as u64);
    }
    let b64 = html.split("data:audio/wav;base64,").nth(1).unwrap();
    let b64 = &b64[..b64.find('"').unwrap()];
    let wav = base64::engine::general_purpose::STANDARD
        .decode(b64)
        .unwrap();
    let r = hound::WavReader::new(std::io::Cursor::new(wav)).unwrap();
    let audio_s = r.duration() as f64 / r.spec().sample_rate as f64;
    assert!((audio_s - seconds).abs() < 0.05, "{audio_s} vs {seconds}");
}

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
    check_viewer(dir, tl["duration_s"].as_f64().unwrap());
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
    // True speed: a frame per 0.1 s of audio.
    let seconds = tl["duration_s"].as_f64().unwrap();
    assert!(
        (frames as f64 - seconds * 10.0).abs() <= 1.0,
        "{frames} frames for {seconds} s"
    );
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

/// `preview.mp4`: the speech as its sound track, real-time length; `--no-video` and a PATH
/// without ffmpeg write everything else (the latter says how to get it in one line).
#[test]
fn run_writes_a_video_with_the_speech_when_ffmpeg_is_there() {
    let s = setup();
    let have_ffmpeg = Command::new("ffmpeg").arg("-version").output().is_ok();
    // No ffmpeg on PATH: the other outputs, and one line saying how to get it.
    let out = s.root.join("out-no-ffmpeg");
    let empty = s.root.join("empty-path");
    std::fs::create_dir_all(&empty).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_gesture-sim"))
        .env("PATH", &empty)
        .args(["run", "--blob", s.full.to_str().unwrap(), "--audio"])
        .args([s.wav.to_str().unwrap(), "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    assert!(
        stdout.contains("no preview.mp4") && stdout.contains("apt-get install ffmpeg"),
        "{stdout}"
    );
    assert!(!out.join("preview.mp4").exists());
    assert!(out.join("preview.gif").exists());
    // --no-video: not even the note.
    let out = s.root.join("out-no-video");
    let o = run_into(&s.full, &s.wav, &out, &["--no-video"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(!text(&o.stdout).contains("preview.mp4"));
    assert!(!out.join("preview.mp4").exists());
    if !have_ffmpeg {
        eprintln!("skipping the video itself: no ffmpeg on PATH");
        return;
    }
    let out = s.root.join("out-video");
    let o = run_into(&s.full, &s.wav, &out, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let mp4 = std::fs::read(out.join("preview.mp4")).unwrap();
    assert_eq!(&mp4[4..8], b"ftyp", "not an MP4");
    // Its streams: H.264 video and AAC audio, each as long as the speech.
    let probe = Command::new("ffprobe")
        .args(["-v", "error", "-show_entries", "stream=codec_name,duration"])
        .args(["-of", "csv=p=0"])
        .arg(out.join("preview.mp4"))
        .output();
    let Ok(probe) = probe else {
        eprintln!("no ffprobe: stream check skipped");
        return;
    };
    let wav = hound::WavReader::open(&s.wav).unwrap();
    let seconds = wav.duration() as f64 / wav.spec().sample_rate as f64;
    let streams = text(&probe.stdout);
    let mut codecs = Vec::new();
    for line in streams.lines() {
        let (codec, dur) = line.split_once(',').unwrap();
        let dur: f64 = dur.parse().unwrap();
        assert!(
            (dur - seconds).abs() < 0.1,
            "{codec}: {dur} s vs {seconds} s"
        );
        codecs.push(codec.to_string());
    }
    assert_eq!(codecs, ["h264", "aac"], "{streams}");
}

/// `viewer.html` in a real browser (headless Chromium, when installed): the script runs and the
/// skeleton frame it shows follows the audio clock (opened at 2.5 s: frame 75 at 30 fps).
#[test]
fn viewer_shows_the_frame_of_the_audio_clock_in_chromium() {
    let s = setup();
    let Some(chromium) = ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|c| Command::new(c).arg("--version").output().is_ok())
    else {
        eprintln!("skipping: no chromium on PATH");
        return;
    };
    let out = s.root.join("out-viewer");
    let o = run_into(&s.full, &s.wav, &out, &["--no-video"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let url = format!("file://{}#t=2.5", out.join("viewer.html").display());
    let profile = tempfile::tempdir().unwrap();
    let o = Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--virtual-time-budget=5000",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(["--dump-dom", &url])
        .output()
        .unwrap();
    let dom = text(&o.stdout);
    let state = dom
        .split("<output id=\"state\"")
        .nth(1)
        .and_then(|x| x.split('>').nth(1))
        .and_then(|x| x.split('<').next())
        .unwrap_or_else(|| panic!("no state in the page: {}", text(&o.stderr)));
    assert_eq!(state, "t=2.500 frame=75", "{state}");
}

/// `--vmc`: a loopback receiver decodes the bundles: the synthetic character's 13 humanoid
/// bones, unit quaternions, times a tick apart; a bad address is one line and exit 2.
#[test]
fn run_streams_vmc_bundles_a_receiver_decodes() {
    let s = setup();
    let rx = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    rx.set_read_timeout(Some(std::time::Duration::from_millis(500)))
        .unwrap();
    let addr = rx.local_addr().unwrap().to_string();
    let receiver = std::thread::spawn(move || {
        let mut got = Vec::new();
        let mut buf = vec![0u8; 65536];
        while let Ok(n) = rx.recv(&mut buf) {
            got.push(buf[..n].to_vec());
        }
        got
    });
    // Three seconds of the utterance, paced in real time (as a receiver wants it; a flood of
    // datagrams would overrun the socket's buffer on a busy machine).
    let short = s.root.join("vmc-3s.wav");
    {
        let mut r = hound::WavReader::open(&s.wav).unwrap();
        let spec = r.spec();
        let n = 3 * spec.sample_rate as usize * spec.channels as usize;
        let samples: Vec<i16> = r.samples::<i16>().take(n).map(Result::unwrap).collect();
        let mut w = hound::WavWriter::create(&short, spec).unwrap();
        samples.iter().for_each(|&x| w.write_sample(x).unwrap());
        w.finalize().unwrap();
    }
    let out = s.root.join("out-vmc");
    let o = run_into(
        &s.full,
        &short,
        &out,
        &["--no-video", "--realtime", "--vmc", &addr],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    assert!(stdout.contains("vmc: sent"), "{stdout}");
    let got = receiver.join().unwrap();
    let tl: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("timeline.json")).unwrap()).unwrap();
    let ticks = tl["ticks"].as_u64().unwrap() as usize;
    let fps = tl["fps"].as_f64().unwrap();
    // UDP may drop a few on a busy machine; nearly all must arrive.
    assert!(got.len() * 10 >= ticks * 9, "{} of {ticks}", got.len());
    let mut last_t = -1.0;
    for bytes in &got {
        let (_, packet) = rosc::decoder::decode_udp(bytes).unwrap();
        let rosc::OscPacket::Bundle(b) = packet else {
            panic!("not a bundle")
        };
        let msgs: Vec<&rosc::OscMessage> = b
            .content
            .iter()
            .map(|p| match p {
                rosc::OscPacket::Message(m) => m,
                _ => panic!("nested bundle"),
            })
            .collect();
        assert_eq!(msgs[0].addr, "/VMC/Ext/Root/Pos");
        let bones: Vec<&rosc::OscMessage> = msgs
            .iter()
            .copied()
            .filter(|m| m.addr == "/VMC/Ext/Bone/Pos")
            .collect();
        let names: Vec<String> = bones
            .iter()
            .map(|m| m.args[0].clone().string().unwrap())
            .collect();
        assert_eq!(
            names,
            [
                "Hips",
                "Spine",
                "Chest",
                "Neck",
                "Head",
                "LeftShoulder",
                "LeftUpperArm",
                "LeftLowerArm",
                "LeftHand",
                "RightShoulder",
                "RightUpperArm",
                "RightLowerArm",
                "RightHand"
            ]
        );
        for m in &bones {
            let q: Vec<f32> = m.args[4..8]
                .iter()
                .map(|a| a.clone().float().unwrap())
                .collect();
            let norm = q.iter().map(|v| v * v).sum::<f32>().sqrt();
            assert!((norm - 1.0).abs() < 1e-4, "{q:?}");
        }
        assert_eq!(msgs[msgs.len() - 2].addr, "/VMC/Ext/OK");
        let t_msg = msgs[msgs.len() - 1];
        assert_eq!(t_msg.addr, "/VMC/Ext/T");
        let t = t_msg.args[0].clone().float().unwrap() as f64;
        assert!(t > last_t, "{t} after {last_t}");
        // Times are tick times.
        let k = (t * fps).round();
        assert!((t * fps - k).abs() < 1e-3, "{t}");
        last_t = t;
    }
    // A bad address: one line, exit 2, nothing written.
    let out = s.root.join("out-vmc-bad");
    let o = run_into(&s.full, &s.wav, &out, &["--vmc", "no-such-host.invalid:1"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert_eq!(text(&o.stderr).lines().count(), 1);
    assert!(text(&o.stderr).contains("--vmc"));
    assert!(!out.exists());
}

/// `--blender`: a script next to motion.bvh and the speech it was played to (valid Python,
/// naming both files), the speech as long as the run.
#[test]
fn blender_script_and_speech_sit_next_to_the_motion() {
    let s = setup();
    let out = s.root.join("out-blender");
    let o = run_into(&s.full, &s.wav, &out, &["--no-video", "--blender"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let script = std::fs::read_to_string(out.join("blender.py")).unwrap();
    assert!(script.contains("\"motion.bvh\"") && script.contains("\"speech.wav\""));
    let tl: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("timeline.json")).unwrap()).unwrap();
    let r = hound::WavReader::open(out.join("speech.wav")).unwrap();
    let seconds = r.duration() as f64 / r.spec().sample_rate as f64;
    assert!((seconds - tl["duration_s"].as_f64().unwrap()).abs() < 0.01);
    match Command::new("python3")
        .args(["-m", "py_compile"])
        .arg(out.join("blender.py"))
        .output()
    {
        Ok(o) => assert!(o.status.success(), "{}", text(&o.stderr)),
        Err(_) => eprintln!("no python3: syntax check skipped"),
    }
    // Without --blender, neither file.
    let out = s.root.join("out-no-blender");
    let o = run_into(&s.full, &s.wav, &out, &["--no-video"]);
    assert!(o.status.success());
    assert!(!out.join("blender.py").exists() && !out.join("speech.wav").exists());
}

/// A run never writes over its inputs: audio named like an output in the output folder is
/// refused in one line, exit 2, the audio unchanged.
#[test]
fn run_refuses_to_overwrite_its_audio() {
    let s = setup();
    let dir = s.root.join("out-overwrite");
    std::fs::create_dir_all(&dir).unwrap();
    let audio = dir.join("speech.wav");
    std::fs::copy(&s.wav, &audio).unwrap();
    let before = std::fs::read(&audio).unwrap();
    let o = run_into(&s.full, &audio, &dir, &["--no-video", "--blender"]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("also an input"), "{err}");
    assert_eq!(std::fs::read(&audio).unwrap(), before);
    assert!(!dir.join("timeline.json").exists());
}

/// `soak`: twelve minutes of hostile generated audio through the puppet's device loop: no
/// drift, no pose or duty cycle out of its limits, steps all along, memory flat.
#[test]
fn soak_finds_no_violation_drift_or_growth() {
    let s = setup();
    let o = sim(&[
        "soak",
        "--blob",
        s.puppet.to_str().unwrap(),
        "--hours",
        "0.2",
    ]);
    let stdout = text(&o.stdout);
    assert!(o.status.success(), "{stdout}{}", text(&o.stderr));
    assert!(
        stdout.contains("limit violations: 0 poses, 0 duty cycles"),
        "{stdout}"
    );
    assert!(stdout.contains("soak passed"), "{stdout}");
    let r = host_sim::soak::soak(
        &Blob::parse(&std::fs::read(&s.puppet).unwrap()).unwrap(),
        0.1,
        3,
    )
    .unwrap();
    assert!(r.ok(), "{r:?}");
    assert!((r.audio_s - 360.0).abs() < 1e-9, "{r:?}");
    assert!(r.steps > 360 && r.decisions > 10, "{r:?}");
}

/// `gesture-sim metrics` on a run folder: the variety figures agree with the timeline's entries
/// counted here, every figure is finite, and broken folders are one line and exit 2.
#[test]
fn metrics_of_a_run_folder_agree_with_its_timeline() {
    let s = setup();
    let out = s.root.join("out-metrics");
    let o = run_into(&s.full, &s.wav, &out, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let o = sim(&["metrics", out.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let m: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let tl: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("timeline.json")).unwrap()).unwrap();
    let entries = tl["entries"].as_array().unwrap();
    let ticks = std::fs::read_to_string(out.join("servo.csv"))
        .unwrap()
        .lines()
        .count()
        - 1;
    // Frames per segment from the entries, counted here.
    let mut frames: std::collections::BTreeMap<u64, usize> = Default::default();
    for (k, e) in entries.iter().enumerate() {
        let start = e["tick"].as_u64().unwrap() as usize;
        let end = entries
            .get(k + 1)
            .map_or(ticks, |n| n["tick"].as_u64().unwrap() as usize);
        *frames.entry(e["segment"].as_u64().unwrap()).or_default() += end - start;
    }
    let covered: usize = frames.values().sum();
    let max_share = *frames.values().max().unwrap() as f64 / covered as f64;
    assert_eq!(m["entries"].as_u64().unwrap() as usize, entries.len());
    assert_eq!(
        m["distinct_segments"].as_u64().unwrap() as usize,
        frames.len()
    );
    assert!((m["max_segment_share"].as_f64().unwrap() - max_share).abs() < 1e-9);
    let cuts = entries
        .iter()
        .filter(|e| e["cut"].as_bool().unwrap() && e["tick"].as_u64().unwrap() > 0)
        .count();
    let seconds = m["seconds"].as_f64().unwrap();
    assert!((m["cuts_per_s"].as_f64().unwrap() - cuts as f64 / seconds).abs() < 1e-9);
    for (k, v) in m.as_object().unwrap() {
        if let Some(x) = v.as_f64() {
            assert!(x.is_finite(), "{k} = {x}");
        }
    }
    // The table names its units.
    let o = sim(&["metrics", out.to_str().unwrap()]);
    assert!(o.status.success());
    assert!(text(&o.stdout).contains("(cm/s)"));
    // A folder without a timeline, and a timeline of the first version.
    let empty = s.root.join("metrics-empty");
    std::fs::create_dir_all(&empty).unwrap();
    let o = sim(&["metrics", empty.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(text(&o.stderr).lines().count(), 1, "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("timeline.json"));
    let old = s.root.join("metrics-v1");
    std::fs::create_dir_all(&old).unwrap();
    std::fs::write(
        old.join("timeline.json"),
        r#"{"format":"gesture-sim-timeline","version":1,"segments":2,"steps":[],"entries":[]}"#,
    )
    .unwrap();
    let o = sim(&["metrics", old.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("version 1"), "{}", text(&o.stderr));
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
        &mut |t, pose| {
            assert_eq!(pose.len(), blob.channels());
            times.push(t);
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
        &mut |_, _| Err("receiver gone".into()),
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
