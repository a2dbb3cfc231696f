//! Motion quality on held-out audio (`gesture-train eval-motion`): every method's motion,
//! measured the same way ([`crate::evaluate::metrics`]):
//!
//! - `online`: the controller as a board runs it;
//! - `online_pure`: the same tables without the variety costs (the paper's selection rule
//!   over this blob's tables);
//! - `online_prior`: an ablation, the belief held at the state prior (the speech's prosody
//!   no longer informs the choice; decisions are still timed on its onsets);
//! - `online_shuffled`: an ablation, the controller on the audio cut into 1 s blocks played
//!   in a shuffled order (seeded), measured against the real audio's onsets;
//! - `random`: a uniformly random segment at every segment end (mean over seeded runs; the
//!   variety figures are of the first run);
//! - `offline_dp`: the offline dynamic-programming sequence (posteriors that see the whole
//!   utterance);
//! - `mocap`: the motion capture of the audio, when given (with its root motion).
//!
//! **Everything runs the bytes `pack` writes.** The model and library are packed in memory
//! ([`pack_model`]) and read back with `Blob::parse`; the online methods run the runtime's
//! device loop ([`Device`]) on the audio's samples, and random and DP are played through the
//! runtime's own [`Player`] over the blob's frames (the same inertialized cuts). Every pose is
//! put back on the library's skeleton ([`PoseSkeleton`]) and measured there, so the figures
//! describe what a viewer of the character sees.
//!
//! **The hand-speed reference.** With `--mocap`, the capture of the speech itself. Without
//! one (another speaker's speech), [`speech_matched_reference`]: the library's capture in
//! its syllables and in its pauses, weighed as the new speech has them. Either is taken *as
//! the character shows it* ([`translation_held`]: the lower body held as `pack` holds it,
//! no translation): the hands of a speaker who walks or sways move faster in the world than
//! any played motion can, since a blob holds rotations only (the 067 take's root moves at a
//! median 8.5 cm/s; with it, its reference for beat-scott put 6.6 % of the frames below
//! 10 cm/s, as shown 11.9 %). The library's whole capture, the reference before, rewarded
//! playing the library's own mix of rest and motion whatever the speech: the 9-joint
//! ZeroEGGS take rests through long pauses (a third of its frames below 10 cm/s) that a
//! monologue does not have, so uniformly random choices were closest to it and a controller
//! that gestures while the speaker talks was furthest.
//!
//! **Regret of variety.** For every decision of the online run, the float, unpruned policy's
//! expected cost of the choice made is compared with the best choice under the same belief
//! (variety costs and voice terms excluded): `variety_regret` is the excess over the best, as a
//! fraction; it counts what the variety costs and following the voice give up of the paper's
//! objective.

use std::path::PathBuf;

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, ControllerEvent};
use gesture_runtime::device::{Device, DeviceEvent, NullPin};
use gesture_runtime::inference::StepNormalizer;
use gesture_runtime::player::{LibraryFrames, Player, MAX_CHANNELS};
use gesture_runtime::policy::{Choice, Variety};
use gesture_runtime::prosody::{ProsodyConfig, Step, StepKind};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::metrics::{
    entries_from_frames, measure, speed_histogram, speed_histogram_where, Entry, MotionMetrics,
    Speech, Trace,
};
use crate::control::mdp::Action;
use crate::control::schedule::{play_dp, play_random, Played};
use crate::inference::model::InferenceModel;
use crate::inference::train::prosody_point;
use crate::motion::{analyze, read_bvh, EffectorSpec, Motion, SegmentParams};
use crate::pack::{hold_lower_bodies, pack_model, PackError, PackOptions};
use crate::rig::PoseSkeleton;

/// What to evaluate.
#[derive(Clone, Debug)]
pub struct MotionEval {
    /// Gesture library (BVH files or folders).
    pub library: Vec<PathBuf>,
    /// Held-out speech: one or more WAV files, played one after the other.
    pub audio: Vec<PathBuf>,
    /// The real motion of that speech (one audio file only).
    pub mocap: Option<PathBuf>,
    /// Only this span of the audio (and motion capture), seconds.
    pub span: Option<(f64, f64)>,
    /// Random runs to average.
    pub random_runs: u64,
    /// Runs of each device method to average (the speech delayed by [`PHASE_STEP_S`]
    /// more of silence each time; 1: the device as it runs, alone).
    pub device_runs: u64,
    /// How to pack (costs, device settings, effectors); the rig is the library's full
    /// skeleton.
    pub pack: PackOptions,
}

