//! The simulation itself: PCM at the blob's rate through the runtime's device loop
//! (`gesture_runtime::device::Device`: the controller and the `ServoRig` on virtual pins) in
//! fixed chunks, every event and every duty cycle recorded.
//!
//! **Timing.** Samples arrive in chunks of `chunk` samples (10 ms by default), as a board's
//! audio DMA would deliver them. A chunk is processed when its last sample has arrived, so a
//! step reported while pushing a chunk is *detected* at that chunk's end time: the detection
//! latency of a syllable is that time minus the syllable's end (the front-end's analysis
//! windows and its 50 ms path-finder lag, plus up to one chunk). At the end of the audio the
//! controller is finished (`Controller::finish`), so the last syllable is reported at the end
//! time; such steps are marked `flushed` and left out of the latency figures (they were closed
//! by the end of the input, not detected). With `realtime`, each chunk waits until its end time
//! on the wall clock.

use std::time::{Duration, Instant};

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, ControllerEvent, LabelOutcome, Lookahead};
use gesture_runtime::device::{Device, DeviceEvent};
use gesture_runtime::player::PlayerCommand;
use gesture_runtime::policy::Choice;
use gesture_runtime::prosody::StepKind;
use gesture_runtime::rig::{ChannelCal, MAX_CHANNELS};

use crate::servo::VirtualPin;
use crate::style::StyleChange;

/// One prosody frame (10 ms).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameRecord {
    /// Centre time (s).
    pub time_s: f64,
    /// Intensity (dB).
    pub intensity_db: f32,
    /// F0 (Hz) when voiced.
    pub f0_hz: Option<f32>,
}

/// One step (syllable or pause) and the belief after it.
#[derive(Clone, Debug, PartialEq)]
pub struct StepRecord {
    /// Syllable or pause.
    pub kind: StepKind,
    /// Start (s).
    pub start_s: f64,
    /// End (s).
    pub end_s: f64,
    /// Mean F0 over voiced frames (Hz).
    pub f0_hz: Option<f32>,
    /// Mean intensity (dB).
    pub intensity_db: f32,
    /// Length (s).
    pub length_s: f32,
    /// When the belief update happened on the sample clock (s): the end of the chunk whose
    /// processing reported the step.
    pub detected_s: f64,
    /// Belief over states after the step.
    pub belief: Vec<f32>,
    /// Reported only because the audio ended (`Controller::finish` closed it): no detection
    /// latency is measured for it.
    pub flushed: bool,
}

impl StepRecord {
    /// Detection latency (s): `detected_s - end_s`.
    pub fn latency_s(&self) -> f64 {
        self.detected_s - self.end_s
    }
}

/// One decision at an exit point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DecisionRecord {
    /// Animation tick.
    pub tick: u64,
    /// Tick time (s).
    pub time_s: f64,
    /// Exit point index.
    pub exit: usize,
    /// The exit point's segment.
    pub exit_segment: usize,
    /// The exit point's frame within its segment.
    pub exit_frame: usize,
    /// Segment entered, `None` for "continue".
    pub entered: Option<usize>,
    /// Candidates weighed.
    pub candidates: usize,
    /// Expected cost of the choice.
    pub cost: f32,
    /// The style in force (index into [`Simulation::styles`]).
    pub style: usize,
}

