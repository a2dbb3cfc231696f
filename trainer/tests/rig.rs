//! Rig files: the sample puppet rig (body channels) on the synthetic, ZeroEGGS and Bandai Namco skeletons,
//! the angle convention on planted rotations, the full-skeleton rig, and bad rig files.
//! Tests on `../shared/data` print "skipping: ..." and pass when it is absent.

use std::path::{Path, PathBuf};

use gesture_runtime::rig::{CalError, MAX_CHANNELS};
use gesture_trainer::motion::{read_bvh, Channel, Motion, Skeleton};
use gesture_trainer::rig::{AngleMode, Rig, RigError, WIDE_CAL};
use gesture_trainer::synth;

fn puppet_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../rigs/puppet-8ch.toml")
}

fn puppet() -> Rig {
    Rig::load(puppet_path()).unwrap_or_else(|e| panic!("{e}"))
}

fn data_dir() -> Option<PathBuf> {
    e2e_tests::shared_data("rig", "")
}

const SHOULDERS: [&str; 4] = [
    "left_shoulder_raise",
    "left_shoulder_swing",
    "right_shoulder_raise",
    "right_shoulder_swing",
];

/// Per-channel (min, max) of the puppet's values over a whole take; asserts they are finite.
fn ranges(rig: &Rig, motion: &Motion, label: &str) -> Vec<(f32, f32)> {
    let bound = rig
        .bind(motion.skeleton(), label)
        .unwrap_or_else(|e| panic!("{e}"));
    let values = bound
        .take_values(motion)
        .expect("the motion's own skeleton");
    assert_eq!(values.len(), motion.frames());
    let mut out = vec![(f32::INFINITY, f32::NEG_INFINITY); rig.channels.len()];
    for (f, row) in values.iter().enumerate() {
        assert_eq!(row.len(), rig.channels.len());
        for (k, &v) in row.iter().enumerate() {
            assert!(v.is_finite(), "{label} frame {f} channel {k}: {v}");
            assert!((-180.0..=180.0).contains(&v), "{label}: {v}");
            out[k].0 = out[k].0.min(v);
            out[k].1 = out[k].1.max(v);
        }
    }
    eprintln!("{label}:");
    for (c, (lo, hi)) in bound.channels().iter().zip(&out) {
        eprintln!(
            "  {:22} {:>14} about {:>2} ({:9}): {lo:7.1} .. {hi:7.1} deg",
            c.name, c.joint_name, c.axis, c.mode
        );
    }
    out
}

#[test]
fn puppet_rig_parses() {
    let rig = puppet();
    assert_eq!(rig.name, "puppet-8ch");
    assert_eq!(rig.period_us, 20_000.0);
    let names: Vec<&str> = rig.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "head_pan",
            "head_tilt",
            "left_shoulder_raise",
            "left_shoulder_swing",
            "right_shoulder_raise",
            "right_shoulder_swing",
            "left_elbow",
            "right_elbow"
        ]
    );
    for c in &rig.channels {
        assert_eq!(c.cal.validate(), Ok(()), "{}", c.name);
    }
    assert_eq!(rig.cals().len(), 8);
}

#[test]
fn puppet_binds_to_the_synthetic_skeleton_and_moves() {
    let rig = puppet();
    let bound = rig.bind(&synth::skeleton(), "synthetic").unwrap();
    let joints: Vec<&str> = bound
        .channels()
        .iter()
        .map(|c| c.joint_name.as_str())
        .collect();
    assert_eq!(
        joints,
        [
            "Head",
            "Head",
            "LeftArm",
            "LeftArm",
            "RightArm",
            "RightArm",
            "LeftForeArm",
            "RightForeArm"
        ]
    );
    // Body channels: the head and both arms are measured in the chest's body frame (the
    // nearest common ancestor of the head and the upper arms), so a clavicle's own turn counts
    // in the arm's direction, as it does in what the audience sees.
    assert_eq!(bound.channels()[0].reference.as_deref(), Some("Chest"));
    assert_eq!(bound.channels()[2].reference.as_deref(), Some("Chest"));
    let take = synth::generate_take(7, 0, 20.0, &synth::speaker_for(7));
    let r = ranges(&rig, &take.motion(), "synthetic take");
    // The synthetic right arm strokes; its shoulder and elbow must move.
    for k in [4, 5, 7] {
        assert!(r[k].1 - r[k].0 > 1.0, "channel {k} {:?}", r[k]);
    }
}

