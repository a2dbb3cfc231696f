//! Motion capture in, gesture segments and their kinematic parameters out.
//!
//! | module | owns |
//! |---|---|
//! | [`skeleton`] | the motion types: [`Skeleton`], [`Joint`], [`Channel`], [`Motion`] |
//! | [`bvh_read`] | the BVH reader, [`BvhError`] (file:line messages) |
//! | [`bvh_write`] | the BVH writer |
//! | [`fk`] | forward kinematics (per-joint rotation order), [`Positions`], the [`FkPlan`] fast path |
//! | [`humanoid`] | humanoid bones (Unity's `HumanBodyBones` names) found by common joint naming |
//! | [`effectors`] | which points to follow: the two hands by name, or any named joints |
//! | [`segment`] | mean effector speed, threshold cuts with hysteresis and a minimum length |
//! | [`kinematic`] | y = (T, D, V, A, C, H) per segment, log scale, corpus [`Normalization`] |
//! | [`body`] | the body units [`analyze`] measures y in: limb lengths, height above the shoulder, derivatives over 1/30 s |
//!
//! [`analyze`] chains them for one take; it is what the corpus loader calls.
//!
//! ## Contract
//!
//! Nothing in this tree panics on any input file: a BVH file that cannot be used gives a
//! [`BvhError`] naming the file and line; a motion is valid once built ([`Motion`] checks its
//! invariants at its only two gates, [`parse_bvh`] and [`Motion::new`]), and everything after
//! that gate returns results or typed errors (bad parameters, missing joints). Everything is
//! `f64` and single-threaded; allocation is proportional to the take's size.

pub mod body;
pub mod bvh_read;
pub mod bvh_write;
pub mod effectors;
pub mod fk;
pub mod humanoid;
pub mod kinematic;
pub mod segment;
pub mod skeleton;

pub use bvh_read::{parse_bvh, read_bvh, BvhError, BvhErrorKind};
pub use bvh_write::{write_bvh, write_bvh_file};
pub use effectors::{EffectorError, EffectorSpec, Effectors};
pub use fk::{FkError, FkPlan, Positions, Target};
pub use kinematic::{
    HeightReference, KinematicParamError, KinematicParams, Kinematics, Normalization,
    NormalizationError,
};
pub use segment::{Phase, Segment, SegmentParams, Threshold};
pub use skeleton::{Channel, Joint, Motion, MotionError, Skeleton};

/// Everything [`analyze`] learns about one take.
#[derive(Clone, Debug, PartialEq)]
pub struct TakeAnalysis {
    /// The take's source name (file path).
    pub source: String,
    /// Seconds per frame.
    pub frame_time: f64,
    /// The effectors followed.
    pub effectors: Effectors,
    /// Effector world positions, frames x effectors.
    pub positions: Positions,
    /// Smoothed mean effector speed per frame (units/s), the segmentation signal.
    pub speed: Vec<f64>,
    /// Centre speed threshold used (units/s).
    pub threshold: f64,
    /// Height H is measured from (along the up axis).
    pub floor: f64,
    /// The segments, tiling the take.
    pub segments: Vec<Segment>,
    /// The body's limb length (skeleton units), the unit of the kinematics ([`body`]).
    pub limb_length: f64,
    /// Kinematic parameters per segment, in body units ([`body`]).
    pub kinematics: Vec<Kinematics>,
    /// `ln(value + eps)` per segment: the un-normalized y vectors.
    pub y_raw: Vec<[f64; 6]>,
}

/// Why a take could not be analyzed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AnalysisError {
    /// The effectors are not in the skeleton.
    #[error(transparent)]
    Effectors(#[from] EffectorError),
    /// Forward kinematics refused the targets.
    #[error(transparent)]
    Fk(#[from] FkError),
    /// A segmentation parameter is out of range.
    #[error(transparent)]
    Segment(#[from] segment::ParamError),
    /// A kinematic parameter is out of range.
    #[error(transparent)]
    Kinematic(#[from] KinematicParamError),
    /// An effector has no limb to measure by.
    #[error(transparent)]
    Body(#[from] body::BodyError),
}

/// Segments one take and computes its kinematic parameters in body units ([`body`]), with
/// default [`KinematicParams`] (Y up).
pub fn analyze(
    motion: &Motion,
    effectors: &EffectorSpec,
    params: &SegmentParams,
) -> Result<TakeAnalysis, AnalysisError> {
    analyze_with(motion, effectors, params, &KinematicParams::default())
}

/// [`analyze`] with explicit kinematic settings.
pub fn analyze_with(
    motion: &Motion,
    effectors: &EffectorSpec,
    params: &SegmentParams,
    kin: &KinematicParams,
) -> Result<TakeAnalysis, AnalysisError> {
    params.validate()?;
    kin.validate()?;
    let effectors = effectors.resolve(motion.skeleton(), motion.source())?;
    let positions = fk::target_positions(motion, &effectors.targets)?;
    let seg = segment::segment(&positions, motion.frame_time(), params)?;
    let floor = match kin.height_reference {
        HeightReference::Floor(h) => h,
        HeightReference::LowestPoint => lowest_point(motion, kin.up_axis)?,
    };
    let limbs = body::limbs(motion, &effectors)?;
    let kinematics = body::segment_kinematics(
        &positions,
        &limbs,
        motion.frame_time(),
        &seg.segments,
        kin.up_axis,
    );
    let y_raw = kinematics.iter().map(|k| k.log(&kin.eps)).collect();
    Ok(TakeAnalysis {
        source: motion.source().to_string(),
        frame_time: motion.frame_time(),
        effectors,
        positions,
        speed: seg.speed,
        threshold: seg.threshold,
        floor,
        limb_length: limbs.length,
        segments: seg.segments,
        kinematics,
        y_raw,
    })
}

/// The lowest coordinate along `up_axis` that any joint or end site reaches in the take
/// (0 for a take without frames or joints).
pub fn lowest_point(motion: &Motion, up_axis: usize) -> Result<f64, FkError> {
    let all = fk::target_positions(motion, &fk::all_targets(motion.skeleton(), true))?;
    let up = up_axis.min(2);
    let min = all
        .as_slice()
        .iter()
        .map(|p| p[up])
        .fold(f64::INFINITY, f64::min);
    Ok(if min.is_finite() { min } else { 0.0 })
}
