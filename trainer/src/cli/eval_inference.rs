//! `gesture-train eval-inference`: the paper's Fig. 4 on our data. Fits on `--train`, scores
//! the online beliefs of the CRF, Brand's remapped HMM and the state prior on `--test` for each
//! window (the logic is `inference::eval::evaluate`; this file parses and prints). The model
//! selection curves go to stderr. With `--json`, stdout is exactly one JSON object
//! `{"rows":[{"window":W,"crf":X,"hmm":Y,"prior":Z,"gain":G,"gain_se":E,"crf_hmm_se":H,
//! "take_prior":T,"take_gain":TG,"take_gain_se":TE,"l2":L,"lag_penalty":P}, ...],
//! "states":S,"clusters":K,"train_steps":N,"test_steps":M,"raw_offset":R}` (plus
//! `"ari":[train,test]` on a synthetic corpus); progress and extras go to stderr. The take
//! prior and `raw_offset` are described in `inference::eval`: the gain over the take prior is
//! what speech says within a take (with several training takes the gain over the prior also
//! counts telling them apart), and `crf + raw_offset` compares across training corpora and
//! `--take-level`.
//!
//! **Leave one take out**: `--train A --test B` (a take outside the training takes is
//! standardized by its own level, as a library is). **Pooled or alone** on a held-out span of
//! a take: `--folds N --test A` with `--train A` or `--train A B`, compared by
//! `crf + raw_offset` or the take gain, not by the gain (the two models' priors differ).
//!
//! When a training folder holds a synthetic corpus's `truth.json`, the adjusted Rand index
//! between the HMM's most likely states and the planted states is reported too.
//!
//! **Cross-validation over time** (`--folds N`): instead of a test corpus, each take (or
//! each take of `--test`, which must be among the training takes) is cut into N spans of
//! equal length and each span is held out in turn, the model trained on everything else
//! (less the steps sharing a motion segment with the held-out span;
//! `inference::train::cv_split`), model selection included. Rows are means over all held-out
//! steps; the gain's standard error comes from the spread of the folds' gains, and each
//! fold's gain is printed (`fold_gains` in the JSON, with every fold's report under
//! `folds`), and likewise `crf - hmm` (`crf_hmm`, `crf_hmm_se`, `fold_crf_hmm`) and the take
//! gain (`take_prior`, `take_gain`, `take_gain_se`); `raw_offset` is the folds'. One split is one draw: on the 9-joint take (4 folds, W = 4) the folds' gains
//! range over +0.36 to +0.40.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::args::{parse_span, CorpusArgs, ModelArgs};
use super::exit::CliError;
use crate::corpus::load_corpus;
use crate::inference::eval::{self, CvReport, EvalReport, PlantedRuns};
use crate::inference::train::{cv_split_levels, pooled_levels, sequences_with_levels, take_levels};

/// Arguments of `eval-inference`.
#[derive(Debug, clap::Args)]
pub struct EvalArgs {
    /// Training corpus (files or folders).
    #[arg(long, required = true, num_args = 1..)]
    pub train: Vec<PathBuf>,
    /// Test corpus (files or folders); with `--folds`, the training takes to hold spans of
    /// out (default: every training take).
    #[arg(long, required_unless_present = "folds", num_args = 1..)]
    pub test: Vec<PathBuf>,
    /// Cross-validate over time: hold out each of N equal spans of each (test) take in
    /// turn, training on the rest.
    #[arg(long, value_parser = |s: &str| super::args::count(s, 2, 10), conflicts_with_all = ["train_span", "test_span"])]
    pub folds: Option<usize>,
    /// CRF windows to compare.
    #[arg(long, value_delimiter = ',', default_values_t = [1usize, 2, 3, 4, 5], value_parser = |s: &str| super::args::count(s, 1, gesture_runtime::inference::MAX_WINDOW))]
    pub windows: Vec<usize>,
    /// Use only training steps in START:END seconds of each take.
    #[arg(long, value_parser = parse_span)]
    pub train_span: Option<(f64, f64)>,
    /// Use only test steps in START:END seconds of each take.
    #[arg(long, value_parser = parse_span)]
    pub test_span: Option<(f64, f64)>,
    /// How each take's log kinematic parameters are standardized before the model's
    /// normalization: by the take's own level (`own`, as `fit` does) or all takes alike by the
    /// level of every training segment together (`pooled`, as before takes had levels of their
    /// own; a test take outside the training takes gets that level too).
    #[arg(long, value_enum, default_value_t = TakeLevel::Own)]
    pub take_level: TakeLevel,
    /// Print exactly one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
    /// Model options.
    #[command(flatten)]
    pub model: ModelArgs,
    /// Corpus loading options.
    #[command(flatten)]
    pub load: CorpusArgs,
}

