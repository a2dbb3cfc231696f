//! `gesture-train eval-motion`: motion quality of the online policy on held-out audio against
//! random selection, the offline DP and the real motion capture (see `control::quality`).

use std::path::PathBuf;

use gesture_runtime::inference::StepNormalizer;
use gesture_runtime::prosody::{ProsodyConfig, StepKind};
use serde::Serialize;

use super::fit::parse_span;
use super::{CliError, ControlArgs, CorpusArgs};
use crate::control::build::{build, QuantizedPolicy};
use crate::control::quality::{
    cut_frames, metrics, play_device, play_dp, play_random, positions, Device, Metrics,
};
use crate::control::Library;
use crate::corpus::discover;
use crate::inference::model::InferenceModel;
use crate::inference::quantize::QuantizedInference;
use crate::inference::train::prosody_point;
use crate::motion::{analyze, read_bvh, SegmentParams};
use gesture_runtime::controller::DecisionTiming;

/// Arguments of `eval-motion`.
#[derive(Debug, clap::Args)]
pub struct EvalMotionArgs {
    /// Trained inference model.
    #[arg(long)]
    pub model: PathBuf,
    /// Gesture library (BVH files or folders).
    #[arg(long, required = true, num_args = 1..)]
    pub library: Vec<PathBuf>,
    /// Held-out speech (WAV).
    #[arg(long)]
    pub audio: PathBuf,
    /// The real motion of that speech (BVH), for the Hellinger distance and as a reference.
    #[arg(long)]
    pub mocap: Option<PathBuf>,
    /// Use only START:END seconds of the audio (and motion capture).
    #[arg(long, value_parser = parse_span)]
    pub span: Option<(f64, f64)>,
    /// Random runs to average.
    #[arg(long, default_value_t = 10)]
    pub random_runs: u64,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Corpus loading options (effectors).
    #[command(flatten)]
    pub load: CorpusArgs,
    /// Control-layer options.
    #[command(flatten)]
    pub control: ControlArgs,
    /// Decide at every exit point at once instead of on syllable onsets (the runtime's
    /// `DecisionTiming::IMMEDIATE`).
    #[arg(long)]
    pub immediate: bool,
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

/// Evaluates and returns the rows (online, random, dp, and mocap when given).
pub fn evaluate(a: &EvalMotionArgs) -> Result<Vec<Row>, CliError> {
    let model = InferenceModel::load(&a.model)?;
    let files: Vec<PathBuf> = discover(&a.library)?
        .into_iter()
        .filter_map(|t| t.bvh)
        .collect();
    let effectors = a.load.options().effectors;
    let lib = Library::from_files(
        &files,
        &model.normalization,
        &effectors,
        &SegmentParams::default(),
        3,
    )?;
    a.control.validate()?;
    let cm = build(&model, &lib, &a.control.params());
    let pcm = crate::audio::load_wav_at(&a.audio, model.sample_rate_hz)?;
    let rate = model.sample_rate_hz as f64;
    let (s0, s1) = a.span.unwrap_or((0.0, f64::INFINITY));
    let i0 = ((s0 * rate) as usize).min(pcm.samples.len());
    let i1 = ((s1 * rate).min(pcm.samples.len() as f64) as usize).max(i0);
    let samples = &pcm.samples[i0..i1];
    let config = ProsodyConfig {
        sample_rate_hz: model.sample_rate_hz,
        ..ProsodyConfig::DEFAULT
    };
    let (_, steps) = crate::features::prosody_of(samples, &config)?;
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
    let real = match &a.mocap {
        Some(p) => {
            let mo = read_bvh(p)?;
            let an = analyze(&mo, &effectors, &SegmentParams::default())
                .map_err(|e| format!("{}: {e}", p.display()))?;
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
    let eval = |seq: &[crate::control::quality::Played]| {
        metrics(
            &positions(&lib, seq),
            &cut_frames(seq),
            fps,
            &onsets,
            real_ref,
        )
    };
    // The online controller is the device's: quantized tables through the runtime Controller
    // (which starts at segment 0), so the references start there too.
    let start = 0;
    let qp = QuantizedPolicy::new(&lib, &cm);
    let qi = QuantizedInference::new(&model.gmm, &model.crf);
    let timing = if a.immediate {
        DecisionTiming::IMMEDIATE
    } else {
        DecisionTiming::DEFAULT
    };
    let device = Device {
        tables: &qp,
        gmm: &qi.gmm,
        crf: qi
            .weights()
            .ok_or("the quantized CRF tables are inconsistent")?,
        config,
        timing,
    };
    let online = play_device(&lib, device, samples, frames).map_err(|e| e.to_string())?;
    let mut rows = vec![Row {
        method: "online".into(),
        metrics: eval(&online),
    }];
    let random: Vec<Metrics> = (0..a.random_runs.max(1))
        .map(|seed| eval(&play_random(&lib, frames, start, seed)))
        .collect();
    rows.push(Row {
        method: "random".into(),
        metrics: mean(&random),
    });
    if !offline.is_empty() {
        rows.push(Row {
            method: "offline_dp".into(),
            metrics: eval(&play_dp(&lib, &cm.policy, &cm.psi, frames, start, &post)),
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

/// Runs the command.
pub fn run(a: &EvalMotionArgs) -> Result<(), CliError> {
    let rows = evaluate(a)?;
    if a.json {
        outln!(
            "{}",
            serde_json::to_string(&serde_json::json!({ "rows": rows }))?
        );
        return Ok(());
    }
    outln!(
        "{:<11} {:>9} {:>12} {:>10} {:>8} {:>10}",
        "method",
        "hellinger",
        "mean_jerk",
        "jump_cuts",
        "cuts/s",
        "beat_align"
    );
    for r in &rows {
        let m = &r.metrics;
        outln!(
            "{:<11} {:>9} {:>12.0} {:>10.2} {:>8.2} {:>10.3}",
            r.method,
            m.hellinger.map_or("-".into(), |h| format!("{h:.3}")),
            m.mean_jerk,
            m.jump_at_cuts,
            m.cuts_per_s,
            m.beat_alignment
        );
    }
    Ok(())
}
