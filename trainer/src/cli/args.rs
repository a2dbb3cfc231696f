//! Options shared by several commands, and their checks: the raw flags as clap parses them,
//! turned into the library's validated settings by each struct's methods.

use gesture_runtime::controller::DecisionTiming;

use super::exit::CliError;

/// A finite number in `lo..=hi`, or the reason it is not (clap prints it with the flag).
pub fn bounded(s: &str, lo: f64, hi: f64) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("{s:?} is not a number"))?;
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(format!("must be a finite number from {lo} to {hi}"))
    }
}

/// A whole number in `lo..=hi`.
pub fn count(s: &str, lo: usize, hi: usize) -> Result<usize, String> {
    let v: usize = s
        .trim()
        .parse()
        .map_err(|_| format!("{s:?} is not a whole number"))?;
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(format!("must be from {lo} to {hi}"))
    }
}

/// A weight or cost: finite, 0 to 1e6.
pub fn weight(s: &str) -> Result<f64, String> {
    bounded(s, 0.0, 1.0e6)
}

/// A cost stored in the blob as `f32`: finite, 0 to 1e6 (the blob's limit).
pub fn cost_f32(s: &str) -> Result<f32, String> {
    bounded(s, 0.0, f64::from(gesture_runtime::blob::MAX_VARIETY_COST)).map(|v| v as f32)
}

/// A regularization strength: finite, more than 0, at most 1e6.
pub fn strength(s: &str) -> Result<f64, String> {
    let v = bounded(s, 0.0, 1.0e6)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err("must be more than 0".into())
    }
}

/// Seconds of audio/motion mismatch: finite, 0 to 60.
pub fn mismatch_s(s: &str) -> Result<f64, String> {
    bounded(s, 0.0, 60.0)
}

/// HMM stickiness: finite, 0 to 100.
pub fn stickiness(s: &str) -> Result<f64, String> {
    bounded(s, 0.0, 100.0)
}

/// Options shared by commands that read a corpus.
#[derive(Debug, Clone, clap::Args)]
pub struct CorpusArgs {
    /// End-effector joints (default: the two hands, found by common names).
    #[arg(long, value_delimiter = ',')]
    pub effectors: Vec<String>,
    /// Largest accepted difference between audio and motion length, in seconds.
    #[arg(long, default_value_t = 0.5, value_parser = mismatch_s)]
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
    #[arg(long, default_value_t = crate::control::costs::CostParams::default().transition_weight, value_parser = weight)]
    pub transition_weight: f64,
    /// Weight of the pose jump when a segment ends in a cut (not scaled by the transition
    /// weight).
    #[arg(long, default_value_t = crate::control::costs::CostParams::default().junction_weight, value_parser = weight)]
    pub junction_weight: f64,
    /// Added to the cost of leaving a segment at an interruption frame.
    #[arg(long, default_value_t = crate::control::costs::CostParams::default().interruption_penalty, value_parser = weight)]
    pub interruption_penalty: f64,
    /// Fewest successors kept per exit point after exact pruning (the next best by expected
    /// cost are added: they give the variety costs something to choose from).
    #[arg(long, default_value_t = crate::control::prune::MIN_SUCCESSORS, value_parser = |s: &str| count(s, 1, 4096))]
    pub min_successors: usize,
    /// Most successors kept per exit point (the best by expected cost under the state prior;
    /// the regret it costs is reported): bounds the work of one decision on a board. Default:
    /// every non-dominated one.
    #[arg(long, value_parser = |s: &str| count(s, 1, 4096))]
    pub max_successors: Option<usize>,
}

