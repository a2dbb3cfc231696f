//! The tiny hand-built blob the blob tests share: every table written byte by byte here,
//! independently of the runtime's encoder, so the tests check the format, not the writer.
#![allow(dead_code)]

use gesture_runtime::blob::*;
use gesture_runtime::inference::GmmComponent;
use gesture_runtime::prosody::ProsodyConfig;
use gesture_runtime::rig::ChannelCal;

pub fn le_i16(v: &[i16]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}
pub fn le_u16(v: &[u16]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}
pub fn le_u32(v: &[u32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}
pub fn le_f32(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

pub const GMM0: GmmComponent = GmmComponent {
    log_voiced: -0.5,
    log_unvoiced: -1.0,
    mean: [0.25, -1.5],
    inv_chol: [2.0, 0.5, 4.0],
    log_norm: -1.25,
    coef: [0.125, 0.5, -0.25],
    inv_sd: 8.0,
    log_norm_f0: 1.5,
};

/// The owned tables of the tiny blob; `payload()` borrows them. Tests change a field, then
/// encode with a correct header so the change reaches the validator.
#[derive(Clone)]
pub struct Tiny {
    pub front_end: FrontEndSection,
    pub states: u8,
    pub clusters: u8,
    pub window: u8,
    pub gmm: Vec<u8>,
    pub init: (f32, Vec<u8>),
    pub trans: (f32, Vec<u8>),
    pub obs: (f32, Vec<u8>),
    pub p_states: u8,
    pub p_segments: u16,
    pub exit_points: u16,
    pub discount: f32,
    pub u: (f32, Vec<u8>),
    pub u_cont: (f32, Vec<u8>),
    pub exits: Vec<u8>,
    pub succ_offsets: Vec<u8>,
    pub succ: Vec<u8>,
    pub succ_scale: f32,
    pub control: ControlSection,
    pub channels: u16,
    pub fps: f32,
    pub frames: u32,
    pub segments: u16,
    pub seg_start: Vec<u8>,
    pub seg_len: Vec<u8>,
    pub frame_scales: Vec<u8>,
    pub frame_values: Vec<u8>,
    pub strokes: Vec<u8>,
    pub labels: Vec<u8>,
    pub continues: Vec<u8>,
    pub beats: Vec<u8>,
    pub calm: Vec<u8>,
    pub energy: Vec<u8>,
    pub peaks: Vec<u8>,
    pub groups: Vec<u8>,
    pub rig_name: String,
    pub period_us: f32,
    pub calibration: Vec<u8>,
    pub channel_names: String,
    pub skeleton: Option<TinySkeleton>,
    /// Tones: count, names, U (scale, bytes), U_cont (scale, bytes).
    pub styles: Option<TinyStyles>,
    /// Semantic labels section.
    pub label_section: Option<TinyLabels>,
}

/// The tiny blob's labels (none by default; [`TinyLabels::one`] gives one on segment 1, whose
/// stroke is frame 1 and whose `library.labels` byte is 2 in the tiny blob, so label names
/// must number two).
#[derive(Clone, Debug)]
pub struct TinyLabels {
    pub labels: u8,
    pub names: String,
    pub semantic_cost: f32,
    pub timeout_ms: u16,
    pub segments: Vec<u8>,
    pub u: (f32, Vec<u8>),
    pub u_cont: (f32, Vec<u8>),
    pub entries: Vec<u8>,
    pub entry_cost_scale: f32,
}

impl TinyLabels {
    /// Labels `hello` and `bye` (segment 1 carries `bye`, stroke frame 1), semantic cost 5,
    /// timeout 2 s; U^w = 1, 2, 3, 4 for both labels (2 segments x 2 states), U_cont^w = 0.5
    /// (3 exits x 2 states); entries from every exit into segment 1 at frame 1, cost 0.25.
    pub fn one() -> Self {
        let u: Vec<u8> = [1i16, 2, 3, 4, 1, 2, 3, 4]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let u_cont: Vec<u8> = [1i16; 12].iter().flat_map(|v| v.to_le_bytes()).collect();
        let entries: Vec<u8> = (0..3).flat_map(|_| [1u8, 0, 1, 0]).collect();
        Self {
            labels: 2,
            names: "hello\nbye".into(),
            semantic_cost: 5.0,
            timeout_ms: 2000,
            segments: vec![1, 0],
            u: (1.0, u),
            u_cont: (0.5, u_cont),
            entries,
            entry_cost_scale: 0.25,
        }
    }

    pub fn section(&self) -> LabelsSection<'_> {
        LabelsSection {
            labels: self.labels,
            names: &self.names,
            semantic_cost: self.semantic_cost,
            timeout_ms: self.timeout_ms,
            segments: &self.segments,
            u: I16Section {
                scale: self.u.0,
                bytes: &self.u.1,
            },
            u_cont: I16Section {
                scale: self.u_cont.0,
                bytes: &self.u_cont.1,
            },
            entries: &self.entries,
            entry_cost_scale: self.entry_cost_scale,
        }
    }
}

/// The tiny blob's tones (none by default; [`TinyStyles::two`] gives two).
#[derive(Clone, Debug)]
pub struct TinyStyles {
    pub tones: u8,
    pub names: String,
    pub u: (f32, Vec<u8>),
    pub u_cont: (f32, Vec<u8>),
}

impl TinyStyles {
    /// Two tones `calm` and `lively` with `u_len` values of U and `u_cont_len` of U_cont
    /// each: U^calm = 1, 2, ..., U^lively the negatives (scale 1); U_cont likewise (scale 0.5).
    pub fn two(u_len: usize, u_cont_len: usize) -> Self {
        let codes = |n: usize| -> Vec<u8> {
            (1..=n as i16)
                .chain((1..=n as i16).map(|v| -v))
                .flat_map(|v| v.to_le_bytes())
                .collect()
        };
        Self {
            tones: 2,
            names: "calm\nlively".into(),
            u: (1.0, codes(u_len)),
            u_cont: (0.5, codes(u_cont_len)),
        }
    }

    pub fn section(&self) -> StylesSection<'_> {
        StylesSection {
            tones: self.tones,
            names: &self.names,
            u: I16Section {
                scale: self.u.0,
                bytes: &self.u.1,
            },
            u_cont: I16Section {
                scale: self.u_cont.0,
                bytes: &self.u_cont.1,
            },
        }
    }
}

