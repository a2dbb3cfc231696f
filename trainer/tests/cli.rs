//! The `gesture-train` binary: errors are one line on stderr with exit status 2.

use std::process::Command;

fn run(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_gesture-train"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn missing_input_is_one_line_and_status_2() {
    let out = run(&["corpus-stats", "/definitely/not/here"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("/definitely/not/here"), "{err}");
}

#[test]
fn synth_then_corpus_stats() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let out = run(&["synth", "--minutes", "0.5", "--seed", "4", "--out", d]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in ["take_000.wav", "take_000.bvh", "truth.json"] {
        assert!(dir.path().join(f).is_file(), "{f}");
    }
    let out = run(&["corpus-stats", "--json", d]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let take = &v["takes"][0];
    assert_eq!(take["frames"], 900);
    assert_eq!(
        take["effectors"],
        serde_json::json!(["LeftHand", "RightHand"])
    );
    assert!(take["segments"].as_u64().unwrap() > 5);
    assert!(take["syllables"].as_u64().unwrap() > 30);
    // The fitted normalization: six means and six positive scales.
    let scale = v["normalization"]["scale"].as_array().unwrap();
    assert_eq!(scale.len(), 6);
    assert!(scale.iter().all(|x| x.as_f64().unwrap() > 0.0));
    // Bad arguments are refused before anything is written.
    let out = run(&["synth", "--minutes", "-1", "--out", d]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn a_closed_stdout_pipe_ends_quietly() {
    use std::io::{BufRead, BufReader};
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    assert!(
        run(&["synth", "--minutes", "1", "--take-seconds", "5", "--out", d])
            .status
            .success()
    );
    let mut child = Command::new(env!("CARGO_BIN_EXE_gesture-train"))
        .args(["corpus-stats", d])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Read one line, then close our end like `| head -1` does.
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert!(first.starts_with("take_000"), "{first}");
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(out.status.code(), Some(0));
}

/// Numeric options are checked when the command line is parsed: NaN, infinities, negative or
/// out-of-range values are one line naming the flag, exit 2, before any input is read (`fit
/// --l2 nan` used to hang in the line search).
#[test]
fn bad_numbers_are_refused_at_parse_time_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("m.json");
    let out = out_path.to_str().unwrap();
    let cases: [(&[&str], &str); 12] = [
        (
            &["fit", "--corpus", "x", "--out", out, "--l2", "nan"],
            "--l2",
        ),
        (
            &["fit", "--corpus", "x", "--out", out, "--l2", "inf"],
            "--l2",
        ),
        (&["fit", "--corpus", "x", "--out", out, "--l2", "0"], "--l2"),
        (
            &["fit", "--corpus", "x", "--out", out, "--stickiness", "nan"],
            "--stickiness",
        ),
        (
            &["fit", "--corpus", "x", "--out", out, "--lag-penalty=-1"],
            "--lag-penalty",
        ),
        (
            &["fit", "--corpus", "x", "--out", out, "--states", "0"],
            "--states",
        ),
        (
            &["fit", "--corpus", "x", "--out", out, "--states", "33"],
            "--states",
        ),
        (
            &["fit", "--corpus", "x", "--out", out, "--window", "9"],
            "--window",
        ),
        (
            &[
                "fit",
                "--corpus",
                "x",
                "--out",
                out,
                "--max-mismatch",
                "NaN",
            ],
            "--max-mismatch",
        ),
        (
            &[
                "pack",
                "--model",
                "m",
                "--library",
                "l",
                "--out",
                out,
                "--usage-cost",
                "inf",
            ],
            "--usage-cost",
        ),
        (
            &[
                "pack",
                "--model",
                "m",
                "--library",
                "l",
                "--out",
                out,
                "--transition-weight",
                "nan",
            ],
            "--transition-weight",
        ),
        (&["synth", "--minutes", "nan", "--out", out], "--minutes"),
    ];
    for (args, flag) in cases {
        let o = run(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.starts_with("gesture-train: ") && err.contains(flag),
            "{args:?}: {err}"
        );
        assert!(!out_path.exists());
    }
    // --help still prints and succeeds.
    assert!(run(&["fit", "--help"]).status.success());
}

fn as_refs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

fn digest(p: &std::path::Path) -> Vec<u8> {
    std::fs::read(p).unwrap()
}

/// No output ever replaces an input: `fit --out` one of its own recordings, `pack --out` or
/// `--report` equal to the model, a library file or each other are one line, exit 2, and every
/// file is left as it was; an output gets the usual permissions and no temporary file stays.
#[test]
fn outputs_never_overwrite_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let corpus = d.join("c");
    let o = run(&[
        "synth",
        "--minutes",
        "0.2",
        "--take-seconds",
        "12",
        "--seed",
        "3",
        "--out",
    ]
    .iter()
    .copied()
    .chain([corpus.to_str().unwrap()])
    .collect::<Vec<_>>());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let wav = std::fs::read_dir(&corpus)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "wav"))
        .unwrap();
    let bvh = wav.with_extension("bvh");
    let (wav_before, bvh_before) = (digest(&wav), digest(&bvh));
    let c = corpus.to_str().unwrap();
    let refused = |args: &[&str], want: &str| {
        let o = run(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(want), "{args:?}: {err}");
    };
    let fit_args = |out: &str| -> Vec<String> {
        [
            "fit",
            "--corpus",
            c,
            "--states",
            "2",
            "--clusters",
            "2",
            "--l2",
            "0.01",
        ]
        .iter()
        .map(|s| s.to_string())
        .chain(["--lag-penalty", "1", "--restarts", "1", "--out", out].map(String::from))
        .collect()
    };
    let a = fit_args(wav.to_str().unwrap());
    refused(&as_refs(&a), "also an input");
    assert_eq!(digest(&wav), wav_before);
    // A working fit, then pack with bad outputs.
    let model = d.join("model.json");
    let a = fit_args(model.to_str().unwrap());
    let o = run(&as_refs(&a));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&model).unwrap().permissions().mode() & 0o777;
        assert_ne!(mode & 0o044, 0, "model.json is private: {mode:o}");
    }
    let model_before = digest(&model);
    let m = model.to_str().unwrap();
    let blob = d.join("x.blob");
    let b = blob.to_str().unwrap();
    for (args, want) in [
        (
            vec!["pack", "--model", m, "--library", c, "--out", m],
            "also an input",
        ),
        (
            vec![
                "pack",
                "--model",
                m,
                "--library",
                c,
                "--out",
                bvh.to_str().unwrap(),
            ],
            "also an input",
        ),
        (
            vec![
                "pack",
                "--model",
                m,
                "--library",
                c,
                "--out",
                b,
                "--report",
                m,
            ],
            "also an input",
        ),
        (
            vec![
                "pack",
                "--model",
                m,
                "--library",
                c,
                "--out",
                b,
                "--report",
                b,
            ],
            "same file",
        ),
    ] {
        refused(&args, want);
    }
    assert_eq!(digest(&model), model_before);
    assert_eq!(digest(&bvh), bvh_before);
    assert!(!blob.exists());
    // No temporary file anywhere.
    for e in std::fs::read_dir(d)
        .unwrap()
        .chain(std::fs::read_dir(&corpus).unwrap())
    {
        let n = e.unwrap().file_name().into_string().unwrap();
        assert!(
            !n.ends_with(".tmp") && !n.ends_with(".partial"),
            "leftover {n}"
        );
    }
}

