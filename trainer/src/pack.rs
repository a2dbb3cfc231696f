//! Packing: a trained inference model plus a gesture library (any BVH files) plus a rig into
//! one policy blob (DESIGN.md "New library, same model": only the control layer is computed
//! here; the inference layer is reused as trained).
//!
//! Steps: read the library and segment it like the corpus; bind the rig to its skeleton and
//! turn every frame into channel angles; solve the control layer and prune it; if a byte budget
//! is given, keep the best `k` successors per exit point with the largest `k` that fits;
//! quantize; write atomically; measure the regret of the pruned, quantized policy against the
//! float unpruned one on simulated belief traces.
//!
//! **One skeleton per library.** Every take of the library must have the same joint hierarchy
//! (names, parents, channels; offsets may differ, the first take's are kept), so the blob's
//! host-side `skeleton` section (docs/blob-format.md 3.6) can describe the motion the frames came
//! from: the first take's skeleton, its first frame as the rest pose, and what each rig channel
//! drives. A library that mixes skeletons is refused with the first difference; pack each
//! skeleton family into its own blob. `--no-skeleton` leaves the section out (the device never
//! reads it; it costs a few KiB for a 75-joint body).

use std::path::{Path, PathBuf};
use std::time::Instant;

use gesture_runtime::blob::{Blob, FrontEndSection};
use gesture_runtime::prosody::ProsodyConfig;
use serde::Serialize;

use crate::blob::{
    drives_of, encode, write_atomic, OwnedInference, OwnedLibrary, OwnedPayload, OwnedPolicy,
    OwnedRig, OwnedSkeleton, PolicyInput, SegmentSpec,
};
use crate::control::build::{
    build, fit_budget, regret, ControlModel, ControlParams, QuantizedPolicy,
};
use crate::control::Library;
use crate::corpus::discover;
use crate::inference::model::InferenceModel;
use crate::inference::quantize::QuantizedInference;
use crate::motion::{EffectorSpec, SegmentParams, Skeleton};
use crate::rig::Rig;

/// Settings of a pack.
#[derive(Clone, Debug, Default)]
pub struct PackOptions {
    /// Rig file (default: every rotation channel of the library's skeleton).
    pub rig: Option<PathBuf>,
    /// Largest blob in bytes.
    pub budget_bytes: Option<usize>,
    /// Control-layer settings.
    pub control: ControlParams,
    /// End effectors for segmenting the library.
    pub effectors: EffectorSpec,
    /// Leave out the host-side skeleton section.
    pub no_skeleton: bool,
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
    /// Library frames.
    pub library: usize,
    /// Rig calibration.
    pub rig: usize,
    /// Host-side skeleton (1 byte when left out).
    pub skeleton: usize,
}

/// Stage timings (s).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct PackTimings {
    /// Model, library and rig reading and binding.
    pub load_s: f64,
    /// psi and successor costs.
    pub costs_s: f64,
    /// Value iteration.
    pub value_iteration_s: f64,
    /// Pruning (and budget truncation).
    pub pruning_s: f64,
    /// Quantization, encoding and writing.
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
    /// Decisions simulated for the regret.
    pub regret_decisions: usize,
    /// Rig name and channels.
    pub rig: String,
    /// Rig channels.
    pub channels: usize,
    /// Library frames stored.
    pub frames: usize,
    /// Timings.
    pub timings: PackTimings,
}

/// Why packing failed.
pub type PackError = Box<dyn std::error::Error + Send + Sync>;

struct Parts {
    inference: OwnedInference,
    library: OwnedLibrary,
    rig: OwnedRig,
    front_end: FrontEndSection,
    skeleton: Option<OwnedSkeleton>,
}

fn policy_section(
    model: &InferenceModel,
    lib: &Library,
    cm: &ControlModel,
) -> Result<(OwnedPolicy, QuantizedPolicy), PackError> {
    let q = QuantizedPolicy::new(lib, cm);
    let exits: Vec<(usize, usize)> = q.exits.iter().map(|&(s, f, _)| (s, f)).collect();
    let owned = OwnedPolicy::new(&PolicyInput {
        states: model.states(),
        segments: lib.segments.len(),
        discount: cm.policy.discount,
        u: &q.u,
        u_cont: &q.u_cont,
        exits: &exits,
        successors: &q.succ,
        succ_cost_scale: q.succ_scale,
    })?;
    Ok((owned, q))
}

fn encode_with(parts: &Parts, policy: &OwnedPolicy) -> Result<Vec<u8>, PackError> {
    let payload = OwnedPayload {
        front_end: parts.front_end,
        inference: parts.inference.clone(),
        policy: policy.clone(),
        library: parts.library.clone(),
        rig: parts.rig.clone(),
        skeleton: parts.skeleton.clone(),
    };
    Ok(encode(&payload.payload())?)
}