/// A skeleton of one rotating joint under a root, with the given rotation channels.
fn one_joint(channels: Vec<Channel>) -> Skeleton {
    use gesture_trainer::motion::Joint;
    Skeleton {
        joints: vec![
            Joint {
                name: "Root".into(),
                parent: None,
                offset: [0.0; 3],
                channels: vec![],
                end_site: None,
            },
            Joint {
                name: "Head".into(),
                parent: Some(0),
                offset: [0.0, 10.0, 0.0],
                channels,
                end_site: Some([0.0, 5.0, 0.0]),
            },
        ],
    }
}

fn three_axes_rig(mode: &str) -> Rig {
    let mut text = String::from("name = \"probe\"\nperiod_us = 20000\n");
    for axis in ["X", "Y", "Z"] {
        text.push_str(&format!(
            "[[channel]]\nname = \"{axis}\"\njoint = [\"head\"]\naxis = \"{axis}\"\n{mode}\n\
             neutral_deg = 0\nmin_deg = -90\nmax_deg = 90\ndirection = 1\n\
             pulse_neutral_us = 1500\nus_per_deg = 10\nmax_slew_deg_per_s = 100\n"
        ));
    }
    Rig::parse(&text, "probe.toml").unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_pure_rotation_about_one_axis_reads_back_exactly() {
    use Channel::{Xrotation, Yrotation, Zrotation};
    for mode in [
        "",
        "mode = \"twist\"",
        "mode = \"euler\"\norder = \"ZYX\"",
        "mode = \"euler\"\norder = \"YZX\"",
        "mode = \"channel\"",
    ] {
        let rig = three_axes_rig(mode);
        for order in [
            vec![Zrotation, Yrotation, Xrotation],
            vec![Zrotation, Xrotation, Yrotation],
            vec![Yrotation, Zrotation, Xrotation],
        ] {
            for axis in 0..3 {
                let sk = one_joint(order.clone());
                // 30 degrees about `axis`, 0 about the others, in the joint's channel order.
                let row: Vec<f64> = order
                    .iter()
                    .map(|c| if c.axis() == axis { 30.0 } else { 0.0 })
                    .collect();
                let m = Motion::new(sk.clone(), 1.0 / 30.0, 1, row).unwrap();
                let v = rig
                    .bind(&sk, "probe")
                    .unwrap()
                    .channel_values(&m, 0)
                    .unwrap();
                for (k, got) in v.iter().enumerate() {
                    let want = if k == axis { 30.0 } else { 0.0 };
                    assert!(
                        (got - want).abs() < 1e-4,
                        "{mode:?}, order {order:?}, rotation about {axis}: channel {k} = {got}"
                    );
                }
            }
        }
    }
}

#[test]
fn channel_values_refuse_other_skeletons_and_frames_out_of_range() {
    let rig = three_axes_rig("");
    let sk = one_joint(vec![
        Channel::Zrotation,
        Channel::Yrotation,
        Channel::Xrotation,
    ]);
    let bound = rig.bind(&sk, "probe").unwrap();
    let m = Motion::new(sk, 1.0 / 30.0, 1, vec![0.0; 3]).unwrap();
    assert!(bound.channel_values(&m, 0).is_some());
    assert!(bound.channel_values(&m, 1).is_none());
    let other = one_joint(vec![Channel::Zrotation]);
    let m2 = Motion::new(other, 1.0 / 30.0, 1, vec![0.0]).unwrap();
    assert!(bound.channel_values(&m2, 0).is_none());
    assert!(bound.take_values(&m2).is_none());
}

#[test]
fn puppet_on_zeroeggs_stays_finite_and_the_shoulders_move() {
    let Some(dir) = data_dir() else { return };
    let m = read_bvh(dir.join("zeroeggs-067-speech2/067_Speech_2_first50s.bvh")).unwrap();
    let rig = puppet();
    let r = ranges(&rig, &m, "ZeroEGGS 067_Speech_2 (50 s)");
    for (c, (lo, hi)) in rig.channels.iter().zip(&r) {
        if SHOULDERS.contains(&c.name.as_str()) {
            assert!(hi - lo > 1.0, "{}: {lo} .. {hi}", c.name);
        }
        // Every channel moves on real speech gesture, and the calibrated limits cover it
        // (the limits were chosen from this take; a change here needs new limits).
        assert!(hi - lo > 1.0, "{}: {lo} .. {hi}", c.name);
        assert!(
            *lo >= c.cal.min_deg - 5.0 && *hi <= c.cal.max_deg + 5.0,
            "{}: {lo} .. {hi} is outside the limits {} .. {}",
            c.name,
            c.cal.min_deg,
            c.cal.max_deg
        );
    }
}

#[test]
fn puppet_binds_to_every_bandai_clip() {
    let Some(dir) = data_dir() else { return };
    let rig = puppet();
    let mut files = Vec::new();
    for sub in ["dataset-1", "dataset-2"] {
        let d = dir.join("bandai-namco-gestures").join(sub);
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "bvh") {
                files.push(p);
            }
        }
    }
    files.sort();
    assert!(!files.is_empty());
    for p in &files {
        let m = read_bvh(p).unwrap();
        let bound = rig.bind(m.skeleton(), &p.display().to_string()).unwrap();
        // No per-skeleton alias: the head is a body measure in the chest's body frame, which
        // comes from the geometry, not from Bandai's joint frames (X up at the chest).
        assert_eq!(bound.channels()[0].mode.to_string(), "body head_pan");
        assert_eq!(bound.channels()[0].joint_name, "Head");
        assert_eq!(bound.channels()[0].reference.as_deref(), Some("Chest"));
        let values = bound.take_values(&m).unwrap();
        assert!(values.iter().flatten().all(|v| v.is_finite()));
    }
    // One clip in detail: both arms raised and waving.
    let wave = files
        .iter()
        .find(|p| p.to_string_lossy().contains("wave-both-hands"))
        .unwrap();
    let m = read_bvh(wave).unwrap();
    let r = ranges(&rig, &m, &wave.file_name().unwrap().to_string_lossy());
    for (k, (lo, hi)) in r.iter().enumerate().skip(2) {
        assert!(hi - lo > 1.0, "channel {k}: {lo} .. {hi}");
    }
    // Mirror symmetry of the conventions: the two arms wave alike, so the left and right
    // channels have similar ranges.
    for (l, rt) in [(2, 4), (3, 5), (6, 7)] {
        let (a, b) = (r[l], r[rt]);
        assert!(
            (a.0 - b.0).abs() < 35.0 && (a.1 - b.1).abs() < 35.0,
            "left {a:?} vs right {b:?}"
        );
    }
}

