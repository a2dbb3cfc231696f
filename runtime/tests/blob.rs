//! The policy blob: golden bytes, round trip of every field, CRC known answer, every error
//! variant, and a deterministic mutation fuzz (never a panic).

use std::collections::BTreeSet;

use gesture_runtime::blob::*;
use gesture_runtime::inference::{GmmComponent, MAX_CLUSTERS, MAX_STATES, MAX_WINDOW};
use gesture_runtime::prosody::{ConfigError, ProsodyConfig};
use gesture_runtime::rig::{CalError, ChannelCal};

fn le_i16(v: &[i16]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}
fn le_u16(v: &[u16]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}
fn le_u32(v: &[u32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}
fn le_f32(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

const GMM0: GmmComponent = GmmComponent {
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
struct Tiny {
    front_end: FrontEndSection,
    states: u8,
    clusters: u8,
    window: u8,
    gmm: Vec<u8>,
    init: (f32, Vec<u8>),
    trans: (f32, Vec<u8>),
    obs: (f32, Vec<u8>),
    p_states: u8,
    p_segments: u16,
    exit_points: u16,
    discount: f32,
    u: (f32, Vec<u8>),
    u_cont: (f32, Vec<u8>),
    exits: Vec<u8>,
    succ_offsets: Vec<u8>,
    succ: Vec<u8>,
    succ_scale: f32,
    channels: u16,
    fps: f32,
    frames: u32,
    segments: u16,
    seg_start: Vec<u8>,
    seg_len: Vec<u8>,
    frame_scales: Vec<u8>,
    frame_values: Vec<u8>,
    strokes: Vec<u8>,
    labels: Vec<u8>,
    rig_name: String,
    period_us: f32,
    calibration: Vec<u8>,
    channel_names: String,
    skeleton: Option<TinySkeleton>,
}

/// The tiny blob's skeleton: `hips` (6 channels) with child `head` (3 rotations, an end site);
/// the rig channel `head` reads `head`'s own Yrotation channel.
#[derive(Clone)]
struct TinySkeleton {
    joints: u16,
    joint_names: String,
    parents: Vec<u8>,
    offsets: Vec<u8>,
    channel_counts: Vec<u8>,
    channel_codes: Vec<u8>,
    rest: Vec<u8>,
    end_sites: Vec<u8>,
    drives: Vec<u8>,
}

impl TinySkeleton {
    fn new() -> Self {
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

    fn section(&self) -> SkeletonSection<'_> {
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
    fn new() -> Self {
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
            rig_name: "tiny".into(),
            period_us: 20_000.0,
            calibration: calibration_record(&ChannelCal::HOBBY).to_vec(),
            channel_names: "head".into(),
            skeleton: Some(TinySkeleton::new()),
        }
    }

    fn payload(&self) -> Payload<'_> {
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
            },
            rig: RigSection {
                name: &self.rig_name,
                period_us: self.period_us,
                calibration: &self.calibration,
                channel_names: &self.channel_names,
            },
            skeleton: self.skeleton.as_ref().map(TinySkeleton::section),
        }
    }

    fn encode(&self) -> Vec<u8> {
        encode(&self.payload())
    }
}

/// Header + postcard, as the trainer's writer does (without `alloc`).
fn encode(p: &Payload<'_>) -> Vec<u8> {
    let mut buf = vec![0u8; 1 << 16];
    let body = postcard::to_slice(p, &mut buf).expect("fits").to_vec();
    with_header(&body)
}

fn with_header(body: &[u8]) -> Vec<u8> {
    let mut out = Header::for_payload(body).unwrap().to_bytes().to_vec();
    out.extend_from_slice(body);
    out
}

