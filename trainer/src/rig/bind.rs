//! A rig bound to one skeleton: each channel's joint resolved by its aliases, its rotation
//! chain, and the angle it reads from a motion frame (the convention is in the parent
//! module's docs). A [`BoundRig`] holds joint indices valid for the skeleton it was bound to;
//! [`BoundRig::channel_values`] gives `None` rather than panicking for another skeleton or a
//! frame out of range, and finite values for a valid [`Motion`].

use gesture_runtime::blob::{BvhChannel, Drive, DriveMode};
use gesture_runtime::rotation::{euler_angles, identity, mat_mul, twist_deg, wrap_deg, Mat3};

use super::body::{Body, BodyMeasure, BodyPart, Effector};
use super::spec::{AngleMode, Axis, Rig, RigChannel, RigError};
use crate::motion::fk::{local_transform, world_transforms};
use crate::motion::{Motion, Skeleton};

impl Rig {
    /// Resolves every channel's joint in `skeleton` (`source` names it in messages, e.g. the
    /// BVH path): the first alias, in order, whose name is a joint (ignoring ASCII case) and
    /// whose `when_skeleton_has` joint, if any, exists.
    /// A channel none of whose aliases applies reads its `body` measure, if it has one (and
    /// holds its neutral if the skeleton lacks that part); without one it is an error.
    pub fn bind(&self, skeleton: &Skeleton, source: &str) -> Result<BoundRig, RigError> {
        let starts = skeleton.channel_starts();
        let body = Body::find(skeleton);
        let mut channels = Vec::with_capacity(self.channels.len());
        for c in &self.channels {
            let found = c.joint_aliases.iter().find_map(|a| {
                let applies = a
                    .when_skeleton_has
                    .as_deref()
                    .is_none_or(|w| skeleton.find_ignore_case(w).is_some());
                if !applies {
                    return None;
                }
                skeleton.find_ignore_case(&a.name).map(|j| (j, a))
            });
            let Some((joint, alias)) = found else {
                if let Some(m) = c.body {
                    channels.push(body_channel(c, m, &body, skeleton, &starts));
                    continue;
                }
                return Err(RigError::MissingJoint {
                    skeleton: source.to_string(),
                    rig: self.name.clone(),
                    channel: c.name.clone(),
                    tried: c
                        .joint_aliases
                        .iter()
                        .map(ToString::to_string)
                        .collect::<Vec<_>>()
                        .join(", "),
                    joints: joint_list(skeleton),
                });
            };
            let chain = self.chain(c, skeleton, joint, source)?;
            channels.push(BoundChannel {
                name: c.name.clone(),
                joint,
                joint_name: skeleton.joints[joint].name.clone(),
                axis: alias.axis.unwrap_or(c.axis),
                mode: c.mode,
                reference: chain
                    .first()
                    .and_then(|&j| skeleton.joints[j].parent)
                    .map(|p| skeleton.joints[p].name.clone()),
                chain: chain.into_iter().map(|j| (j, starts[j])).collect(),
                held: None,
                neutral: c.cal.neutral_deg,
                detail: String::new(),
            });
        }
        Ok(BoundRig {
            rig: self.name.clone(),
            source: source.to_string(),
            joints: skeleton.joints.len(),
            channel_count: skeleton.channel_count(),
            channels,
            body,
            axes: None,
            rest_given: false,
        })
    }
}

