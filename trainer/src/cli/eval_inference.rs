//! `gesture-train eval-inference`: the paper's Fig. 4 on our data. Fits on `--train`, scores
//! the online beliefs of the CRF, Brand's remapped HMM and the state prior on `--test` for each
//! window (the logic is `inference::eval::evaluate`; this file parses and prints). The model
//! selection curves go to stderr. With `--json`, stdout is exactly one JSON object
//! `{"rows":[{"window":W,"crf":X,"hmm":Y,"prior":Z,"gain":G,"gain_se":E,"l2":L,"lag_penalty":P}, ...],
//! "states":S,"clusters":K,"train_steps":N,"test_steps":M}` (plus `"ari":[train,test]` on a
//! synthetic corpus); progress and extras go to stderr.
//!
//! When a training folder holds a synthetic corpus's `truth.json`, the adjusted Rand index
//! between the HMM's most likely states and the planted states is reported too.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::args::{parse_span, CorpusArgs, ModelArgs};
use super::CliError;
use crate::corpus::load_corpus;
use crate::inference::eval::{self, EvalReport, PlantedRuns};
use crate::inference::train::sequences;

/// Arguments of `eval-inference`.
#[derive(Debug, clap::Args)]
pub struct EvalArgs {
    /// Training corpus (files or folders).
    #[arg(long, required = true, num_args = 1..)]
    pub train: Vec<PathBuf>,
    /// Test corpus (files or folders).
    #[arg(long, required = true, num_args = 1..)]
    pub test: Vec<PathBuf>,
    /// CRF windows to compare.
    #[arg(long, value_delimiter = ',', default_values_t = [1usize, 2, 3, 4, 5], value_parser = |s: &str| super::args::count(s, 1, gesture_runtime::inference::MAX_WINDOW))]
    pub windows: Vec<usize>,
    /// Use only training steps in START:END seconds of each take.
    #[arg(long, value_parser = parse_span)]
    pub train_span: Option<(f64, f64)>,
    /// Use only test steps in START:END seconds of each take.
    #[arg(long, value_parser = parse_span)]
    pub test_span: Option<(f64, f64)>,
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
    let (train_seqs, segs) = sequences(&train, a.train_span);
    let (test_seqs, _) = sequences(&test, a.test_span);
    // S and K are chosen with the paper's window (4) when it is compared, as `fit` does.
    let w = if a.windows.contains(&4) {
        4
    } else {
        a.windows.first().copied().unwrap_or(4)
    };
    let cfg = a.model.config(w);
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

/// Runs the command.
pub fn run(a: &EvalArgs) -> Result<(), CliError> {
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
        "{:>6} {:>10} {:>10} {:>10} {:>10} {:>7} {:>8} {:>6}",
        "window",
        "crf",
        "hmm",
        "prior",
        "gain",
        "+-se",
        "l2",
        "lag"
    )?;
    for w in &r.rows {
        outln!(
            "{:>6} {:>10.3} {:>10.3} {:>10.3} {:>+10.3} {:>7.3} {:>8} {:>6}",
            w.window,
            w.crf,
            w.hmm,
            w.prior,
            w.gain,
            w.gain_se,
            w.l2,
            w.lag_penalty
        )?;
    }
    outln!("{extras}")?;
    Ok(())
}