/// Recomputes the header's CRC (and length) for the payload after it.
fn fix_crc(bytes: &mut [u8]) {
    if bytes.len() >= HEADER_LEN {
        let (h, body) = bytes.split_at_mut(HEADER_LEN);
        h[8..12].copy_from_slice(&(body.len() as u32).to_le_bytes());
        h[12..16].copy_from_slice(&crc32(body).to_le_bytes());
    }
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// The tiny blob's bytes. Changing the format changes these: bump FORMAT_VERSION and update
/// docs/blob-format.md with them.
const GOLDEN: &str = concat!(
    "4753544202000000af0100005c5acdf8",
    "807d00009642000016448fc2f53c6666e63e0ad7233c3333b33e295c0f3e0000",
    "00400000c8410000c84100008c42061902010134000000bf000080bf0000803e",
    "0000c0bf000000400000003f000080400000a0bf0000003e0000003f000080be",
    "000000410000c03f0ad7233c0464009cff6f12833a08e80300000000e8036f12",
    "033b04f4010cfe0202036666663f0000003f080a0014001e0028000000803e0c",
    "0100020003000400050006000c00000200010001000100020010000000000200",
    "0000020000000400000010000005000100fbff0000070001000000cdcccc3d01",
    "0000f04106020800000000030000000403000300080ad7233c000020410c0000",
    "6400c8002c019cff38ff04ffff01000200020474696e7900409c461c00000000",
    "0000b4c20000b4420000803f0080bb440000204100007a430468656164010209",
    "686970730a6865616404ffff0000180000000000000000000000000000000000",
    "002041000000000206030900010205030405030424000000000000b442000000",
    "000000000000000000000000000000000000000000000000000e010000000000",
    "0000a0400000000006010001000101",
);

#[test]
fn crc_known_answer() {
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
}

#[test]
fn golden_bytes_and_round_trip() {
    let tiny = Tiny::new();
    let bytes = tiny.encode();
    let want: String = GOLDEN.chars().filter(|c| !c.is_whitespace()).collect();
    assert_eq!(
        hex(&bytes),
        want,
        "golden bytes changed ({} bytes)",
        bytes.len()
    );

    let blob = Blob::parse(&bytes).unwrap();
    assert_eq!(*blob.payload(), tiny.payload());
    let h = blob.header();
    assert_eq!((h.version, h.flags), (FORMAT_VERSION, 0));
    assert_eq!(h.payload_len as usize, bytes.len() - HEADER_LEN);
    let sz = blob.section_sizes();
    assert_eq!(
        sz.front_end + sz.inference + sz.policy + sz.library + sz.rig + sz.skeleton,
        h.payload_len as usize
    );
    assert_eq!(sz.front_end, postcard_len(&tiny.payload().front_end));
    assert_eq!(sz.rig, postcard_len(&tiny.payload().rig));

    // front_end
    assert_eq!(blob.prosody_config(), ProsodyConfig::DEFAULT);
    // inference
    assert_eq!((blob.states(), blob.clusters(), blob.window()), (2, 1, 1));
    assert_eq!(blob.gmm_component(0), Some(GMM0));
    assert_eq!(blob.gmm_component(1), None);
    assert_eq!(blob.gmm().as_slice(), &[GMM0]);
    let crf = blob.crf_weights();
    assert_eq!((crf.states, crf.clusters, crf.window), (2, 1, 1));
    assert_eq!(crf.init.get(1), -1.0);
    assert_eq!(crf.trans.get(3), 1.0);
    assert_eq!(crf.obs.get(0), 1.0);
    // policy
    assert_eq!((blob.segments(), blob.exit_points()), (2, 3));
    assert_eq!(blob.successor_entries(), 4);
    assert_eq!(blob.discount(), 0.9);
    assert_eq!(blob.u(1, 0), 15.0);
    assert_eq!(blob.u(0, 1), 10.0);
    assert_eq!(blob.u(2, 0), 0.0);
    assert_eq!(blob.u(0, 2), 0.0);
    assert_eq!(blob.u_cont(2, 1), 1.5);
    assert_eq!(blob.u_cont(usize::MAX, 0), 0.0);
    assert_eq!(
        blob.exit(1),
        Some(ExitPoint {
            segment: 1,
            frame: 1
        })
    );
    assert_eq!(blob.exit(3), None);
    assert_eq!(blob.find_exit(1, 2), Some(2));
    assert_eq!(blob.find_exit(0, 1), None);
    assert_eq!(blob.exits_of(0), 0..1);
    assert_eq!(blob.exits_of(1), 1..3);
    assert_eq!(blob.exits_of(2), 3..3);
    assert!(blob.exit_is_end(0) && !blob.exit_is_end(1) && blob.exit_is_end(2));
    let s: Vec<_> = blob.successors(0).collect();
    assert_eq!(
        s,
        vec![
            Successor {
                segment: 0,
                cost: 0.5
            },
            Successor {
                segment: 1,
                cost: -0.5
            }
        ]
    );
    assert_eq!(blob.successors(1).len(), 0);
    assert_eq!(blob.successor_count(2), 2);
    assert_eq!(blob.successor(2, 1).map(|x| x.segment), Some(1));
    assert_eq!(blob.successor(2, 2), None);
    assert_eq!(blob.successor(usize::MAX, 0), None);
    assert_eq!(
        blob.successors(2).map(|s| s.segment).collect::<Vec<_>>(),
        [0, 1]
    );
    assert_eq!(blob.successors(3).len(), 0);
    // library
    assert_eq!((blob.channels(), blob.frames(), blob.fps()), (1, 6, 30.0));
    assert_eq!(
        blob.segment(1),
        Some(SegmentInfo {
            start: 3,
            len: 3,
            stroke: Some(1),
            label: core::num::NonZeroU8::new(2)
        })
    );
    assert_eq!(blob.segment(0).unwrap().stroke, None);
    assert_eq!(blob.segment(0).unwrap().label, None);
    assert_eq!(blob.segment(2), None);
    assert!((blob.frame(0, 3) - 13.0).abs() < 1e-5);
    assert!((blob.segment_value(1, 2, 0) - 8.0).abs() < 1e-5);
    assert_eq!(blob.segment_value(1, 3, 0), 0.0);
    assert_eq!(blob.frame(1, 0), 0.0);
    let mut pose = [0.0f32; 4];
    assert_eq!(blob.pose(1, &mut pose), 1);
    assert!((pose[0] - 11.0).abs() < 1e-5);
    assert_eq!(blob.pose(6, &mut pose), 0);
    // rig
    assert_eq!(blob.rig_name(), "tiny");
    assert_eq!(blob.period_us(), 20_000.0);
    assert_eq!(blob.calibration(0), Some(ChannelCal::HOBBY));
    assert_eq!(blob.calibration(1), None);
    assert_eq!(blob.channel_name(0), Some("head"));
    assert_eq!(blob.channel_names().collect::<Vec<_>>(), ["head"]);
    // skeleton
    assert_eq!(sz.skeleton, postcard_len(&tiny.payload().skeleton));
    let sk = blob.skeleton().unwrap();
    assert_eq!((sk.joints(), sk.channel_count(), sk.drives()), (2, 9, 1));
    assert_eq!(sk.joint_names().collect::<Vec<_>>(), ["hips", "head"]);
    assert_eq!((sk.joint_name(1), sk.joint_name(2)), (Some("head"), None));
    assert_eq!(
        (sk.parent(0), sk.parent(1), sk.parent(2)),
        (None, Some(0), None)
    );
    assert_eq!(sk.offset(1), [0.0, 10.0, 0.0]);
    assert_eq!(sk.offset(9), [0.0; 3]);
    assert_eq!((sk.joint_channels(0), sk.joint_channels(1)), (0..6, 6..9));
    assert_eq!(sk.joint_channels(2), 0..0);
    assert_eq!((sk.channel_code(3), sk.channel_code(9)), (Some(5), None));
    assert_eq!((sk.rest(1), sk.rest(99)), (90.0, 0.0));
    assert_eq!(
        (sk.end_site(0), sk.end_site(1)),
        (None, Some([0.0, 5.0, 0.0]))
    );
    assert_eq!(
        sk.drive(0),
        Some(Drive {
            joint: 1,
            chain_top: 1,
            axis: 1,
            negated: false,
            mode: DriveMode::Channel
        })
    );
    assert_eq!(sk.drive(1), None);
    for code in 0..8u8 {
        assert_eq!(DriveMode::from_code(code).map(DriveMode::code), Some(code));
    }
    assert_eq!(DriveMode::from_code(8), None);
    // Without the section: one byte (postcard's None), and no skeleton.
    let mut bare = Tiny::new();
    bare.skeleton = None;
    let bytes = bare.encode();
    let b = Blob::parse(&bytes).unwrap();
    assert_eq!((b.skeleton(), b.section_sizes().skeleton), (None, 1));
}

fn postcard_len<T: serde::Serialize>(v: &T) -> usize {
    let mut buf = vec![0u8; 1 << 16];
    postcard::to_slice(v, &mut buf).unwrap().len()
}

/// A name per variant; the exhaustive match makes a new variant fail to compile here until it
/// is added to `ALL` and triggered below.
fn variant(e: &BlobError) -> &'static str {
    match e {
        BlobError::BlobTooShort { .. } => "BlobTooShort",
        BlobError::BadMagic => "BadMagic",
        BlobError::UnsupportedVersion { .. } => "UnsupportedVersion",
        BlobError::UnsupportedFlags { .. } => "UnsupportedFlags",
        BlobError::Truncated { .. } => "Truncated",
        BlobError::TrailingBytes { .. } => "TrailingBytes",
        BlobError::BadCrc { .. } => "BadCrc",
        BlobError::Malformed { .. } => "Malformed",
        BlobError::FrontEnd(_) => "FrontEnd",
        BlobError::ZeroCount { .. } => "ZeroCount",
        BlobError::StateCountTooLarge { .. } => "StateCountTooLarge",
        BlobError::ClusterCountTooLarge { .. } => "ClusterCountTooLarge",
        BlobError::WindowTooLarge { .. } => "WindowTooLarge",
        BlobError::TooManySegments { .. } => "TooManySegments",
        BlobError::TooManyExits { .. } => "TooManyExits",
        BlobError::TooManyChannels { .. } => "TooManyChannels",
        BlobError::TooManyFrames { .. } => "TooManyFrames",
        BlobError::StateCountMismatch { .. } => "StateCountMismatch",
        BlobError::SegmentCountMismatch { .. } => "SegmentCountMismatch",
        BlobError::TableLength { .. } => "TableLength",
        BlobError::NotFinite { .. } => "NotFinite",
        BlobError::BadFrameRate => "BadFrameRate",
        BlobError::EmptySegment { .. } => "EmptySegment",
        BlobError::SegmentOutOfFrames { .. } => "SegmentOutOfFrames",
        BlobError::StrokeOutOfRange { .. } => "StrokeOutOfRange",
        BlobError::BadPwmPeriod => "BadPwmPeriod",
        BlobError::BadCalibration { .. } => "BadCalibration",
        BlobError::ChannelNameCount { .. } => "ChannelNameCount",
        BlobError::BadDiscount => "BadDiscount",
        BlobError::ExitSegmentOutOfRange { .. } => "ExitSegmentOutOfRange",
        BlobError::ExitFrameOutOfRange { .. } => "ExitFrameOutOfRange",
        BlobError::ExitsNotSorted { .. } => "ExitsNotSorted",
        BlobError::MissingEndExit { .. } => "MissingEndExit",
        BlobError::SuccessorOffsetsNotMonotone { .. } => "SuccessorOffsetsNotMonotone",
        BlobError::SuccessorSegmentOutOfRange { .. } => "SuccessorSegmentOutOfRange",
        BlobError::SuccessorsNotSorted { .. } => "SuccessorsNotSorted",
        BlobError::NoSuccessors { .. } => "NoSuccessors",
        BlobError::TooManyJoints { .. } => "TooManyJoints",
        BlobError::JointNameCount { .. } => "JointNameCount",
        BlobError::BadParent { .. } => "BadParent",
        BlobError::BadJointChannels { .. } => "BadJointChannels",
        BlobError::BadEndSite { .. } => "BadEndSite",
        BlobError::BadDrive { .. } => "BadDrive",
    }
}

