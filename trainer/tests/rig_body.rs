//! Body channels: one constructed pose (left arm straight out to the side, i.e. raised 90
//! degrees from hanging, elbow bent 45; right arm raised 45 from hanging and swung 20 forward,
//! elbow bent 90; head turned 30 to the left and nodded 15 down) built on every skeleton the
//! project meets, from each skeleton's own rest geometry, must give the same servo angles on
//! all of them through the unchanged puppet rig, and the simulator's inverse must put those
//! angles back. The skeletons disagree on joint frames (Bandai's), names (ReActIdle's), hands
//! (ReActIdle's wrists are end sites) and heads (the 9-joint ZeroEGGS has none).
//! Tests on `../shared/data` print "skipping: ..." and pass when it is absent.

use std::path::{Path, PathBuf};

use gesture_runtime::blob::DriveMode;
use gesture_runtime::rotation::{axis_rotation, euler_angles, mat_mul, mat_vec, transpose, Mat3};
use gesture_trainer::motion::fk::{world_transforms, Transform, Vec3};
use gesture_trainer::motion::{read_bvh, Motion, Skeleton};
use gesture_trainer::rig::{PoseSkeleton, Rig};
use gesture_trainer::synth;

/// The joints a test names for one skeleton (by hand, not through the humanoid name matcher
/// under test): hips, chest, head, and per arm (upper arm, forearm, wrist; a wrist ending in
/// `/end` is the forearm's end site).
struct Names {
    label: &'static str,
    hips: &'static str,
    chest: &'static str,
    head: Option<&'static str>,
    arms: [[&'static str; 3]; 2],
}

const SYNTH: Names = Names {
    label: "synthetic",
    hips: "Hips",
    chest: "Chest",
    head: Some("Head"),
    arms: [
        ["LeftArm", "LeftForeArm", "LeftHand"],
        ["RightArm", "RightForeArm", "RightHand"],
    ],
};

/// (shared-data file, names).
const REAL: [(&str, Names); 5] = [
    (
        "zeroeggs-067-speech2/067_Speech_2_first50s.bvh",
        Names {
            label: "ZeroEGGS 75-joint",
            hips: "Hips",
            chest: "Spine3",
            head: Some("Head"),
            arms: [
                ["LeftArm", "LeftForeArm", "LeftHand"],
                ["RightArm", "RightForeArm", "RightHand"],
            ],
        },
    ),
    (
        "zeroeggs-001-neutral-9joint/001_Neutral_0_x_1_0.bvh",
        Names {
            label: "ZeroEGGS 9-joint",
            hips: "Hips",
            chest: "Chest",
            head: None,
            arms: [
                ["LeftArm", "LeftForeArm", "LeftHand"],
                ["RightArm", "RightForeArm", "RightHand"],
            ],
        },
    ),
    (
        "bandai-namco-gestures/dataset-2/dataset-2_wave-both-hands_normal_001.bvh",
        Names {
            label: "Bandai Namco",
            hips: "Hips",
            chest: "Chest",
            head: Some("Head"),
            arms: [
                ["UpperArm_L", "LowerArm_L", "Hand_L"],
                ["UpperArm_R", "LowerArm_R", "Hand_R"],
            ],
        },
    ),
    (
        "shippable/cmu-mocap/18_08.bvh",
        Names {
            label: "CMU",
            hips: "Hips",
            chest: "Spine1",
            head: Some("Head"),
            arms: [
                ["LeftArm", "LeftForeArm", "LeftHand"],
                ["RightArm", "RightForeArm", "RightHand"],
            ],
        },
    ),
    (
        "shippable/reactidle/000_genuine.bvh",
        Names {
            label: "ReActIdle",
            hips: "pelvis",
            chest: "spine.001",
            head: Some("face"),
            arms: [
                ["upper_arm.L", "forearm.L", "forearm.L/end"],
                ["upper_arm.R", "forearm.R", "forearm.R/end"],
            ],
        },
    ),
];

/// The constructed pose, per arm: (raise, swing, elbow flex), degrees; and the head's (pan,
/// tilt).
const ARMS: [[f64; 3]; 2] = [[0.0, 0.0, 45.0], [-45.0, 20.0, 90.0]];
const HEAD: [f64; 2] = [30.0, 15.0];

/// What the puppet rig must read, in its channel order (head pan, tilt, left raise, swing,
/// right raise, swing, left elbow, right elbow).
fn expected(has_head: bool) -> [f64; 8] {
    let head = if has_head { HEAD } else { [0.0, 0.0] };
    [
        head[0], head[1], ARMS[0][0], ARMS[0][1], ARMS[1][0], ARMS[1][1], ARMS[0][2], ARMS[1][2],
    ]
}

fn find(sk: &Skeleton, name: &str) -> usize {
    sk.find(name)
        .unwrap_or_else(|| panic!("no joint {name} in the skeleton"))
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn unit(a: Vec3) -> Vec3 {
    let n = dot(a, a).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

/// Rotation by `deg` about unit axis `n` (Rodrigues).
fn about(n: Vec3, deg: f64) -> Mat3 {
    let (s, c) = deg.to_radians().sin_cos();
    let t = 1.0 - c;
    let [x, y, z] = n;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

/// The rotation taking unit `a` to unit `b` about their common normal.
fn turn(a: Vec3, b: Vec3) -> Mat3 {
    let n = cross(a, b);
    if dot(n, n) < 1e-20 {
        return axis_rotation(0, 0.0);
    }
    about(unit(n), dot(a, b).clamp(-1.0, 1.0).acos().to_degrees())
}

/// A point by the test's naming (`NAME/end` = that joint's end site).
fn point(sk: &Skeleton, w: &[Transform], name: &str) -> Vec3 {
    match name.strip_suffix("/end") {
        Some(j) => {
            let j = find(sk, j);
            let e = sk.joints[j].end_site.expect("an end site");
            let p = mat_vec(&w[j].rotation, &e);
            [
                w[j].position[0] + p[0],
                w[j].position[1] + p[1],
                w[j].position[2] + p[2],
            ]
        }
        None => w[find(sk, name)].position,
    }
}

/// Gives joint `j` world rotation `r` (its parent's unchanged), written in its channel order.
fn set_world(sk: &Skeleton, frame: &mut [f64], j: usize, r: &Mat3) {
    let w = world_transforms(sk, frame);
    let parent = sk.joints[j]
        .parent
        .map_or(axis_rotation(0, 0.0), |p| w[p].rotation);
    let local = mat_mul(&transpose(&parent), r);
    let start = sk.channel_starts()[j];
    let rot: Vec<(usize, usize)> = sk.joints[j]
        .channels
        .iter()
        .enumerate()
        .filter(|(_, c)| c.is_rotation())
        .map(|(k, c)| (k, c.axis()))
        .collect();
    assert_eq!(
        rot.len(),
        3,
        "joint {} needs three rotations",
        sk.joints[j].name
    );
    let angles = euler_angles(&local, [rot[0].1, rot[1].1, rot[2].1]);
    for (i, &(k, _)) in rot.iter().enumerate() {
        frame[start + k] = angles[i];
    }
}

/// The rest frame with the constructed pose on it.
fn construct(sk: &Skeleton, rest: &[f64], n: &Names) -> Vec<f64> {
    let mut frame = rest.to_vec();
    let w = world_transforms(sk, &frame);
    // The body frame from the rest geometry (world): left from the right shoulder to the left,
    // up from the hips to the middle of the shoulders, forward = left x up.
    let (lu, ru) = (point(sk, &w, n.arms[0][0]), point(sk, &w, n.arms[1][0]));
    let left = unit(sub(lu, ru));
    let mid = [
        (lu[0] + ru[0]) / 2.0,
        (lu[1] + ru[1]) / 2.0,
        (lu[2] + ru[2]) / 2.0,
    ];
    let up0 = sub(mid, point(sk, &w, n.hips));
    let k = dot(up0, left);
    let up = unit([
        up0[0] - k * left[0],
        up0[1] - k * left[1],
        up0[2] - k * left[2],
    ]);
    let fwd = cross(left, up);
    let body = |b: Vec3| [0, 1, 2].map(|i| b[0] * left[i] + b[1] * up[i] + b[2] * fwd[i]);
    // Head: the neck chain straight (local identity below the chest), then the head turned
    // about the body's up axis and nodded about its (turned) left axis.
    if let Some(h) = n.head {
        let (chest, head) = (find(sk, n.chest), find(sk, h));
        let mut chain = Vec::new();
        let mut cur = sk.joints[head].parent;
        while let Some(p) = cur.filter(|&p| p != chest) {
            chain.push(p);
            cur = sk.joints[p].parent;
        }
        for &j in chain.iter().rev() {
            let parent = sk.joints[j].parent.unwrap();
            let pr = world_transforms(sk, &frame)[parent].rotation;
            set_world(sk, &mut frame, j, &pr);
        }
        let pan = about(up, HEAD[0]);
        let tilt = about(mat_vec(&pan, &left), HEAD[1]);
        let rc = world_transforms(sk, &frame)[chest].rotation;
        set_world(sk, &mut frame, head, &mat_mul(&mat_mul(&tilt, &pan), &rc));
    }
    for (s, names) in n.arms.iter().enumerate() {
        let [raise, swing, flex] = ARMS[s];
        let out = if s == 0 { 1.0 } else { -1.0 };
        let (r, sw) = (raise.to_radians(), swing.to_radians());
        let want = body([out * sw.cos() * r.cos(), sw.cos() * r.sin(), sw.sin()]);
        let w = world_transforms(sk, &frame);
        let d = unit(sub(point(sk, &w, names[1]), point(sk, &w, names[0])));
        let upper = find(sk, names[0]);
        set_world(
            sk,
            &mut frame,
            upper,
            &mat_mul(&turn(d, want), &w[upper].rotation),
        );
        // The elbow bends the forearm forward, about the upper arm x forward.
        let w = world_transforms(sk, &frame);
        let f = unit(sub(point(sk, &w, names[2]), point(sk, &w, names[1])));
        let bent = mat_vec(&about(unit(cross(want, fwd)), flex), &want);
        let fore = find(sk, names[1]);
        set_world(
            sk,
            &mut frame,
            fore,
            &mat_mul(&turn(f, bent), &w[fore].rotation),
        );
    }
    frame
}

fn puppet(name: &str) -> Rig {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../rigs")
        .join(name);
    Rig::load(p).unwrap_or_else(|e| panic!("{e}"))
}

/// Reads the puppet rig on the constructed pose; checks the angles and the inverse.
fn check(sk: &Skeleton, rest: &[f64], n: &Names) -> Vec<f32> {
    let frame = construct(sk, rest, n);
    let rig = puppet("puppet-8ch.toml");
    let bound = rig.bind(sk, n.label).unwrap().with_rest(sk, rest);
    for line in bound.describe() {
        eprintln!("  {line}");
    }
    let m = Motion::new(sk.clone(), 1.0 / 30.0, 1, frame).unwrap();
    let got = bound.channel_values(&m, 0).unwrap();
    eprintln!(
        "{:18} {}",
        n.label,
        got.iter()
            .map(|v| format!("{v:7.2}"))
            .collect::<Vec<_>>()
            .join(" ")
    );
    for ((c, &v), want) in rig
        .channels
        .iter()
        .zip(&got)
        .zip(expected(n.head.is_some()))
    {
        assert!(
            (f64::from(v) - want).abs() < 0.5,
            "{}: {} reads {v}, want {want}",
            n.label,
            c.name
        );
    }
    // The inverse (the simulator's BVH output): these angles put on the rest frame read back.
    let drives = bound.drives().unwrap();
    assert!(drives.iter().all(|d| matches!(d.mode, DriveMode::Body(_))));
    let pose_sk = PoseSkeleton::new(sk.clone(), rest.to_vec(), &drives);
    let rebuilt = pose_sk.frame(&got);
    let m = Motion::new(sk.clone(), 1.0 / 30.0, 1, rebuilt).unwrap();
    let back = bound.channel_values(&m, 0).unwrap();
    for ((c, a), b) in rig.channels.iter().zip(&got).zip(&back) {
        assert!(
            (a - b).abs() < 0.01,
            "{} inverse: {}: {a} vs {b}",
            n.label,
            c.name
        );
    }
    got
}

#[test]
fn a_constructed_pose_reads_the_same_on_every_skeleton() {
    eprintln!(
        "{:18} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7}",
        "skeleton", "pan", "tilt", "L raise", "L swing", "R raise", "R swing", "L elbow", "R elbow"
    );
    let take = synth::generate_take(7, 0, 2.0, &synth::speaker_for(7));
    let m = take.motion();
    check(m.skeleton(), m.frame(0).unwrap(), &SYNTH);
    let Some(dir) = e2e_tests::shared_data("rig_body", "") else {
        return;
    };
    for (file, names) in &REAL {
        let path: PathBuf = dir.join(file);
        let m = read_bvh(&path).unwrap_or_else(|e| panic!("{e}"));
        check(m.skeleton(), m.frame(0).unwrap(), names);
    }
}

#[test]
fn a_missing_head_holds_neutral_and_says_so() {
    let Some(dir) = e2e_tests::shared_data("rig_body", "zeroeggs-001-neutral-9joint") else {
        return;
    };
    let m = read_bvh(dir.join("001_Neutral_0_x_1_0.bvh")).unwrap();
    let rig = puppet("puppet-pca9685.toml");
    let bound = rig.bind(m.skeleton(), "9-joint").unwrap();
    let lines = bound.describe();
    assert!(lines[0].starts_with("head_pan: held at its neutral 0 deg: the skeleton has no head"));
    assert!(lines[1].starts_with("head_tilt: held at its neutral"));
    assert!(lines[2..].iter().all(|l| !l.contains("held")), "{lines:#?}");
    let values = bound.take_values(&m).unwrap();
    assert!(values.iter().all(|v| v[0] == 0.0 && v[1] == 0.0));
}
