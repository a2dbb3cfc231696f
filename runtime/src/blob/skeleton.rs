//! The optional host-side `skeleton` section, read: the library's BVH joint tree, its rest
//! pose, and which joint rotation each rig channel drives (docs/blob-format.md, 3.7).
//!
//! The device never needs it: the controller plays rig channel values. Host tools (the
//! simulator's BVH output and previews) use it to put those values back on the skeleton. Like
//! every section it is validated at load, so every index read here is in range; accessors take
//! caller indices and return `None` or zeros when those are out of range. Per-joint channel
//! lookups walk the joint list (O(J)): fine on the host, not meant for a control loop.

use super::payload::{SkeletonSection, DRIVE_RECORD_BYTES, END_SITE_RECORD_BYTES, ROOT_PARENT};
use super::records::{f32_at, record, u16_at};

/// One degree of freedom of a BVH joint, as named in a `CHANNELS` line; its blob code
/// (`skeleton.channel_codes`) is its position in [`BvhChannel::ALL`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BvhChannel {
    /// Translation along X (skeleton units), code 0.
    Xposition,
    /// Translation along Y (skeleton units), code 1.
    Yposition,
    /// Translation along Z (skeleton units), code 2.
    Zposition,
    /// Rotation about X (degrees), code 3.
    Xrotation,
    /// Rotation about Y (degrees), code 4.
    Yrotation,
    /// Rotation about Z (degrees), code 5.
    Zrotation,
}

impl BvhChannel {
    /// All six channels, in code order: positions then rotations.
    pub const ALL: [BvhChannel; 6] = [
        Self::Xposition,
        Self::Yposition,
        Self::Zposition,
        Self::Xrotation,
        Self::Yrotation,
        Self::Zrotation,
    ];

    /// The name used in BVH files (`Xposition`, ..., `Zrotation`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Xposition => "Xposition",
            Self::Yposition => "Yposition",
            Self::Zposition => "Zposition",
            Self::Xrotation => "Xrotation",
            Self::Yrotation => "Yrotation",
            Self::Zrotation => "Zrotation",
        }
    }

    /// Parses a channel name, ignoring letter case (`Zrotation`, `ZROTATION`, `zrotation`).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|c| c.name().eq_ignore_ascii_case(name))
    }

    /// The blob code (0..=5).
    pub fn code(self) -> u8 {
        self as u8
    }

    /// The channel of a blob code, `None` above 5.
    pub fn from_code(code: u8) -> Option<Self> {
        Self::ALL.get(code as usize).copied()
    }

    /// The axis: 0 for X, 1 for Y, 2 for Z.
    pub fn axis(self) -> usize {
        (self as usize) % 3
    }

    /// The rotation channel about `axis` (0..=2; larger counts as Z).
    pub fn rotation(axis: usize) -> Self {
        [Self::Xrotation, Self::Yrotation, Self::Zrotation][axis.min(2)]
    }

    /// True for the three rotation channels.
    pub fn is_rotation(self) -> bool {
        self as u8 >= 3
    }
}

/// Euler decomposition orders of drive modes 2..=7, as axis indices (0 = X, 1 = Y, 2 = Z):
/// `XYZ`, `XZY`, `YXZ`, `YZX`, `ZXY`, `ZYX`.
pub const EULER_ORDERS: [[u8; 3]; 6] = [
    [0, 1, 2],
    [0, 2, 1],
    [1, 0, 2],
    [1, 2, 0],
    [2, 0, 1],
    [2, 1, 0],
];

/// Body measures of drive modes 8..=16 (the trainer's rig key `body`), in code order: mode
/// `8 + k` is `BODY_MEASURES[k]`. Their definitions (angles of world-space bone directions in
/// the chest's body frame) are in docs/blob-format.md, 3.7.
pub const BODY_MEASURES: [&str; 9] = [
    "head_pan",
    "head_tilt",
    "head_roll",
    "left_arm_raise",
    "left_arm_swing",
    "right_arm_raise",
    "right_arm_swing",
    "left_elbow_flex",
    "right_elbow_flex",
];

/// How a rig channel's angle was read from its joint (the trainer's rig `mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DriveMode {
    /// Twist about the axis of the chain's rotation (mode code 0).
    Twist,
    /// The joint's own BVH rotation channel about the axis (mode code 1).
    Channel,
    /// The angle for the axis in the Euler decomposition with this order (codes 2..=7,
    /// [`EULER_ORDERS`]).
    Euler([u8; 3]),
    /// A body measure, [`BODY_MEASURES`]`[k]` (codes 8..=16): `joint` is the bone that moves
    /// (head, upper arm or forearm), `chain_top` the chest whose frame is the reference;
    /// `axis` is unused (0).
    Body(u8),
}

impl DriveMode {
    /// The mode of a code, `None` if the code is unknown.
    pub fn from_code(code: u8) -> Option<Self> {
        match code {
            0 => Some(Self::Twist),
            1 => Some(Self::Channel),
            2..=7 => EULER_ORDERS
                .get(usize::from(code) - 2)
                .map(|&o| Self::Euler(o)),
            c => {
                let k = c.checked_sub(8)?;
                (usize::from(k) < BODY_MEASURES.len()).then_some(Self::Body(k))
            }
        }
    }

