//! Stage 6 of packing: the report ([`PackReport`], `--report`), measured on the bytes as the
//! device reads them: section sizes from the parsed blob, and the regret and decision
//! agreement of its tables against the float unpruned policy, neutral and per tone
//! ([`crate::control::regret`], seeded), with what the earlier stages did (segments, pruning,
//! the budget's `k`, labelled clips, the held lower body, timings).

use gesture_runtime::blob::encode::EncodeError;
use gesture_runtime::blob::Blob;
use gesture_runtime::policy::Style;
use serde::Serialize;

use crate::control::build::ControlModel;
use crate::control::regret::regret;
use crate::inference::model::InferenceModel;

use super::error::PackError;
use super::library::PackLibrary;
use super::policy::PolicySections;
use super::sections::Sections;

/// Decisions simulated for each regret figure.
pub const REGRET_DECISIONS: usize = 20_000;
/// The seed of the simulated belief traces.
const REGRET_SEED: u64 = 7;

/// Bytes per blob section.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct SectionBytes {
    /// Header (16).
    pub header: usize,
    /// Front-end settings.
    pub front_end: usize,
    /// GMM and CRF.
    pub inference: usize,
    /// Value tables and successor lists.
    pub policy: usize,
    /// Controller settings.
    pub control: usize,
    /// Library frames.
    pub library: usize,
    /// Rig calibration.
    pub rig: usize,
    /// Host-side skeleton (1 byte when left out).
    pub skeleton: usize,
    /// Tones' value tables (1 byte without tones).
    pub styles: usize,
    /// Semantic labels (1 byte without labels).
    pub labels: usize,
}

/// One labelled clip of the pack report.
#[derive(Clone, Debug, Serialize)]
pub struct LabelReport {
    /// Label name.
    pub label: String,
    /// The library file.
    pub clip: String,
    /// The segment carrying it.
    pub segment: usize,
    /// Its stroke frame within the segment.
    pub stroke_frame: usize,
    /// The latest semantic entry frame over all exit points.
    pub max_entry_frame: usize,
}

/// One tone of the pack report.
#[derive(Clone, Debug, Serialize)]
pub struct ToneReport {
    /// Its name.
    pub name: String,
    /// Motion segments its transform was fitted on (0: synthetic).
    pub segments: usize,
    /// Mean factor of T, D, V, A, C, H under the tone against neutral (`exp` of the shift of
    /// the log parameters).
    pub factors: [f64; 6],
    /// Regret of the packed tables read with this tone's weight at 1, against its float
    /// unpruned policy.
    pub regret: f64,
    /// Agreement of those decisions with its float unpruned policy.
    pub agreement: f64,
    /// Bytes its tables add to the blob.
    pub bytes: usize,
}

/// Stage timings (s).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct PackTimings {
    /// Library, rig and tones reading, and the sections the policy does not touch (stages 1
    /// and 2).
    pub load_s: f64,
    /// psi and successor costs.
    pub costs_s: f64,
    /// Value iteration.
    pub value_iteration_s: f64,
    /// Pruning (and fitting the budget, stage 4).
    pub pruning_s: f64,
    /// Quantization and encoding of the policy's sections, and the blob's bytes.
    pub write_s: f64,
    /// Regret simulation.
    pub regret_s: f64,
    /// Everything.
    pub total_s: f64,
}

/// The pack report (`--report`).
#[derive(Clone, Debug, Serialize)]
pub struct PackReport {
    /// Blob size.
    pub blob_bytes: usize,
    /// Bytes per section.
    pub section_bytes: SectionBytes,
    /// Library segments.
    pub segments: usize,
    /// Exit points.
    pub exit_points: usize,
    /// Successor entries before pruning (exit points x segments).
    pub entries_total: usize,
    /// Entries after exact pruning.
    pub entries_nondominated: usize,
    /// Entries in the blob.
    pub entries_kept: usize,
    /// `1 - entries_kept / entries_total`.
    pub pruned_fraction: f64,
    /// Successors per exit point kept by the budget (`null`: all non-dominated).
    pub successors_per_exit: Option<usize>,
    /// Expected cost of the pruned, quantized policy over the float unpruned one.
    pub regret: f64,
    /// Fraction of simulated decisions equal to the float unpruned policy's.
    pub agreement: f64,
    /// The tones, in the blob's order.
    pub styles: Vec<ToneReport>,
    /// The labelled clips.
    pub labels: Vec<LabelReport>,
    /// Decisions simulated for the regret.
    pub regret_decisions: usize,
    /// Rig name.
    pub rig: String,
    /// Rig channels.
    pub channels: usize,
    /// One line per rig channel: what it reads on the library's skeleton, or why it holds
    /// its neutral.
    pub rig_channels: Vec<String>,
    /// Library frames stored.
    pub frames: usize,
    /// How the lower body is played (`null`: as captured, or no legs).
    pub lower_body: Option<String>,
    /// Timings.
    pub timings: PackTimings,
}

