//! Drives the runtime's device loop over 16 kHz PCM the way a microphone DMA would deliver
//! it, and writes the decision trace.
//!
//! This file is shared, byte for byte, by the firmware (`src/main.rs`) and by the host
//! reference (`tests/examples/qemu_m4_host.rs` includes it with `#[path]`), so the device and
//! the desktop run the same loop over the same samples in the same chunks and print the same
//! lines. Only the CPU differs; CI diffs the two traces.
//!
//! ## The trace
//!
//! An input whose name ends in `-ahead` runs with [`LOOKAHEAD_MS`] of look-ahead (known
//! audio: the controller hears it that long before it is played), followed by that much
//! silence so every tick of the audio is played (`gesture-sim run --lookahead-ms` does the
//! same).
//!
//! Per input: `input <name> samples=<n>`, then one line per decision
//!
//! ```text
//! decision tick=<t> exit=<e> choice=<continue|segment N>
//! ```
//!
//! and a closing `end` line with counts and FNV-1a hashes of every belief and every pose
//! (their `f32` bit patterns), so a numeric drift between host and device shows even when no
//! decision changes.
//!
//! ## Checks on the way
//!
//! The runtime's device loop (`gesture_runtime::device::Device`) runs the blob: every pose
//! must be finite, and every duty cycle its `ServoRig` writes (the blob's calibration, 16-bit
//! recording pins) must stay within the 500..=2500 us pulse range. A violation stops the run
//! with [`RunError::Pose`].
//!
//! ## Style
//!
//! A blob with tones runs with every tone and neutral weighted alike (`1 / (M + 1)` each): the
//! dearest mix, every value table read at every candidate, so the measured cost is the worst a
//! style can make it. `check` gives `gesture-sim run` the same `--style`.
//!
//! ## Labels
//!
//! A blob with semantic labels is given label 0 at the sample times of [`LABELS`], as a
//! keyword spotter or a button would, so the labelled decisions are checked too.
//!
//! `no_std`, no heap: the device and the DMA buffer are on the caller's stack.

use core::convert::Infallible;
use core::fmt::{self, Write};

use embedded_hal::pwm::{ErrorType, SetDutyCycle};
use gesture_runtime::blob::{Blob, BlobError};
use gesture_runtime::controller::{BlobController, ControllerEvent, Lookahead};
use gesture_runtime::device::{Device, DeviceError, DeviceEvent};
use gesture_runtime::policy::Choice;
use gesture_runtime::prosody::arith::{Arith, DefaultArith};
use gesture_runtime::rig::{duty_cycle, PULSE_MAX_US, PULSE_MIN_US};

/// Samples per DMA buffer (16 ms at 16 kHz).
pub const CHUNK: usize = 256;
/// Semantic labels given to a blob that has labels: `(sample, label)`, at DMA buffer
/// boundaries (1.504 s and 4.0 s); `check` gives `gesture-sim run` the same as `--labels`.
pub const LABELS: [(usize, usize); 2] = [(94 * CHUNK, 0), (250 * CHUNK, 0)];
/// The look-ahead of an input named `*-ahead` (ms): the controller hears it this long before
/// it is played; other inputs run live.
pub const LOOKAHEAD_MS: u32 = 500;

/// The look-ahead of input `name` ([`LOOKAHEAD_MS`] for a name ending in `-ahead`, else 0).
pub fn lookahead_ms(name: &str) -> u32 {
    if name.ends_with("-ahead") {
        LOOKAHEAD_MS
    } else {
        0
    }
}

/// Sample rate of the embedded audio.
pub const AUDIO_RATE_HZ: u32 = 16_000;
/// Servo channels of the board (the puppet rig, `rigs/puppet-8ch.toml`).
pub const CHANNELS: usize = 8;

/// The device loop over a blob, as [`run`] builds it (`A`: the front-end's arithmetic).
pub type BoardDevice<'c, 'a, A = DefaultArith> = Device<'c, 'a, RecordingPin, CHANNELS, A>;

/// Why a run stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RunError {
    /// The blob was refused.
    Blob(BlobError),
    /// The blob's front-end runs at another rate than the audio.
    SampleRate {
        /// The blob's rate (Hz).
        found: u32,
    },
    /// The blob drives another number of servos than the board has.
    Channels {
        /// The blob's channel count.
        found: usize,
    },
    /// The device refused the blob (tables, channels or calibration).
    Device(DeviceError),
    /// The audio is not whole 16-bit samples.
    OddAudio {
        /// Its length in bytes.
        len: usize,
    },
    /// A pose was not finite, or a servo pulse left 500..=2500 us.
    Pose {
        /// The animation tick.
        tick: u64,
    },
    /// The controller refused the style (a blob with more tones than a style holds).
    Style,
    /// Writing the trace failed.
    Output,
}

