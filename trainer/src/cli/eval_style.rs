//! `gesture-train eval-style`: what each style does to the played motion
//! (`crate::evaluate::style`), as a table or JSON.

use std::path::PathBuf;

use super::args::{parse_span, ControlArgs, CorpusArgs, DeviceArgs, StyleArgs};
use super::exit::CliError;
use crate::evaluate::motion::MotionEval;
use crate::evaluate::style::evaluate_styles;
use crate::inference::model::InferenceModel;
use crate::pack::PackOptions;

/// Arguments of `eval-style`.
#[derive(Debug, clap::Args)]
pub struct EvalStyleArgs {
    /// Trained inference model.
    #[arg(long)]
    pub model: PathBuf,
    /// Gesture library (BVH files or folders).
    #[arg(long, required = true, num_args = 1..)]
    pub library: Vec<PathBuf>,
    /// Held-out speech: one or more WAV files, played one after the other.
    #[arg(long, required = true, num_args = 1..)]
    pub audio: Vec<PathBuf>,
    /// Use only START:END seconds of the audio.
    #[arg(long, value_parser = parse_span)]
    pub span: Option<(f64, f64)>,
    /// The styles to compare, the first being the reference of the ratios (e.g. `neutral`
    /// `active=1` `sad=1` `active=0.5,sad=0.5`).
    #[arg(long, num_args = 1.., default_value = "neutral")]
    pub styles: Vec<String>,
    /// Runs of each style to average, the speech delayed by 0.2 s more each time and by a
    /// share of a 10 ms front-end frame (one run is one draw).
    #[arg(long, default_value_t = crate::evaluate::motion::DEFAULT_DEVICE_RUNS, value_parser = clap::value_parser!(u64).range(1..=100))]
    pub device_runs: u64,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Tones to pack (as `pack` takes them).
    #[command(flatten)]
    pub tones: StyleArgs,
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

/// Runs the command.
pub fn run(a: &EvalStyleArgs) -> Result<(), CliError> {
    a.control.validate()?;
    a.device.validate()?;
    let mut pack = PackOptions {
        control: a.control.params(),
        effectors: a.load.options().effectors,
        styles: a.tones.options()?,
        ..PackOptions::default()
    };
    a.device.apply(&mut pack);
    let settings = MotionEval {
        library: a.library.clone(),
        audio: a.audio.clone(),
        mocap: None,
        span: a.span,
        random_runs: 1,
        device_runs: a.device_runs,
        pack,
        lookahead: Vec::new(),
    };
    let model = InferenceModel::load(&a.model)?;
    let ev = evaluate_styles(&model, &settings, &a.styles)?;
    if a.json {
        outln!("{}", serde_json::to_string(&ev)?)?;
        return Ok(());
    }
    outln!(
        "{:.1} s of audio; tones: {}; ratios to `{}`",
        ev.seconds,
        ev.tones.join(", "),
        ev.rows.first().map_or("", |r| r.style.as_str())
    )?;
    outln!(
        "{:<24} {:>9} {:>6} | {:>6} {:>6} {:>6} {:>6} {:>6} {:>6} | {:>5} {:>5}",
        "style",
        "hand cm/s",
        "x",
        "T x",
        "D x",
        "V x",
        "A x",
        "C x",
        "H x",
        "segs",
        "decs"
    )?;
    for r in &ev.rows {
        let k = r.kinematics_ratio;
        outln!(
            "{:<24} {:>9.2} {:>6.3} | {:>6.3} {:>6.3} {:>6.3} {:>6.3} {:>6.3} {:>6.3} | {:>5.1} {:>5.1}",
            r.style,
            r.hand_speed,
            r.hand_speed_ratio,
            k[0],
            k[1],
            k[2],
            k[3],
            k[4],
            k[5],
            r.segments,
            r.decisions
        )?;
    }
    Ok(())
}
