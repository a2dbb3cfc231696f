//! Rig files: which output channel follows which joint rotation, with servo calibration
//! (docs/method.md, "The runtime").
//!
//! - this module: the rig's types ([`Rig`], [`RigChannel`], [`Axis`], [`AngleMode`]), its
//!   errors, and the full-skeleton default rig for BVH output ([`Rig::full_skeleton`]);
//! - `file`: the TOML rig format ([`Rig::parse`], [`Rig::load`]);
//! - `bind`: binding to a BVH skeleton by joint-name aliases ([`Rig::bind`] ->
//!   [`BoundRig`]), the extraction of one angle per channel from a motion frame
//!   ([`BoundRig::channel_values`]) and what each channel drives in the blob's skeleton
//!   section ([`BoundRig::drives`]);
//! - `pose`: the inverse, rig poses back on the library's skeleton from a blob's skeleton
//!   section ([`PoseSkeleton`]): what the simulator writes as BVH and what the motion
//!   evaluation measures.
//!
//! The rotation math (Euler decompositions, twist, quaternions) is the runtime's
//! ([`gesture_runtime::rotation`]), shared with the simulator that puts poses back on the
//! skeleton.
//!
//! ## Format
//!
//! ```toml
//! name = "puppet-8ch"
//! period_us = 20000                 # PWM period (us)
//!
//! [[channel]]
//! name = "head_pan"
//! # Aliases, tried in order; the first joint found in the skeleton (ignoring case) wins.
//! # A table form overrides the axis for skeletons whose joint frames differ, and may apply
//! # only when the skeleton also has some joint (to tell apart skeletons with the same name).
//! joint = [{ name = "Head", axis = "X", when_skeleton_has = "joint_Root" }, "Head", "head"]
//! axis = "Y"                        # X, Y or Z of the reference frame; "-Y" flips the sign
//! mode = "twist"                    # optional: "twist" (default), "euler" or "channel"
//! # order = "ZYX"                   # with mode = "euler": the decomposition order
//! relative_to = ["Spine3", "Chest"] # optional: measure against this ancestor, not the parent
//! neutral_deg = 0.0                 # calibration: see gesture_runtime::rig::ChannelCal
//! min_deg = -60.0
//! max_deg = 60.0
//! direction = 1
//! pulse_neutral_us = 1500
//! us_per_deg = 10.0
//! max_slew_deg_per_s = 300.0
//! ```
//!
//! Unknown keys are errors (a typo in `max_slew_deg_per_s` must not silently mean "default").
//! Every error names the file and, where it has one, the line.
//!
//! ## The angle of a channel (the convention)
//!
//! A channel's value comes from the joint's rotation relative to a reference frame: its
//! parent's by default (the joint's **local** rotation, built from its rotation channels in its
//! own order, as [`crate::motion::fk`] does), or, with `relative_to`, the first listed joint
//! that is an ancestor of it (the product of the local rotations along the chain, so a head
//! channel can follow the whole neck). The angle is measured about one axis of that frame:
//!
//! - `mode = "twist"` (default): the **twist** angle of a swing-twist decomposition about the
//!   axis. With the rotation as a unit quaternion `(w, v)`, `w >= 0`, it is
//!   `2 atan2(v . axis, w)`, in `[-180, 180]` degrees. It does not depend on the joint's
//!   channel order, has no gimbal lock, and is exact for a pure rotation about the axis (30 deg
//!   about Y gives 30 for Y and 0 for X and Z) and, more usefully, for any composition of two
//!   rotations about perpendicular axes in either order (`Ry(s) Rz(e)` gives `s` for Y and `e`
//!   for Z): a two-servo gimbal reads back its own two angles. With all three axes moving it is
//!   a projection: the part of the rotation about that axis. Right for hinges (elbows) and
//!   small rotations (head), even past 90 degrees.
//! - `mode = "euler"` with `order = "ZYX"` (any permutation of XYZ): the angle for the axis in
//!   the decomposition `R = R_Z(a) R_Y(b) R_X(c)` (rotations acting on column vectors, the
//!   BVH channel convention), the first and last angles in `[-180, 180]`, the middle one in
//!   `[-90, 90]`; at gimbal lock the last angle is 0. Right for a two-servo shoulder: with the
//!   bone axis last (X for arms along X at rest) the first two angles fix the bone's direction
//!   whatever the twist about the bone, which a real upper arm has plenty of and a two-servo
//!   shoulder cannot show. (Twist would mix that rotation into the raise angle: on ZeroEGGS it
//!   made the right shoulder raise swing across +-180 degrees.) Choose the order so the lock
//!   (middle angle +-90) is a rare pose: with `ZYX` it is an arm pointing straight forward or
//!   back, not hanging down as with `YZX`. Exact for a pure rotation about the first or last
//!   axis, and about the middle axis up to 90 degrees.
//! - `mode = "channel"`: the joint's own BVH rotation channel about that axis, wrapped to
//!   `[-180, 180]` (0 if the joint has no such channel). This is the raw Euler angle, used by
//!   the full-skeleton rig so BVH output can reproduce the joints exactly.
//!
//! A leading `-` on the axis negates the value, so one calibration can serve skeletons whose
//! frames point the other way.
//!
//! ## Invariants
//!
//! A [`Rig`] from [`Rig::parse`] or [`Rig::full_skeleton`] has 1..=[`MAX_CHANNELS`] channels
//! with distinct names, at least one joint alias each, calibrations that pass
//! [`ChannelCal::validate`] and a period that passes
//! [`gesture_runtime::rig::validate_period`], so a runtime `ServoRig` built from it cannot
//! refuse it. A [`BoundRig`] holds joint indices valid for the skeleton it was bound to;
//! [`BoundRig::channel_values`] gives `None` rather than panicking for another skeleton or a
//! frame out of range, and finite values for a valid [`Motion`](crate::motion::Motion).

