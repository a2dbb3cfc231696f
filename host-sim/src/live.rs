//! `gesture-sim live` and `gesture-sim devices`: the microphone through the runtime's
//! `Controller`, printing decisions and a live belief bar.
//!
//! The audio path is behind [`AudioSource`]: [`CpalSource`] reads a microphone through cpal
//! (any sample format, mixed to mono), [`FakeSource`] plays samples from memory and can inject
//! a failure, so the whole live loop ([`live_loop`]) is tested without hardware. Samples are
//! resampled to the blob's front-end rate with a streaming band-limited resampler
//! ([`StreamResampler`], rubato's asynchronous sinc, 128 taps: about 1.3 ms of delay at 48 kHz)
//! and converted to `i16` as the WAV path does (scale by 32768, round, clamp).
//!
//! **Real-time safety.** cpal calls its data callback on an audio thread: the callback only
//! mixes each frame to mono and pushes it into a preallocated lock-free single-producer
//! single-consumer ring (`rtrb`, 2 s of audio); it never allocates, locks or blocks. A full
//! ring drops the rest of the block and counts the dropped samples (an atomic), rather than
//! blocking the audio thread. Everything else (the resampler, the controller, printing) runs
//! on the calling thread, which drains the ring.
//!
//! **No device.** With no input device (as on a headless server), `live` and `devices` fail
//! with one line naming what is missing and exit status 2. ALSA's own diagnostics (which it
//! would print to stderr while probing cards) are captured and dropped on Linux.

use std::io::Write;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, ControllerEvent};
use gesture_runtime::device::{Device, DeviceEvent, NullPin};
use gesture_runtime::policy::Choice;
use gesture_runtime::prosody::StepKind;
use gesture_runtime::rig::MAX_CHANNELS;
use gesture_trainer::audio::{to_i16, StreamResampler};

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

/// A one-line picture of a belief: one block character per state, then the top state.
pub fn belief_bar(b: &[f32]) -> String {
    const BLOCKS: [char; 8] = ['▁', '▂', '▃', '▄', '▅', '▆', '▇', '█'];
    let mut s: String = b
        .iter()
        .map(|&v| BLOCKS[((v.clamp(0.0, 1.0) * 7.0).round() as usize).min(7)])
        .collect();
    if let Some((i, p)) = b.iter().enumerate().max_by(|x, y| x.1.total_cmp(y.1)) {
        s.push_str(&format!("  top state {i} ({:.0}%)", 100.0 * p));
    }
    s
}

/// Settings of the live loop.
#[derive(Clone, Copy, Debug, Default)]
pub struct LiveOptions {
    /// Stop after this much audio (s); `None`: until the source ends.
    pub seconds: Option<f64>,
    /// Redraw one belief line in place (`\r`, for a terminal) instead of one line per step.
    pub redraw: bool,
}

/// What a live session did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LiveStats {
    /// Audio fed to the controller (s, at the blob's rate).
    pub seconds: f64,
    /// Steps (syllables and pauses).
    pub steps: usize,
    /// Syllables.
    pub syllables: usize,
    /// Decisions.
    pub decisions: usize,
    /// Animation ticks.
    pub ticks: u64,
}