impl RunError {
    /// The error without formatting code: a firmware logs this instead of `Debug` or
    /// `Display` (the blob's `Display` formats floats, about 15 KiB of code; derived `Debug`
    /// of the nested errors about 7 KiB).
    pub fn name(&self) -> &'static str {
        match self {
            Self::Blob(e) => e.name(),
            Self::SampleRate { .. } => "SampleRate",
            Self::Channels { .. } => "Channels",
            Self::Device(DeviceError::Controller(_)) => "Controller",
            Self::Device(DeviceError::TooManyChannels { .. }) => "TooManyChannels",
            Self::Device(DeviceError::Rig(_)) => "Rig",
            Self::OddAudio { .. } => "OddAudio",
            Self::Pose { .. } => "Pose",
            Self::Style => "Style",
            Self::Output => "Output",
        }
    }
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Blob(e) => write!(f, "blob: {e}"),
            Self::SampleRate { found } => write!(
                f,
                "blob front-end runs at {found} Hz, the audio at {AUDIO_RATE_HZ} Hz"
            ),
            Self::Channels { found } => write!(
                f,
                "blob drives {found} channels, this board has {CHANNELS} servos"
            ),
            Self::Device(e) => write!(f, "device: {e}"),
            Self::OddAudio { len } => write!(f, "audio is {len} bytes, not whole i16 samples"),
            Self::Pose { tick } => write!(f, "invalid pose or servo pulse at tick {tick}"),
            Self::Style => f.write_str("the controller refused the style"),
            Self::Output => f.write_str("writing the trace failed"),
        }
    }
}

/// Measurement hooks (the firmware's `measure` build times the controller with them).
/// Every method defaults to nothing.
pub trait Probe {
    /// The controller is built; the samples come next.
    fn ready(&mut self) {}
    /// Just before a DMA buffer is handed to the controller.
    fn chunk_begin(&mut self) {}
    /// Just after the controller returned from a buffer.
    fn chunk_end(&mut self) {}
    /// On entry to the event sink, before the event is handled.
    fn event_begin(&mut self, _event: &ControllerEvent<'_>) {}
    /// On leaving the event sink.
    fn event_end(&mut self) {}
}

/// No measurement.
#[allow(dead_code)] // not used by the firmware's `measure` build
pub struct NoProbe;

impl Probe for NoProbe {}

/// What a run saw.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Summary {
    /// Samples fed.
    pub samples: u64,
    /// Prosody frames.
    pub frames: u64,
    /// Steps (syllables and pauses).
    pub steps: u64,
    /// Decisions.
    pub decisions: u64,
    /// Animation ticks (poses).
    pub ticks: u64,
    /// FNV-1a over every belief's bits.
    pub belief_hash: u32,
    /// FNV-1a over every pose's bits.
    pub pose_hash: u32,
    /// Shortest and longest servo pulse commanded (duty steps of a 16-bit timer).
    pub duty_range: (u16, u16),
}

/// A servo output that keeps the last duty cycle (a 16-bit timer channel).
#[derive(Clone, Copy, Debug, Default)]
pub struct RecordingPin {
    duty: u16,
}

impl ErrorType for RecordingPin {
    type Error = Infallible;
}