#[test]
fn full_skeleton_rig_reads_every_rotation_channel() {
    let sk = synth::skeleton();
    let rig = Rig::full_skeleton(&sk).unwrap();
    assert_eq!(rig.channels.len(), 3 * sk.joints.len());
    assert_eq!(rig.channels[0].name, "Hips.Zrotation");
    assert_eq!(rig.channels[3 * 6].name, "LeftArm.Yrotation");
    assert!(rig
        .channels
        .iter()
        .all(|c| c.cal == WIDE_CAL && c.mode == AngleMode::Channel));
    let take = synth::generate_take(3, 0, 5.0, &synth::speaker_for(3));
    let m = take.motion();
    let bound = rig.bind(&sk, "synthetic").unwrap();
    for f in [0, m.frames() / 2, m.frames() - 1] {
        let v = bound.channel_values(&m, f).unwrap();
        let mut k = 0;
        for (j, joint) in sk.joints.iter().enumerate() {
            for &c in joint.channels.iter().filter(|c| c.is_rotation()) {
                let raw = m.value(f, j, c).unwrap();
                let wrapped = (raw + 180.0).rem_euclid(360.0) - 180.0;
                assert!(
                    (f64::from(v[k]) - wrapped).abs() < 1e-4,
                    "{}",
                    rig.channels[k].name
                );
                k += 1;
            }
        }
    }
}

