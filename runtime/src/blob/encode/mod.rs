//! Writing policy blobs (feature `encode`, host tools; needs `alloc`): owned sections whose
//! constructors lay out and quantize the tables, and [`encode`], which serializes a
//! [`Payload`] (header + postcard) and checks the result with [`Blob::parse`] before returning
//! it, so a blob that leaves a host tool is one the device accepts (a violation is a packer
//! bug, reported as [`EncodeError::Invalid`] with the reader's typed error).
//!
//! The owned sections borrow into the same wire structs the reader decodes
//! ([`OwnedPayload::payload`]), and every table is quantized by [`Quantization`], so the
//! writer and the reader share one definition of every byte.

use alloc::string::String;
use alloc::vec::Vec;
use core::fmt;

use super::payload::*;
use super::quantize::{quantize_range, quantize_symmetric, Quantization};
use super::records::{calibration_record, gmm_from_record, gmm_record};
use super::skeleton::{BvhChannel, Drive};
use super::{Blob, BlobError, Header};
use crate::controller::DecisionTiming;
use crate::follow::VoiceFollow;
use crate::inference::{CrfWeights, GmmComponent, I16Table};
use crate::policy::Variety;
use crate::prosody::ProsodyConfig;
use crate::rig::ChannelCal;

/// Why a blob could not be built.
#[derive(Clone, Debug, PartialEq)]
pub enum EncodeError {
    /// A dimension or index does not fit its field's type.
    TooLarge {
        /// What overflowed.
        what: &'static str,
        /// Its value.
        value: usize,
        /// The field's type.
        ty: &'static str,
    },
    /// Inputs that disagree with each other (lengths, non-finite values).
    Inconsistent(String),
    /// postcard refused to serialize (does not happen for these types).
    Encode,
    /// The encoded blob breaks a rule of the format.
    Invalid(BlobError),
}

impl fmt::Display for EncodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TooLarge { what, value, ty } => write!(
                f,
                "{what} = {value} does not fit the blob's {ty} field (use a smaller model, \
                 library or rig)"
            ),
            Self::Inconsistent(m) => f.write_str(m),
            Self::Encode => f.write_str("cannot encode the payload"),
            Self::Invalid(e) => write!(f, "the packed blob would be refused by the runtime: {e}"),
        }
    }
}

impl core::error::Error for EncodeError {}

fn fit<T: TryFrom<usize>>(
    what: &'static str,
    value: usize,
    ty: &'static str,
) -> Result<T, EncodeError> {
    T::try_from(value).map_err(|_| EncodeError::TooLarge { what, value, ty })
}

/// `{index: u16, cost: i16}` records of `rows`, the costs quantized together (symmetric over
/// their largest finite magnitude): the quantization and the bytes. `what` names the index for
/// errors.
fn records<'r>(
    rows: impl Iterator<Item = &'r (usize, f64)> + Clone,
    what: &'static str,
) -> Result<(Quantization, Vec<u8>), EncodeError> {
    let max = rows
        .clone()
        .map(|&(_, c)| c)
        .filter(|c| c.is_finite())
        .fold(0.0f64, |m, c| m.max(c.abs()));
    let q = Quantization::symmetric(max);
    let mut out = Vec::new();
    for &(index, cost) in rows {
        out.extend(fit::<u16>(what, index, "u16")?.to_le_bytes());
        out.extend(q.code(cost).to_le_bytes());
    }
    Ok((q, out))
}

fn inconsistent<T>(msg: String) -> Result<T, EncodeError> {
    Err(EncodeError::Inconsistent(msg))
}

/// An owned scaled `i16` table (`I16Section`).
#[derive(Clone, Debug, PartialEq)]
pub struct QTable {
    /// `2 * len` little-endian bytes.
    pub bytes: Vec<u8>,
    /// Value = `i16 * scale`.
    pub scale: f32,
}

