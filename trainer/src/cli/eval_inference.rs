//! `gesture-train eval-inference`: the paper's Fig. 4 on our data. Fits on `--train`, scores
//! the online beliefs of the CRF, Brand's remapped HMM and the state prior on `--test` for each
//! window (see `inference::eval`). With `--json`, stdout is exactly one JSON object
//! `{"rows":[{"window":W,"crf":X,"hmm":Y,"prior":Z}, ...]}`; progress and extras go to stderr.
//!
//! When a training folder holds a synthetic corpus's `truth.json`, the adjusted Rand index
//! between the HMM's most likely states and the planted states is reported too.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;

use super::args::{parse_span, CorpusArgs, ModelArgs};
use super::CliError;
use crate::corpus::load_corpus;
use crate::inference::eval::{
    adjusted_rand_index, crf_beliefs, mean_score, prior_beliefs, RemappedHmm,
};
use crate::inference::train::{fit_base, fit_crf, normalized, sequences, FitReport, Sequence};

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
    #[arg(long, value_delimiter = ',', default_values_t = [1usize, 2, 3, 4, 5])]
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

/// One row of the comparison.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Row {
    /// Window W.
    pub window: usize,
    /// CRF mean log-likelihood per step.
    pub crf: f64,
    /// Brand's remapped HMM.
    pub hmm: f64,
    /// State prior.
    pub prior: f64,
}

/// Planted state runs `(start_s, end_s, state)` per take stem.
type PlantedRuns = HashMap<String, Vec<(f64, f64, usize)>>;

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

/// ARI between HMM states (argmax posterior) and the planted states at step midpoints.
fn ari(
    base: &crate::inference::train::FitBase,
    seqs: &[Sequence],
    y: &[crate::inference::hmm::Seq],
    runs: &PlantedRuns,
) -> Option<f64> {
    let (mut found, mut planted) = (Vec::new(), Vec::new());
    for (s, ys) in seqs.iter().zip(y) {
        let r = runs.get(&s.stem)?;
        let post = base.hmm.posterior(ys);
        for (g, &(a, b)) in post.gamma_rows().zip(&s.times) {
            let mid = 0.5 * (a + b);
            let Some(&(_, _, state)) = r.iter().find(|(s0, s1, _)| mid >= *s0 && mid < *s1) else {
                continue;
            };
            let best = (0..g.len())
                .max_by(|&i, &j| g[i].total_cmp(&g[j]))
                .unwrap_or(0);
            found.push(best);
            planted.push(state);
        }
    }
    (!found.is_empty()).then(|| adjusted_rand_index(&found, &planted))
}

/// The comparison and the extras line (train/test sizes, timing, ARI when known).
pub fn evaluate(a: &EvalArgs) -> Result<(Vec<Row>, String, Option<f64>), CliError> {
    let start = Instant::now();
    let opts = a.load.options();
    let train = load_corpus(&a.train, &opts)?;
    let test = if a.test == a.train {
        train.clone()
    } else {
        load_corpus(&a.test, &opts)?
    };
    let (train_seqs, segs) = sequences(&train, a.train_span);
    let (test_seqs, _) = sequences(&test, a.test_span);
    let test_steps: usize = test_seqs.iter().map(Sequence::len).sum();
    if test_steps == 0 {
        return Err("the test set has no time steps (check --test and --test-span)".into());
    }
    let cfg = a.model.config(a.windows.first().copied().unwrap_or(4));
    let log = |line: &str| eprintln!("{line}");
    let mut report = FitReport::default();
    let base = fit_base(&train_seqs, &segs, &cfg, &mut report, &log)?;
    let y_test = normalized(&test_seqs, &base.normalization);
    let prior = mean_score(&base, &y_test, &prior_beliefs(&base, &test_seqs));
    let mut rows = Vec::new();
    for &w in &a.windows {
        if !(1..=gesture_runtime::inference::MAX_WINDOW).contains(&w) {
            return Err(format!(
                "window {w} out of range 1-{}",
                gesture_runtime::inference::MAX_WINDOW
            )
            .into());
        }
        let crf = fit_crf(&base, w, cfg.l2, &mut report, &log)?;
        let crf_score = mean_score(&base, &y_test, &crf_beliefs(&base, &crf, &test_seqs));
        let brand = RemappedHmm::fit(&base, &train_seqs, w);
        let hb: Vec<Vec<Vec<f64>>> = test_seqs.iter().map(|s| brand.beliefs(&base, s)).collect();
        let hmm_score = mean_score(&base, &y_test, &hb);
        rows.push(Row {
            window: w,
            crf: crf_score,
            hmm: hmm_score,
            prior,
        });
    }
    let train_steps: usize = train_seqs.iter().map(Sequence::len).sum();
    let mut extras = format!(
        "train {train_steps} steps, test {test_steps} steps, S={} K={}; {:.2} s",
        a.model.states,
        a.model.clusters,
        start.elapsed().as_secs_f64()
    );
    let mut train_ari = None;
    if let Some(runs) = planted_runs(&a.train) {
        if let Some(v) = ari(&base, &train_seqs, &base.y, &runs) {
            extras += &format!("; ARI(HMM states, planted) train {v:.3}");
            train_ari = Some(v);
        }
    }
    if let Some(runs) = planted_runs(&a.test) {
        if let Some(v) = ari(&base, &test_seqs, &y_test, &runs) {
            extras += &format!(", test {v:.3}");
        }
    }
    Ok((rows, extras, train_ari))
}

/// Runs the command.
pub fn run(a: &EvalArgs) -> Result<(), CliError> {
    let (rows, extras, _) = evaluate(a)?;
    if a.json {
        eprintln!("{extras}");
        // A struct, not `json!`, so the keys keep the documented order.
        #[derive(Serialize)]
        struct Rows<'a> {
            rows: &'a [Row],
        }
        outln!("{}", serde_json::to_string(&Rows { rows: &rows })?)?;
        return Ok(());
    }
    outln!("mean log-likelihood per test step of the true kinematic parameters")?;
    outln!(
        "{:>6} {:>10} {:>10} {:>10}",
        "window",
        "crf",
        "hmm",
        "prior"
    )?;
    for r in &rows {
        outln!(
            "{:>6} {:>10.3} {:>10.3} {:>10.3}",
            r.window,
            r.crf,
            r.hmm,
            r.prior
        )?;
    }
    outln!("{extras}")?;
    Ok(())
}