/// Channel `c` reading body measure `m` (or holding its neutral when the skeleton lacks it).
fn body_channel(
    c: &RigChannel,
    m: BodyMeasure,
    body: &Body,
    skeleton: &Skeleton,
    starts: &[usize],
) -> BoundChannel {
    let name = |j: usize| skeleton.joints.get(j).map_or("", |x| x.name.as_str());
    let point = |e: Effector| match e {
        Effector::Joint(j) => format!("`{}`", name(j)),
        Effector::EndSite(j) => format!("`{}`'s end site", name(j)),
    };
    let (joint, chest) = match (body.joint(m), body.chest) {
        (Some(j), Some(chest)) => (j, chest),
        _ => {
            return BoundChannel {
                name: c.name.clone(),
                joint: 0,
                joint_name: name(0).to_string(),
                axis: c.axis,
                mode: AngleMode::Body(m),
                reference: None,
                chain: Vec::new(),
                held: Some(
                    body.missing(m)
                        .unwrap_or_else(|| "no such part".to_string()),
                ),
                neutral: c.cal.neutral_deg,
                detail: String::new(),
            }
        }
    };
    let detail = match (m.part(), body.arms) {
        (BodyPart::Head, _) => format!("`{}`", name(joint)),
        (BodyPart::UpperArm(s), arms) => arms[s].map_or(String::new(), |a| {
            format!("`{}` -> {}", name(a.upper), point(a.elbow))
        }),
        (BodyPart::Elbow(s), arms) => arms[s].map_or(String::new(), |a| {
            let wrist = a.wrist.map_or(String::new(), point);
            format!(
                "{} -> {} -> {wrist}",
                point(Effector::Joint(a.upper)),
                point(a.elbow)
            )
        }),
    };
    BoundChannel {
        name: c.name.clone(),
        joint,
        joint_name: name(joint).to_string(),
        axis: c.axis,
        mode: AngleMode::Body(m),
        reference: Some(name(chest).to_string()),
        // The chest: the drive record's `chain_top` (the reference), not a rotation chain.
        chain: vec![(chest, starts[chest])],
        held: None,
        neutral: c.cal.neutral_deg,
        detail,
    }
}

impl Rig {
    /// The joints whose local rotations make up channel `c`'s rotation, from the reference
    /// frame's child down to `joint`.
    fn chain(
        &self,
        c: &RigChannel,
        skeleton: &Skeleton,
        joint: usize,
        source: &str,
    ) -> Result<Vec<usize>, RigError> {
        // Ancestors nearest first; bounded by the joint count even for a malformed tree.
        let mut ancestors = Vec::new();
        let mut cur = skeleton.joints[joint].parent;
        while let Some(p) = cur {
            if ancestors.len() >= skeleton.joints.len() {
                break;
            }
            ancestors.push(p);
            cur = skeleton.joints[p].parent;
        }
        if c.relative_to.is_empty() {
            return Ok(vec![joint]);
        }
        let reference = c.relative_to.iter().find_map(|name| {
            ancestors
                .iter()
                .position(|&a| skeleton.joints[a].name.eq_ignore_ascii_case(name))
        });
        let Some(k) = reference else {
            let names: Vec<String> = ancestors
                .iter()
                .map(|&a| format!("`{}`", skeleton.joints[a].name))
                .collect();
            return Err(RigError::MissingAncestor {
                skeleton: source.to_string(),
                channel: c.name.clone(),
                joint: skeleton.joints[joint].name.clone(),
                tried: c
                    .relative_to
                    .iter()
                    .map(|n| format!("`{n}`"))
                    .collect::<Vec<_>>()
                    .join(", "),
                ancestors: if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                },
            });
        };
        // ancestors[k] is the reference; the chain is ancestors[..k] (farthest first), then joint.
        let mut chain: Vec<usize> = ancestors[..k].iter().rev().copied().collect();
        chain.push(joint);
        Ok(chain)
    }
}

/// Up to 40 joint names, for messages.
fn joint_list(skeleton: &Skeleton) -> String {
    const SHOWN: usize = 40;
    let n = skeleton.joints.len();
    let mut s: Vec<String> = skeleton
        .joint_names()
        .take(SHOWN)
        .map(|j| format!("`{j}`"))
        .collect();
    if n > SHOWN {
        s.push(format!("... ({} more)", n - SHOWN));
    }
    if s.is_empty() {
        "none".to_string()
    } else {
        s.join(", ")
    }
}

/// One channel resolved against a skeleton.
#[derive(Clone, Debug, PartialEq)]
pub struct BoundChannel {
    /// The channel's name.
    pub name: String,
    /// Index of the joint in the skeleton.
    pub joint: usize,
    /// The joint's name in the skeleton.
    pub joint_name: String,
    /// The axis in effect (the alias's override, else the channel's).
    pub axis: Axis,
    /// How the angle is read.
    pub mode: AngleMode,
    /// The joint whose frame is the reference (`None` for a root without `relative_to`).
    pub reference: Option<String>,
    /// (joint, first channel in a frame) from the reference's child down to `joint`; for a
    /// body measure, just the chest.
    chain: Vec<(usize, usize)>,
    /// Why the channel holds its neutral (the skeleton lacks its body part), or `None`.
    pub held: Option<String>,
    /// The calibration's neutral, the value of a held channel.
    neutral: f32,
    /// For a body measure: the bones it reads, for [`BoundChannel::describe`].
    detail: String,
}