impl QTable {
    /// Quantizes `w` symmetrically ([`quantize_symmetric`]).
    pub fn quantize(w: &[f64]) -> Self {
        let mut q = alloc::vec![0i16; w.len()];
        let scale = quantize_symmetric(w, &mut q);
        Self::from_codes(&q, scale)
    }

    /// A table of given codes and scale.
    pub fn from_codes(codes: &[i16], scale: f32) -> Self {
        Self {
            bytes: codes.iter().flat_map(|v| v.to_le_bytes()).collect(),
            scale,
        }
    }

    /// The runtime view of the table.
    pub fn view(&self) -> Option<I16Table<'_>> {
        I16Table::new(&self.bytes, self.scale, self.bytes.len() / 2)
    }

    /// The wire form, borrowing from `self`.
    pub fn section(&self) -> I16Section<'_> {
        I16Section {
            scale: self.scale,
            bytes: &self.bytes,
        }
    }
}

/// Owned `inference` section.
#[derive(Clone, Debug, PartialEq)]
pub struct OwnedInference {
    /// States S.
    pub states: u8,
    /// Clusters K.
    pub clusters: u8,
    /// Window W.
    pub window: u8,
    /// K GMM records.
    pub gmm: Vec<u8>,
    /// CRF initial weights.
    pub crf_init: QTable,
    /// CRF transition weights.
    pub crf_trans: QTable,
    /// CRF observation weights.
    pub crf_obs: QTable,
}

impl OwnedInference {
    /// The wire form, borrowing from `self`.
    pub fn section(&self) -> InferenceSection<'_> {
        InferenceSection {
            states: self.states,
            clusters: self.clusters,
            window: self.window,
            gmm: &self.gmm,
            crf_init: self.crf_init.section(),
            crf_trans: self.crf_trans.section(),
            crf_obs: self.crf_obs.section(),
        }
    }

    /// The section for GMM components `gmm` and CRF weights in nats (`init`: S, `trans`:
    /// S x S from-major, `obs`: S x W x K), quantized symmetrically per table.
    pub fn new(
        gmm: &[GmmComponent],
        window: usize,
        init: &[f64],
        trans: &[f64],
        obs: &[f64],
    ) -> Result<Self, EncodeError> {
        let s = init.len();
        if trans.len() != s * s || obs.len() != s * window * gmm.len() {
            return inconsistent(alloc::format!(
                "CRF tables of {} / {} / {} weights for S = {s}, W = {window}, K = {}",
                init.len(),
                trans.len(),
                obs.len(),
                gmm.len()
            ));
        }
        Ok(Self {
            states: fit("states", s, "u8")?,
            clusters: fit("clusters", gmm.len(), "u8")?,
            window: fit("window", window, "u8")?,
            gmm: gmm.iter().flat_map(gmm_record).collect(),
            crf_init: QTable::quantize(init),
            crf_trans: QTable::quantize(trans),
            crf_obs: QTable::quantize(obs),
        })
    }

    /// The GMM components as the device decodes them.
    pub fn components(&self) -> Vec<GmmComponent> {
        self.gmm
            .chunks_exact(GMM_RECORD_BYTES)
            .filter_map(|r| r.first_chunk::<GMM_RECORD_BYTES>())
            .map(gmm_from_record)
            .collect()
    }

    /// The quantized CRF weights as the device reads them (`None` only if the dimensions
    /// exceed the runtime's capacities).
    pub fn crf_weights(&self) -> Option<CrfWeights<'_>> {
        CrfWeights::new(
            self.states as usize,
            self.clusters as usize,
            self.window as usize,
            self.crf_init.view()?,
            self.crf_trans.view()?,
            self.crf_obs.view()?,
        )
    }
}