mod bind;
mod file;
mod pose;

use std::fmt;

use gesture_runtime::rig::{CalError, ChannelCal, MAX_CHANNELS};

pub use bind::{BoundChannel, BoundRig};
pub use pose::PoseSkeleton;

use crate::motion::Skeleton;

/// A rotation axis of a joint's parent frame, possibly negated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Axis {
    /// 0 for X, 1 for Y, 2 for Z.
    pub index: usize,
    /// Whether the angle is measured about the negative axis (its sign flipped).
    pub negated: bool,
}

impl Axis {
    /// Parses `X`, `Y`, `Z`, optionally with a `+` or `-` sign, ignoring case.
    pub fn parse(text: &str) -> Option<Axis> {
        let t = text.trim();
        let (negated, letter) = match t.strip_prefix('-') {
            Some(rest) => (true, rest),
            None => (false, t.strip_prefix('+').unwrap_or(t)),
        };
        let index = match letter {
            "X" | "x" => 0,
            "Y" | "y" => 1,
            "Z" | "z" => 2,
            _ => return None,
        };
        Some(Axis { index, negated })
    }

    /// -1 for a negated axis, else 1.
    pub fn sign(self) -> f64 {
        if self.negated {
            -1.0
        } else {
            1.0
        }
    }
}

impl fmt::Display for Axis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let letter = ["X", "Y", "Z"][self.index.min(2)];
        if self.negated {
            write!(f, "-{letter}")
        } else {
            f.write_str(letter)
        }
    }
}

/// How a channel's angle is read from its joint (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AngleMode {
    /// The twist about the axis of a swing-twist decomposition of the local rotation.
    #[default]
    Twist,
    /// The angle for the axis in an Euler decomposition `R = R_o0 R_o1 R_o2` with
    /// `order = [o0, o1, o2]` (axis indices, a permutation of 0, 1, 2).
    Euler([usize; 3]),
    /// The joint's own BVH rotation channel about the axis, wrapped to `[-180, 180]`.
    Channel,
}

impl fmt::Display for AngleMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AngleMode::Twist => f.write_str("twist"),
            AngleMode::Channel => f.write_str("channel"),
            AngleMode::Euler(order) => {
                f.write_str("euler ")?;
                for &o in order {
                    f.write_str(["X", "Y", "Z"][o.min(2)])?;
                }
                Ok(())
            }
        }
    }
}

/// Parses an Euler order such as `ZYX` (any case) into axis indices.
pub fn parse_order(text: &str) -> Option<[usize; 3]> {
    let mut order = [0; 3];
    let mut chars = text.trim().chars();
    for o in order.iter_mut() {
        *o = match chars.next()? {
            'X' | 'x' => 0,
            'Y' | 'y' => 1,
            'Z' | 'z' => 2,
            _ => return None,
        };
    }
    let distinct = order[0] != order[1] && order[1] != order[2] && order[0] != order[2];
    (chars.next().is_none() && distinct).then_some(order)
}

/// One joint name a channel may follow.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct JointAlias {
    /// The joint name (matched ignoring ASCII case).
    pub name: String,
    /// Axis to use instead of the channel's when this alias is the one found.
    pub axis: Option<Axis>,
    /// The alias applies only to skeletons that also have a joint of this name.
    pub when_skeleton_has: Option<String>,
}

