//! A rig as specified: its output channels ([`RigChannel`]), each an [`Axis`] of a joint
//! found by name aliases ([`JointAlias`]) read in an [`AngleMode`] with a servo calibration;
//! the full-skeleton rig ([`Rig::full_skeleton`]); and why a rig is refused ([`RigError`]).
//! The file format, the binding and the poses build on these (see [`super`]).

use std::fmt;

use gesture_runtime::rig::{CalError, ChannelCal, MAX_CHANNELS};

use super::body::BodyMeasure;
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
    /// A body measure (the channel's `body` key, see the module docs): set on a
    /// [`BoundChannel`](super::BoundChannel) that reads it; never a rig file's `mode`.
    Body(BodyMeasure),
}

impl fmt::Display for AngleMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AngleMode::Twist => f.write_str("twist"),
            AngleMode::Channel => f.write_str("channel"),
            AngleMode::Body(m) => write!(f, "body {m}"),
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
    /// Joint names to follow, tried in order (may be empty for a channel with a `body`).
    pub joint_aliases: Vec<JointAlias>,
    /// The body measure to read when no joint alias applies (the `body` key).
    pub body: Option<BodyMeasure>,
    /// The axis (of the joint's parent frame) the angle is measured about (joint aliases only).
    pub axis: Axis,
    /// How the angle is read from a joint alias.
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
        "{path}:{line}: channel `{channel}` has an empty `joint` list and no `body`; name at \
         least one joint, or a body measure such as body = \"head_pan\""
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
                        body: None,
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