/// Runs `source` through the controller of `blob`, printing decisions and the belief to `out`.
pub fn live_loop(
    blob: &Blob<'_>,
    source: &mut dyn AudioSource,
    opts: LiveOptions,
    out: &mut dyn Write,
) -> Result<LiveStats, LiveError> {
    let config = blob.prosody_config();
    let rate = config.sample_rate_hz;
    let mut slot = Box::new(None);
    let controller = BlobController::from_blob_in(&mut slot, blob)
        .map_err(|e| LiveError::Backend(format!("controller: {e}")))?;
    let mut device: Device<'_, '_, NullPin, MAX_CHANNELS> =
        Device::new(controller, [NullPin; MAX_CHANNELS])
            .map_err(|e| LiveError::Backend(format!("device: {e}")))?;
    let (from, to) = (source.rate_hz(), rate);
    let resample_err = |e: gesture_trainer::audio::ConvertError| LiveError::Resample {
        from,
        to,
        reason: e.to_string(),
    };
    let mut resampler = StreamResampler::new(from, to).map_err(resample_err)?;
    let fps = blob.fps() as f64;
    let limit = opts.seconds.map(|s| (s * rate as f64).round() as u64);
    let mut stats = LiveStats::default();
    let mut raw = Vec::new();
    let mut resampled = Vec::new();
    let mut pcm: Vec<i16> = Vec::new();
    let mut fed = 0u64;
    let mut io_err: Option<std::io::Error> = None;
    writeln!(
        out,
        "listening at {} Hz (blob rate {} Hz, {} states, {} segments); Ctrl-C stops",
        source.rate_hz(),
        rate,
        blob.states(),
        blob.segments()
    )?;
    loop {
        raw.clear();
        let more = source.read(&mut raw, Duration::from_millis(200))?;
        resampled.clear();
        resampler.push(&raw, &mut resampled).map_err(resample_err)?;
        pcm.clear();
        pcm.extend(resampled.iter().map(|&x| to_i16(x)));
        if let Some(l) = limit {
            let room = l.saturating_sub(fed) as usize;
            pcm.truncate(room);
        }
        fed += pcm.len() as u64;
        let now = fed as f64 / rate as f64;
        // Null pins cannot fail.
        let _ = device.push(&pcm, &mut |e| {
            let DeviceEvent::Controller(e) = e else {
                return;
            };
            let r = match e {
                ControllerEvent::Step { step, belief } => {
                    stats.steps += 1;
                    if step.kind == StepKind::Syllable {
                        stats.syllables += 1;
                    }
                    let kind = match step.kind {
                        StepKind::Syllable => "syllable",
                        StepKind::Pause => "pause   ",
                    };
                    let line = format!(
                        "{now:8.2} s  {kind} {:6.2}-{:6.2} s  {}",
                        step.start_s(),
                        step.end_s(),
                        belief_bar(belief)
                    );
                    if opts.redraw {
                        write!(out, "\r\x1b[K{line}").and_then(|()| out.flush())
                    } else {
                        writeln!(out, "{line}")
                    }
                }
                ControllerEvent::Decision { tick, decision } => {
                    stats.decisions += 1;
                    let what = match decision.choice {
                        Choice::Continue => "continue".to_string(),
                        Choice::Enter(c) => format!("enter segment {c}"),
                    };
                    let line = format!(
                        "{:8.2} s  decision at exit {}: {what} (cost {:.3}, {} candidates)",
                        tick as f64 / fps,
                        decision.exit,
                        decision.cost,
                        decision.candidates
                    );
                    if opts.redraw {
                        writeln!(out, "\r\x1b[K{line}")
                    } else {
                        writeln!(out, "{line}")
                    }
                }
                ControllerEvent::Pose { tick, .. } => {
                    stats.ticks = tick + 1;
                    Ok(())
                }
                ControllerEvent::Frame(_) | ControllerEvent::Onset(_) => Ok(()),
            };
            if let (Err(e), None) = (r, &io_err) {
                io_err = Some(e);
            }
        });
        if let Some(e) = io_err.take() {
            return Err(e.into());
        }
        stats.seconds = now;
        if !more || limit.is_some_and(|l| fed >= l) {
            break;
        }
    }
    let _ = device.finish(&mut |_| {});
    if opts.redraw {
        writeln!(out)?;
    }
    writeln!(
        out,
        "stopped after {:.2} s: {} syllables, {} steps, {} decisions, {} ticks",
        stats.seconds, stats.syllables, stats.steps, stats.decisions, stats.ticks
    )?;
    Ok(stats)
}

// ----- cpal ------------------------------------------------------------------------------------

