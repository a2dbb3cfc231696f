//! `gesture-train corpus-stats`: what a user checks about their data before training.
//!
//! Speech+motion pairs get the full report; a BVH alone (a gesture library) gets the motion part,
//! a WAV alone the speech part.

use std::path::PathBuf;
use std::time::Instant;

use gesture_runtime::prosody::{ProsodyConfig, StepKind};
use rayon::prelude::*;
use serde::Serialize;

use super::{progress_bar, CliError, CorpusArgs};
use crate::corpus::{discover, load_take, Take};
use crate::motion::{analyze, read_bvh, TakeAnalysis};

/// Arguments of `corpus-stats`.
#[derive(Debug, clap::Args)]
pub struct StatsArgs {
    /// BVH and WAV files, or folders (searched recursively).
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Corpus loading options.
    #[command(flatten)]
    pub corpus: CorpusArgs,
}

/// Summary statistics of one take.
#[derive(Debug, Serialize)]
pub struct TakeStats {
    /// File stem.
    pub stem: String,
    /// Files read.
    pub files: Vec<String>,
    /// Motion length (s), if any motion.
    pub motion_s: Option<f64>,
    /// Audio length (s), if any audio.
    pub audio_s: Option<f64>,
    /// Motion frames.
    pub frames: Option<usize>,
    /// Motion frame rate.
    pub fps: Option<f64>,
    /// Effector joints used.
    pub effectors: Vec<String>,
    /// Segment count.
    pub segments: Option<usize>,
    /// Segment duration quantiles (min, 25%, median, 75%, max), seconds.
    pub segment_s: Option<[f64; 5]>,
    /// Speed threshold used for segmentation (units/s).
    pub threshold: Option<f64>,
    /// Mean and standard deviation of T, D, V, A, C, H (physical units).
    pub kinematics: Option<[[f64; 2]; 6]>,
    /// Syllables found by the front-end.
    pub syllables: Option<usize>,
    /// Pause steps.
    pub pauses: Option<usize>,
    /// Log-scale kinematic vectors of the segments (for the corpus normalization).
    #[serde(skip)]
    pub y_raw: Vec<[f64; 6]>,
}

fn quantiles(mut v: Vec<f64>) -> [f64; 5] {
    v.sort_by(|a, b| a.total_cmp(b));
    let q = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
    [q(0.0), q(0.25), q(0.5), q(0.75), q(1.0)]
}

fn motion_part(s: &mut TakeStats, a: &TakeAnalysis, frames: usize) {
    s.frames = Some(frames);
    s.fps = Some(1.0 / a.frame_time);
    s.motion_s = Some(frames as f64 * a.frame_time);
    s.effectors = a.effectors.names.clone();
    s.segments = Some(a.segments.len());
    s.y_raw = a.y_raw.clone();
    s.threshold = Some(a.threshold);
    if !a.segments.is_empty() {
        s.segment_s = Some(quantiles(
            a.segments
                .iter()
                .map(|g| g.len() as f64 * a.frame_time)
                .collect(),
        ));
    }
    if !a.kinematics.is_empty() {
        let n = a.kinematics.len() as f64;
        let mut out = [[0.0; 2]; 6];
        for (d, o) in out.iter_mut().enumerate() {
            let vals: Vec<f64> = a.kinematics.iter().map(|k| k.to_array()[d]).collect();
            let m = vals.iter().sum::<f64>() / n;
            let sd = (vals.iter().map(|v| (v - m).powi(2)).sum::<f64>() / n).sqrt();
            *o = [m, sd];
        }
        s.kinematics = Some(out);
    }
}

fn stats_of(t: &Take, args: &StatsArgs) -> Result<TakeStats, CliError> {
    let opts = args.corpus.options();
    let mut s = TakeStats {
        stem: t.stem.clone(),
        files: [&t.bvh, &t.wav]
            .iter()
            .filter_map(|p| p.as_ref().map(|p| p.display().to_string()))
            .collect(),
        motion_s: None,
        audio_s: None,
        frames: None,
        fps: None,
        effectors: vec![],
        segments: None,
        segment_s: None,
        threshold: None,
        kinematics: None,
        syllables: None,
        pauses: None,
        y_raw: vec![],
    };
    let count = |steps: &[gesture_runtime::prosody::Step], k: StepKind| {
        steps.iter().filter(|x| x.kind == k).count()
    };
    match (&t.bvh, &t.wav) {
        (Some(b), Some(w)) => {
            let l = load_take(&t.stem, b, w, &opts)?;
            motion_part(&mut s, &l.motion, l.motion_frames);
            s.audio_s = Some(l.audio_s);
            s.syllables = Some(count(&l.steps, StepKind::Syllable));
            s.pauses = Some(count(&l.steps, StepKind::Pause));
        }
        (Some(b), None) => {
            let m = read_bvh(b)?;
            let a = analyze(&m, &opts.effectors, &opts.segment)
                .map_err(|e| format!("{}: {e}", b.display()))?;
            motion_part(&mut s, &a, m.frames());
        }
        (None, Some(w)) => {
            let pcm = crate::audio::load_wav_at(w, ProsodyConfig::DEFAULT.sample_rate_hz)?;
            let (_, steps) = crate::features::prosody_of(&pcm.samples, &ProsodyConfig::DEFAULT)?;
            s.audio_s = Some(pcm.duration_s());
            s.syllables = Some(count(&steps, StepKind::Syllable));
            s.pauses = Some(count(&steps, StepKind::Pause));
        }
        (None, None) => {}
    }
    Ok(s)
}

