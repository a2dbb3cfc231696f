//! Packing: a trained inference model plus a gesture library (any BVH files) plus a rig into
//! one policy blob (docs/method.md "New library, same model": only the control layer is
//! computed here; the inference layer is reused as trained).
//!
//! [`pack_model`] is a straight pipeline; each stage is owned by one file and takes only what
//! the stages before it made:
//!
//! 1. **library** ([`library`]): the BVH files segmented like the corpus and standardized in
//!    the model's terms, the rig loaded, one skeleton checked, the lower body held
//!    ([`plant`]), labels assigned and the tones' transforms fitted ([`PackLibrary`]);
//! 2. **sections** ([`sections`]): everything the policy does not touch, built once: the
//!    front-end settings and inference layer as trained, the controller's settings, the
//!    frames as rig channel angles, the rig and the skeleton ([`Sections`]);
//! 3. **control model** ([`crate::control::build`]): `psi`, successor costs, value iteration
//!    per tone and per label, exact pruning ([`ControlModel`]);
//! 4. **policy fitted to the budget** ([`policy`]): the policy's, tones' and labels' tables,
//!    the successor lists cut to the largest `k` per exit point whose blob fits
//!    ([`PolicySections`]);
//! 5. **bytes**: the sections encoded by the runtime's writer, which checks them with
//!    `Blob::parse`;
//! 6. **report** ([`report`]): sizes, and the regret of the packed tables read back from the
//!    bytes against the float unpruned policy on simulated belief traces ([`PackReport`]).
//!
//! [`pack_model`] returns the bytes with everything an evaluation needs; [`pack`] also loads
//! the model and writes the blob atomically. Options and defaults: [`options`]; errors:
//! [`error`].
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

pub mod error;
pub mod library;
pub mod options;
pub mod plant;
pub mod policy;
pub mod report;
pub mod sections;

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::control::build::{build, ControlModel};
use crate::control::Library;
use crate::inference::model::InferenceModel;
use crate::output::write_atomic;

pub use error::PackError;
pub use library::{hold_lower_bodies, skeleton_difference, tone_transforms, PackLibrary};
pub use options::{PackOptions, StyleOptions, DEFAULT_BLEND_MS, DEFAULT_FOLLOW, DEFAULT_VARIETY};
pub use policy::PolicySections;
pub use report::{LabelReport, PackReport, PackTimings, SectionBytes, ToneReport};
pub use sections::Sections;

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

/// Packs `model` and the BVH files in `library` in memory, stage by stage (see the module
/// docs).
pub fn pack_model(
    model: &InferenceModel,
    library: &[PathBuf],
    opts: &PackOptions,
) -> Result<Packed, PackError> {
    let start = Instant::now();
    // Drawn only when stderr is a terminal; a big library takes a while to load and solve.
    let progress = crate::progress::spinner("pack: loading the library");
    let source = PackLibrary::load(model, library, opts)?;
    let sections = Sections::new(model, &source, opts)?;
    let load_s = start.elapsed().as_secs_f64();

    progress.set_message("pack: value iteration and pruning");
    let labels = source.labelling.as_ref().map(|l| (l, &opts.label_params));
    let mut control = build(model, &source.lib, &opts.control, &source.tones, labels);

    let t_fit = Instant::now();
    let policy = PolicySections::fit(model, &source.lib, &mut control, &sections, opts)?;
    let fit_s = t_fit.elapsed().as_secs_f64();

    let t_write = Instant::now();
    let bytes = policy.encode(&sections)?;
    let write_s = t_write.elapsed().as_secs_f64();

    progress.set_message("pack: regret of the packed tables");
    let timings = PackTimings {
        load_s,
        costs_s: control.timings.costs,
        value_iteration_s: control.timings.value_iteration,
        pruning_s: control.timings.pruning + fit_s,
        write_s,
        ..PackTimings::default()
    };
    let stages = report::Stages {
        source: &source,
        sections: &sections,
        control: &control,
        policy: &policy,
    };
    let report = PackReport::measure(model, &stages, &bytes, timings, start)?;
    progress.finish_and_clear();
    Ok(Packed {
        bytes,
        report,
        library: source.lib,
        control,
    })
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
