//! Style control through `gesture-sim run`: `--energy`, `--style` and `--style-track` on a blob
//! packed with the energy knob's tones, the style in force at every decision in
//! `timeline.json`, and bad style options refused in one line with exit 2.

mod common;

use common::*;

fn timeline(dir: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("timeline.json")).unwrap()).unwrap()
}

#[test]
fn the_timeline_records_the_style_in_force_at_each_decision() {
    let s = setup();
    let blob = styled_blob();
    let track = s.root.join("track.csv");
    std::fs::write(
        &track,
        "time_s,style\n5,calm=1\n10,\"energetic=0.5,neutral=0.5\"\n",
    )
    .unwrap();
    let out = s.root.join("out-styled");
    let o = run_into(
        &blob,
        &s.wav,
        &out,
        &[
            "--style",
            "energetic=1",
            "--style-track",
            track.to_str().unwrap(),
            "--no-video",
        ],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let t = timeline(&out);
    assert_eq!(t["tones"], serde_json::json!(["energetic", "calm"]));
    let styles = t["styles"].as_array().unwrap();
    assert_eq!(styles.len(), 3);
    assert_eq!(styles[0]["style"], serde_json::json!({"energetic": 1.0}));
    assert_eq!(styles[1]["time_s"], 5.0);
    assert_eq!(
        styles[2]["style"],
        serde_json::json!({"energetic": 0.5, "neutral": 0.5})
    );
    let decisions = t["decisions"].as_array().unwrap();
    assert!(decisions.len() > 10, "{} decisions", decisions.len());
    let mut seen = [false; 3];
    for d in decisions {
        let time = d["time_s"].as_f64().unwrap();
        // A decision is made at a tick; the style changes on the audio clock before the tick
        // it applies to, so compare with a tick of slack.
        let want = if time < 5.0 - 0.05 {
            0
        } else if time < 10.0 - 0.05 {
            1
        } else {
            2
        };
        if (time - 5.0).abs() > 0.05 && (time - 10.0).abs() > 0.05 {
            assert_eq!(d["style"], styles[want]["style"], "decision at {time}");
            seen[want] = true;
        }
    }
    assert_eq!(seen, [true; 3], "decisions under every style");
}

#[test]
fn energy_on_a_styled_blob_and_neutral_on_any() {
    let s = setup();
    let blob = styled_blob();
    let out = s.root.join("out-energy");
    let o = run_into(&blob, &s.wav, &out, &["--energy", "-0.5", "--no-video"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let t = timeline(&out);
    assert_eq!(
        t["decisions"][0]["style"],
        serde_json::json!({"calm": 0.5, "neutral": 0.5})
    );
    // An unstyled blob runs neutral, and says so.
    let out = s.root.join("out-neutral");
    let o = run_into(
        &s.full,
        &s.wav,
        &out,
        &["--style", "neutral=1", "--no-video"],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let t = timeline(&out);
    assert_eq!(t["tones"], serde_json::json!([]));
    assert_eq!(
        t["decisions"][0]["style"],
        serde_json::json!({"neutral": 1.0})
    );
}

#[test]
fn bad_style_options_are_refused_in_one_line() {
    let s = setup();
    let blob = styled_blob();
    let track = s.root.join("bad-track.csv");
    std::fs::write(&track, "time_s,style\n2,calm=1\n1,calm=0\n").unwrap();
    let t = track.to_str().unwrap();
    for (blob, extra, want) in [
        (&blob, vec!["--style", "happy=1"], "no tone `happy`"),
        (&blob, vec!["--style", "calm=-1"], "at least 0"),
        (&blob, vec!["--style", "calm=nan"], "finite"),
        (&blob, vec!["--style", "calm"], "expected NAME=WEIGHT"),
        (&blob, vec!["--style-track", t], "bad-track.csv:3"),
        (&blob, vec!["--energy", "2"], "from -1 to 1"),
        (&s.full, vec!["--style", "calm=1"], "has no tones"),
        (&s.full, vec!["--energy", "0.5"], "pack --energy"),
    ] {
        let out = s.root.join("out-bad-style");
        let o = run_into(blob, &s.wav, &out, &extra);
        refused(&o, &out, want);
    }
}
