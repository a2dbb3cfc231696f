//! Rig files: which output channel follows which joint rotation, with servo calibration
//! (DESIGN.md, "The runtime"; issue 5 item 2).
//!
//! Owns the TOML rig format ([`Rig::parse`], [`Rig::load`]), its binding to a BVH skeleton by
//! joint-name aliases ([`Rig::bind`] -> [`BoundRig`]), the extraction of one angle per channel
//! from a motion frame ([`BoundRig::channel_values`]) and the full-skeleton default rig for BVH
//! output ([`Rig::full_skeleton`]).
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
//! frame out of range, and finite values for a valid [`Motion`].

use std::fmt;
use std::path::Path;

use gesture_runtime::rig::{validate_period, CalError, ChannelCal, MAX_CHANNELS};
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;

use crate::motion::fk::{axis_rotation, local_transform, mat_mul, Mat3, IDENTITY};
use crate::motion::{Channel, Motion, Skeleton};

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

    fn sign(self) -> f64 {
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

/// Calibration of the channels of [`Rig::full_skeleton`]: neutral 0, limits +-180 deg, direction
/// +1, slew effectively unlimited. The pulse fields (1500 us, 5 us/deg) only satisfy
/// [`ChannelCal::validate`]; they mean nothing for BVH output.
pub const WIDE_CAL: ChannelCal = ChannelCal {
    neutral_deg: 0.0,
    min_deg: -180.0,
    max_deg: 180.0,
    direction: 1.0,
    pulse_neutral_us: 1500.0,
    us_per_deg: 5.0,
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

// ----- TOML reading ---------------------------------------------------------------------------

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRig {
    name: String,
    period_us: f32,
    #[serde(default)]
    channel: Vec<RawChannel>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawChannel {
    name: toml::Spanned<String>,
    joint: Vec<RawAlias>,
    axis: String,
    #[serde(default)]
    mode: Option<String>,
    #[serde(default)]
    order: Option<String>,
    #[serde(default)]
    relative_to: Vec<String>,
    neutral_deg: f32,
    min_deg: f32,
    max_deg: f32,
    direction: f32,
    pulse_neutral_us: f32,
    us_per_deg: f32,
    max_slew_deg_per_s: f32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAliasTable {
    name: String,
    #[serde(default)]
    axis: Option<String>,
    #[serde(default)]
    when_skeleton_has: Option<String>,
}

/// A joint alias: a bare name or a table (a hand-written visitor, so a typo inside the table
/// gets the TOML reader's precise message rather than "did not match any variant").
struct RawAlias(RawAliasTable);

impl<'de> Deserialize<'de> for RawAlias {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<RawAlias, D::Error> {
        struct AliasVisitor;
        impl<'de> Visitor<'de> for AliasVisitor {
            type Value = RawAlias;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a joint name or a table { name = \"...\", axis = \"...\" }")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<RawAlias, E> {
                Ok(RawAlias(RawAliasTable {
                    name: v.to_string(),
                    axis: None,
                    when_skeleton_has: None,
                }))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<RawAlias, A::Error> {
                RawAliasTable::deserialize(de::value::MapAccessDeserializer::new(map)).map(RawAlias)
            }
            fn visit_seq<A: SeqAccess<'de>>(self, _seq: A) -> Result<RawAlias, A::Error> {
                Err(de::Error::invalid_type(de::Unexpected::Seq, &self))
            }
        }
        deserializer.deserialize_any(AliasVisitor)
    }
}

/// 1-based (line, column) of byte offset `at` in `text`.
fn line_col(text: &str, at: usize) -> (usize, usize) {
    let at = at.min(text.len());
    let mut start = at;
    while !text.is_char_boundary(start) {
        start -= 1;
    }
    let before = &text[..start];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[line_start..].chars().count() + 1)
}

impl Rig {
    /// Reads and checks a rig file.
    pub fn load(path: impl AsRef<Path>) -> Result<Rig, RigError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| RigError::Io {
            path: shown.clone(),
            source,
        })?;
        Rig::parse(&text, &shown)
    }

    /// Parses and checks rig text; `path` is only used in messages.
    pub fn parse(text: &str, path: &str) -> Result<Rig, RigError> {
        let raw: RawRig = toml::from_str(text).map_err(|e| {
            let (line, column) = e.span().map_or((1, 1), |s| line_col(text, s.start));
            RigError::Toml {
                path: path.to_string(),
                line,
                column,
                message: e.message().trim_end().to_string(),
            }
        })?;
        validate_period(raw.period_us).map_err(|error| RigError::Period {
            path: path.to_string(),
            value: raw.period_us,
            error,
        })?;
        if raw.channel.is_empty() {
            return Err(RigError::NoChannels {
                path: path.to_string(),
            });
        }
        if raw.channel.len() > MAX_CHANNELS {
            return Err(RigError::TooManyChannels {
                path: path.to_string(),
                count: raw.channel.len(),
                max: MAX_CHANNELS,
            });
        }
        let mut channels: Vec<RigChannel> = Vec::with_capacity(raw.channel.len());
        for c in raw.channel {
            let line = line_col(text, c.name.span().start).0;
            let name = c.name.into_inner();
            let path = path.to_string();
            if channels.iter().any(|o| o.name == name) {
                return Err(RigError::DuplicateChannel {
                    path,
                    line,
                    channel: name,
                });
            }
            let axis_of = |value: &str| {
                Axis::parse(value).ok_or_else(|| RigError::UnknownAxis {
                    path: path.clone(),
                    line,
                    channel: name.clone(),
                    value: value.to_string(),
                })
            };
            let axis = axis_of(&c.axis)?;
            let mut joint_aliases = Vec::with_capacity(c.joint.len());
            for RawAlias(a) in c.joint {
                joint_aliases.push(JointAlias {
                    name: a.name,
                    axis: a.axis.as_deref().map(axis_of).transpose()?,
                    when_skeleton_has: a.when_skeleton_has,
                });
            }
            if joint_aliases.is_empty() {
                return Err(RigError::NoJointAliases {
                    path,
                    line,
                    channel: name,
                });
            }
            let bad = |reason: String| RigError::BadChannel {
                path: path.clone(),
                line,
                channel: name.clone(),
                reason,
            };
            let mode = match c.mode.as_deref().map(str::to_ascii_lowercase).as_deref() {
                None | Some("twist") => AngleMode::Twist,
                Some("channel") => AngleMode::Channel,
                Some("euler") => {
                    let text = c.order.as_deref().ok_or_else(|| {
                        bad("mode \"euler\" needs an `order`, e.g. order = \"ZYX\"".to_string())
                    })?;
                    AngleMode::Euler(parse_order(text).ok_or_else(|| {
                        bad(format!(
                            "unknown Euler order `{text}`; use three distinct axes such as \"ZYX\""
                        ))
                    })?)
                }
                Some(_) => {
                    return Err(bad(format!(
                        "unknown mode `{}`; use \"twist\", \"euler\" or \"channel\"",
                        c.mode.unwrap_or_default()
                    )))
                }
            };
            if c.order.is_some() && !matches!(mode, AngleMode::Euler(_)) {
                return Err(bad(
                    "`order` only applies with mode = \"euler\"; remove it or set the mode"
                        .to_string(),
                ));
            }
            if !c.relative_to.is_empty() && mode == AngleMode::Channel {
                return Err(bad(
                    "mode \"channel\" reads the raw BVH channel, which is always \
                     relative to the parent; remove `relative_to` or use another mode"
                        .to_string(),
                ));
            }
            let cal = ChannelCal {
                neutral_deg: c.neutral_deg,
                min_deg: c.min_deg,
                max_deg: c.max_deg,
                direction: c.direction,
                pulse_neutral_us: c.pulse_neutral_us,
                us_per_deg: c.us_per_deg,
                max_slew_deg_per_s: c.max_slew_deg_per_s,
            };
            if let Err(error) = cal.validate() {
                return Err(RigError::Calibration {
                    path,
                    line,
                    channel: name,
                    error,
                });
            }
            channels.push(RigChannel {
                name,
                joint_aliases,
                axis,
                mode,
                relative_to: c.relative_to,
                cal,
            });
        }
        Ok(Rig {
            name: raw.name,
            period_us: raw.period_us,
            channels,
        })
    }

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

    /// Resolves every channel's joint in `skeleton` (`source` names it in messages, e.g. the
    /// BVH path): the first alias, in order, whose name is a joint (ignoring ASCII case) and
    /// whose `when_skeleton_has` joint, if any, exists.
    pub fn bind(&self, skeleton: &Skeleton, source: &str) -> Result<BoundRig, RigError> {
        let starts = skeleton.channel_starts();
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
            });
        }
        Ok(BoundRig {
            rig: self.name.clone(),
            source: source.to_string(),
            joints: skeleton.joints.len(),
            channel_count: skeleton.channel_count(),
            channels,
        })
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