/// How takes are standardized (`--take-level`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TakeLevel {
    /// Each take by its own level.
    Own,
    /// Every take by the level of all training segments together.
    Pooled,
}

/// Planted state runs per take stem, from a `truth.json` next to the inputs.
fn planted_runs(inputs: &[PathBuf]) -> Option<PlantedRuns> {
    let mut out = HashMap::new();
    for p in inputs {
        let dir: &Path = if p.is_dir() { p } else { p.parent()? };
        let Ok(text) = std::fs::read_to_string(dir.join("truth.json")) else {
            continue;
        };
        let v: serde_json::Value = serde_json::from_str(&text).ok()?;
        for t in v["takes"].as_array()? {
            let runs = t["state_runs"]
                .as_array()?
                .iter()
                .filter_map(|r| {
                    Some((
                        r["start_s"].as_f64()?,
                        r["end_s"].as_f64()?,
                        r["state"].as_u64()? as usize,
                    ))
                })
                .collect();
            out.insert(t["stem"].as_str()?.to_string(), runs);
        }
    }
    (!out.is_empty()).then_some(out)
}

/// Loads both corpora and runs [`crate::inference::eval::evaluate`].
pub fn evaluate(a: &EvalArgs) -> Result<EvalReport, CliError> {
    let opts = a.load.options();
    let train = load_corpus(&a.train, &opts)?;
    let test = if a.test == a.train {
        train.clone()
    } else {
        load_corpus(&a.test, &opts)?
    };
    // A test span of a training take is standardized by the training span's level.
    let levels = match a.take_level {
        TakeLevel::Own => take_levels(&train, a.train_span),
        TakeLevel::Pooled => {
            let mut levels = pooled_levels(&train, a.train_span);
            if let Some(&pooled) = levels.values().next() {
                for t in &test.takes {
                    levels.entry(t.stem.clone()).or_insert(pooled);
                }
            }
            levels
        }
    };
    let (train_seqs, segs) = sequences_with_levels(&train, a.train_span, &levels);
    let (test_seqs, _) = sequences_with_levels(&test, a.test_span, &levels);
    let cfg = a.model.config(selection_window(a));
    let (train_runs, test_runs) = (planted_runs(&a.train), planted_runs(&a.test));
    Ok(eval::evaluate(
        (&train_seqs, &segs),
        &test_seqs,
        &cfg,
        &a.windows,
        (train_runs.as_ref(), test_runs.as_ref()),
        &|line| eprintln!("{line}"),
    )?)
}

/// The paper's window when compared, else the first: S and K are chosen with it, as `fit`
/// does.
fn selection_window(a: &EvalArgs) -> usize {
    if a.windows.contains(&4) {
        4
    } else {
        a.windows.first().copied().unwrap_or(4)
    }
}

/// Loads the training corpus and runs [`crate::inference::eval::cross_validate`] with
/// `--folds` (see the module docs).
pub fn cross_validate(a: &EvalArgs) -> Result<CvReport, CliError> {
    let folds = a
        .folds
        .ok_or_else(|| CliError::Input("cross-validation needs --folds N".into()))?;
    let opts = a.load.options();
    let train = load_corpus(&a.train, &opts)?;
    let held: Vec<String> = if a.test.is_empty() {
        train.takes.iter().map(|t| t.stem.clone()).collect()
    } else {
        let test = load_corpus(&a.test, &opts)?;
        let mut stems = Vec::new();
        for t in &test.takes {
            if !train.takes.iter().any(|u| u.stem == t.stem) {
                return Err(CliError::Input(format!(
                    "--test take {} is not among the --train takes (with --folds, --test names \
                     the training takes to hold spans of out)",
                    t.stem
                )));
            }
            stems.push(t.stem.clone());
        }
        stems
    };
    let splits: Vec<_> = (0..folds)
        .map(|k| {
            cv_split_levels(
                &train,
                k,
                folds,
                |stem| held.iter().any(|h| h == stem),
                a.take_level == TakeLevel::Own,
            )
        })
        .collect();
    let cfg = a.model.config(selection_window(a));
    Ok(eval::cross_validate(&splits, &cfg, &a.windows, &|line| {
        eprintln!("{line}")
    })?)
}

