//! Stage 1 of packing: the library in the model's terms. Its BVH files are found, segmented
//! like the corpus and standardized by the library's own level
//! ([`InferenceModel::library_normalization`]); the rig is loaded (or the full-skeleton rig
//! made); every take must share the first take's skeleton; the lower body is held in a
//! standing pose ([`super::plant`]); labels are assigned to their clips; and the tones'
//! transforms are fitted in the library's normalization. Reads files, allocates; returns the
//! first problem as a [`PackError`].

use std::path::PathBuf;

use crate::control::library::LibraryError;
use crate::control::semantic::Labelling;
use crate::control::style::{ToneTransform, ENERGY_TONES};
use crate::control::Library;
use crate::corpus::discover;
use crate::inference::model::InferenceModel;
use crate::motion::fk::Target;
use crate::motion::{
    analyze, read_bvh, EffectorSpec, Motion, Normalization, SegmentParams, Skeleton,
};
use crate::rig::Rig;

use super::error::PackError;
use super::options::{PackOptions, StyleOptions};
use super::plant::{self, Planted};

/// The library as the later stages take it.
#[derive(Clone, Debug)]
pub struct PackLibrary {
    /// Segmented, standardized, lower body held.
    pub lib: Library,
    /// The library's normalization of the kinematic parameters.
    pub norm: Normalization,
    /// The output rig.
    pub rig: Rig,
    /// How the lower body is held (`None`: as captured, or no legs).
    pub lower_body: Option<Planted>,
    /// The labelled clips (`None` without labels).
    pub labelling: Option<Labelling>,
    /// The tones' transforms, in the blob's order.
    pub tones: Vec<ToneTransform>,
}

impl PackLibrary {
    /// Reads the BVH files among `paths` and prepares them as the module docs say.
    pub fn load(
        model: &InferenceModel,
        paths: &[PathBuf],
        opts: &PackOptions,
    ) -> Result<Self, PackError> {
        let files: Vec<PathBuf> = discover(paths)?.into_iter().filter_map(|t| t.bvh).collect();
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
        let tones = tone_transforms(&norm, &opts.styles, &opts.effectors)?;
        Ok(Self {
            lib,
            norm,
            rig,
            lower_body,
            labelling,
            tones,
        })
    }
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
fn hold_lower_body(lib: &mut Library, effectors: &EffectorSpec) -> Option<Planted> {
    let mut motions: Vec<Motion> = lib.takes.iter().map(|t| t.motion.clone()).collect();
    let planted = hold_lower_bodies(&mut motions, effectors)?;
    for (t, m) in lib.takes.iter_mut().zip(motions) {
        t.motion = m;
    }
    Some(planted)
}

/// Holds the lower body of `motions` (one skeleton) as `pack` holds a library's (see
/// [`plant`]); `None`, and the motions untouched, without feet or hands.
pub fn hold_lower_bodies(motions: &mut [Motion], effectors: &EffectorSpec) -> Option<Planted> {
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