// ----- Bound rig and angle extraction ---------------------------------------------------------

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
    /// (joint, first channel in a frame) from the reference's child down to `joint`.
    chain: Vec<(usize, usize)>,
}

impl BoundChannel {
    /// The first joint of the rotation chain the angle is read from: `joint` itself, or with
    /// `relative_to` the reference's child on the path down to `joint`.
    pub fn chain_top(&self) -> usize {
        self.chain.first().map_or(self.joint, |&(j, _)| j)
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
}

impl BoundRig {
    /// The resolved channels, in rig order.
    pub fn channels(&self) -> &[BoundChannel] {
        &self.channels
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
            c.chain.iter().fold(IDENTITY, |acc, &(j, start)| {
                mat_mul(
                    &acc,
                    &local_transform(&skeleton.joints[j], joint_values(j, start)).0,
                )
            })
        };
        Some(
            self.channels
                .iter()
                .map(|c| {
                    let joint = &skeleton.joints[c.joint];
                    let deg = match c.mode {
                        AngleMode::Twist => twist_deg(&rotation(c), c.axis),
                        AngleMode::Euler(order) => euler_deg(&rotation(c), order, c.axis),
                        AngleMode::Channel => {
                            let values = c
                                .chain
                                .last()
                                .map_or(&[][..], |&(j, start)| joint_values(j, start));
                            let ch = [Channel::Xrotation, Channel::Yrotation, Channel::Zrotation]
                                [c.axis.index.min(2)];
                            let raw = joint
                                .channels
                                .iter()
                                .position(|&x| x == ch)
                                .and_then(|k| values.get(k).copied())
                                .unwrap_or(0.0);
                            c.axis.sign() * wrap_deg(raw)
                        }
                    };
                    deg as f32
                })
                .collect(),
        )
    }

