//! The `gesture-sim` binary as a user runs it: output formats, exit codes, error lines.
//! Input WAVs are generated here; the shared real recordings are used only when present.

use std::f64::consts::PI;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_gesture-sim"))
}

fn run(args: &[&str]) -> Output {
    sim().args(args).output().expect("gesture-sim runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8(b.to_vec()).expect("utf-8 output")
}

/// A 150 Hz tone with 4 Hz amplitude modulation (syllable-like bursts with quiet gaps).
fn write_tone(path: &Path, seconds: f64, rate: u32, channels: u16) {
    let spec = hound::WavSpec {
        channels,
        sample_rate: rate,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut w = hound::WavWriter::create(path, spec).unwrap();
    for i in 0..(seconds * rate as f64) as usize {
        let t = i as f64 / rate as f64;
        let env = 0.5 - 0.5 * (2.0 * PI * 4.0 * t).cos();
        let v = (0.5 * env * (2.0 * PI * 150.0 * t).sin() * 32767.0) as i16;
        for _ in 0..channels {
            w.write_sample(v).unwrap();
        }
    }
    w.finalize().unwrap();
}

fn tone_file(dir: &Path, name: &str, rate: u32, channels: u16) -> PathBuf {
    let p = dir.join(name);
    write_tone(&p, 1.0, rate, channels);
    p
}

fn fields(line: &str) -> Vec<&str> {
    line.split(',').collect()
}

#[test]
fn frame_csv_format() {
    let dir = tempfile::tempdir().unwrap();
    for (name, rate, ch) in [("mono16k.wav", 16_000, 1), ("stereo44k.wav", 44_100, 2)] {
        let wav = tone_file(dir.path(), name, rate, ch);
        let out = run(&["prosody", wav.to_str().unwrap()]);
        assert!(out.status.success(), "{name}: {}", text(&out.stderr));
        assert!(out.stderr.is_empty());
        let stdout = text(&out.stdout);
        let mut lines = stdout.lines();
        assert_eq!(lines.next(), Some("time_s,f0_hz,intensity_db"));
        let mut prev_t: Option<f64> = None;
        let mut voiced = Vec::new();
        let mut rows = 0;
        for line in lines {
            rows += 1;
            let f = fields(line);
            assert_eq!(f.len(), 3, "{name}: row {line:?}");
            // Fixed decimals: 4 for time, 2 for the rest.
            assert_eq!(f[0].split('.').nth(1).map(str::len), Some(4), "{line:?}");
            let t: f64 = f[0].parse().unwrap();
            if let Some(p) = prev_t {
                assert!((t - p - 0.01).abs() < 1e-9, "{name}: time step {p} -> {t}");
            } else {
                assert_eq!(f[0], "0.0100");
            }
            prev_t = Some(t);
            if !f[1].is_empty() {
                assert_eq!(f[1].split('.').nth(1).map(str::len), Some(2), "{line:?}");
                let f0: f64 = f[1].parse().unwrap();
                assert!((75.0..=600.0).contains(&f0), "{name}: f0 {f0}");
                voiced.push(f0);
            }
            assert_eq!(f[2].split('.').nth(1).map(str::len), Some(2), "{line:?}");
            let db: f64 = f[2].parse().unwrap();
            assert!(db.is_finite());
        }
        assert_eq!(rows, 100, "{name}: one frame per 10 ms of a 1 s file");
        assert!(
            voiced.len() > 30,
            "{name}: only {} voiced frames",
            voiced.len()
        );
        voiced.sort_by(f64::total_cmp);
        let median = voiced[voiced.len() / 2];
        assert!((median - 150.0).abs() < 3.0, "{name}: median f0 {median}");
    }
}

#[test]
fn syllable_csv_format() {
    let dir = tempfile::tempdir().unwrap();
    let wav = tone_file(dir.path(), "tone.wav", 16_000, 1);
    let out = run(&["prosody", "--syllables", wav.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let mut lines = stdout.lines();
    assert_eq!(
        lines.next(),
        Some("start_s,end_s,f0_hz,intensity_db,length_s")
    );
    let mut prev_end = 0.0;
    let mut rows = 0;
    for line in lines {
        rows += 1;
        let f = fields(line);
        assert_eq!(f.len(), 5, "row {line:?}");
        let num = |s: &str| s.parse::<f64>().unwrap();
        let (start, end, len) = (num(f[0]), num(f[1]), num(f[4]));
        assert!(start < end, "{line}");
        assert!(start >= prev_end - 1e-9, "syllables overlap: {line}");
        assert!((len - (end - start)).abs() <= 0.0005, "{line}");
        if !f[2].is_empty() {
            assert!((75.0..=600.0).contains(&num(f[2])), "{line}");
        }
        assert!(num(f[3]).is_finite());
        prev_end = end;
    }
    // Four amplitude bursts in one second: the edge bursts may merge or be cut.
    assert!((2..=5).contains(&rows), "{rows} syllables");
}

fn assert_one_error_line(out: &Output, name: &str) {
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty(), "stdout: {}", text(&out.stdout));
    let err = text(&out.stderr);
    assert_eq!(err.lines().count(), 1, "stderr: {err:?}");
    assert!(err.starts_with("gesture-sim: "), "{err:?}");
    assert!(err.contains(name), "{err:?} does not name {name}");
}

#[test]
fn not_a_wav_file_is_one_error_line_and_status_2() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("notes.wav");
    std::fs::write(&p, "just some text, not audio\n").unwrap();
    let out = run(&["prosody", p.to_str().unwrap()]);
    assert_one_error_line(&out, "notes.wav");
    assert!(text(&out.stderr).contains("not a WAV file"));
}

#[test]
fn missing_file_is_status_2() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("absent.wav");
    let out = run(&["prosody", "--syllables", p.to_str().unwrap()]);
    assert_one_error_line(&out, "absent.wav");
    assert!(text(&out.stderr).contains("file not found"));
}

#[test]
fn bad_usage_is_status_2() {
    assert_eq!(run(&["prosody"]).status.code(), Some(2));
    assert_eq!(run(&["no-such-command"]).status.code(), Some(2));
    assert_eq!(
        run(&["bench-prosody", "--runs", "0"]).status.code(),
        Some(2)
    );
    assert_eq!(
        run(&["bench-prosody", "--seconds", "-1"]).status.code(),
        Some(2)
    );
}

#[test]
fn closed_stdout_does_not_panic() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("long.wav");
    write_tone(&p, 120.0, 16_000, 1); // ~240 kB of CSV, more than a pipe buffer
    let mut child = sim()
        .args(["prosody", p.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Read the first bytes, then hang up, like `| head -c 100`.
    let mut stdout = child.stdout.take().unwrap();
    let mut first = [0u8; 100];
    stdout.read_exact(&mut first).unwrap();
    drop(stdout);
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    let status = child.wait().unwrap();
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(status.code(), Some(0), "stderr: {err}");
}

/// A data folder given with `--data` that does not exist, or holds no referenced recording, is
/// one line naming it and exit 2 (it used to print "nothing was measured" and succeed); only
/// the default folder may be absent quietly, so that tests can skip.
#[test]
fn eval_with_a_missing_data_folder_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let absent = dir.path().join("no-data-here");
    for args in [
        vec!["eval-prosody", "--data", absent.to_str().unwrap()],
        vec!["eval-prosody", "--json", "--data", absent.to_str().unwrap()],
        vec!["eval-prosody", "--data", dir.path().to_str().unwrap()],
    ] {
        let out = run(&args);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(args.last().unwrap()), "{err}");
        assert!(out.stdout.is_empty());
    }
}

