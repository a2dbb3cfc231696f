//! The blob writer (feature `encode`): typed constructors quantize and lay out the tables,
//! the result round-trips through the reader within half a quantization step, and errors
//! are typed (a rule of the format broken comes back as the reader's error).

use gesture_runtime::blob::encode::*;
use gesture_runtime::blob::{Blob, BlobError, ControlSection, FrontEndSection};
use gesture_runtime::controller::DecisionTiming;
use gesture_runtime::follow::VoiceFollow;
use gesture_runtime::inference::GmmComponent;
use gesture_runtime::policy::Variety;
use gesture_runtime::prosody::ProsodyConfig;
use gesture_runtime::rig::ChannelCal;

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

/// Within half a step of a symmetric table whose largest magnitude is `max`.
fn near(got: f32, want: f64, max: f64) {
    let half = 0.5 * max / 32767.0;
    assert!(
        (got as f64 - want).abs() <= half * 1.001 + 1e-6,
        "{got} vs {want}"
    );
}

#[test]
fn constructors_round_trip_through_the_reader() {
    let gmm = [
        GMM0,
        GmmComponent {
            mean: [1.0, 2.0],
            ..GMM0
        },
    ];
    let obs: Vec<f64> = (0..12).map(|i| i as f64 * 0.01).collect();
    let inference = OwnedInference::new(&gmm, 2, &[0.1, 0.2, 0.3], &[0.0; 9], &obs).unwrap();
    assert_eq!(inference.components(), gmm);
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
            continues: i < 3,
        })
        .collect();
    // Channels 0..3 hold one rotation (Z, Y, X: EULER_ORDERS index 5).
    let library = OwnedLibrary::new(25.0, 3, &frames, &segs, &[3, 17], &[(0, 5)])
        .unwrap()
        .with_calm(&[0, 9, 19, 20])
        .with_energy(&[-1.0, 0.03, 2.5, 100.0]);
    // Exits: an interruption at frame 2 of every segment and the end at frame 4.
    let exits: Vec<(usize, usize)> = (0..4).flat_map(|s| [(s, 2), (s, 4)]).collect();
    // End exits: two successors sorted by segment; interruptions: none.
    let successors: Vec<Vec<(usize, f64)>> = exits
        .iter()
        .map(|&(s, f)| {
            let mut l = if f == 4 {
                vec![((s + 1) % 4, 1.0), ((s + 2) % 4, -2.0)]
            } else {
                vec![]
            };
            l.sort_by_key(|x| x.0);
            l
        })
        .collect();
    let u: Vec<f64> = (0..12).map(|i| i as f64 * 5.0).collect();
    let u_cont: Vec<f64> = (0..24).map(|i| i as f64 * 0.25).collect();
    let policy = OwnedPolicy::new(&PolicyInput {
        states: 3,
        segments: 4,
        discount: 0.95,
        u: &u,
        u_cont: &u_cont,
        exits: &exits,
        successors: &successors,
    })
    .unwrap();
    let names = ["pan", "tilt", "jaw"];
    let rig_ch: Vec<(String, ChannelCal)> = names
        .iter()
        .map(|n| (n.to_string(), ChannelCal::HOBBY))
        .collect();
    let rig = OwnedRig::new("puppet", 20_000.0, &rig_ch).unwrap();
    let timing = DecisionTiming {
        sync_to_onsets: false,
        onset_window_ms: 0,
        max_wait_ms: 120,
        beat_hold_ms: 90,
        defer_cut_ms: 70,
    };
    let variety = Variety {
        recency_cost: 1.25,
        recency_ms: 4000,
        usage_cost: 3.0,
        usage_ms: 20000,
    };
    let follow = VoiceFollow {
        rest_ms: 600,
        rest_cost: 3.5,
        energy_cost: 0.75,
    };
    let owned = OwnedPayload {
        front_end: FrontEndSection::from_config(&ProsodyConfig::DEFAULT),
        inference,
        policy,
        control: ControlSection::new(&timing, &variety, &follow, 200),
        library,
        rig,
        skeleton: None,
        // Two tones over 4 segments, 8 exits and 3 states; one scale for both.
        styles: Some(
            OwnedStyles::new(
                &["calm", "lively"],
                &[
                    (0..12).map(|v| v as f64).collect(),
                    (0..12).map(|v| -2.0 * v as f64).collect(),
                ],
                &[vec![0.5; 24], vec![-0.5; 24]],
            )
            .unwrap(),
        ),
        labels: None,
    };
    let bytes = owned.encode().unwrap();
    let b = Blob::parse(&bytes).unwrap();
    assert_eq!((b.states(), b.clusters(), b.window()), (3, 2, 2));
    assert_eq!(b.gmm_component(1).unwrap().mean, [1.0, 2.0]);
    near(b.crf_weights().obs.get(11), 0.11, 0.11);
    near(b.crf_weights().init.get(2), 0.3, 0.3);
    assert_eq!(b.timing(), timing);
    assert_eq!(b.variety(), variety);
    assert_eq!(b.follow(), follow);
    assert_eq!(b.blend_ms(), 200);
    assert!(b.continues(0) && b.continues(2) && !b.continues(3));
    let beats: Vec<usize> = (0..20).filter(|&f| b.is_beat_frame(f)).collect();
    assert_eq!(beats, [3, 17]);
    // Calm frames as given; one past the frame table is dropped.
    let calm: Vec<usize> = (0..24).filter(|&f| b.is_calm_frame(f)).collect();
    assert_eq!(calm, [0, 9, 19]);
    // Energies in steps of 1/16, saturating at the i8's range.
    let energy: Vec<f32> = (0..4).map(|c| b.segment_energy(c)).collect();
    assert_eq!(energy, [-1.0, 0.0, 2.5, 127.0 / 16.0]);
    assert_eq!((b.group_count(), b.group(0)), (1, Some((0, [2, 1, 0]))));
    // Frames come back within half a quantization step of each channel's range.
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
    assert_eq!((s[0].0, s[1].0), (1, 2));
    near(s[0].1, 1.0, 2.0);
    near(s[1].1, -2.0, 2.0);
    assert_eq!(b.successors(0).len(), 0);
    near(b.u(3, 2), 55.0, 55.0);
    near(b.u_cont(7, 1), 5.5, 5.75);
    assert!((b.discount() - 0.95).abs() < 1e-7);
    assert_eq!(b.channel_names().collect::<Vec<_>>(), names);
    assert_eq!(b.rig_name(), "puppet");
    assert_eq!(b.fps(), 25.0);
    // Tones: U^calm(3, 2) = 11, U^lively(3, 2) = -22 (the scale is 22 / 32767 for both).
    assert_eq!(b.tone_names().collect::<Vec<_>>(), ["calm", "lively"]);
    near(b.tone_u(0, 3, 2), 11.0, 22.0);
    near(b.tone_u(1, 3, 2), -22.0, 22.0);
    near(b.tone_u_cont(1, 7, 1), -0.5, 0.5);
    // A line break in a name, or tables that do not match the names, are refused.
    assert!(OwnedStyles::new(&["a\nb"], &[vec![]], &[vec![]]).is_err());
    assert!(OwnedStyles::new(&["a", "b"], &[vec![]], &[vec![]]).is_err());
}

