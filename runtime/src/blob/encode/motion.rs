//! The motion sections: the library's frames and segments ([`OwnedLibrary`]), the rig's
//! calibration ([`OwnedRig`]) and the host-side skeleton ([`OwnedSkeleton`]).

use alloc::string::String;
use alloc::vec::Vec;

use super::error::{fit, inconsistent, EncodeError};
use crate::blob::format::ENERGY_SCALE;
use crate::blob::payload::*;
use crate::blob::quantize::quantize_range;
use crate::blob::records::calibration_record;
use crate::blob::skeleton::{BvhChannel, Drive};
use crate::rig::ChannelCal;

/// A library segment for [`OwnedLibrary::new`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SegmentSpec {
    /// Index of its first frame in the frame table.
    pub start: usize,
    /// Length in frames.
    pub len: usize,
    /// Stroke frame within the segment.
    pub stroke: Option<usize>,
    /// Semantic label (0 = none).
    pub label: u8,
    /// The next segment continues this one (its recorded successor, stored right after it).
    pub continues: bool,
}

/// Owned `library` section.
#[derive(Clone, Debug, PartialEq)]
pub struct OwnedLibrary {
    /// Channels.
    pub channels: u16,
    /// Frames per second.
    pub fps: f32,
    /// Frames.
    pub frames: u32,
    /// Segments.
    pub segments: u16,
    /// `u32` per segment.
    pub seg_start: Vec<u8>,
    /// `u16` per segment.
    pub seg_len: Vec<u8>,
    /// `(scale, offset)` `f32` per channel.
    pub frame_scales: Vec<u8>,
    /// `i16` frames x channels.
    pub frame_values: Vec<u8>,
    /// `u16` per segment.
    pub strokes: Vec<u8>,
    /// `u8` per segment.
    pub labels: Vec<u8>,
    /// `u8` per segment.
    pub continues: Vec<u8>,
    /// Beat bitset over the frame table.
    pub beats: Vec<u8>,
    /// Calm bitset over the frame table.
    pub calm: Vec<u8>,
    /// `i8` energy per segment.
    pub energy: Vec<u8>,
    /// Stroke bitset over the frame table.
    pub peaks: Vec<u8>,
    /// Rotation-group records.
    pub groups: Vec<u8>,
}

/// A bitset of `frames` bits (bit `f % 8` of byte `f / 8`) with the bits `set` set (those of
/// no frame ignored, so the padding bits stay 0).
fn frame_bits(frames: usize, set: &[usize]) -> Vec<u8> {
    let mut bits = alloc::vec![0u8; frames.div_ceil(8)];
    for &f in set.iter().filter(|&&f| f < frames) {
        bits[f / 8] |= 1 << (f % 8);
    }
    bits
}