/// Packs `model` and the BVH files in `library` into `out`; returns the report.
pub fn pack(
    model_path: &Path,
    library: &[PathBuf],
    opts: &PackOptions,
    out: &Path,
) -> Result<PackReport, PackError> {
    let start = Instant::now();
    let model = InferenceModel::load(model_path)?;
    let files: Vec<PathBuf> = discover(library)?
        .into_iter()
        .filter_map(|t| t.bvh)
        .collect();
    if files.is_empty() {
        return Err("the library has no .bvh files".into());
    }
    let lib = Library::from_files(
        &files,
        &model.normalization,
        &opts.effectors,
        &SegmentParams::default(),
        3,
    )?;
    let rig = match &opts.rig {
        Some(p) => Rig::load(p)?,
        None => Rig::full_skeleton(lib.takes[0].motion.skeleton())?,
    };
    let first = &lib.takes[0];
    for t in &lib.takes[1..] {
        if let Some(diff) = skeleton_difference(first.motion.skeleton(), t.motion.skeleton()) {
            return Err(format!(
                "the library mixes skeletons: {} and {} differ ({diff}); pack one skeleton per \
                 library",
                first.source.display(),
                t.source.display()
            )
            .into());
        }
    }
    // Channel angles of every frame, take after take.
    let mut frames: Vec<Vec<f32>> = Vec::new();
    let mut offsets = Vec::with_capacity(lib.takes.len());
    for t in &lib.takes {
        let bound = rig.bind(t.motion.skeleton(), &t.source.display().to_string())?;
        offsets.push(frames.len());
        let values = bound
            .take_values(&t.motion)
            .ok_or_else(|| format!("{}: the rig does not fit this skeleton", t.source.display()))?;
        frames.extend(values);
    }
    let segments: Vec<SegmentSpec> = lib
        .segments
        .iter()
        .map(|s| SegmentSpec {
            start: offsets[s.take] + s.start,
            len: s.len(),
            stroke: None,
            label: 0,
        })
        .collect();
    let cals: Vec<(String, gesture_runtime::rig::ChannelCal)> = rig
        .channels
        .iter()
        .map(|c| (c.name.clone(), c.cal))
        .collect();
    let config = ProsodyConfig {
        sample_rate_hz: model.sample_rate_hz,
        ..ProsodyConfig::DEFAULT
    };
    let skeleton = if opts.no_skeleton {
        None
    } else {
        let sk = first.motion.skeleton();
        let bound = rig.bind(sk, &first.source.display().to_string())?;
        let rest: Vec<f64> = first.motion.frame(0).unwrap_or(&[]).to_vec();
        Some(OwnedSkeleton::new(sk, &rest, &drives_of(&bound)?)?)
    };
    let parts = Parts {
        inference: OwnedInference::new(&QuantizedInference::new(&model.gmm, &model.crf))?,
        library: OwnedLibrary::new(lib.fps, rig.channels.len(), &frames, &segments)?,
        rig: OwnedRig::new(&rig.name, rig.period_us, &cals)?,
        front_end: FrontEndSection::from_config(&config),
        skeleton,
    };
    let load_s = start.elapsed().as_secs_f64();

    let mut cm = build(&model, &lib, &opts.control);
    let t_prune = Instant::now();
    let mut k = None;
    if let Some(budget) = opts.budget_bytes {
        let size = |c: &ControlModel| {
            policy_section(&model, &lib, c)
                .and_then(|(p, _)| encode_with(&parts, &p))
                .map_or(usize::MAX, |b| b.len())
        };
        k = fit_budget(&model, &mut cm, budget, &size);
        if k.is_none() {
            return Err(format!(
                "the blob does not fit {budget} bytes even with one successor per exit point \
                 ({} bytes): use a smaller library, fewer rig channels, or a larger budget",
                size(&cm)
            )
            .into());
        }
        if k == cm.pruned.iter().map(Vec::len).max() {
            k = None;
        }
    }
    let pruning_extra = t_prune.elapsed().as_secs_f64();
    let t_write = Instant::now();
    let (policy, q) = policy_section(&model, &lib, &cm)?;
    let bytes = encode_with(&parts, &policy)?;
    write_atomic(out, &bytes)?;
    let blob = Blob::parse(&bytes).map_err(|e| format!("{}: {e}", out.display()))?;
    let sizes = blob.section_sizes();
    let write_s = t_write.elapsed().as_secs_f64();
    let t_regret = Instant::now();
    let decisions = 20_000;
    let r = regret(&lib, &cm, &q, &model, decisions, 7);
    let regret_s = t_regret.elapsed().as_secs_f64();
    Ok(PackReport {
        blob_bytes: bytes.len(),
        section_bytes: SectionBytes {
            header: gesture_runtime::blob::HEADER_LEN,
            front_end: sizes.front_end,
            inference: sizes.inference,
            policy: sizes.policy,
            library: sizes.library,
            rig: sizes.rig,
            skeleton: sizes.skeleton,
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
        regret_decisions: decisions,
        rig: rig.name.clone(),
        channels: rig.channels.len(),
        frames: frames.len(),
        timings: PackTimings {
            load_s,
            costs_s: cm.timings.costs,
            value_iteration_s: cm.timings.value_iteration,
            pruning_s: cm.timings.pruning + pruning_extra,
            write_s,
            regret_s,
            total_s: start.elapsed().as_secs_f64(),
        },
    })
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
