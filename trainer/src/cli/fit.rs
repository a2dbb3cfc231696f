//! `gesture-train fit`: trains the inference layer and writes the model file.

use std::path::PathBuf;
use std::time::Instant;

use super::args::{parse_span, CorpusArgs, ModelArgs};
use super::exit::CliError;
use crate::corpus::load_corpus;
use crate::inference::train::{fit, sequences};

/// Arguments of `fit`.
#[derive(Debug, clap::Args)]
pub struct FitArgs {
    /// Training corpus: BVH+WAV files or folders.
    #[arg(long, required = true, num_args = 1..)]
    pub corpus: Vec<PathBuf>,
    /// CRF input window W (syllables, causal).
    #[arg(long, default_value_t = 4, value_parser = |s: &str| super::args::count(s, 1, gesture_runtime::inference::MAX_WINDOW))]
    pub window: usize,
    /// Use only steps whose midpoint is in START:END seconds of each take.
    #[arg(long, value_parser = parse_span)]
    pub span: Option<(f64, f64)>,
    /// Output model file.
    #[arg(long)]
    pub out: PathBuf,
    /// Model options.
    #[command(flatten)]
    pub model: ModelArgs,
    /// Corpus loading options.
    #[command(flatten)]
    pub load: CorpusArgs,
}

/// Runs the command.
pub fn run(a: &FitArgs) -> Result<(), CliError> {
    let start = Instant::now();
    // The output must not be one of the recordings it is trained on.
    let inputs: Vec<std::path::PathBuf> = crate::corpus::discover(&a.corpus)
        .map(|takes| {
            takes
                .into_iter()
                .flat_map(|t| [t.bvh, t.wav])
                .flatten()
                .collect()
        })
        .unwrap_or_default();
    let inputs: Vec<&std::path::Path> = inputs.iter().map(|p| p.as_path()).collect();
    crate::output::refuse_inputs(&[&a.out], &inputs)?;
    let load = a.load.options();
    let corpus = load_corpus(&a.corpus, &load)?;
    let (seqs, segs) = sequences(&corpus, a.span);
    let steps: usize = seqs.iter().map(|s| s.len()).sum();
    eprintln!(
        "loaded {} takes, {steps} steps, {} segments in {:.2} s",
        corpus.takes.len(),
        segs.len(),
        corpus.load_s
    );
    let mut cfg = a.model.config(a.window);
    // The model records the front end its features came from.
    cfg.prosody = load.prosody;
    cfg.sample_rate_hz = load.prosody.sample_rate_hz;
    // A spinner while it works (terminal only); the stage lines print above it.
    let sp = crate::progress::spinner("fit: model selection and training");
    let (model, report) = fit(&seqs, &segs, &cfg, &|line| {
        sp.suspend(|| eprintln!("{line}"))
    })?;
    sp.finish_and_clear();
    model.save(&a.out)?;
    if let Some(sel) = &report.selection {
        outln!("{}", sel.to_string().trim_end())?;
    }
    outln!(
        "wrote {}: {}; fit {:.2} s (selection {:.2}, hmm {:.2}, gmm {:.2}, crf {:.2}), total {:.2} s",
        a.out.display(),
        model.summary,
        report.seconds.iter().sum::<f64>(),
        report.seconds[0],
        report.seconds[1],
        report.seconds[2],
        report.seconds[3],
        start.elapsed().as_secs_f64()
    )?;
    Ok(())
}