const ALL: &[&str] = &[
    "BlobTooShort",
    "BadMagic",
    "UnsupportedVersion",
    "UnsupportedFlags",
    "Truncated",
    "TrailingBytes",
    "BadCrc",
    "Malformed",
    "FrontEnd",
    "ZeroCount",
    "StateCountTooLarge",
    "ClusterCountTooLarge",
    "WindowTooLarge",
    "TooManySegments",
    "TooManyExits",
    "TooManyChannels",
    "TooManyFrames",
    "StateCountMismatch",
    "SegmentCountMismatch",
    "TableLength",
    "NotFinite",
    "BadFrameRate",
    "EmptySegment",
    "SegmentOutOfFrames",
    "StrokeOutOfRange",
    "BadPwmPeriod",
    "BadCalibration",
    "ChannelNameCount",
    "BadDiscount",
    "ExitSegmentOutOfRange",
    "ExitFrameOutOfRange",
    "ExitsNotSorted",
    "MissingEndExit",
    "SuccessorOffsetsNotMonotone",
    "SuccessorSegmentOutOfRange",
    "SuccessorsNotSorted",
    "NoSuccessors",
    "TooManyJoints",
    "JointNameCount",
    "BadParent",
    "BadJointChannels",
    "BadEndSite",
    "BadDrive",
];