/// `pack`'s tone options: every mistake is one line, exit 2, before anything is read or written.
#[test]
fn bad_style_options_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let clip = dir.path().join("a_active_1.bvh");
    std::fs::write(&clip, "not read: the options fail first").unwrap();
    let clip = clip.to_str().unwrap().to_string();
    let out = dir.path().join("x.blob");
    let nothing = format!("active={}/*_sad_*.bvh", dir.path().display());
    let active = format!("active={clip}");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["--style-neutral", &clip, "--style", &nothing],
            "matches no .bvh file",
        ),
        (
            vec!["--style-neutral", &clip, "--style", "neutral=x"],
            "cannot name a tone",
        ),
        (
            vec!["--style-neutral", &clip, "--style", "a b=x"],
            "cannot name a tone",
        ),
        (
            vec!["--style-neutral", &clip, "--style", "active"],
            "expected NAME=PATTERN",
        ),
        (vec!["--style", &active], "needs neutral motion"),
        (vec!["--style-neutral", &clip], "nothing to compare"),
        (
            vec![
                "--style-neutral",
                &clip,
                "--style",
                &active,
                "--style",
                &active,
            ],
            "given twice",
        ),
        (
            vec!["--style-neutral", "/no/such/dir", "--style", &active],
            "no such file",
        ),
        (vec!["--energy", "0.5"], "--energy"),
    ];
    for (extra, want) in cases {
        let mut args = vec![
            "pack",
            "--model",
            "/no/model.json",
            "--library",
            &clip,
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra.iter().copied());
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{extra:?}: {err}");
        assert!(err.contains(want), "{extra:?}: {want:?} not in {err}");
        assert!(!out.exists());
    }
}

/// `pack`'s label options: every mistake is one line, exit 2, nothing written.
#[test]
fn bad_label_options_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.blob");
    let file = dir.path().join("labels.csv");
    std::fs::write(&file, "pattern,label,stroke_s\n*_bye_*,bye,soon\n").unwrap();
    let file = file.to_str().unwrap().to_string();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--label", "bye"], "expected NAME=PATTERN"),
        (vec!["--label", "b y=*"], "cannot name a label"),
        (vec!["--label", "bye=[*"], "bad pattern"),
        (
            vec!["--label-file", &file],
            "labels.csv:2: `soon` is not a time",
        ),
        (vec!["--label-timeout-ms", "5"], "--label-timeout-ms"),
    ];
    for (extra, want) in cases {
        let mut args = vec![
            "pack",
            "--model",
            "/no/model.json",
            "--library",
            "/no/library",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra.iter().copied());
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{extra:?}: {err}");
        assert!(err.contains(want), "{extra:?}: {want:?} not in {err}");
        assert!(!out.exists());
    }
}
