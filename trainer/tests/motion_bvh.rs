//! BVH reader/writer and forward kinematics on hand-written files: rotation orders, whitespace,
//! number formats, end sites, 0-channel joints, every error with its file and line, a
//! no-panic mutation sweep, parse speed, and FK against hand-computed trigonometry.

use gesture_trainer::motion::fk::{self, Target};
use gesture_trainer::motion::{
    parse_bvh, read_bvh, write_bvh, BvhError, BvhErrorKind, Channel, Motion,
};
use std::time::Instant;

/// Root with 6 channels (Z Y X), a 3-channel Z X Y joint with an end site, a 0-channel joint
/// without a CHANNELS line, and a 3-channel X Y Z joint.
const MIXED: &str = "HIERARCHY
ROOT Hips
{
\tOFFSET 0.0 90.0 0.0
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
\tJOINT Left Arm
\t{
\t\tOFFSET 1.5e1 0 -2.5E-1
\t\tCHANNELS 3 Zrotation Xrotation Yrotation
\t\tEnd Site
\t\t{
\t\t\tOFFSET 10 0 0
\t\t}
\t}
\tJOINT Fixed
\t{
\t\tOFFSET 0 5 0
\t\tJOINT Head
\t\t{
\t\t\tOFFSET 0 10 0
\t\t\tCHANNELS 3 Xrotation Yrotation Zrotation
\t\t}
\t}
}
MOTION
Frames: 3
Frame Time: 0.0333333
1.0 90.5 -2.0 10 20 30 1e-5 -4.5 0.25 7 8 9
2.0 91.5 -3.0 11 21 31 2 -5.5 1.25 -7 -8 -9
3.0 92.5 -4.0 12 22 32 3 -6.5 2.25 70.123456 80 90
";

fn syntax(e: &BvhError) -> (usize, BvhErrorKind) {
    match e {
        BvhError::Syntax { line, kind, .. } => (*line, kind.clone()),
        BvhError::Io { .. } => panic!("expected a syntax error, got {e}"),
    }
}

fn rel_close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-6 * a.abs().max(b.abs()) + 1e-24
}

fn assert_same_motion(a: &Motion, b: &Motion) {
    assert_eq!(a.skeleton(), b.skeleton());
    assert_eq!(a.frames(), b.frames());
    assert_eq!(a.frame_time(), b.frame_time());
    for (i, (x, y)) in a.data().iter().zip(b.data()).enumerate() {
        assert!(rel_close(*x, *y), "value {i}: {x} vs {y}");
    }
}

fn round_trip(m: &Motion) -> Motion {
    let mut out = Vec::new();
    write_bvh(m, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains("\n\tJOINT ") || m.skeleton().joints.len() < 2);
    parse_bvh(&text, "rewritten.bvh").unwrap()
}

#[test]
fn mixed_orders_spaces_scientific_end_sites_and_zero_channels() {
    let m = parse_bvh(MIXED, "mixed.bvh").unwrap();
    let s = m.skeleton();
    let names: Vec<_> = s.joint_names().collect();
    assert_eq!(names, ["Hips", "Left Arm", "Fixed", "Head"]);
    assert_eq!(
        s.joints[0].channels[3..],
        [Channel::Zrotation, Channel::Yrotation, Channel::Xrotation]
    );
    assert_eq!(
        s.joints[1].channels,
        [Channel::Zrotation, Channel::Xrotation, Channel::Yrotation]
    );
    assert!(s.joints[2].channels.is_empty());
    assert_eq!(s.joints[3].parent, Some(2));
    assert_eq!(s.joints[1].offset, [15.0, 0.0, -0.25]);
    assert_eq!(s.joints[1].end_site, Some([10.0, 0.0, 0.0]));
    assert_eq!(m.channel_count(), 12);
    assert_eq!(m.frames(), 3);
    assert_eq!(m.frame(0).unwrap()[6], 1e-5);
    assert_eq!(m.value(2, 3, Channel::Xrotation), Some(70.123456));
    assert_same_motion(&m, &round_trip(&m));
}