#[test]
fn every_error_variant_is_reachable() {
    let good = Tiny::new().encode();
    let mut hit = BTreeSet::new();
    let mut check = |bytes: &[u8], want: BlobError| {
        let got = Blob::parse(bytes).err();
        assert_eq!(got, Some(want));
        // Every message is one line and says something.
        let msg = want.to_string();
        assert!(!msg.is_empty() && !msg.contains('\n'), "{msg}");
        hit.insert(variant(&want));
    };
    let mutated = |f: &dyn Fn(&mut Tiny)| {
        let mut t = Tiny::new();
        f(&mut t);
        t.encode()
    };

    // Header.
    check(&good[..15], BlobError::BlobTooShort { len: 15 });
    check(&[], BlobError::BlobTooShort { len: 0 });
    let mut b = good.clone();
    b[0] = b'X';
    check(&b, BlobError::BadMagic);
    let mut b = good.clone();
    b[4] = 1;
    check(&b, BlobError::UnsupportedVersion { found: 1 });
    let mut b = good.clone();
    b[4] = 3;
    check(&b, BlobError::UnsupportedVersion { found: 3 });
    let mut b = good.clone();
    b[6] = 1;
    check(&b, BlobError::UnsupportedFlags { found: 1 });
    let n = good.len() - HEADER_LEN;
    check(
        &good[..good.len() - 1],
        BlobError::Truncated {
            declared: n as u32,
            available: n - 1,
        },
    );
    let mut b = good.clone();
    b.push(0);
    check(
        &b,
        BlobError::TrailingBytes {
            declared: n as u32,
            available: n + 1,
        },
    );
    let mut b = good.clone();
    let last = b.len() - 1;
    b[last] ^= 0x40;
    let stored = u32::from_le_bytes(good[12..16].try_into().unwrap());
    check(
        &b,
        BlobError::BadCrc {
            stored,
            computed: crc32(&b[HEADER_LEN..]),
        },
    );

    // Payload decoding.
    check(
        &with_header(&[1, 2, 3]),
        BlobError::Malformed {
            section: Section::FrontEnd,
        },
    );
    let mut b = good.clone();
    b.push(0);
    fix_crc(&mut b);
    check(
        &b,
        BlobError::Malformed {
            section: Section::Skeleton,
        },
    );
    let mut b = good.clone();
    b.truncate(b.len() - 3);
    fix_crc(&mut b);
    check(
        &b,
        BlobError::Malformed {
            section: Section::Skeleton,
        },
    );
    let mut b = mutated(&|t| t.skeleton = None);
    b.truncate(b.len() - 3);
    fix_crc(&mut b);
    check(
        &b,
        BlobError::Malformed {
            section: Section::Rig,
        },
    );

    // front_end.
    check(
        &mutated(&|t| t.front_end.sample_rate_hz = 44_100),
        BlobError::FrontEnd(ConfigError::UnsupportedSampleRate(44_100)),
    );
    check(
        &mutated(&|t| t.front_end.margin_db = f32::NAN),
        BlobError::FrontEnd(ConfigError::SyllableParams),
    );

    // inference.
    check(
        &mutated(&|t| t.states = 0),
        BlobError::ZeroCount {
            field: Field::States,
        },
    );
    check(
        &mutated(&|t| t.states = MAX_STATES as u8 + 1),
        BlobError::StateCountTooLarge {
            found: MAX_STATES as u32 + 1,
        },
    );
    check(
        &mutated(&|t| t.clusters = MAX_CLUSTERS as u8 + 1),
        BlobError::ClusterCountTooLarge {
            found: MAX_CLUSTERS as u32 + 1,
        },
    );
    check(
        &mutated(&|t| t.window = MAX_WINDOW as u8 + 1),
        BlobError::WindowTooLarge {
            found: MAX_WINDOW as u32 + 1,
        },
    );
    check(
        &mutated(&|t| {
            t.gmm.pop();
        }),
        BlobError::TableLength {
            field: Field::Gmm,
            expected: GMM_RECORD_BYTES,
            found: GMM_RECORD_BYTES - 1,
        },
    );
    check(
        &mutated(&|t| t.gmm[4..8].copy_from_slice(&f32::INFINITY.to_le_bytes())),
        BlobError::NotFinite { field: Field::Gmm },
    );
    check(
        &mutated(&|t| t.trans.0 = f32::NAN),
        BlobError::NotFinite {
            field: Field::CrfTrans,
        },
    );
    check(
        &mutated(&|t| t.obs.1.extend([0, 0])),
        BlobError::TableLength {
            field: Field::CrfObs,
            expected: 4,
            found: 6,
        },
    );

    // library.
    check(
        &mutated(&|t| t.channels = 0),
        BlobError::ZeroCount {
            field: Field::Channels,
        },
    );
    check(
        &mutated(&|t| t.channels = MAX_CHANNELS as u16 + 1),
        BlobError::TooManyChannels {
            found: MAX_CHANNELS as u32 + 1,
        },
    );
    check(&mutated(&|t| t.fps = 0.0), BlobError::BadFrameRate);
    check(&mutated(&|t| t.fps = f32::NAN), BlobError::BadFrameRate);
    check(
        &mutated(&|t| t.frames = MAX_FRAMES as u32 + 1),
        BlobError::TooManyFrames {
            found: MAX_FRAMES as u32 + 1,
        },
    );
    check(
        &mutated(&|t| t.segments = MAX_SEGMENTS as u16 + 1),
        BlobError::TooManySegments {
            found: MAX_SEGMENTS as u32 + 1,
        },
    );
    check(
        &mutated(&|t| {
            t.frame_values.truncate(10);
        }),
        BlobError::TableLength {
            field: Field::FrameValues,
            expected: 12,
            found: 10,
        },
    );
    check(
        &mutated(&|t| t.frame_scales = le_f32(&[3e38, 0.0])),
        BlobError::NotFinite {
            field: Field::FrameScales,
        },
    );
    check(
        &mutated(&|t| t.seg_len = le_u16(&[3, 0])),
        BlobError::EmptySegment { segment: 1 },
    );
    check(
        &mutated(&|t| t.seg_start = le_u32(&[0, 4])),
        BlobError::SegmentOutOfFrames { segment: 1 },
    );
    check(
        &mutated(&|t| t.seg_start = le_u32(&[u32::MAX, 0])),
        BlobError::SegmentOutOfFrames { segment: 0 },
    );
    check(
        &mutated(&|t| t.strokes = le_u16(&[3, NO_STROKE])),
        BlobError::StrokeOutOfRange { segment: 0 },
    );

    // rig.
    check(&mutated(&|t| t.period_us = 0.0), BlobError::BadPwmPeriod);
    check(
        &mutated(&|t| {
            let mut c = ChannelCal::HOBBY;
            c.min_deg = 100.0;
            t.calibration = calibration_record(&c).to_vec();
        }),
        BlobError::BadCalibration {
            channel: 0,
            error: CalError::EmptyRange,
        },
    );
    check(
        &mutated(&|t| t.calibration.clear()),
        BlobError::TableLength {
            field: Field::Calibration,
            expected: CALIBRATION_RECORD_BYTES,
            found: 0,
        },
    );
    check(
        &mutated(&|t| t.channel_names = "head\njaw".into()),
        BlobError::ChannelNameCount {
            expected: 1,
            found: 2,
        },
    );

    // policy.
    check(
        &mutated(&|t| t.p_states = 3),
        BlobError::StateCountMismatch {
            inference: 2,
            policy: 3,
        },
    );
    check(
        &mutated(&|t| t.p_segments = 3),
        BlobError::SegmentCountMismatch {
            library: 2,
            policy: 3,
        },
    );
    check(
        &mutated(&|t| t.exit_points = 0),
        BlobError::ZeroCount {
            field: Field::ExitPoints,
        },
    );
    check(
        &mutated(&|t| t.exit_points = MAX_EXITS as u16 + 1),
        BlobError::TooManyExits {
            found: MAX_EXITS as u32 + 1,
        },
    );
    check(&mutated(&|t| t.discount = 1.5), BlobError::BadDiscount);
    check(
        &mutated(&|t| t.u.1.truncate(6)),
        BlobError::TableLength {
            field: Field::U,
            expected: 8,
            found: 6,
        },
    );
    check(
        &mutated(&|t| t.u_cont.0 = f32::INFINITY),
        BlobError::NotFinite {
            field: Field::UCont,
        },
    );
    check(
        &mutated(&|t| t.exits = le_u16(&[0, 2, 2, 1, 1, 2])),
        BlobError::ExitSegmentOutOfRange {
            exit: 1,
            segment: 2,
        },
    );
    check(
        &mutated(&|t| t.exits = le_u16(&[0, 3, 1, 1, 1, 2])),
        BlobError::ExitFrameOutOfRange { exit: 0, frame: 3 },
    );
    check(
        &mutated(&|t| t.exits = le_u16(&[0, 2, 1, 2, 1, 1])),
        BlobError::ExitsNotSorted { exit: 2 },
    );
    check(
        &mutated(&|t| t.exits = le_u16(&[0, 1, 1, 1, 1, 2])),
        BlobError::MissingEndExit { segment: 0 },
    );
    check(
        &mutated(&|t| t.succ_offsets = le_u32(&[0, 2, 1, 4])),
        BlobError::SuccessorOffsetsNotMonotone { exit: 2 },
    );
    check(
        &mutated(&|t| t.succ_offsets = le_u32(&[1, 2, 2, 4])),
        BlobError::SuccessorOffsetsNotMonotone { exit: 0 },
    );
    check(
        &mutated(&|t| t.succ_offsets = le_u32(&[0, 2, 2, 5])),
        BlobError::TableLength {
            field: Field::Succ,
            expected: 20,
            found: 16,
        },
    );
    check(
        &mutated(&|t| t.succ_scale = f32::NAN),
        BlobError::NotFinite { field: Field::Succ },
    );
    check(
        &mutated(&|t| t.succ = le_i16(&[0, 5, 1, -5, 0, 7, 2, 0])),
        BlobError::SuccessorSegmentOutOfRange {
            entry: 3,
            segment: 2,
        },
    );
    check(
        &mutated(&|t| t.succ = le_i16(&[1, 5, 0, -5, 0, 7, 1, 0])),
        BlobError::SuccessorsNotSorted { exit: 0 },
    );
    check(
        &mutated(&|t| {
            t.succ_offsets = le_u32(&[0, 2, 2, 2]);
            t.succ.truncate(8);
        }),
        BlobError::NoSuccessors { exit: 2 },
    );

    // skeleton.
    let sk = |f: &dyn Fn(&mut TinySkeleton)| {
        mutated(&|t| {
            if let Some(s) = t.skeleton.as_mut() {
                f(s)
            }
        })
    };
    check(
        &sk(&|s| s.joints = 0),
        BlobError::ZeroCount {
            field: Field::Joints,
        },
    );
    check(
        &sk(&|s| s.joints = MAX_JOINTS as u16 + 1),
        BlobError::TooManyJoints {
            found: MAX_JOINTS as u32 + 1,
        },
    );
    check(
        &sk(&|s| s.joint_names = "hips".into()),
        BlobError::JointNameCount {
            expected: 2,
            found: 1,
        },
    );
    check(
        &sk(&|s| s.offsets.truncate(20)),
        BlobError::TableLength {
            field: Field::Offsets,
            expected: 24,
            found: 20,
        },
    );
    check(
        &sk(&|s| s.channel_counts = vec![6, 2]),
        BlobError::TableLength {
            field: Field::ChannelCodes,
            expected: 8,
            found: 9,
        },
    );
    check(
        &sk(&|s| s.rest.truncate(32)),
        BlobError::TableLength {
            field: Field::Rest,
            expected: 36,
            found: 32,
        },
    );
    check(
        &sk(&|s| s.end_sites.push(0)),
        BlobError::TableLength {
            field: Field::EndSites,
            expected: 14,
            found: 15,
        },
    );
    check(
        &sk(&|s| s.drives.push(0)),
        BlobError::TableLength {
            field: Field::Drives,
            expected: 6,
            found: 7,
        },
    );
    check(
        &sk(&|s| s.offsets[4..8].copy_from_slice(&f32::NAN.to_le_bytes())),
        BlobError::NotFinite {
            field: Field::Offsets,
        },
    );
    check(
        &sk(&|s| s.rest[0..4].copy_from_slice(&f32::INFINITY.to_le_bytes())),
        BlobError::NotFinite { field: Field::Rest },
    );
    check(
        &sk(&|s| s.end_sites[2..6].copy_from_slice(&f32::NAN.to_le_bytes())),
        BlobError::NotFinite {
            field: Field::EndSites,
        },
    );
    check(
        &sk(&|s| s.parents = le_u16(&[ROOT_PARENT, 1])),
        BlobError::BadParent { joint: 1 },
    );
    check(
        &sk(&|s| s.channel_codes[8] = 6),
        BlobError::BadJointChannels { joint: 1 },
    );
    check(
        &sk(&|s| s.channel_codes[1] = 0),
        BlobError::BadJointChannels { joint: 0 },
    );
    check(
        &sk(&|s| s.end_sites[0] = 2),
        BlobError::BadEndSite { entry: 0 },
    );
    check(
        &sk(&|s| s.drives[0] = 2),
        BlobError::BadDrive { channel: 0 },
    );
    check(
        &sk(&|s| s.drives[4] = 6),
        BlobError::BadDrive { channel: 0 },
    );
    check(
        &sk(&|s| s.drives[5] = 8),
        BlobError::BadDrive { channel: 0 },
    );
    // The chain top must be the joint or an ancestor: hips (0) above head (1) is fine, head
    // above hips is not.
    assert!(Blob::parse(&sk(&|s| s.drives[2] = 0)).is_ok());
    check(
        &sk(&|s| {
            s.drives[0] = 0;
            s.drives[2] = 1;
        }),
        BlobError::BadDrive { channel: 0 },
    );

    let all: BTreeSet<&str> = ALL.iter().copied().collect();
    let missing: Vec<_> = all.difference(&hit).collect();
    assert!(missing.is_empty(), "never triggered: {missing:?}");
}

