//! Playing a blob as the evaluations do: the runtime's device loop on audio samples
//! (`play_online`, `play_delayed`), a schedule of library frames through the runtime's
//! player ([`play_schedule`]), and the audio shuffled in blocks for the ablation
//! ([`shuffle_blocks`]). What was shown comes back as a [`Playback`].

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, ControllerEvent, Lookahead};
use gesture_runtime::device::{Device, DeviceEvent, NullPin};
use gesture_runtime::player::{Player, MAX_CHANNELS};
use gesture_runtime::policy::Choice;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::error::EvalError;
use crate::control::schedule::Played;

/// What a playback showed: per tick the pose, and the segment and frame it came from.
#[derive(Clone, Debug, Default)]
pub struct Playback {
    /// One pose per tick (rig channels, degrees).
    pub poses: Vec<Vec<f32>>,
    /// Per tick, (segment, frame) shown.
    pub shown: Vec<(usize, usize)>,
}

/// One online decision: exit, choice, and the belief it was made with.
#[derive(Clone, Debug)]
pub(crate) struct Made {
    /// The exit point decided at.
    pub(crate) exit: usize,
    /// The choice.
    pub(crate) choice: Choice,
    /// The belief it was made with.
    pub(crate) belief: Vec<f64>,
}

/// Runs the blob's device loop on `samples` (starting at segment 0), after `setup` on its
/// controller; returns the first `frames` ticks (the last one repeated if the audio ends
/// earlier) and the decisions.
pub(crate) fn play_online(
    blob: &Blob<'_>,
    samples: &[i16],
    frames: usize,
    setup: impl FnOnce(&mut BlobController<'_>),
) -> Result<(Playback, Vec<Made>), EvalError> {
    let mut slot = Box::new(None);
    let controller = BlobController::from_blob_in(&mut slot, blob)
        .map_err(|e| EvalError::Device(e.to_string()))?;
    setup(controller);
    let mut device: Device<'_, '_, NullPin, MAX_CHANNELS> =
        Device::new(controller, [NullPin; MAX_CHANNELS])
            .map_err(|e| EvalError::Device(e.to_string()))?;
    let mut out = Playback::default();
    let mut made = Vec::new();
    let states = blob.states();
    let mut belief: Vec<f64> = vec![1.0 / states as f64; states];
    // Null pins cannot fail.
    let _ = device.push(samples, &mut |ev| match ev {
        DeviceEvent::Controller(ControllerEvent::Pose {
            pose,
            segment,
            frame,
            ..
        }) => {
            out.poses.push(pose.to_vec());
            out.shown.push((segment, frame));
        }
        DeviceEvent::Controller(ControllerEvent::Step { belief: b, .. }) => {
            belief = b.iter().map(|&v| v as f64).collect();
        }
        DeviceEvent::Controller(ControllerEvent::Decision { decision, .. }) => made.push(Made {
            exit: decision.exit,
            choice: decision.choice,
            belief: belief.clone(),
        }),
        _ => {}
    });
    hold_to(&mut out, frames);
    Ok((out, made))
}

/// The device's motion on `samples` after `lead` of silence (as [`play_delayed`]) with the controller hearing the audio `l.ms` before it is played: fed
/// the samples followed by that much silence (after a recording, nothing), so every tick of
/// the audio is played.
pub(crate) fn play_ahead(
    blob: &Blob<'_>,
    samples: &[i16],
    rate: u32,
    frames: usize,
    lead: Lead,
    l: Lookahead,
) -> Result<Playback, EvalError> {
    let mut input = samples.to_vec();
    input.resize(
        samples.len() + (l.ms as usize * rate as usize).div_ceil(1000),
        0,
    );
    let (p, _) = play_delayed(blob, &input, rate, frames, lead, |c| c.set_lookahead(l))?;
    Ok(p)
}

/// The whole of `samples` after `lead` of silence planned and played from its show
/// ([`crate::bake`]), measured from the end of the lead's whole frames (`frames` ticks), as
/// [`play_delayed`] measures a live run: one plan is one draw of where the speech meets the
/// front-end's frames and the animation's ticks.
pub(crate) fn play_baked(
    blob: &Blob<'_>,
    samples: &[i16],
    rate: u32,
    frames: usize,
    lead: Lead,
) -> Result<Playback, EvalError> {
    let delay = lead.frames;
    let input = lead.before(samples, rate, blob.fps());
    let baked = crate::bake::bake_after(blob, &input, delay as u64)
        .map_err(|e| EvalError::Device(e.to_string()))?;
    let poses = baked
        .play(blob)
        .map_err(|e| EvalError::Device(e.to_string()))?;
    let mut out = Playback::default();
    for p in poses.into_iter().skip(delay) {
        out.shown.push((p.segment, p.frame));
        out.poses.push(p.pose);
    }
    hold_to(&mut out, frames);
    Ok(out)
}

/// Truncates or extends (repeating the last tick) a playback to `frames` ticks.
fn hold_to(p: &mut Playback, frames: usize) {
    p.poses.truncate(frames);
    p.shown.truncate(frames);
    if let (Some(pose), Some(&shown)) = (p.poses.last().cloned(), p.shown.last()) {
        p.poses.resize(frames, pose);
        p.shown.resize(frames, shown);
    }
}

/// Plays a schedule of library frames through the runtime's player over the blob's frames,
/// with the blob's inertialization at every entry (set up as the controller's: blend time,
/// speed cap, rest segments).
pub fn play_schedule(blob: &Blob<'_>, schedule: &[Played]) -> Playback {
    let mut player = Player::new();
    let blend = (blob.blend_ms() as f64 * blob.fps() as f64 / 1000.0).ceil() as u32;
    player.set_blend_ticks(blend);
    player.set_speed_cap(gesture_runtime::player::library_speed_cap(blob));
    player.set_rest_segments(gesture_runtime::follow::rest_segments(
        blob,
        gesture_runtime::player::LibraryFrames::segment_count(blob),
        &blob.follow(),
    ));
    let mut out = Playback::default();
    let mut pose = [0.0f32; MAX_CHANNELS];
    let n = blob.channels();
    for (t, p) in schedule.iter().enumerate() {
        let entered = t > 0 && (p.segment != schedule[t - 1].segment || p.frame == 0);
        if entered {
            player.enter(blob, p.segment);
        }
        let f = player.tick(blob, &mut pose);
        out.poses.push(pose[..n].to_vec());
        out.shown.push((player.segment(), f));
    }
    out
}

/// The audio cut into 1 s blocks and played in a seeded shuffled order.
pub fn shuffle_blocks(samples: &[i16], rate: u32, seed: u64) -> Vec<i16> {
    let block = rate.max(1) as usize;
    let mut blocks: Vec<&[i16]> = samples.chunks(block).collect();
    blocks.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
    blocks.concat()
}

/// Where a device run's speech starts: after `frames` animation frames of silence and
/// `phase` samples more (less than one of the front-end's 10 ms frames), so that runs meet
/// the speech both with the animation elsewhere and at another point of the front-end's frame
/// grid. With whole frames alone, every run that began with a rest (half a second of silence)
/// heard exactly the same samples in the same frames and made the same choices from then on:
/// 30 runs were three or four draws. A real microphone meets the speech at any phase.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Lead {
    /// Animation frames of silence (the measured trace starts after them).
    pub frames: usize,
    /// Samples of silence more, less than one front-end frame (the speech then starts that
    /// much after the trace's time 0: under 10 ms).
    pub phase: usize,
}