/// The labels writer: the example's segment 1 carries label 2 (`bye`) with its stroke at
/// frame 1; entries from its 3 exit points.
#[test]
fn labels_are_written_and_read_back() {
    let mut p = OwnedPayload::example();
    let entries = vec![vec![(1usize, 0.5f64)], vec![(0, -0.25)], vec![(1, 0.0)]];
    let input = LabelsInput {
        names: &["hello", "bye"],
        semantic_cost: 5.0,
        timeout_ms: 2500,
        segments: &[1],
        u: &[vec![1.0, 2.0, 3.0, 4.0], vec![-4.0, -3.0, -2.0, -1.0]],
        u_cont: &[vec![0.5; 6], vec![0.25; 6]],
        entries: &entries,
    };
    p.labels = Some(OwnedLabels::new(&input).unwrap());
    let bytes = p.encode().unwrap();
    let b = Blob::parse(&bytes).unwrap();
    assert_eq!(b.label_names().collect::<Vec<_>>(), ["hello", "bye"]);
    assert_eq!((b.labels(), b.labelled_count(), b.label_of(1)), (2, 1, 2));
    assert_eq!((b.semantic_cost(), b.label_timeout_ms()), (5.0, 2500));
    let (f, c) = b.entry(0, 0).unwrap();
    assert_eq!(f, 1);
    near(c, 0.5, 0.5);
    near(b.entry(1, 0).unwrap().1, -0.25, 0.5);
    let belief = [1.0f32, 0.0];
    near(b.label_u_dot(1, 1, &belief), -2.0, 4.0);
    near(b.label_u_cont_dot(0, 2, &belief), 0.5, 0.5);
    // Tables that do not match the names, rows of the wrong length, or an entry after the
    // stroke are refused.
    let mut i = input;
    i.names = &["a"];
    assert!(OwnedLabels::new(&i).is_err());
    let short = vec![vec![], vec![], vec![]];
    let mut i = input;
    i.entries = &short;
    assert!(OwnedLabels::new(&i).is_err());
    let late = vec![vec![(2usize, 0.0f64)], vec![(0, 0.0)], vec![(0, 0.0)]];
    let mut i = input;
    i.entries = &late;
    p.labels = Some(OwnedLabels::new(&i).unwrap());
    assert!(matches!(
        p.encode(),
        Err(gesture_runtime::blob::encode::EncodeError::Invalid(
            BlobError::EntryAfterStroke { entry: 0 }
        ))
    ));
}