/// Inputs of [`OwnedPolicy::new`], in float: the quantization happens there.
#[derive(Clone, Copy, Debug)]
pub struct PolicyInput<'a> {
    /// Hidden states S.
    pub states: usize,
    /// Library segments.
    pub segments: usize,
    /// Discount of the value iteration.
    pub discount: f64,
    /// U, segments x S, segment-major.
    pub u: &'a [f64],
    /// U_cont, exit points x S, exit-major (any value at end exits; never read).
    pub u_cont: &'a [f64],
    /// Exit points `(segment, frame within the segment)`, sorted by (segment, frame); every
    /// segment's last frame is one.
    pub exits: &'a [(usize, usize)],
    /// Per exit point, its successors `(segment, cost)`, sorted by segment.
    pub successors: &'a [Vec<(usize, f64)>],
}

/// Owned `policy` section.
#[derive(Clone, Debug, PartialEq)]
pub struct OwnedPolicy {
    /// States S.
    pub states: u8,
    /// Segments.
    pub segments: u16,
    /// Exit points.
    pub exit_points: u16,
    /// Discount.
    pub discount: f32,
    /// U.
    pub u: QTable,
    /// U_cont.
    pub u_cont: QTable,
    /// Exit records.
    pub exits: Vec<u8>,
    /// Successor offsets.
    pub succ_offsets: Vec<u8>,
    /// Successor records.
    pub succ: Vec<u8>,
    /// Successor cost scale.
    pub succ_cost_scale: f32,
}

impl OwnedPolicy {
    /// The wire form, borrowing from `self`.
    pub fn section(&self) -> PolicySection<'_> {
        PolicySection {
            states: self.states,
            segments: self.segments,
            exit_points: self.exit_points,
            discount: self.discount,
            u: self.u.section(),
            u_cont: self.u_cont.section(),
            exits: &self.exits,
            succ_offsets: &self.succ_offsets,
            succ: &self.succ,
            succ_cost_scale: self.succ_cost_scale,
        }
    }

    /// Quantizes and lays out the policy tables (checks that every number fits its field;
    /// the rules of the format are checked by [`encode`]).
    pub fn new(p: &PolicyInput<'_>) -> Result<Self, EncodeError> {
        if p.successors.len() != p.exits.len() {
            return inconsistent(alloc::format!(
                "{} successor lists for {} exit points",
                p.successors.len(),
                p.exits.len()
            ));
        }
        if p.u.len() != p.segments * p.states || p.u_cont.len() != p.exits.len() * p.states {
            return inconsistent(alloc::format!(
                "value tables of {} and {} entries for {} segments, {} exits, {} states",
                p.u.len(),
                p.u_cont.len(),
                p.segments,
                p.exits.len(),
                p.states
            ));
        }
        let mut exits = Vec::with_capacity(4 * p.exits.len());
        for &(seg, frame) in p.exits {
            exits.extend(fit::<u16>("exit segment", seg, "u16")?.to_le_bytes());
            exits.extend(fit::<u16>("exit frame", frame, "u16")?.to_le_bytes());
        }
        let (q, succ) = records(p.successors.iter().flatten(), "successor segment")?;
        let mut succ_offsets = Vec::with_capacity(4 * (p.exits.len() + 1));
        let mut n = 0usize;
        succ_offsets.extend(0u32.to_le_bytes());
        for list in p.successors {
            n += list.len();
            succ_offsets.extend(fit::<u32>("successor entries", n, "u32")?.to_le_bytes());
        }
        Ok(Self {
            states: fit("policy states", p.states, "u8")?,
            segments: fit("policy segments", p.segments, "u16")?,
            exit_points: fit("exit points", p.exits.len(), "u16")?,
            discount: p.discount as f32,
            u: QTable::quantize(p.u),
            u_cont: QTable::quantize(p.u_cont),
            exits,
            succ_offsets,
            succ,
            succ_cost_scale: q.scale,
        })
    }
}

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
            groups: &self.groups,
        }
    }

    /// The same library with the frames `calm` (indices into the frame table; none by
    /// default) marked calm (the hands slow: where a deferred cut may fall).
    pub fn with_calm(mut self, calm: &[usize]) -> Self {
        self.calm = frame_bits(self.frames as usize, calm);
        self
    }

    /// The same library with each segment's energy (the log of its hands' mean speed over the
    /// library's median frame speed; 0 for all by default, a missing one 0) quantized to an
    /// `i8` in steps of 1/[`ENERGY_SCALE`](super::ENERGY_SCALE), saturating.
    pub fn with_energy(mut self, energy: &[f32]) -> Self {
        for (q, &e) in self.energy.iter_mut().zip(energy) {
            let v = if e.is_finite() {
                e * super::ENERGY_SCALE
            } else {
                0.0
            };
            *q = (libm::roundf(v).clamp(-127.0, 127.0) as i8) as u8;
        }
        self
    }

    /// Quantizes `frames` (one `Vec` of channel values in degrees per frame, all of length
    /// `channels`) per channel over its range ([`quantize_range`]: error at most half a step,
    /// range / 65534), and lays out `segments`, the motion `beats` (frame indices) and the
    /// rotation `groups` (first channel, Euler order as an
    /// [`EULER_ORDERS`](super::EULER_ORDERS) index).
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

