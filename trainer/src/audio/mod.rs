//! WAV files in, front-end PCM out: the one gate between users' audio and the prosody front-end.
//!
//! [`load_wav`] reads any common WAV file and returns mono `i16` samples at the front-end rate;
//! [`convert`] does the same for samples already in memory (`f32` mono at some rate).
//!
//! **Accepted input.** 8 to 48 kHz; mono or stereo (stereo mixed to mono by averaging, so a
//! stereo file with the same signal on both sides loads as that signal; more channels are
//! refused rather than guessed at, and so is a file without samples); integer PCM of 8, 16,
//! 24 (3- or 4-byte containers) or 32 bits, or 32-bit IEEE float; plain `WAVE_FORMAT_PCM` /
//! `WAVE_FORMAT_IEEE_FLOAT` headers or `WAVE_FORMAT_EXTENSIBLE`. Everything else is refused with
//! an [`AudioError`] whose `Display` is one line, `<file>: <reason>`.
//!
//! **Conversion.** Integer samples are scaled by `2^-(bits-1)` to [-1, 1). Float samples are
//! taken as they are, except that NaN and ±infinity become 0 *before* resampling (a single NaN
//! would otherwise smear over the whole resampling filter). When the file rate differs from the
//! target, the signal is resampled with rubato 5.0.1 (the current release when this was written;
//! its `process_all` trims the start-up delay correctly, 4.x did not) using the asynchronous sinc
//! resampler: 256-tap Blackman-Harris² windowed sinc, automatic anti-aliasing cutoff just below
//! the lower Nyquist frequency. When the rates match, nothing is resampled and 16-bit input
//! comes out bit for bit. Finally samples are scaled by 32768, rounded to nearest and clamped
//! to the `i16` range (float input beyond ±1 clips).
//!
//! **Invariants of the output** (tested):
//! - length = `round(frames * target / rate)`;
//! - timing is preserved: the resampler's start-up delay is trimmed, so an event at time `t` in
//!   the file appears at time `t` in the output within one output sample;
//! - no input makes this module panic; every failure is a typed error.
//!
//! Why some of this is hand-written: hound decodes the samples, but its header errors are
//! static strings that do not say *which* sample format was refused, so on that error path
//! `describe_fmt` re-reads the `fmt ` chunk only to name the format in the message. The whole
//! file is read into memory first (WAV files we handle are at most tens of MB), which also makes
//! every I/O error after opening mean "the file ends early".

use std::fmt;
use std::io::{self, Cursor};
use std::path::{Path, PathBuf};

use hound::{SampleFormat, WavReader};

mod resample;

use resample::resample;
pub use resample::{converted_len, ConvertError, StreamResampler, MAX_RATE_HZ, MIN_RATE_HZ};

/// Most channels a loaded file may have (stereo).
pub const MAX_CHANNELS: usize = 2;

/// The default target rate: the front-end's default rate.
pub const DEFAULT_TARGET_RATE_HZ: u32 = gesture_runtime::prosody::DEFAULT_RATE_HZ;

/// How samples are stored in a WAV file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// Integer PCM with this many significant bits.
    Int(u16),
    /// IEEE float with this many bits.
    Float(u16),
    /// Some other `wFormatTag` (compressed or vendor-specific).
    Other(u16),
}

impl fmt::Display for Encoding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Int(bits) => write!(f, "{bits}-bit integer"),
            Self::Float(bits) => write!(f, "{bits}-bit float"),
            Self::Other(0x0002) => f.write_str("ADPCM (format tag 0x0002)"),
            Self::Other(0x0006) => f.write_str("A-law (format tag 0x0006)"),
            Self::Other(0x0007) => f.write_str("mu-law (format tag 0x0007)"),
            Self::Other(0x0055) => f.write_str("MP3 (format tag 0x0055)"),
            Self::Other(tag) => write!(f, "format tag 0x{tag:04x}"),
        }
    }
}

/// What a WAV file contained (before conversion).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SourceFormat {
    /// Sample rate in Hz.
    pub rate_hz: u32,
    /// Channel count.
    pub channels: u16,
    /// Sample encoding.
    pub encoding: Encoding,
    /// Sample frames (samples per channel).
    pub frames: u64,
}