/// A deterministic LCG (Knuth's MMIX constants).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Calls every accessor with in- and out-of-range indices; nothing may panic and the values of
/// in-range lookups must be finite.
fn exercise(b: &Blob<'_>, rng: &mut Lcg) {
    let fin = |v: f32| assert!(v.is_finite(), "{v}");
    let _ = (
        b.header(),
        b.section_sizes(),
        b.prosody_config(),
        b.payload(),
    );
    for c in b.gmm().as_slice() {
        fin(c.log_norm);
    }
    let _ = b.gmm_component(rng.below(20));
    let crf = b.crf_weights();
    for i in 0..crf.states {
        fin(crf.init.get(i));
    }
    for _ in 0..8 {
        let seg = rng.below(b.segments() + 2);
        let e = rng.below(b.exit_points() + 2);
        let s = rng.below(40);
        fin(b.u(seg, s));
        fin(b.u_cont(e, s));
        b.successors(e).for_each(|x| fin(x.cost));
        let _ = (b.exit(e), b.exit_is_end(e), b.exits_of(seg), b.segment(seg));
        if let Some(x) = b.exit(e) {
            assert_eq!(b.find_exit(x.segment, x.frame), Some(e));
        }
        fin(b.frame(rng.below(40), rng.below(b.frames() + 2)));
        fin(b.segment_value(seg, rng.below(10), rng.below(3)));
        let mut pose = [0.0f32; MAX_CHANNELS];
        b.pose(rng.below(b.frames() + 2), &mut pose);
        pose.iter().for_each(|&v| fin(v));
        let _ = (b.calibration(rng.below(40)), b.channel_name(rng.below(40)));
        if let Some(sk) = b.skeleton() {
            let j = rng.below(sk.joints() + 2);
            let _ = (
                sk.joint_name(j),
                sk.parent(j),
                sk.end_site(j),
                sk.drive(rng.below(4)),
            );
            sk.offset(j).iter().for_each(|&v| fin(v));
            for i in sk.joint_channels(j) {
                fin(sk.rest(i));
                assert!(sk.channel_code(i).is_some_and(|c| c <= 5));
            }
            if let Some(p) = sk.parent(j) {
                assert!(p < j);
            }
        }
    }
    for seg in 0..b.segments() {
        // Every segment ends in an exit with a successor (validated).
        let r = b.exits_of(seg);
        assert!(!r.is_empty());
        assert!(b.exit_is_end(r.end - 1));
        assert!(b.successors(r.end - 1).len() > 0);
    }
    for e in [usize::MAX, usize::MAX / 2, usize::MAX / 4 + 1] {
        fin(b.u(e, 0) + b.u_cont(e, 1) + b.frame(0, e) + b.segment_value(e, e, 0));
        let _ = (b.exit(e), b.successors(e).len(), b.segment(e));
    }
}