/// Everything a run produced.
#[derive(Clone, Debug, Default)]
pub struct Simulation {
    /// Front-end rate (Hz).
    pub sample_rate_hz: u32,
    /// Animation ticks per second (the library's fps).
    pub fps: f64,
    /// Audio duration (s).
    pub duration_s: f64,
    /// Prosody frames.
    pub frames: Vec<FrameRecord>,
    /// Steps with beliefs.
    pub steps: Vec<StepRecord>,
    /// Decisions.
    pub decisions: Vec<DecisionRecord>,
    /// One pose per tick (rig channel values, degrees).
    pub poses: Vec<Vec<f32>>,
    /// Per tick, the library segment and frame shown.
    pub shown: Vec<(usize, usize)>,
    /// What the controller asked of its player, with the tick each command precedes (what a
    /// show file records).
    pub plays: Vec<(u64, PlayerCommand)>,
    /// One row of duty cycles per tick, from the virtual servo rig.
    pub duties: Vec<Vec<u16>>,
    /// One row per tick of the angles (deg) the servo rig commanded: the pose within the
    /// calibration's limits and slew rate (what `--ros2` and `--mcap` publish).
    pub angles: Vec<Vec<f32>>,
    /// Wall-clock time of the simulation (s).
    pub wall_s: f64,
    /// The style changes applied, in time order (the first at time 0; neutral if none given).
    pub styles: Vec<StyleChange>,
    /// The semantic labels given, in time order, and what became of them.
    pub labels: Vec<LabelRecord>,
}

/// A semantic label to give the controller at an audio time.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelPush {
    /// Audio time (s).
    pub time_s: f64,
    /// Label index (the blob's order).
    pub label: usize,
    /// Where it came from (`track`, `keyword`, `key`).
    pub source: String,
}

/// A label given to the controller and what became of it.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelRecord {
    /// When it reached the controller (s, audio clock).
    pub time_s: f64,
    /// Label index.
    pub label: usize,
    /// Where it came from.
    pub source: String,
    /// Whether the controller took it in (not refused for a full queue).
    pub accepted: bool,
    /// Whether the controller has reported it received (it may wait behind another).
    pub received: bool,
    /// The segment entered for it, and the frame it was entered at.
    pub segment: Option<(usize, usize)>,
    /// When that segment was entered (s).
    pub entered_s: Option<f64>,
    /// When its stroke frame played (s).
    pub stroke_s: Option<f64>,
    /// It waited past the blob's timeout and was dropped.
    pub timed_out: bool,
}

impl Simulation {
    /// Detection latencies of the syllables (not pause steps, not those closed by the end of
    /// the audio), in order (s).
    pub fn syllable_latencies(&self) -> Vec<f64> {
        self.steps
            .iter()
            .filter(|s| s.kind == StepKind::Syllable && !s.flushed)
            .map(StepRecord::latency_s)
            .collect()
    }

    /// The tone weights in force at `decision` (index into `decisions`).
    pub fn style_at(&self, decision: usize) -> &[f32] {
        self.decisions
            .get(decision)
            .and_then(|d| self.styles.get(d.style))
            .map_or(&[], |s| &s.weights)
    }

    /// Audio seconds per wall-clock second.
    pub fn speed(&self) -> f64 {
        self.duration_s / self.wall_s.max(1e-9)
    }
}

/// Median and maximum of `v` (`None` if empty).
pub fn median_max(v: &[f64]) -> Option<(f64, f64)> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    let median = if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    };
    Some((median, s[n - 1]))
}

/// How to run.
#[derive(Clone, Copy, Debug)]
pub struct SimOptions {
    /// Samples per chunk (>= 1).
    pub chunk: usize,
    /// Pace the chunks on the wall clock.
    pub realtime: bool,
    /// How long before it is played the controller hears the audio.
    pub lookahead: Lookahead,
}

/// Splits `samples` into chunks of `chunk`, and also at every sample index in `cuts` (sorted):
/// `(start, end)` ranges.
fn chunk_ranges(len: usize, chunk: usize, cuts: &[usize]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    let mut cut = cuts
        .iter()
        .copied()
        .filter(|&c| c > 0 && c < len)
        .peekable();
    while start < len {
        let mut end = (start + chunk.max(1)).min(len);
        while let Some(&c) = cut.peek() {
            if c <= start {
                cut.next();
            } else {
                if c < end {
                    end = c;
                }
                break;
            }
        }
        out.push((start, end));
        start = end;
    }
    out
}

