//! Writing policy blobs (docs/blob-format.md): owned mirrors of the runtime's payload sections,
//! typed constructors that lay out and quantize the tables, and the serializer (header +
//! postcard) with an atomic file write.
//!
//! The wire structs live in `gesture_runtime::blob`; [`OwnedPayload::payload`] borrows the
//! owned vectors into them, so the trainer and the device share one definition of the format.
//! [`encode`] checks its output with the runtime's own [`Blob::parse`] before returning it, so
//! a blob that leaves the trainer is one the device accepts (a violation is a packer bug,
//! reported as [`BlobWriteError::Invalid`] with the runtime's typed error).

use std::io::Write;
use std::path::{Path, PathBuf};

use gesture_runtime::blob::{
    calibration_record, gmm_record, Blob, BlobError, Drive, DriveMode, FrontEndSection, Header,
    I16Section, InferenceSection, LibrarySection, Payload, PolicySection, RigSection,
    SkeletonSection, NO_STROKE, ROOT_PARENT,
};
use gesture_runtime::inference::GmmComponent;
use gesture_runtime::prosody::ProsodyConfig;
use gesture_runtime::rig::ChannelCal;

use crate::inference::quantize::{QTable, QuantizedInference};
use crate::motion::{Channel, Skeleton};
use crate::rig::{AngleMode, BoundRig};

/// Why a blob could not be built or written.
#[derive(Debug, thiserror::Error)]
pub enum BlobWriteError {
    /// A dimension or index does not fit its field's type.
    #[error(
        "{what} = {value} does not fit the blob's {ty} field (use a smaller model, library or rig)"
    )]
    TooLarge {
        /// What overflowed.
        what: &'static str,
        /// Its value.
        value: usize,
        /// The field's type.
        ty: &'static str,
    },
    /// Inputs that disagree with each other (lengths, non-finite values).
    #[error("{0}")]
    Inconsistent(String),
    /// postcard refused to serialize (should not happen for these types).
    #[error("cannot encode the payload: {0}")]
    Encode(postcard::Error),
    /// The encoded blob breaks a rule of docs/blob-format.md.
    #[error("the packed blob would be refused by the runtime: {0}")]
    Invalid(BlobError),
    /// Writing the file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

fn fit<T: TryFrom<usize>>(
    what: &'static str,
    value: usize,
    ty: &'static str,
) -> Result<T, BlobWriteError> {
    T::try_from(value).map_err(|_| BlobWriteError::TooLarge { what, value, ty })
}

fn inconsistent<T>(msg: impl Into<String>) -> Result<T, BlobWriteError> {
    Err(BlobWriteError::Inconsistent(msg.into()))
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
    /// From the quantized inference layer.
    pub fn new(q: &QuantizedInference) -> Result<Self, BlobWriteError> {
        Ok(Self {
            states: fit("states", q.states, "u8")?,
            clusters: fit("clusters", q.gmm.len(), "u8")?,
            window: fit("window", q.window, "u8")?,
            gmm: gmm_bytes(&q.gmm),
            crf_init: q.init.clone(),
            crf_trans: q.trans.clone(),
            crf_obs: q.obs.clone(),
        })
    }
}

/// The GMM records of `comps`, back to back.
pub fn gmm_bytes(comps: &[GmmComponent]) -> Vec<u8> {
    comps.iter().flat_map(gmm_record).collect()
}

