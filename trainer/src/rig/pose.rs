//! Rig poses back on the library's skeleton: the blob's host-side `skeleton` section
//! (docs/blob-format.md 3.7) as a [`Skeleton`], and each played pose as a BVH frame.
//!
//! ## How a pose becomes a frame (the choice, also stated in the format doc)
//!
//! Start from the rest frame (the library's first frame). Then, joint by joint in file order
//! (so a chain's upper joints are final before the joints below them):
//!
//! - a channel in **channel** mode (the full-skeleton rig) writes its value into the joint's
//!   own rotation channel: the library's frames come back exactly, up to the blob's 16-bit
//!   quantization (at most range / 65534 degrees per channel);
//! - the other channels of a joint (puppet rigs: twist or Euler angles, maybe over a
//!   `relative_to` chain) start from the chain's current rotation `R` and replace what they
//!   control: an Euler channel sets its angle of the decomposition in the rig's order; a twist
//!   channel sets the twist about its axis and keeps the swing (`R <- R * Rot(axis, new - old)`,
//!   exact because twists about one axis commute). The joint then gets the local rotation that
//!   makes its chain equal `R` (joints above it in the chain keep their values), written in its
//!   own channel order.
//!
//! - **body** channels come last: the parts and the body frame are found on the blob's skeleton
//!   and rest frame exactly as the packer found them (same names, same rest frame); the head
//!   gets the rotation relative to the chest that shows its pan, tilt and roll (the neck
//!   keeps its rest values), each upper arm the least turn that points it at its raise and
//!   swing, then each forearm the turn about the elbow's hinge (forward for a straight arm)
//!   to its flex. Each is exact, so these read back exactly too (away from an arm pointing
//!   straight forward or back, where raise is undefined).
//!
//! So reading the rig back from the rebuilt frame ([`BoundRig::channel_values`](super::BoundRig::channel_values))
//! gives the pose again for one channel per joint and for Euler gimbals; two twist channels on
//! one joint are applied in rig order and the second can disturb the first slightly. Joints no
//! channel drives, and the root position, keep their rest values: a puppet rig moves only its
//! joints, the character stays in place.
//!
//! Everything here is `f64`; nothing panics on a validated blob (the section's indices were
//! checked at load).

use gesture_runtime::blob::{BvhChannel, Drive, DriveMode, SkeletonView};
use gesture_runtime::rotation::{
    axis_rotation, euler_angles, euler_matrix, identity, mat_mul, transpose, twist_deg, Mat3,
};

use super::body::{Body, BodyMeasure, BodyPart};
use super::spec::Axis;
use crate::motion::fk::{local_transform, world_transforms, Transform};
use crate::motion::{Joint, Motion, MotionError, Skeleton};

/// The blob's skeleton, rest frame and rig channel drives, ready to rebuild frames.
#[derive(Clone, Debug)]
pub struct PoseSkeleton {
    skeleton: Skeleton,
    rest: Vec<f64>,
    starts: Vec<usize>,
    /// Per rig channel: (joint, chain top, axis, mode).
    drives: Vec<(usize, usize, Axis, DriveMode)>,
    /// The humanoid parts, found by name as the packer found them.
    body: Body,
    /// The body frame in the chest's frame, from the rest frame (as the packer took it).
    axes: Option<Mat3>,
}

impl PoseSkeleton {
    /// From a validated blob's skeleton section.
    pub fn from_blob(v: &SkeletonView<'_>) -> Result<Self, MotionError> {
        let joints: Vec<Joint> = (0..v.joints())
            .map(|j| Joint {
                name: v.joint_name(j).unwrap_or("").to_string(),
                parent: v.parent(j),
                offset: v.offset(j).map(f64::from),
                channels: v.joint_channels(j).filter_map(|i| v.channel(i)).collect(),
                end_site: v.end_site(j).map(|e| e.map(f64::from)),
            })
            .collect();
        let skeleton = Skeleton { joints };
        skeleton.validate()?;
        let rest: Vec<f64> = (0..v.channel_count()).map(|i| v.rest(i) as f64).collect();
        let drives: Vec<Drive> = (0..v.drives()).filter_map(|ch| v.drive(ch)).collect();
        Ok(Self::new(skeleton, rest, &drives))
    }