/// Owned `styles` section: one pair of value tables per tone (docs/blob-format.md).
#[derive(Clone, Debug, PartialEq)]
pub struct OwnedStyles {
    /// Tones M.
    pub tones: u8,
    /// Names joined by `'\n'`.
    pub names: String,
    /// U of every tone (M x segments x S), one scale for all tones.
    pub u: QTable,
    /// U_cont of every tone (M x exit points x S).
    pub u_cont: QTable,
}

impl OwnedStyles {
    /// The section for tones named `names`, tone `m` having `u[m]` (segments x S,
    /// segment-major) and `u_cont[m]` (exit points x S; any value at end exits). The tables are
    /// quantized together, one scale for all tones, so a mix of tones is the mix of their
    /// stored codes. Names must not contain `'\n'`; the other rules are checked by [`encode`].
    pub fn new(names: &[&str], u: &[Vec<f64>], u_cont: &[Vec<f64>]) -> Result<Self, EncodeError> {
        if u.len() != names.len() || u_cont.len() != names.len() {
            return inconsistent(alloc::format!(
                "{} tone names for {} U and {} U_cont tables",
                names.len(),
                u.len(),
                u_cont.len()
            ));
        }
        if let Some(n) = names.iter().find(|n| n.contains('\n')) {
            return inconsistent(alloc::format!("tone name {n:?} contains a line break"));
        }
        let flat_u: Vec<f64> = u.iter().flatten().copied().collect();
        let flat_uc: Vec<f64> = u_cont.iter().flatten().copied().collect();
        Ok(Self {
            tones: fit("tones", names.len(), "u8")?,
            names: names.join("\n"),
            u: QTable::quantize(&flat_u),
            u_cont: QTable::quantize(&flat_uc),
        })
    }

    /// The wire form, borrowing from `self`.
    pub fn section(&self) -> StylesSection<'_> {
        StylesSection {
            tones: self.tones,
            names: &self.names,
            u: self.u.section(),
            u_cont: self.u_cont.section(),
        }
    }
}

/// Inputs of [`OwnedLabels::new`], in float.
#[derive(Clone, Copy, Debug)]
pub struct LabelsInput<'a> {
    /// Label names (label `w` is `library.labels` value `w + 1`).
    pub names: &'a [&'a str],
    /// Cost added to candidates that do not carry the waiting label.
    pub semantic_cost: f64,
    /// A label not shown within this long is dropped (ms).
    pub timeout_ms: u32,
    /// The labelled segments, increasing.
    pub segments: &'a [usize],
    /// Per label, U^w (segments x S, segment-major).
    pub u: &'a [Vec<f64>],
    /// Per label, U_cont^w (exit points x S).
    pub u_cont: &'a [Vec<f64>],
    /// Per exit point, per labelled segment: `(entry frame, cost)`.
    pub entries: &'a [Vec<(usize, f64)>],
}

