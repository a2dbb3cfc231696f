//! Motion quality on held-out audio (`gesture-train eval-motion`): the online controller
//! against random selection from the same library, the offline DP reference and, where the
//! audio has its own motion capture, the real motion (metrics in [`crate::control::quality`]).
//!
//! **The online row runs the bytes `pack` writes.** The model and library are packed in
//! memory ([`pack_model`]), the bytes are read back with `Blob::parse` and run through the
//! runtime's device loop ([`Device`]) on the audio's samples, with the blob's decision timing:
//! exactly what a board does, detection latencies included.

use std::path::PathBuf;

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, ControllerEvent};
use gesture_runtime::device::{Device, DeviceError, DeviceEvent, NullPin};
use gesture_runtime::inference::StepNormalizer;
use gesture_runtime::policy::{Choice, PolicyTables};
use gesture_runtime::prosody::{ProsodyConfig, StepKind};
use gesture_runtime::rig::MAX_CHANNELS;
use serde::Serialize;

use crate::control::quality::{
    cut_frames, is_cut, metrics, play_dp, play_random, positions, Metrics, Played,
};
use crate::control::Library;
use crate::inference::model::InferenceModel;
use crate::inference::train::prosody_point;
use crate::motion::{analyze, read_bvh, SegmentParams};
use crate::pack::{pack_model, PackError, PackOptions};

/// What to evaluate.
#[derive(Clone, Debug)]
pub struct MotionEval {
    /// Gesture library (BVH files or folders).
    pub library: Vec<PathBuf>,
    /// Held-out speech.
    pub audio: PathBuf,
    /// The real motion of that speech.
    pub mocap: Option<PathBuf>,
    /// Only this span of the audio (and motion capture), seconds.
    pub span: Option<(f64, f64)>,
    /// Random runs to average.
    pub random_runs: u64,
    /// How to pack (costs, timing, effectors); the rig is the library's full skeleton.
    pub pack: PackOptions,
}

/// One method's row.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// Method name.
    pub method: String,
    /// Its metrics.
    #[serde(flatten)]
    pub metrics: Metrics,
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
    /// Analysing the motion capture.
    #[error("{0}")]
    Analysis(String),
    /// The front-end refused the audio's settings.
    #[error("{0}")]
    Features(String),
    /// The device refused the packed blob (a packer bug).
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

fn mean(ms: &[Metrics]) -> Metrics {
    let n = ms.len().max(1) as f64;
    Metrics {
        hellinger: ms
            .iter()
            .map(|m| m.hellinger)
            .sum::<Option<f64>>()
            .map(|v| v / n),
        mean_jerk: ms.iter().map(|m| m.mean_jerk).sum::<f64>() / n,
        jump_at_cuts: ms.iter().map(|m| m.jump_at_cuts).sum::<f64>() / n,
        cuts_per_s: ms.iter().map(|m| m.cuts_per_s).sum::<f64>() / n,
        beat_alignment: ms.iter().map(|m| m.beat_alignment).sum::<f64>() / n,
    }
}

/// Online play as the device does it: the blob through the runtime's device loop (starting
/// at segment 0), fed `samples`. Returns `frames` played frames (the last one held if the
/// audio ends earlier).
pub fn play_blob(
    lib: &Library,
    blob: &Blob<'_>,
    samples: &[i16],
    frames: usize,
) -> Result<Vec<Played>, DeviceError> {
    let mut slot = Box::new(None);
    let controller =
        BlobController::from_blob_in(&mut slot, blob).map_err(DeviceError::Controller)?;
    let mut device: Device<'_, '_, NullPin, MAX_CHANNELS> =
        Device::new(controller, [NullPin; MAX_CHANNELS])?;
    let mut out: Vec<Played> = Vec::with_capacity(frames + 1);
    let mut cut_next = false;
    // Null pins cannot fail.
    let _ = device.push(samples, &mut |ev| match ev {
        DeviceEvent::Controller(ControllerEvent::Pose { segment, frame, .. }) => {
            out.push(Played {
                segment,
                frame,
                cut: std::mem::take(&mut cut_next),
            });
        }
        DeviceEvent::Controller(ControllerEvent::Decision { decision, .. }) => {
            if let Choice::Enter(c) = decision.choice {
                let e = decision.exit;
                cut_next = is_cut(lib, blob.exit_segment(e), c, blob.exit_is_end(e));
            }
        }
        _ => {}
    });
    out.truncate(frames);
    if let Some(&last) = out.last() {
        out.resize(frames, Played { cut: false, ..last });
    }
    Ok(out)
}