/// Runs `samples` (at the blob's rate) through the device loop of `blob` (the runtime's
/// [`Device`]: its controller and its servo rig on virtual pins), with servo calibrations
/// `cals` and PWM period `period_us`. Each of `styles` (time order) is given to the controller
/// when the audio reaches its time (chunks are split there, which changes nothing else: the
/// controller's output does not depend on the chunking); none: neutral throughout.
pub fn simulate(
    blob: &Blob<'_>,
    samples: &[i16],
    cals: &[ChannelCal],
    period_us: f32,
    opts: SimOptions,
    styles: &[StyleChange],
    labels: &[LabelPush],
) -> Result<Simulation, String> {
    let mut slot = Box::new(None);
    let controller = BlobController::from_blob_in(&mut slot, blob).map_err(|e| e.to_string())?;
    let mut device: Device<'_, '_, VirtualPin, MAX_CHANNELS> = Device::calibrated(
        controller,
        [VirtualPin::default(); MAX_CHANNELS],
        Some((cals, period_us)),
    )
    .map_err(|e| e.to_string())?;
    device.controller_mut().set_lookahead(opts.lookahead);
    let rate = blob.prosody_config().sample_rate_hz;
    let mut sim = Simulation {
        sample_rate_hz: rate,
        fps: blob.fps() as f64,
        duration_s: samples.len() as f64 / rate as f64,
        ..Simulation::default()
    };
    let channels = blob.channels();
    let at = |c: &StyleChange| (c.time_s * rate as f64).round().max(0.0) as usize;
    let label_at = |l: &LabelPush| (l.time_s * rate as f64).round().max(0.0) as usize;
    let mut cuts: Vec<usize> = styles
        .iter()
        .map(at)
        .chain(labels.iter().map(label_at))
        .collect();
    cuts.sort_unstable();
    let mut next_label = 0usize;
    let mut next_style = 0usize;
    let mut style = 0usize;
    let start = Instant::now();
    let mut pushed = 0usize;
    for (a, b) in chunk_ranges(samples.len(), opts.chunk, &cuts) {
        while next_style < styles.len() && at(&styles[next_style]) <= a {
            device
                .controller_mut()
                .set_style(&styles[next_style].weights)
                .map_err(|e| format!("style at {:.3} s: {e}", styles[next_style].time_s))?;
            sim.styles.push(styles[next_style].clone());
            style = sim.styles.len() - 1;
            next_style += 1;
        }
        while next_label < labels.len() && label_at(&labels[next_label]) <= a {
            let l = &labels[next_label];
            let accepted = device.controller_mut().push_label(l.label).is_ok();
            sim.labels.push(LabelRecord {
                time_s: a as f64 / rate as f64,
                label: l.label,
                source: l.source.clone(),
                accepted,
                received: false,
                segment: None,
                entered_s: None,
                stroke_s: None,
                timed_out: false,
            });
            next_label += 1;
        }
        let chunk = &samples[a..b];
        pushed += chunk.len();
        let now_s = pushed as f64 / rate as f64;
        if opts.realtime {
            let due = Duration::from_secs_f64(now_s);
            if let Some(wait) = due.checked_sub(start.elapsed()) {
                std::thread::sleep(wait);
            }
        }
        // Virtual pins cannot fail.
        let _ = device.push(chunk, &mut |e| {
            record(&mut sim, blob, channels, now_s, false, style, e)
        });
    }
    // With look-ahead, the recording is followed by that much silence (nothing more is heard),
    // so every tick of the audio is played.
    let pad = (opts.lookahead.ms as usize * rate as usize).div_ceil(1000);
    if pad > 0 {
        let silence = vec![0i16; pad];
        let now_s = pushed as f64 / rate as f64;
        for chunk in silence.chunks(opts.chunk.max(1)) {
            let _ = device.push(chunk, &mut |e| {
                record(&mut sim, blob, channels, now_s, false, style, e)
            });
        }
    }
    let now_s = pushed as f64 / rate as f64;
    let _ = device.finish(&mut |e| record(&mut sim, blob, channels, now_s, true, style, e));
    if sim.styles.is_empty() {
        sim.styles.push(StyleChange {
            time_s: 0.0,
            weights: vec![0.0; blob.tones()],
        });
    }
    sim.wall_s = start.elapsed().as_secs_f64();
    Ok(sim)
}

