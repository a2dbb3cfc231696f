//! `gesture-train pack`: model + library + rig into a policy blob, with a JSON report.

use std::path::PathBuf;

use super::args::{ControlArgs, CorpusArgs, DeviceArgs, LabelArgs, StyleArgs};
use super::exit::CliError;
use crate::output::write_atomic;
use crate::pack::{pack, PackOptions};

/// Arguments of `pack`.
#[derive(Debug, clap::Args)]
pub struct PackArgs {
    /// Trained inference model (from `gesture-train fit`).
    #[arg(long)]
    pub model: PathBuf,
    /// Gesture library: BVH files or folders (WAV files are ignored).
    #[arg(long, required = true, num_args = 1..)]
    pub library: Vec<PathBuf>,
    /// Rig file (TOML); default: every rotation channel of the library's skeleton.
    #[arg(long)]
    pub rig: Option<PathBuf>,
    /// Largest blob size in bytes; successor lists are truncated to fit (with regret reported).
    #[arg(long, value_parser = |s: &str| super::args::count(s, 1, usize::MAX))]
    pub budget_bytes: Option<usize>,
    /// Output blob.
    #[arg(long)]
    pub out: PathBuf,
    /// Write the pack report (JSON) here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Leave out the host-side skeleton section (the simulator then writes no BVH).
    #[arg(long)]
    pub no_skeleton: bool,
    /// Corpus loading options (effectors).
    #[command(flatten)]
    pub load: CorpusArgs,
    /// Control-layer options.
    #[command(flatten)]
    pub control: ControlArgs,
    /// How the device runs the policy.
    #[command(flatten)]
    pub device: DeviceArgs,
    /// Tones mixed at run time.
    #[command(flatten)]
    pub styles: StyleArgs,
    /// Semantic labels.
    #[command(flatten)]
    pub labels: LabelArgs,
}

/// Runs the command.
pub fn run(a: &PackArgs) -> Result<(), CliError> {
    // No output may be an input (the model, the rig, a library file) or the other output.
    let mut inputs: Vec<std::path::PathBuf> = vec![a.model.clone()];
    inputs.extend(a.rig.clone());
    inputs.extend(a.labels.label_file.clone());
    let styles = a.styles.options()?;
    let (labels, label_params) = a.labels.options()?;
    inputs.extend(styles.neutral.iter().cloned());
    inputs.extend(styles.tones.iter().flat_map(|(_, f)| f.iter().cloned()));
    if let Ok(takes) = crate::corpus::discover(&a.library) {
        inputs.extend(takes.into_iter().flat_map(|t| [t.bvh, t.wav]).flatten());
    }
    if let Some(r) = &a.report {
        inputs.push(r.clone());
        // The report against the inputs, the blob against the inputs and the report (a report
        // that does not exist yet cannot be compared by canonical path: compare the targets).
        if crate::output::canonical_target(r) == crate::output::canonical_target(&a.out) {
            return Err(CliError::Input(format!(
                "{}: --out and --report are the same file",
                a.out.display()
            )));
        }
    }
    let ins: Vec<&std::path::Path> = inputs.iter().map(|p| p.as_path()).collect();
    crate::output::refuse_inputs(&[&a.out], &ins)?;
    if let Some(r) = &a.report {
        crate::output::refuse_inputs(&[r], &ins[..ins.len() - 1])?;
    }
    a.control.validate()?;
    a.device.validate()?;
    let mut opts = PackOptions {
        styles,
        labels,
        label_params,
        control: a.control.params(),
        rig: a.rig.clone(),
        budget_bytes: a.budget_bytes,
        effectors: a.load.options().effectors,
        no_skeleton: a.no_skeleton,
        ..PackOptions::default()
    };
    a.device.apply(&mut opts);
    let r = pack(&a.model, &a.library, &opts, &a.out)?;
    outln!(
        "wrote {}: {} bytes (front-end {}, inference {}, policy {}, control {}, library {}, \
         rig {}, skeleton {}, styles {}, labels {})",
        a.out.display(),
        r.blob_bytes,
        r.section_bytes.front_end,
        r.section_bytes.inference,
        r.section_bytes.policy,
        r.section_bytes.control,
        r.section_bytes.library,
        r.section_bytes.rig,
        r.section_bytes.skeleton,
        r.section_bytes.styles,
        r.section_bytes.labels
    )?;
    outln!(
        "library: {} segments, {} exit points, {} frames; rig {} ({} channels)",
        r.segments,
        r.exit_points,
        r.frames,
        r.rig,
        r.channels
    )?;
    for line in &r.rig_channels {
        outln!("  {line}")?;
    }
    outln!(
        "lower body: {}",
        r.lower_body
            .as_deref()
            .unwrap_or("as captured (no legs, or --free-legs)")
    )?;
    outln!(
        "successors: {} of {} kept ({:.2}% pruned{}); regret {:.4}%, agreement {:.2}% over {} simulated decisions",
        r.entries_kept,
        r.entries_total,
        100.0 * r.pruned_fraction,
        r.successors_per_exit
            .map_or(String::new(), |k| format!(", at most {k} per exit point")),
        100.0 * r.regret,
        100.0 * r.agreement,
        r.regret_decisions
    )?;
    for l in &r.labels {
        outln!(
            "label {}: {} (segment {}, stroke at frame {}, entered from frame {} at the latest)",
            l.label,
            l.clip,
            l.segment,
            l.stroke_frame,
            l.max_entry_frame
        )?;
    }
    for t in &r.styles {
        let f = t.factors;
        outln!(
            "tone {}: {} ({} bytes): T x{:.2} D x{:.2} V x{:.2} A x{:.2} C x{:.2} H x{:.2}; \
             regret {:.4}%, agreement {:.2}%",
            t.name,
            if t.segments > 0 {
                format!("fitted on {} segments", t.segments)
            } else {
                "synthetic".into()
            },
            t.bytes,
            f[0],
            f[1],
            f[2],
            f[3],
            f[4],
            f[5],
            100.0 * t.regret,
            100.0 * t.agreement
        )?;
    }
    outln!(
        "time: load {:.2} s, costs {:.2} s, value iteration {:.2} s, pruning {:.2} s, write {:.2} s, total {:.2} s",
        r.timings.load_s,
        r.timings.costs_s,
        r.timings.value_iteration_s,
        r.timings.pruning_s,
        r.timings.write_s,
        r.timings.total_s
    )?;
    if let Some(p) = &a.report {
        let text = serde_json::to_string_pretty(&r)?;
        write_atomic(p, text.as_bytes())?;
    }
    Ok(())
}