/// Mono PCM at the front-end rate, and where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Pcm {
    /// Mono samples.
    pub samples: Vec<i16>,
    /// Their rate in Hz.
    pub rate_hz: u32,
    /// The file's own format.
    pub source: SourceFormat,
}

impl Pcm {
    /// Duration in seconds.
    pub fn duration_s(&self) -> f64 {
        self.samples.len() as f64 / self.rate_hz as f64
    }
}

/// Why a WAV file could not be loaded. `Display` is one line: `<file>: <reason>`.
#[derive(Debug, thiserror::Error)]
pub enum AudioError {
    /// There is no file at this path.
    #[error("{}: file not found", path.display())]
    NotFound {
        /// The file.
        path: PathBuf,
    },
    /// The file exists but could not be read (permissions, a directory, ...).
    #[error("{}: cannot read: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: io::Error,
    },
    /// The file does not start with a RIFF/WAVE header.
    #[error("{}: not a WAV file (no {missing} header)", path.display())]
    NotWav {
        /// The file.
        path: PathBuf,
        /// `"RIFF"` or `"WAVE"`.
        missing: &'static str,
    },
    /// The file ends inside its header or its sample data.
    #[error("{}: truncated WAV file ({detail})", path.display())]
    Truncated {
        /// The file.
        path: PathBuf,
        /// Where it ends.
        detail: String,
    },
    /// The header is inconsistent.
    #[error("{}: malformed WAV header: {reason}", path.display())]
    Malformed {
        /// The file.
        path: PathBuf,
        /// hound's diagnosis.
        reason: &'static str,
    },
    /// The samples are stored in a way this loader does not decode.
    #[error(
        "{}: unsupported sample format: {encoding} (use 8/16/24/32-bit integer or 32-bit float PCM)",
        path.display()
    )]
    UnsupportedFormat {
        /// The file.
        path: PathBuf,
        /// What it holds.
        encoding: Encoding,
    },
    /// The file's sample rate is outside [`MIN_RATE_HZ`]..=[`MAX_RATE_HZ`].
    #[error("{}: sample rate {rate_hz} Hz outside {MIN_RATE_HZ}-{MAX_RATE_HZ} Hz", path.display())]
    UnsupportedRate {
        /// The file.
        path: PathBuf,
        /// Its rate.
        rate_hz: u32,
    },
    /// More channels than a speech recording has.
    #[error(
        "{}: {channels} channels: give a mono or stereo recording (e.g. `ffmpeg -i in.wav -ac 1 out.wav`)",
        path.display()
    )]
    UnsupportedChannels {
        /// The file.
        path: PathBuf,
        /// Its channel count.
        channels: u16,
    },
    /// The file holds no audio at all.
    #[error("{}: no audio samples (the data chunk is empty)", path.display())]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// Conversion to the target rate failed.
    #[error("{}: {source}", path.display())]
    Convert {
        /// The file.
        path: PathBuf,
        /// Why.
        source: ConvertError,
    },
}

impl AudioError {
    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            Self::NotFound { path }
            | Self::Io { path, .. }
            | Self::NotWav { path, .. }
            | Self::Truncated { path, .. }
            | Self::Malformed { path, .. }
            | Self::UnsupportedFormat { path, .. }
            | Self::UnsupportedRate { path, .. }
            | Self::UnsupportedChannels { path, .. }
            | Self::Empty { path }
            | Self::Convert { path, .. } => path,
        }
    }
}

/// Loads a WAV file as mono `i16` at [`DEFAULT_TARGET_RATE_HZ`] (16 kHz).
pub fn load_wav(path: impl AsRef<Path>) -> Result<Pcm, AudioError> {
    load_wav_at(path, DEFAULT_TARGET_RATE_HZ)
}

/// Loads a WAV file as mono `i16` at `target_rate_hz` (see the module docs for what is accepted
/// and how samples are converted).
pub fn load_wav_at(path: impl AsRef<Path>, target_rate_hz: u32) -> Result<Pcm, AudioError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| match e.kind() {
        io::ErrorKind::NotFound => AudioError::NotFound {
            path: path.to_owned(),
        },
        _ => AudioError::Io {
            path: path.to_owned(),
            source: e,
        },
    })?;
    decode_wav(&bytes, path, target_rate_hz)
}