impl ControlArgs {
    /// Control-layer settings from the arguments (everything else at its default).
    pub fn params(&self) -> crate::control::build::ControlParams {
        let mut p = crate::control::build::ControlParams::default();
        p.cost.transition_weight = self.transition_weight;
        p.cost.interruption_penalty = self.interruption_penalty;
        p.cost.junction_weight = self.junction_weight;
        p.min_successors = Some(self.min_successors);
        p.max_successors = self.max_successors;
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
    /// Hidden states S (default: chosen by held-out likelihood).
    #[arg(long, value_parser = |s: &str| count(s, 1, gesture_runtime::inference::MAX_STATES))]
    pub states: Option<usize>,
    /// Prosody clusters K (default: chosen by held-out likelihood).
    #[arg(long, value_parser = |s: &str| count(s, 1, gesture_runtime::inference::MAX_CLUSTERS))]
    pub clusters: Option<usize>,
    /// HMM restarts (run in parallel; EM finds better optima with more).
    #[arg(long, default_value_t = 16, value_parser = |s: &str| count(s, 1, 1000))]
    pub restarts: usize,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// CRF L2 regularization per training step, toward the CRF that learned nothing (default:
    /// chosen by held-out likelihood, per window).
    #[arg(long, value_parser = strength)]
    pub l2: Option<f64>,
    /// Multiplier of the L2 strength on the CRF's older window steps (default: chosen by
    /// held-out likelihood from 1, 10, 100).
    #[arg(long, value_parser = strength)]
    pub lag_penalty: Option<f64>,
    /// HMM stickiness: extra self-transition pseudo-count as a fraction of steps per state.
    #[arg(long, default_value_t = 0.0, value_parser = stickiness)]
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
            lag_penalty: self.lag_penalty,
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

/// How the device runs the policy: options shared by `pack` and `eval-motion`, stored in the
/// blob's `control` section (and the lower-body choice, applied to the library's frames).
#[derive(Debug, Clone, clap::Args)]
pub struct DeviceArgs {
    /// Decide at every exit point at once instead of on syllable onsets (the runtime's
    /// `DecisionTiming::IMMEDIATE`).
    #[arg(long)]
    pub immediate: bool,
    /// An onset detected this recently counts as "now" (ms).
    #[arg(long, default_value_t = DecisionTiming::DEFAULT.onset_window_ms, value_parser = clap::value_parser!(u32).range(0..=gesture_runtime::blob::MAX_ONSET_WINDOW_MS as i64))]
    pub onset_window_ms: u32,
    /// Longest wait for an onset at a segment's end (ms; the body runs on meanwhile).
    #[arg(long, default_value_t = DecisionTiming::DEFAULT.max_wait_ms, value_parser = clap::value_parser!(u32).range(0..=gesture_runtime::blob::MAX_WAIT_MS as i64))]
    pub max_wait_ms: u32,
    /// Longest hold at a motion beat (a pause of the hands) waiting for an onset (ms; 0: no
    /// holds).
    #[arg(long, default_value_t = DecisionTiming::DEFAULT.beat_hold_ms, value_parser = clap::value_parser!(u32).range(0..=gesture_runtime::blob::MAX_BEAT_HOLD_MS as i64))]
    pub beat_hold_ms: u32,
    /// A cut decided in the middle of a segment waits for the playing segment's hands to
    /// pause: its first calm frame within this many ms, else its first motion beat there, else
    /// its last frame there, else the first of these that comes, so the cut falls between
    /// strokes (ms; 0: cut at once).
    #[arg(long, default_value_t = DecisionTiming::DEFAULT.defer_cut_ms, value_parser = clap::value_parser!(u32).range(0..=gesture_runtime::blob::MAX_DEFER_CUT_MS as i64))]
    pub defer_cut_ms: u32,
    /// Cost of entering a segment entered just now, falling to 0 over --recency-ms (0: no
    /// recency cost).
    #[arg(long, default_value_t = crate::pack::DEFAULT_VARIETY.recency_cost, value_parser = cost_f32)]
    pub recency_cost: f32,
    /// Recency window (ms).
    #[arg(long, default_value_t = crate::pack::DEFAULT_VARIETY.recency_ms, value_parser = clap::value_parser!(u32).range(0..=u16::MAX as i64))]
    pub recency_ms: u32,
    /// Cost per unit of a segment's share of the frames played in the last --usage-ms.
    #[arg(long, default_value_t = crate::pack::DEFAULT_VARIETY.usage_cost, value_parser = cost_f32)]
    pub usage_cost: f32,
    /// Usage window (ms).
    #[arg(long, default_value_t = crate::pack::DEFAULT_VARIETY.usage_ms, value_parser = clap::value_parser!(u32).range(0..=u16::MAX as i64))]
    pub usage_ms: u32,
    /// Silence (ms) after which the character rests, moving to the library's calmest
    /// segments (0: never rests).
    #[arg(long, default_value_t = crate::pack::DEFAULT_FOLLOW.rest_ms, value_parser = clap::value_parser!(u32).range(0..=gesture_runtime::blob::MAX_REST_MS as i64))]
    pub rest_ms: u32,
    /// Cost per unit of a segment's energy while resting (0: no rest).
    #[arg(long, default_value_t = crate::pack::DEFAULT_FOLLOW.rest_cost, value_parser = cost_f32)]
    pub rest_cost: f32,
    /// Cost per unit of a segment's energy at full voice level while speaking: louder speech
    /// favours energetic segments, quieter calm ones (0: off).
    #[arg(long, default_value_t = crate::pack::DEFAULT_FOLLOW.energy_cost, value_parser = cost_f32)]
    pub energy_cost: f32,
    /// Inertialization time at cuts (ms; 0: hard cuts).
    #[arg(long, default_value_t = crate::pack::DEFAULT_BLEND_MS, value_parser = clap::value_parser!(u32).range(0..=gesture_runtime::blob::MAX_BLEND_MS as i64))]
    pub blend_ms: u32,
    /// Play the library's legs as captured (feet may slide) instead of holding the lower
    /// body in a standing pose.
    #[arg(long)]
    pub free_legs: bool,
}

impl DeviceArgs {
    /// Refuses values the blob cannot hold.
    pub fn validate(&self) -> Result<(), CliError> {
        for (name, v) in [
            ("--recency-cost", self.recency_cost),
            ("--usage-cost", self.usage_cost),
            ("--rest-cost", self.rest_cost),
            ("--energy-cost", self.energy_cost),
        ] {
            if !(v.is_finite() && (0.0..=1.0e6).contains(&v)) {
                return Err(format!("{name} must be a number from 0 to 1e6, not {v}").into());
            }
        }
        for (name, v, max) in [
            ("--recency-ms", self.recency_ms, 65_535),
            ("--usage-ms", self.usage_ms, 65_535),
            ("--blend-ms", self.blend_ms, 5_000),
            ("--onset-window-ms", self.onset_window_ms, 1_000),
            ("--max-wait-ms", self.max_wait_ms, 5_000),
            ("--beat-hold-ms", self.beat_hold_ms, 1_000),
            ("--defer-cut-ms", self.defer_cut_ms, 1_000),
            ("--rest-ms", self.rest_ms, 10_000),
        ] {
            if v > max {
                return Err(format!("{name} must be at most {max}, not {v}").into());
            }
        }
        Ok(())
    }

    /// Applies these settings to `opts`.
    pub fn apply(&self, opts: &mut crate::pack::PackOptions) {
        opts.timing = if self.immediate {
            DecisionTiming::IMMEDIATE
        } else {
            DecisionTiming {
                sync_to_onsets: true,
                onset_window_ms: self.onset_window_ms,
                max_wait_ms: self.max_wait_ms,
                beat_hold_ms: self.beat_hold_ms,
                defer_cut_ms: self.defer_cut_ms,
            }
        };
        opts.variety = gesture_runtime::policy::Variety {
            recency_cost: self.recency_cost,
            recency_ms: self.recency_ms,
            usage_cost: self.usage_cost,
            usage_ms: self.usage_ms,
        };
        opts.follow = gesture_runtime::follow::VoiceFollow {
            rest_ms: self.rest_ms,
            rest_cost: self.rest_cost,
            energy_cost: self.energy_cost,
        };
        opts.blend_ms = self.blend_ms;
        opts.plant_feet = !self.free_legs;
    }
}

/// Tones to pack (`pack`, `eval-motion`; docs/method.md "Style control").
#[derive(Debug, Clone, Default, clap::Args)]
pub struct StyleArgs {
    /// Neutral motion the tones are compared with: BVH files, folders or path patterns (e.g.
    /// `'bandai/*_normal_*.bvh'`).
    #[arg(long, num_args = 1.., value_name = "FILES")]
    pub style_neutral: Vec<String>,
    /// A tone and the motion that shows it, as NAME=PATTERN (a BVH file, a folder or a path
    /// pattern such as `'active=bandai/*_active_*.bvh'`); repeatable. Names: letters, digits,
    /// `-` and `_`.
    #[arg(long = "style", value_name = "NAME=PATTERN")]
    pub style: Vec<String>,
    /// Add the energy knob: tones `energetic` and `calm`, the same motion FACTOR times larger
    /// or smaller (path length, speed, acceleration), no motion data needed.
    #[arg(long, num_args = 0..=1, default_missing_value = "1.5", value_name = "FACTOR",
          value_parser = |s: &str| bounded(s, 1.01, 10.0))]
    pub energy: Option<f64>,
}

