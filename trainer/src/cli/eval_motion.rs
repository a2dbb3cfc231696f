//! `gesture-train eval-motion`: motion quality of the online controller on held-out audio
//! against its ablations, random selection, the offline DP and the real motion capture
//! (`crate::evaluate::motion`), as a table or JSON.

use std::path::PathBuf;

use super::args::{parse_span, ControlArgs, CorpusArgs, DeviceArgs};
use super::exit::CliError;
use crate::evaluate::metrics::MotionMetrics;
use crate::evaluate::motion::{evaluate_motion, Evaluation, Horizon, MotionEval};
use crate::evaluate::table::motion_table;
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
    /// Held-out speech: one or more WAV files, played one after the other.
    #[arg(long, required = true, num_args = 1..)]
    pub audio: Vec<PathBuf>,
    /// The real motion of that speech (BVH; one audio file), for the Hellinger distance and
    /// as a reference row.
    #[arg(long)]
    pub mocap: Option<PathBuf>,
    /// Use only START:END seconds of the audio (and motion capture).
    #[arg(long, value_parser = parse_span)]
    pub span: Option<(f64, f64)>,
    /// Random runs to average.
    #[arg(long, default_value_t = crate::evaluate::motion::DEFAULT_DEVICE_RUNS, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub random_runs: u64,
    /// Runs of each device method (online and its ablations) to average, the speech delayed
    /// by 0.2 s more each time and by a share of a 10 ms front-end frame (every figure is the
    /// mean over the runs, the largest jump the largest of any).
    #[arg(long, default_value_t = crate::evaluate::motion::DEFAULT_DEVICE_RUNS, value_parser = clap::value_parser!(u64).range(1..=100))]
    pub device_runs: u64,
    /// Add a row per look-ahead: the controller fed the audio that many ms before it is played
    /// (`lookahead_<ms>`), or `all` for the whole file planned (`lookahead_all`); a list such
    /// as `0,100,300,500,1000,all`.
    #[arg(long, value_delimiter = ',', value_parser = clap::value_parser!(Horizon))]
    pub lookahead_ms: Vec<Horizon>,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Corpus loading options (effectors).
    #[command(flatten)]
    pub load: CorpusArgs,
    /// Control-layer options.
    #[command(flatten)]
    pub control: ControlArgs,
    /// How the device runs the policy.
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl EvalMotionArgs {
    /// The evaluation these flags ask for.
    pub fn settings(&self) -> Result<MotionEval, CliError> {
        self.control.validate()?;
        self.device.validate()?;
        let mut pack = PackOptions {
            control: self.control.params(),
            effectors: self.load.options().effectors,
            ..PackOptions::default()
        };
        self.device.apply(&mut pack);
        Ok(MotionEval {
            library: self.library.clone(),
            audio: self.audio.clone(),
            mocap: self.mocap.clone(),
            span: self.span,
            random_runs: self.random_runs,
            device_runs: self.device_runs,
            pack,
            lookahead: self.lookahead_ms.clone(),
        })
    }
}

/// Evaluates (see [`evaluate_motion`]).
pub fn evaluate(a: &EvalMotionArgs) -> Result<Evaluation, CliError> {
    let settings = a.settings()?;
    let model = InferenceModel::load(&a.model)?;
    Ok(evaluate_motion(&model, &settings)?)
}

/// Runs the command.
pub fn run(a: &EvalMotionArgs) -> Result<(), CliError> {
    let ev = evaluate(a)?;
    if a.json {
        outln!("{}", serde_json::to_string(&ev)?)?;
        return Ok(());
    }
    outln!(
        "{:.1} s of audio, library of {} segments; {} online decisions, variety regret {:.2}%",
        ev.seconds,
        ev.library_segments,
        ev.decisions,
        100.0 * ev.variety_regret
    )?;
    let rows: Vec<(&str, &MotionMetrics)> = ev
        .rows
        .iter()
        .map(|r| (r.method.as_str(), &r.metrics))
        .collect();
    for line in motion_table(&rows) {
        outln!("{line}")?;
    }
    outln!("runs averaged, and their spread (standard deviation) where there are several:")?;
    for r in &ev.rows {
        match &r.spread {
            Some(s) => outln!(
                "  {:<16} {:>3} runs   coupling +-{:.3}   beat align +-{:.3}   Hellinger {}",
                r.method,
                r.runs,
                s.speech_coupling,
                s.beat_alignment,
                s.hellinger.map_or("-".into(), |h| format!("+-{h:.3}"))
            )?,
            None => outln!("  {:<16} {:>3} run", r.method, r.runs)?,
        }
    }
    if let Some(d) = ev.online_minus_prior {
        outln!(
            "online less online_prior in coupling, run by run: {:+.3} +-{:.3} (standard error, {} runs)",
            d.mean,
            d.se,
            d.runs
        )?;
    }
    Ok(())
}
