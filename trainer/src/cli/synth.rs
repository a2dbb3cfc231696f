//! `gesture-train synth`: a synthetic corpus with planted truth.

use std::path::PathBuf;
use std::time::Instant;

use super::{ensure_dir, progress_bar, CliError};
use crate::synth::{generate_take, speaker_for, write_take, write_truth, SynthParams, Truth};

/// Arguments of `synth`.
#[derive(Debug, clap::Args)]
pub struct SynthArgs {
    /// Total length in minutes.
    #[arg(long, default_value_t = 2.0)]
    pub minutes: f64,
    /// Seed (the same seed gives the same corpus, byte for byte).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Length of each take in seconds.
    #[arg(long, default_value_t = 60.0)]
    pub take_seconds: f64,
    /// Output folder (created if missing).
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs the command.
pub fn run(a: &SynthArgs) -> Result<(), CliError> {
    if !(a.minutes.is_finite() && a.minutes > 0.0 && a.minutes <= 600.0) {
        return Err(format!("--minutes must be between 0 and 600, not {}", a.minutes).into());
    }
    if !(a.take_seconds.is_finite() && a.take_seconds >= 5.0 && a.take_seconds <= 3600.0) {
        return Err(format!(
            "--take-seconds must be between 5 and 3600, not {}",
            a.take_seconds
        )
        .into());
    }
    ensure_dir(&a.out)?;
    let start = Instant::now();
    let params = SynthParams {
        minutes: a.minutes,
        seed: a.seed,
        take_seconds: a.take_seconds,
    };
    let total = params.minutes * 60.0;
    let n = (total / params.take_seconds).ceil().max(1.0) as usize;
    let speaker = speaker_for(params.seed);
    let pb = progress_bar(n as u64, "synth");
    let mut truths = Vec::with_capacity(n);
    let (mut syllables, mut segments) = (0usize, 0usize);
    for i in 0..n {
        let dur = (total - i as f64 * params.take_seconds)
            .min(params.take_seconds)
            .max(1.0);
        let take = generate_take(params.seed, i, dur, &speaker);
        write_take(&take, &a.out)?;
        syllables += take.truth.syllables.len();
        segments += take.truth.segments.len();
        truths.push(take.truth);
        pb.inc(1);
    }
    pb.finish_and_clear();
    let truth = Truth {
        format: "gesture-synth-truth/1",
        seed: params.seed,
        speaker,
        states: crate::synth::styles::styles().to_vec(),
        takes: truths,
    };
    write_truth(&truth, &a.out)?;
    println!(
        "wrote {n} takes ({:.1} min) to {}: {syllables} planted syllables, {segments} gesture segments, \
         {} states; truth in {} ({:.1} s)",
        total / 60.0,
        a.out.display(),
        truth.states.len(),
        a.out.join("truth.json").display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
