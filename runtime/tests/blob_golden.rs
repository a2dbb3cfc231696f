//! The policy blob: golden bytes, round trip of every field, CRC known answer, and the
//! writer (feature `encode`) against the hand-built bytes.

mod common;

use common::*;
use gesture_runtime::blob::*;
use gesture_runtime::prosody::ProsodyConfig;
use gesture_runtime::rig::ChannelCal;

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
        sz.front_end
            + sz.inference
            + sz.policy
            + sz.control
            + sz.library
            + sz.rig
            + sz.skeleton
            + sz.styles
            + sz.labels,
        h.payload_len as usize
    );
    assert_eq!(
        (sz.styles, sz.labels),
        (1, 1),
        "absent sections are postcard's None"
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
    // control
    assert_eq!(sz.control, 33);
    let t = blob.timing();
    assert_eq!(
        (
            t.sync_to_onsets,
            t.onset_window_ms,
            t.max_wait_ms,
            t.beat_hold_ms,
            t.defer_cut_ms
        ),
        (true, 50, 300, 150, 200)
    );
    let v = blob.variety();
    assert_eq!(
        (v.recency_cost, v.recency_ms, v.usage_cost, v.usage_ms),
        (1.5, 5000, 4.0, 30000)
    );
    assert_eq!(blob.blend_ms(), 250);
    let f = blob.follow();
    assert_eq!((f.rest_ms, f.rest_cost, f.energy_cost), (750, 2.5, 1.5));
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
    assert!(blob.continues(0) && !blob.continues(1) && !blob.continues(2));
    let beats: Vec<usize> = (0..8).filter(|&f| blob.is_beat_frame(f)).collect();
    assert_eq!(beats, [1, 4]);
    let calm: Vec<usize> = (0..8).filter(|&f| blob.is_calm_frame(f)).collect();
    assert_eq!(calm, [0, 5]);
    let peaks: Vec<usize> = (0..8).filter(|&f| blob.is_peak_frame(f)).collect();
    assert_eq!(peaks, [2]);
    assert_eq!(
        (blob.segment_energy(0), blob.segment_energy(1)),
        (-1.0, 1.5)
    );
    assert_eq!(blob.segment_energy(2), 0.0);
    assert_eq!((blob.group_count(), blob.group(0)), (0, None));
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
    assert_eq!(
        (sk.channel(3), sk.channel(9)),
        (Some(BvhChannel::Zrotation), None)
    );
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
    // 0..=7: twist, channel and the six Euler orders; 8..=16: the body measures.
    for code in 0..17u8 {
        assert_eq!(DriveMode::from_code(code).map(DriveMode::code), Some(code));
    }
    assert_eq!(DriveMode::from_code(8), Some(DriveMode::Body(0)));
    assert_eq!(DriveMode::from_code(17), None);
    assert_eq!(DriveMode::Body(9).code(), 0xFF);
    // Without the section: one byte (postcard's None), and no skeleton.
    let mut bare = Tiny::new();
    bare.skeleton = None;
    let bytes = bare.encode();
    let b = Blob::parse(&bytes).unwrap();
    assert_eq!((b.skeleton(), b.section_sizes().skeleton), (None, 1));
}

/// The writer puts the same bytes around the same payload as the hand-built golden blob.
#[cfg(feature = "encode")]
#[test]
fn the_writer_produces_the_golden_bytes() {
    let tiny = Tiny::new();
    let bytes = gesture_runtime::blob::encode::encode(&tiny.payload()).unwrap();
    let want: String = GOLDEN.chars().filter(|c| !c.is_whitespace()).collect();
    assert_eq!(hex(&bytes), want);
}
