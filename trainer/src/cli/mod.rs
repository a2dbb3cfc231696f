//! The `gesture-train` command line: argument parsing into validated settings and dispatch to
//! the library. Every command prints what it did to stdout and progress to stderr; errors are
//! one line, and the binary exits with status 2 on any error. Output goes through the `outln!`
//! macro, which ends the process quietly (status 0) when stdout is a closed pipe
//! (`gesture-train ... | head`) instead of panicking like `println!`.

/// `println!` that exits with status 0 when stdout is a closed pipe.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let mut out = std::io::stdout().lock();
        if let Err(e) = writeln!(out, $($arg)*) {
            if e.kind() == std::io::ErrorKind::BrokenPipe {
                std::process::exit(0);
            }
        }
    }};
}

pub mod eval_inference;
pub mod eval_motion;
pub mod fit;
pub mod inspect;
pub mod pack;
mod stats;
mod synth;

use std::path::PathBuf;

use clap::{Parser, Subcommand};

/// Learns gesture controllers from motion capture with speech (BVH + WAV).
#[derive(Debug, Parser)]
#[command(name = "gesture-train", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Generate a synthetic speech+motion corpus with planted truth (truth.json).
    Synth(synth::SynthArgs),
    /// Summarize a corpus: durations, segments, kinematics, syllables per file.
    CorpusStats(stats::StatsArgs),
    /// Train the inference layer (HMM, prosody mixture, CRF) and write the model file.
    Fit(fit::FitArgs),
    /// Compare CRF, remapped HMM and prior on held-out data (the paper's Fig. 4).
    EvalInference(eval_inference::EvalArgs),
    /// Pack a model, a gesture library and a rig into a policy blob.
    Pack(pack::PackArgs),
    /// Motion quality of the online policy on held-out audio vs random, offline DP, mocap.
    EvalMotion(eval_motion::EvalMotionArgs),
    /// Validate a policy blob and summarize it: header, section sizes, dimensions, rig.
    Inspect(inspect::InspectArgs),
}

/// Options shared by commands that read a corpus.
#[derive(Debug, Clone, clap::Args)]
pub struct CorpusArgs {
    /// End-effector joints (default: the two hands, found by common names).
    #[arg(long, value_delimiter = ',')]
    pub effectors: Vec<String>,
    /// Largest accepted difference between audio and motion length, in seconds.
    #[arg(long, default_value_t = 0.5)]
    pub max_mismatch: f64,
}

impl CorpusArgs {
    /// Load options from the arguments.
    pub fn options(&self) -> crate::corpus::LoadOptions {
        let mut o = crate::corpus::LoadOptions::default();
        if !self.effectors.is_empty() {
            o.effectors = crate::motion::EffectorSpec::joints(self.effectors.iter().cloned());
        }
        o.max_mismatch_s = self.max_mismatch;
        o
    }
}

/// Control-layer options shared by `pack` and `eval-motion`.
#[derive(Debug, Clone, clap::Args)]
pub struct ControlArgs {
    /// Weight of transition costs against the fit of a segment to the belief (lower: gestures
    /// follow the speech more and the recorded order less, with more cuts).
    #[arg(long, default_value_t = crate::control::costs::CostParams::default().transition_weight)]
    pub transition_weight: f64,
    /// Weight of the pose jump when a segment ends in a cut (not scaled by the transition
    /// weight).
    #[arg(long, default_value_t = crate::control::costs::CostParams::default().junction_weight)]
    pub junction_weight: f64,
    /// Added to the cost of leaving a segment at an interruption frame.
    #[arg(long, default_value_t = crate::control::costs::CostParams::default().interruption_penalty)]
    pub interruption_penalty: f64,
}

impl ControlArgs {
    /// Control-layer settings from the arguments (everything else at its default).
    pub fn params(&self) -> crate::control::build::ControlParams {
        let mut p = crate::control::build::ControlParams::default();
        p.cost.transition_weight = self.transition_weight;
        p.cost.interruption_penalty = self.interruption_penalty;
        p.cost.junction_weight = self.junction_weight;
        p
    }

    /// Refuses values that make no sense.
    pub fn validate(&self) -> Result<(), CliError> {
        for (name, v) in [
            ("--transition-weight", self.transition_weight),
            ("--interruption-penalty", self.interruption_penalty),
            ("--junction-weight", self.junction_weight),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{name} must be a finite number >= 0, not {v}").into());
            }
        }
        Ok(())
    }
}

/// Model options shared by `fit` and `eval-inference`.
#[derive(Debug, Clone, clap::Args)]
pub struct ModelArgs {
    /// Hidden states S.
    #[arg(long, default_value_t = 12)]
    pub states: usize,
    /// Prosody clusters K.
    #[arg(long, default_value_t = 12)]
    pub clusters: usize,
    /// HMM restarts (run in parallel; EM finds better optima with more).
    #[arg(long, default_value_t = 16)]
    pub restarts: usize,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// CRF L2 regularization per training step (default: chosen by validation on the last
    /// 20% of each training take).
    #[arg(long)]
    pub l2: Option<f64>,
    /// HMM stickiness: extra self-transition pseudo-count as a fraction of steps per state.
    #[arg(long, default_value_t = 0.0)]
    pub stickiness: f64,
}

impl ModelArgs {
    /// The fit settings for CRF window `window`.
    pub fn config(&self, window: usize) -> crate::inference::train::FitConfig {
        crate::inference::train::FitConfig {
            states: self.states,
            clusters: self.clusters,
            window,
            restarts: self.restarts,
            seed: self.seed,
            stickiness: self.stickiness,
            l2: self.l2,
            ..Default::default()
        }
    }
}

/// An error of any command, printed as one line.
pub type CliError = Box<dyn std::error::Error + Send + Sync>;

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Synth(a) => synth::run(&a),
        Command::CorpusStats(a) => stats::run(&a),
        Command::Fit(a) => fit::run(&a),
        Command::EvalInference(a) => eval_inference::run(&a),
        Command::Pack(a) => pack::run(&a),
        Command::EvalMotion(a) => eval_motion::run(&a),
        Command::Inspect(a) => inspect::run(&a),
    }
}

/// A progress bar on stderr (hidden when stderr is not a terminal); the style every command
/// of both binaries uses.
pub fn progress_bar(len: u64, what: &str) -> indicatif::ProgressBar {
    let pb = indicatif::ProgressBar::new(len);
    pb.set_style(
        indicatif::ProgressStyle::with_template("{msg:>12} [{bar:30}] {pos}/{len} ({elapsed})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    pb.set_message(what.to_string());
    pb
}

/// Checks that an output folder can be created.
pub(crate) fn ensure_dir(dir: &PathBuf) -> Result<(), CliError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| format!("{}: cannot create folder: {e}", dir.display()).into())
}