#[test]
fn twenty_thousand_mutations_never_panic() {
    let good = Tiny::new().encode();
    let mut rng = Lcg(0x5EED_B10B);
    let mut outcomes = std::collections::BTreeMap::<&str, usize>::new();
    for i in 0..20_000 {
        let mut b = good.clone();
        match rng.below(4) {
            // Flip a few bits.
            0 | 1 => {
                for _ in 0..1 + rng.below(4) {
                    let j = rng.below(b.len());
                    b[j] ^= 1 << rng.below(8);
                }
            }
            // Overwrite a byte with an extreme value.
            2 => {
                let j = rng.below(b.len());
                b[j] = [0, 0xFF, 0x7F, 0x80][rng.below(4)];
            }
            // Truncate or extend.
            _ => {
                let n = rng.below(b.len() + 8);
                b.resize(n, rng.below(256) as u8);
            }
        }
        // Most mutations should reach the decoder and validator, not stop at the CRC.
        if i % 4 != 0 {
            fix_crc(&mut b);
        }
        match Blob::parse(&b) {
            Ok(blob) => {
                exercise(&blob, &mut rng);
                *outcomes.entry("ok").or_default() += 1;
            }
            Err(e) => {
                let _ = e.to_string();
                *outcomes.entry(variant(&e)).or_default() += 1;
            }
        }
    }
    eprintln!("{outcomes:?}");
    // The fuzz reaches deep: successes and field-level errors both occur.
    assert!(
        outcomes.get("ok").copied().unwrap_or(0) > 100,
        "{outcomes:?}"
    );
    assert!(outcomes.len() > 15, "{outcomes:?}");
}

#[test]
fn the_valid_tiny_blob_exercises_cleanly() {
    let good = Tiny::new().encode();
    let blob = Blob::parse(&good).unwrap();
    exercise(&blob, &mut Lcg(1));
}
