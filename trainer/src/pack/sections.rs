//! Stage 2 of packing: the sections the policy does not touch, from the model and the
//! prepared library: the front-end settings and the inference layer as trained, the
//! controller's settings, the library's frames as rig channel angles (with its calm frames,
//! motion beats, segment energies and rotation groups), the rig's calibration and (unless
//! left out) the library's skeleton; and [`Sections::encode`], which writes them with a
//! policy's sections through the runtime's writer (checked with `Blob::parse`). Built once;
//! stage 4 encodes them with each candidate policy to measure its size.

use gesture_runtime::blob::encode::{
    encode, EncodeError, JointSpec, OwnedInference, OwnedLabels, OwnedLibrary, OwnedPolicy,
    OwnedRig, OwnedSkeleton, OwnedStyles, SegmentSpec,
};
use gesture_runtime::blob::{ControlSection, FrontEndSection, Payload, EULER_ORDERS};
use gesture_runtime::prosody::ProsodyConfig;
use gesture_runtime::rig::ChannelCal;

use crate::evaluate::signals::{quantile, smoothed_hand_speed, speed_minima, speed_peaks};
use crate::inference::model::InferenceModel;
use crate::inference::quantize::inference_section;
use crate::motion::Skeleton;
use crate::rig::{AngleMode, Rig};

use super::error::PackError;
use super::library::PackLibrary;
use super::options::PackOptions;

/// Every section but the policy's (see the module docs).
pub struct Sections {
    front_end: FrontEndSection,
    inference: OwnedInference,
    control: ControlSection,
    library: OwnedLibrary,
    rig: OwnedRig,
    skeleton: Option<OwnedSkeleton>,
    /// Library frames stored.
    pub frames: usize,
    /// One line per rig channel saying what it reads on the library's skeleton, or why it
    /// holds its neutral.
    pub rig_lines: Vec<String>,
}

/// The joints of `skeleton` as the writer takes them.
pub fn joint_specs(skeleton: &Skeleton) -> Vec<JointSpec<'_>> {
    skeleton
        .joints
        .iter()
        .map(|j| JointSpec {
            name: &j.name,
            parent: j.parent,
            offset: j.offset,
            channels: &j.channels,
            end_site: j.end_site,
        })
        .collect()
}

/// The quantile of the library's smoothed hand speeds at or below which a frame is calm.
pub const CALM_QUANTILE: f64 = 0.3;

/// The calm frames (indices into the frame table) of takes given as (first frame in the
/// table, smoothed hand speed per frame): those whose speed is at most the
/// [`CALM_QUANTILE`] of all the takes' speeds, where a cut decided mid-segment may fall
/// (`DecisionTiming::defer_cut_ms`).
pub fn calm_frames(takes: &[(usize, Vec<f64>)]) -> Vec<usize> {
    let all: Vec<f64> = takes.iter().flat_map(|(_, s)| s.iter().copied()).collect();
    if all.is_empty() {
        return Vec::new();
    }
    let threshold = quantile(&all, CALM_QUANTILE);
    takes
        .iter()
        .flat_map(|(first, s)| {
            s.iter()
                .enumerate()
                .filter(move |(_, &v)| v <= threshold)
                .map(move |(i, _)| first + i)
        })
        .collect()
}

/// Each segment's energy (`library.energy`, read by `gesture_runtime::follow`): the natural
/// log of its hands' mean smoothed speed over the median smoothed speed of all the takes'
/// frames. `takes` as for [`calm_frames`], `segments` as (take, first frame, end frame) in
/// the take. A segment without frames, or a library that never moves, has energy 0; a
/// segment that stands still is floored at 1/100 of the median (`ln = -4.6`).
pub fn segment_energies(
    takes: &[(usize, Vec<f64>)],
    segments: &[(usize, usize, usize)],
) -> Vec<f32> {
    let all: Vec<f64> = takes.iter().flat_map(|(_, s)| s.iter().copied()).collect();
    let median = quantile(&all, 0.5);
    segments
        .iter()
        .map(|&(take, a, b)| {
            let sp = takes
                .get(take)
                .map_or(&[][..], |(_, s)| &s[a.min(s.len())..b.min(s.len())]);
            if sp.is_empty() || median <= 0.0 {
                return 0.0;
            }
            let mean = sp.iter().sum::<f64>() / sp.len() as f64;
            (mean.max(0.01 * median) / median).ln() as f32
        })
        .collect()
}