    /// The code of a mode (`Euler` with an order not in [`EULER_ORDERS`], or `Body` past
    /// [`BODY_MEASURES`], gives 0xFF).
    pub fn code(self) -> u8 {
        match self {
            Self::Twist => 0,
            Self::Channel => 1,
            Self::Euler(o) => EULER_ORDERS
                .iter()
                .position(|&x| x == o)
                .map_or(0xFF, |i| i as u8 + 2),
            Self::Body(k) if usize::from(k) < BODY_MEASURES.len() => 8 + k,
            Self::Body(_) => 0xFF,
        }
    }
}

/// Which joint rotation a rig channel shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Drive {
    /// The joint the channel follows.
    pub joint: u16,
    /// First joint of the rotation chain: the angle is measured on the product of the local
    /// rotations from `chain_top` down to `joint`, in `chain_top`'s parent frame (`joint`
    /// itself unless the rig file said `relative_to`).
    pub chain_top: u16,
    /// Axis index, 0 = X, 1 = Y, 2 = Z.
    pub axis: u8,
    /// Whether the value is the angle about the negative axis.
    pub negated: bool,
    /// How the angle is read.
    pub mode: DriveMode,
}

impl Drive {
    /// Decodes a 6-byte drive record; `None` if the axis or mode code is unknown.
    pub fn from_record(r: &[u8; DRIVE_RECORD_BYTES]) -> Option<Self> {
        let axis = r[4];
        if axis > 5 {
            return None;
        }
        Some(Self {
            joint: u16::from_le_bytes([r[0], r[1]]),
            chain_top: u16::from_le_bytes([r[2], r[3]]),
            axis: axis % 3,
            negated: axis >= 3,
            mode: DriveMode::from_code(r[5])?,
        })
    }

    /// The 6-byte record of this drive.
    pub fn record(&self) -> [u8; DRIVE_RECORD_BYTES] {
        let [a, b] = self.joint.to_le_bytes();
        let [c, d] = self.chain_top.to_le_bytes();
        let axis = self.axis.min(2) + if self.negated { 3 } else { 0 };
        [a, b, c, d, axis, self.mode.code()]
    }
}

/// A validated skeleton section (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkeletonView<'a> {
    s: SkeletonSection<'a>,
}

impl<'a> SkeletonView<'a> {
    pub(super) fn new(s: SkeletonSection<'a>) -> Self {
        Self { s }
    }

    /// Joints J (1..=[`MAX_JOINTS`](super::MAX_JOINTS)).
    pub fn joints(&self) -> usize {
        self.s.joints as usize
    }

    /// Joint names in order.
    pub fn joint_names(&self) -> core::str::Split<'a, char> {
        self.s.joint_names.split('\n')
    }

    /// Name of joint `j`.
    pub fn joint_name(&self, j: usize) -> Option<&'a str> {
        self.joint_names().nth(j)
    }

    /// Parent of joint `j` (`None` for a root or out of range); always `< j`.
    pub fn parent(&self, j: usize) -> Option<usize> {
        match u16_at(self.s.parents, j)? {
            ROOT_PARENT => None,
            p => Some(p as usize),
        }
    }

    /// BVH offset of joint `j` (zeros out of range).
    pub fn offset(&self, j: usize) -> [f32; 3] {
        let g = |k| f32_at(self.s.offsets, 3 * j + k).unwrap_or(0.0);
        [g(0), g(1), g(2)]
    }

    /// Total channels N (values per BVH frame).
    pub fn channel_count(&self) -> usize {
        self.s.channel_codes.len()
    }

    /// Joint `j`'s channels as indices into the frame (and [`Self::channel`],
    /// [`Self::rest`]); empty out of range. O(j).
    pub fn joint_channels(&self, j: usize) -> core::ops::Range<usize> {
        let counts = self.s.channel_counts;
        if j >= counts.len() {
            return 0..0;
        }
        let start: usize = counts[..j].iter().map(|&c| c as usize).sum();
        start..start + counts[j] as usize
    }

    /// Frame channel `i` (`None` out of range).
    pub fn channel(&self, i: usize) -> Option<BvhChannel> {
        self.s
            .channel_codes
            .get(i)
            .and_then(|&c| BvhChannel::from_code(c))
    }

    /// Rest-pose value of frame channel `i` (0 out of range).
    pub fn rest(&self, i: usize) -> f32 {
        f32_at(self.s.rest, i).unwrap_or(0.0)
    }

    /// End-site offset of joint `j`, if it has one (binary search).
    pub fn end_site(&self, j: usize) -> Option<[f32; 3]> {
        let n = self.s.end_sites.len() / END_SITE_RECORD_BYTES;
        let (mut lo, mut hi) = (0usize, n);
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            let r = record::<END_SITE_RECORD_BYTES>(self.s.end_sites, mid)?;
            let joint = u16::from_le_bytes([r[0], r[1]]) as usize;
            match joint.cmp(&j) {
                core::cmp::Ordering::Less => lo = mid + 1,
                core::cmp::Ordering::Greater => hi = mid,
                core::cmp::Ordering::Equal => {
                    let f = |k: usize| f32::from_le_bytes([r[k], r[k + 1], r[k + 2], r[k + 3]]);
                    return Some([f(2), f(6), f(10)]);
                }
            }
        }
        None
    }

    /// What rig channel `ch` drives (`None` out of range).
    pub fn drive(&self, ch: usize) -> Option<Drive> {
        record::<DRIVE_RECORD_BYTES>(self.s.drives, ch).and_then(Drive::from_record)
    }

    /// Number of drive records (the rig's channel count).
    pub fn drives(&self) -> usize {
        self.s.drives.len() / DRIVE_RECORD_BYTES
    }
}

impl core::fmt::Display for BvhChannel {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}