/// Evaluates `model` on `e` and returns the rows (online, random, offline DP, and mocap when
/// given).
pub fn evaluate_motion(model: &InferenceModel, e: &MotionEval) -> Result<Vec<Row>, EvalError> {
    let packed = pack_model(model, &e.library, &e.pack)?;
    let lib = &packed.library;
    let cm = &packed.control;
    let blob = Blob::parse(&packed.bytes).map_err(|x| EvalError::Device(x.to_string()))?;
    let pcm = crate::audio::load_wav_at(&e.audio, model.sample_rate_hz)?;
    let rate = model.sample_rate_hz as f64;
    let (s0, s1) = e.span.unwrap_or((0.0, f64::INFINITY));
    let i0 = ((s0 * rate) as usize).min(pcm.samples.len());
    let i1 = ((s1 * rate).min(pcm.samples.len() as f64) as usize).max(i0);
    let samples = &pcm.samples[i0..i1];
    let config: ProsodyConfig = blob.prosody_config();
    let (_, steps) = crate::features::prosody_of(samples, &config)
        .map_err(|x| EvalError::Features(x.to_string()))?;
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
    let frames = ((samples.len() as f64 / rate) * fps) as usize;
    let prior = model.state_prior.clone();
    let post = |t: usize| {
        let time = t as f64 / fps;
        match steps.iter().position(|s| s.end_s() > time) {
            Some(k) => offline[k].clone(),
            None => offline.last().cloned().unwrap_or_else(|| prior.clone()),
        }
    };
    let onsets: Vec<f64> = steps
        .iter()
        .filter(|s| s.kind == StepKind::Syllable)
        .map(|s| s.start_s())
        .collect();
    let effectors = &e.pack.effectors;
    let real = match &e.mocap {
        Some(p) => {
            let mo = read_bvh(p)?;
            let an = analyze(&mo, effectors, &SegmentParams::default())
                .map_err(|x| EvalError::Analysis(format!("{}: {x}", p.display())))?;
            let f0 = (s0 * mo.fps()) as usize;
            Some(
                (f0..(f0 + frames).min(an.positions.frames()))
                    .map(|f| an.positions.frame(f).to_vec())
                    .collect::<Vec<_>>(),
            )
        }
        None => None,
    };
    let real_ref = real.as_deref();
    let eval = |seq: &[Played]| {
        metrics(
            &positions(lib, seq),
            &cut_frames(seq),
            fps,
            &onsets,
            real_ref,
        )
    };
    // The device starts at segment 0, so the references start there too.
    let start = 0;
    let online =
        play_blob(lib, &blob, samples, frames).map_err(|x| EvalError::Device(x.to_string()))?;
    let mut rows = vec![Row {
        method: "online".into(),
        metrics: eval(&online),
    }];
    let random: Vec<Metrics> = (0..e.random_runs.max(1))
        .map(|seed| eval(&play_random(lib, frames, start, seed)))
        .collect();
    rows.push(Row {
        method: "random".into(),
        metrics: mean(&random),
    });
    if !offline.is_empty() {
        rows.push(Row {
            method: "offline_dp".into(),
            metrics: eval(&play_dp(lib, &cm.policy, &cm.psi, frames, start, &post)),
        });
    }
    if let Some(r) = real_ref {
        rows.push(Row {
            method: "mocap".into(),
            metrics: metrics(r, &[], fps, &onsets, Some(r)),
        });
    }
    Ok(rows)
}