#[test]
fn crlf_tabs_mixed_whitespace_and_glued_braces() {
    let messy = MIXED
        .replace('\n', "\r\n")
        .replace("\tOFFSET 0.0 90.0 0.0", " \t OFFSET\t0.0   90.0\t0.0 ")
        .replace("ROOT Hips\r\n{", "ROOT Hips {")
        .replace("Frames: 3", "Frames:\t3")
        .replace("1.0 90.5", "  1.0\t\t90.5");
    let a = parse_bvh(MIXED, "a.bvh").unwrap();
    let b = parse_bvh(&messy, "b.bvh").unwrap();
    assert_eq!(a.skeleton(), b.skeleton());
    assert_eq!(a.data(), b.data());
    // Lone CR line ends, a trailing blank line and a BOM.
    let cr = format!("\u{feff}{}\n\n", MIXED.replace('\n', "\r"));
    let c = parse_bvh(&cr, "c.bvh").unwrap();
    assert_eq!(a.data(), c.data());
}

#[test]
fn several_rotation_orders_round_trip() {
    for order in [
        "Zrotation Yrotation Xrotation",
        "Zrotation Xrotation Yrotation",
        "Xrotation Yrotation Zrotation",
        "Yrotation Zrotation Xrotation",
    ] {
        let text = MIXED.replace("Zrotation Xrotation Yrotation", order);
        let m = parse_bvh(&text, "o.bvh").unwrap();
        let got: Vec<_> = m.skeleton().joints[1]
            .channels
            .iter()
            .map(|c| c.name())
            .collect();
        assert_eq!(got.join(" "), order);
        assert_same_motion(&m, &round_trip(&m));
    }
}

#[test]
fn round_trip_keeps_tiny_and_large_values() {
    let text = MIXED.replace("1e-5 -4.5 0.25", "1.87007e-05 -123456.789 3.3e-12");
    let m = parse_bvh(&text, "v.bvh").unwrap();
    assert_same_motion(&m, &round_trip(&m));
    // Written twice, the text is stable.
    let mut once = Vec::new();
    write_bvh(&m, &mut once).unwrap();
    let mut twice = Vec::new();
    write_bvh(&round_trip(&m), &mut twice).unwrap();
    assert_eq!(once, twice);
}

#[test]
fn zero_frames_and_zero_channels_are_legal() {
    let header_only = MIXED.replace("Frames: 3", "Frames: 0");
    let header_only = header_only.split("1.0 90.5").next().unwrap();
    let m = parse_bvh(header_only, "z.bvh").unwrap();
    assert_eq!(m.frames(), 0);
    let bare = "HIERARCHY\nROOT A\n{\nOFFSET 0 0 0\nCHANNELS 0\nEnd Site\n{\nOFFSET 0 1 0\n}\n}\nMOTION\nFrames: 4\nFrame Time: 0.1\n";
    let m = parse_bvh(bare, "bare.bvh").unwrap();
    assert_eq!((m.frames(), m.channel_count()), (4, 0));
    assert_same_motion(&m, &round_trip(&m));
}