    /// [`BoundRig::channel_values`] for every frame of `motion` (frames x channels); `None` if
    /// `motion` is not of the bound skeleton.
    pub fn take_values(&self, motion: &Motion) -> Option<Vec<Vec<f32>>> {
        (0..motion.frames())
            .map(|f| self.channel_values(motion, f))
            .collect()
    }
}

/// `deg` wrapped to `[-180, 180]`.
fn wrap_deg(deg: f64) -> f64 {
    let w = (deg + 180.0).rem_euclid(360.0) - 180.0;
    // rem_euclid can round up to exactly 360 for tiny negative inputs.
    w.clamp(-180.0, 180.0)
}

/// The unit quaternion `[w, x, y, z]` of a rotation matrix, `w >= 0` (Shepperd's method: the
/// largest of the four squared components is taken from the diagonal, so no division by a
/// small number).
pub fn quaternion(m: &Mat3) -> [f64; 4] {
    let tr = m[0][0] + m[1][1] + m[2][2];
    let q = if tr >= m[0][0] && tr >= m[1][1] && tr >= m[2][2] {
        let s = (1.0 + tr).max(0.0).sqrt() * 2.0;
        [
            0.25 * s,
            (m[2][1] - m[1][2]) / s,
            (m[0][2] - m[2][0]) / s,
            (m[1][0] - m[0][1]) / s,
        ]
    } else if m[0][0] >= m[1][1] && m[0][0] >= m[2][2] {
        let s = (1.0 + m[0][0] - m[1][1] - m[2][2]).max(0.0).sqrt() * 2.0;
        [
            (m[2][1] - m[1][2]) / s,
            0.25 * s,
            (m[0][1] + m[1][0]) / s,
            (m[0][2] + m[2][0]) / s,
        ]
    } else if m[1][1] >= m[2][2] {
        let s = (1.0 + m[1][1] - m[0][0] - m[2][2]).max(0.0).sqrt() * 2.0;
        [
            (m[0][2] - m[2][0]) / s,
            (m[0][1] + m[1][0]) / s,
            0.25 * s,
            (m[1][2] + m[2][1]) / s,
        ]
    } else {
        let s = (1.0 + m[2][2] - m[0][0] - m[1][1]).max(0.0).sqrt() * 2.0;
        [
            (m[1][0] - m[0][1]) / s,
            (m[0][2] + m[2][0]) / s,
            (m[1][2] + m[2][1]) / s,
            0.25 * s,
        ]
    };
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    if !(n.is_finite() && n > 0.0) {
        return [1.0, 0.0, 0.0, 0.0];
    }
    let sign = if q[0] < 0.0 { -1.0 } else { 1.0 };
    q.map(|v| sign * v / n)
}

