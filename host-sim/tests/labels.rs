//! Semantic labels through `gesture-sim run`: on the synthetic setup with one clip labelled,
//! a label from `--labels` is answered by that clip's labelled segment, entered at a frame no
//! later than its stroke, and its stroke is shown; without labels the labelled blob decides as
//! the unlabelled one; bad label inputs are refused in one line. With the `kws` feature and the
//! shared recordings, keyword spotting brings labels on real speech.

mod common;

use common::*;
use gesture_runtime::blob::Blob;
use gesture_trainer::control::semantic::LabelSpec;
use gesture_trainer::pack::{pack, PackOptions};

fn timeline(dir: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("timeline.json")).unwrap()).unwrap()
}

#[test]
fn a_label_is_answered_by_its_segment_before_the_stroke() {
    let s = setup();
    let path = labelled_blob();
    let bytes = std::fs::read(&path).unwrap();
    let blob = Blob::parse(&bytes).unwrap();
    assert_eq!(blob.labelled_count(), 1);
    let seg = blob.labelled_segment(0).unwrap();
    let info = blob.segment(seg).unwrap();
    let stroke = info.stroke.unwrap() as u64;
    let track = s.root.join("labels.csv");
    std::fs::write(&track, "time_s,label\n2.0,wave\n8.0,wave\n").unwrap();
    let out = s.root.join("out-labels");
    let o = run_into(
        &path,
        &s.wav,
        &out,
        &["--labels", track.to_str().unwrap(), "--no-video"],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let t = timeline(&out);
    let labels = t["labels"].as_array().unwrap();
    assert_eq!(labels.len(), 2);
    for l in labels {
        assert_eq!(l["label"], "wave");
        assert_eq!(l["source"], "track");
        assert_eq!(l["outcome"], "stroke", "{l}");
        assert_eq!(l["segment"].as_u64(), Some(seg as u64), "{l}");
        let entry = l["entry_frame"].as_u64().unwrap();
        assert!(entry <= stroke, "entered at {entry}, stroke at {stroke}");
        assert!(
            entry as f64 <= 0.5 * (info.len - 1) as f64,
            "entered past half the segment"
        );
        let (at, shown) = (
            l["time_s"].as_f64().unwrap(),
            l["stroke_time_s"].as_f64().unwrap(),
        );
        assert!(shown >= at && shown - at < 3.0, "{at} -> {shown}");
    }
}

#[test]
fn without_labels_the_labelled_blob_decides_as_the_unlabelled_one() {
    let s = setup();
    let path = labelled_blob();
    let (a, b) = (s.root.join("out-nolabel-a"), s.root.join("out-nolabel-b"));
    for (blob, out) in [(&s.full, &a), (&path, &b)] {
        let o = run_into(blob, &s.wav, out, &["--no-video"]);
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
    let (ta, tb) = (timeline(&a), timeline(&b));
    assert!(ta["decisions"].as_array().unwrap().len() > 10);
    assert_eq!(ta["decisions"], tb["decisions"]);
    assert_eq!(ta["entries"], tb["entries"]);
}

#[test]
fn bad_label_inputs_are_refused_in_one_line() {
    let s = setup();
    let path = labelled_blob();
    let track = s.root.join("bad-labels.csv");
    std::fs::write(&track, "time_s,label\n1,hello\n").unwrap();
    let kw = s.root.join("kw.tsv");
    std::fs::write(&kw, "hello\tnope\n").unwrap();
    for (blob, extra, want) in [
        (
            &path,
            vec!["--labels", track.to_str().unwrap()],
            "no label `hello`",
        ),
        (
            &s.full,
            vec!["--labels", track.to_str().unwrap()],
            "has no labels",
        ),
        (
            &path,
            vec!["--keywords", kw.to_str().unwrap()],
            "label `nope`",
        ),
    ] {
        let out = s.root.join("out-bad-labels");
        let o = run_into(blob, &s.wav, &out, &extra);
        refused(&o, &out, want);
    }
}

/// Without the `kws` feature, `--keywords` says how to get it.
#[cfg(not(feature = "kws"))]
#[test]
fn keywords_without_the_feature_say_how_to_enable_it() {
    let s = setup();
    let path = labelled_blob();
    let kw = s.root.join("kw-wave.tsv");
    std::fs::write(&kw, "hello\twave\n").unwrap();
    let out = s.root.join("out-kws-off");
    let o = run_into(&path, &s.wav, &out, &["--keywords", kw.to_str().unwrap()]);
    refused(&o, &out, "--features kws");
}

/// With the feature and the shared recordings: "fashion" is said six times in BEAT's second
/// monologue (PocketSphinx's own full decoder finds it at 6.76, 9.10, 10.25, 11.53, 13.24 and
/// 21.62 s, word ends); the spotter hears every one within 0.3 s of its end.
#[cfg(feature = "kws")]
#[test]
fn keywords_are_spotted_in_real_speech() {
    let Some(d) = e2e_tests::shared_data("keywords_are_spotted_in_real_speech", "beat-scott")
    else {
        return;
    };
    let s = setup();
    let kw = s.root.join("kw-fashion.tsv");
    std::fs::write(&kw, "fashion\twave\n").unwrap();
    let o = sim(&[
        "keywords",
        "--audio",
        d.join("2_scott_0_2_2.wav").to_str().unwrap(),
        "--keywords",
        kw.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let times: Vec<f64> = text(&o.stdout)
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    for end in [6.76, 9.10, 10.25, 11.53, 13.24, 21.62] {
        assert!(
            times.iter().any(|&t| t >= end && t <= end + 0.3),
            "no detection within 0.3 s after {end}: {times:?}"
        );
    }
    assert!(times.len() <= 9, "{} detections: {times:?}", times.len());
}

/// A label pattern that matches no library file is an input error of one line.
#[test]
fn a_label_matching_no_file_is_refused() {
    let s = setup();
    let opts = PackOptions {
        labels: vec![LabelSpec {
            name: "bye".into(),
            pattern: "*_bye_*".into(),
            stroke_s: None,
        }],
        ..PackOptions::default()
    };
    let out = s.root.join("never.blob");
    let e = pack(
        &s.root.join("model.json"),
        std::slice::from_ref(&s.corpus),
        &opts,
        &out,
    )
    .unwrap_err();
    let msg = e.to_string();
    assert!(e.is_input(), "{msg}");
    assert!(msg.contains("--label bye=*_bye_*: matches no library file") && !msg.contains('\n'));
    assert!(!out.exists());
}