fn opt(v: Option<f64>, prec: usize) -> String {
    v.map_or_else(|| "-".into(), |x| format!("{x:.prec$}"))
}

/// Runs the command.
pub fn run(a: &StatsArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let takes = discover(&a.inputs)?;
    let pb = progress_bar(takes.len() as u64, "reading");
    let stats: Vec<TakeStats> = takes
        .par_iter()
        .map(|t| {
            let r = stats_of(t, a);
            pb.inc(1);
            r
        })
        .collect::<Result<_, _>>()?;
    pb.finish_and_clear();
    let elapsed = start.elapsed().as_secs_f64();
    if a.json {
        let total_motion = stats
            .iter()
            .filter_map(|s| s.motion_s)
            .fold(0.0, |a, b| a + b);
        // The per-dimension normalization of the log kinematic parameters fitted on this corpus
        // (the paper's W and B); `fit` stores the same one in the model.
        let all: Vec<[f64; 6]> = stats.iter().flat_map(|s| s.y_raw.iter().copied()).collect();
        let norm = crate::motion::Normalization::fit(&all).ok();
        let v = serde_json::json!({
            "takes": stats,
            "total_motion_s": total_motion,
            "normalization": norm,
            "elapsed_s": elapsed,
        });
        outln!("{v}");
        return Ok(());
    }
    let names = ["T (s)", "D", "V (/s)", "A (/s2)", "C (1/u)", "H"];
    for s in &stats {
        outln!("{}  ({})", s.stem, s.files.join(" + "));
        outln!(
            "  duration: motion {} s, audio {} s; {} frames at {} fps",
            opt(s.motion_s, 2),
            opt(s.audio_s, 2),
            s.frames.map_or("-".into(), |f| f.to_string()),
            opt(s.fps, 1)
        );
        if !s.effectors.is_empty() {
            outln!("  effectors: {}", s.effectors.join(", "));
        }
        if let (Some(n), Some(q)) = (s.segments, s.segment_s) {
            outln!(
                "  segments: {n} (threshold {} /s); duration s: min {:.2}  q25 {:.2}  median {:.2}  q75 {:.2}  max {:.2}",
                opt(s.threshold, 1),
                q[0],
                q[1],
                q[2],
                q[3],
                q[4]
            );
        }
        if let Some(k) = s.kinematics {
            let parts: Vec<String> = names
                .iter()
                .zip(k.iter())
                .map(|(n, [m, sd])| format!("{n} {m:.3}±{sd:.3}"))
                .collect();
            outln!("  kinematics (mean±sd): {}", parts.join("  "));
        }
        if let Some(n) = s.syllables {
            let per_s = s.audio_s.map(|d| n as f64 / d.max(1e-9));
            outln!(
                "  syllables: {n} ({} /s), pause steps: {}",
                opt(per_s, 2),
                s.pauses.unwrap_or(0)
            );
        }
    }
    // Summing from +0.0: an empty f64 sum is -0.0, which would print as "-0.0".
    let total_motion = stats
        .iter()
        .filter_map(|s| s.motion_s)
        .fold(0.0, |a, b| a + b);
    let total_audio = stats
        .iter()
        .filter_map(|s| s.audio_s)
        .fold(0.0, |a, b| a + b);
    let segs: usize = stats.iter().filter_map(|s| s.segments).sum();
    let syl: usize = stats.iter().filter_map(|s| s.syllables).sum();
    outln!(
        "total: {} files, motion {:.1} s, audio {:.1} s, {segs} segments, {syl} syllables; read in {elapsed:.2} s",
        stats.len(),
        total_motion,
        total_audio
    );
    Ok(())
}