impl BoundChannel {
    /// The first joint of the rotation chain the angle is read from: `joint` itself, or with
    /// `relative_to` the reference's child on the path down to `joint`.
    pub fn chain_top(&self) -> usize {
        self.chain.first().map_or(self.joint, |&(j, _)| j)
    }

    /// One line saying what the channel reads on this skeleton (what `pack` prints).
    pub fn describe(&self) -> String {
        if let Some(why) = &self.held {
            return format!(
                "{}: held at its neutral {} deg: the skeleton has {why}",
                self.name, self.neutral
            );
        }
        match self.mode {
            AngleMode::Body(m) => format!(
                "{}: {m} of {} in the body frame of `{}`",
                self.name,
                self.detail,
                self.reference.as_deref().unwrap_or("")
            ),
            mode => format!(
                "{}: {mode} about {} of joint `{}` in the frame of `{}`",
                self.name,
                self.axis,
                self.joint_name,
                self.reference.as_deref().unwrap_or("the world")
            ),
        }
    }
}

/// A rig resolved against one skeleton: reads channel values from that skeleton's motion.
#[derive(Clone, Debug, PartialEq)]
pub struct BoundRig {
    rig: String,
    source: String,
    joints: usize,
    channel_count: usize,
    channels: Vec<BoundChannel>,
    body: Body,
    /// The body frame in the chest's frame, fixed by [`BoundRig::with_rest`].
    axes: Option<Mat3>,
    /// Whether [`BoundRig::with_rest`] fixed the body frame (or found none).
    rest_given: bool,
}

impl BoundRig {
    /// The resolved channels, in rig order.
    pub fn channels(&self) -> &[BoundChannel] {
        &self.channels
    }

    /// Fixes the body frame of the body channels from `rest` (one frame's channel values of the
    /// bound skeleton, e.g. the library's first frame, which the blob stores as its rest
    /// pose). Without it each motion's own first frame is used. A `rest` of the wrong length
    /// is ignored.
    pub fn with_rest(mut self, skeleton: &Skeleton, rest: &[f64]) -> BoundRig {
        if self.matches(skeleton) && rest.len() == self.channel_count {
            self.axes = self.body.axes(&world_transforms(skeleton, rest));
            self.rest_given = true;
        }
        self
    }

    /// The skeleton's humanoid parts, as the body channels found them.
    pub fn body(&self) -> &Body {
        &self.body
    }

    /// One line per channel: what it reads, or why it holds its neutral; after
    /// [`BoundRig::with_rest`], a body channel also holds it when the rest frame gives no body
    /// frame (no shoulders or hips to take left-right from).
    pub fn describe(&self) -> Vec<String> {
        self.channels
            .iter()
            .map(|c| match c.mode {
                AngleMode::Body(_)
                    if c.held.is_none() && self.rest_given && self.axes.is_none() =>
                {
                    format!(
                    "{}: held at its neutral {} deg: no body frame (no two upper arms or upper \
                     legs for left-right, or no hips)",
                    c.name, c.neutral
                )
                }
                _ => c.describe(),
            })
            .collect()
    }

    /// The rig's name.
    pub fn rig_name(&self) -> &str {
        &self.rig
    }

    /// Where the bound skeleton came from.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Whether `motion`'s skeleton looks like the one this rig was bound to (same joint and
    /// channel counts, and every bound joint has the same name at the same index).
    pub fn matches(&self, skeleton: &Skeleton) -> bool {
        skeleton.joints.len() == self.joints
            && skeleton.channel_count() == self.channel_count
            && self.channels.iter().all(|c| {
                c.chain.iter().all(|&(j, _)| j < skeleton.joints.len())
                    && skeleton.joints[c.joint].name == c.joint_name
            })
    }

    /// Every channel's angle (degrees, see the module docs for the convention) at frame
    /// `frame`; `None` if the frame is out of range or `motion` is not of the bound skeleton.
    pub fn channel_values(&self, motion: &Motion, frame: usize) -> Option<Vec<f32>> {
        self.values_with(motion, frame, self.axes_for(motion).as_ref())
    }