/// Records one device event (`now_s`: the sample clock at the end of the current chunk;
/// `flushed`: reported by the end of the stream).
fn record(
    sim: &mut Simulation,
    blob: &Blob<'_>,
    channels: usize,
    now_s: f64,
    flushed: bool,
    style: usize,
    e: DeviceEvent<'_, VirtualPin, MAX_CHANNELS>,
) {
    let fps = sim.fps;
    let e = match e {
        DeviceEvent::Servos { rig, .. } => {
            sim.duties.push(
                rig.pins()[..channels]
                    .iter()
                    .map(VirtualPin::duty)
                    .collect(),
            );
            sim.angles.push(rig.angles()[..channels].to_vec());
            return;
        }
        DeviceEvent::Controller(e) => e,
    };
    match e {
        ControllerEvent::Frame(f) => sim.frames.push(FrameRecord {
            time_s: f.time_s(),
            intensity_db: f.intensity_db,
            f0_hz: f.f0_hz,
        }),
        ControllerEvent::Step { step, belief } => sim.steps.push(StepRecord {
            kind: step.kind,
            start_s: step.start_s(),
            end_s: step.end_s(),
            f0_hz: step.f0_hz,
            intensity_db: step.intensity_db,
            length_s: step.length_s(),
            detected_s: now_s,
            belief: belief.to_vec(),
            flushed,
        }),
        ControllerEvent::Decision { tick, decision } => {
            let x = blob.exit(decision.exit);
            sim.decisions.push(DecisionRecord {
                tick,
                time_s: tick as f64 / fps,
                exit: decision.exit,
                exit_segment: x.map_or(0, |x| x.segment as usize),
                exit_frame: x.map_or(0, |x| x.frame as usize),
                entered: match decision.choice {
                    Choice::Continue => None,
                    Choice::Enter(c) => Some(c),
                },
                candidates: decision.candidates,
                cost: decision.cost,
                style,
            })
        }
        ControllerEvent::Pose {
            pose,
            segment,
            frame,
            ..
        } => {
            sim.poses.push(pose.to_vec());
            sim.shown.push((segment, frame));
        }
        ControllerEvent::Onset(_) => {}
        ControllerEvent::Play { tick, command } => sim.plays.push((tick, command)),
        ControllerEvent::Label {
            tick,
            label,
            outcome,
        } => {
            let t = tick as f64 / fps;
            // The record this event is about: the first accepted one of this label not yet
            // received (for `Received`), else the latest received and unfinished one.
            let open = |r: &LabelRecord| {
                r.label == label && r.accepted && r.stroke_s.is_none() && !r.timed_out
            };
            let k = match outcome {
                LabelOutcome::Received => sim.labels.iter().position(|r| open(r) && !r.received),
                _ => sim.labels.iter().rposition(|r| open(r) && r.received),
            };
            let Some(r) = k.and_then(|k| sim.labels.get_mut(k)) else {
                return;
            };
            match outcome {
                LabelOutcome::Received => r.received = true,
                LabelOutcome::Entered { segment, frame } => {
                    r.segment = Some((segment, frame));
                    r.entered_s = Some(t);
                }
                LabelOutcome::Stroke => r.stroke_s = Some(t),
                LabelOutcome::TimedOut => r.timed_out = true,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunks_are_split_at_style_changes() {
        assert_eq!(
            chunk_ranges(10, 4, &[0, 6, 8, 20]),
            [(0, 4), (4, 6), (6, 8), (8, 10)]
        );
        assert_eq!(chunk_ranges(5, 10, &[]), [(0, 5)]);
        assert_eq!(chunk_ranges(0, 10, &[3]), []);
        assert_eq!(chunk_ranges(6, 3, &[3, 3]), [(0, 3), (3, 6)]);
    }
}
