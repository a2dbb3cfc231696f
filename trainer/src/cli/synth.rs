//! `gesture-train synth`: a synthetic corpus with planted truth.

use std::path::PathBuf;
use std::time::Instant;

use super::exit::{ensure_dir, CliError};
use crate::progress::progress_bar;
use crate::synth::{write_corpus, SynthParams};

/// Arguments of `synth`.
#[derive(Debug, clap::Args)]
pub struct SynthArgs {
    /// Total length in minutes.
    #[arg(long, default_value_t = 2.0, value_parser = |s: &str| super::args::bounded(s, 0.01, 600.0))]
    pub minutes: f64,
    /// Seed (the same seed gives the same corpus, byte for byte).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Length of each take in seconds.
    #[arg(long, default_value_t = 60.0, value_parser = |s: &str| super::args::bounded(s, 5.0, 3600.0))]
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
    let pb = progress_bar(1, "synth");
    let w = write_corpus(&params, &a.out, |done, total| {
        pb.set_length(total as u64);
        pb.set_position(done as u64);
    })?;
    pb.finish_and_clear();
    outln!(
        "wrote {} takes ({:.1} min) to {}: {} planted syllables, {} gesture segments, \
         {} states; truth in {} ({:.1} s)",
        w.takes,
        a.minutes,
        a.out.display(),
        w.syllables,
        w.segments,
        w.truth.states.len(),
        a.out.join("truth.json").display(),
        start.elapsed().as_secs_f64()
    )?;
    Ok(())
}
