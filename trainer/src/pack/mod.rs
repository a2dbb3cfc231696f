//! Packing: a trained inference model plus a gesture library (any BVH files) plus a rig into
//! one policy blob (docs/method.md "New library, same model": only the control layer is
//! computed here; the inference layer is reused as trained).
//!
//! Steps: read the library and segment it like the corpus; bind the rig to its skeleton and
//! turn every frame into channel angles ([`assemble`]); solve the control layer and prune it;
//! if a byte budget is given, keep the best `k` successors per exit point with the largest `k`
//! that fits; quantize and encode with the runtime's writer; measure the regret of the
//! pruned, quantized policy *read back from the bytes* against the float unpruned one on
//! simulated belief traces. [`pack_model`] does all of this in memory and returns the bytes
//! with everything an evaluation needs; [`pack`] also loads the model and writes the blob
//! atomically.
//!
//! **One skeleton per library.** Every take of the library must have the same joint hierarchy
//! (names, parents, channels; offsets may differ, the first take's are kept), so the blob's
//! host-side `skeleton` section (docs/blob-format.md 3.7) can describe the motion the frames
//! came from: the first take's skeleton, its first frame as the rest pose, and what each rig
//! channel drives. A library that mixes skeletons is refused with the first difference; pack
//! each skeleton family into its own blob. `no_skeleton` leaves the section out (the device
//! never reads it; it costs a few KiB for a 75-joint body).
//!
//! **Tones** ([`StyleOptions`], docs/method.md "Style control"): with neutral motion and motion
//! per tone (any BVH, any skeleton: the transform is relative), each tone's transform is
//! fitted ([`crate::control::style`]), the library's segments are scored through it, one value
//! function is solved per tone, and the blob gets a `styles` section with their tables; the
//! successor lists are shared. `energy` adds the two synthetic tones of the energy knob.

pub mod assemble;
pub mod plant;

use std::path::{Path, PathBuf};
use std::time::Instant;

use gesture_runtime::blob::encode::EncodeError;
use gesture_runtime::blob::Blob;
use gesture_runtime::controller::DecisionTiming;
use gesture_runtime::follow::VoiceFollow;
use gesture_runtime::policy::{Style, Variety};
use serde::Serialize;

use crate::control::build::{build, fit_budget, regret, ControlModel, ControlParams};
use crate::control::library::LibraryError;
use crate::control::semantic::{LabelParams, LabelSpec, Labelling};
use crate::control::style::{ToneError, ToneTransform, ENERGY_TONES};
use crate::control::Library;
use crate::corpus::discover;
use crate::inference::model::{InferenceModel, ModelError};
use crate::motion::fk::Target;
use crate::motion::{
    analyze, read_bvh, EffectorSpec, Motion, Normalization, SegmentParams, Skeleton,
};
use crate::output::{write_atomic, OutputError};
use crate::rig::{Rig, RigError};
use assemble::{encode_with, labels_section, parts, policy_section, styles_section};

/// Variety costs a blob gets by default (see `gesture_runtime::policy`): chosen with
/// `gesture-train eval-motion` on tuning speech (067's 50 s twice and the six CMU Arctic
/// sentences, 119 s) with the default models and libraries of both ZeroEGGS takes, never on
/// the speech the README reports (docs/method.md, "Variety"). A usage window of a minute
/// (bounded by the 32 remembered entries) spreads the motion over the library in the
/// proportions the capture has; a shorter one let a few segments come back every half minute.
pub const DEFAULT_VARIETY: Variety = Variety {
    recency_cost: 1.0,
    recency_ms: 8000,
    usage_cost: 12.0,
    usage_ms: 45000,
};

/// How a blob follows the voice by default (see `gesture_runtime::follow`): chosen with
/// `gesture-train eval-motion` on tuning speech (the 9-joint ZeroEGGS model and library on
/// its held-out 90-121 s, the 067 model and library on the first 60 s of the 9-joint take's
/// speech; 10 device runs each), never on the speech the README reports. The energy cost
/// brought the pause/speech hand-speed ratio from 0.17-0.28 (at 1) to 0.05-0.10 and the
/// speech coupling from 0.30/0.58 to 0.52/0.65 (the captures: 0.55/0.62); 3 and 4 gave no
/// more. Resting after two pause steps (500 ms) leaves the short breaths of a sentence alone.
pub const DEFAULT_FOLLOW: VoiceFollow = VoiceFollow {
    rest_ms: 500,
    rest_cost: 4.0,
    energy_cost: 2.0,
};