/// (description, edited text, expected line, check on the kind, expected message fragment)
#[test]
fn every_error_names_file_and_line() {
    type Check = fn(&BvhErrorKind) -> bool;
    let cases: Vec<(&str, String, usize, Check, &str)> = vec![
        (
            "misspelt OFFSET",
            MIXED.replace("\t\tOFFSET 1.5e1", "\t\tCHANNEL 1.5e1"),
            8,
            |k| matches!(k, BvhErrorKind::Unexpected { .. }),
            "bad.bvh:8: expected `OFFSET`, found `CHANNEL`",
        ),
        (
            "truncated hierarchy",
            MIXED[..MIXED.find("\tJOINT Fixed").unwrap()].to_string(),
            15,
            |k| matches!(k, BvhErrorKind::UnexpectedEnd { .. }),
            "bad.bvh:15: file ends early (truncated?): expected `JOINT`, `End Site` or `}`",
        ),
        (
            "no MOTION section",
            MIXED[..MIXED.find("MOTION").unwrap()].to_string(),
            25,
            |k| matches!(k, BvhErrorKind::UnexpectedEnd { .. }),
            "expected `ROOT` or `MOTION`",
        ),
        (
            "wrong channel count on a frame line",
            MIXED.replace("2.0 91.5 -3.0 11", "2.0 -3.0 11"),
            29,
            |k| {
                matches!(
                    k,
                    BvhErrorKind::ChannelCount {
                        frame: 1,
                        found: 11,
                        expected: 12,
                        ..
                    }
                )
            },
            "bad.bvh:29: frame 1 has 11 values, but the hierarchy declares 12 channels",
        ),
        (
            "last line cut short",
            MIXED.replace(" 70.123456 80 90\n", " 70.1"),
            30,
            |k| matches!(k, BvhErrorKind::ChannelCount { found: 10, .. }),
            "is the file truncated?",
        ),
        (
            "non-numeric value",
            MIXED.replace("11 21 31", "11 abc 31"),
            29,
            |k| matches!(k, BvhErrorKind::NotANumber { .. }),
            "bad.bvh:29: expected a number, found `abc`",
        ),
        (
            "decimal comma",
            MIXED.replace("11 21 31", "11 21,5 31"),
            29,
            |k| matches!(k, BvhErrorKind::NotANumber { .. }),
            "use `.` as the decimal separator",
        ),
        (
            "NaN",
            MIXED.replace("12 22 32", "12 NaN 32"),
            30,
            |k| matches!(k, BvhErrorKind::NonFinite { .. }),
            "bad.bvh:30: value `NaN` is not finite",
        ),
        (
            "infinity by overflow",
            MIXED.replace("10 20 30", "10 1e999 30"),
            28,
            |k| matches!(k, BvhErrorKind::NonFinite { .. }),
            "value `1e999` is not finite",
        ),
        (
            "inf in an offset",
            MIXED.replace("OFFSET 0 5 0", "OFFSET 0 inf 0"),
            17,
            |k| matches!(k, BvhErrorKind::NonFinite { .. }),
            "bad.bvh:17: value `inf` is not finite",
        ),
        (
            "fewer frame lines than Frames",
            MIXED.replace("Frames: 3", "Frames: 5"),
            26,
            |k| {
                matches!(
                    k,
                    BvhErrorKind::FrameCount {
                        declared: 5,
                        found: 3,
                        ..
                    }
                )
            },
            "bad.bvh:26: `Frames: 5` but the file has 3 frame lines; the file may be truncated",
        ),
        (
            "more frame lines than Frames",
            MIXED.replace("Frames: 3", "Frames: 2"),
            26,
            |k| {
                matches!(
                    k,
                    BvhErrorKind::FrameCount {
                        declared: 2,
                        found: 3,
                        ..
                    }
                )
            },
            "set `Frames:` to the number of frame lines, or remove the extra lines",
        ),
        (
            "zero frame time",
            MIXED.replace("Frame Time: 0.0333333", "Frame Time: 0"),
            27,
            |k| matches!(k, BvhErrorKind::BadFrameTime { .. }),
            "bad.bvh:27: frame time must be between 0.001 and 1 seconds (1 to 1000 frames per \
             second), found `0`",
        ),
        (
            "huge frame time (used to exhaust memory in pack)",
            MIXED.replace("Frame Time: 0.0333333", "Frame Time: 1e300"),
            27,
            |k| matches!(k, BvhErrorKind::BadFrameTime { .. }),
            "found `1e300`",
        ),
        (
            "frame time too short",
            MIXED.replace("Frame Time: 0.0333333", "Frame Time: 0.00001"),
            27,
            |k| matches!(k, BvhErrorKind::BadFrameTime { .. }),
            "found `0.00001`",
        ),
        (
            "negative frame time",
            MIXED.replace("Frame Time: 0.0333333", "Frame Time: -0.1"),
            27,
            |k| matches!(k, BvhErrorKind::BadFrameTime { .. }),
            "found `-0.1`",
        ),
        (
            "unknown channel",
            MIXED.replace("CHANNELS 3 Xrotation", "CHANNELS 3 Wrotation"),
            21,
            |k| matches!(k, BvhErrorKind::Unexpected { .. }),
            "expected a channel name",
        ),
        (
            "duplicate channel",
            MIXED.replace(
                "Zrotation Xrotation Yrotation",
                "Zrotation Xrotation Zrotation",
            ),
            9,
            |k| matches!(k, BvhErrorKind::Invalid(_)),
            "channel `Zrotation` is listed twice",
        ),
        (
            "too many channels",
            MIXED.replace("CHANNELS 3 Zrotation", "CHANNELS 7 Zrotation"),
            9,
            |k| matches!(k, BvhErrorKind::Unexpected { .. }),
            "expected a channel count from 0 to 6, found `7`",
        ),
        (
            "missing joint name",
            MIXED.replace("JOINT Head", "JOINT"),
            18,
            |k| matches!(k, BvhErrorKind::Unexpected { .. }),
            "expected a joint name",
        ),
        (
            "fractional frame count",
            MIXED.replace("Frames: 3", "Frames: 3.5"),
            26,
            |k| matches!(k, BvhErrorKind::Unexpected { .. }),
            "expected a frame count",
        ),
        (
            "not a BVH file",
            "RIFF....WAVEfmt ".to_string(),
            1,
            |k| matches!(k, BvhErrorKind::Unexpected { .. }),
            "bad.bvh:1: expected `HIERARCHY`, found `RIFF....WAVEfmt`",
        ),
        (
            "empty file",
            String::new(),
            1,
            |k| matches!(k, BvhErrorKind::UnexpectedEnd { .. }),
            "bad.bvh:1: file ends early (truncated?): expected `HIERARCHY`",
        ),
    ];
    for (what, text, line, check, fragment) in cases {
        let e = parse_bvh(&text, "bad.bvh").expect_err(what);
        let msg = e.to_string();
        let (got_line, kind) = syntax(&e);
        assert_eq!(got_line, line, "{what}: {msg}");
        assert!(check(&kind), "{what}: wrong kind {kind:?}");
        assert!(msg.contains(fragment), "{what}: `{msg}` lacks `{fragment}`");
        assert!(
            msg.starts_with(&format!("bad.bvh:{line}: ")),
            "{what}: {msg}"
        );
    }
}