/// Whether `name` can name a tone: 1-32 letters, digits, `-` or `_`, and not `neutral` (the
/// policy's own tables).
pub fn tone_name_ok(name: &str) -> bool {
    (1..=32).contains(&name.len())
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        && name != "neutral"
}

/// The BVH files a command-line path or pattern names (`flag` for the error): a file, the
/// BVH files under a folder, or the files a pattern with `*`, `?` or `[` matches.
pub fn bvh_files(flag: &str, pattern: &str) -> Result<Vec<std::path::PathBuf>, CliError> {
    let is_bvh = |p: &std::path::Path| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh"));
    let mut out: Vec<std::path::PathBuf> = if pattern.contains(['*', '?', '[']) {
        glob::glob(pattern)
            .map_err(|e| CliError::Input(format!("{flag} {pattern}: bad pattern: {e}")))?
            .filter_map(Result::ok)
            .filter(|p| p.is_file() && is_bvh(p))
            .collect()
    } else {
        let p = std::path::PathBuf::from(pattern);
        if !p.exists() {
            return Err(CliError::Input(format!(
                "{flag} {pattern}: no such file or folder"
            )));
        }
        crate::corpus::discover(&[p])
            .map_err(|e| CliError::Input(format!("{flag} {pattern}: {e}")))?
            .into_iter()
            .filter_map(|t| t.bvh)
            .collect()
    };
    out.sort();
    if out.is_empty() {
        return Err(CliError::Input(format!(
            "{flag} {pattern}: matches no .bvh file"
        )));
    }
    Ok(out)
}

