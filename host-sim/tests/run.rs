//! `gesture-sim run` end to end on a small synthetic setup built here with the trainer library
//! (synthetic corpus -> fit with 4 states -> pack, full-skeleton and puppet rigs), plus bad
//! inputs, the BVH round trip of the skeleton section, and the shared real recordings when
//! they are present.

mod common;

use std::path::PathBuf;

use common::*;
use gesture_runtime::blob::Blob;
use gesture_trainer::motion::read_bvh;
use gesture_trainer::pack::{pack, PackOptions};
use gesture_trainer::rig::Rig;

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
    // The memory check is the subprocess's above: this process's resident memory also counts
    // the tests running beside this one.
    assert_eq!(r.tick_drift, 0, "{r:?}");
    assert_eq!((r.pose_violations, r.duty_violations), (0, 0), "{r:?}");
    assert!(r.longest_without_step_s <= 2.0, "{r:?}");
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
    // The voice figures come from the audio the timeline names. The setup's speech has no
    // pause of 1.5 s (they are null there); the same speech twice with 3 s of silence between
    // has one.
    let mut r = hound::WavReader::open(&s.wav).unwrap();
    let spec = r.spec();
    let speech: Vec<i16> = r.samples::<i16>().map(Result::unwrap).collect();
    let paused = s.root.join("metrics-paused.wav");
    let mut w = hound::WavWriter::create(&paused, spec).unwrap();
    let silence = 3 * spec.sample_rate as usize * spec.channels as usize;
    for v in speech.iter().chain(&vec![0; silence]).chain(&speech) {
        w.write_sample(*v).unwrap();
    }
    w.finalize().unwrap();
    let out_paused = s.root.join("out-metrics-paused");
    let o = run_into(&s.full, &paused, &out_paused, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let o = sim(&["metrics", out_paused.to_str().unwrap(), "--json"]);
    let m: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for k in ["pause_ratio", "settle_s", "react_s", "speech_speed"] {
        assert!(
            m[k].as_f64().is_some_and(|v| v.is_finite() && v >= 0.0),
            "{k}: {m}"
        );
    }
    // Without the audio they are null (and the table says why), the other figures the same.
    let lost = s.root.join("metrics-no-audio");
    std::fs::create_dir_all(&lost).unwrap();
    std::fs::copy(out_paused.join("motion.bvh"), lost.join("motion.bvh")).unwrap();
    let mut tl_lost: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_paused.join("timeline.json")).unwrap())
            .unwrap();
    tl_lost["audio"] = "no-such-folder/speech.wav".into();
    std::fs::write(lost.join("timeline.json"), tl_lost.to_string()).unwrap();
    let o = sim(&["metrics", lost.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let m_lost: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for k in ["pause_ratio", "settle_s", "react_s", "speech_speed"] {
        assert!(m_lost[k].is_null(), "{k}: {m_lost}");
    }
    assert_eq!(m_lost["speech_coupling"], m["speech_coupling"]);
    let o = sim(&["metrics", lost.to_str().unwrap()]);
    assert!(text(&o.stdout).contains("(no voice figures: no speech audio"));
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
    // (The shipped rig's channels are body measures; the first becomes a joint channel.)
    let text_rig = rig.replacen(
        "body = \"head_pan\"",
        "joint = [\"NoSuchJoint\"]\naxis = \"Y\"",
        1,
    );
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