impl OwnedLibrary {
    /// The wire form, borrowing from `self`.
    pub fn section(&self) -> LibrarySection<'_> {
        LibrarySection {
            channels: self.channels,
            fps: self.fps,
            frames: self.frames,
            segments: self.segments,
            seg_start: &self.seg_start,
            seg_len: &self.seg_len,
            frame_scales: &self.frame_scales,
            frame_values: &self.frame_values,
            strokes: &self.strokes,
            labels: &self.labels,
            continues: &self.continues,
            beats: &self.beats,
            calm: &self.calm,
            energy: &self.energy,
            peaks: &self.peaks,
            groups: &self.groups,
        }
    }

    /// The same library with the frames `calm` (indices into the frame table; none by
    /// default) marked calm (the hands slow: where a deferred cut may fall).
    pub fn with_calm(mut self, calm: &[usize]) -> Self {
        self.calm = frame_bits(self.frames as usize, calm);
        self
    }

    /// The same library with the frames `peaks` (indices into the frame table; none by
    /// default) marked as strokes (prominent peaks of the hands' speed).
    pub fn with_peaks(mut self, peaks: &[usize]) -> Self {
        self.peaks = frame_bits(self.frames as usize, peaks);
        self
    }

    /// The same library with each segment's energy (the log of its hands' mean speed over the
    /// library's median frame speed; 0 for all by default, a missing one 0) quantized to an
    /// `i8` in steps of 1/[`ENERGY_SCALE`](crate::blob::ENERGY_SCALE), saturating.
    pub fn with_energy(mut self, energy: &[f32]) -> Self {
        for (q, &e) in self.energy.iter_mut().zip(energy) {
            let v = if e.is_finite() { e * ENERGY_SCALE } else { 0.0 };
            *q = (libm::roundf(v).clamp(-127.0, 127.0) as i8) as u8;
        }
        self
    }

    /// Quantizes `frames` (one `Vec` of channel values in degrees per frame, all of length
    /// `channels`) per channel over its range ([`quantize_range`]: error at most half a step,
    /// range / 65534), and lays out `segments`, the motion `beats` (frame indices) and the
    /// rotation `groups` (first channel, Euler order as an
    /// [`EULER_ORDERS`](crate::blob::EULER_ORDERS) index).
    pub fn new(
        fps: f64,
        channels: usize,
        frames: &[Vec<f32>],
        segments: &[SegmentSpec],
        beats: &[usize],
        groups: &[(usize, u8)],
    ) -> Result<Self, EncodeError> {
        if let Some((i, f)) = frames.iter().enumerate().find(|(_, f)| f.len() != channels) {
            return inconsistent(alloc::format!(
                "library frame {i} has {} values for {channels} channels",
                f.len()
            ));
        }
        for (i, f) in frames.iter().enumerate() {
            if let Some(ch) = f.iter().position(|v| !v.is_finite()) {
                return inconsistent(alloc::format!(
                    "library frame {i}, channel {ch} is {}",
                    f[ch]
                ));
            }
        }
        let mut frame_scales = Vec::with_capacity(8 * channels);
        let mut q = alloc::vec![0i16; frames.len() * channels];
        for ch in 0..channels {
            let t = quantize_range(frames.iter().map(|f| f[ch] as f64));
            frame_scales.extend(t.scale.to_le_bytes());
            frame_scales.extend(t.offset.to_le_bytes());
            for (i, f) in frames.iter().enumerate() {
                q[i * channels + ch] = t.code(f[ch] as f64);
            }
        }
        let mut seg_start = Vec::with_capacity(4 * segments.len());
        let mut seg_len = Vec::with_capacity(2 * segments.len());
        let mut strokes = Vec::with_capacity(2 * segments.len());
        for s in segments {
            seg_start.extend(fit::<u32>("segment start", s.start, "u32")?.to_le_bytes());
            seg_len.extend(fit::<u16>("segment length", s.len, "u16")?.to_le_bytes());
            let stroke = match s.stroke {
                Some(k) if k < NO_STROKE as usize => k as u16,
                Some(k) => {
                    return inconsistent(alloc::format!("stroke frame {k} does not fit u16"))
                }
                None => NO_STROKE,
            };
            strokes.extend(stroke.to_le_bytes());
        }
        Ok(Self {
            channels: fit("channels", channels, "u16")?,
            fps: fps as f32,
            frames: fit("frames", frames.len(), "u32")?,
            segments: fit("segments", segments.len(), "u16")?,
            seg_start,
            seg_len,
            frame_scales,
            frame_values: q.iter().flat_map(|v| v.to_le_bytes()).collect(),
            strokes,
            labels: segments.iter().map(|s| s.label).collect(),
            continues: segments.iter().map(|s| s.continues as u8).collect(),
            beats: frame_bits(frames.len(), beats),
            calm: frame_bits(frames.len(), &[]),
            energy: alloc::vec![0u8; segments.len()],
            peaks: frame_bits(frames.len(), &[]),
            groups: groups
                .iter()
                .map(|&(first, order)| {
                    let [a, b] = fit::<u16>("group channel", first, "u16")?.to_le_bytes();
                    Ok([a, b, order])
                })
                .collect::<Result<Vec<[u8; 3]>, EncodeError>>()?
                .concat(),
        })
    }
}

/// Owned `rig` section.
#[derive(Clone, Debug, PartialEq)]
pub struct OwnedRig {
    /// Rig name.
    pub name: String,
    /// PWM period (us).
    pub period_us: f32,
    /// 28-byte calibration records.
    pub calibration: Vec<u8>,
    /// `'\n'`-separated names.
    pub channel_names: String,
}

impl OwnedRig {
    /// The wire form, borrowing from `self`.
    pub fn section(&self) -> RigSection<'_> {
        RigSection {
            name: &self.name,
            period_us: self.period_us,
            calibration: &self.calibration,
            channel_names: &self.channel_names,
        }
    }

    /// A rig of `channels` (name, calibration), PWM period `period_us`.
    pub fn new(
        name: &str,
        period_us: f32,
        channels: &[(String, ChannelCal)],
    ) -> Result<Self, EncodeError> {
        if let Some((n, _)) = channels.iter().find(|(n, _)| n.contains('\n')) {
            return inconsistent(alloc::format!("channel name {n:?} contains a newline"));
        }
        let mut names = String::new();
        for (k, (n, _)) in channels.iter().enumerate() {
            if k > 0 {
                names.push('\n');
            }
            names.push_str(n);
        }
        Ok(Self {
            name: name.into(),
            period_us,
            calibration: channels
                .iter()
                .flat_map(|(_, c)| calibration_record(c))
                .collect(),
            channel_names: names,
        })
    }
}

