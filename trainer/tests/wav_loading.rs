//! `trainer::audio` on real files: every supported encoding, channel count and rate is written
//! with hound (or by hand where hound cannot write it), loaded at 16 kHz, and checked for length,
//! amplitude, frequency and phase of a known sine; broken and unsupported files must give the
//! right typed error naming the file.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use gesture_trainer::audio::{load_wav, AudioError, Encoding};
use hound::{SampleFormat, WavSpec, WavSpecEx, WavWriter};

const FREQ: f64 = 220.0;
const AMP: f64 = 0.5;
const TARGET: u32 = 16_000;

/// How a test file stores its samples.
#[derive(Clone, Copy, Debug)]
enum Store {
    Int { bits: u16, bytes: u16 },
    Float,
}

fn sine(t: f64) -> f64 {
    AMP * (2.0 * PI * FREQ * t).sin()
}

/// Writes `seconds` of the test sine. Stereo files carry 1.6x the sine on the left and 0.4x on
/// the right, so only a true average gives the expected amplitude back.
fn write_sine(path: &Path, store: Store, channels: u16, rate: u32, seconds: f64) {
    let (bits, bytes, fmt) = match store {
        Store::Int { bits, bytes } => (bits, bytes, SampleFormat::Int),
        Store::Float => (32, 4, SampleFormat::Float),
    };
    let spec = WavSpecEx {
        spec: WavSpec {
            channels,
            sample_rate: rate,
            bits_per_sample: bits,
            sample_format: fmt,
        },
        bytes_per_sample: bytes,
    };
    let mut w = WavWriter::new_with_spec_ex(
        std::io::BufWriter::new(std::fs::File::create(path).unwrap()),
        spec,
    )
    .unwrap();
    let gains: &[f64] = if channels == 1 { &[1.0] } else { &[1.6, 0.4] };
    let n = (seconds * rate as f64).round() as usize;
    for i in 0..n {
        let x = sine(i as f64 / rate as f64);
        for g in gains {
            let v = x * g;
            match store {
                Store::Float => w.write_sample(v as f32).unwrap(),
                Store::Int { bits, .. } => {
                    let full = (1i64 << (bits - 1)) as f64;
                    let q = (v * full).round().clamp(-full, full - 1.0) as i32;
                    w.write_sample(q).unwrap();
                }
            }
        }
    }
    w.finalize().unwrap();
}

/// Amplitude, phase (rad) of the FREQ component of `y` (full scale 1) over samples
/// `[from, to)` at TARGET Hz, by projection onto sin and cos.
fn sine_fit(y: &[i16], from: usize, to: usize) -> (f64, f64) {
    let (mut s, mut c) = (0.0, 0.0);
    for (i, &v) in y.iter().enumerate().take(to).skip(from) {
        let ph = 2.0 * PI * FREQ * i as f64 / TARGET as f64;
        let v = v as f64 / 32768.0;
        s += v * ph.sin();
        c += v * ph.cos();
    }
    let n = (to - from) as f64;
    let (s, c) = (2.0 * s / n, 2.0 * c / n);
    ((s * s + c * c).sqrt(), c.atan2(s))
}

/// Frequency from linearly interpolated rising zero crossings over `[from, to)`.
fn crossing_freq(y: &[i16], from: usize, to: usize) -> f64 {
    let mut times = Vec::new();
    for i in from + 1..to {
        let (a, b) = (y[i - 1] as f64, y[i] as f64);
        if a < 0.0 && b >= 0.0 {
            times.push(i as f64 - 1.0 + a / (a - b));
        }
    }
    assert!(times.len() > 10, "too few crossings");
    (times.len() - 1) as f64 * TARGET as f64 / (times[times.len() - 1] - times[0])
}

