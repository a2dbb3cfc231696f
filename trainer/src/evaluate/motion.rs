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
//! - `random`: a uniformly random segment at every segment end (mean over seeded runs);
//! - `offline_dp`: the offline dynamic-programming sequence (posteriors that see the whole
//!   utterance);
//! - `mocap`: the motion capture of the audio, when given (with its root motion).
//!
//! **Everything runs the bytes `pack` writes.** The model and library are packed in memory
//! ([`pack_model`]) and read back with `Blob::parse`; the online methods run the runtime's
//! device loop ([`Device`](gesture_runtime::device::Device)) on the audio's samples, and random and DP are played through the
//! runtime's own [`Player`](gesture_runtime::player::Player) over the blob's frames (the same inertialized cuts). Every pose is
//! put back on the library's skeleton ([`PoseSkeleton`]) and measured there, so the figures
//! describe what a viewer of the character sees.
//!
//! **The hand-speed reference.** With `--mocap`, the capture of the speech itself. Without
//! one (another speaker's speech), [`speech_matched_reference`]: the library's capture in
//! its syllables and in its pauses, weighed as the new speech has them. Either is taken *as
//! the character shows it* ([`translation_held`](super::reference::translation_held): the lower body held as `pack` holds it,
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
use gesture_runtime::inference::StepNormalizer;
use gesture_runtime::player::LibraryFrames;
use gesture_runtime::policy::{Choice, Variety};
use gesture_runtime::prosody::ProsodyConfig;
use serde::Serialize;

use super::error::EvalError;
use super::metrics::{measure, MotionMetrics, Speech};
use super::playback::{
    play_ahead, play_baked, play_delayed, play_schedule, shuffle_blocks, Lead, Playback,
};
use super::reference::{shown_speed_histogram, speech_matched_reference};
use super::signals::speed_histogram;
use super::trace::{entries_from_frames, Entry, Trace};
use crate::control::mdp::Action;
use crate::control::schedule::{play_dp, play_random};
use crate::inference::model::InferenceModel;
use crate::inference::train::prosody_point;
use crate::motion::{analyze, read_bvh, Motion, SegmentParams};
use crate::pack::{pack_model, PackOptions};
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
    /// more of silence each time, and by a share of a front-end frame: `Lead::of_run`; 1:
    /// the device as it runs, alone).
    pub device_runs: u64,
    /// How to pack (costs, device settings, effectors); the rig is the library's full
    /// skeleton.
    pub pack: PackOptions,
    /// Look-ahead rows to add (`lookahead_<ms>`, `lookahead_all`): the controller fed the
    /// audio that long before it is played, or the whole file planned ([`Horizon`]).
    pub lookahead: Vec<Horizon>,
}

/// How far ahead of its playback the speech is known.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Horizon {
    /// The controller hears the audio this many ms before it is played.
    Ms(u32),
    /// The whole file is known: planned in advance (`gesture-sim run --lookahead-ms all`).
    All,
}

impl std::str::FromStr for Horizon {
    type Err = String;

    /// Milliseconds (at most a second) or `all`.
    fn from_str(s: &str) -> Result<Self, String> {
        if s.trim() == "all" {
            return Ok(Self::All);
        }
        let max = gesture_runtime::controller::MAX_LOOKAHEAD_MS;
        match s.trim().parse::<u32>() {
            Ok(ms) if ms <= max => Ok(Self::Ms(ms)),
            _ => Err(format!(
                "`{s}` is not a look-ahead: milliseconds from 0 to {max}, or `all`"
            )),
        }
    }
}

impl Horizon {
    /// The controller's look-ahead for this horizon (the whole file: the most the runtime
    /// takes, a second).
    pub fn lookahead(self) -> gesture_runtime::controller::Lookahead {
        use gesture_runtime::controller::{Lookahead, MAX_LOOKAHEAD_MS};
        match self {
            Self::Ms(ms) => Lookahead::ms(ms),
            Self::All => Lookahead::ms(MAX_LOOKAHEAD_MS),
        }
    }

    /// The row's name.
    pub fn row_name(self) -> String {
        match self {
            Self::Ms(ms) => format!("lookahead_{ms}"),
            Self::All => "lookahead_all".into(),
        }
    }
}

/// One method's row.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// Method name.
    pub method: String,
    /// Its figures (means over its runs; the largest jump the largest of any).
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

/// Mean and sample standard deviation of `v` (`None` with fewer than two values).
fn mean_sd(v: &[f64]) -> Option<(f64, f64)> {
    if v.len() < 2 {
        return None;
    }
    let m = v.iter().sum::<f64>() / v.len() as f64;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
    Some((m, var.sqrt()))
}

/// Sample standard deviation of `f` over `runs` (`None` with fewer than two runs).
fn sd(runs: &[MotionMetrics], f: impl Fn(&MotionMetrics) -> Option<f64>) -> Option<f64> {
    let v: Vec<f64> = runs.iter().map(f).collect::<Option<_>>()?;
    mean_sd(&v).map(|(_, s)| s)
}

fn spread(runs: &[MotionMetrics]) -> Option<Spread> {
    Some(Spread {
        speech_coupling: sd(runs, |m| Some(m.speech_coupling))?,
        beat_alignment: sd(runs, |m| Some(m.beat_alignment))?,
        hellinger: sd(runs, |m| m.hellinger),
    })
}

/// A paired difference over runs: the mean of `a[k] - b[k]` and its standard error.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct Paired {
    /// Mean difference.
    pub mean: f64,
    /// Its standard error (the differences' sample standard deviation over the root of the
    /// runs).
    pub se: f64,
    /// Pairs.
    pub runs: usize,
}