/// One joint of a skeleton for [`OwnedSkeleton::new`], in BVH file (depth-first) order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointSpec<'a> {
    /// Name (no newline).
    pub name: &'a str,
    /// Parent joint (an earlier one), `None` for a root.
    pub parent: Option<usize>,
    /// BVH `OFFSET`.
    pub offset: [f64; 3],
    /// BVH channels in `CHANNELS` order.
    pub channels: &'a [BvhChannel],
    /// `End Site` offset.
    pub end_site: Option<[f64; 3]>,
}

/// Owned `skeleton` section (host-side: the device ignores it).
#[derive(Clone, Debug, PartialEq)]
pub struct OwnedSkeleton {
    /// Joints.
    pub joints: u16,
    /// `'\n'`-separated joint names.
    pub joint_names: String,
    /// `u16` parent per joint.
    pub parents: Vec<u8>,
    /// `3 f32` offset per joint.
    pub offsets: Vec<u8>,
    /// `u8` channel count per joint.
    pub channel_counts: Vec<u8>,
    /// `u8` channel code per channel.
    pub channel_codes: Vec<u8>,
    /// `f32` rest value per channel.
    pub rest: Vec<u8>,
    /// End-site records.
    pub end_sites: Vec<u8>,
    /// Drive records, one per rig channel.
    pub drives: Vec<u8>,
}

impl OwnedSkeleton {
    /// The section for `joints` with rest pose `rest` (one value per channel of a frame, in
    /// BVH units) and one drive per rig channel.
    pub fn new(
        joints: &[JointSpec<'_>],
        rest: &[f64],
        drives: &[Drive],
    ) -> Result<Self, EncodeError> {
        let n: usize = joints.iter().map(|j| j.channels.len()).sum();
        if rest.len() != n {
            return inconsistent(alloc::format!(
                "skeleton rest pose has {} values for {n} channels",
                rest.len()
            ));
        }
        if let Some(j) = joints.iter().find(|j| j.name.contains('\n')) {
            return inconsistent(alloc::format!("joint name {:?} contains a newline", j.name));
        }
        let f32s = |v: &mut Vec<u8>, xs: &[f64]| {
            for &x in xs {
                v.extend((x as f32).to_le_bytes());
            }
        };
        let mut s = Self {
            joints: fit("skeleton joints", joints.len(), "u16")?,
            joint_names: String::new(),
            parents: Vec::new(),
            offsets: Vec::new(),
            channel_counts: Vec::new(),
            channel_codes: Vec::new(),
            rest: Vec::new(),
            end_sites: Vec::new(),
            drives: drives.iter().flat_map(Drive::record).collect(),
        };
        f32s(&mut s.rest, rest);
        for (k, j) in joints.iter().enumerate() {
            if k > 0 {
                s.joint_names.push('\n');
            }
            s.joint_names.push_str(j.name);
            let parent = match j.parent {
                Some(p) => fit::<u16>("joint parent", p, "u16")?,
                None => ROOT_PARENT,
            };
            s.parents.extend(parent.to_le_bytes());
            f32s(&mut s.offsets, &j.offset);
            s.channel_counts
                .push(fit("joint channels", j.channels.len(), "u8")?);
            s.channel_codes.extend(j.channels.iter().map(|c| c.code()));
            if let Some(e) = j.end_site {
                s.end_sites
                    .extend(fit::<u16>("end-site joint", k, "u16")?.to_le_bytes());
                f32s(&mut s.end_sites, &e);
            }
        }
        Ok(s)
    }

    /// The wire form, borrowing from `self`.
    pub fn section(&self) -> SkeletonSection<'_> {
        SkeletonSection {
            joints: self.joints,
            joint_names: &self.joint_names,
            parents: &self.parents,
            offsets: &self.offsets,
            channel_counts: &self.channel_counts,
            channel_codes: &self.channel_codes,
            rest: &self.rest,
            end_sites: &self.end_sites,
            drives: &self.drives,
        }
    }
}