/// Decodes WAV bytes held in memory; `path` only names the source in errors.
pub fn decode_wav(bytes: &[u8], path: &Path, target_rate_hz: u32) -> Result<Pcm, AudioError> {
    let (mono, source) = decode_mono(bytes, path)?;
    let samples =
        convert(&mono, source.rate_hz, target_rate_hz).map_err(|source| AudioError::Convert {
            path: path.to_owned(),
            source,
        })?;
    Ok(Pcm {
        samples,
        rate_hz: target_rate_hz,
        source,
    })
}

/// Converts mono `f32` samples (full scale ±1) at `rate_hz` to `i16` at `target_rate_hz`:
/// non-finite samples become 0, the signal is resampled when the rates differ (length
/// `round(len * target / rate)`, timing preserved), then scaled by 32768, rounded and clamped.
pub fn convert(
    samples: &[f32],
    rate_hz: u32,
    target_rate_hz: u32,
) -> Result<Vec<i16>, ConvertError> {
    for r in [rate_hz, target_rate_hz] {
        if !(MIN_RATE_HZ..=MAX_RATE_HZ).contains(&r) {
            return Err(ConvertError::UnsupportedRate(r));
        }
    }
    if rate_hz == target_rate_hz {
        return Ok(samples.iter().map(|&x| to_i16(x)).collect());
    }
    let clean: Vec<f32> = samples.iter().map(|&x| finite_or_zero(x)).collect();
    let resampled = resample(&clean, rate_hz, target_rate_hz)?;
    Ok(resampled.iter().map(|&x| to_i16(x)).collect())
}

fn finite_or_zero(x: f32) -> f32 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

/// Full scale ±1 to `i16`: round to nearest, clamp, non-finite to 0 (the one conversion of
/// every audio path: WAV files and the live microphone).
pub fn to_i16(x: f32) -> i16 {
    if !x.is_finite() {
        return 0;
    }
    (x * 32768.0).round().clamp(-32768.0, 32767.0) as i16
}

/// Reads the header with hound, validates rate and format, and mixes the samples to mono `f32`.
fn decode_mono(bytes: &[u8], path: &Path) -> Result<(Vec<f32>, SourceFormat), AudioError> {
    let reader = WavReader::new(Cursor::new(bytes)).map_err(|e| header_error(e, bytes, path))?;
    let spec = reader.spec();
    let encoding = match spec.sample_format {
        SampleFormat::Int => Encoding::Int(spec.bits_per_sample),
        SampleFormat::Float => Encoding::Float(spec.bits_per_sample),
    };
    let supported = matches!(
        encoding,
        Encoding::Int(8 | 16 | 24 | 32) | Encoding::Float(32)
    );
    if !supported {
        return Err(AudioError::UnsupportedFormat {
            path: path.to_owned(),
            encoding,
        });
    }
    if !(MIN_RATE_HZ..=MAX_RATE_HZ).contains(&spec.sample_rate) {
        return Err(AudioError::UnsupportedRate {
            path: path.to_owned(),
            rate_hz: spec.sample_rate,
        });
    }
    let channels = spec.channels as usize; // hound refuses 0 channels
    if channels > MAX_CHANNELS {
        return Err(AudioError::UnsupportedChannels {
            path: path.to_owned(),
            channels: spec.channels,
        });
    }
    let frames = reader.duration() as usize;
    if frames == 0 {
        return Err(AudioError::Empty {
            path: path.to_owned(),
        });
    }
    let source = SourceFormat {
        rate_hz: spec.sample_rate,
        channels: spec.channels,
        encoding,
        frames: frames as u64,
    };
    let truncated = |read: usize| AudioError::Truncated {
        path: path.to_owned(),
        detail: format!(
            "the data chunk promises {frames} sample frames but the file ends after {}",
            read / channels
        ),
    };
    // The header's promise is capped by what the bytes can hold: a damaged length field must
    // not turn into a multi-gigabyte allocation.
    let max_samples = bytes.len() / (spec.bits_per_sample as usize / 8).max(1);
    let mut interleaved = Vec::with_capacity((frames * channels).min(max_samples));
    match encoding {
        Encoding::Float(_) => {
            for s in reader.into_samples::<f32>() {
                let s = s.map_err(|_| truncated(interleaved.len()))?;
                interleaved.push(finite_or_zero(s));
            }
        }
        _ => {
            let scale = 1.0 / (1u64 << (spec.bits_per_sample - 1)) as f64;
            for s in reader.into_samples::<i32>() {
                let s = s.map_err(|_| truncated(interleaved.len()))?;
                interleaved.push((s as f64 * scale) as f32);
            }
        }
    }
    let mono = if channels == 1 {
        interleaved
    } else {
        let inv = 1.0 / channels as f32;
        interleaved
            .chunks_exact(channels)
            .map(|frame| frame.iter().sum::<f32>() * inv)
            .collect()
    };
    Ok((mono, source))
}