/// What the stages made, for [`PackReport::measure`].
pub struct Stages<'a> {
    /// Stage 1.
    pub source: &'a PackLibrary,
    /// Stage 2.
    pub sections: &'a Sections,
    /// Stage 3.
    pub control: &'a ControlModel,
    /// Stage 4.
    pub policy: &'a PolicySections,
}

impl PackReport {
    /// Measures `bytes` (the blob of `stages`) and reports it with `timings` (the regret's
    /// and the total are filled in here, the total from `start`).
    pub fn measure(
        model: &InferenceModel,
        stages: &Stages<'_>,
        bytes: &[u8],
        mut timings: PackTimings,
        start: std::time::Instant,
    ) -> Result<Self, PackError> {
        let t_regret = std::time::Instant::now();
        // The writer checked the bytes; what is measured below is what the device reads.
        let blob = Blob::parse(bytes).map_err(EncodeError::Invalid)?;
        let (lib, cm) = (&stages.source.lib, stages.control);
        let sizes = blob.section_sizes();
        let decisions = REGRET_DECISIONS;
        let r = regret(
            lib,
            &cm.policy,
            &blob,
            &Style::NEUTRAL,
            model,
            decisions,
            REGRET_SEED,
        );
        let tone_reports = cm
            .tones
            .iter()
            .enumerate()
            .map(|(m, t)| {
                let mut w = vec![0.0f32; cm.tones.len()];
                w[m] = 1.0;
                let style = Style::new(&w).map_err(|e| PackError::Style(e.to_string()))?;
                let r = regret(lib, &t.policy, &blob, &style, model, decisions, REGRET_SEED);
                Ok(ToneReport {
                    name: t.transform.name.clone(),
                    segments: t.transform.segments,
                    factors: t.transform.factors(&stages.source.norm),
                    regret: r.regret,
                    agreement: r.agreement,
                    // Two i16 per segment and exit point per state.
                    bytes: 2 * model.states() * (lib.segments.len() + lib.exits.len()),
                })
            })
            .collect::<Result<Vec<_>, PackError>>()?;
        timings.regret_s = t_regret.elapsed().as_secs_f64();
        let rig = &stages.source.rig;
        let mut report = PackReport {
            blob_bytes: bytes.len(),
            section_bytes: SectionBytes {
                header: gesture_runtime::blob::HEADER_LEN,
                front_end: sizes.front_end,
                inference: sizes.inference,
                policy: sizes.policy,
                control: sizes.control,
                library: sizes.library,
                rig: sizes.rig,
                skeleton: sizes.skeleton,
                styles: sizes.styles,
                labels: sizes.labels,
            },
            segments: lib.segments.len(),
            exit_points: lib.exits.len(),
            entries_total: cm.entries_total(),
            entries_nondominated: cm.pruned.iter().map(Vec::len).sum(),
            entries_kept: cm.entries_kept(),
            pruned_fraction: 1.0 - cm.entries_kept() as f64 / cm.entries_total().max(1) as f64,
            successors_per_exit: stages.policy.successors_per_exit,
            regret: r.regret,
            agreement: r.agreement,
            styles: tone_reports,
            labels: cm
                .labelling
                .segments
                .iter()
                .enumerate()
                .map(|(k, &c)| LabelReport {
                    label: cm.labelling.names[(cm.labelling.label_of[c] - 1) as usize].clone(),
                    clip: cm.labelling.sources[k].clone(),
                    segment: c,
                    stroke_frame: cm.labelling.stroke[c].unwrap_or(0),
                    max_entry_frame: cm.entries.iter().map(|r| r[k].0).max().unwrap_or(0),
                })
                .collect(),
            regret_decisions: decisions,
            rig: rig.name.clone(),
            channels: rig.channels.len(),
            rig_channels: stages.sections.rig_lines.clone(),
            frames: stages.sections.frames,
            lower_body: stages.source.lower_body.as_ref().map(|p| {
                format!(
                    "held in a standing pose ({} joints: the legs, {} and above), {}'s rotation \
                     moved into {}",
                    p.held_joints,
                    p.pelvis,
                    p.pelvis,
                    p.upper.join(", ")
                )
            }),
            timings,
        };
        report.timings.total_s = start.elapsed().as_secs_f64();
        Ok(report)
    }
}