    /// From a skeleton, its rest frame (one value per channel) and the rig channels' drives
    /// (what the packer writes in the blob; `BoundRig::drives`). The drives' indices must be
    /// valid for `skeleton` and `rest` must have its channel count, as a validated blob
    /// guarantees.
    pub fn new(skeleton: Skeleton, rest: Vec<f64>, drives: &[Drive]) -> Self {
        let drives = drives
            .iter()
            .map(|d| {
                let axis = Axis {
                    index: d.axis as usize,
                    negated: d.negated,
                };
                (d.joint as usize, d.chain_top as usize, axis, d.mode)
            })
            .collect();
        let body = Body::find(&skeleton);
        let axes = body.axes(&world_transforms(&skeleton, &rest));
        Self {
            starts: skeleton.channel_starts(),
            skeleton,
            rest,
            drives,
            body,
            axes,
        }
    }

    /// The skeleton.
    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// The rest frame (one value per BVH channel).
    pub fn rest(&self) -> &[f64] {
        &self.rest
    }

    /// The humanoid parts the body channels read, found as the packer found them.
    pub fn body(&self) -> &Body {
        &self.body
    }

    /// The body frame in the chest's frame (columns left, up, forward), from the rest frame;
    /// `None` if the skeleton gives none ([`Body::axes`]).
    pub fn body_axes(&self) -> Option<Mat3> {
        self.axes
    }

    fn local_rotation(&self, frame: &[f64], j: usize) -> Mat3 {
        let joint = &self.skeleton.joints[j];
        let s = self.starts[j];
        local_transform(joint, &frame[s..s + joint.channels.len()]).0
    }

    /// The chain from `top` down to `joint` (top first); just `joint` if `top` is not above it.
    fn chain(&self, joint: usize, top: usize) -> Vec<usize> {
        let mut c = vec![joint];
        let mut cur = joint;
        while cur != top {
            match self.skeleton.joints[cur].parent {
                Some(p) => {
                    c.push(p);
                    cur = p;
                }
                None => return vec![joint],
            }
        }
        c.reverse();
        c
    }

    /// Writes rotation `m` into joint `j`'s rotation channels (decomposed in their order).
    fn set_local_rotation(&self, frame: &mut [f64], j: usize, m: &Mat3) {
        let joint = &self.skeleton.joints[j];
        let rot: Vec<(usize, usize)> = joint
            .channels
            .iter()
            .enumerate()
            .filter(|(_, c)| c.is_rotation())
            .map(|(k, c)| (k, c.axis()))
            .collect();
        if rot.is_empty() {
            return;
        }
        // The joint's order, completed with the axes it lacks (their angles are dropped).
        let mut order: Vec<usize> = rot.iter().map(|&(_, a)| a).collect();
        for a in 0..3 {
            if !order.contains(&a) {
                order.push(a);
            }
        }
        let angles = euler_angles(m, [order[0], order[1], order[2]]);
        for (i, &(k, _)) in rot.iter().enumerate() {
            frame[self.starts[j] + k] = angles[i];
        }
    }