/// Owned `labels` section.
#[derive(Clone, Debug, PartialEq)]
pub struct OwnedLabels {
    /// Labels L.
    pub labels: u8,
    /// Names joined by `'\n'`.
    pub names: String,
    /// Semantic cost.
    pub semantic_cost: f32,
    /// Timeout (ms).
    pub timeout_ms: u16,
    /// `u16` per labelled segment.
    pub segments: Vec<u8>,
    /// U^w of every label, one scale.
    pub u: QTable,
    /// U_cont^w of every label.
    pub u_cont: QTable,
    /// Entry records.
    pub entries: Vec<u8>,
    /// Entry cost scale.
    pub entry_cost_scale: f32,
}

impl OwnedLabels {
    /// Quantizes and lays out the labels section (the format's rules are checked by
    /// [`encode`]).
    pub fn new(p: &LabelsInput<'_>) -> Result<Self, EncodeError> {
        let l = p.names.len();
        if p.u.len() != l || p.u_cont.len() != l {
            return inconsistent(alloc::format!(
                "{l} label names for {} U and {} U_cont tables",
                p.u.len(),
                p.u_cont.len()
            ));
        }
        if let Some(n) = p.names.iter().find(|n| n.contains('\n')) {
            return inconsistent(alloc::format!("label name {n:?} contains a line break"));
        }
        if let Some(r) = p.entries.iter().find(|r| r.len() != p.segments.len()) {
            return inconsistent(alloc::format!(
                "{} entries for {} labelled segments",
                r.len(),
                p.segments.len()
            ));
        }
        let mut segments = Vec::with_capacity(2 * p.segments.len());
        for &c in p.segments {
            segments.extend(fit::<u16>("labelled segment", c, "u16")?.to_le_bytes());
        }
        let (q, entries) = records(p.entries.iter().flatten(), "entry frame")?;
        let flat_u: Vec<f64> = p.u.iter().flatten().copied().collect();
        let flat_uc: Vec<f64> = p.u_cont.iter().flatten().copied().collect();
        Ok(Self {
            labels: fit("labels", l, "u8")?,
            names: p.names.join("\n"),
            semantic_cost: p.semantic_cost as f32,
            timeout_ms: fit("label timeout (ms)", p.timeout_ms as usize, "u16")?,
            segments,
            u: QTable::quantize(&flat_u),
            u_cont: QTable::quantize(&flat_uc),
            entries,
            entry_cost_scale: q.scale,
        })
    }

    /// The wire form, borrowing from `self`.
    pub fn section(&self) -> LabelsSection<'_> {
        LabelsSection {
            labels: self.labels,
            names: &self.names,
            semantic_cost: self.semantic_cost,
            timeout_ms: self.timeout_ms,
            segments: &self.segments,
            u: self.u.section(),
            u_cont: self.u_cont.section(),
            entries: &self.entries,
            entry_cost_scale: self.entry_cost_scale,
        }
    }
}

/// Everything a blob holds, owned.
#[derive(Clone, Debug, PartialEq)]
pub struct OwnedPayload {
    /// Front-end settings.
    pub front_end: FrontEndSection,
    /// Inference layer.
    pub inference: OwnedInference,
    /// Control layer.
    pub policy: OwnedPolicy,
    /// Controller settings.
    pub control: ControlSection,
    /// Gesture library.
    pub library: OwnedLibrary,
    /// Output rig.
    pub rig: OwnedRig,
    /// The library's skeleton (optional, host-side).
    pub skeleton: Option<OwnedSkeleton>,
    /// Tones (optional).
    pub styles: Option<OwnedStyles>,
    /// Semantic labels (optional).
    pub labels: Option<OwnedLabels>,
}