#[test]
fn every_supported_format_channel_count_and_rate_loads_the_same_sine() {
    let dir = tempfile::tempdir().unwrap();
    let stores = [
        Store::Int { bits: 8, bytes: 1 },
        Store::Int { bits: 16, bytes: 2 },
        Store::Int { bits: 24, bytes: 3 },
        Store::Int { bits: 24, bytes: 4 },
        Store::Int { bits: 32, bytes: 4 },
        Store::Float,
    ];
    let seconds = 0.5;
    for store in stores {
        for channels in [1u16, 2] {
            for rate in [8_000u32, 16_000, 22_050, 44_100, 48_000] {
                let name = format!("{store:?}-{channels}ch-{rate}.wav")
                    .replace([' ', '{', '}', ',', ':'], "");
                let path = dir.path().join(name);
                write_sine(&path, store, channels, rate, seconds);
                let pcm = load_wav(&path).unwrap_or_else(|e| panic!("{e}"));
                let what = format!("{store:?} {channels} ch {rate} Hz");
                assert_eq!(pcm.rate_hz, TARGET);
                assert_eq!(pcm.source.rate_hz, rate);
                assert_eq!(pcm.source.channels, channels);
                let frames = (seconds * rate as f64).round() as usize;
                let want_len = (frames as f64 * TARGET as f64 / rate as f64).round() as usize;
                assert_eq!(pcm.samples.len(), want_len, "{what}");
                // Away from the edges (the resampler rings there).
                let (from, to) = (800, want_len - 800);
                let (amp, phase) = sine_fit(&pcm.samples, from, to);
                assert!((amp / AMP - 1.0).abs() < 0.01, "{what}: amplitude {amp}");
                // One output sample at 16 kHz is 0.086 rad of a 220 Hz sine.
                assert!(phase.abs() < 0.05, "{what}: phase {phase} rad");
                let f = crossing_freq(&pcm.samples, from, to);
                assert!((f / FREQ - 1.0).abs() < 0.002, "{what}: {f} Hz");
            }
        }
    }
}

#[test]
fn sixteen_bit_at_the_target_rate_is_bit_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("exact.wav");
    let spec = WavSpec {
        channels: 1,
        sample_rate: TARGET,
        bits_per_sample: 16,
        sample_format: SampleFormat::Int,
    };
    let x: Vec<i16> = (0..4000)
        .map(|i| ((i * 7919) % 65536 - 32768) as i16)
        .collect();
    let mut w = WavWriter::create(&path, spec).unwrap();
    for &v in &x {
        w.write_sample(v).unwrap();
    }
    w.finalize().unwrap();
    assert_eq!(load_wav(&path).unwrap().samples, x);
}

/// A RIFF/WAVE file with a plain 16-byte `fmt ` chunk, built by hand (hound cannot write
/// 12-bit, 64-bit float or compressed files, and writes float only as WAVE_FORMAT_EXTENSIBLE).
fn hand_made_wav(tag: u16, channels: u16, rate: u32, bits: u16, data: &[u8]) -> Vec<u8> {
    let block = channels * bits.div_ceil(8);
    let mut b = Vec::new();
    b.extend_from_slice(b"RIFF");
    b.extend_from_slice(&(4 + 24 + 8 + data.len() as u32).to_le_bytes());
    b.extend_from_slice(b"WAVEfmt ");
    b.extend_from_slice(&16u32.to_le_bytes());
    b.extend_from_slice(&tag.to_le_bytes());
    b.extend_from_slice(&channels.to_le_bytes());
    b.extend_from_slice(&rate.to_le_bytes());
    b.extend_from_slice(&(rate * block as u32).to_le_bytes());
    b.extend_from_slice(&block.to_le_bytes());
    b.extend_from_slice(&bits.to_le_bytes());
    b.extend_from_slice(b"data");
    b.extend_from_slice(&(data.len() as u32).to_le_bytes());
    b.extend_from_slice(data);
    b
}