#[test]
fn full_skeleton_rig_fits_zeroeggs() {
    let Some(dir) = data_dir() else { return };
    let m = read_bvh(dir.join("zeroeggs-067-speech2/067_Speech_2_first50s.bvh")).unwrap();
    let rig = Rig::full_skeleton(m.skeleton()).unwrap();
    assert_eq!(rig.channels.len(), 225);
    assert!(rig.channels.len() <= MAX_CHANNELS);
    let v = rig
        .bind(m.skeleton(), "zeroeggs")
        .unwrap()
        .take_values(&m)
        .unwrap();
    assert!(v.iter().flatten().all(|x| x.is_finite()));
}

// ----- bad rig files --------------------------------------------------------------------------

/// A valid one-channel rig with `field` lines replaced or added.
fn one_channel(extra: &str) -> String {
    format!(
        "name = \"t\"\nperiod_us = 20000\n\n[[channel]]\nname = \"elbow\"\n\
         joint = [\"LeftForeArm\", \"lowerarm_l\"]\naxis = \"Y\"\n{extra}"
    )
}

const CAL: &str = "neutral_deg = 0\nmin_deg = -60\nmax_deg = 60\ndirection = 1\n\
                   pulse_neutral_us = 1500\nus_per_deg = 10\nmax_slew_deg_per_s = 250\n";

#[test]
fn missing_joint_names_the_aliases_and_the_joints() {
    let mut rig = Rig::parse(&one_channel(CAL), "t.toml").unwrap();
    rig.channels[0].joint_aliases[1].when_skeleton_has = Some("joint_Root".into());
    let sk = one_joint(vec![Channel::Zrotation]);
    let e = rig.bind(&sk, "probe.bvh").unwrap_err();
    let msg = e.to_string();
    eprintln!("{msg}");
    assert!(matches!(e, RigError::MissingJoint { .. }));
    for want in [
        "probe.bvh",
        "`elbow`",
        "`LeftForeArm`",
        "`lowerarm_l` (if the skeleton has `joint_Root`)",
        "`Root`, `Head`",
    ] {
        assert!(msg.contains(want), "{want:?} not in {msg}");
    }
}

#[test]
fn missing_ancestor_is_reported() {
    let text = one_channel(&format!("relative_to = [\"Chest\"]\n{CAL}"));
    let rig = Rig::parse(&text, "t.toml").unwrap();
    let sk = one_joint(vec![Channel::Zrotation]);
    let mut sk = sk;
    sk.joints[1].name = "LeftForeArm".into();
    let msg = rig.bind(&sk, "probe.bvh").unwrap_err().to_string();
    assert!(
        msg.contains("`Chest`") && msg.contains("ancestors are `Root`"),
        "{msg}"
    );
}