/// Inertialization time at cuts a blob gets by default (ms).
pub const DEFAULT_BLEND_MS: u32 = 400;

/// Settings of a pack.
#[derive(Clone, Debug)]
pub struct PackOptions {
    /// Rig file (default: every rotation channel of the library's skeleton).
    pub rig: Option<PathBuf>,
    /// Largest blob in bytes.
    pub budget_bytes: Option<usize>,
    /// Control-layer settings.
    pub control: ControlParams,
    /// When the device decides (the blob's `control` section).
    pub timing: DecisionTiming,
    /// How the device varies its choices (the blob's `control` section).
    pub variety: Variety,
    /// How the device follows the voice (the blob's `control` section).
    pub follow: VoiceFollow,
    /// Inertialization time at cuts (ms; the blob's `control` section).
    pub blend_ms: u32,
    /// Hold the lower body of a skeleton with legs in a standing pose (see `plant`).
    pub plant_feet: bool,
    /// End effectors for segmenting the library.
    pub effectors: EffectorSpec,
    /// Leave out the host-side skeleton section.
    pub no_skeleton: bool,
    /// Tones (none by default).
    pub styles: StyleOptions,
    /// Semantic labels by library file name (none by default).
    pub labels: Vec<LabelSpec>,
    /// How labels are served.
    pub label_params: LabelParams,
}

/// Tones to pack (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct StyleOptions {
    /// BVH files of neutral motion (needed with `tones`).
    pub neutral: Vec<PathBuf>,
    /// Per tone: its name and the BVH files that show it.
    pub tones: Vec<(String, Vec<PathBuf>)>,
    /// Add the energy knob's tones (`energetic`, `calm`) with this factor (> 1).
    pub energy: Option<f64>,
}

impl Default for PackOptions {
    fn default() -> Self {
        Self {
            rig: None,
            budget_bytes: None,
            control: ControlParams::default(),
            timing: DecisionTiming::default(),
            variety: DEFAULT_VARIETY,
            follow: DEFAULT_FOLLOW,
            blend_ms: DEFAULT_BLEND_MS,
            plant_feet: true,
            effectors: EffectorSpec::default(),
            no_skeleton: false,
            styles: StyleOptions::default(),
            labels: Vec::new(),
            label_params: LabelParams::default(),
        }
    }
}

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
    /// Library and rig reading and binding.
    pub load_s: f64,
    /// psi and successor costs.
    pub costs_s: f64,
    /// Value iteration.
    pub value_iteration_s: f64,
    /// Pruning (and budget truncation).
    pub pruning_s: f64,
    /// Quantization and encoding.
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
    /// Library frames stored.
    pub frames: usize,
    /// How the lower body is played (`null`: as captured, or no legs).
    pub lower_body: Option<String>,
    /// Timings.
    pub timings: PackTimings,
}