/// The twist angle (degrees, `[-180, 180]`) of rotation `m` about `axis`: `2 atan2(v . a, w)`
/// for its quaternion `(w, v)` with `w >= 0`, negated for a negated axis (module docs).
pub fn twist_deg(m: &Mat3, axis: Axis) -> f64 {
    let q = quaternion(m);
    let t = 2.0 * q[1 + axis.index.min(2)].atan2(q[0]);
    axis.sign() * t.to_degrees()
}

/// The angle (degrees) for `axis` in the decomposition `m = R_o0(a) R_o1(b) R_o2(c)`,
/// `order = [o0, o1, o2]` a permutation of 0, 1, 2 (module docs); negated for a negated axis.
/// `a` and `c` are in `[-180, 180]`, `b` in `[-90, 90]`; at gimbal lock `c = 0`.
pub fn euler_deg(m: &Mat3, order: [usize; 3], axis: Axis) -> f64 {
    let angles = euler_angles(m, order);
    let k = order.iter().position(|&o| o == axis.index).unwrap_or(0);
    axis.sign() * angles[k]
}

/// All three angles (degrees) of [`euler_deg`]'s decomposition, in `order`.
pub fn euler_angles(m: &Mat3, order: [usize; 3]) -> [f64; 3] {
    let [i, j, k] = order.map(|o| o.min(2));
    if i == j || j == k || i == k {
        return [0.0; 3];
    }
    // +1 for cyclic orders (XYZ, YZX, ZXY), -1 for the others.
    let s = if j == (i + 1) % 3 { 1.0 } else { -1.0 };
    let sb = (s * m[i][k]).clamp(-1.0, 1.0);
    let b = sb.asin();
    if (1.0 - sb.abs()) > 1e-12 {
        let a = (-s * m[j][k]).atan2(m[k][k]);
        let c = (-s * m[i][j]).atan2(m[i][i]);
        [a.to_degrees(), b.to_degrees(), c.to_degrees()]
    } else {
        // Gimbal lock: only a + c (or a - c) is defined; put it all in `a`. What is left after
        // undoing the middle rotation is a rotation about axis i.
        let b_deg = b.to_degrees();
        let rest = mat_mul(m, &transpose(&axis_rotation(j, b_deg)));
        let (p, q) = ((i + 1) % 3, (i + 2) % 3);
        let a = rest[q][p].atan2(rest[p][p]);
        [a.to_degrees(), b_deg, 0.0]
    }
}