impl Sections {
    /// The sections of `source`'s library through its rig (the takes share a skeleton, stage 1
    /// checked it).
    pub fn new(
        model: &InferenceModel,
        source: &PackLibrary,
        opts: &PackOptions,
    ) -> Result<Self, PackError> {
        let (lib, rig) = (&source.lib, &source.rig);
        let labelling = source.labelling.as_ref();
        // The body channels' frame comes from the library's first frame, for every take (the
        // blob's rest pose, from which the simulator takes it again).
        let rest: Vec<f64> = lib.takes[0].motion.frame(0).unwrap_or(&[]).to_vec();
        let mut rig_lines = Vec::new();
        // Channel angles of every frame, take after take.
        let mut frames: Vec<Vec<f32>> = Vec::new();
        let mut offsets = Vec::with_capacity(lib.takes.len());
        let mut beats = Vec::new();
        let mut peaks = Vec::new();
        // Per take, its first frame in the table and its hands' smoothed speed per frame.
        let mut speeds: Vec<(usize, Vec<f64>)> = Vec::with_capacity(lib.takes.len());
        for t in &lib.takes {
            let pos = &t.analysis.positions;
            let hands: Vec<Vec<[f64; 3]>> =
                (0..pos.frames()).map(|f| pos.frame(f).to_vec()).collect();
            let speed = smoothed_hand_speed(&hands, t.motion.fps());
            beats.extend(speed_minima(&speed).into_iter().map(|b| frames.len() + b));
            peaks.extend(
                speed_peaks(&speed, t.motion.fps())
                    .into_iter()
                    .map(|p| frames.len() + p),
            );
            speeds.push((frames.len(), speed));
            let bound = rig
                .bind(t.motion.skeleton(), &t.source.display().to_string())?
                .with_rest(t.motion.skeleton(), &rest);
            if rig_lines.is_empty() {
                rig_lines = bound.describe();
            }
            offsets.push(frames.len());
            let values = bound.take_values(&t.motion).ok_or_else(|| {
                EncodeError::Inconsistent(format!(
                    "{}: the rig does not fit this skeleton",
                    t.source.display()
                ))
            })?;
            frames.extend(values);
        }
        let segments: Vec<SegmentSpec> = lib
            .segments
            .iter()
            .enumerate()
            .map(|(i, s)| SegmentSpec {
                start: offsets[s.take] + s.start,
                len: s.len(),
                stroke: labelling.and_then(|l| l.stroke[i]),
                label: labelling.map_or(0, |l| l.label_of[i]),
                // The recorded successor is stored right after (segments of a take are
                // contiguous and in order).
                continues: s.next == Some(i + 1)
                    && lib.segments.get(i + 1).is_some_and(|n| n.start == s.end),
            })
            .collect();
        let cals: Vec<(String, ChannelCal)> = rig
            .channels
            .iter()
            .map(|c| (c.name.clone(), c.cal))
            .collect();
        // Exactly what the model's features were computed with (recorded in the model file).
        let config: ProsodyConfig = model.prosody;
        config
            .validate()
            .map_err(|e| PackError::FrontEnd(format!("the model's front-end settings: {e}")))?;
        let skeleton = if opts.no_skeleton {
            None
        } else {
            let first = &lib.takes[0];
            let sk = first.motion.skeleton();
            let bound = rig.bind(sk, &first.source.display().to_string())?;
            let drives = bound.drives().ok_or(EncodeError::TooLarge {
                what: "skeleton joints",
                value: sk.joints.len(),
                ty: "u16",
            })?;
            Some(OwnedSkeleton::new(&joint_specs(sk), &rest, &drives)?)
        };
        let calm = calm_frames(&speeds);
        let energy = segment_energies(
            &speeds,
            &lib.segments
                .iter()
                .map(|s| (s.take, s.start, s.end))
                .collect::<Vec<_>>(),
        );
        let n = frames.len();
        Ok(Self {
            front_end: FrontEndSection::from_config(&config),
            inference: inference_section(&model.gmm, &model.crf)?,
            control: ControlSection::new(&opts.timing, &opts.variety, &opts.follow, opts.blend_ms),
            library: OwnedLibrary::new(
                lib.fps,
                rig.channels.len(),
                &frames,
                &segments,
                &beats,
                &rotation_groups(
                    rig,
                    &lib.takes[0].motion.skeleton().clone(),
                    &lib.takes[0].source.display().to_string(),
                )?,
            )?
            .with_calm(&calm)
            .with_energy(&energy)
            .with_peaks(&peaks),
            rig: OwnedRig::new(&rig.name, rig.period_us, &cals)?,
            skeleton,
            frames: n,
            rig_lines,
        })
    }