#[test]
fn bad_toml_gives_line_and_column() {
    let text = "name = \"t\"\nperiod_us = 20000\n[[channel]]\nname = \"a\"\naxis = = \"Y\"\n";
    let e = Rig::parse(text, "bad.toml").unwrap_err();
    eprintln!("{e}");
    match &e {
        RigError::Toml { line, column, .. } => {
            assert_eq!(*line, 5);
            assert!(*column >= 7, "column {column}");
        }
        other => panic!("{other:?}"),
    }
    assert!(e.to_string().starts_with("bad.toml:5:"), "{e}");

    // A typo in a key is an error at that key, not a silent default.
    let typo = one_channel(&CAL.replace("max_slew_deg_per_s", "max_slew_deg_per_sec"));
    let e = Rig::parse(&typo, "typo.toml").unwrap_err();
    eprintln!("{e}");
    assert!(matches!(e, RigError::Toml { line: 14, .. }), "{e:?}");
    assert!(e.to_string().contains("max_slew_deg_per_sec"), "{e}");

    // A missing key names it.
    let missing = one_channel(&CAL.replace("us_per_deg = 10\n", ""));
    let e = Rig::parse(&missing, "missing.toml").unwrap_err();
    assert!(e.to_string().contains("us_per_deg"), "{e}");
}

#[test]
fn invalid_calibration_names_channel_and_line() {
    let text = one_channel(
        &CAL.replace("min_deg = -60", "min_deg = 70")
            .replace("neutral_deg = 0", "neutral_deg = 65"),
    );
    let e = Rig::parse(&text, "cal.toml").unwrap_err();
    eprintln!("{e}");
    assert!(
        matches!(
            e,
            RigError::Calibration {
                line: 5,
                error: CalError::EmptyRange,
                ..
            }
        ),
        "{e:?}"
    );
    assert_eq!(
        e.to_string(),
        "cal.toml:5: channel `elbow`: invalid calibration: min_deg must be below max_deg"
    );
    let wide = one_channel(&CAL.replace("us_per_deg = 10", "us_per_deg = 20"));
    let e = Rig::parse(&wide, "cal.toml").unwrap_err();
    assert!(matches!(
        e,
        RigError::Calibration {
            error: CalError::PulseOutOfRange,
            ..
        }
    ));
}

#[test]
fn other_bad_rigs() {
    let cases: Vec<(String, &str)> = vec![
        (
            one_channel(CAL).replace("axis = \"Y\"", "axis = \"W\""),
            "unknown axis `W`",
        ),
        (
            one_channel(CAL).replace("joint = [\"LeftForeArm\", \"lowerarm_l\"]", "joint = []"),
            "empty `joint` list",
        ),
        (
            one_channel(CAL).replace("joint = [\"LeftForeArm\", \"lowerarm_l\"]", ""),
            "empty `joint` list and no `body`",
        ),
        (
            one_channel(CAL).replace("axis = \"Y\"", ""),
            "needs an `axis`",
        ),
        (
            one_channel(&format!("body = \"tail_wag\"\n{CAL}")),
            "unknown body measure `tail_wag`; use one of head_pan,",
        ),
        (
            one_channel(&format!("body = \"left_elbow_flex\"\n{CAL}"))
                .replace("joint = [\"LeftForeArm\", \"lowerarm_l\"]", ""),
            "`axis` applies to `joint` aliases and this channel has none",
        ),
        (
            one_channel(&format!("mode = \"euler\"\n{CAL}")),
            "needs an `order`",
        ),
        (
            one_channel(&format!("mode = \"euler\"\norder = \"XXY\"\n{CAL}")),
            "unknown Euler order `XXY`",
        ),
        (
            one_channel(&format!("order = \"ZYX\"\n{CAL}")),
            "`order` only applies",
        ),
        (
            one_channel(&format!("mode = \"swing\"\n{CAL}")),
            "unknown mode `swing`",
        ),
        (
            one_channel(&format!(
                "mode = \"channel\"\nrelative_to = [\"Chest\"]\n{CAL}"
            )),
            "remove `relative_to`",
        ),
        (
            one_channel(CAL).replace("period_us = 20000", "period_us = 1000"),
            "period_us = 1000",
        ),
        (
            "name = \"empty\"\nperiod_us = 20000\n".to_string(),
            "has no channels",
        ),
        (
            format!(
                "{}[[channel]]\nname = \"elbow\"\njoint = [\"X\"]\naxis = \"Y\"\n{CAL}",
                one_channel(CAL)
            ),
            "used twice",
        ),
        (
            one_channel(CAL).replace("\"lowerarm_l\"", "{ name = \"lowerarm_l\", axs = \"Y\" }"),
            "axs",
        ),
    ];
    for (text, want) in cases {
        let e = Rig::parse(&text, "bad.toml").unwrap_err().to_string();
        eprintln!("{e}");
        assert!(e.contains(want), "{want:?} not in {e:?}");
        assert!(e.starts_with("bad.toml"), "{e}");
    }

    let mut many = String::from("name = \"many\"\nperiod_us = 20000\n");
    for k in 0..=MAX_CHANNELS {
        many.push_str(&format!(
            "[[channel]]\nname = \"c{k}\"\njoint = [\"Head\"]\naxis = \"Y\"\n{CAL}"
        ));
    }
    let e = Rig::parse(&many, "many.toml").unwrap_err();
    assert!(
        matches!(e, RigError::TooManyChannels { count, max, .. } if count == MAX_CHANNELS + 1 && max == MAX_CHANNELS),
        "{e:?}"
    );

    let e = Rig::load("/nonexistent/rig.toml").unwrap_err();
    assert!(matches!(e, RigError::Io { .. }));
    assert!(
        e.to_string()
            .starts_with("/nonexistent/rig.toml: cannot read"),
        "{e}"
    );
}

