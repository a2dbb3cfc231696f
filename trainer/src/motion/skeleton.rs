//! The in-memory motion types: [`Skeleton`], [`Joint`], [`Channel`] (the runtime's
//! [`BvhChannel`](gesture_runtime::blob::BvhChannel), whose blob codes the packer writes) and
//! [`Motion`]. Everything else in [`crate::motion`] reads motion through these types.
//!
//! **A [`Motion`] is valid once built** (check once, then trust): joints are in depth-first
//! order (every parent precedes its children, and the joints of a subtree are contiguous, as
//! in the file), no joint lists a channel twice, joint names are not empty and have no line
//! breaks, offsets and all samples are finite, `0.001 <= frame_time <= 1`, and
//! `data.len() == frames * channel_count`. The BVH reader ([`super::parse_bvh`]) and
//! [`Motion::new`] enforce this, and the fields are private, so forward kinematics and the
//! writer can rely on it without re-checking.

/// Shortest accepted frame time (s): 1000 frames per second.
pub const MIN_FRAME_TIME_S: f64 = 0.001;
/// Longest accepted frame time (s): 1 frame per second.
pub const MAX_FRAME_TIME_S: f64 = 1.0;

pub use gesture_runtime::blob::BvhChannel as Channel;

/// One joint of a [`Skeleton`].
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// The name given after `ROOT` / `JOINT` (may contain spaces).
    pub name: String,
    /// Index of the parent joint in [`Skeleton::joints`]; `None` for a root.
    pub parent: Option<usize>,
    /// Position of this joint in its parent's frame when it has no translation channels.
    pub offset: [f64; 3],
    /// The joint's channels in file order; this order is also the rotation order.
    pub channels: Vec<Channel>,
    /// The `End Site` offset, in this joint's frame, if the joint has one.
    pub end_site: Option<[f64; 3]>,
}

/// A joint hierarchy. Joints are in depth-first (file) order: a parent precedes its children.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Skeleton {
    /// The joints in file order; the channels of a frame follow this order.
    pub joints: Vec<Joint>,
}

impl Skeleton {
    /// Total number of channels (values per frame).
    pub fn channel_count(&self) -> usize {
        self.joints.iter().map(|j| j.channels.len()).sum()
    }

    /// Index of each joint's first channel within a frame (`channel_starts()[j]`).
    pub fn channel_starts(&self) -> Vec<usize> {
        let mut start = 0;
        self.joints
            .iter()
            .map(|j| {
                let s = start;
                start += j.channels.len();
                s
            })
            .collect()
    }

    /// The first joint with exactly this name.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The first joint whose name equals `name` ignoring ASCII case.
    pub fn find_ignore_case(&self, name: &str) -> Option<usize> {
        self.joints
            .iter()
            .position(|j| j.name.eq_ignore_ascii_case(name))
    }

    /// Indices of the direct children of joint `j`, in file order.
    pub fn children(&self, j: usize) -> impl Iterator<Item = usize> + '_ {
        self.joints
            .iter()
            .enumerate()
            .filter(move |(_, joint)| joint.parent == Some(j))
            .map(|(i, _)| i)
    }

    /// Number of ancestors of joint `j` (0 for a root). Out-of-range `j` gives 0.
    pub fn depth(&self, j: usize) -> usize {
        let mut depth = 0;
        let mut cur = self.joints.get(j).and_then(|joint| joint.parent);
        // Bounded by the joint count even if a hand-built skeleton had a cycle.
        while let Some(p) = cur {
            depth += 1;
            if depth > self.joints.len() {
                break;
            }
            cur = self.joints.get(p).and_then(|joint| joint.parent);
        }
        depth
    }

    /// Joint names in file order (for messages).
    pub fn joint_names(&self) -> impl Iterator<Item = &str> + '_ {
        self.joints.iter().map(|j| j.name.as_str())
    }

    /// Checks the structural invariants listed in the module docs.
    pub fn validate(&self) -> Result<(), MotionError> {
        // `open` is the chain of ancestors of the previous joint (depth-first order check).
        let mut open: Vec<usize> = Vec::new();
        for (i, joint) in self.joints.iter().enumerate() {
            let bad = |reason: &'static str| MotionError::InvalidSkeleton {
                joint: joint.name.clone(),
                reason,
            };
            // A BVH file names every joint on its own line: an empty name, or one with a line
            // break or braces, could not be written back readably.
            let name = joint.name.trim();
            if name.is_empty()
                || name.len() != joint.name.len()
                || joint.name.contains(['\n', '\r', '{', '}'])
            {
                return Err(bad(
                    "joint names must be non-empty, without surrounding spaces, line breaks or braces",
                ));
            }
            match joint.parent {
                None => open.clear(),
                Some(p) => {
                    if p >= i {
                        return Err(bad("its parent does not precede it"));
                    }
                    while open.last().is_some_and(|&top| top != p) {
                        open.pop();
                    }
                    if open.is_empty() {
                        return Err(bad("joints are not in depth-first order"));
                    }
                }
            }
            open.push(i);
            if joint.name.trim().is_empty() || joint.name.contains(['\n', '\r']) {
                return Err(bad("its name is empty or spans lines"));
            }
            if !joint.offset.iter().all(|v| v.is_finite())
                || !joint
                    .end_site
                    .is_none_or(|e| e.iter().all(|v| v.is_finite()))
            {
                return Err(bad("an offset is not finite"));
            }
            for (k, c) in joint.channels.iter().enumerate() {
                if joint.channels[..k].contains(c) {
                    return Err(bad("a channel is listed twice"));
                }
            }
        }
        Ok(())
    }
}

