//! `gesture-sim demo`: the whole chain on synthetic data, then real recorded speech driving the
//! real motion-capture library it ships (`host-sim/assets`, each file with its licence beside
//! it), and the real run's `viewer.html` in a real browser showing a body.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::*;
use host_sim::demo::{demo, DemoParams, REAL_ASSETS};

fn assets() -> PathBuf {
    workspace().join("host-sim/assets")
}

fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files_under(&p, out);
        } else {
            out.push(p);
        }
    }
}

/// Every shipped file has its licence beside it and is named in the README with its source;
/// the demo writes all of them (so its copy carries the licences too).
#[test]
fn shipped_assets_carry_their_licence_and_attribution() {
    let root = assets();
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let mut files = Vec::new();
    files_under(&root, &mut files);
    let mut names: Vec<String> = files
        .iter()
        .map(|f| {
            f.strip_prefix(&root)
                .unwrap()
                .to_str()
                .unwrap()
                .replace('\\', "/")
        })
        .collect();
    names.sort();
    let mut built_in: Vec<String> = REAL_ASSETS.iter().map(|(n, _)| n.to_string()).collect();
    built_in.sort();
    assert_eq!(
        names, built_in,
        "host-sim/assets and the demo's built-in copy differ"
    );
    for (name, bytes) in REAL_ASSETS {
        let on_disk = std::fs::read(root.join(name)).unwrap();
        assert!(on_disk == bytes, "{name}: the built-in copy is stale");
        if name.ends_with(".bvh") || name.ends_with(".wav") {
            let file = Path::new(name).file_name().unwrap().to_str().unwrap();
            assert!(readme.contains(file), "README.md does not name {file}");
            let licence = root
                .join(Path::new(name).parent().unwrap())
                .join("LICENSE.txt");
            let words = std::fs::read_to_string(&licence)
                .unwrap_or_else(|e| panic!("{}: {e}", licence.display()));
            let source = if name.starts_with("cmu/") {
                "mocap.cs.cmu.edu"
            } else {
                "public domain"
            };
            assert!(
                words.contains(source),
                "{}: no {source:?}",
                licence.display()
            );
        }
    }
    // CMU asks for this acknowledgement.
    assert!(readme.contains("The database was created with funding from NSF EIA-0196217."));
    // The material is what the README says: 16 kHz mono speech, 30 fps motion.
    let wav = hound::WavReader::open(root.join("speech/lj001-0001-0003.wav")).unwrap();
    assert_eq!((wav.spec().sample_rate, wav.spec().channels), (16_000, 1));
    let seconds = wav.duration() as f64 / 16_000.0;
    assert!((15.0..25.0).contains(&seconds), "{seconds} s");
    for clip in ["18_08-listening", "18_08-explaining", "19_08"] {
        let m = gesture_trainer::motion::read_bvh(root.join(format!("cmu/{clip}.bvh"))).unwrap();
        assert!((m.fps() - 30.0).abs() < 1e-9, "{clip}: {} fps", m.fps());
        assert_eq!(m.skeleton().joints.len(), 31, "{clip}");
    }
}

/// A headless-Chromium screenshot of `viewer.html` at `t` seconds (1200 x 800), or `None`
/// without a Chromium on PATH.
pub fn screenshot(viewer: &Path, t: f64, png: &Path) -> Option<Vec<[u8; 3]>> {
    let chromium = ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|c| Command::new(c).arg("--version").output().is_ok())?;
    let profile = tempfile::tempdir().unwrap();
    let o = Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--hide-scrollbars",
            "--virtual-time-budget=5000",
            "--window-size=1200,800",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg(format!("--screenshot={}", png.display()))
        .arg(format!("file://{}#t={t}", viewer.display()))
        .output()
        .unwrap();
    assert!(png.is_file(), "no screenshot: {}", text(&o.stderr));
    let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(png).unwrap()));
    let mut r = dec.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size().unwrap()];
    let info = r.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (1200, 800));
    let step = info.color_type.samples();
    Some(
        buf[..info.buffer_size()]
            .chunks_exact(step)
            .map(|p| [p[0], p[1], p[2]])
            .collect(),
    )
}