/// The paired difference of `a` and `b` run by run (`None` with fewer than two pairs).
pub fn paired(a: &[f64], b: &[f64]) -> Option<Paired> {
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    let (mean, sd) = mean_sd(&d)?;
    Some(Paired {
        mean,
        se: sd / (d.len() as f64).sqrt(),
        runs: d.len(),
    })
}

/// An evaluation's result.
#[derive(Debug, Clone, Serialize)]
pub struct Evaluation {
    /// One row per method.
    pub rows: Vec<Row>,
    /// Speech coupling online less with the belief held at the prior, run by run (the same
    /// delay in both): what the belief adds, and whether that is more than the runs' noise
    /// (`None` with one run).
    pub online_minus_prior: Option<Paired>,
    /// Library segments.
    pub library_segments: usize,
    /// Online decisions.
    pub decisions: usize,
    /// Expected-cost excess of the online choices over the pure policy's best (fraction).
    pub variety_regret: f64,
    /// Seconds of audio.
    pub seconds: f64,
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
/// method on two minutes of held-out speech spread by 0.02-0.03 in speech coupling and in
/// beat alignment (standard deviations; 0.09 in coupling on ten seconds), as much as the
/// methods differ; 30 runs bring a mean's standard error to about 0.006 (0.016 on ten
/// seconds).
pub const DEFAULT_DEVICE_RUNS: u64 = 30;

fn mean(ms: &[MotionMetrics]) -> MotionMetrics {
    let n = ms.len().max(1) as f64;
    let avg = |f: fn(&MotionMetrics) -> f64| ms.iter().map(f).sum::<f64>() / n;
    let avg_count = |f: fn(&MotionMetrics) -> usize| {
        (ms.iter().map(|m| f(m) as f64).sum::<f64>() / n).round() as usize
    };
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
        // Variety as a run's on average: each run is a draw (it meets the speech at its own
        // point of the frame grid), so one run's distinct count or largest share is one draw.
        entries: avg_count(|m| m.entries),
        distinct_segments: avg_count(|m| m.distinct_segments),
        library_share: avg_opt(|m| m.library_share),
        max_segment_share: avg(|m| m.max_segment_share),
        usage_entropy_bits: avg(|m| m.usage_entropy_bits),
        repeat_5s_share: avg(|m| m.repeat_5s_share),
    }
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
    // and a share of a front-end frame each time: its choices depend on where the animation
    // stands when each syllable comes and on where the syllables fall in the front-end's
    // frames, so one run is one draw; every figure is the mean over the runs.
    let runs = e.device_runs.max(1) as usize;
    let step = ((PHASE_STEP_S * fps).round() as usize).max(1);
    let prior: Vec<f32> = model.state_prior.iter().map(|&v| v as f32).collect();
    let mut made = Vec::new();
    let (mut online_coupling, mut prior_coupling) = (Vec::new(), Vec::new());
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
            let (p, m) = play_delayed(
                &blob,
                input,
                rate,
                frames,
                Lead::of_run(run, step, rate),
                |c| match method {
                    Ablation::Pure => c.set_variety(Variety::NONE),
                    Ablation::Prior => c.hold_belief(Some(&prior)),
                    Ablation::None | Ablation::Shuffled => {}
                },
            )?;
            if method == Ablation::None && run == 0 {
                made = m;
            }
            ms.push(measured(&p)?);
        }
        let coupling = ms.iter().map(|m| m.speech_coupling).collect();
        match method {
            Ablation::None => online_coupling = coupling,
            Ablation::Prior => prior_coupling = coupling,
            _ => {}
        }
        rows.push(Row::of_runs(method.name(), &ms));
    }
    for &h in &e.lookahead {
        progress.set_message(format!("eval-motion: {}", h.row_name()));
        if h == Horizon::All {
            // The whole file planned, once per run: the plan depends on where the speech
            // meets the frames as much as a live run does.
            let mut ms = Vec::with_capacity(runs);
            for run in 0..runs {
                let lead = Lead::of_run(run, step, rate);
                ms.push(measured(&play_baked(&blob, &samples, rate, frames, lead)?)?);
            }
            rows.push(Row::of_runs(&h.row_name(), &ms));
            continue;
        }
        let mut ms = Vec::with_capacity(runs);
        for run in 0..runs {
            let p = play_ahead(
                &blob,
                &samples,
                rate,
                frames,
                Lead::of_run(run, step, rate),
                h.lookahead(),
            )?;
            ms.push(measured(&p)?);
        }
        rows.push(Row::of_runs(&h.row_name(), &ms));
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
        online_minus_prior: paired(&online_coupling, &prior_coupling),
        library_segments: segments,
        decisions: made.len(),
        variety_regret: excess / best_total.max(1e-12),
        seconds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_paired_difference_is_the_mean_difference_and_its_standard_error() {
        // Differences 0.5, 0.5, -0.5: mean 1/6, sample deviation sqrt(1/3), error 1/3.
        let d = paired(&[1.0, 2.0, 3.0], &[0.5, 1.5, 3.5]).unwrap();
        assert!((d.mean - 1.0 / 6.0).abs() < 1e-12);
        assert!((d.se - 1.0 / 3.0).abs() < 1e-12);
        assert_eq!(d.runs, 3);
        // A constant difference has no error; one pair has no estimate.
        assert_eq!(paired(&[2.0, 3.0], &[1.0, 2.0]).unwrap().se, 0.0);
        assert_eq!(paired(&[1.0], &[0.0]), None);
    }

    /// Device runs and random runs are averaged figure by figure (the speech coupling and the
    /// variety figures included; counts to the nearest whole), and the largest jump is the
    /// largest of any run.
    #[test]
    fn runs_average_every_figure_and_keep_the_largest_jump() {
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
        assert_eq!((m.distinct_segments, m.max_segment_share), (8, 0.375));
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