fn transpose(m: &Mat3) -> Mat3 {
    [
        [m[0][0], m[1][0], m[2][0]],
        [m[0][1], m[1][1], m[2][1]],
        [m[0][2], m[1][2], m[2][2]],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    const X: Axis = Axis {
        index: 0,
        negated: false,
    };
    const Y: Axis = Axis {
        index: 1,
        negated: false,
    };
    const Z: Axis = Axis {
        index: 2,
        negated: false,
    };

    #[test]
    fn twist_is_exact_for_single_axis_rotations() {
        for axis in 0..3 {
            for deg in [-179.0, -120.0, -30.0, 0.0, 1e-3, 30.0, 90.0, 135.0, 179.5] {
                let m = axis_rotation(axis, deg);
                for (k, a) in [X, Y, Z].into_iter().enumerate() {
                    let want = if k == axis { deg } else { 0.0 };
                    let got = twist_deg(&m, a);
                    assert!(
                        (got - want).abs() < 1e-9,
                        "rotation {deg} about {axis}: twist about {a} = {got}, want {want}"
                    );
                }
                let neg = Axis {
                    negated: true,
                    ..[X, Y, Z][axis]
                };
                assert!((twist_deg(&m, neg) + deg).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn twist_recovers_both_angles_of_a_two_axis_gimbal() {
        for (a, b) in [(0, 1), (1, 2), (2, 0), (1, 0), (2, 1), (0, 2)] {
            for (s, e) in [(40.0, -70.0), (-150.0, 60.0), (10.0, 170.0)] {
                let m = mat_mul(&axis_rotation(a, s), &axis_rotation(b, e));
                let ta = twist_deg(&m, [X, Y, Z][a]);
                let tb = twist_deg(&m, [X, Y, Z][b]);
                assert!(
                    (ta - s).abs() < 1e-9 && (tb - e).abs() < 1e-9,
                    "{a}{b}: {ta} {tb}"
                );
            }
        }
    }

    const ORDERS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];

    fn compose(order: [usize; 3], angles: [f64; 3]) -> Mat3 {
        (0..3).fold(IDENTITY, |acc, k| {
            mat_mul(&acc, &axis_rotation(order[k], angles[k]))
        })
    }

    #[test]
    fn euler_recovers_the_angles_that_built_the_matrix() {
        for order in ORDERS {
            for angles in [
                [30.0, -40.0, 50.0],
                [-170.0, 80.0, 175.0],
                [120.0, -89.0, -100.0],
                [0.0, 0.0, 0.0],
            ] {
                let got = euler_angles(&compose(order, angles), order);
                for k in 0..3 {
                    assert!(
                        (got[k] - angles[k]).abs() < 1e-7,
                        "{order:?} {angles:?}: {got:?}"
                    );
                }
            }
            // Gimbal lock: the angles differ but the rotation is the same, and finite.
            for b in [90.0, -90.0] {
                let m = compose(order, [25.0, b, 40.0]);
                let got = euler_angles(&m, order);
                assert!(got.iter().all(|v| v.is_finite()));
                assert_eq!(got[2], 0.0);
                let back = compose(order, got);
                for r in 0..3 {
                    for c in 0..3 {
                        assert!(
                            (back[r][c] - m[r][c]).abs() < 1e-9,
                            "{order:?} {b}: {got:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn euler_is_exact_for_single_axis_rotations() {
        for order in ORDERS {
            for axis in 0..3 {
                let middle = order[1] == axis;
                for deg in [-150.0, -90.0, -30.0, 0.0, 30.0, 89.0, 179.0] {
                    if middle && f64::abs(deg) > 90.0 {
                        continue;
                    }
                    let m = axis_rotation(axis, deg);
                    for (k, a) in [X, Y, Z].into_iter().enumerate() {
                        let want = if k == axis { deg } else { 0.0 };
                        let got = euler_deg(&m, order, a);
                        assert!((got - want).abs() < 1e-7, "{order:?} {axis} {deg}: {got}");
                    }
                }
            }
        }
    }

    #[test]
    fn order_parsing() {
        assert_eq!(parse_order("ZYX"), Some([2, 1, 0]));
        assert_eq!(parse_order("yzx"), Some([1, 2, 0]));
        assert_eq!(parse_order("ZZX"), None);
        assert_eq!(parse_order("ZY"), None);
        assert_eq!(parse_order("ZYXW"), None);
    }

    #[test]
    fn quaternion_is_unit_and_reproduces_the_matrix() {
        let m = mat_mul(
            &mat_mul(&axis_rotation(2, 170.0), &axis_rotation(0, -100.0)),
            &axis_rotation(1, 179.9),
        );
        let [w, x, y, z] = quaternion(&m);
        assert!(w >= 0.0);
        assert!(((w * w + x * x + y * y + z * z) - 1.0).abs() < 1e-12);
        let r = [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
            ],
            [
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
            ],
            [
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ];
        for i in 0..3 {
            for j in 0..3 {
                assert!((r[i][j] - m[i][j]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn axis_parsing_and_wrapping() {
        assert_eq!(Axis::parse("y"), Some(Y));
        assert_eq!(Axis::parse(" +Z "), Some(Z));
        assert_eq!(
            Axis::parse("-X"),
            Some(Axis {
                index: 0,
                negated: true
            })
        );
        assert_eq!(Axis::parse("W"), None);
        assert_eq!(Axis::parse("--X"), None);
        assert_eq!(wrap_deg(190.0), -170.0);
        assert_eq!(wrap_deg(-540.0), -180.0);
        assert_eq!(wrap_deg(45.0), 45.0);
    }

    #[test]
    fn line_col_counts_characters() {
        let t = "a = 1\nbé = x\n";
        assert_eq!(line_col(t, 0), (1, 1));
        assert_eq!(line_col(t, 6), (2, 1));
        assert_eq!(line_col(t, t.find('x').unwrap()), (2, 6));
        assert_eq!(line_col(t, 999), (3, 1));
    }
}