/// A skeleton with sampled channel values: what a BVH file holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    skeleton: Skeleton,
    frame_time: f64,
    frames: usize,
    data: Vec<f64>,
    source: String,
}

impl Motion {
    /// Builds a motion from parts, checking every invariant of the module docs.
    /// `data` is frames x channels, row-major; the frame count is `data.len() / channels`
    /// (`frames` must be given explicitly so a skeleton without channels can have frames).
    pub fn new(
        skeleton: Skeleton,
        frame_time: f64,
        frames: usize,
        data: Vec<f64>,
    ) -> Result<Motion, MotionError> {
        skeleton.validate()?;
        if !(MIN_FRAME_TIME_S..=MAX_FRAME_TIME_S).contains(&frame_time) {
            return Err(MotionError::BadFrameTime(frame_time));
        }
        let channels = skeleton.channel_count();
        let expected = frames.checked_mul(channels);
        if expected != Some(data.len()) {
            return Err(MotionError::DataLength {
                frames,
                channels,
                found: data.len(),
            });
        }
        if let Some(i) = data.iter().position(|v| !v.is_finite()) {
            return Err(MotionError::NonFinite {
                frame: i / channels.max(1),
                channel: i % channels.max(1),
            });
        }
        Ok(Motion {
            skeleton,
            frame_time,
            frames,
            data,
            source: String::from("<memory>"),
        })
    }

    /// The same motion with a display name for messages (usually the file path).
    pub fn with_source(mut self, source: impl Into<String>) -> Motion {
        self.source = source.into();
        self
    }

    /// The name used in messages: the path it was read from, or `<memory>`.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The joint hierarchy.
    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// Seconds per frame (> 0).
    pub fn frame_time(&self) -> f64 {
        self.frame_time
    }

    /// Frames per second.
    pub fn fps(&self) -> f64 {
        1.0 / self.frame_time
    }

    /// Number of frames.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Duration in seconds (`frames * frame_time`).
    pub fn duration(&self) -> f64 {
        self.frames as f64 * self.frame_time
    }

    /// Values per frame.
    pub fn channel_count(&self) -> usize {
        self.skeleton.channel_count()
    }

    /// All samples, frames x channels, row-major.
    pub fn data(&self) -> &[f64] {
        &self.data
    }

    /// The channel values of frame `f`; `None` if `f >= frames()`.
    pub fn frame(&self, f: usize) -> Option<&[f64]> {
        let n = self.channel_count();
        if f >= self.frames {
            return None;
        }
        self.data.get(f * n..(f + 1) * n)
    }

    /// Iterates over the frames in order (each item has `channel_count()` values).
    pub fn frame_rows(&self) -> impl Iterator<Item = &[f64]> + '_ {
        let n = self.channel_count();
        (0..self.frames).map(move |f| &self.data[f * n..(f + 1) * n])
    }

    /// Value of `channel` of joint `joint` at frame `f`; `None` if any index is out of range
    /// or the joint has no such channel.
    pub fn value(&self, f: usize, joint: usize, channel: Channel) -> Option<f64> {
        let joints = &self.skeleton.joints;
        let k = joints
            .get(joint)?
            .channels
            .iter()
            .position(|&c| c == channel)?;
        let start: usize = joints[..joint].iter().map(|j| j.channels.len()).sum();
        self.frame(f)?.get(start + k).copied()
    }

    /// Frames `from..to` (clamped) as a motion of their own; `None` if that is empty.
    pub fn slice(&self, from: usize, to: usize) -> Option<Motion> {
        let to = to.min(self.frames);
        if from >= to {
            return None;
        }
        let n = self.skeleton.channel_count();
        let mut m = self.clone();
        m.data = self.data[from * n..to * n].to_vec();
        m.frames = to - from;
        Some(m)
    }

    /// Takes the motion apart: skeleton, frame time, frame count, data.
    pub fn into_parts(self) -> (Skeleton, f64, usize, Vec<f64>) {
        (self.skeleton, self.frame_time, self.frames, self.data)
    }
}

/// Why [`Motion::new`] refused its parts.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MotionError {
    /// The skeleton breaks an invariant.
    #[error("invalid skeleton at joint `{joint}`: {reason}")]
    InvalidSkeleton {
        /// The offending joint's name.
        joint: String,
        /// What is wrong.
        reason: &'static str,
    },
    /// The frame time is not between 0.001 and 1 s.
    #[error(
        "frame time must be between 0.001 and 1 seconds (1 to 1000 frames per second), got {0}"
    )]
    BadFrameTime(f64),
    /// `data.len()` is not `frames * channels`.
    #[error("{frames} frames x {channels} channels needs that many values, got {found}")]
    DataLength {
        /// Declared frames.
        frames: usize,
        /// Channels per frame.
        channels: usize,
        /// Values given.
        found: usize,
    },
    /// A sample is NaN or infinite.
    #[error("frame {frame}, channel {channel} is not finite")]
    NonFinite {
        /// Frame index.
        frame: usize,
        /// Channel index within the frame.
        channel: usize,
    },
}