/// Inputs of [`OwnedPolicy::new`].
#[derive(Clone, Copy, Debug)]
pub struct PolicyInput<'a> {
    /// Hidden states S.
    pub states: usize,
    /// Library segments.
    pub segments: usize,
    /// Discount of the value iteration.
    pub discount: f64,
    /// U, segments x S, segment-major.
    pub u: &'a QTable,
    /// U_cont, exit points x S, exit-major.
    pub u_cont: &'a QTable,
    /// Exit points `(segment, frame within the segment)`, sorted by (segment, frame); every
    /// segment's last frame is one.
    pub exits: &'a [(usize, usize)],
    /// Per exit point, its successors `(segment, quantized cost)`, sorted by segment.
    pub successors: &'a [Vec<(usize, i16)>],
    /// Cost = quantized cost x this.
    pub succ_cost_scale: f32,
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
    /// Lays out the policy tables (checks that every number fits its field; the rules of
    /// docs/blob-format.md are checked by [`encode`]).
    pub fn new(p: &PolicyInput<'_>) -> Result<Self, BlobWriteError> {
        if p.successors.len() != p.exits.len() {
            return inconsistent(format!(
                "{} successor lists for {} exit points",
                p.successors.len(),
                p.exits.len()
            ));
        }
        let mut exits = Vec::with_capacity(4 * p.exits.len());
        for &(seg, frame) in p.exits {
            exits.extend(fit::<u16>("exit segment", seg, "u16")?.to_le_bytes());
            exits.extend(fit::<u16>("exit frame", frame, "u16")?.to_le_bytes());
        }
        let mut succ_offsets = Vec::with_capacity(4 * (p.exits.len() + 1));
        let mut succ = Vec::new();
        let mut n = 0usize;
        succ_offsets.extend(0u32.to_le_bytes());
        for list in p.successors {
            for &(seg, cost) in list {
                succ.extend(fit::<u16>("successor segment", seg, "u16")?.to_le_bytes());
                succ.extend(cost.to_le_bytes());
            }
            n += list.len();
            succ_offsets.extend(fit::<u32>("successor entries", n, "u32")?.to_le_bytes());
        }
        Ok(Self {
            states: fit("policy states", p.states, "u8")?,
            segments: fit("policy segments", p.segments, "u16")?,
            exit_points: fit("exit points", p.exits.len(), "u16")?,
            discount: p.discount as f32,
            u: p.u.clone(),
            u_cont: p.u_cont.clone(),
            exits,
            succ_offsets,
            succ,
            succ_cost_scale: p.succ_cost_scale,
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
}

impl OwnedLibrary {
    /// Quantizes `frames` (one `Vec` of channel values in degrees per frame, all of length
    /// `channels`) per channel to `i16` around the channel's mid-range (rounding error at most
    /// half a step, range / 65534), and lays out `segments`.
    pub fn new(
        fps: f64,
        channels: usize,
        frames: &[Vec<f32>],
        segments: &[SegmentSpec],
    ) -> Result<Self, BlobWriteError> {
        if let Some((i, f)) = frames.iter().enumerate().find(|(_, f)| f.len() != channels) {
            return inconsistent(format!(
                "library frame {i} has {} values for {channels} channels",
                f.len()
            ));
        }
        let mut frame_scales = Vec::with_capacity(8 * channels);
        let mut q = vec![0i16; frames.len() * channels];
        for ch in 0..channels {
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for (i, f) in frames.iter().enumerate() {
                let v = f[ch] as f64;
                if !v.is_finite() {
                    return inconsistent(format!("library frame {i}, channel {ch} is {v}"));
                }
                lo = lo.min(v);
                hi = hi.max(v);
            }
            if frames.is_empty() {
                (lo, hi) = (0.0, 0.0);
            }
            let offset = ((lo + hi) / 2.0) as f32;
            let half = (hi - lo) / 2.0;
            let scale = if half > 0.0 { half / 32767.0 } else { 1.0 } as f32;
            frame_scales.extend(scale.to_le_bytes());
            frame_scales.extend(offset.to_le_bytes());
            for (i, f) in frames.iter().enumerate() {
                let x = (f[ch] as f64 - offset as f64) / scale as f64;
                q[i * channels + ch] = x.round().clamp(-32767.0, 32767.0) as i16;
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
                Some(k) => return inconsistent(format!("stroke frame {k} does not fit u16")),
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
    /// A rig of `channels` (name, calibration), PWM period `period_us`.
    pub fn new(
        name: &str,
        period_us: f32,
        channels: &[(String, ChannelCal)],
    ) -> Result<Self, BlobWriteError> {
        if let Some((n, _)) = channels.iter().find(|(n, _)| n.contains('\n')) {
            return inconsistent(format!("channel name {n:?} contains a newline"));
        }
        Ok(Self {
            name: name.to_string(),
            period_us,
            calibration: channels
                .iter()
                .flat_map(|(_, c)| calibration_record(c))
                .collect(),
            channel_names: channels
                .iter()
                .map(|(n, _)| n.as_str())
                .collect::<Vec<_>>()
                .join("\n"),
        })
    }
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

/// The blob code of a BVH channel (docs/blob-format.md, `skeleton.channel_codes`).
pub fn channel_code(c: Channel) -> u8 {
    match c {
        Channel::Xposition => 0,
        Channel::Yposition => 1,
        Channel::Zposition => 2,
        Channel::Xrotation => 3,
        Channel::Yrotation => 4,
        Channel::Zrotation => 5,
    }
}

/// What each channel of a bound rig drives, in rig channel order.
pub fn drives_of(bound: &BoundRig) -> Result<Vec<Drive>, BlobWriteError> {
    bound
        .channels()
        .iter()
        .map(|c| {
            let mode = match c.mode {
                AngleMode::Twist => DriveMode::Twist,
                AngleMode::Channel => DriveMode::Channel,
                AngleMode::Euler(o) => DriveMode::Euler([o[0] as u8, o[1] as u8, o[2] as u8]),
            };
            Ok(Drive {
                joint: fit("drive joint", c.joint, "u16")?,
                chain_top: fit("drive chain top", c.chain_top(), "u16")?,
                axis: c.axis.index.min(2) as u8,
                negated: c.axis.negated,
                mode,
            })
        })
        .collect()
}

impl OwnedSkeleton {
    /// The section for `skeleton` with rest pose `rest` (one value per channel of a frame, in
    /// BVH units) and one drive per rig channel.
    pub fn new(
        skeleton: &Skeleton,
        rest: &[f64],
        drives: &[Drive],
    ) -> Result<Self, BlobWriteError> {
        let n = skeleton.channel_count();
        if rest.len() != n {
            return inconsistent(format!(
                "skeleton rest pose has {} values for {n} channels",
                rest.len()
            ));
        }
        if let Some(j) = skeleton.joints.iter().find(|j| j.name.contains('\n')) {
            return inconsistent(format!("joint name {:?} contains a newline", j.name));
        }
        let f32s = |v: &mut Vec<u8>, xs: &[f64]| {
            for &x in xs {
                v.extend((x as f32).to_le_bytes());
            }
        };
        let mut s = Self {
            joints: fit("skeleton joints", skeleton.joints.len(), "u16")?,
            joint_names: skeleton.joint_names().collect::<Vec<_>>().join("\n"),
            parents: Vec::new(),
            offsets: Vec::new(),
            channel_counts: Vec::new(),
            channel_codes: Vec::new(),
            rest: Vec::new(),
            end_sites: Vec::new(),
            drives: drives.iter().flat_map(Drive::record).collect(),
        };
        f32s(&mut s.rest, rest);
        for (k, j) in skeleton.joints.iter().enumerate() {
            let parent = match j.parent {
                Some(p) => fit::<u16>("joint parent", p, "u16")?,
                None => ROOT_PARENT,
            };
            s.parents.extend(parent.to_le_bytes());
            f32s(&mut s.offsets, &j.offset);
            s.channel_counts
                .push(fit("joint channels", j.channels.len(), "u8")?);
            s.channel_codes
                .extend(j.channels.iter().map(|&c| channel_code(c)));
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

/// Everything a blob holds, owned.
#[derive(Clone, Debug, PartialEq)]
pub struct OwnedPayload {
    /// Front-end settings.
    pub front_end: FrontEndSection,
    /// Inference layer.
    pub inference: OwnedInference,
    /// Control layer.
    pub policy: OwnedPolicy,
    /// Gesture library.
    pub library: OwnedLibrary,
    /// Output rig.
    pub rig: OwnedRig,
    /// The library's skeleton (optional, host-side).
    pub skeleton: Option<OwnedSkeleton>,
}

fn section(t: &QTable) -> I16Section<'_> {
    I16Section {
        scale: t.scale,
        bytes: &t.bytes,
    }
}

impl OwnedPayload {
    /// The wire form, borrowing from `self`.
    pub fn payload(&self) -> Payload<'_> {
        let (i, p, l, r) = (&self.inference, &self.policy, &self.library, &self.rig);
        Payload {
            front_end: self.front_end,
            inference: InferenceSection {
                states: i.states,
                clusters: i.clusters,
                window: i.window,
                gmm: &i.gmm,
                crf_init: section(&i.crf_init),
                crf_trans: section(&i.crf_trans),
                crf_obs: section(&i.crf_obs),
            },
            policy: PolicySection {
                states: p.states,
                segments: p.segments,
                exit_points: p.exit_points,
                discount: p.discount,
                u: section(&p.u),
                u_cont: section(&p.u_cont),
                exits: &p.exits,
                succ_offsets: &p.succ_offsets,
                succ: &p.succ,
                succ_cost_scale: p.succ_cost_scale,
            },
            library: LibrarySection {
                channels: l.channels,
                fps: l.fps,
                frames: l.frames,
                segments: l.segments,
                seg_start: &l.seg_start,
                seg_len: &l.seg_len,
                frame_scales: &l.frame_scales,
                frame_values: &l.frame_values,
                strokes: &l.strokes,
                labels: &l.labels,
            },
            rig: RigSection {
                name: &r.name,
                period_us: r.period_us,
                calibration: &r.calibration,
                channel_names: &r.channel_names,
            },
            skeleton: self.skeleton.as_ref().map(OwnedSkeleton::section),
        }
    }

    /// A small valid payload (2 states, 1 cluster, 2 segments of 3 frames, one hobby-servo
    /// channel) for tests and examples.
    pub fn example() -> Self {
        let q = |v: &[i16], scale: f32| QTable {
            bytes: v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            scale,
        };
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
            .map(|&v| vec![v])
            .collect();
        let seg = |start, stroke, label| SegmentSpec {
            start,
            len: 3,
            stroke,
            label,
        };
        // Infallible for these fixed, in-range inputs; checked by the tests.
        let policy = OwnedPolicy::new(&PolicyInput {
            states: 2,
            segments: 2,
            discount: 0.9,
            u: &q(&[10, 20, 30, 40], 0.5),
            u_cont: &q(&[1, 2, 3, 4, 5, 6], 0.25),
            exits: &[(0, 2), (1, 1), (1, 2)],
            successors: &[vec![(0, 5), (1, -5)], vec![], vec![(0, 7), (1, 0)]],
            succ_cost_scale: 0.1,
        });
        let library = OwnedLibrary::new(30.0, 1, &frames, &[seg(0, None, 0), seg(3, Some(1), 2)]);
        let rig = OwnedRig::new("example", 20_000.0, &[("head".into(), ChannelCal::HOBBY)]);
        match (policy, library, rig) {
            (Ok(policy), Ok(library), Ok(rig)) => Self {
                front_end: FrontEndSection::from_config(&ProsodyConfig::DEFAULT),
                inference: OwnedInference {
                    states: 2,
                    clusters: 1,
                    window: 1,
                    gmm: gmm_bytes(&[gmm]),
                    crf_init: q(&[100, -100], 0.01),
                    crf_trans: q(&[1000, 0, 0, 1000], 0.001),
                    crf_obs: q(&[500, -500], 0.002),
                },
                policy,
                library,
                rig,
                skeleton: None,
            },
            _ => unreachable!("the example's fixed tables fit their fields"),
        }
    }
}

/// The blob's bytes: header + postcard payload, checked with the runtime's [`Blob::parse`].
pub fn encode(payload: &Payload<'_>) -> Result<Vec<u8>, BlobWriteError> {
    let body = postcard::to_allocvec(payload).map_err(BlobWriteError::Encode)?;
    let header = Header::for_payload(&body).ok_or(BlobWriteError::TooLarge {
        what: "payload bytes",
        value: body.len(),
        ty: "u32",
    })?;
    let mut out = Vec::with_capacity(body.len() + header.to_bytes().len());
    out.extend_from_slice(&header.to_bytes());
    out.extend_from_slice(&body);
    Blob::parse(&out).map_err(BlobWriteError::Invalid)?;
    Ok(out)
}

/// Encodes `payload` and writes it to `path` atomically: a temporary file in the same folder,
/// flushed to disk, then renamed over `path`, so `path` is never a half-written blob. Returns
/// the blob's size in bytes.
pub fn write_blob(path: &Path, payload: &Payload<'_>) -> Result<usize, BlobWriteError> {
    let bytes = encode(payload)?;
    write_atomic(path, &bytes)?;
    Ok(bytes.len())
}

/// Writes `bytes` to `path` through a temporary sibling file and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), BlobWriteError> {
    let io = |source| BlobWriteError::Io {
        path: path.to_path_buf(),
        source,
    };
    let name = path
        .file_name()
        .ok_or_else(|| io(std::io::Error::other("not a file name")))?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".tmp{}", std::process::id()));
    let tmp = path.with_file_name(tmp_name);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn example_encodes_and_loads() {
        let p = OwnedPayload::example();
        let bytes = encode(&p.payload()).unwrap();
        let b = Blob::parse(&bytes).unwrap();
        assert_eq!(*b.payload(), p.payload());
        assert_eq!((b.states(), b.segments(), b.channels()), (2, 2, 1));
    }
}
