//! The policy blob's errors: every variant of `BlobError` is reachable, each from the tiny
//! blob with one field broken.

mod common;

use std::collections::BTreeSet;

use common::*;
use gesture_runtime::blob::*;
use gesture_runtime::inference::{MAX_CLUSTERS, MAX_STATES, MAX_WINDOW};
use gesture_runtime::prosody::ConfigError;
use gesture_runtime::rig::{CalError, ChannelCal};

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
    "BadControl",
    "BadContinuation",
    "BadGroup",
    "TooManyJoints",
    "JointNameCount",
    "BadParent",
    "BadJointChannels",
    "BadEndSite",
    "BadDrive",
    "TooManyTones",
    "BadToneNames",
    "TooManyLabels",
    "BadLabelNames",
    "BadLabelledSegment",
    "EntryAfterStroke",
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
    for v in [1u16, 2, 4, FORMAT_VERSION + 1] {
        let mut b = good.clone();
        b[4..6].copy_from_slice(&v.to_le_bytes());
        check(&b, BlobError::UnsupportedVersion { found: v });
    }
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
    // A byte after the last section (`labels`, absent).
    let mut b = good.clone();
    b.push(0);
    fix_crc(&mut b);
    check(
        &b,
        BlobError::Malformed {
            section: Section::Labels,
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
    // Without skeleton, styles and labels the payload ends `00 00 00`: cut those and two bytes
    // of the rig.
    let mut b = mutated(&|t| t.skeleton = None);
    b.truncate(b.len() - 5);
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
    check(
        &mutated(&|t| t.continues = vec![0]),
        BlobError::TableLength {
            field: Field::Continues,
            expected: 2,
            found: 1,
        },
    );
    check(
        &mutated(&|t| t.beats = vec![]),
        BlobError::TableLength {
            field: Field::Beats,
            expected: 1,
            found: 0,
        },
    );
    check(
        &mutated(&|t| t.calm = vec![0, 0]),
        BlobError::TableLength {
            field: Field::Calm,
            expected: 1,
            found: 2,
        },
    );
    check(
        &mutated(&|t| t.peaks = vec![]),
        BlobError::TableLength {
            field: Field::Peaks,
            expected: 1,
            found: 0,
        },
    );
    check(
        &mutated(&|t| t.energy = vec![0]),
        BlobError::TableLength {
            field: Field::Energy,
            expected: 2,
            found: 1,
        },
    );
    check(
        &mutated(&|t| t.groups = vec![0, 0]),
        BlobError::TableLength {
            field: Field::Groups,
            expected: 0,
            found: 2,
        },
    );
    // Segment 1 is the last: it cannot be continued.
    check(
        &mutated(&|t| t.continues = vec![1, 1]),
        BlobError::BadContinuation { segment: 1 },
    );
    check(
        &mutated(&|t| {
            t.continues = vec![1, 0];
            t.seg_start = le_u32(&[0, 2]);
        }),
        BlobError::BadContinuation { segment: 0 },
    );
    check(
        &mutated(&|t| t.continues = vec![2, 0]),
        BlobError::BadContinuation { segment: 0 },
    );
    // One channel: a rotation group (three channels) cannot fit.
    check(
        &mutated(&|t| t.groups = vec![0, 0, 5]),
        BlobError::BadGroup { group: 0 },
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

    // control.
    check(
        &mutated(&|t| t.control.sync_to_onsets = 2),
        BlobError::BadControl {
            field: Field::SyncToOnsets,
        },
    );
    check(
        &mutated(&|t| t.control.onset_window_ms = 1001),
        BlobError::BadControl {
            field: Field::OnsetWindow,
        },
    );
    check(
        &mutated(&|t| t.control.max_wait_ms = 5001),
        BlobError::BadControl {
            field: Field::MaxWait,
        },
    );
    check(
        &mutated(&|t| t.control.recency_cost = f32::NAN),
        BlobError::BadControl {
            field: Field::Recency,
        },
    );
    check(
        &mutated(&|t| t.control.usage_cost = -1.0),
        BlobError::BadControl {
            field: Field::Usage,
        },
    );
    check(
        &mutated(&|t| t.control.blend_ms = 5001),
        BlobError::BadControl {
            field: Field::Blend,
        },
    );
    check(
        &mutated(&|t| t.control.beat_hold_ms = 1001),
        BlobError::BadControl {
            field: Field::BeatHold,
        },
    );
    check(
        &mutated(&|t| t.control.defer_cut_ms = 1001),
        BlobError::BadControl {
            field: Field::DeferCut,
        },
    );
    check(
        &mutated(&|t| t.control.rest_ms = 10_001),
        BlobError::BadControl {
            field: Field::RestAfter,
        },
    );
    for bad in [-1.0, f32::NAN, f32::INFINITY, 2.0e6] {
        check(
            &mutated(&|t| t.control.rest_cost = bad),
            BlobError::BadControl {
                field: Field::RestCost,
            },
        );
        check(
            &mutated(&|t| t.control.energy_cost = bad),
            BlobError::BadControl {
                field: Field::EnergyCost,
            },
        );
    }

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
    // Modes 0..=16 are defined (8..=16 are the body measures); 17 is the first unknown one.
    assert!(Blob::parse(&sk(&|s| s.drives[5] = 16)).is_ok());
    check(
        &sk(&|s| s.drives[5] = 17),
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

    // Styles: two tones over the tiny policy (2 segments, 3 exits, 2 states) are valid.
    let st = |f: &dyn Fn(&mut TinyStyles)| {
        mutated(&|t| {
            let mut s = TinyStyles::two(4, 6);
            f(&mut s);
            t.styles = Some(s);
        })
    };
    let good_styles = st(&|_| {});
    let b = Blob::parse(&good_styles).unwrap();
    assert_eq!(b.tones(), 2);
    assert_eq!(b.tone_names().collect::<Vec<_>>(), ["calm", "lively"]);
    assert_eq!(b.tone_index("lively"), Some(1));
    assert_eq!(b.tone_index("neutral"), None);
    // U^calm(1, 1) is the 4th value (1-based) = 4; U^lively(0, 0) = -1; U_cont^lively(2, 1) =
    // -6 * 0.5.
    assert_eq!(
        (b.tone_u(0, 1, 1), b.tone_u(1, 0, 0), b.tone_u_cont(1, 2, 1)),
        (4.0, -1.0, -3.0)
    );
    assert_eq!(b.tone_u(2, 0, 0), 0.0, "out of range reads 0");
    assert_eq!(Blob::parse(&good).unwrap().tones(), 0);
    check(
        &st(&|s| s.tones = 0),
        BlobError::ZeroCount {
            field: Field::Tones,
        },
    );
    check(&st(&|s| s.tones = 9), BlobError::TooManyTones { found: 9 });
    check(
        &st(&|s| s.names = "calm".into()),
        BlobError::BadToneNames { tone: 1 },
    );
    check(
        &st(&|s| s.names = "calm\ncalm".into()),
        BlobError::BadToneNames { tone: 1 },
    );
    check(
        &st(&|s| s.names = "neutral\nlively".into()),
        BlobError::BadToneNames { tone: 0 },
    );
    check(
        &st(&|s| s.names = "\nlively".into()),
        BlobError::BadToneNames { tone: 0 },
    );
    check(
        &st(&|s| s.names = "calm\nlively\nsad".into()),
        BlobError::BadToneNames { tone: 2 },
    );
    check(
        &st(&|s| {
            s.u.1.pop();
        }),
        BlobError::TableLength {
            field: Field::ToneU,
            expected: 16,
            found: 15,
        },
    );
    check(
        &st(&|s| s.u_cont.1.extend([0, 0])),
        BlobError::TableLength {
            field: Field::ToneUCont,
            expected: 24,
            found: 26,
        },
    );
    check(
        &st(&|s| s.u_cont.0 = f32::NAN),
        BlobError::NotFinite {
            field: Field::ToneUCont,
        },
    );

    // Labels: one on segment 1 (`bye`, stroke frame 1) is valid.
    let lb = |f: &dyn Fn(&mut Tiny, &mut TinyLabels)| {
        let mut t = Tiny::new();
        let mut l = TinyLabels::one();
        f(&mut t, &mut l);
        t.label_section = Some(l);
        t.encode()
    };
    let good_labels = lb(&|_, _| {});
    let b = Blob::parse(&good_labels).unwrap();
    assert_eq!((b.labels(), b.labelled_count()), (2, 1));
    assert_eq!(b.label_names().collect::<Vec<_>>(), ["hello", "bye"]);
    assert_eq!((b.label_of(1), b.label_of(0)), (2, 0));
    assert_eq!(b.entry(2, 0), Some((1, 0.25)));
    assert_eq!(b.entry(3, 0), None);
    assert_eq!(b.label_timeout_ms(), 2000);
    // Without a labels section the library's label bytes are ignored.
    assert_eq!(Blob::parse(&good).unwrap().label_of(1), 0);
    check(
        &lb(&|_, l| l.labels = 0),
        BlobError::ZeroCount {
            field: Field::LabelCount,
        },
    );
    check(
        &lb(&|_, l| l.labels = 17),
        BlobError::TooManyLabels { found: 17 },
    );
    check(
        &lb(&|_, l| l.names = "hello\nhello".into()),
        BlobError::BadLabelNames { label: 1 },
    );
    check(
        &lb(&|_, l| l.semantic_cost = -1.0),
        BlobError::BadControl {
            field: Field::SemanticCost,
        },
    );
    // Segment 1's label byte (2) is above a single label.
    check(
        &lb(&|_, l| {
            l.labels = 1;
            l.names = "bye".into();
            l.u.1.truncate(8);
            l.u_cont.1.truncate(12);
        }),
        BlobError::BadLabelledSegment { segment: 1 },
    );
    check(
        &lb(&|_, l| l.segments = vec![0, 0]),
        BlobError::BadLabelledSegment { segment: 1 },
    );
    check(
        &lb(&|_, l| l.segments = vec![]),
        BlobError::BadLabelledSegment { segment: 1 },
    );
    check(
        &lb(&|_, l| l.entries[4] = 2),
        BlobError::EntryAfterStroke { entry: 1 },
    );
    check(
        &lb(&|_, l| {
            l.entries.pop();
        }),
        BlobError::TableLength {
            field: Field::LabelEntries,
            expected: 12,
            found: 11,
        },
    );
    check(
        &lb(&|_, l| l.u.1.extend([0, 0])),
        BlobError::TableLength {
            field: Field::LabelU,
            expected: 16,
            found: 18,
        },
    );

    let all: BTreeSet<&str> = ALL.iter().copied().collect();
    let missing: Vec<_> = all.difference(&hit).collect();
    assert!(missing.is_empty(), "never triggered: {missing:?}");
}