/// Turns hound's header error into a typed, named one.
fn header_error(e: hound::Error, bytes: &[u8], path: &Path) -> AudioError {
    let path = path.to_owned();
    match e {
        hound::Error::FormatError("no RIFF tag found") => AudioError::NotWav {
            path,
            missing: "RIFF",
        },
        hound::Error::FormatError("no WAVE tag found") => AudioError::NotWav {
            path,
            missing: "WAVE",
        },
        // The bytes are in memory, so any read error means they ran out.
        hound::Error::IoError(_) if bytes.len() < 12 || &bytes[..4] != b"RIFF" => {
            AudioError::NotWav {
                path,
                missing: "RIFF",
            }
        }
        hound::Error::IoError(_) => AudioError::Truncated {
            path,
            detail: "the file ends inside its header".into(),
        },
        hound::Error::FormatError(reason) => match describe_fmt(bytes) {
            Some(encoding) if !matches!(encoding, Encoding::Int(8 | 16 | 24 | 32)) => {
                AudioError::UnsupportedFormat { path, encoding }
            }
            _ => AudioError::Malformed { path, reason },
        },
        hound::Error::Unsupported | hound::Error::TooWide | hound::Error::InvalidSampleFormat => {
            match describe_fmt(bytes) {
                Some(encoding) => AudioError::UnsupportedFormat { path, encoding },
                None => AudioError::Malformed {
                    path,
                    reason: "unsupported fmt chunk",
                },
            }
        }
        hound::Error::UnfinishedSample => AudioError::Malformed {
            path,
            reason: "unfinished sample",
        },
    }
}