impl StyleArgs {
    /// The tones to pack, every pattern expanded and every name checked.
    pub fn options(&self) -> Result<crate::pack::StyleOptions, CliError> {
        let mut o = crate::pack::StyleOptions {
            energy: self.energy,
            ..Default::default()
        };
        for p in &self.style_neutral {
            o.neutral.extend(bvh_files("--style-neutral", p)?);
        }
        for spec in &self.style {
            let (name, pattern) = spec.split_once('=').ok_or_else(|| {
                CliError::Input(format!(
                    "--style {spec}: expected NAME=PATTERN (e.g. 'active=clips/*_active_*.bvh')"
                ))
            })?;
            if !tone_name_ok(name) {
                return Err(CliError::Input(format!(
                    "--style {spec}: `{name}` cannot name a tone (1-32 letters, digits, - or _; \
                     not `neutral`)"
                )));
            }
            if o.tones.iter().any(|(n, _)| n == name) {
                return Err(CliError::Input(format!(
                    "--style {spec}: the tone `{name}` is given twice"
                )));
            }
            o.tones.push((
                name.to_string(),
                bvh_files(&format!("--style {name}="), pattern)?,
            ));
        }
        if !o.tones.is_empty() && o.neutral.is_empty() {
            return Err(CliError::Input(
                "--style needs neutral motion to compare with: add --style-neutral FILES".into(),
            ));
        }
        if o.tones.is_empty() && !o.neutral.is_empty() {
            return Err(CliError::Input(
                "--style-neutral without any --style NAME=PATTERN: nothing to compare".into(),
            ));
        }
        Ok(o)
    }
}

