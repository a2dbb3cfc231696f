//! Shared setup of the simulator's integration tests: a small synthetic corpus, a model fitted
//! with 4 states, a full-skeleton and a puppet blob, a new utterance, and the checks of a run's
//! output folder. Each test binary builds its own (a few seconds).
#![allow(dead_code)] // every test binary uses a different part

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

use gesture_runtime::blob::Blob;
use gesture_trainer::corpus::{load_corpus, LoadOptions};
use gesture_trainer::inference::train::{fit, sequences, FitConfig};
use gesture_trainer::motion::read_bvh;
use gesture_trainer::pack::{pack, PackOptions};
use gesture_trainer::synth::{write_corpus, SynthParams};

/// The shared setup: a corpus, a model, two blobs and a new utterance.
pub struct Setup {
    _dir: tempfile::TempDir,
    pub root: PathBuf,
    pub full: PathBuf,
    pub puppet: PathBuf,
    pub wav: PathBuf,
    pub corpus: PathBuf,
}

pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

pub fn setup() -> &'static Setup {
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

pub fn sim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gesture-sim"))
        .args(args)
        .output()
        .expect("gesture-sim runs")
}

pub fn run_into(blob: &Path, wav: &Path, out: &Path, extra: &[&str]) -> Output {
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

pub fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

pub const OUTPUTS: [&str; 6] = [
    "motion.bvh",
    "timeline.json",
    "servo.csv",
    "preview.png",
    "preview.gif",
    "viewer.html",
];

/// `viewer.html` holds the speech (a WAV as long as the run) and a skeleton frame per 1/30 s
/// whose bones index its points; one script, no network.
pub fn check_viewer(dir: &Path, seconds: f64, servos: usize) {
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
    // The body: limbs with thickness, the head and the hands as balls, a floor.
    let limbs = v["limbs"].as_array().unwrap();
    assert!(limbs.len() >= 10, "{} limbs", limbs.len());
    for l in limbs {
        assert!(l[0].as_u64().unwrap() < points as u64 && l[1].as_u64().unwrap() < points as u64);
        assert!(l[2].as_f64().unwrap() > 0.0);
    }
    let balls = v["balls"].as_array().unwrap();
    assert_eq!(balls.len(), 3, "the head and two hands: {balls:?}");
    let height = v["height"].as_f64().unwrap();
    for b in balls {
        assert!(b[0].as_u64().unwrap() < points as u64 && b[1].as_u64().unwrap() < points as u64);
        assert!(b[3].as_f64().unwrap() > 0.0 && b[3].as_f64().unwrap() < 0.1 * height);
    }
    assert!(v["floor"].as_f64().unwrap().is_finite());
    // A rig's servos: one pulse per channel per frame.
    if servos == 0 {
        assert!(v["servos"].is_null());
    } else {
        let pulses = v["servos"]["pulses"].as_array().unwrap();
        assert_eq!(pulses.len(), frames.len());
        assert!(pulses.iter().all(|p| p.as_array().unwrap().len() == servos));
        assert_eq!(v["servos"]["names"].as_array().unwrap().len(), servos);
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
pub fn check_outputs(blob_path: &Path, dir: &Path) {
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
    let servos = if blob.rig_name() == "full-skeleton" {
        0
    } else {
        blob.channels()
    };
    check_viewer(dir, tl["duration_s"].as_f64().unwrap(), servos);
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

/// One line on stderr, exit 2, and no output file in the folder.
pub fn refused(o: &Output, dir: &Path, want: &str) {
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

pub fn shared_data() -> Option<PathBuf> {
    e2e_tests::shared_data("run_on_the_shared_recordings", "zeroeggs-067-speech2")
        .and_then(|_| e2e_tests::shared_data("run_on_the_shared_recordings", "beat-scott"))
        .map(|_| e2e_tests::shared_data_dir())
}

/// The setup's model and corpus packed with `opts` into `name` under the setup's folder, once.
fn packed_once(name: &str, opts: gesture_trainer::pack::PackOptions) -> PathBuf {
    let s = setup();
    let path = s.root.join(name);
    if !path.exists() {
        gesture_trainer::pack::pack(
            &s.root.join("model.json"),
            std::slice::from_ref(&s.corpus),
            &opts,
            &path,
        )
        .unwrap();
    }
    path
}

/// The setup's model and corpus packed with `take_001` labelled `wave` (one clip: one labelled
/// segment).
pub fn labelled_blob() -> PathBuf {
    packed_once(
        "labelled.blob",
        gesture_trainer::pack::PackOptions {
            labels: vec![gesture_trainer::control::semantic::LabelSpec {
                name: "wave".into(),
                pattern: "take_001*".into(),
                stroke_s: None,
            }],
            ..gesture_trainer::pack::PackOptions::default()
        },
    )
}

/// The setup's model and corpus packed with the energy knob (`energetic`, `calm`).
pub fn styled_blob() -> PathBuf {
    packed_once(
        "styled.blob",
        gesture_trainer::pack::PackOptions {
            styles: gesture_trainer::pack::StyleOptions {
                energy: Some(1.5),
                ..gesture_trainer::pack::StyleOptions::default()
            },
            ..gesture_trainer::pack::PackOptions::default()
        },
    )
}