#[test]
fn missing_file_names_the_path() {
    let e = read_bvh("/nonexistent/dir/take.bvh").unwrap_err();
    assert!(matches!(e, BvhError::Io { .. }));
    let msg = e.to_string();
    assert!(
        msg.starts_with("/nonexistent/dir/take.bvh: cannot read: "),
        "{msg}"
    );
    assert_eq!(e.line(), None);
}

/// Random byte edits of a valid file must give a motion or an error, never a panic.
#[test]
fn mutations_never_panic() {
    let mut x = 0x9e3779b97f4a7c15u64;
    let mut rand = move |n: usize| {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x % n as u64) as usize
    };
    let alphabet = b" \t\r\n{}-+.eE0123456789xXJOINTEndSiteMOTIONFrames:";
    let (mut ok, mut err) = (0, 0);
    for _ in 0..3000 {
        let mut bytes = MIXED.as_bytes().to_vec();
        for _ in 0..1 + rand(4) {
            if bytes.is_empty() {
                break;
            }
            let i = rand(bytes.len());
            match rand(4) {
                0 => bytes[i] = alphabet[rand(alphabet.len())],
                1 => {
                    bytes.remove(i);
                }
                2 => bytes.insert(i, alphabet[rand(alphabet.len())]),
                _ => bytes.truncate(i),
            }
        }
        let text = String::from_utf8_lossy(&bytes);
        match parse_bvh(&text, "fuzz.bvh") {
            Ok(m) => {
                ok += 1;
                let _ = fk::joint_positions(&m);
            }
            Err(e) => {
                err += 1;
                assert!(e.to_string().starts_with("fuzz.bvh:"));
            }
        }
    }
    eprintln!("mutations: {ok} parsed, {err} rejected");
    assert!(ok > 0 && err > 0);
}