/// The tiny blob's skeleton: `hips` (6 channels) with child `head` (3 rotations, an end site);
/// the rig channel `head` reads `head`'s own Yrotation channel.
#[derive(Clone)]
pub struct TinySkeleton {
    pub joints: u16,
    pub joint_names: String,
    pub parents: Vec<u8>,
    pub offsets: Vec<u8>,
    pub channel_counts: Vec<u8>,
    pub channel_codes: Vec<u8>,
    pub rest: Vec<u8>,
    pub end_sites: Vec<u8>,
    pub drives: Vec<u8>,
}

impl TinySkeleton {
    pub fn new() -> Self {
        let mut end_sites = le_u16(&[1]);
        end_sites.extend(le_f32(&[0.0, 5.0, 0.0]));
        Self {
            joints: 2,
            joint_names: "hips\nhead".into(),
            parents: le_u16(&[ROOT_PARENT, 0]),
            offsets: le_f32(&[0.0, 0.0, 0.0, 0.0, 10.0, 0.0]),
            channel_counts: vec![6, 3],
            channel_codes: vec![0, 1, 2, 5, 3, 4, 5, 3, 4],
            rest: le_f32(&[0.0, 90.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
            end_sites,
            drives: Drive {
                joint: 1,
                chain_top: 1,
                axis: 1,
                negated: false,
                mode: DriveMode::Channel,
            }
            .record()
            .to_vec(),
        }
    }

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

impl Tiny {
    /// S=2, K=1, W=1; 2 segments of 3 frames on 1 channel; exits (0,2), (1,1), (1,2).
    pub fn new() -> Self {
        Self {
            front_end: FrontEndSection::from_config(&ProsodyConfig::DEFAULT),
            states: 2,
            clusters: 1,
            window: 1,
            gmm: gmm_record(&GMM0).to_vec(),
            init: (0.01, le_i16(&[100, -100])),
            trans: (0.001, le_i16(&[1000, 0, 0, 1000])),
            obs: (0.002, le_i16(&[500, -500])),
            p_states: 2,
            p_segments: 2,
            exit_points: 3,
            discount: 0.9,
            u: (0.5, le_i16(&[10, 20, 30, 40])),
            u_cont: (0.25, le_i16(&[1, 2, 3, 4, 5, 6])),
            exits: le_u16(&[0, 2, 1, 1, 1, 2]),
            succ_offsets: le_u32(&[0, 2, 2, 4]),
            succ: le_i16(&[0, 5, 1, -5, 0, 7, 1, 0]),
            succ_scale: 0.1,
            control: ControlSection {
                sync_to_onsets: 1,
                onset_window_ms: 50,
                max_wait_ms: 300,
                recency_cost: 1.5,
                recency_ms: 5000,
                usage_cost: 4.0,
                usage_ms: 30000,
                blend_ms: 250,
                beat_hold_ms: 150,
                defer_cut_ms: 200,
                rest_ms: 750,
                rest_cost: 2.5,
                energy_cost: 1.5,
            },
            channels: 1,
            fps: 30.0,
            frames: 6,
            segments: 2,
            seg_start: le_u32(&[0, 3]),
            seg_len: le_u16(&[3, 3]),
            frame_scales: le_f32(&[0.01, 10.0]),
            frame_values: le_i16(&[0, 100, 200, 300, -100, -200]),
            strokes: le_u16(&[NO_STROKE, 1]),
            labels: vec![0, 2],
            continues: vec![1, 0],
            beats: vec![0b0001_0010],
            calm: vec![0b0010_0001],
            energy: vec![(-16i8) as u8, 24],
            peaks: vec![0b0000_0100],
            groups: vec![],
            rig_name: "tiny".into(),
            period_us: 20_000.0,
            calibration: calibration_record(&ChannelCal::HOBBY).to_vec(),
            channel_names: "head".into(),
            skeleton: Some(TinySkeleton::new()),
            styles: None,
            label_section: None,
        }
    }

    pub fn payload(&self) -> Payload<'_> {
        fn t(x: &(f32, Vec<u8>)) -> I16Section<'_> {
            I16Section {
                scale: x.0,
                bytes: &x.1,
            }
        }
        Payload {
            front_end: self.front_end,
            inference: InferenceSection {
                states: self.states,
                clusters: self.clusters,
                window: self.window,
                gmm: &self.gmm,
                crf_init: t(&self.init),
                crf_trans: t(&self.trans),
                crf_obs: t(&self.obs),
            },
            policy: PolicySection {
                states: self.p_states,
                segments: self.p_segments,
                exit_points: self.exit_points,
                discount: self.discount,
                u: t(&self.u),
                u_cont: t(&self.u_cont),
                exits: &self.exits,
                succ_offsets: &self.succ_offsets,
                succ: &self.succ,
                succ_cost_scale: self.succ_scale,
            },
            control: self.control,
            library: LibrarySection {
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
            },
            rig: RigSection {
                name: &self.rig_name,
                period_us: self.period_us,
                calibration: &self.calibration,
                channel_names: &self.channel_names,
            },
            skeleton: self.skeleton.as_ref().map(TinySkeleton::section),
            styles: self.styles.as_ref().map(TinyStyles::section),
            labels: self.label_section.as_ref().map(TinyLabels::section),
        }
    }

    pub fn encode(&self) -> Vec<u8> {
        encode(&self.payload())
    }
}

/// Header + postcard, as the trainer's writer does (without `alloc`).
pub fn encode(p: &Payload<'_>) -> Vec<u8> {
    let mut buf = vec![0u8; 1 << 16];
    let body = postcard::to_slice(p, &mut buf).expect("fits").to_vec();
    with_header(&body)
}

pub fn with_header(body: &[u8]) -> Vec<u8> {
    let mut out = Header::for_payload(body).unwrap().to_bytes().to_vec();
    out.extend_from_slice(body);
    out
}

/// Recomputes the header's CRC (and length) for the payload after it.
pub fn fix_crc(bytes: &mut [u8]) {
    if bytes.len() >= HEADER_LEN {
        let (h, body) = bytes.split_at_mut(HEADER_LEN);
        h[8..12].copy_from_slice(&(body.len() as u32).to_le_bytes());
        h[12..16].copy_from_slice(&crc32(body).to_le_bytes());
    }
}

pub fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// The tiny blob's bytes (format version 8: `styles` and `labels` absent, the final `00 00`;
/// the `control` section after `policy.succ_cost_scale` is
/// `01 32 ac02 0000c03f 8827 00008040 b0ea01 fa01 9601 c801 ee05 00002040 0000c03f`; the
/// library ends with `continues` `02 01 00`, `beats` `01 12` (frames 1 and 4), `calm` `01 21`
/// (frames 0 and 5), `energy` `02 f0 18` (-1 and 1.5 in sixteenths), `peaks` `01 04` (frame 2)
/// and no `groups`,
/// `00`). Changing the format changes
/// these: bump FORMAT_VERSION and update docs/blob-format.md with them.
pub const GOLDEN: &str = concat!(
    "4753544208000000df01000023727cea807d00009642000016448fc2f53c6666",
    "e63e0ad7233c3333b33e295c0f3e000000400000c8410000c84100008c420619",
    "02010134000000bf000080bf0000803e0000c0bf000000400000003f00008040",
    "0000a0bf0000003e0000003f000080be000000410000c03f0ad7233c0464009c",
    "ff6f12833a08e80300000000e8036f12033b04f4010cfe0202036666663f0000",
    "003f080a0014001e0028000000803e0c0100020003000400050006000c000002",
    "0001000100010002001000000000020000000200000004000000100000050001",
    "00fbff0000070001000000cdcccc3d0132ac020000c03f882700008040b0ea01",
    "fa019601c801ee05000020400000c03f010000f0410602080000000003000000",
    "0403000300080ad7233c000020410c00006400c8002c019cff38ff04ffff0100",
    "0200020201000112012102f0180104000474696e7900409c461c000000000000",
    "b4c20000b4420000803f0080bb440000204100007a4304686561640102096869",
    "70730a6865616404ffff00001800000000000000000000000000000000000020",
    "41000000000206030900010205030405030424000000000000b4420000000000",
    "00000000000000000000000000000000000000000000000e0100000000000000",
    "a04000000000060100010001010000",
);

pub fn postcard_len<T: serde::Serialize>(v: &T) -> usize {
    let mut buf = vec![0u8; 1 << 16];
    postcard::to_slice(v, &mut buf).unwrap().len()
}

/// A name per variant (`BlobError::name`, an exhaustive match); `blob_errors.rs` checks that
/// every name in its list is triggered.
pub fn variant(e: &BlobError) -> &'static str {
    e.name()
}
