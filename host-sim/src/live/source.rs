//! Where live audio comes from ([`AudioSource`]; [`FakeSource`] from memory, for tests), and
//! why the live path failed ([`LiveError`]): what the microphone and the loop both name.

use std::time::Duration;

/// Why the live path failed.
#[derive(Debug, thiserror::Error)]
pub enum LiveError {
    /// There is no audio input device at all.
    #[error("no audio input device found (connect a microphone, or use `gesture-sim run` on a WAV file)")]
    NoDevice,
    /// The named device does not exist.
    #[error("no input device named {name:?}; available: {available} (see `gesture-sim devices`)")]
    DeviceNotFound {
        /// What was asked for.
        name: String,
        /// What there is.
        available: String,
    },
    /// The audio backend failed (opening, configuring or running the stream).
    #[error("audio input: {0}")]
    Backend(String),
    /// The source's sample rate cannot be resampled to the blob's.
    #[error("cannot resample {from} Hz to {to} Hz: {reason}")]
    Resample {
        /// Source rate.
        from: u32,
        /// Blob rate.
        to: u32,
        /// Why.
        reason: String,
    },
    /// This build has no microphone support.
    #[error(
        "this gesture-sim was built without microphone support: build it with `--features mic` \
         (e.g. `cargo run --release -p host-sim --features mic -- live ...`; on Linux that needs \
         the ALSA headers: `apt-get install libasound2-dev pkg-config`)"
    )]
    NoMicSupport,
    /// Writing to stdout failed.
    #[error("writing output: {0}")]
    Output(#[from] std::io::Error),
}

impl LiveError {
    /// Exit status: 2 for a missing or failing device, 1 for output errors.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Output(_) => 1,
            _ => 2,
        }
    }
}

/// Where live audio comes from.
pub trait AudioSource {
    /// Rate (Hz) of the samples [`AudioSource::read`] delivers.
    fn rate_hz(&self) -> u32;
    /// Appends the next mono samples (full scale +-1) to `out`, waiting at most `timeout`
    /// for them (appending nothing on a timeout). `Ok(false)` when the source has ended.
    fn read(&mut self, out: &mut Vec<f32>, timeout: Duration) -> Result<bool, LiveError>;
}

/// Samples from memory, `block` at a time; optionally fails after `fail_after` reads.
#[derive(Clone, Debug)]
pub struct FakeSource {
    samples: Vec<f32>,
    rate_hz: u32,
    block: usize,
    pos: usize,
    reads: usize,
    fail_after: Option<usize>,
}

impl FakeSource {
    /// A source playing `samples` at `rate_hz`, `block` samples per read.
    pub fn new(samples: Vec<f32>, rate_hz: u32, block: usize) -> Self {
        Self {
            samples,
            rate_hz,
            block: block.max(1),
            pos: 0,
            reads: 0,
            fail_after: None,
        }
    }

    /// The same source, failing like an unplugged device after `reads` successful reads.
    pub fn failing_after(mut self, reads: usize) -> Self {
        self.fail_after = Some(reads);
        self
    }
}

impl AudioSource for FakeSource {
    fn rate_hz(&self) -> u32 {
        self.rate_hz
    }

    fn read(&mut self, out: &mut Vec<f32>, _timeout: Duration) -> Result<bool, LiveError> {
        if self.fail_after.is_some_and(|n| self.reads >= n) {
            return Err(LiveError::Backend("device unplugged (injected)".into()));
        }
        self.reads += 1;
        if self.pos >= self.samples.len() {
            return Ok(false);
        }
        let end = (self.pos + self.block).min(self.samples.len());
        out.extend_from_slice(&self.samples[self.pos..end]);
        self.pos = end;
        Ok(true)
    }
}