/// The alias format of earlier rig files (per-skeleton joint names and axes, as the shipped
/// puppet used before its channels became body measures) still parses and binds, and a
/// channel with both `joint` and `body` reads the joint where an alias applies and the body
/// measure elsewhere.
#[test]
fn joint_alias_rigs_still_work_and_override_body_measures() {
    let old = "name = \"old\"\nperiod_us = 20000\n\n[[channel]]\nname = \"head_pan\"\n\
               joint = [{ name = \"Head\", axis = \"X\", when_skeleton_has = \"joint_Root\" }, \"Head\"]\n\
               axis = \"Y\"\nrelative_to = [\"Spine3\", \"Chest\"]\n\
               neutral_deg = 0\nmin_deg = -60\nmax_deg = 60\ndirection = 1\n\
               pulse_neutral_us = 1500\nus_per_deg = 10\nmax_slew_deg_per_s = 200\n\n\
               [[channel]]\nname = \"left_elbow\"\njoint = [\"NoSuchJoint\"]\naxis = \"-Y\"\n\
               body = \"left_elbow_flex\"\n\
               neutral_deg = 20\nmin_deg = 0\nmax_deg = 150\ndirection = 1\n\
               pulse_neutral_us = 950\nus_per_deg = 10\nmax_slew_deg_per_s = 300\n";
    let rig = Rig::parse(old, "old.toml").unwrap_or_else(|e| panic!("{e}"));
    let bound = rig.bind(&synth::skeleton(), "synthetic").unwrap();
    let c = bound.channels();
    assert_eq!(
        (c[0].mode, c[0].axis.to_string()),
        (AngleMode::Twist, "Y".to_string())
    );
    assert_eq!(c[0].reference.as_deref(), Some("Chest"));
    assert_eq!(c[1].mode.to_string(), "body left_elbow_flex");
    // Where the alias applies, the joint wins over the body measure.
    let text = old.replace("NoSuchJoint", "LeftForeArm");
    let rig = Rig::parse(&text, "old.toml").unwrap();
    let bound = rig.bind(&synth::skeleton(), "synthetic").unwrap();
    assert_eq!(bound.channels()[1].mode, AngleMode::Twist);
    assert_eq!(bound.channels()[1].joint_name, "LeftForeArm");
}