/// A 12-minute take of a 75-joint skeleton (21,600 frames x 228 channels).
#[test]
fn parse_speed() {
    let mut text = String::from("HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 87 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n");
    for j in 1..75 {
        text.push_str(&format!("\tJOINT J{j}\n\t{{\n\t\tOFFSET 0 1 0\n\t\tCHANNELS 3 Zrotation Yrotation Xrotation\n\t}}\n"));
    }
    text.push_str("}\nMOTION\nFrames: 21600\nFrame Time: 0.03333333333333333\n");
    let mut row = String::new();
    for c in 0..228 {
        row.push_str(&format!("{:.6} ", (c as f64 * 0.37).sin() * 45.0));
    }
    row.push('\n');
    for _ in 0..21600 {
        text.push_str(&row);
    }
    let t = Instant::now();
    let m = parse_bvh(&text, "long.bvh").unwrap();
    let elapsed = t.elapsed();
    eprintln!(
        "parsed {} MB, {} frames x {} channels in {:?}",
        text.len() / 1_000_000,
        m.frames(),
        m.channel_count(),
        elapsed
    );
    assert_eq!(m.data().len(), 21600 * 228);
    // Generous bound for a loaded 2-core machine; typical release time is far lower.
    assert!(elapsed.as_secs_f64() < 5.0);
}

fn chain(rot_b: &str) -> String {
    format!(
        "HIERARCHY
ROOT A
{{
\tOFFSET 0 0 0
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
\tJOINT B
\t{{
\t\tOFFSET 1 0 0
\t\tCHANNELS 3 {rot_b}
\t\tJOINT C
\t\t{{
\t\t\tOFFSET 0 2 0
\t\t\tCHANNELS 3 Xrotation Yrotation Zrotation
\t\t\tEnd Site
\t\t\t{{
\t\t\t\tOFFSET 0 0 1
\t\t\t}}
\t\t}}
\t}}
}}
MOTION
Frames: 3
Frame Time: 0.1
10 20 30 90 0 0 0 90 0 0 0 0
0 0 0 0 30 0 0 0 0 0 0 0
0 0 0 0 0 0 45 0 0 0 0 0
"
    )
}

fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() < 1e-12)
}

#[test]
fn fk_three_joint_chain_by_hand() {
    // Joint B lists Z then X: its local rotation is Rz(z) * Rx(x).
    let m = parse_bvh(&chain("Zrotation Xrotation Yrotation"), "chain.bvh").unwrap();
    let targets = [
        Target::Joint(0),
        Target::Joint(1),
        Target::Joint(2),
        Target::EndSite(2),
    ];
    let p = fk::target_positions(&m, &targets).unwrap();
    // Frame 0: root at (10,20,30) turned 90 deg about Z, which maps (1,0,0) to (0,1,0):
    // B = (10,21,30). B adds Rx(90), which maps C's offset (0,2,0) to (0,0,2), and Rz(90)
    // leaves (0,0,2) alone: C = (10,21,32). The end site (0,0,1) goes to (0,-1,0) under Rx(90)
    // and to (1,0,0) under Rz(90): (11,21,32).
    assert!(close(p.get(0, 0), [10.0, 20.0, 30.0]));
    assert!(close(p.get(0, 1), [10.0, 21.0, 30.0]), "{:?}", p.get(0, 1));
    assert!(close(p.get(0, 2), [10.0, 21.0, 32.0]), "{:?}", p.get(0, 2));
    assert!(close(p.get(0, 3), [11.0, 21.0, 32.0]), "{:?}", p.get(0, 3));
    // Frame 1: root turned 30 deg about Y: (1,0,0) -> (cos 30, 0, -sin 30); C's offset is
    // vertical and stays (0,2,0); the end site (0,0,1) -> (sin 30, 0, cos 30).
    let (s, c) = (0.5, 3f64.sqrt() / 2.0);
    assert!(close(p.get(1, 1), [c, 0.0, -s]));
    assert!(close(p.get(1, 2), [c, 2.0, -s]));
    assert!(close(p.get(1, 3), [c + s, 2.0, -s + c]));
    // Frame 2: B turned 45 deg about Z: C's offset (0,2,0) -> (-2 sin 45, 2 cos 45, 0).
    let r = 2f64.sqrt();
    assert!(close(p.get(2, 2), [1.0 - r, r, 0.0]), "{:?}", p.get(2, 2));

    // Order matters: B turned 90 deg about Z and 90 deg about X. Listed Z X:
    // Rz(90) * Rx(90) * (0,2,0) = Rz(90) * (0,0,2) = (0,0,2), so C = (1,0,2). Listed X Z:
    // Rx(90) * Rz(90) * (0,2,0) = Rx(90) * (-2,0,0) = (-2,0,0), so C = (-1,0,0).
    let zx =
        chain("Zrotation Xrotation Yrotation").replace("0 0 0 0 0 0 45 0 0", "0 0 0 0 0 0 90 90 0");
    let p = fk::target_positions(&parse_bvh(&zx, "zx.bvh").unwrap(), &targets).unwrap();
    assert!(close(p.get(2, 2), [1.0, 0.0, 2.0]), "{:?}", p.get(2, 2));
    let xz =
        chain("Xrotation Zrotation Yrotation").replace("0 0 0 0 0 0 45 0 0", "0 0 0 0 0 0 90 90 0");
    let m = parse_bvh(&xz, "xz.bvh").unwrap();
    let p = fk::target_positions(&m, &targets).unwrap();
    assert!(close(p.get(2, 2), [-1.0, 0.0, 0.0]), "{:?}", p.get(2, 2));

    // The fast path (one target) agrees with full FK.
    let plan = fk::FkPlan::new(m.skeleton(), &[Target::Joint(1)]).unwrap();
    assert_eq!(plan.evaluated_joints(), 2);
    let fast = plan.positions(&m).unwrap();
    let full = fk::joint_positions(&m);
    for f in 0..m.frames() {
        assert_eq!(fast.get(f, 0), full.get(f, 1));
    }
}