fn write_bytes(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// The test sine at `rate` as little-endian f32 bytes, with NaN, +inf and -inf at `bad`.
fn float_sine_bytes(rate: u32, n: usize, bad: [usize; 3]) -> (Vec<f32>, Vec<u8>) {
    let mut x: Vec<f32> = (0..n)
        .map(|i| sine(i as f64 / rate as f64) as f32)
        .collect();
    for (i, v) in bad
        .into_iter()
        .zip([f32::NAN, f32::INFINITY, f32::NEG_INFINITY])
    {
        x[i] = v;
    }
    let bytes = x.iter().flat_map(|v| v.to_le_bytes()).collect();
    (x, bytes)
}

#[test]
fn plain_ieee_float_header_and_non_finite_samples() {
    let dir = tempfile::tempdir().unwrap();

    // At the target rate: the bad samples become exactly 0, the rest is the sine.
    let (x, data) = float_sine_bytes(TARGET, 8000, [1000, 2000, 3000]);
    let p = write_bytes(
        dir.path(),
        "float16k.wav",
        &hand_made_wav(3, 1, TARGET, 32, &data),
    );
    let pcm = load_wav(&p).unwrap();
    assert_eq!(pcm.source.encoding, Encoding::Float(32));
    assert_eq!(pcm.samples.len(), 8000);
    for i in [1000, 2000, 3000] {
        assert_eq!(pcm.samples[i], 0, "sample {i}");
    }
    assert_eq!(pcm.samples[1001], (x[1001] * 32768.0).round() as i16);

    // Resampled from 48 kHz: the bad samples act as zeros, not as a NaN smear; elsewhere the
    // sine is intact, and next to them it is off by at most a fraction of one sample's value.
    let (_, data) = float_sine_bytes(48_000, 24_000, [3000, 6000, 9000]);
    let p = write_bytes(
        dir.path(),
        "float48k.wav",
        &hand_made_wav(3, 1, 48_000, 32, &data),
    );
    let pcm = load_wav(&p).unwrap();
    assert_eq!(pcm.samples.len(), 8000);
    let (amp, phase) = sine_fit(&pcm.samples, 3500, 7500);
    assert!((amp / AMP - 1.0).abs() < 0.01, "amplitude {amp}");
    assert!(phase.abs() < 0.05, "phase {phase}");
    for k in (980..1020).chain(1980..2020).chain(2980..3020) {
        let want = sine(k as f64 / TARGET as f64);
        let got = pcm.samples[k] as f64 / 32768.0;
        assert!((got - want).abs() < 0.25, "sample {k}: {got} vs {want}");
    }
}

fn expect_err(path: &Path) -> AudioError {
    let e = load_wav(path).expect_err("loading should fail");
    let msg = e.to_string();
    let name = path.file_name().unwrap().to_str().unwrap();
    assert!(msg.contains(name), "message {msg:?} does not name {name}");
    assert!(!msg.contains('\n'), "message {msg:?} is not one line");
    assert_eq!(e.path(), path);
    e
}

#[test]
fn missing_file() {
    let dir = tempfile::tempdir().unwrap();
    let e = expect_err(&dir.path().join("nope.wav"));
    assert!(matches!(e, AudioError::NotFound { .. }), "{e:?}");
    assert!(e.to_string().ends_with("nope.wav: file not found"), "{e}");
}

#[test]
fn garbage_and_truncated_files() {
    let dir = tempfile::tempdir().unwrap();
    let p = write_bytes(
        dir.path(),
        "garbage.wav",
        b"this is not audio at all, just text\n",
    );
    let e = expect_err(&p);
    assert!(
        matches!(
            e,
            AudioError::NotWav {
                missing: "RIFF",
                ..
            }
        ),
        "{e:?}"
    );
    assert!(
        e.to_string().contains("not a WAV file (no RIFF header)"),
        "{e}"
    );

    let p = write_bytes(dir.path(), "empty.wav", b"");
    assert!(matches!(expect_err(&p), AudioError::NotWav { .. }));

    let p = write_bytes(
        dir.path(),
        "riff-avi.wav",
        b"RIFF\x10\0\0\0AVI LIST\0\0\0\0",
    );
    let e = expect_err(&p);
    assert!(
        matches!(
            e,
            AudioError::NotWav {
                missing: "WAVE",
                ..
            }
        ),
        "{e:?}"
    );

    let good = hand_made_wav(1, 1, TARGET, 16, &[0u8; 3200]);
    for cut in [14, 20, 30, 40] {
        let p = write_bytes(dir.path(), &format!("header-cut-{cut}.wav"), &good[..cut]);
        let e = expect_err(&p);
        assert!(
            matches!(e, AudioError::Truncated { .. }),
            "cut at {cut}: {e:?}"
        );
    }
    // A damaged length field promising ~2 G frames: an error, not a huge allocation.
    let mut huge = good.clone();
    huge[40..44].copy_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
    let p = write_bytes(dir.path(), "huge-length.wav", &huge);
    assert!(matches!(expect_err(&p), AudioError::Truncated { .. }));
    // Data chunk promises 1600 frames, the file holds 1000.
    let p = write_bytes(dir.path(), "data-cut.wav", &good[..44 + 2000]);
    let e = expect_err(&p);
    assert!(matches!(e, AudioError::Truncated { .. }), "{e:?}");
    assert!(
        e.to_string().contains("1600") && e.to_string().contains("1000"),
        "{e}"
    );
}

#[test]
fn unsupported_rates() {
    let dir = tempfile::tempdir().unwrap();
    for rate in [96_000u32, 4_000, 0] {
        let p = write_bytes(
            dir.path(),
            &format!("rate-{rate}.wav"),
            &hand_made_wav(1, 1, rate, 16, &[0u8; 200]),
        );
        let e = expect_err(&p);
        match e {
            AudioError::UnsupportedRate { rate_hz, .. } => assert_eq!(rate_hz, rate),
            other => panic!("{rate} Hz: {other:?}"),
        }
        assert!(
            e.to_string()
                .contains(&format!("sample rate {rate} Hz outside 8000-48000 Hz")),
            "{e}"
        );
    }
}

#[test]
fn unsupported_sample_formats() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, u16, u16, Encoding, &str); 3] = [
        (
            "12bit.wav",
            1,
            12,
            Encoding::Int(12),
            "unsupported sample format: 12-bit integer",
        ),
        (
            "f64.wav",
            3,
            64,
            Encoding::Float(64),
            "unsupported sample format: 64-bit float",
        ),
        (
            "adpcm.wav",
            2,
            4,
            Encoding::Other(2),
            "unsupported sample format: ADPCM",
        ),
    ];
    for (name, tag, bits, enc, text) in cases {
        let p = write_bytes(
            dir.path(),
            name,
            &hand_made_wav(tag, 1, TARGET, bits, &[0u8; 64]),
        );
        let e = expect_err(&p);
        match &e {
            AudioError::UnsupportedFormat { encoding, .. } => assert_eq!(*encoding, enc, "{name}"),
            other => panic!("{name}: {other:?}"),
        }
        assert!(e.to_string().contains(text), "{e}");
    }
}

/// A file with more than two channels, or with no samples at all, is refused in one line
/// naming the file (both used to load silently: six channels averaged, or an empty signal).
#[test]
fn six_channels_and_empty_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let spec = WavSpec {
        channels: 6,
        sample_rate: 16_000,
        bits_per_sample: 16,
        sample_format: SampleFormat::Int,
    };
    let six = dir.path().join("surround.wav");
    let mut w = WavWriter::create(&six, spec).unwrap();
    for _ in 0..6 * 1600 {
        w.write_sample(100i16).unwrap();
    }
    w.finalize().unwrap();
    let e = load_wav(&six).unwrap_err();
    assert!(
        matches!(e, AudioError::UnsupportedChannels { channels: 6, .. }),
        "{e}"
    );
    assert!(e
        .to_string()
        .starts_with(&format!("{}: 6 channels", six.display())));
    let empty = dir.path().join("empty.wav");
    let w = WavWriter::create(
        &empty,
        WavSpec {
            channels: 1,
            ..spec
        },
    )
    .unwrap();
    w.finalize().unwrap();
    let e = load_wav(&empty).unwrap_err();
    assert!(matches!(e, AudioError::Empty { .. }), "{e}");
    assert_eq!(e.to_string().lines().count(), 1);
}
