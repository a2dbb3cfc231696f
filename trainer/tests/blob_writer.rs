//! The blob writer: same bytes as the runtime's golden blob, typed constructors round-trip
//! through the runtime's loader, errors, and the atomic file write.

use gesture_runtime::blob::{
    calibration_record, gmm_record, Blob, BlobError, Drive, DriveMode, FrontEndSection, HEADER_LEN,
    NO_STROKE,
};
use gesture_runtime::inference::GmmComponent;
use gesture_runtime::prosody::ProsodyConfig;
use gesture_runtime::rig::ChannelCal;
use gesture_trainer::blob::*;
use gesture_trainer::inference::quantize::{QTable, QuantizedInference};
use gesture_trainer::motion::{Channel, Joint, Skeleton};

fn q(v: &[i16], scale: f32) -> QTable {
    QTable {
        bytes: v.iter().flat_map(|x| x.to_le_bytes()).collect(),
        scale,
    }
}

fn le<T: Copy, const N: usize>(v: &[T], f: fn(T) -> [u8; N]) -> Vec<u8> {
    v.iter().flat_map(|&x| f(x)).collect()
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

/// The content of the runtime's golden blob (runtime/tests/blob.rs, `Tiny::new`).
fn golden_content() -> OwnedPayload {
    OwnedPayload {
        front_end: FrontEndSection::from_config(&ProsodyConfig::DEFAULT),
        inference: OwnedInference {
            states: 2,
            clusters: 1,
            window: 1,
            gmm: gmm_record(&GMM0).to_vec(),
            crf_init: q(&[100, -100], 0.01),
            crf_trans: q(&[1000, 0, 0, 1000], 0.001),
            crf_obs: q(&[500, -500], 0.002),
        },
        policy: OwnedPolicy {
            states: 2,
            segments: 2,
            exit_points: 3,
            discount: 0.9,
            u: q(&[10, 20, 30, 40], 0.5),
            u_cont: q(&[1, 2, 3, 4, 5, 6], 0.25),
            exits: le(&[0u16, 2, 1, 1, 1, 2], u16::to_le_bytes),
            succ_offsets: le(&[0u32, 2, 2, 4], u32::to_le_bytes),
            succ: le(&[0i16, 5, 1, -5, 0, 7, 1, 0], i16::to_le_bytes),
            succ_cost_scale: 0.1,
        },
        library: OwnedLibrary {
            channels: 1,
            fps: 30.0,
            frames: 6,
            segments: 2,
            seg_start: le(&[0u32, 3], u32::to_le_bytes),
            seg_len: le(&[3u16, 3], u16::to_le_bytes),
            frame_scales: le(&[0.01f32, 10.0], f32::to_le_bytes),
            frame_values: le(&[0i16, 100, 200, 300, -100, -200], i16::to_le_bytes),
            strokes: le(&[NO_STROKE, 1], u16::to_le_bytes),
            labels: vec![0, 2],
        },
        rig: OwnedRig {
            name: "tiny".into(),
            period_us: 20_000.0,
            calibration: calibration_record(&ChannelCal::HOBBY).to_vec(),
            channel_names: "head".into(),
        },
        skeleton: Some(tiny_skeleton()),
    }
}

/// The golden blob's skeleton, built from a BVH skeleton like `pack` does.
fn tiny_skeleton() -> OwnedSkeleton {
    let skeleton = Skeleton {
        joints: vec![
            Joint {
                name: "hips".into(),
                parent: None,
                offset: [0.0; 3],
                channels: vec![
                    Channel::Xposition,
                    Channel::Yposition,
                    Channel::Zposition,
                    Channel::Zrotation,
                    Channel::Xrotation,
                    Channel::Yrotation,
                ],
                end_site: None,
            },
            Joint {
                name: "head".into(),
                parent: Some(0),
                offset: [0.0, 10.0, 0.0],
                channels: vec![Channel::Zrotation, Channel::Xrotation, Channel::Yrotation],
                end_site: Some([0.0, 5.0, 0.0]),
            },
        ],
    };
    let rest = [0.0, 90.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let drive = Drive {
        joint: 1,
        chain_top: 1,
        axis: 1,
        negated: false,
        mode: DriveMode::Channel,
    };
    OwnedSkeleton::new(&skeleton, &rest, &[drive]).unwrap()
}

/// Copy of `GOLDEN` in runtime/tests/blob.rs: the writer must produce exactly the bytes the
/// format's golden test pins.
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

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

#[test]
fn writer_produces_the_golden_bytes() {
    let bytes = encode(&golden_content().payload()).unwrap();
    assert_eq!(bytes.len(), 447);
    assert_eq!(hex(&bytes), GOLDEN);
}

#[test]
fn constructors_round_trip_through_the_runtime_loader() {
    let qi = QuantizedInference {
        gmm: vec![
            GMM0,
            GmmComponent {
                mean: [1.0, 2.0],
                ..GMM0
            },
        ],
        states: 3,
        window: 2,
        init: q(&[1, 2, 3], 0.1),
        trans: q(&[0; 9], 1.0),
        obs: q(&(0..12).collect::<Vec<i16>>(), 0.01),
    };
    let inference = OwnedInference::new(&qi).unwrap();
    // 4 segments of 5 frames over 20 frames, 3 channels with different ranges.
    let frames: Vec<Vec<f32>> = (0..20)
        .map(|f| {
            let t = f as f32;
            vec![t * 3.0 - 30.0, 45.0, (t * 0.7).sin() * 80.0]
        })
        .collect();
    let segs: Vec<SegmentSpec> = (0..4)
        .map(|i| SegmentSpec {
            start: 5 * i,
            len: 5,
            stroke: (i % 2 == 1).then_some(2),
            label: i as u8,
        })
        .collect();
    let library = OwnedLibrary::new(25.0, 3, &frames, &segs).unwrap();
    // Exits: an interruption at frame 2 of every segment and the end at frame 4.
    let exits: Vec<(usize, usize)> = (0..4).flat_map(|s| [(s, 2), (s, 4)]).collect();
    // End exits: two successors sorted by segment; interruptions: none.
    let successors: Vec<Vec<(usize, i16)>> = exits
        .iter()
        .map(|&(s, f)| {
            let mut l = if f == 4 {
                vec![((s + 1) % 4, 100), ((s + 2) % 4, -200)]
            } else {
                vec![]
            };
            l.sort();
            l
        })
        .collect();
    let u = q(&(0..12).map(|i| i * 10).collect::<Vec<i16>>(), 0.5);
    let u_cont = q(&(0..24).collect::<Vec<i16>>(), 0.25);
    let policy = OwnedPolicy::new(&PolicyInput {
        states: 3,
        segments: 4,
        discount: 0.95,
        u: &u,
        u_cont: &u_cont,
        exits: &exits,
        successors: &successors,
        succ_cost_scale: 0.01,
    })
    .unwrap();
    let names = ["pan", "tilt", "jaw"];
    let rig_ch: Vec<(String, ChannelCal)> = names
        .iter()
        .map(|n| (n.to_string(), ChannelCal::HOBBY))
        .collect();
    let rig = OwnedRig::new("puppet", 20_000.0, &rig_ch).unwrap();
    let owned = OwnedPayload {
        front_end: FrontEndSection::from_config(&ProsodyConfig::DEFAULT),
        inference,
        policy,
        library,
        rig,
        skeleton: None,
    };
    let bytes = encode(&owned.payload()).unwrap();
    let b = Blob::parse(&bytes).unwrap();
    assert_eq!((b.states(), b.clusters(), b.window()), (3, 2, 2));
    assert_eq!(b.gmm_component(1).unwrap().mean, [1.0, 2.0]);
    assert_eq!(b.crf_weights().obs.get(11), 11.0 * 0.01);
    // Frames come back within half a quantization step of each channel.
    for (f, fr) in frames.iter().enumerate() {
        for (ch, &v) in fr.iter().enumerate() {
            let range = match ch {
                0 => 57.0,
                1 => 0.0,
                _ => 160.0,
            };
            let tol = range / 65534.0 + 1e-4;
            assert!((b.frame(ch, f) - v).abs() <= tol, "f {f} ch {ch}");
        }
    }
    assert_eq!(b.segment(3).unwrap().start, 15);
    assert_eq!(b.segment(1).unwrap().stroke, Some(2));
    assert_eq!(b.segment(2).unwrap().stroke, None);
    assert_eq!(b.segment(2).unwrap().label.map(|l| l.get()), Some(2));
    assert_eq!(b.exit_points(), 8);
    assert_eq!(b.find_exit(2, 4), Some(5));
    let s: Vec<_> = b.successors(1).map(|x| (x.segment, x.cost)).collect();
    assert_eq!(s, vec![(1, 1.0), (2, -2.0)]);
    assert_eq!(b.successors(0).len(), 0);
    assert_eq!(b.u(3, 2), 110.0 * 0.5);
    assert_eq!(b.u_cont(7, 1), 22.0 * 0.25);
    assert!((b.discount() - 0.95).abs() < 1e-7);
    assert_eq!(b.channel_names().collect::<Vec<_>>(), names);
    assert_eq!(b.rig_name(), "puppet");
    assert_eq!(b.fps(), 25.0);
}

#[test]
fn example_payload_is_valid() {
    let p = OwnedPayload::example();
    let bytes = encode(&p.payload()).unwrap();
    let b = Blob::parse(&bytes).unwrap();
    assert_eq!(b.rig_name(), "example");
    assert!((b.frame(0, 5) + 20.0).abs() < 1e-3);
}

#[test]
fn builder_errors_are_typed() {
    let u = q(&[0; 2], 1.0);
    let input = PolicyInput {
        states: 1,
        segments: 2,
        discount: 0.9,
        u: &u,
        u_cont: &u,
        exits: &[(0, 0), (70_000, 0)],
        successors: &[vec![], vec![]],
        succ_cost_scale: 1.0,
    };
    let e = OwnedPolicy::new(&input).unwrap_err();
    assert!(matches!(
        e,
        BlobWriteError::TooLarge {
            what: "exit segment",
            value: 70_000,
            ..
        }
    ));
    let e = OwnedPolicy::new(&PolicyInput {
        successors: &[vec![]],
        ..input
    })
    .unwrap_err();
    assert!(matches!(e, BlobWriteError::Inconsistent(_)), "{e}");
    let e = OwnedLibrary::new(30.0, 2, &[vec![1.0]], &[]).unwrap_err();
    assert!(e.to_string().contains("1 values for 2 channels"), "{e}");
    let e = OwnedLibrary::new(30.0, 1, &[vec![f32::NAN]], &[]).unwrap_err();
    assert!(matches!(e, BlobWriteError::Inconsistent(_)));
    let e = OwnedRig::new("r", 20_000.0, &[("a\nb".into(), ChannelCal::HOBBY)]).unwrap_err();
    assert!(e.to_string().contains("newline"), "{e}");

    // A rule of the format broken: the runtime's error comes back.
    let mut p = OwnedPayload::example();
    p.policy.succ = le(&[1i16, 5, 0, -5, 0, 7, 1, 0], i16::to_le_bytes);
    let e = encode(&p.payload()).unwrap_err();
    assert!(matches!(
        e,
        BlobWriteError::Invalid(BlobError::SuccessorsNotSorted { exit: 0 })
    ));
    assert!(e.to_string().contains("refused by the runtime"), "{e}");
}

#[test]
fn write_is_atomic_and_replaces() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("policy.blob");
    std::fs::write(&path, b"old contents").unwrap();
    let p = OwnedPayload::example();
    let n = write_blob(&path, &p.payload()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(n, bytes.len());
    assert_eq!(bytes, encode(&p.payload()).unwrap());
    assert!(Blob::parse(&bytes).is_ok());
    assert_eq!(
        bytes.len(),
        HEADER_LEN + Blob::parse(&bytes).unwrap().header().payload_len as usize
    );
    // Only the blob is left in the folder.
    let files: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(files.len(), 1);

    // An invalid payload writes nothing.
    let bad_path = dir.path().join("bad.blob");
    let mut bad = OwnedPayload::example();
    bad.library.fps = 0.0;
    assert!(matches!(
        write_blob(&bad_path, &bad.payload()),
        Err(BlobWriteError::Invalid(BlobError::BadFrameRate))
    ));
    assert!(!bad_path.exists());

    // A missing folder is an I/O error naming the file, and leaves nothing behind.
    let missing = dir.path().join("no/such/dir/x.blob");
    let e = write_blob(&missing, &p.payload()).unwrap_err();
    assert!(matches!(e, BlobWriteError::Io { .. }));
    assert!(e.to_string().contains("x.blob"), "{e}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}