/// On the shared recordings (skipped when they are absent): the report covers every reference,
/// every metric is in range, and the agreement is far above chance.
#[test]
fn eval_on_shared_data_when_present() {
    let out = run(&["eval-prosody", "--json"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    if v["measured"] == false {
        e2e_tests::skip("eval_on_shared_data_when_present", &v["reason"].to_string());
        return;
    }
    let data = PathBuf::from(v["data"].as_str().unwrap());
    let references = std::fs::read_dir(data.join("reference/praat"))
        .unwrap()
        .count();
    let files = v["files"].as_array().unwrap();
    assert_eq!(files.len(), references, "one row per reference CSV");
    for f in files {
        for key in ["voicing", "gpe"] {
            let x = f[key].as_f64().unwrap();
            assert!((0.0..=1.0).contains(&x), "{key} {x} in {f}");
        }
        assert!(f["frames"].as_u64().unwrap() > 50, "{f}");
    }
    let pooled = &v["pooled"];
    assert!(pooled["voicing"].as_f64().unwrap() > 0.8, "{pooled}");
    assert!(pooled["gpe"].as_f64().unwrap() < 0.1, "{pooled}");
    assert!(pooled["int_r_nosil"].as_f64().unwrap() > 0.9, "{pooled}");
    let syl = &v["syllables"];
    assert_eq!(syl["files"].as_array().unwrap().len(), 6);
    assert!(syl["relative_error"].as_f64().unwrap().abs() < 0.3, "{syl}");
}

#[test]
fn bench_reports_timings() {
    let out = run(&["bench-prosody", "--seconds", "2", "--runs", "2"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let s = text(&out.stdout);
    assert!(
        s.contains("median") && s.contains("real-time x") && s.contains("ns/sample"),
        "{s}"
    );
}