#[test]
fn translation_channels_replace_the_offset() {
    let text = "HIERARCHY\nROOT R\n{\nOFFSET 0 0 0\nCHANNELS 0\nJOINT S\n{\nOFFSET 5 6 7\nCHANNELS 1 Yposition\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n-3\n";
    let m = parse_bvh(text, "t.bvh").unwrap();
    let p = fk::joint_positions(&m);
    assert_eq!(p.get(0, 1), [5.0, -3.0, 7.0]);
}

#[test]
fn fk_plan_errors() {
    let m = parse_bvh(&chain("Zrotation Xrotation Yrotation"), "chain.bvh").unwrap();
    assert!(matches!(
        fk::FkPlan::new(m.skeleton(), &[Target::Joint(9)]),
        Err(fk::FkError::JointOutOfRange {
            joint: 9,
            joints: 3
        })
    ));
    let e = fk::FkPlan::new(m.skeleton(), &[Target::EndSite(1)]).unwrap_err();
    assert_eq!(e.to_string(), "joint `B` has no End Site");
    let other = parse_bvh(MIXED, "mixed.bvh").unwrap();
    let plan = fk::FkPlan::new(m.skeleton(), &[Target::Joint(0)]).unwrap();
    assert!(matches!(
        plan.positions(&other),
        Err(fk::FkError::SkeletonMismatch { .. })
    ));
}

/// A joint name that could not be written back as BVH (empty, padded, with a brace or a line
/// break) is refused by the skeleton's check, so no reader (BVH, blob) can pass one on to the
/// writer (an empty name used to give an unreadable motion.bvh).
#[test]
fn unwritable_joint_names_are_refused() {
    for bad in ["", " ", " Hips", "Hips\n", "a{b"] {
        let sk = gesture_trainer::motion::Skeleton {
            joints: vec![gesture_trainer::motion::Joint {
                name: bad.to_string(),
                parent: None,
                offset: [0.0; 3],
                channels: vec![],
                end_site: None,
            }],
        };
        let e = sk.validate().unwrap_err().to_string();
        assert!(e.contains("joint names must be"), "{bad:?}: {e}");
    }
}

/// A frame count no file could hold is refused at its line (without channels the frame lines
/// are empty, so nothing else would bound it; the fuzzer found one).
#[test]
fn an_absurd_frame_count_is_refused() {
    let bare = "HIERARCHY\nROOT A\n{\nOFFSET 0 0 0\nCHANNELS 0\nEnd Site\n{\nOFFSET 0 1 0\n}\n}\nMOTION\nFrames: 28888888888888888\nFrame Time: 0.1\n";
    let e = parse_bvh(bare, "huge.bvh").unwrap_err().to_string();
    assert!(
        e.contains("huge.bvh:12") && e.contains("from 0 to 10000000"),
        "{e}"
    );
}