impl OwnedPayload {
    /// The wire form, borrowing from `self`.
    pub fn payload(&self) -> Payload<'_> {
        Payload {
            front_end: self.front_end,
            inference: self.inference.section(),
            policy: self.policy.section(),
            control: self.control,
            library: self.library.section(),
            rig: self.rig.section(),
            skeleton: self.skeleton.as_ref().map(OwnedSkeleton::section),
            styles: self.styles.as_ref().map(OwnedStyles::section),
            labels: self.labels.as_ref().map(OwnedLabels::section),
        }
    }

    /// The blob's bytes ([`encode`] of [`payload`](Self::payload)).
    pub fn encode(&self) -> Result<Vec<u8>, EncodeError> {
        encode(&self.payload())
    }

    /// A small valid payload (2 states, 1 cluster, 2 segments of 3 frames, one hobby-servo
    /// channel) for tests and examples.
    pub fn example() -> Self {
        let gmm = GmmComponent {
            log_voiced: -0.5,
            log_unvoiced: -1.0,
            inv_chol: [1.0, 0.0, 1.0],
            log_norm: -1.8,
            inv_sd: 2.0,
            ..GmmComponent::default()
        };
        let frames: Vec<Vec<f32>> = [0.0, 10.0, 20.0, 20.0, 0.0, -20.0]
            .iter()
            .map(|&v| alloc::vec![v])
            .collect();
        let seg = |start, stroke, label| SegmentSpec {
            start,
            len: 3,
            stroke,
            label,
            continues: false,
        };
        let policy = OwnedPolicy::new(&PolicyInput {
            states: 2,
            segments: 2,
            discount: 0.9,
            u: &[5.0, 10.0, 15.0, 20.0],
            u_cont: &[0.25, 0.5, 0.75, 1.0, 1.25, 1.5],
            exits: &[(0, 2), (1, 1), (1, 2)],
            successors: &[
                alloc::vec![(0, 0.5), (1, -0.5)],
                alloc::vec![],
                alloc::vec![(0, 0.7), (1, 0.0)],
            ],
        });
        let inference =
            OwnedInference::new(&[gmm], 1, &[1.0, -1.0], &[1.0, 0.0, 0.0, 1.0], &[1.0, -1.0]);
        let library = OwnedLibrary::new(
            30.0,
            1,
            &frames,
            &[seg(0, None, 0), seg(3, Some(1), 2)],
            &[],
            &[],
        );
        let rig = OwnedRig::new("example", 20_000.0, &[("head".into(), ChannelCal::HOBBY)]);
        match (inference, policy, library, rig) {
            (Ok(inference), Ok(policy), Ok(library), Ok(rig)) => Self {
                front_end: FrontEndSection::from_config(&ProsodyConfig::DEFAULT),
                inference,
                policy,
                control: ControlSection::new(
                    &DecisionTiming::DEFAULT,
                    &Variety::NONE,
                    &VoiceFollow::NONE,
                    0,
                ),
                library,
                rig,
                skeleton: None,
                styles: None,
                labels: None,
            },
            _ => unreachable!("the example's fixed tables fit their fields"),
        }
    }
}

/// The blob's bytes: header + postcard payload, checked with the runtime's [`Blob::parse`].
pub fn encode(payload: &Payload<'_>) -> Result<Vec<u8>, EncodeError> {
    let body = postcard::to_allocvec(payload).map_err(|_| EncodeError::Encode)?;
    let header = Header::for_payload(&body).ok_or(EncodeError::TooLarge {
        what: "payload bytes",
        value: body.len(),
        ty: "u32",
    })?;
    let mut out = Vec::with_capacity(body.len() + 16);
    out.extend_from_slice(&header.to_bytes());
    out.extend_from_slice(&body);
    Blob::parse(&out).map_err(EncodeError::Invalid)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn example_encodes_and_loads() {
        let p = OwnedPayload::example();
        let bytes = p.encode().unwrap();
        let b = Blob::parse(&bytes).unwrap();
        assert_eq!(*b.payload(), p.payload());
        assert_eq!((b.states(), b.segments(), b.channels()), (2, 2, 1));
        // Quantized values come back within half a step.
        assert!((b.u(1, 1) - 20.0).abs() <= 0.5 * 20.0 / 32767.0 + 1e-6);
        let s = b.successor(0, 1).unwrap();
        assert!((s.cost + 0.5).abs() < 1e-4);
    }
}