/// Clay-coloured pixels (the body's shading) in the figure's part of a 1200 x 800 screenshot.
fn body_pixels(px: &[[u8; 3]]) -> usize {
    let mut n = 0;
    for y in 60..470 {
        for x in 20..560 {
            let [r, g, b] = px[y * 1200 + x].map(i32::from);
            if r > g + 25 && g > b && r > 40 && r < 240 {
                n += 1;
            }
        }
    }
    n
}

#[test]
fn demo_runs_end_to_end_into_a_temp_dir() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo");
    let t = std::time::Instant::now();
    let o = sim(&["demo", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(t.elapsed().as_secs() < 240, "{:?}", t.elapsed());
    let stdout = text(&o.stdout);
    for f in [
        "model.json",
        "puppet-8ch.toml",
        "utterance.wav",
        "corpus/truth.json",
        "real/README.md",
        "real/cmu/LICENSE.txt",
        "real/speech/LICENSE.txt",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    check_outputs(&out.join("character.blob"), &out.join("run-character"));
    check_outputs(&out.join("puppet.blob"), &out.join("run-puppet"));
    // The real speech through the real library: the same outputs, the 8 servos' trace.
    check_outputs(&out.join("real-character.blob"), &out.join("run-real"));
    check_outputs(&out.join("real-puppet.blob"), &out.join("run-real-puppet"));
    let tl: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run-real/timeline.json")).unwrap())
            .unwrap();
    assert!((tl["duration_s"].as_f64().unwrap() - 22.12).abs() < 0.01);
    assert!(stdout.contains("no recording of speech with its gestures may be shipped"));
    assert!(stdout.contains("38 segments"), "{stdout}");
    let last = stdout.lines().last().unwrap();
    assert!(last.starts_with("done in"), "{last}");
    assert!(last.contains("run-real/viewer.html"), "{last}");

    // In a browser: a body (clay pixels where the figure is), not a stick figure.
    let png = dir.path().join("viewer.png");
    match screenshot(&out.join("run-real/viewer.html"), 5.5, &png) {
        None => eprintln!("skipping the screenshot: no chromium on PATH"),
        Some(px) => {
            let n = body_pixels(&px);
            assert!(n > 8000, "{n} body pixels in the figure's area");
        }
    }
}

/// `--audio` with a file that is not speech: one line naming it, exit 2, nothing written.
#[test]
fn demo_refuses_a_bad_audio_file_before_writing_anything() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("notes.wav");
    std::fs::write(&bad, "not a recording").unwrap();
    let out = dir.path().join("demo");
    let o = sim(&[
        "demo",
        "--out",
        out.to_str().unwrap(),
        "--audio",
        bad.to_str().unwrap(),
    ]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("--audio") && err.contains("notes.wav"),
        "{err}"
    );
    assert!(!out.exists());
}

/// `--audio` with a good file (44.1 kHz stereo, another format than the shipped speech): the
/// real runs hear it (a smaller demo, through the library function).
#[test]
fn demo_plays_your_own_recording() {
    let dir = tempfile::tempdir().unwrap();
    let mine = dir.path().join("mine.wav");
    let pcm =
        gesture_trainer::audio::load_wav_at(assets().join("speech/lj001-0001-0003.wav"), 44_100)
            .unwrap();
    let spec = hound::WavSpec {
        channels: 2,
        sample_rate: 44_100,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut w = hound::WavWriter::create(&mine, spec).unwrap();
    for &s in &pcm.samples[..44_100 * 12] {
        w.write_sample(s).unwrap();
        w.write_sample(s).unwrap();
    }
    w.finalize().unwrap();
    let out = dir.path().join("demo");
    let params = DemoParams {
        corpus_minutes: 1.0,
        utterance_s: 5.0,
        states: 4,
    };
    let mut printed = Vec::new();
    demo(&out, params, Some(&mine), &mut printed).unwrap();
    let printed = text(&printed);
    assert!(printed.contains("your recording"), "{printed}");
    let tl: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run-real/timeline.json")).unwrap())
            .unwrap();
    assert!((tl["duration_s"].as_f64().unwrap() - 12.0).abs() < 0.01);
    assert!(tl["audio"].as_str().unwrap().ends_with("mine.wav"));
    check_outputs(&out.join("real-puppet.blob"), &out.join("run-real-puppet"));
}