impl SetDutyCycle for RecordingPin {
    fn max_duty_cycle(&self) -> u16 {
        u16::MAX
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Infallible> {
        self.duty = duty;
        Ok(())
    }
}

/// FNV-1a's offset basis: the hash of nothing.
pub const FNV_OFFSET: u32 = 0x811c_9dc5;

/// FNV-1a of `values`' `f32` bit patterns (little-endian), continuing from `h` (`show.rs`
/// hashes a show's poses with it too).
pub fn fnv(mut h: u32, values: &[f32]) -> u32 {
    for v in values {
        for b in v.to_bits().to_le_bytes() {
            h ^= b as u32;
            h = h.wrapping_mul(0x0100_0193);
        }
    }
    h
}

/// Builds the controller over `blob` in `slot`, in place and out of line, so that neither a
/// copy of it nor the temporaries of its construction stay on the stack while samples run.
#[inline(never)]
fn build<'s, 'a, A: Arith>(
    slot: &'s mut Option<BlobController<'a, A>>,
    blob: &'a Blob<'a>,
) -> Result<&'s mut BlobController<'a, A>, DeviceError> {
    BlobController::from_blob_arith_in(slot, blob).map_err(DeviceError::Controller)
}

/// Runs a fresh controller from `blob` over `audio` (little-endian i16 at 16 kHz) in
/// [`CHUNK`]-sample buffers, writing the trace for input `name` to `out`. The front-end's
/// arithmetic is the build's ([`run_with`] chooses it).
pub fn run(
    name: &str,
    blob: &[u8],
    audio: &[u8],
    out: &mut impl Write,
    probe: &mut impl Probe,
) -> Result<Summary, RunError> {
    run_with::<DefaultArith>(name, blob, audio, out, probe)
}

/// [`run`] with the front-end arithmetic `A` (the host reference runs the fixed-point
/// front-end of an ARMv6-M firmware with it).
pub fn run_with<A: Arith>(
    name: &str,
    blob: &[u8],
    audio: &[u8],
    out: &mut impl Write,
    probe: &mut impl Probe,
) -> Result<Summary, RunError> {
    let blob = Blob::parse(blob).map_err(RunError::Blob)?;
    let config = blob.prosody_config();
    if config.sample_rate_hz != AUDIO_RATE_HZ {
        return Err(RunError::SampleRate {
            found: config.sample_rate_hz,
        });
    }
    if blob.channels() != CHANNELS {
        return Err(RunError::Channels {
            found: blob.channels(),
        });
    }
    if audio.len() % 2 != 0 {
        return Err(RunError::OddAudio { len: audio.len() });
    }
    let period_us = blob.period_us();
    let duty_min = duty_cycle(PULSE_MIN_US, period_us, u16::MAX);
    let duty_max = duty_cycle(PULSE_MAX_US, period_us, u16::MAX);

    let mut slot: Option<BlobController<'_, A>> = None;
    let controller = build(&mut slot, &blob).map_err(RunError::Device)?;
    let tones = blob.tones();
    if tones > 0 {
        let mut w = [0.0f32; gesture_runtime::policy::MAX_TONES];
        let share = 1.0 / (tones as f32 + 1.0);
        w[..tones].iter_mut().for_each(|v| *v = share);
        controller
            .set_style(&w[..tones])
            .map_err(|_| RunError::Style)?;
    }
    controller.set_lookahead(Lookahead::ms(lookahead_ms(name)));
    let mut device: BoardDevice<'_, '_, A> =
        Device::new(controller, [RecordingPin::default(); CHANNELS]).map_err(RunError::Device)?;
    probe.ready();

    write_parts(
        out,
        &[
            Part::Text("input "),
            Part::Text(name),
            Part::Text(" samples="),
            Part::Dec((audio.len() / 2) as u64),
            Part::Text("\n"),
        ],
    )
    .map_err(|_| RunError::Output)?;
    let mut sum = Summary {
        belief_hash: FNV_OFFSET,
        pose_hash: FNV_OFFSET,
        duty_range: (u16::MAX, 0),
        ..Summary::default()
    };
    let mut failure: Option<RunError> = None;
    // The DMA buffer: samples land here in RAM before the controller sees them.
    let mut dma = [0i16; CHUNK];
    let labelled = blob.labels() > 0;
    // A look-ahead input is followed by that much silence (after a recording, nothing), so
    // every tick of the audio is played.
    let ahead = lookahead_ms(name);
    let heard = audio.len() / 2 + (ahead as usize * AUDIO_RATE_HZ as usize).div_ceil(1000);
    for k in 0..heard.div_ceil(CHUNK) {
        let n = CHUNK.min(heard - k * CHUNK);
        let bytes = audio.get(2 * k * CHUNK..).unwrap_or(&[]);
        if labelled {
            for &(at, label) in &LABELS {
                if at == k * CHUNK {
                    // A full queue drops the label, as on a board.
                    let _ = device.controller_mut().push_label(label);
                }
            }
        }
        dma.fill(0);
        for (s, b) in dma[..n].iter_mut().zip(bytes.chunks_exact(2)) {
            *s = i16::from_le_bytes([b[0], b[1]]);
        }
        probe.chunk_begin();
        // Recording pins cannot fail.
        let _ = device.push(&dma[..n], &mut |dev| {
            let ev = match dev {
                DeviceEvent::Controller(ev) => ev,
                DeviceEvent::Servos { tick, rig } => {
                    let mut ok = true;
                    for pin in rig.pins() {
                        ok &= (duty_min..=duty_max).contains(&pin.duty);
                        sum.duty_range.0 = sum.duty_range.0.min(pin.duty);
                        sum.duty_range.1 = sum.duty_range.1.max(pin.duty);
                    }
                    if !ok && failure.is_none() {
                        failure = Some(RunError::Pose { tick });
                    }
                    return;
                }
            };
            probe.event_begin(&ev);
            match ev {
                ControllerEvent::Frame(_) => sum.frames += 1,
                ControllerEvent::Onset(_)
                | ControllerEvent::Label { .. }
                | ControllerEvent::Play { .. } => {}
                ControllerEvent::Step { belief, .. } => {
                    sum.steps += 1;
                    sum.belief_hash = fnv(sum.belief_hash, belief);
                }
                ControllerEvent::Decision { tick, decision } => {
                    sum.decisions += 1;
                    let head = [
                        Part::Text("decision tick="),
                        Part::Dec(tick),
                        Part::Text(" exit="),
                        Part::Dec(decision.exit as u64),
                    ];
                    let written = write_parts(out, &head).and_then(|()| match decision.choice {
                        Choice::Continue => out.write_str(" choice=continue\n"),
                        Choice::Enter(c) => write_parts(
                            out,
                            &[
                                Part::Text(" choice=segment "),
                                Part::Dec(c as u64),
                                Part::Text("\n"),
                            ],
                        ),
                    });
                    if written.is_err() && failure.is_none() {
                        failure = Some(RunError::Output);
                    }
                }
                ControllerEvent::Pose { tick, pose, .. } => {
                    sum.ticks += 1;
                    sum.pose_hash = fnv(sum.pose_hash, pose);
                    if !pose.iter().all(|v| v.is_finite()) && failure.is_none() {
                        failure = Some(RunError::Pose { tick });
                    }
                }
            }
            probe.event_end();
        });
        probe.chunk_end();
        sum.samples += n as u64;
        if let Some(e) = failure {
            return Err(e);
        }
    }
    write_parts(
        out,
        &[
            Part::Text("end samples="),
            Part::Dec(sum.samples),
            Part::Text(" frames="),
            Part::Dec(sum.frames),
            Part::Text(" steps="),
            Part::Dec(sum.steps),
            Part::Text(" decisions="),
            Part::Dec(sum.decisions),
            Part::Text(" ticks="),
            Part::Dec(sum.ticks),
            Part::Text(" belief_hash="),
            Part::Hex8(sum.belief_hash),
            Part::Text(" pose_hash="),
            Part::Hex8(sum.pose_hash),
            Part::Text(" duty="),
            Part::Dec(sum.duty_range.0 as u64),
            Part::Text(".."),
            Part::Dec(sum.duty_range.1 as u64),
            Part::Text("\n"),
        ],
    )
    .map_err(|_| RunError::Output)?;
    Ok(sum)
}

/// Writes `parts` in order: text as it is, numbers in decimal or as eight hex digits. The
/// trace's only formatting: core's integer `Display` links its padding code (about 2.5 KB of
/// the firmware's flash), and `{}` of a `str` the same.
pub fn write_parts(out: &mut impl Write, parts: &[Part<'_>]) -> fmt::Result {
    for part in parts {
        match *part {
            Part::Text(t) => out.write_str(t)?,
            Part::Dec(v) => {
                let mut digits = [0u8; 20];
                let (mut i, mut v) = (digits.len(), v);
                loop {
                    i -= 1;
                    digits[i] = b'0' + (v % 10) as u8;
                    v /= 10;
                    if v == 0 {
                        break;
                    }
                }
                for &d in &digits[i..] {
                    out.write_char(d as char)?;
                }
            }
            Part::Hex8(v) => {
                for k in (0..8).rev() {
                    let d = ((v >> (4 * k)) & 0xf) as u8;
                    out.write_char(if d < 10 { b'0' + d } else { b'a' + d - 10 } as char)?;
                }
            }
        }
    }
    Ok(())
}

/// A piece of a trace line ([`write_parts`]).
#[derive(Clone, Copy, Debug)]
pub enum Part<'a> {
    /// Text as it is.
    Text(&'a str),
    /// A number in decimal.
    Dec(u64),
    /// A number as eight lowercase hex digits.
    Hex8(u32),
}
