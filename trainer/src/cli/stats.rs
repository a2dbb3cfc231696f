//! `gesture-train corpus-stats`: prints `crate::corpus::stats` for every take found.

use std::path::PathBuf;
use std::time::Instant;

use rayon::prelude::*;

use super::args::CorpusArgs;
use super::exit::CliError;
use crate::corpus::discover;
use crate::corpus::stats::{take_stats, TakeStats};
use crate::progress::progress_bar;

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

fn opt(v: Option<f64>, prec: usize) -> String {
    v.map_or_else(|| "-".into(), |x| format!("{x:.prec$}"))
}

/// Runs the command.
pub fn run(a: &StatsArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let opts = a.corpus.options();
    let takes = discover(&a.inputs)?;
    let pb = progress_bar(takes.len() as u64, "reading");
    let stats: Vec<TakeStats> = takes
        .par_iter()
        .map(|t| {
            let r = take_stats(t, &opts);
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
        outln!("{v}")?;
        return Ok(());
    }
    let names = ["T (s)", "D", "V (/s)", "A (/s2)", "C (1/u)", "H"];
    for s in &stats {
        outln!("{}  ({})", s.stem, s.files.join(" + "))?;
        outln!(
            "  duration: motion {} s, audio {} s; {} frames at {} fps",
            opt(s.motion_s, 2),
            opt(s.audio_s, 2),
            s.frames.map_or("-".into(), |f| f.to_string()),
            opt(s.fps, 1)
        )?;
        if !s.effectors.is_empty() {
            outln!("  effectors: {}", s.effectors.join(", "))?;
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
            )?;
        }
        if let Some(k) = s.kinematics {
            let parts: Vec<String> = names
                .iter()
                .zip(k.iter())
                .map(|(n, [m, sd])| format!("{n} {m:.3}±{sd:.3}"))
                .collect();
            outln!("  kinematics (mean±sd): {}", parts.join("  "))?;
        }
        if let Some(n) = s.syllables {
            let per_s = s.audio_s.map(|d| n as f64 / d.max(1e-9));
            outln!(
                "  syllables: {n} ({} /s), pause steps: {}",
                opt(per_s, 2),
                s.pauses.unwrap_or(0)
            )?;
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
    )?;
    Ok(())
}