    /// The BVH frame showing `pose` (one value per rig channel, degrees; see the module docs).
    pub fn frame(&self, pose: &[f32]) -> Vec<f64> {
        let mut frame = self.rest.clone();
        // Channel mode: the joint's own channel.
        for (&(j, _, axis, mode), &v) in self.drives.iter().zip(pose) {
            if mode != DriveMode::Channel {
                continue;
            }
            let joint = &self.skeleton.joints[j];
            let want = BvhChannel::rotation(axis.index);
            if let Some(k) = joint.channels.iter().position(|&c| c == want) {
                let sign = if axis.negated { -1.0 } else { 1.0 };
                frame[self.starts[j] + k] = sign * v as f64;
            }
        }
        // Angle modes, joint by joint in file order.
        let mut joints: Vec<usize> = self
            .drives
            .iter()
            .filter(|d| matches!(d.3, DriveMode::Twist | DriveMode::Euler(_)))
            .map(|d| d.0)
            .collect();
        joints.sort_unstable();
        joints.dedup();
        for j in joints {
            let mine: Vec<(usize, Axis, DriveMode, f64)> = self
                .drives
                .iter()
                .zip(pose)
                .filter(|(d, _)| d.0 == j && matches!(d.3, DriveMode::Twist | DriveMode::Euler(_)))
                .map(|(d, &v)| (d.1, d.2, d.3, v as f64))
                .collect();
            let top = mine[0].0;
            let chain = self.chain(j, top);
            let above = chain[..chain.len() - 1].iter().fold(identity(), |acc, &k| {
                mat_mul(&acc, &self.local_rotation(&frame, k))
            });
            let mut r = mat_mul(&above, &self.local_rotation(&frame, j));
            for &(_, axis, mode, v) in &mine {
                let sign = if axis.negated { -1.0 } else { 1.0 };
                let target = sign * v;
                match mode {
                    DriveMode::Twist => {
                        let old = twist_deg(&r, axis.index);
                        r = mat_mul(&r, &axis_rotation(axis.index, target - old));
                    }
                    DriveMode::Euler(o) => {
                        let order = [o[0] as usize, o[1] as usize, o[2] as usize];
                        let mut a = euler_angles(&r, order);
                        if let Some(k) = order.iter().position(|&x| x == axis.index) {
                            a[k] = target;
                        }
                        r = euler_matrix(order, a);
                    }
                    DriveMode::Channel | DriveMode::Body(_) => {}
                }
            }
            let local = mat_mul(&transpose(&above), &r);
            self.set_local_rotation(&mut frame, j, &local);
        }
        self.pose_body(&mut frame, pose);
        frame
    }

    /// The body measures of `pose` (see the module docs): the head, then each upper arm, then
    /// each elbow, each turned the least that shows its values.
    fn pose_body(&self, frame: &mut [f64], pose: &[f32]) {
        let Some(axes) = self.axes else { return };
        let mut want = [None::<f64>; 9];
        for (d, &v) in self.drives.iter().zip(pose) {
            if let DriveMode::Body(k) = d.3 {
                if let Some(slot) = want.get_mut(usize::from(k)) {
                    *slot = Some(f64::from(v));
                }
            }
        }
        let measure = |k: u8| BodyMeasure::from_index(k).filter(|&m| self.body.joint(m).is_some());
        let wanted = |k: u8| measure(k).and(want[usize::from(k)]);
        let mut world = world_transforms(&self.skeleton, frame);
        let head = [wanted(0), wanted(1), wanted(2)];
        if head.iter().any(Option::is_some) {
            if let Some((j, r)) = self.body.head_target(&world, &axes, head) {
                self.set_world_rotation(frame, &mut world, j, &r);
            }
        }
        for (s, (raise, swing, flex)) in [(3u8, 4u8, 7u8), (5, 6, 8)].into_iter().enumerate() {
            let arm = [wanted(raise), wanted(swing)];
            if arm.iter().any(Option::is_some) {
                if let Some((j, r)) =
                    self.body
                        .upper_arm_target(&self.skeleton, &world, &axes, s, arm)
                {
                    self.set_world_rotation(frame, &mut world, j, &r);
                }
            }
            debug_assert!(matches!(
                BodyMeasure::from_index(flex).map(BodyMeasure::part),
                Some(BodyPart::Elbow(_))
            ));
            if let Some(v) = wanted(flex) {
                if let Some((j, r)) = self.body.elbow_target(&self.skeleton, &world, &axes, s, v) {
                    self.set_world_rotation(frame, &mut world, j, &r);
                }
            }
        }
    }

    /// Gives joint `j` the local rotation that makes its world rotation `r` (its parent's
    /// unchanged), then updates `world`.
    fn set_world_rotation(
        &self,
        frame: &mut [f64],
        world: &mut Vec<Transform>,
        j: usize,
        r: &Mat3,
    ) {
        let parent = self.skeleton.joints[j]
            .parent
            .and_then(|p| world.get(p))
            .map_or_else(identity, |t| t.rotation);
        self.set_local_rotation(frame, j, &mat_mul(&transpose(&parent), r));
        *world = world_transforms(&self.skeleton, frame);
    }

    /// A motion of `poses` at `fps` frames per second.
    pub fn motion(&self, poses: &[Vec<f32>], fps: f64) -> Result<Motion, MotionError> {
        let mut data = Vec::with_capacity(poses.len() * self.rest.len());
        for p in poses {
            data.extend(self.frame(p));
        }
        Motion::new(self.skeleton.clone(), 1.0 / fps, poses.len(), data)
    }
}
