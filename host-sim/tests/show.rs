//! Show files end to end: `gesture-sim run --show` bakes a run of the puppet blob, and
//! `gesture-sim play-show` plays it with the runtime's ShowPlayer (no inference): its
//! `servo.csv` and `motion.bvh` are byte for byte the run's, with the run's audio as the
//! clock or without it. Bad shows, and a show played with another blob, are one line and
//! exit 2, nothing written.

mod common;

use common::*;

fn play_show(
    blob: &std::path::Path,
    show: &std::path::Path,
    out: &std::path::Path,
    audio: Option<&std::path::Path>,
) -> std::process::Output {
    let mut a = vec![
        "play-show",
        "--blob",
        blob.to_str().unwrap(),
        "--show",
        show.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    if let Some(w) = audio {
        a.extend_from_slice(&["--audio", w.to_str().unwrap()]);
    }
    sim(&a)
}

#[test]
fn a_played_show_writes_the_runs_servo_trace_and_motion_byte_for_byte() {
    let s = setup();
    let dir = s.root.join("show-run");
    let show = s.root.join("puppet.show");
    let o = run_into(
        &s.puppet,
        &s.wav,
        &dir,
        &["--no-video", "--show", show.to_str().unwrap()],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    assert!(
        stdout.contains("show ") && stdout.contains(" commands, "),
        "{stdout}"
    );
    for (name, audio) in [
        ("played-audio", Some(s.wav.as_path())),
        ("played-bare", None),
    ] {
        let out = s.root.join(name);
        let p = play_show(&s.puppet, &show, &out, audio);
        assert!(p.status.success(), "{}", text(&p.stderr));
        let said = text(&p.stdout);
        assert!(
            said.contains("no inference") && said.contains("wrote "),
            "{said}"
        );
        for f in ["servo.csv", "motion.bvh"] {
            let a = std::fs::read(dir.join(f)).unwrap();
            let b = std::fs::read(out.join(f)).unwrap();
            assert!(
                a == b,
                "{f} differs ({name}: {} against {} bytes)",
                b.len(),
                a.len()
            );
        }
    }
}

#[test]
fn bad_shows_and_other_blobs_are_refused_in_one_line() {
    let s = setup();
    let dir = s.root.join("show-run-2");
    let show = s.root.join("puppet-2.show");
    let o = run_into(
        &s.puppet,
        &s.wav,
        &dir,
        &["--no-video", "--show", show.to_str().unwrap()],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let garbage = s.root.join("garbage.show");
    std::fs::write(&garbage, [b"GSTB".as_slice(), &[0u8; 40]].concat()).unwrap();
    let out = s.root.join("refused-garbage");
    refused(
        &play_show(&s.puppet, &garbage, &out, None),
        &out,
        "garbage.show: not a show file",
    );
    let out = s.root.join("refused-other");
    refused(&play_show(&s.full, &show, &out, None), &out, "another blob");
    let mut damaged = std::fs::read(&show).unwrap();
    let n = damaged.len();
    damaged[n / 2] ^= 0x40;
    let bad = s.root.join("damaged.show");
    std::fs::write(&bad, &damaged).unwrap();
    let out = s.root.join("refused-damaged");
    refused(
        &play_show(&s.puppet, &bad, &out, None),
        &out,
        "CRC mismatch",
    );
    let out = s.root.join("refused-missing");
    refused(
        &play_show(&s.puppet, &s.root.join("none.show"), &out, None),
        &out,
        "cannot read the show",
    );
}