/// Reads the sample encoding from the `fmt ` chunk, only to name it in an error message.
/// `None` when there is no readable `fmt ` chunk.
fn describe_fmt(bytes: &[u8]) -> Option<Encoding> {
    const PCM: u16 = 0x0001;
    const IEEE_FLOAT: u16 = 0x0003;
    const EXTENSIBLE: u16 = 0xfffe;
    let u16_at = |b: &[u8], i: usize| Some(u16::from_le_bytes(b.get(i..i + 2)?.try_into().ok()?));
    let u32_at = |b: &[u8], i: usize| Some(u32::from_le_bytes(b.get(i..i + 4)?.try_into().ok()?));
    let mut pos = 12usize;
    loop {
        let id = bytes.get(pos..pos + 4)?;
        let len = u32_at(bytes, pos + 4)? as usize;
        let body = pos + 8;
        if id == b"fmt " {
            let fmt = bytes.get(body..body.checked_add(len)?.min(bytes.len()))?;
            let tag = u16_at(fmt, 0)?;
            let bits = u16_at(fmt, 14)?;
            let (tag, bits) = if tag == EXTENSIBLE {
                let valid = u16_at(fmt, 18).filter(|&v| v > 0).unwrap_or(bits);
                // The sub-format GUID starts with the classic format tag.
                (u16_at(fmt, 24)?, valid)
            } else {
                (tag, bits)
            };
            return Some(match tag {
                PCM => Encoding::Int(bits),
                IEEE_FLOAT => Encoding::Float(bits),
                other => Encoding::Other(other),
            });
        }
        // Chunks are padded to an even length.
        pos = body.checked_add(len)?.checked_add(len & 1)?;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn to_i16_rounds_clamps_and_zeroes_non_finite() {
        assert_eq!(to_i16(0.0), 0);
        assert_eq!(to_i16(1.0), 32767);
        assert_eq!(to_i16(-1.0), -32768);
        assert_eq!(to_i16(2.5), 32767);
        assert_eq!(to_i16(-7.0), -32768);
        assert_eq!(to_i16(0.4 / 32768.0), 0);
        assert_eq!(to_i16(0.6 / 32768.0), 1);
        assert_eq!(to_i16(-0.6 / 32768.0), -1);
        assert_eq!(to_i16(f32::NAN), 0);
        assert_eq!(to_i16(f32::INFINITY), 0);
        assert_eq!(to_i16(f32::NEG_INFINITY), 0);
    }

    #[test]
    fn converted_len_rounds() {
        assert_eq!(converted_len(44_100, 44_100, 16_000), 16_000);
        assert_eq!(converted_len(1, 48_000, 16_000), 0); // 1/3 rounds down
        assert_eq!(converted_len(2, 48_000, 16_000), 1); // 2/3 rounds up
        assert_eq!(converted_len(3, 8_000, 16_000), 6);
        assert_eq!(converted_len(22_051, 22_050, 16_000), 16_001);
    }

    #[test]
    fn same_rate_is_exact() {
        let x: Vec<f32> = (-5..5).map(|v| v as f32 * 1000.0 / 32768.0).collect();
        let y = convert(&x, 16_000, 16_000).unwrap();
        assert_eq!(y, (-5..5).map(|v| v * 1000).collect::<Vec<i16>>());
    }

    #[test]
    fn refuses_rates_out_of_range() {
        assert_eq!(
            convert(&[0.0], 96_000, 16_000),
            Err(ConvertError::UnsupportedRate(96_000))
        );
        assert_eq!(
            convert(&[0.0], 16_000, 4_000),
            Err(ConvertError::UnsupportedRate(4_000))
        );
    }

    #[test]
    fn empty_and_tiny_inputs() {
        for rate in [8_000, 22_050, 44_100, 48_000] {
            assert!(convert(&[], rate, 16_000).unwrap().is_empty());
            let one = convert(&[0.5], rate, 16_000).unwrap();
            assert_eq!(one.len(), converted_len(1, rate, 16_000));
        }
    }

    /// An impulse at input sample n must peak at output position n * ratio: within half an
    /// output frame plus the peak estimate's own error (the contract is one frame).
    #[test]
    fn resampling_preserves_timing() {
        for from in [
            8_000u32, 11_025, 12_000, 22_050, 24_000, 32_000, 44_100, 48_000,
        ] {
            for to in [8_000u32, 16_000] {
                if from == to {
                    continue;
                }
                let n_in = from as usize; // 1 s
                for &at in &[0.1f64, 0.5, 0.873] {
                    let mut x = vec![0.0f32; n_in];
                    let idx = (at * from as f64).round() as usize;
                    x[idx] = 0.5;
                    let y = resample(&x, from, to).unwrap();
                    assert_eq!(y.len(), converted_len(n_in, from, to));
                    let (k, _) = y
                        .iter()
                        .enumerate()
                        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                        .unwrap();
                    // Sub-sample peak by parabolic interpolation.
                    let (a, b, c) = (y[k - 1] as f64, y[k] as f64, y[k + 1] as f64);
                    let peak = k as f64 + 0.5 * (a - c) / (a - 2.0 * b + c);
                    let want = idx as f64 * to as f64 / from as f64;
                    assert!(
                        (peak - want).abs() < 0.6,
                        "{from} -> {to} Hz, impulse at {idx}: peak {peak:.3}, want {want:.3}"
                    );
                }
            }
        }
    }

    #[test]
    fn describe_fmt_names_formats() {
        // RIFF header, a LIST chunk of odd length (padded), then fmt.
        let mut b = b"RIFF\0\0\0\0WAVE".to_vec();
        b.extend_from_slice(b"LIST\x03\0\0\0abc\0");
        b.extend_from_slice(b"fmt \x10\0\0\0");
        b.extend_from_slice(&3u16.to_le_bytes()); // float
        b.extend_from_slice(&1u16.to_le_bytes());
        b.extend_from_slice(&16_000u32.to_le_bytes());
        b.extend_from_slice(&128_000u32.to_le_bytes());
        b.extend_from_slice(&8u16.to_le_bytes());
        b.extend_from_slice(&64u16.to_le_bytes());
        assert_eq!(describe_fmt(&b), Some(Encoding::Float(64)));
        assert_eq!(describe_fmt(&b[..30]), None);
        assert_eq!(describe_fmt(b"RIFF"), None);
    }
}