/// Why packing failed.
#[derive(Debug, thiserror::Error)]
pub enum PackError {
    /// The model file.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// Finding the library's files.
    #[error(transparent)]
    Discover(#[from] crate::corpus::DiscoverError),
    /// No BVH among the library's paths.
    #[error("the library has no .bvh files")]
    NoBvh,
    /// Reading or segmenting the library.
    #[error(transparent)]
    Library(#[from] LibraryError),
    /// The rig file or its binding (boxed: the largest error).
    #[error(transparent)]
    Rig(Box<RigError>),
    /// Takes with different skeletons.
    #[error(
        "the library mixes skeletons: {first} and {other} differ ({diff}); pack one skeleton \
         per library"
    )]
    MixedSkeletons {
        /// The first take.
        first: String,
        /// The differing take.
        other: String,
        /// The first difference.
        diff: String,
    },
    /// The budget cannot be met.
    #[error(
        "the blob does not fit {budget} bytes even with one successor per exit point \
         ({size} bytes): use a smaller library, fewer rig channels, or a larger budget"
    )]
    Budget {
        /// The budget.
        budget: usize,
        /// The smallest size reached.
        size: usize,
    },
    /// The model's front-end settings are not ones this runtime accepts.
    #[error("{0}")]
    FrontEnd(String),
    /// A tone's motion or options.
    #[error("{0}")]
    Style(String),
    /// A tone's transform could not be fitted.
    #[error(transparent)]
    Tone(#[from] ToneError),
    /// The labels do not fit the library.
    #[error("{0}")]
    Label(String),
    /// The writer refused the content (a packer bug or a dimension beyond the format).
    #[error(transparent)]
    Encode(#[from] EncodeError),
    /// Writing the blob.
    #[error(transparent)]
    Output(#[from] OutputError),
}

impl From<RigError> for PackError {
    fn from(e: RigError) -> Self {
        Self::Rig(Box::new(e))
    }
}

impl PackError {
    /// Whether the user's input is at fault (a file, an option), not the machine or the code.
    pub fn is_input(&self) -> bool {
        !matches!(
            self,
            Self::Output(_) | Self::Encode(EncodeError::Invalid(_) | EncodeError::Encode)
        )
    }
}

/// A blob packed in memory, with what an evaluation needs besides the bytes.
#[derive(Clone, Debug)]
pub struct Packed {
    /// The blob (the runtime's writer checked it with `Blob::parse`).
    pub bytes: Vec<u8>,
    /// The report.
    pub report: PackReport,
    /// The library as segmented.
    pub library: Library,
    /// The solved control layer (float, unpruned policy and the kept successors).
    pub control: ControlModel,
}

/// Packs `model` and the BVH files in `library` in memory (see the module docs).
pub fn pack_model(
    model: &InferenceModel,
    library: &[PathBuf],
    opts: &PackOptions,
) -> Result<Packed, PackError> {
    let start = Instant::now();
    // Drawn only when stderr is a terminal; a big library takes a while to load and solve.
    let progress = crate::progress::spinner("pack: loading the library");
    let files: Vec<PathBuf> = discover(library)?
        .into_iter()
        .filter_map(|t| t.bvh)
        .collect();
    if files.is_empty() {
        return Err(PackError::NoBvh);
    }
    // Segmented with no normalization first: the library's own level is part of its
    // normalization (`InferenceModel::library_normalization`).
    let mut lib = Library::from_files(
        &files,
        &Normalization::identity(),
        &opts.effectors,
        &SegmentParams::default(),
        3,
    )?;
    let raw: Vec<[f64; 6]> = lib.segments.iter().map(|s| s.y).collect();
    let norm = model.library_normalization(&raw);
    for s in &mut lib.segments {
        s.y = norm.apply(&s.y);
    }
    let rig = match &opts.rig {
        Some(p) => Rig::load(p)?,
        None => Rig::full_skeleton(lib.takes[0].motion.skeleton())?,
    };
    let first = &lib.takes[0];
    for t in &lib.takes[1..] {
        if let Some(diff) = skeleton_difference(first.motion.skeleton(), t.motion.skeleton()) {
            return Err(PackError::MixedSkeletons {
                first: first.source.display().to_string(),
                other: t.source.display().to_string(),
                diff,
            });
        }
    }
    let lower_body = if opts.plant_feet {
        hold_lower_body(&mut lib, &opts.effectors)
    } else {
        None
    };
    let labelling = if opts.labels.is_empty() {
        None
    } else {
        Some(Labelling::assign(&lib, &opts.labels).map_err(PackError::Label)?)
    };
    let (parts, frames) = parts(model, &lib, &rig, opts, labelling.as_ref())?;
    progress.set_message("pack: fitting the tones");
    let tones = tone_transforms(&norm, &opts.styles, &opts.effectors)?;
    let load_s = start.elapsed().as_secs_f64();

    progress.set_message("pack: value iteration and pruning");
    let mut cm = build(
        model,
        &lib,
        &opts.control,
        &tones,
        labelling.as_ref().map(|l| (l, &opts.label_params)),
    );
    let t_prune = Instant::now();
    let mut k = None;
    if let Some(budget) = opts.budget_bytes {
        let styles = styles_section(&cm)?;
        let labels = labels_section(&cm, &opts.label_params)?;
        let size = |c: &ControlModel| {
            policy_section(model, &lib, c)
                .and_then(|p| encode_with(&parts, &p, styles.as_ref(), labels.as_ref()))
                .map_or(usize::MAX, |b| b.len())
        };
        k = fit_budget(model, &mut cm, budget, &size);
        if k.is_none() {
            return Err(PackError::Budget {
                budget,
                size: size(&cm),
            });
        }
        if k == cm.pruned.iter().map(Vec::len).max() {
            k = None;
        }
    }
    if k.is_none() {
        let most = cm.pruned.iter().map(Vec::len).max().unwrap_or(0);
        k = opts.control.max_successors.filter(|&m| m < most);
    }
    let pruning_extra = t_prune.elapsed().as_secs_f64();
    let t_write = Instant::now();
    let policy = policy_section(model, &lib, &cm)?;
    let styles = styles_section(&cm)?;
    let labels = labels_section(&cm, &opts.label_params)?;
    let bytes = encode_with(&parts, &policy, styles.as_ref(), labels.as_ref())?;
    // The writer checked the bytes; what is measured below is what the device reads.
    let blob = Blob::parse(&bytes).map_err(EncodeError::Invalid)?;
    let sizes = blob.section_sizes();
    let write_s = t_write.elapsed().as_secs_f64();
    let t_regret = Instant::now();
    progress.set_message("pack: regret of the packed tables");
    let decisions = 20_000;
    let r = regret(
        &lib,
        &cm.policy,
        &blob,
        &Style::NEUTRAL,
        model,
        decisions,
        7,
    );
    let tone_reports = cm
        .tones
        .iter()
        .enumerate()
        .map(|(m, t)| {
            let mut w = vec![0.0f32; cm.tones.len()];
            w[m] = 1.0;
            let style = Style::new(&w).map_err(|e| PackError::Style(e.to_string()))?;
            let r = regret(&lib, &t.policy, &blob, &style, model, decisions, 7);
            Ok(ToneReport {
                name: t.transform.name.clone(),
                segments: t.transform.segments,
                factors: t.transform.factors(&norm),
                regret: r.regret,
                agreement: r.agreement,
                // Two i16 per segment and exit point per state.
                bytes: 2 * model.states() * (lib.segments.len() + lib.exits.len()),
            })
        })
        .collect::<Result<Vec<_>, PackError>>()?;
    let regret_s = t_regret.elapsed().as_secs_f64();
    progress.finish_and_clear();
    let report = PackReport {
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
        successors_per_exit: k,
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
        frames,
        lower_body: lower_body.map(|p| {
            format!(
                "held in a standing pose ({} joints: the legs, {} and above), {}'s rotation \
                 moved into {}",
                p.held_joints,
                p.pelvis,
                p.pelvis,
                p.upper.join(", ")
            )
        }),
        timings: PackTimings {
            load_s,
            costs_s: cm.timings.costs,
            value_iteration_s: cm.timings.value_iteration,
            pruning_s: cm.timings.pruning + pruning_extra,
            write_s,
            regret_s,
            total_s: start.elapsed().as_secs_f64(),
        },
    };
    Ok(Packed {
        bytes,
        report,
        library: lib,
        control: cm,
    })
}

/// Kinematic vectors of every segment of the BVH files `files`, normalized by `norm`.
fn segment_vectors(
    norm: &Normalization,
    files: &[PathBuf],
    effectors: &EffectorSpec,
) -> Result<Vec<[f64; 6]>, PackError> {
    let mut ys = Vec::new();
    for f in files {
        let motion = read_bvh(f).map_err(LibraryError::from)?;
        let analysis = analyze(&motion, effectors, &SegmentParams::default())
            .map_err(|e| LibraryError::Analysis(format!("{}: {e}", f.display())))?;
        ys.extend(analysis.y_raw.iter().map(|y| norm.apply(y)));
    }
    Ok(ys)
}

/// The tones' transforms, in the library's normalization `norm`: fitted from motion, then the
/// energy knob's (see [`StyleOptions`]).
pub fn tone_transforms(
    norm: &Normalization,
    st: &StyleOptions,
    effectors: &EffectorSpec,
) -> Result<Vec<ToneTransform>, PackError> {
    let mut out = Vec::new();
    if !st.tones.is_empty() {
        if st.neutral.is_empty() {
            return Err(PackError::Style(
                "--style needs neutral motion to compare with: give --style-neutral FILES".into(),
            ));
        }
        let neutral = segment_vectors(norm, &st.neutral, effectors)?;
        for (name, files) in &st.tones {
            let ys = segment_vectors(norm, files, effectors)?;
            out.push(ToneTransform::fit(name, &neutral, &ys)?);
        }
    }
    if let Some(f) = st.energy {
        if !(f.is_finite() && f > 1.0) {
            return Err(PackError::Style(format!(
                "--energy {f}: the factor must be a number above 1 (e.g. 1.5)"
            )));
        }
        if let Some(n) = ENERGY_TONES
            .iter()
            .find(|n| st.tones.iter().any(|(t, _)| t == *n))
        {
            return Err(PackError::Style(format!(
                "--style {n}: the name is taken by the --energy knob's tones"
            )));
        }
        out.extend(ToneTransform::energy(f, norm));
    }
    if out.len() > gesture_runtime::policy::MAX_TONES {
        return Err(PackError::Style(format!(
            "{} tones, a blob holds at most {} (the energy knob counts two)",
            out.len(),
            gesture_runtime::policy::MAX_TONES
        )));
    }
    Ok(out)
}

/// Holds the lower body of the library's takes (see [`plant`]); `None` without feet.
fn hold_lower_body(lib: &mut Library, effectors: &EffectorSpec) -> Option<plant::Planted> {
    let mut motions: Vec<Motion> = lib.takes.iter().map(|t| t.motion.clone()).collect();
    let planted = hold_lower_bodies(&mut motions, effectors)?;
    for (t, m) in lib.takes.iter_mut().zip(motions) {
        t.motion = m;
    }
    Some(planted)
}

/// Holds the lower body of `motions` (one skeleton) as `pack` holds a library's (see
/// [`plant`]); `None`, and the motions untouched, without feet or hands.
pub fn hold_lower_bodies(
    motions: &mut [Motion],
    effectors: &EffectorSpec,
) -> Option<plant::Planted> {
    let first = motions.first()?;
    let hands: Vec<usize> = effectors
        .resolve(first.skeleton(), first.source())
        .ok()?
        .targets
        .iter()
        .map(|t| match *t {
            Target::Joint(j) | Target::EndSite(j) => j,
        })
        .collect();
    plant::plant_feet(motions, &hands)
}

/// Loads the model at `model_path`, packs it with the BVH files in `library` and writes the
/// blob to `out` atomically; returns the report.
pub fn pack(
    model_path: &Path,
    library: &[PathBuf],
    opts: &PackOptions,
    out: &Path,
) -> Result<PackReport, PackError> {
    let start = Instant::now();
    let model = InferenceModel::load(model_path)?;
    let mut packed = pack_model(&model, library, opts)?;
    let t_write = Instant::now();
    write_atomic(out, &packed.bytes)?;
    let r = &mut packed.report;
    r.timings.write_s += t_write.elapsed().as_secs_f64();
    r.timings.total_s = start.elapsed().as_secs_f64();
    Ok(packed.report)
}

/// The first structural difference between two skeletons (joint count, names, parents,
/// channels), or `None` if they have the same hierarchy. Offsets are not compared.
pub fn skeleton_difference(a: &Skeleton, b: &Skeleton) -> Option<String> {
    if a.joints.len() != b.joints.len() {
        return Some(format!(
            "{} joints against {}",
            a.joints.len(),
            b.joints.len()
        ));
    }
    a.joints
        .iter()
        .zip(&b.joints)
        .enumerate()
        .find_map(|(k, (x, y))| {
            if x.name != y.name {
                Some(format!("joint {k} is `{}` against `{}`", x.name, y.name))
            } else if x.parent != y.parent {
                Some(format!("joint `{}` has another parent", x.name))
            } else if x.channels != y.channels {
                Some(format!("joint `{}` has other channels", x.name))
            } else {
                None
            }
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mixed_skeletons_are_told_apart() {
        let a = crate::synth::skeleton();
        assert_eq!(skeleton_difference(&a, &a.clone()), None);
        let mut b = a.clone();
        b.joints[0].offset[1] += 1.0;
        assert_eq!(skeleton_difference(&a, &b), None, "offsets may differ");
        b.joints[2].name = "Other".into();
        let d = skeleton_difference(&a, &b).unwrap();
        assert!(d.contains("joint 2") && d.contains("`Other`"), "{d}");
        let mut c = a.clone();
        c.joints.pop();
        assert!(skeleton_difference(&a, &c)
            .unwrap()
            .contains("joints against"));
    }
}
