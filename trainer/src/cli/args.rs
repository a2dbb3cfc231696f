//! Options shared by several commands, and their checks: the raw flags as clap parses them,
//! turned into the library's validated settings by each struct's methods.

use gesture_runtime::controller::DecisionTiming;

use super::CliError;

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

/// Parses `START:END` (seconds).
pub fn parse_span(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(':')
        .ok_or("expected START:END in seconds, e.g. 0:40")?;
    let a: f64 = if a.is_empty() {
        0.0
    } else {
        a.parse().map_err(|_| format!("bad start `{a}`"))?
    };
    let b: f64 = if b.is_empty() {
        f64::INFINITY
    } else {
        b.parse().map_err(|_| format!("bad end `{b}`"))?
    };
    if !(a >= 0.0 && b > a) {
        return Err(format!("span {s}: need 0 <= START < END"));
    }
    Ok((a, b))
}

/// Decision timing options shared by `pack` and `eval-motion`.
#[derive(Debug, Clone, clap::Args)]
pub struct TimingArgs {
    /// Decide at every exit point at once instead of on syllable onsets (the runtime's
    /// `DecisionTiming::IMMEDIATE`; stored in the blob).
    #[arg(long)]
    pub immediate: bool,
}

impl TimingArgs {
    /// The timing the blob records.
    pub fn timing(&self) -> DecisionTiming {
        if self.immediate {
            DecisionTiming::IMMEDIATE
        } else {
            DecisionTiming::DEFAULT
        }
    }
}