/// Semantic labels to pack (`pack`; docs/method.md "Semantic labels").
#[derive(Debug, Clone, Default, clap::Args)]
pub struct LabelArgs {
    /// A label and the library files that carry it, as NAME=PATTERN on file names (e.g.
    /// `'bye=*_bye_*'`); repeatable. The stroke is the clip's hand-speed peak.
    #[arg(long = "label", value_name = "NAME=PATTERN")]
    pub label: Vec<String>,
    /// Labels from a CSV file with the header `pattern,label,stroke_s` (`stroke_s`, the stroke's
    /// time in the clip, may be empty: the hand-speed peak).
    #[arg(long, value_name = "CSV")]
    pub label_file: Option<std::path::PathBuf>,
    /// Cost of every decision that does not serve a waiting label.
    #[arg(long, default_value_t = crate::control::semantic::LabelParams::default().semantic_cost, value_parser = weight)]
    pub semantic_cost: f64,
    /// A label not shown within this long is dropped (ms).
    #[arg(long, default_value_t = crate::control::semantic::LabelParams::default().timeout_ms, value_parser = |s: &str| count(s, 100, 60_000).map(|v| v as u32))]
    pub label_timeout_ms: u32,
    /// Enter a labelled gesture at its first frame only (no jump toward the stroke).
    #[arg(long)]
    pub no_stroke_entry: bool,
}

impl LabelArgs {
    /// The label specs and settings, every name checked and the label file read.
    pub fn options(
        &self,
    ) -> Result<
        (
            Vec<crate::control::semantic::LabelSpec>,
            crate::control::semantic::LabelParams,
        ),
        CliError,
    > {
        use crate::control::semantic::{LabelParams, LabelSpec};
        let mut specs = Vec::new();
        let name_ok = |name: &str, what: &str| -> Result<(), CliError> {
            if (1..=32).contains(&name.len())
                && name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
            {
                Ok(())
            } else {
                Err(CliError::Input(format!(
                    "{what}: `{name}` cannot name a label (1-32 letters, digits, - or _)"
                )))
            }
        };
        for spec in &self.label {
            let (name, pattern) = spec.split_once('=').ok_or_else(|| {
                CliError::Input(format!(
                    "--label {spec}: expected NAME=PATTERN (e.g. 'bye=*_bye_*')"
                ))
            })?;
            name_ok(name, &format!("--label {spec}"))?;
            glob::Pattern::new(pattern)
                .map_err(|e| CliError::Input(format!("--label {spec}: bad pattern: {e}")))?;
            specs.push(LabelSpec {
                name: name.into(),
                pattern: pattern.into(),
                stroke_s: None,
            });
        }
        if let Some(path) = &self.label_file {
            let text = std::fs::read_to_string(path)
                .map_err(|e| CliError::Input(format!("{}: {e}", path.display())))?;
            let mut lines = text.lines().enumerate();
            match lines.next() {
                Some((_, h)) if h.trim().starts_with("pattern") => {}
                _ => {
                    return Err(CliError::Input(format!(
                        "{}:1: expected the header `pattern,label,stroke_s`",
                        path.display()
                    )))
                }
            }
            for (i, line) in lines {
                let what = format!("{}:{}", path.display(), i + 1);
                if line.trim().is_empty() || line.trim_start().starts_with('#') {
                    continue;
                }
                let f: Vec<&str> = line.split(',').map(str::trim).collect();
                if f.len() < 2 || f.len() > 3 {
                    return Err(CliError::Input(format!(
                        "{what}: expected `pattern,label,stroke_s`"
                    )));
                }
                name_ok(f[1], &what)?;
                glob::Pattern::new(f[0])
                    .map_err(|e| CliError::Input(format!("{what}: bad pattern: {e}")))?;
                let stroke_s = match f.get(2) {
                    Some(v) if !v.is_empty() => Some(
                        v.parse::<f64>()
                            .ok()
                            .filter(|t| t.is_finite() && *t >= 0.0)
                            .ok_or_else(|| {
                                CliError::Input(format!("{what}: `{v}` is not a time in seconds"))
                            })?,
                    ),
                    _ => None,
                };
                specs.push(LabelSpec {
                    name: f[1].into(),
                    pattern: f[0].into(),
                    stroke_s,
                });
            }
        }
        let params = LabelParams {
            semantic_cost: self.semantic_cost,
            timeout_ms: self.label_timeout_ms,
            stroke_entry: !self.no_stroke_entry,
            ..LabelParams::default()
        };
        Ok((specs, params))
    }
}