    /// The blob's bytes: these sections with `policy`, `styles` and `labels`.
    pub fn encode(
        &self,
        policy: &OwnedPolicy,
        styles: Option<&OwnedStyles>,
        labels: Option<&OwnedLabels>,
    ) -> Result<Vec<u8>, EncodeError> {
        encode(&Payload {
            front_end: self.front_end,
            inference: self.inference.section(),
            policy: policy.section(),
            control: self.control,
            library: self.library.section(),
            rig: self.rig.section(),
            skeleton: self.skeleton.as_ref().map(OwnedSkeleton::section),
            styles: styles.map(OwnedStyles::section),
            labels: labels.map(OwnedLabels::section),
        })
    }
}

/// The rig's rotation groups: three consecutive channels that read one joint's own BVH
/// rotation channels (the full-skeleton rig), as (first channel, Euler order index). The
/// player blends them as one rotation.
pub fn rotation_groups(
    rig: &Rig,
    skeleton: &Skeleton,
    source: &str,
) -> Result<Vec<(usize, u8)>, PackError> {
    let bound = rig.bind(skeleton, source)?;
    let ch = bound.channels();
    let mut groups = Vec::new();
    let mut k = 0;
    while k + 3 <= ch.len() {
        let three = &ch[k..k + 3];
        let same_joint = three.iter().all(|c| c.joint == three[0].joint);
        let raw = three
            .iter()
            .all(|c| c.mode == AngleMode::Channel && !c.axis.negated);
        let order = [
            three[0].axis.index,
            three[1].axis.index,
            three[2].axis.index,
        ];
        let code = EULER_ORDERS
            .iter()
            .position(|o| [o[0] as usize, o[1] as usize, o[2] as usize] == order);
        match (same_joint && raw, code) {
            (true, Some(code)) => {
                groups.push((k, code as u8));
                k += 3;
            }
            _ => k += 1,
        }
    }
    Ok(groups)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_energy_is_the_log_of_its_mean_speed_over_the_median_frame() {
        // All frames sorted: 0 0 1 1 1 1 4 4 4 4, median (nearest rank) 1.
        let takes = vec![
            (0, vec![1.0, 1.0, 1.0, 1.0]),
            (4, vec![4.0, 4.0, 4.0, 4.0]),
            (8, vec![0.0, 0.0]),
        ];
        let e = segment_energies(
            &takes,
            &[(0, 0, 4), (1, 1, 3), (2, 0, 2), (0, 2, 2), (5, 0, 1)],
        );
        let want = [0.0, 4f32.ln(), 0.01f32.ln(), 0.0, 0.0];
        for (got, want) in e.iter().zip(want) {
            assert!((got - want).abs() < 1e-6, "{e:?}");
        }
        // A library that never moves: every energy 0.
        assert_eq!(segment_energies(&[(0, vec![0.0; 3])], &[(0, 0, 3)]), [0.0]);
    }

    #[test]
    fn calm_frames_are_those_at_or_below_the_30th_percentile_of_all_takes() {
        // Speeds 0..=6 over two takes: the 30th percentile (nearest rank) is 2.
        let takes = [(0, vec![5.0, 1.0, 3.0, 2.0]), (4, vec![4.0, 0.0, 6.0])];
        assert_eq!(calm_frames(&takes), [1, 3, 5]);
        assert!(calm_frames(&[]).is_empty());
        assert!(calm_frames(&[(0, vec![])]).is_empty());
    }
}