#[test]
fn example_payload_is_valid() {
    let p = OwnedPayload::example();
    let b_bytes = p.encode().unwrap();
    let b = Blob::parse(&b_bytes).unwrap();
    assert_eq!(b.rig_name(), "example");
    assert!((b.frame(0, 5) + 20.0).abs() < 1e-3);
    assert_eq!(b.timing(), DecisionTiming::DEFAULT);
}

#[test]
fn builder_errors_are_typed() {
    let u = [0.0; 2];
    let input = PolicyInput {
        states: 1,
        segments: 2,
        discount: 0.9,
        u: &u,
        u_cont: &u,
        exits: &[(0, 0), (70_000, 0)],
        successors: &[vec![], vec![]],
    };
    let e = OwnedPolicy::new(&input).unwrap_err();
    assert!(matches!(
        e,
        EncodeError::TooLarge {
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
    assert!(matches!(e, EncodeError::Inconsistent(_)), "{e}");
    let e = OwnedLibrary::new(30.0, 2, &[vec![1.0]], &[], &[], &[]).unwrap_err();
    assert!(e.to_string().contains("1 values for 2 channels"), "{e}");
    let e = OwnedLibrary::new(30.0, 1, &[vec![f32::NAN]], &[], &[], &[]).unwrap_err();
    assert!(matches!(e, EncodeError::Inconsistent(_)));
    let e = OwnedRig::new("r", 20_000.0, &[("a\nb".into(), ChannelCal::HOBBY)]).unwrap_err();
    assert!(e.to_string().contains("newline"), "{e}");
    let e = OwnedInference::new(&[GMM0], 1, &[0.0; 2], &[0.0; 3], &[0.0; 2]).unwrap_err();
    assert!(matches!(e, EncodeError::Inconsistent(_)), "{e}");

    // A rule of the format broken: the reader's error comes back.
    let mut p = OwnedPayload::example();
    p.policy.succ = [1i16, 5, 0, -5, 0, 7, 1, 0]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let e = p.encode().unwrap_err();
    assert!(matches!(
        e,
        EncodeError::Invalid(BlobError::SuccessorsNotSorted { exit: 0 })
    ));
    assert!(e.to_string().contains("refused by the runtime"), "{e}");
    let mut bad = OwnedPayload::example();
    bad.library.fps = 0.0;
    assert!(matches!(
        bad.encode(),
        Err(EncodeError::Invalid(BlobError::BadFrameRate))
    ));
}
