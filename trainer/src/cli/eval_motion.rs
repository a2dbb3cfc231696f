//! `gesture-train eval-motion`: motion quality of the online controller on held-out audio
//! against random selection, the offline DP and the real motion capture
//! (`crate::evaluate::motion`).

use std::path::PathBuf;

use super::args::{parse_span, ControlArgs, CorpusArgs, TimingArgs};
use super::CliError;
use crate::evaluate::motion::{evaluate_motion, MotionEval, Row};
use crate::inference::model::InferenceModel;
use crate::pack::PackOptions;

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
    /// Decision timing.
    #[command(flatten)]
    pub timing: TimingArgs,
}

impl EvalMotionArgs {
    /// The evaluation these flags ask for.
    pub fn settings(&self) -> Result<MotionEval, CliError> {
        self.control.validate()?;
        Ok(MotionEval {
            library: self.library.clone(),
            audio: self.audio.clone(),
            mocap: self.mocap.clone(),
            span: self.span,
            random_runs: self.random_runs,
            pack: PackOptions {
                control: self.control.params(),
                timing: self.timing.timing(),
                effectors: self.load.options().effectors,
                ..PackOptions::default()
            },
        })
    }
}

/// Evaluates and returns the rows (online, random, dp, and mocap when given).
pub fn evaluate(a: &EvalMotionArgs) -> Result<Vec<Row>, CliError> {
    let settings = a.settings()?;
    let model = InferenceModel::load(&a.model)?;
    Ok(evaluate_motion(&model, &settings)?)
}

/// Runs the command.
pub fn run(a: &EvalMotionArgs) -> Result<(), CliError> {
    let rows = evaluate(a)?;
    if a.json {
        outln!(
            "{}",
            serde_json::to_string(&serde_json::json!({ "rows": rows }))?
        )?;
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
    )?;
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
        )?;
    }
    Ok(())
}