/// One method's row.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// Method name.
    pub method: String,
    /// Its figures (means over its runs; the variety figures are the first run's).
    #[serde(flatten)]
    pub metrics: MotionMetrics,
    /// Runs averaged.
    pub runs: usize,
    /// Run-to-run standard deviation of the timing and distribution figures (`None` for one
    /// run): how far apart two methods must be for a difference to mean something.
    pub spread: Option<Spread>,
}

/// Sample standard deviations over a method's runs.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct Spread {
    /// Of [`MotionMetrics::speech_coupling`].
    pub speech_coupling: f64,
    /// Of [`MotionMetrics::beat_alignment`].
    pub beat_alignment: f64,
    /// Of [`MotionMetrics::hellinger`].
    pub hellinger: Option<f64>,
}

impl Row {
    /// The row of `method` from its runs' figures (see [`mean`]).
    fn of_runs(method: &str, runs: &[MotionMetrics]) -> Self {
        Self {
            method: method.into(),
            metrics: mean(runs),
            runs: runs.len(),
            spread: spread(runs),
        }
    }
}

/// Sample standard deviation of `f` over `runs` (`None` with fewer than two runs).
fn sd(runs: &[MotionMetrics], f: impl Fn(&MotionMetrics) -> Option<f64>) -> Option<f64> {
    let v: Vec<f64> = runs.iter().map(f).collect::<Option<_>>()?;
    if v.len() < 2 {
        return None;
    }
    let m = v.iter().sum::<f64>() / v.len() as f64;
    Some((v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt())
}

fn spread(runs: &[MotionMetrics]) -> Option<Spread> {
    Some(Spread {
        speech_coupling: sd(runs, |m| Some(m.speech_coupling))?,
        beat_alignment: sd(runs, |m| Some(m.beat_alignment))?,
        hellinger: sd(runs, |m| m.hellinger),
    })
}

/// An evaluation's result.
#[derive(Debug, Clone, Serialize)]
pub struct Evaluation {
    /// One row per method.
    pub rows: Vec<Row>,
    /// Library segments.
    pub library_segments: usize,
    /// Online decisions.
    pub decisions: usize,
    /// Expected-cost excess of the online choices over the pure policy's best (fraction).
    pub variety_regret: f64,
    /// Seconds of audio.
    pub seconds: f64,
}

/// Why an evaluation failed.
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    /// Packing the model and library.
    #[error(transparent)]
    Pack(#[from] PackError),
    /// Reading the audio.
    #[error(transparent)]
    Audio(#[from] crate::audio::AudioError),
    /// Reading the motion capture.
    #[error(transparent)]
    Bvh(#[from] crate::motion::BvhError),
    /// Analysing motion, speech or the options.
    #[error("{0}")]
    Input(String),
    /// The device refused the packed blob or a pose could not be rebuilt (a packer bug).
    #[error("the packed blob: {0}")]
    Device(String),
}

impl EvalError {
    /// Whether the user's input is at fault.
    pub fn is_input(&self) -> bool {
        match self {
            Self::Pack(e) => e.is_input(),
            Self::Device(_) => false,
            _ => true,
        }
    }
}

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
    exit: usize,
    choice: Choice,
    belief: Vec<f64>,
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
/// with the blob's inertialization at every entry.
pub fn play_schedule(blob: &Blob<'_>, schedule: &[Played]) -> Playback {
    let mut player = Player::new();
    let blend = (blob.blend_ms() as f64 * blob.fps() as f64 / 1000.0).ceil() as u32;
    player.set_blend_ticks(blend);
    player.set_speed_cap(gesture_runtime::player::library_speed_cap(blob));
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

/// The trace of a playback on the blob's skeleton.
fn trace_of(
    blob: &Blob<'_>,
    skeleton: &PoseSkeleton,
    p: &Playback,
    pack: &PackOptions,
) -> Result<Trace, EvalError> {
    let motion = skeleton
        .motion(&p.poses, blob.fps() as f64)
        .map_err(|e| EvalError::Device(e.to_string()))?;
    let entries = entries_from_frames(&p.shown, |s| blob.continues(s), |s| blob.segment_len(s));
    Trace::from_motion(&motion, &pack.effectors, entries).map_err(EvalError::Device)
}

/// The audio's samples (files in order, the span applied) at the model's rate.
pub(crate) fn load_audio(model: &InferenceModel, e: &MotionEval) -> Result<Vec<i16>, EvalError> {
    let rate = model.sample_rate_hz as f64;
    let mut all = Vec::new();
    for path in &e.audio {
        let pcm = crate::audio::load_wav_at(path, model.sample_rate_hz)?;
        let (s0, s1) = e.span.unwrap_or((0.0, f64::INFINITY));
        let i0 = ((s0 * rate) as usize).min(pcm.samples.len());
        let i1 = ((s1 * rate).min(pcm.samples.len() as f64) as usize).max(i0);
        all.extend_from_slice(&pcm.samples[i0..i1]);
    }
    Ok(all)
}

/// The audio cut into 1 s blocks and played in a seeded shuffled order.
pub fn shuffle_blocks(samples: &[i16], rate: u32, seed: u64) -> Vec<i16> {
    let block = rate.max(1) as usize;
    let mut blocks: Vec<&[i16]> = samples.chunks(block).collect();
    blocks.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
    blocks.concat()
}

/// The motion capture of the span as a trace (its own segmentation gives the entries).
fn mocap_trace(
    path: &std::path::Path,
    e: &MotionEval,
    frames_at: impl Fn(f64) -> usize,
) -> Result<(Trace, Motion), EvalError> {
    let mo = read_bvh(path)?;
    let s0 = e.span.map_or(0.0, |s| s.0);
    let f0 = ((s0 * mo.fps()) as usize).min(mo.frames());
    let f1 = (f0 + frames_at(mo.fps())).min(mo.frames());
    let sub = mo
        .slice(f0, f1)
        .ok_or_else(|| EvalError::Input(format!("{}: no frames in the span", path.display())))?;
    let an = analyze(&sub, &e.pack.effectors, &SegmentParams::default())
        .map_err(|x| EvalError::Input(format!("{}: {x}", path.display())))?;
    let entries: Vec<Entry> = an
        .segments
        .iter()
        .enumerate()
        .map(|(k, s)| Entry {
            frame: s.start_frame,
            segment: k,
            cut: false,
        })
        .collect();
    let t = Trace::from_motion(&sub, &e.pack.effectors, entries).map_err(EvalError::Input)?;
    Ok((t, sub))
}

/// The device methods: the controller as packed and its ablations (see the module docs).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Ablation {
    None,
    Pure,
    Prior,
    Shuffled,
}

impl Ablation {
    fn name(self) -> &'static str {
        match self {
            Self::None => "online",
            Self::Pure => "online_pure",
            Self::Prior => "online_prior",
            Self::Shuffled => "online_shuffled",
        }
    }
}

/// The delay between two device runs (s), rounded to whole animation frames.
pub const PHASE_STEP_S: f64 = 0.2;

/// Device runs (and random runs) a [`MotionEval`] averages by default. Single runs of one
/// method on two minutes of speech spread by 0.02-0.04 in beat alignment and about 0.08 in
/// speech coupling (standard deviations), as much as the methods differ; 30 runs bring a
/// mean's standard error to about a fifth of that (10 left it at a third, and comparisons
/// that flipped between settings).
pub const DEFAULT_DEVICE_RUNS: u64 = 30;

/// The device's motion on `samples` delayed by `delay` frames of silence, measured from where
/// the speech starts (`frames` ticks), and its decisions.
pub(crate) fn play_delayed(
    blob: &Blob<'_>,
    samples: &[i16],
    rate: u32,
    frames: usize,
    delay: usize,
    setup: impl FnOnce(&mut BlobController<'_>),
) -> Result<(Playback, Vec<Made>), EvalError> {
    let lead = (delay as f64 * rate as f64 / blob.fps().max(1.0) as f64).round() as usize;
    let mut input = vec![0i16; lead];
    input.extend_from_slice(samples);
    let (mut p, made) = play_online(blob, &input, frames + delay, setup)?;
    p.poses.drain(..delay.min(p.poses.len()));
    p.shown.drain(..delay.min(p.shown.len()));
    Ok((p, made))
}

fn mean(ms: &[MotionMetrics]) -> MotionMetrics {
    let n = ms.len().max(1) as f64;
    let avg = |f: fn(&MotionMetrics) -> f64| ms.iter().map(f).sum::<f64>() / n;
    let avg_opt =
        |f: fn(&MotionMetrics) -> Option<f64>| ms.iter().map(f).sum::<Option<f64>>().map(|v| v / n);
    // The voice figures are `None` in a run without a pause in reach: the mean of the others.
    let avg_some = |f: fn(&MotionMetrics) -> Option<f64>| {
        let v: Vec<f64> = ms.iter().filter_map(f).collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
    };
    MotionMetrics {
        seconds: avg(|m| m.seconds),
        still_share: avg(|m| m.still_share),
        foot_speed: avg_opt(|m| m.foot_speed),
        mean_jerk: avg(|m| m.mean_jerk),
        jump_at_cuts: avg(|m| m.jump_at_cuts),
        max_jump_at_cuts: ms.iter().map(|m| m.max_jump_at_cuts).fold(0.0, f64::max),
        p99_step: avg(|m| m.p99_step),
        cuts_per_s: avg(|m| m.cuts_per_s),
        beat_alignment: avg(|m| m.beat_alignment),
        beats_per_s: avg(|m| m.beats_per_s),
        beat_chance: avg(|m| m.beat_chance),
        beat_lift: avg(|m| m.beat_lift),
        speech_coupling: avg(|m| m.speech_coupling),
        hellinger: avg_opt(|m| m.hellinger),
        pause_ratio: avg_some(|m| m.pause_ratio),
        settle_s: avg_some(|m| m.settle_s),
        react_s: avg_some(|m| m.react_s),
        speech_speed: avg_some(|m| m.speech_speed),
        // Variety of one run (averages of counts mean little).
        ..ms.first().copied().unwrap_or_default()
    }
}

/// `f` of the normalized `spoken` histogram and `1 - f` of the normalized `paused` one;
/// `None` when either is empty.
pub fn mix_by_speech(spoken: &[f64], paused: &[f64], f: f64) -> Option<Vec<f64>> {
    let (zs, zp) = (spoken.iter().sum::<f64>(), paused.iter().sum::<f64>());
    (zs > 0.0 && zp > 0.0).then(|| {
        spoken
            .iter()
            .zip(paused)
            .map(|(s, p)| f * s / zs + (1.0 - f) * p / zp)
            .collect()
    })
}

/// Share of `seconds` that the syllables of `steps` cover.
fn syllable_share(steps: &[Step], seconds: f64) -> f64 {
    let spoken: f64 = steps
        .iter()
        .filter(|s| s.kind == StepKind::Syllable)
        .map(|s| s.end_s().min(seconds) - s.start_s().min(seconds))
        .sum();
    (spoken / seconds.max(1e-9)).clamp(0.0, 1.0)
}

/// `m` with every translation channel held at its first frame's value: the capture as a
/// blob's character shows it (a blob's frames hold rotations only; the character stays where
/// it is). The hands' speeds in the capture itself include the speaker walking and swaying
/// (the 067 take's root moves at a median 8.5 cm/s), which no played motion can show.
pub fn translation_held(m: &Motion) -> Motion {
    let (skeleton, frame_time, frames, mut data) = m.clone().into_parts();
    let n = skeleton.channel_count();
    let moves: Vec<usize> = skeleton
        .joints
        .iter()
        .flat_map(|j| j.channels.iter())
        .enumerate()
        .filter(|(_, c)| !c.is_rotation())
        .map(|(k, _)| k)
        .collect();
    if n > 0 && data.len() >= n {
        let (first, rest) = data.split_at_mut(n);
        for row in rest.chunks_mut(n) {
            for &k in &moves {
                row[k] = first[k];
            }
        }
    }
    Motion::new(skeleton, frame_time, frames, data)
        .map(|held| held.with_source(m.source()))
        .unwrap_or_else(|_| m.clone())
}

/// The hands' speed histogram of a capture as a blob's character shows it: the lower body
/// held as `pack` holds a library's, then [`translation_held`]. The reference of a run
/// against its speech's own capture (`eval-motion --mocap`, `gesture-sim metrics --mocap`).
pub fn shown_speed_histogram(m: &Motion, effectors: &EffectorSpec) -> Result<Vec<f64>, String> {
    let mut held = [m.clone()];
    hold_lower_bodies(&mut held, effectors);
    let t = Trace::from_motion(&translation_held(&held[0]), effectors, Vec::new())?;
    Ok(speed_histogram(&t.hands, t.fps))
}

/// What the library's character does in speech like the new speech, as the reference of the
/// hands' speeds when the speech has no capture of its own: the library's capture split
/// into the frames spoken in syllables and those in pauses (its own speech, the WAV beside
/// each BVH, through the blob's front-end), the two histograms weighted by the share of the
/// new speech in syllables. People gesture while they speak and rest while they pause, so a
/// take with long pauses is not what the same person does through a monologue. When a take
/// has no speech beside it (a gesture library of clips), the library's whole capture.
pub fn speech_matched_reference(
    lib: &crate::control::library::Library,
    config: &ProsodyConfig,
    rate: u32,
    steps: &[Step],
    seconds: f64,
    effectors: &EffectorSpec,
) -> Vec<f64> {
    // The takes as the blob's character shows them (pack has held the library's lower
    // bodies already).
    let shown: Vec<Vec<Vec<[f64; 3]>>> = lib
        .takes
        .iter()
        .map(|t| {
            Trace::from_motion(&translation_held(&t.motion), effectors, Vec::new())
                .map(|tr| tr.hands)
                .unwrap_or_else(|_| {
                    let pos = &t.analysis.positions;
                    (0..pos.frames()).map(|f| pos.frame(f).to_vec()).collect()
                })
        })
        .collect();
    let whole = || speed_histogram(&shown.concat(), lib.fps);
    let mut spoken = vec![0.0; 26];
    let mut paused = vec![0.0; 26];
    for (t, hands) in lib.takes.iter().zip(&shown) {
        let wav = t.source.with_extension("wav");
        let Ok(pcm) = crate::audio::load_wav_at(&wav, rate) else {
            return whole();
        };
        let Ok((_, own)) = crate::features::prosody_of(&pcm.samples, config) else {
            return whole();
        };
        // Syllable spans in time order (steps tile the speech in order).
        let spans: Vec<(f64, f64)> = own
            .iter()
            .filter(|s| s.kind == StepKind::Syllable)
            .map(|s| (s.start_s(), s.end_s()))
            .collect();
        let in_syllable = |time: f64| {
            let k = spans.partition_point(|&(a, _)| a <= time);
            k > 0 && time < spans[k - 1].1
        };
        let fps = t.motion.fps();
        // Each take weighs by its frames in syllables and in pauses.
        let frame_steps = hands.len().saturating_sub(1);
        let n_spoken = (0..frame_steps)
            .filter(|&i| in_syllable((i + 1) as f64 / fps))
            .count() as f64;
        let hs = speed_histogram_where(hands, fps, in_syllable);
        let hp = speed_histogram_where(hands, fps, |time| !in_syllable(time));
        for k in 0..26 {
            spoken[k] += n_spoken * hs[k];
            paused[k] += (frame_steps as f64 - n_spoken) * hp[k];
        }
    }
    mix_by_speech(&spoken, &paused, syllable_share(steps, seconds)).unwrap_or_else(whole)
}

/// Evaluates `model` on `e` (see the module docs).
pub fn evaluate_motion(model: &InferenceModel, e: &MotionEval) -> Result<Evaluation, EvalError> {
    if e.audio.is_empty() {
        return Err(EvalError::Input("no audio to evaluate on".into()));
    }
    if e.mocap.is_some() && e.audio.len() != 1 {
        return Err(EvalError::Input(
            "--mocap goes with one audio file (its own speech)".into(),
        ));
    }
    let mut pack = e.pack.clone();
    pack.rig = None;
    pack.no_skeleton = false;
    let packed = pack_model(model, &e.library, &pack)?;
    let lib = &packed.library;
    let cm = &packed.control;
    let blob = Blob::parse(&packed.bytes).map_err(|x| EvalError::Device(x.to_string()))?;
    let skeleton = blob
        .skeleton()
        .ok_or_else(|| EvalError::Device("no skeleton section".into()))
        .and_then(|v| PoseSkeleton::from_blob(&v).map_err(|x| EvalError::Device(x.to_string())))?;
    let samples = load_audio(model, e)?;
    let rate = model.sample_rate_hz;
    let config: ProsodyConfig = blob.prosody_config();
    let (_, steps) = crate::features::prosody_of(&samples, &config)
        .map_err(|x| EvalError::Input(x.to_string()))?;
    let mut norm = StepNormalizer::new();
    let m: Vec<Vec<f64>> = steps
        .iter()
        .map(|s| model.gmm.memberships(&prosody_point(&norm.push(s))))
        .collect();
    let offline = if m.is_empty() {
        vec![]
    } else {
        model.crf.posteriors(&m)
    };
    let fps = lib.fps;
    let seconds = samples.len() as f64 / rate as f64;
    let frames = (seconds * fps) as usize;
    // The measured traces start where the speech starts (a delayed run's lead is cut off), so
    // the loudness frames of the samples line up with trace time 0.
    let speech = Speech::from_steps(&steps).with_audio(&samples, rate);
    let reference = match &e.mocap {
        Some(p) => Some(mocap_trace(p, e, |mo_fps| (seconds * mo_fps) as usize)?),
        None => None,
    };
    // Hand speeds are compared with the speech's own capture when there is one, else with the
    // library's capture in speech like this (see `speech_matched_reference`).
    // Both as the blob's character shows them (no walking; see `translation_held`).
    let ref_hist: Vec<f64> = match &reference {
        Some((t, mo)) => shown_speed_histogram(mo, &pack.effectors)
            .unwrap_or_else(|_| speed_histogram(&t.hands, t.fps)),
        None => speech_matched_reference(lib, &config, rate, &steps, seconds, &pack.effectors),
    };
    let segments = lib.segments.len();
    let measured = |p: &Playback| -> Result<MotionMetrics, EvalError> {
        let t = trace_of(&blob, &skeleton, p, &pack)?;
        Ok(measure(&t, &speech, Some(segments), Some(&ref_hist)))
    };
    let mut rows = Vec::new();

    // The device, as packed.
    // Drawn only when stderr is a terminal.
    let progress = crate::progress::spinner("eval-motion: the device and its ablations");
    // Each device method runs `device_runs` times, the speech delayed by a few more frames
    // each time: its choices depend on where the animation stands when each syllable comes,
    // so one run is one draw; the variety figures are of the first (undelayed) run, the
    // others the mean.
    let runs = e.device_runs.max(1) as usize;
    let step = ((PHASE_STEP_S * fps).round() as usize).max(1);
    let prior: Vec<f32> = model.state_prior.iter().map(|&v| v as f32).collect();
    let mut made = Vec::new();
    for method in [
        Ablation::None,
        Ablation::Pure,
        Ablation::Prior,
        Ablation::Shuffled,
    ] {
        let mut ms = Vec::with_capacity(runs);
        for run in 0..runs {
            let shuffled;
            let input = if method == Ablation::Shuffled {
                shuffled = shuffle_blocks(&samples, rate, 11 + run as u64);
                &shuffled
            } else {
                &samples
            };
            let (p, m) = play_delayed(&blob, input, rate, frames, run * step, |c| match method {
                Ablation::Pure => c.set_variety(Variety::NONE),
                Ablation::Prior => c.hold_belief(Some(&prior)),
                Ablation::None | Ablation::Shuffled => {}
            })?;
            if method == Ablation::None && run == 0 {
                made = m;
            }
            ms.push(measured(&p)?);
        }
        rows.push(Row::of_runs(method.name(), &ms));
    }
    // References, played by the same player.
    let start = 0;
    progress.set_message("eval-motion: random selection and the offline DP");
    let random: Vec<MotionMetrics> = (0..e.random_runs.max(1))
        .map(|seed| {
            measured(&play_schedule(
                &blob,
                &play_random(lib, frames, start, seed),
            ))
        })
        .collect::<Result<_, _>>()?;
    rows.push(Row::of_runs("random", &random));
    if !offline.is_empty() {
        let prior64 = model.state_prior.clone();
        let post = |t: usize| {
            let time = t as f64 / fps;
            match steps.iter().position(|s| s.end_s() > time) {
                Some(k) => offline[k].clone(),
                None => offline.last().cloned().unwrap_or_else(|| prior64.clone()),
            }
        };
        let plan = play_dp(lib, &cm.policy, &cm.psi, frames, start, &post);
        rows.push(Row::of_runs(
            "offline_dp",
            &[measured(&play_schedule(&blob, &plan))?],
        ));
    }
    if let Some((t, _)) = &reference {
        rows.push(Row::of_runs(
            "mocap",
            &[measure(t, &speech, None, Some(&ref_hist))],
        ));
    }
    // What variety costs against the pure policy.
    let (mut excess, mut best_total) = (0.0, 0.0);
    for d in &made {
        let chosen = match d.choice {
            Choice::Continue => Action::Continue,
            Choice::Enter(c) => Action::Enter(c),
        };
        let best = cm.policy.decide(d.exit, &d.belief, 0..segments);
        let cb = cm.policy.cost(d.exit, best, &d.belief);
        let cc = cm.policy.cost(d.exit, chosen, &d.belief);
        if cb.is_finite() && cc.is_finite() {
            excess += (cc - cb).max(0.0);
            best_total += cb.abs();
        }
    }
    progress.finish_and_clear();
    Ok(Evaluation {
        rows,
        library_segments: segments,
        decisions: made.len(),
        variety_regret: excess / best_total.max(1e-12),
        seconds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corpus::{load_corpus, LoadOptions};
    use crate::inference::train::{fit, sequences, FitConfig};
    use crate::synth::{write_corpus, SynthParams};
    use gesture_runtime::prosody::Step;

    #[test]
    fn a_capture_as_shown_keeps_its_rotations_and_drops_its_walk() {
        // A root walking 3 units per frame along X and turning 10 degrees per frame about Y,
        // with an arm of length 2 along X: in the capture the hand moves by the walk plus
        // the turn; held, only by the turn (a chord of 2 sin(5 deg) * 2 per frame).
        let text = "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 6 Xposition Yposition \
                    Zposition Zrotation Yrotation Xrotation\n\tJOINT RightHand\n\t{\n\t\t\
                    OFFSET 2 0 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tEnd Site\n\
                    \t\t{\n\t\t\tOFFSET 0 0 0\n\t\t}\n\t}\n}\nMOTION\nFrames: 3\n\
                    Frame Time: 0.1\n0 5 0 0 0 0 0 0 0\n3 5 0 0 10 0 0 0 0\n6 5 0 0 20 0 0 0 0\n";
        let m = crate::motion::parse_bvh(text, "walk.bvh").unwrap();
        let held = translation_held(&m);
        assert_eq!(held.source(), "walk.bvh");
        for f in 0..3 {
            let (a, b) = (m.frame(f).unwrap(), held.frame(f).unwrap());
            // Translations are the first frame's; rotations untouched.
            assert_eq!(&b[..3], &[0.0, 5.0, 0.0]);
            assert_eq!(&b[3..], &a[3..]);
        }
        let hand = |mo: &Motion, f: usize| {
            let p = crate::motion::FkPlan::new(mo.skeleton(), &[crate::motion::Target::Joint(1)])
                .unwrap()
                .positions(mo)
                .unwrap();
            p.frame(f)[0]
        };
        let step = |mo: &Motion| {
            let (p, q) = (hand(mo, 1), hand(mo, 2));
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        };
        let chord = 2.0 * 2.0 * (5.0f64.to_radians()).sin();
        assert!((step(&held) - chord).abs() < 1e-9, "{}", step(&held));
        assert!(step(&m) > 2.5, "the walk is in the capture: {}", step(&m));
    }

    #[test]
    fn the_speech_matched_reference_weighs_speech_and_pauses_as_the_new_speech_has_them() {
        // Hands still in the capture's pauses (bin 0) and at 55 units/s in its syllables
        // (bin 5), in any proportion: new speech spoken 70 % of its time gets 0.7 in bin 5.
        let mut spoken = vec![0.0; 26];
        let mut paused = vec![0.0; 26];
        spoken[5] = 300.0;
        paused[0] = 900.0;
        let r = mix_by_speech(&spoken, &paused, 0.7).unwrap();
        assert!((r[5] - 0.7).abs() < 1e-12 && (r[0] - 0.3).abs() < 1e-12);
        assert!((r.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        // A capture without pauses (or without speech) cannot be split.
        assert_eq!(mix_by_speech(&spoken, &[0.0; 26], 0.7), None);
        // Syllables of 0.5 s and 1 s and a pause step of 0.5 s in 4 s of speech: 3/8 spoken.
        let step = |kind, a: u32, b: u32| Step {
            kind,
            start_frame: a,
            end_frame: b,
            f0_hz: None,
            intensity_db: 60.0,
        };
        let steps = [
            step(StepKind::Syllable, 0, 50),
            step(StepKind::Pause, 50, 100),
            step(StepKind::Syllable, 100, 200),
        ];
        assert!((syllable_share(&steps, 4.0) - 0.375).abs() < 1e-12);
        // Past the end of the audio nothing counts: 0.5 s + 0.5 s of 1.5 s.
        assert!((syllable_share(&steps, 1.5) - 2.0 / 3.0).abs() < 1e-12);
    }

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
        let (delayed, _) = play_delayed(&blob, &silence, rate, frames, d, |_| {}).unwrap();
        assert_eq!(delayed.poses.len(), frames);
        let lead = (d as f64 * rate as f64 / fps).round() as usize;
        let longer = vec![0i16; lead + silence.len()];
        let (whole, _) = play_online(&blob, &longer, frames + d, |_| {}).unwrap();
        assert_eq!(delayed.poses[..], whole.poses[d..]);
        assert_eq!(delayed.shown[..], whole.shown[d..]);
        // No delay: the plain run.
        let (plain, _) = play_delayed(&blob, &silence, rate, frames, 0, |_| {}).unwrap();
        assert_eq!(plain.poses[..], whole.poses[..frames]);
    }

    /// Device runs and random runs are averaged figure by figure (the speech coupling
    /// included), the largest jump is the largest of any run, and the variety figures are the
    /// first run's.
    #[test]
    fn runs_average_every_continuous_figure_and_keep_the_first_runs_variety() {
        let a = MotionMetrics {
            distinct_segments: 7,
            max_segment_share: 0.25,
            speech_coupling: 0.2,
            beat_alignment: 0.8,
            max_jump_at_cuts: 3.0,
            hellinger: Some(0.1),
            ..MotionMetrics::default()
        };
        let b = MotionMetrics {
            distinct_segments: 9,
            max_segment_share: 0.5,
            speech_coupling: -0.4,
            beat_alignment: 0.9,
            max_jump_at_cuts: 5.0,
            hellinger: Some(0.3),
            ..MotionMetrics::default()
        };
        let m = mean(&[a, b]);
        assert!((m.speech_coupling + 0.1).abs() < 1e-12, "{m:?}");
        assert!((m.beat_alignment - 0.85).abs() < 1e-12);
        assert!((m.hellinger.unwrap() - 0.2).abs() < 1e-12);
        assert_eq!(m.max_jump_at_cuts, 5.0);
        assert_eq!((m.distinct_segments, m.max_segment_share), (7, 0.25));
        // Sample standard deviations: two values d apart have sd d / sqrt(2).
        let s = spread(&[a, b]).unwrap();
        let r2 = std::f64::consts::SQRT_2;
        assert!((s.speech_coupling - 0.6 / r2).abs() < 1e-12, "{s:?}");
        assert!((s.beat_alignment - 0.1 / r2).abs() < 1e-12);
        assert!((s.hellinger.unwrap() - 0.2 / r2).abs() < 1e-12);
        assert_eq!(spread(&[a]), None);
    }

    /// The voice figures average over the runs that have them (a run may have no pause in
    /// reach); `None` only when no run has one.
    #[test]
    fn voice_figures_average_over_the_runs_that_have_them() {
        let run = |r: Option<f64>| MotionMetrics {
            pause_ratio: r,
            settle_s: r.map(|v| 10.0 * v),
            react_s: None,
            speech_speed: r.map(|v| 100.0 * v),
            ..MotionMetrics::default()
        };
        let m = mean(&[run(Some(0.1)), run(None), run(Some(0.3))]);
        assert!((m.pause_ratio.unwrap() - 0.2).abs() < 1e-12, "{m:?}");
        assert!((m.settle_s.unwrap() - 2.0).abs() < 1e-12);
        assert!((m.speech_speed.unwrap() - 20.0).abs() < 1e-12);
        assert_eq!(m.react_s, None);
        assert_eq!(mean(&[run(None), run(None)]).pause_ratio, None);
    }
}