impl fmt::Display for JointAlias {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "`{}`", self.name)?;
        if let Some(w) = &self.when_skeleton_has {
            write!(f, " (if the skeleton has `{w}`)")?;
        }
        Ok(())
    }
}

/// One output channel: a joint rotation about one axis, and the servo that shows it.
#[derive(Clone, Debug, PartialEq)]
pub struct RigChannel {
    /// The channel's name (unique within the rig).
    pub name: String,
    /// Joint names to follow, tried in order.
    pub joint_aliases: Vec<JointAlias>,
    /// The axis (of the joint's parent frame) the angle is measured about.
    pub axis: Axis,
    /// How the angle is read.
    pub mode: AngleMode,
    /// Ancestor joint names whose frame is the reference, tried in order (empty: the parent).
    pub relative_to: Vec<String>,
    /// The servo calibration (validated).
    pub cal: ChannelCal,
}

/// A rig: named output channels with their calibrations (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Rig {
    /// The rig's name.
    pub name: String,
    /// PWM period (us), e.g. 20000 for 50 Hz hobby servos.
    pub period_us: f32,
    /// The channels, in output order.
    pub channels: Vec<RigChannel>,
}

/// Calibration of the channels of [`Rig::full_skeleton`]: neutral 0, limits +-360 deg (a
/// capture's Euler angles may pass +-180; the controller clamps poses to these limits),
/// direction +1, slew effectively unlimited. The pulse fields (1500 us, 2.5 us/deg) only
/// satisfy [`ChannelCal::validate`]; they mean nothing for BVH output.
pub const WIDE_CAL: ChannelCal = ChannelCal {
    neutral_deg: 0.0,
    min_deg: -360.0,
    max_deg: 360.0,
    direction: 1.0,
    pulse_neutral_us: 1500.0,
    us_per_deg: 2.5,
    max_slew_deg_per_s: 1.0e6,
};

/// Why a rig file could not be used, or a rig not bound to a skeleton.
#[derive(Debug, thiserror::Error)]
pub enum RigError {
    /// The file could not be read.
    #[error("{path}: cannot read the rig file: {source}")]
    Io {
        /// The path as given.
        path: String,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The text is not valid TOML, or has a missing, unknown or mistyped key.
    #[error("{path}:{line}:{column}: {message}")]
    Toml {
        /// The path as given.
        path: String,
        /// 1-based line.
        line: usize,
        /// 1-based column (characters).
        column: usize,
        /// The TOML reader's message.
        message: String,
    },
    /// An axis is not X, Y or Z.
    #[error(
        "{path}:{line}: channel `{channel}`: unknown axis `{value}`; use X, Y or Z, \
         optionally signed (\"-Y\")"
    )]
    UnknownAxis {
        /// The path as given.
        path: String,
        /// Line of the channel's name.
        line: usize,
        /// The channel.
        channel: String,
        /// What the file says.
        value: String,
    },
    /// A channel's `mode`, `order` or `relative_to` is unusable.
    #[error("{path}:{line}: channel `{channel}`: {reason}")]
    BadChannel {
        /// The path as given.
        path: String,
        /// Line of the channel's name.
        line: usize,
        /// The channel.
        channel: String,
        /// What is wrong and what to write instead.
        reason: String,
    },
    /// A channel's calibration is invalid.
    #[error("{path}:{line}: channel `{channel}`: invalid calibration: {error}")]
    Calibration {
        /// The path as given.
        path: String,
        /// Line of the channel's name.
        line: usize,
        /// The channel.
        channel: String,
        /// What is wrong.
        error: CalError,
    },
    /// The PWM period is unusable.
    #[error("{path}: period_us = {value}: {error}")]
    Period {
        /// The path as given.
        path: String,
        /// The period.
        value: f32,
        /// The runtime's reason.
        error: gesture_runtime::rig::RigError,
    },
    /// No channels.
    #[error("{path}: the rig has no channels; add at least one [[channel]] table")]
    NoChannels {
        /// The path as given.
        path: String,
    },
    /// More channels than the runtime can hold.
    #[error(
        "{path}: {count} channels, but a rig has at most {max} \
         (gesture_runtime::rig::MAX_CHANNELS); drop some channels"
    )]
    TooManyChannels {
        /// The path as given.
        path: String,
        /// Channels in the rig.
        count: usize,
        /// The capacity.
        max: usize,
    },
    /// Two channels share a name.
    #[error("{path}:{line}: channel name `{channel}` is used twice; names must be unique")]
    DuplicateChannel {
        /// The path as given.
        path: String,
        /// Line of the second use.
        line: usize,
        /// The name.
        channel: String,
    },
    /// A channel lists no joint.
    #[error(
        "{path}:{line}: channel `{channel}` has an empty `joint` list; name at least one joint"
    )]
    NoJointAliases {
        /// The path as given.
        path: String,
        /// Line of the channel's name.
        line: usize,
        /// The channel.
        channel: String,
    },
    /// None of a channel's `relative_to` names is an ancestor of its joint.
    #[error(
        "{skeleton}: channel `{channel}`: none of {tried} is an ancestor of joint \
         `{joint}` (its ancestors are {ancestors}); fix the channel's `relative_to` list"
    )]
    MissingAncestor {
        /// Where the skeleton came from.
        skeleton: String,
        /// The channel.
        channel: String,
        /// The joint the channel follows.
        joint: String,
        /// The names tried.
        tried: String,
        /// The joint's ancestors, nearest first.
        ancestors: String,
    },
    /// None of a channel's joint aliases is in the skeleton.
    #[error(
        "{skeleton}: rig `{rig}`, channel `{channel}`: no joint named {tried} (ignoring case); \
         the skeleton's joints are {joints}. Add the right name to the channel's `joint` list"
    )]
    MissingJoint {
        /// Where the skeleton came from (a BVH path).
        skeleton: String,
        /// The rig's name.
        rig: String,
        /// The channel.
        channel: String,
        /// The aliases tried, as a readable list.
        tried: String,
        /// Some of the skeleton's joint names.
        joints: String,
    },
}

