//! What people watch and animate from a run: `preview.mp4` with the speech, `viewer.html` in a
//! real browser, the VMC stream to avatar apps, and the Blender script.

mod common;

use std::process::Command;

use common::*;

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