    /// The body frame: the one fixed by [`BoundRig::with_rest`], else from `motion`'s first
    /// frame (`None` too when no channel reads a body measure).
    fn axes_for(&self, motion: &Motion) -> Option<Mat3> {
        let reads_body = self
            .channels
            .iter()
            .any(|c| matches!(c.mode, AngleMode::Body(_)) && c.held.is_none());
        if !reads_body || !self.matches(motion.skeleton()) {
            return None;
        }
        self.axes.or_else(|| {
            let rest = motion.frame(0)?;
            self.body.axes(&world_transforms(motion.skeleton(), rest))
        })
    }

    fn values_with(&self, motion: &Motion, frame: usize, axes: Option<&Mat3>) -> Option<Vec<f32>> {
        let skeleton = motion.skeleton();
        if !self.matches(skeleton) {
            return None;
        }
        let row = motion.frame(frame)?;
        let joint_values = |j: usize, start: usize| {
            let n = skeleton.joints[j].channels.len();
            row.get(start..start + n).unwrap_or(&[])
        };
        let rotation = |c: &BoundChannel| {
            c.chain.iter().fold(identity::<f64>(), |acc, &(j, start)| {
                mat_mul(
                    &acc,
                    &local_transform(&skeleton.joints[j], joint_values(j, start)).0,
                )
            })
        };
        let world = axes.map(|_| world_transforms(skeleton, row));
        Some(
            self.channels
                .iter()
                .map(|c| {
                    let joint = &skeleton.joints[c.joint];
                    let deg = match c.mode {
                        AngleMode::Twist => c.axis.sign() * twist_deg(&rotation(c), c.axis.index),
                        AngleMode::Euler(order) => euler_deg(&rotation(c), order, c.axis),
                        AngleMode::Channel => {
                            let values = c
                                .chain
                                .last()
                                .map_or(&[][..], |&(j, start)| joint_values(j, start));
                            let ch = BvhChannel::rotation(c.axis.index);
                            let raw = joint
                                .channels
                                .iter()
                                .position(|&x| x == ch)
                                .and_then(|k| values.get(k).copied())
                                .unwrap_or(0.0);
                            c.axis.sign() * wrap_deg(raw)
                        }
                        AngleMode::Body(m) => match (&world, axes, &c.held) {
                            (Some(w), Some(a), None) => self
                                .body
                                .measure(skeleton, w, a, m)
                                .unwrap_or(f64::from(c.neutral)),
                            _ => f64::from(c.neutral),
                        },
                    };
                    deg as f32
                })
                .collect(),
        )
    }

    /// [`BoundRig::channel_values`] for every frame of `motion` (frames x channels); `None` if
    /// `motion` is not of the bound skeleton.
    pub fn take_values(&self, motion: &Motion) -> Option<Vec<Vec<f32>>> {
        let axes = self.axes_for(motion);
        (0..motion.frames())
            .map(|f| self.values_with(motion, f, axes.as_ref()))
            .collect()
    }

    /// What each channel drives, in rig channel order: the records of the blob's skeleton
    /// section. `None` if a joint index does not fit the record's `u16`.
    pub fn drives(&self) -> Option<Vec<Drive>> {
        self.channels
            .iter()
            .map(|c| {
                let mode = match c.mode {
                    AngleMode::Twist => DriveMode::Twist,
                    AngleMode::Channel => DriveMode::Channel,
                    AngleMode::Euler(o) => DriveMode::Euler([o[0] as u8, o[1] as u8, o[2] as u8]),
                    AngleMode::Body(m) => DriveMode::Body(m.index()),
                };
                Some(Drive {
                    joint: u16::try_from(c.joint).ok()?,
                    chain_top: u16::try_from(c.chain_top()).ok()?,
                    axis: if matches!(mode, DriveMode::Body(_)) {
                        0
                    } else {
                        c.axis.index.min(2) as u8
                    },
                    negated: c.axis.negated && !matches!(mode, DriveMode::Body(_)),
                    mode,
                })
            })
            .collect()
    }
}

/// The angle (degrees) for `axis` in the Euler decomposition of `m` in `order`, negated for a
/// negated axis.
fn euler_deg(m: &Mat3, order: [usize; 3], axis: Axis) -> f64 {
    let angles = euler_angles(m, order);
    let k = order.iter().position(|&o| o == axis.index).unwrap_or(0);
    axis.sign() * angles[k]
}
