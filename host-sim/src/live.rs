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
//! **Feature.** The microphone (cpal, and on Linux the ALSA headers it builds against) is
//! behind the `mic` feature, so the default build needs nothing but Rust; without it `live`
//! and `devices` fail with one line naming the feature ([`LiveError::NoMicSupport`], exit 2).
//!
//! **No device.** With no input device (as on a headless server), `live` and `devices` fail
//! with one line naming what is missing and exit status 2. ALSA's own diagnostics (which it
//! would print to stderr while probing cards) are captured and dropped on Linux.

use std::io::Write;
use std::time::Duration;

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, ControllerEvent, LabelOutcome};
use gesture_runtime::device::{Device, DeviceEvent, NullPin};
use gesture_runtime::policy::Choice;
use gesture_runtime::prosody::StepKind;
use gesture_runtime::rig::MAX_CHANNELS;
use gesture_trainer::audio::{to_i16, StreamResampler};

mod source;
pub use source::{AudioSource, FakeSource, LiveError};

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
#[derive(Debug, Default)]
pub struct LiveOptions {
    /// Stop after this much audio (s); `None`: until the source ends.
    pub seconds: Option<f64>,
    /// Redraw one belief line in place (`\r`, for a terminal) instead of one line per step.
    pub redraw: bool,
    /// Style changes (times from the start of listening; `--style`, `--energy`,
    /// `--style-track`), each given to the controller when the audio reaches it.
    pub styles: Vec<crate::style::StyleChange>,
    /// Label numbers typed while listening (1-based, the blob's order; see [`read_keys`]):
    /// each asks the controller for that label.
    pub keys: Option<std::sync::mpsc::Receiver<usize>>,
    /// Keyword spotting on the microphone (`--keywords`): the spotter and, per keyword, the
    /// index of its label.
    pub keywords: Option<(crate::kws::Stream, Vec<usize>)>,
}

/// Reads lines from `input` (the terminal) on a thread and sends the label numbers typed (a
/// number and Enter: `2` asks for the second label); anything else is ignored. The thread
/// ends with the input.
pub fn read_keys(
    input: impl std::io::BufRead + Send + 'static,
) -> std::sync::mpsc::Receiver<usize> {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in input.lines() {
            let Ok(line) = line else { break };
            if let Ok(k) = line.trim().parse::<usize>() {
                if k >= 1 && tx.send(k).is_err() {
                    break;
                }
            }
        }
    });
    rx
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
    live_loop_with(blob, source, opts, out, &mut |_| Ok(()))
}

/// One animation tick as it plays.
#[derive(Clone, Copy, Debug)]
pub struct PlayedTick<'a> {
    /// The tick.
    pub tick: u64,
    /// Its time (s from the start of listening).
    pub time_s: f64,
    /// The played pose (rig channel values, degrees).
    pub pose: &'a [f32],
    /// The angles the servo rig commanded for it (degrees: the pose within the blob's limits
    /// and slew rate).
    pub angles: &'a [f32],
}

/// Receives each played tick.
pub type PoseSink<'a> = dyn FnMut(PlayedTick<'_>) -> Result<(), String> + 'a;