/// Runs `f` with ALSA's stderr diagnostics captured (Linux), so a failure is our one line.
fn quiet_alsa<T>(f: impl FnOnce() -> T) -> T {
    #[cfg(target_os = "linux")]
    let _guard = alsa::Output::local_error_handler().ok();
    f()
}

/// A device's identifier (ALSA: the PCM name, e.g. `hw:CARD=USB,DEV=0`) and description.
fn device_id(d: &cpal::Device) -> (String, String) {
    use cpal::traits::DeviceTrait;
    match d.description() {
        Ok(desc) => (
            desc.driver().unwrap_or(desc.name()).to_string(),
            desc.name().to_string(),
        ),
        Err(_) => (String::new(), String::new()),
    }
}

/// ALSA's `null` PCM "captures" endless zeros: it is there on machines without any sound card
/// and is no microphone, so it is never listed or opened.
fn is_dummy(d: &cpal::Device) -> bool {
    device_id(d).0 == "null"
}

/// The usable input devices: (identifier, description, is the default).
pub fn input_devices() -> Result<Vec<(String, String, bool)>, LiveError> {
    use cpal::traits::{DeviceTrait, HostTrait};
    quiet_alsa(|| {
        let host = cpal::default_host();
        let default = host.default_input_device().map(|d| device_id(&d).0);
        let devices = host
            .input_devices()
            .map_err(|e| LiveError::Backend(e.to_string()))?;
        Ok(devices
            .filter(|d| !is_dummy(d) && d.supports_input())
            .map(|d| {
                let (id, name) = device_id(&d);
                let is_default = default.as_deref() == Some(id.as_str());
                (id, name, is_default)
            })
            .collect())
    })
}

/// `gesture-sim devices`: prints the input devices (`*` marks the default), or fails with
/// [`LiveError::NoDevice`] when there is none.
pub fn devices(out: &mut dyn Write) -> Result<(), LiveError> {
    let list = input_devices()?;
    if list.is_empty() {
        return Err(LiveError::NoDevice);
    }
    for (id, name, d) in list {
        writeln!(out, "{}{id}  ({name})", if d { "* " } else { "  " })?;
    }
    Ok(())
}

/// A cpal input stream as an [`AudioSource`]. Keep it on the thread that opened it.
pub struct CpalSource {
    _stream: cpal::Stream,
    rx: rtrb::Consumer<f32>,
    rate_hz: u32,
    errors: Arc<Mutex<Option<String>>>,
    failed: Arc<AtomicBool>,
    dropped: Arc<AtomicU64>,
}