fn run_folds(a: &EvalArgs) -> Result<(), CliError> {
    let r = cross_validate(a)?;
    let train: usize = r.folds.iter().map(|f| f.train_steps).sum::<usize>() / r.folds.len().max(1);
    let test: usize = r.folds.iter().map(|f| f.test_steps).sum();
    let models: Vec<String> = r
        .folds
        .iter()
        .map(|f| format!("S={} K={}", f.states, f.clusters))
        .collect();
    let extras = format!(
        "{} folds: {test} test steps in all, about {train} training steps each; models {}; \
         {:.2} s",
        r.folds.len(),
        models.join(", "),
        r.seconds
    );
    if a.json {
        eprintln!("{extras}");
        outln!("{}", serde_json::to_string(&r)?)?;
        return Ok(());
    }
    outln!("mean log-likelihood per held-out step of the true kinematic parameters, all folds")?;
    outln!(
        "{:>6} {:>9} {:>9} {:>9} {:>8} {:>6} {:>8} {:>6} {:>9} {:>6}  {}",
        "window",
        "crf",
        "hmm",
        "prior",
        "gain",
        "+-se",
        "crf-hmm",
        "+-se",
        "take-gain",
        "+-se",
        "gain per fold"
    )?;
    for w in &r.rows {
        let per: Vec<String> = w.fold_gains.iter().map(|g| format!("{g:+.3}")).collect();
        outln!(
            "{:>6} {:>9.3} {:>9.3} {:>9.3} {:>+8.3} {:>6.3} {:>+8.3} {:>6.3} {:>+9.3} {:>6.3}  {}",
            w.window,
            w.crf,
            w.hmm,
            w.prior,
            w.gain,
            w.gain_se,
            w.crf_hmm,
            w.crf_hmm_se,
            w.take_gain,
            w.take_gain_se,
            per.join(" ")
        )?;
    }
    let per: Vec<String> = r
        .rows
        .iter()
        .map(|w| {
            let d: Vec<String> = w.fold_crf_hmm.iter().map(|g| format!("{g:+.3}")).collect();
            format!("W={}: {}", w.window, d.join(" "))
        })
        .collect();
    outln!("crf-hmm per fold: {}", per.join("; "))?;
    outln!(
        "{}",
        raw_line(r.raw_offset, r.rows.iter().map(|w| (w.window, w.crf)))
    )?;
    outln!("{extras}")?;
    Ok(())
}

/// The CRF's scores as log-densities of the log kinematic parameters themselves.
fn raw_line(offset: f64, crf: impl Iterator<Item = (usize, f64)>) -> String {
    let v: Vec<String> = crf
        .map(|(w, c)| format!("W={w} {:.3}", c + offset))
        .collect();
    format!(
        "crf as log-density of the log kinematic parameters (scores {offset:+.3}; compares \
         across training corpora and --take-level): {}",
        v.join(", ")
    )
}

/// Runs the command.
pub fn run(a: &EvalArgs) -> Result<(), CliError> {
    if a.folds.is_some() {
        return run_folds(a);
    }
    let r = evaluate(a)?;
    let mut extras = format!(
        "train {} steps, test {} steps, S={} K={}; {:.2} s",
        r.train_steps, r.test_steps, r.states, r.clusters, r.seconds
    );
    if let Some((train, test)) = r.ari {
        extras += &format!("; ARI(HMM states, planted) train {train:.3}");
        if let Some(t) = test {
            extras += &format!(", test {t:.3}");
        }
    }
    if a.json {
        if let Some(sel) = &r.selection {
            eprint!("{sel}");
        }
        eprintln!("{extras}");
        outln!("{}", serde_json::to_string(&r)?)?;
        return Ok(());
    }
    if let Some(sel) = &r.selection {
        eprint!("{sel}");
    }
    outln!("mean log-likelihood per test step of the true kinematic parameters")?;
    outln!(
        "{:>6} {:>9} {:>9} {:>9} {:>8} {:>6} {:>8} {:>6} {:>9} {:>6} {:>7} {:>5}",
        "window",
        "crf",
        "hmm",
        "prior",
        "gain",
        "+-se",
        "crf-hmm",
        "+-se",
        "take-gain",
        "+-se",
        "l2",
        "lag"
    )?;
    for w in &r.rows {
        outln!(
            "{:>6} {:>9.3} {:>9.3} {:>9.3} {:>+8.3} {:>6.3} {:>+8.3} {:>6.3} {:>+9.3} {:>6.3} {:>7} {:>5}",
            w.window,
            w.crf,
            w.hmm,
            w.prior,
            w.gain,
            w.gain_se,
            w.crf - w.hmm,
            w.crf_hmm_se,
            w.take_gain,
            w.take_gain_se,
            w.l2,
            w.lag_penalty
        )?;
    }
    outln!(
        "{}",
        raw_line(r.raw_offset, r.rows.iter().map(|w| (w.window, w.crf)))
    )?;
    outln!("{extras}")?;
    Ok(())
}