/// [`live_loop`], handing every tick ([`PlayedTick`]) to `on_pose` as it is played (e.g. a
/// VMC sender or a ROS 2 publisher); its error stops the loop.
pub fn live_loop_with(
    blob: &Blob<'_>,
    source: &mut dyn AudioSource,
    mut opts: LiveOptions,
    out: &mut dyn Write,
    on_pose: &mut PoseSink<'_>,
) -> Result<LiveStats, LiveError> {
    let mut pose_err: Option<String> = None;
    let mut last_pose: Vec<f32> = Vec::with_capacity(blob.channels());
    let channels = blob.channels();
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
    let tones: Vec<&str> = blob.tone_names().collect();
    let label_names: Vec<&str> = blob.label_names().collect();
    if opts.keys.is_some() && !label_names.is_empty() {
        let list: Vec<String> = label_names
            .iter()
            .enumerate()
            .map(|(k, n)| format!("{} {n}", k + 1))
            .collect();
        writeln!(out, "labels: {} (type a number and Enter)", list.join(", "))?;
    }
    let mut next_style = 0usize;
    loop {
        if let Some(keys) = &opts.keys {
            while let Ok(k) = keys.try_recv() {
                let msg = match device.controller_mut().push_label(k - 1) {
                    Ok(()) => format!("asked for label {k}"),
                    Err(e) => format!("label {k}: {e}"),
                };
                writeln!(out, "{:8.2} s  {msg}", fed as f64 / rate as f64)?;
            }
        }
        while let Some(c) = opts.styles.get(next_style) {
            if c.time_s * rate as f64 > fed as f64 {
                break;
            }
            device
                .controller_mut()
                .set_style(&c.weights)
                .map_err(|e| LiveError::Backend(format!("style: {e}")))?;
            if next_style > 0 || c.weights.iter().any(|&w| w > 0.0) {
                let d: Vec<String> = crate::style::describe(&c.weights, &tones)
                    .iter()
                    .map(|(n, w)| format!("{n}={w:.2}"))
                    .collect();
                writeln!(
                    out,
                    "{:7.2} s  style {}",
                    fed as f64 / rate as f64,
                    d.join(",")
                )?;
            }
            next_style += 1;
        }
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
        if let Some((spotter, labels)) = &mut opts.keywords {
            if let Some(k) = spotter.push(&pcm).map_err(LiveError::Backend)? {
                let label = labels[k];
                let name = label_names.get(label).copied().unwrap_or("?");
                let msg = match device.controller_mut().push_label(label) {
                    Ok(()) => format!("keyword heard: label {name}"),
                    Err(e) => format!("keyword heard: label {name}: {e}"),
                };
                writeln!(out, "{now:8.2} s  {msg}")?;
            }
        }
        // Null pins cannot fail.
        let _ = device.push(&pcm, &mut |e| {
            let e = match e {
                DeviceEvent::Controller(e) => e,
                // The servos follow the tick's pose event: both go to the sink together.
                DeviceEvent::Servos { tick, rig } => {
                    if pose_err.is_none() {
                        pose_err = on_pose(PlayedTick {
                            tick,
                            time_s: tick as f64 / fps.max(1e-9),
                            pose: &last_pose,
                            angles: &rig.angles()[..channels],
                        })
                        .err();
                    }
                    return;
                }
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
                ControllerEvent::Pose { tick, pose, .. } => {
                    stats.ticks = tick + 1;
                    last_pose.clear();
                    last_pose.extend_from_slice(pose);
                    Ok(())
                }
                ControllerEvent::Label {
                    tick,
                    label,
                    outcome,
                } => {
                    let name = blob.label_names().nth(label).unwrap_or("?");
                    let what = match outcome {
                        LabelOutcome::Received => "received".to_string(),
                        LabelOutcome::Entered { segment, frame } => {
                            format!("answered by segment {segment} from frame {frame}")
                        }
                        LabelOutcome::Stroke => "stroke".to_string(),
                        LabelOutcome::TimedOut => "dropped (timed out)".to_string(),
                    };
                    let line = format!("{:8.2} s  label {name}: {what}", tick as f64 / fps);
                    if opts.redraw {
                        writeln!(out, "\r\x1b[K{line}")
                    } else {
                        writeln!(out, "{line}")
                    }
                }
                ControllerEvent::Frame(_)
                | ControllerEvent::Onset(_)
                | ControllerEvent::Play { .. } => Ok(()),
            };
            if let (Err(e), None) = (r, &io_err) {
                io_err = Some(e);
            }
        });
        if let Some(e) = pose_err.take() {
            return Err(LiveError::Backend(e));
        }
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

// ----- the microphone ------------------------------------------------------------------------

#[cfg(feature = "mic")]
mod mic;
#[cfg(feature = "mic")]
pub use mic::{devices, input_devices, CpalSource};

/// Without the `mic` feature: the microphone commands name the feature.
#[cfg(not(feature = "mic"))]
mod no_mic {
    use super::{AudioSource, LiveError};
    use std::io::Write;
    use std::time::Duration;

    /// Always [`LiveError::NoMicSupport`] in a build without the `mic` feature.
    pub fn input_devices() -> Result<Vec<(String, String, bool)>, LiveError> {
        Err(LiveError::NoMicSupport)
    }

    /// Always [`LiveError::NoMicSupport`] in a build without the `mic` feature.
    pub fn devices(_out: &mut dyn Write) -> Result<(), LiveError> {
        Err(LiveError::NoMicSupport)
    }

    /// Stands in for the cpal source in a build without the `mic` feature: it never opens.
    pub enum CpalSource {}

    impl CpalSource {
        /// Always [`LiveError::NoMicSupport`].
        pub fn open(_name: Option<&str>) -> Result<Self, LiveError> {
            Err(LiveError::NoMicSupport)
        }
    }

    impl AudioSource for CpalSource {
        fn rate_hz(&self) -> u32 {
            match *self {}
        }
        fn read(&mut self, _out: &mut Vec<f32>, _timeout: Duration) -> Result<bool, LiveError> {
            match *self {}
        }
    }
}
#[cfg(not(feature = "mic"))]
pub use no_mic::{devices, input_devices, CpalSource};
