//! What a style does to the played motion (`gesture-train eval-style`): the model and library
//! packed with their tones, the device run on held-out speech per style, and the played
//! motion measured.
//!
//! Per style: the mean hand speed over the frames (the smoothed mean effector speed the
//! segmentation uses, in skeleton units per second, i.e. cm/s for the shared captures), and the
//! played motion segmented like the corpus, with the geometric mean over its segments of each
//! kinematic parameter T, D, V, A, C, H (in body units: the space the tones are fitted in), and
//! every figure's ratio to the first style given (neutral by convention).
//!
//! As in `eval-motion`, everything runs the packed bytes through the runtime's device loop
//! (the style set on its controller with `Controller::set_style`), `device_runs` times per
//! style with the speech delayed 0.2 s more each time (and by a share of a front-end frame, as
//! in `eval-motion`): one run is one draw (single runs put
//! active at x1.03 to x1.24 on the two beat-scott monologues). The hand speed is the mean over
//! the runs, the geometric means are over all the runs' segments, and the segment and
//! decision counts are per run.

use gesture_runtime::blob::Blob;
use serde::Serialize;

use super::error::EvalError;
use super::motion::{load_audio, MotionEval, PHASE_STEP_S};
use super::playback::{play_delayed, Lead};
use crate::control::style::parse_weights;
use crate::inference::model::InferenceModel;
use crate::motion::{analyze, SegmentParams};
use crate::pack::pack_model;
use crate::rig::PoseSkeleton;

/// One style's row.
#[derive(Clone, Debug, Serialize)]
pub struct StyleRow {
    /// The style as given (e.g. `active=1`).
    pub style: String,
    /// Its tone weights (the blob's tone order).
    pub weights: Vec<f32>,
    /// Mean hand speed (skeleton units per second).
    pub hand_speed: f64,
    /// Geometric means of T, D, V, A, C, H over the played motion's segments (body units).
    pub kinematics: [f64; 6],
    /// Segments of the played motion (mean per run).
    pub segments: f64,
    /// `hand_speed` over the first row's.
    pub hand_speed_ratio: f64,
    /// `kinematics` over the first row's.
    pub kinematics_ratio: [f64; 6],
    /// Decisions made (mean per run).
    pub decisions: f64,
}

/// The result: one row per style.
#[derive(Clone, Debug, Serialize)]
pub struct StyleEvaluation {
    /// The blob's tones.
    pub tones: Vec<String>,
    /// Seconds of audio.
    pub seconds: f64,
    /// Rows, in the order the styles were given.
    pub rows: Vec<StyleRow>,
}

/// Packs `model` with `e.pack` (its tones included) and plays `e.audio` once per style of
/// `styles` (specs as `gesture-sim run --style` takes them; `neutral` alone is the neutral
/// style).
pub fn evaluate_styles(
    model: &InferenceModel,
    e: &MotionEval,
    styles: &[String],
) -> Result<StyleEvaluation, EvalError> {
    if styles.is_empty() {
        return Err(EvalError::Input("no --styles to compare".into()));
    }
    let mut pack = e.pack.clone();
    pack.rig = None;
    pack.no_skeleton = false;
    let packed = pack_model(model, &e.library, &pack)?;
    let blob = Blob::parse(&packed.bytes).map_err(|x| EvalError::Device(x.to_string()))?;
    let tones: Vec<&str> = blob.tone_names().collect();
    let specs: Vec<Vec<f32>> = styles
        .iter()
        .map(|s| parse_weights(s, &tones, &format!("--styles {s}")).map_err(EvalError::Input))
        .collect::<Result<_, _>>()?;
    let skeleton = blob
        .skeleton()
        .ok_or_else(|| EvalError::Device("no skeleton section".into()))
        .and_then(|v| PoseSkeleton::from_blob(&v).map_err(|x| EvalError::Device(x.to_string())))?;
    let samples = load_audio(model, e)?;
    let seconds = samples.len() as f64 / model.sample_rate_hz as f64;
    let frames = (seconds * blob.fps() as f64) as usize;
    let rate = model.sample_rate_hz;
    let runs = e.device_runs.max(1) as usize;
    let step = ((PHASE_STEP_S * blob.fps() as f64).round() as usize).max(1);
    let progress = crate::progress::spinner("eval-style: playing each style");
    let mut rows: Vec<StyleRow> = Vec::new();
    for (spec, w) in styles.iter().zip(&specs) {
        progress.set_message(format!("eval-style: {spec}"));
        let (mut speeds, mut logs, mut segments, mut decisions) = (0.0, [0.0f64; 6], 0usize, 0);
        for run in 0..runs {
            let mut refused = None;
            let (played, made) = play_delayed(
                &blob,
                &samples,
                rate,
                frames,
                Lead::of_run(run, step, rate),
                |c| {
                    refused = c.set_style(w).err();
                },
            )?;
            if let Some(err) = refused {
                return Err(EvalError::Input(format!("--styles {spec}: {err}")));
            }
            let motion = skeleton
                .motion(&played.poses, blob.fps() as f64)
                .map_err(|x| EvalError::Device(x.to_string()))?;
            let an = analyze(&motion, &pack.effectors, &SegmentParams::default())
                .map_err(|x| EvalError::Device(format!("the played motion of {spec}: {x}")))?;
            speeds += an.speed.iter().sum::<f64>() / an.speed.len().max(1) as f64;
            for k in &an.kinematics {
                for (l, v) in logs.iter_mut().zip(k.to_array()) {
                    *l += v.max(1e-9).ln();
                }
            }
            segments += an.kinematics.len();
            decisions += made.len();
        }
        let hand_speed = speeds / runs as f64;
        let kinematics: [f64; 6] =
            std::array::from_fn(|d| (logs[d] / segments.max(1) as f64).exp());
        let (hs0, k0) = rows
            .first()
            .map_or((hand_speed, kinematics), |r| (r.hand_speed, r.kinematics));
        rows.push(StyleRow {
            style: spec.clone(),
            weights: w.clone(),
            hand_speed,
            kinematics,
            segments: segments as f64 / runs as f64,
            hand_speed_ratio: hand_speed / hs0.max(1e-12),
            kinematics_ratio: std::array::from_fn(|d| kinematics[d] / k0[d].max(1e-12)),
            decisions: decisions as f64 / runs as f64,
        });
    }
    progress.finish_and_clear();
    Ok(StyleEvaluation {
        tones: tones.iter().map(|t| t.to_string()).collect(),
        seconds,
        rows,
    })
}