impl CpalSource {
    /// Opens the device named `name` (or the default input device) at its default config.
    pub fn open(name: Option<&str>) -> Result<Self, LiveError> {
        use cpal::traits::{DeviceTrait, HostTrait, StreamTrait};
        use cpal::SampleFormat;
        quiet_alsa(|| {
            let host = cpal::default_host();
            let device = match name {
                None => host
                    .default_input_device()
                    .filter(|d| !is_dummy(d))
                    .ok_or(LiveError::NoDevice)?,
                Some(n) => {
                    let all: Vec<cpal::Device> = host
                        .input_devices()
                        .map_err(|e| LiveError::Backend(e.to_string()))?
                        .filter(|d| !is_dummy(d))
                        .collect();
                    let names: Vec<String> = all.iter().map(|d| device_id(d).0).collect();
                    let found = all.into_iter().find(|d| {
                        let (id, desc) = device_id(d);
                        id == n || desc == n
                    });
                    match found {
                        Some(d) => d,
                        None if names.is_empty() => return Err(LiveError::NoDevice),
                        None => {
                            return Err(LiveError::DeviceNotFound {
                                name: n.to_string(),
                                available: names.join(", "),
                            })
                        }
                    }
                }
            };
            let supported = device.default_input_config().map_err(|e| match name {
                None => LiveError::NoDevice,
                Some(_) => LiveError::Backend(e.to_string()),
            })?;
            let config = supported.config();
            let channels = config.channels.max(1) as usize;
            let rate_hz = config.sample_rate;
            // Two seconds of mono audio: the controller thread drains it every 200 ms.
            let (tx, rx) = rtrb::RingBuffer::<f32>::new((2 * rate_hz as usize).max(4096));
            let errors = Arc::new(Mutex::new(None));
            let failed = Arc::new(AtomicBool::new(false));
            let dropped = Arc::new(AtomicU64::new(0));
            let (e2, f2, d2) = (errors.clone(), failed.clone(), dropped.clone());
            // Not on the data path: cpal reports stream errors from its own context.
            let on_error = move |e: cpal::Error| {
                if let Ok(mut g) = e2.lock() {
                    g.get_or_insert(e.to_string());
                }
                f2.store(true, Ordering::Release);
            };
            // Mixes a block to mono into the ring without allocating, locking or blocking.
            fn sender<T: Copy + Send + 'static>(
                mut tx: rtrb::Producer<f32>,
                dropped: Arc<AtomicU64>,
                channels: usize,
                to_f32: fn(T) -> f32,
            ) -> impl FnMut(&[T], &cpal::InputCallbackInfo) + Send + 'static {
                move |data: &[T], _: &cpal::InputCallbackInfo| {
                    let scale = 1.0 / channels as f32;
                    let mut lost = 0u64;
                    for frame in data.chunks(channels) {
                        let mono = frame.iter().map(|&x| to_f32(x)).sum::<f32>() * scale;
                        if tx.push(mono).is_err() {
                            lost += 1;
                        }
                    }
                    if lost > 0 {
                        dropped.fetch_add(lost, Ordering::Relaxed);
                    }
                }
            }
            let backend = |e: cpal::Error| LiveError::Backend(e.to_string());
            let stream = match supported.sample_format() {
                SampleFormat::F32 => device.build_input_stream(
                    config,
                    sender::<f32>(tx, d2, channels, |x| x),
                    on_error,
                    None,
                ),
                SampleFormat::I16 => device.build_input_stream(
                    config,
                    sender::<i16>(tx, d2, channels, |x| x as f32 / 32768.0),
                    on_error,
                    None,
                ),
                SampleFormat::I32 => device.build_input_stream(
                    config,
                    sender::<i32>(tx, d2, channels, |x| x as f32 / 2_147_483_648.0),
                    on_error,
                    None,
                ),
                SampleFormat::U16 => device.build_input_stream(
                    config,
                    sender::<u16>(tx, d2, channels, |x| (x as f32 - 32768.0) / 32768.0),
                    on_error,
                    None,
                ),
                other => {
                    return Err(LiveError::Backend(format!(
                        "unsupported sample format {other}"
                    )))
                }
            }
            .map_err(backend)?;
            stream.play().map_err(backend)?;
            Ok(Self {
                _stream: stream,
                rx,
                rate_hz,
                errors,
                failed,
                dropped,
            })
        })
    }

    /// Samples dropped because the controller fell behind.
    pub fn dropped_samples(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }
}

impl AudioSource for CpalSource {
    fn rate_hz(&self) -> u32 {
        self.rate_hz
    }

    fn read(&mut self, out: &mut Vec<f32>, timeout: Duration) -> Result<bool, LiveError> {
        let start = Instant::now();
        loop {
            if self.failed.load(Ordering::Acquire) {
                let e = self.errors.lock().ok().and_then(|mut g| g.take());
                return Err(LiveError::Backend(
                    e.unwrap_or_else(|| "the input stream failed".into()),
                ));
            }
            let n = self.rx.slots();
            if n > 0 {
                if let Ok(chunk) = self.rx.read_chunk(n) {
                    let (a, b) = chunk.as_slices();
                    out.extend_from_slice(a);
                    out.extend_from_slice(b);
                    chunk.commit_all();
                }
                return Ok(true);
            }
            if self.rx.is_abandoned() {
                return Ok(false);
            }
            if start.elapsed() >= timeout {
                return Ok(true);
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}