impl Rig {
    /// The full-skeleton default for BVH output: one channel per rotation channel of every joint,
    /// in skeleton order and each joint's channel order, named `<Joint>.<Xrotation>`, reading
    /// the raw channel ([`AngleMode::Channel`]) with [`WIDE_CAL`] (no servo meaning), so a
    /// pose of this rig holds every joint rotation a BVH writer needs. Translation channels
    /// (the root's position) are not included. Fails with
    /// [`RigError::TooManyChannels`] if the skeleton has more than [`MAX_CHANNELS`] rotation
    /// channels (ZeroEGGS has 225).
    pub fn full_skeleton(skeleton: &Skeleton) -> Result<Rig, RigError> {
        let channels: Vec<RigChannel> = skeleton
            .joints
            .iter()
            .flat_map(|j| {
                j.channels
                    .iter()
                    .filter(|c| c.is_rotation())
                    .map(move |&c| RigChannel {
                        name: format!("{}.{}", j.name, c.name()),
                        joint_aliases: vec![JointAlias {
                            name: j.name.clone(),
                            axis: None,
                            when_skeleton_has: None,
                        }],
                        axis: Axis {
                            index: c.axis(),
                            negated: false,
                        },
                        mode: AngleMode::Channel,
                        relative_to: Vec::new(),
                        cal: WIDE_CAL,
                    })
            })
            .collect();
        let path = "full-skeleton rig".to_string();
        if channels.is_empty() {
            return Err(RigError::NoChannels { path });
        }
        if channels.len() > MAX_CHANNELS {
            return Err(RigError::TooManyChannels {
                path,
                count: channels.len(),
                max: MAX_CHANNELS,
            });
        }
        Ok(Rig {
            name: "full-skeleton".to_string(),
            period_us: 20_000.0,
            channels,
        })
    }

    /// The calibrations in channel order (for a runtime `ServoRig`).
    pub fn cals(&self) -> Vec<ChannelCal> {
        self.channels.iter().map(|c| c.cal).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_parsing() {
        assert_eq!(parse_order("ZYX"), Some([2, 1, 0]));
        assert_eq!(parse_order("yzx"), Some([1, 2, 0]));
        assert_eq!(parse_order("ZZX"), None);
        assert_eq!(parse_order("ZY"), None);
        assert_eq!(parse_order("ZYXW"), None);
    }

    #[test]
    fn axis_parsing() {
        assert_eq!(
            Axis::parse("y"),
            Some(Axis {
                index: 1,
                negated: false
            })
        );
        assert_eq!(
            Axis::parse(" +Z "),
            Some(Axis {
                index: 2,
                negated: false
            })
        );
        assert_eq!(
            Axis::parse("-X"),
            Some(Axis {
                index: 0,
                negated: true
            })
        );
        assert_eq!(Axis::parse("W"), None);
        assert_eq!(Axis::parse("--X"), None);
    }
}