/// The fractional part of the golden ratio: run `k`'s phase is `frac(k * GOLDEN)` of a
/// front-end frame, so any number of runs spreads evenly over the frame.
const GOLDEN: f64 = 0.618_033_988_749_894_9;

impl Lead {
    /// Run `run` of a series: `run * step` frames and a phase spread over the front-end's
    /// 10 ms frame at `rate` Hz (run 0: no lead at all).
    pub fn of_run(run: usize, step: usize, rate: u32) -> Self {
        let hop = (rate / 100).max(1) as f64;
        Self {
            frames: run * step,
            phase: ((run as f64 * GOLDEN).fract() * hop) as usize,
        }
    }

    /// `samples` at `rate` Hz after the lead's silence, its frames at `fps`.
    fn before(&self, samples: &[i16], rate: u32, fps: f32) -> Vec<i16> {
        let silence =
            (self.frames as f64 * rate as f64 / fps.max(1.0) as f64).round() as usize + self.phase;
        let mut input = vec![0i16; silence];
        input.extend_from_slice(samples);
        input
    }
}

/// The device's motion on `samples` after `lead` of silence, measured from the end of the
/// lead's whole frames (`frames` ticks), and its decisions.
pub(crate) fn play_delayed(
    blob: &Blob<'_>,
    samples: &[i16],
    rate: u32,
    frames: usize,
    lead: Lead,
    setup: impl FnOnce(&mut BlobController<'_>),
) -> Result<(Playback, Vec<Made>), EvalError> {
    let delay = lead.frames;
    let input = lead.before(samples, rate, blob.fps());
    let (mut p, made) = play_online(blob, &input, frames + delay, setup)?;
    p.poses.drain(..delay.min(p.poses.len()));
    p.shown.drain(..delay.min(p.shown.len()));
    Ok((p, made))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corpus::{load_corpus, LoadOptions};
    use crate::inference::train::{fit, sequences, FitConfig};
    use crate::pack::{pack_model, PackOptions};
    use crate::synth::{write_corpus, SynthParams};

    /// A delayed device run is the undelayed run of the longer input with the lead cut off:
    /// on silence (nothing for the controller to hear) delaying by `d` frames shows, at every
    /// tick, what a run `d` frames longer shows `d` ticks later; and it always has `frames`
    /// ticks.
    #[test]
    fn a_delayed_run_is_the_longer_run_without_its_lead() {
        let dir = tempfile::tempdir().unwrap();
        let params = SynthParams {
            minutes: 0.5,
            seed: 5,
            take_seconds: 30.0,
        };
        write_corpus(&params, dir.path(), |_, _| {}).unwrap();
        let c = load_corpus(&[dir.path().to_path_buf()], &LoadOptions::default()).unwrap();
        let (seqs, segs) = sequences(&c, None);
        let cfg = FitConfig {
            states: Some(2),
            clusters: Some(2),
            restarts: 1,
            l2: Some(1e-2),
            ..FitConfig::default()
        };
        let (model, _) = fit(&seqs, &segs, &cfg, &|_| {}).unwrap();
        let packed =
            pack_model(&model, &[dir.path().to_path_buf()], &PackOptions::default()).unwrap();
        let blob = Blob::parse(&packed.bytes).unwrap();
        let rate = model.sample_rate_hz;
        let fps = blob.fps() as f64;
        let frames = (3.0 * fps) as usize;
        let silence = vec![0i16; 3 * rate as usize];
        let d = 7;
        let run_lead = Lead {
            frames: d,
            phase: 53,
        };
        let (delayed, _) = play_delayed(&blob, &silence, rate, frames, run_lead, |_| {}).unwrap();
        assert_eq!(delayed.poses.len(), frames);
        let lead = (d as f64 * rate as f64 / fps).round() as usize + 53;
        let longer = vec![0i16; lead + silence.len()];
        let (whole, _) = play_online(&blob, &longer, frames + d, |_| {}).unwrap();
        assert_eq!(delayed.poses[..], whole.poses[d..]);
        assert_eq!(delayed.shown[..], whole.shown[d..]);
        // No delay: the plain run.
        let (plain, _) =
            play_delayed(&blob, &silence, rate, frames, Lead::default(), |_| {}).unwrap();
        assert_eq!(plain.poses[..], whole.poses[..frames]);
        // A whole-file plan likewise: the plan of the longer input, its lead cut off.
        let baked = play_baked(&blob, &silence, rate, frames, run_lead).unwrap();
        assert_eq!(baked.poses.len(), frames);
        let plan = crate::bake::bake_after(&blob, &longer, d as u64)
            .unwrap()
            .play(&blob)
            .unwrap();
        let shown: Vec<(usize, usize)> = plan.iter().map(|p| (p.segment, p.frame)).collect();
        assert_eq!(baked.shown[..], shown[d..d + frames]);
        assert!(baked
            .poses
            .iter()
            .zip(&plan[d..])
            .all(|(a, b)| *a == b.pose));
    }

    /// Known answer: run 0 has no lead; run `k` is `k` steps of frames and a phase under one
    /// 10 ms front-end frame (160 samples at 16 kHz), and 30 runs leave no tenth of the frame
    /// without a phase (the golden-ratio sequence spreads evenly).
    #[test]
    fn runs_spread_their_phase_over_the_front_end_frame() {
        assert_eq!(Lead::of_run(0, 12, 16_000), Lead::default());
        assert_eq!(
            Lead::of_run(1, 12, 16_000),
            Lead {
                frames: 12,
                phase: 98
            }
        );
        assert_eq!(Lead::of_run(2, 12, 16_000).phase, 37);
        let phases: Vec<usize> = (0..30).map(|k| Lead::of_run(k, 12, 16_000).phase).collect();
        assert!(phases.iter().all(|&p| p < 160));
        for tenth in 0..10 {
            assert!(
                phases.iter().any(|&p| p / 16 == tenth),
                "no phase in tenth {tenth}: {phases:?}"
            );
        }
        // Whatever the rate, under one frame.
        assert!((0..100).all(|k| Lead::of_run(k, 1, 44_100).phase < 441));
    }
}
