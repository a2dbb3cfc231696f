//! ROS 2 output checked by ROS 2's own tools, none of them ours: the MCAP file of a run
//! decoded by `rosbags` and by `mcap-ros2-support`, the URDF parsed by `urdf-parser-py`
//! (and its forward kinematics against the run's skeleton), and, with the `ros2` feature, the
//! DDS messages received by an Eclipse Cyclone DDS subscriber in a network namespace of its
//! own (loopback only). The reference is always the run's own `motion.bvh`.
//!
//! The Python packages live in the venv `.ci/run` makes (`e2e_tests::ros2_python`); without
//! it the tests say "skipping" and pass, unless `GESTURE_REQUIRE_ROS2` is set (CI).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{run_into, setup, text, workspace};
use gesture_runtime::blob::{Blob, DriveMode};
use gesture_runtime::rig::ChannelCal;
use gesture_runtime::rotation::{mat_mul, mat_vec, transpose, Mat3};
use gesture_trainer::motion::fk::{world_pose, world_transforms, Transform};
use gesture_trainer::motion::{read_bvh, Skeleton};
use gesture_trainer::rig::{Body, BodyMeasure, Effector, PoseSkeleton};
use host_sim::ros2::urdf::{Motion, Robot, SCALE};
use serde_json::Value;

fn script(name: &str) -> PathBuf {
    workspace().join("host-sim/tests/ros2").join(name)
}

fn python_json(python: &Path, args: &[&Path]) -> Value {
    let o = Command::new(python)
        .args(args)
        .output()
        .expect("python runs");
    assert!(o.status.success(), "{}", text(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("one JSON object")
}

/// The run's joint states as its motion.bvh shows them: for a full-skeleton blob every
/// rotation channel `<joint>.<axis>rotation`, in radians, per frame; and the frame rate.
fn bvh_states(dir: &Path) -> (Vec<String>, Vec<Vec<f64>>, f64) {
    let m = read_bvh(dir.join("motion.bvh")).unwrap();
    let sk = m.skeleton();
    let starts = sk.channel_starts();
    let mut names = Vec::new();
    let mut cols = Vec::new();
    for (j, joint) in sk.joints.iter().enumerate() {
        for (k, c) in joint.channels.iter().enumerate() {
            if c.is_rotation() {
                names.push(format!("{}.{}", joint.name, c.name()));
                cols.push(starts[j] + k);
            }
        }
    }
    let frames = (0..m.frames())
        .map(|f| {
            let row = m.frame(f).unwrap();
            cols.iter().map(|&c| row[c].to_radians()).collect()
        })
        .collect();
    (names, frames, m.fps())
}

/// A decoded message's names and positions equal the reference's frame `k`.
fn check_message(m: &Value, k: usize, names: &[String], frames: &[Vec<f64>]) {
    let got: Vec<&str> = m["name"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    assert_eq!(got, names, "message {k}");
    let pos: Vec<f64> = m["position"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(pos.len(), frames[k].len());
    for (c, (a, b)) in pos.iter().zip(&frames[k]).enumerate() {
        assert!(
            (a - b).abs() <= 1e-6,
            "message {k} {}: {a} rad, motion.bvh {b}",
            names[c]
        );
    }
}

fn stamp_ns(m: &Value) -> i64 {
    m["sec"].as_i64().unwrap() * 1_000_000_000 + m["nanosec"].as_i64().unwrap()
}

/// `gesture-sim run` of `blob` on `wav` with `--mcap`, which must succeed and write the URDF
/// beside the run: (the temporary folder, kept while it is used; the run's folder; the MCAP file).
fn mcap_run(blob: &Path, wav: &Path) -> (tempfile::TempDir, PathBuf, PathBuf) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    let mcap = tmp.path().join("run.mcap");
    let o = run_into(
        blob,
        wav,
        &dir,
        &["--no-video", "--mcap", mcap.to_str().unwrap()],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    assert!(stdout.contains("robot.urdf ("), "{stdout}");
    (tmp, dir, mcap)
}

/// The MCAP file of a run: both decoders read one message per frame on /joint_states, names
/// and positions those of motion.bvh (within 1e-6 rad), stamps and log times the frames'
/// times on the audio clock; the URDF written beside it parses, its movable joints are the
/// messages' names, and its forward kinematics put every joint where motion.bvh does.
#[test]
fn mcap_and_urdf_of_a_run_open_in_ros_tools() {
    let Some(python) = e2e_tests::ros2_python("mcap_and_urdf_of_a_run_open_in_ros_tools") else {
        return;
    };
    let s = setup();
    let (tmp, dir, mcap) = mcap_run(&s.full, &s.wav);
    let (names, frames, fps) = bvh_states(&dir);
    assert!(frames.len() > 100);

    let v = python_json(&python, &[&script("read_mcap.py"), &mcap]);
    assert_eq!(v["profile"], "ros2");
    assert_eq!(v["schema"][0], "sensor_msgs/msg/JointState");
    assert_eq!(v["schema"][1], "ros2msg");
    assert_eq!(v["schema"][2], "cdr");
    for decoder in ["mcap_ros2", "rosbags"] {
        let msgs = v[decoder].as_array().unwrap();
        assert_eq!(
            msgs.len(),
            frames.len(),
            "{decoder}: messages against frames"
        );
        for (k, m) in msgs.iter().enumerate() {
            assert_eq!(m["topic"], "/joint_states");
            check_message(m, k, &names, &frames);
            let t = (k as f64 * 1e9 / fps).round() as i64;
            assert_eq!(stamp_ns(m), t, "{decoder} message {k}");
            assert_eq!(m["log_time"].as_i64().unwrap(), t);
        }
        eprintln!(
            "{decoder}: {} messages, {} frames",
            msgs.len(),
            frames.len()
        );
    }

    // The URDF, with the positions of a few frames for its forward kinematics.
    let picks: Vec<usize> = (0..5).map(|i| i * (frames.len() - 1) / 4).collect();
    let positions = tmp.path().join("positions.json");
    let p = serde_json::json!({
        "name": names,
        "frames": picks.iter().map(|&f| frames[f].clone()).collect::<Vec<_>>(),
    });
    std::fs::write(&positions, p.to_string()).unwrap();
    let u = python_json(
        &python,
        &[&script("read_urdf.py"), &dir.join("robot.urdf"), &positions],
    );
    let joints = u["joints"].as_array().unwrap();
    let mut movable: Vec<&str> = joints
        .iter()
        .filter(|j| j["type"] != "fixed")
        .map(|j| j["name"].as_str().unwrap())
        .collect();
    assert!(joints
        .iter()
        .filter(|j| j["type"] != "fixed")
        .all(|j| j["type"] == "continuous"));
    movable.sort_unstable();
    let mut want: Vec<&str> = names.iter().map(String::as_str).collect();
    want.sort_unstable();
    assert_eq!(
        movable, want,
        "URDF movable joints against the JointState names"
    );
    assert_eq!(u["root"], "base_link");
    eprintln!(
        "urdf: {} joints ({} movable), {} links",
        joints.len(),
        movable.len(),
        u["links"].as_array().unwrap().len()
    );
    // Forward kinematics: the parsed URDF against the run's BVH (Y up, cm -> Z up, m).
    let m = read_bvh(dir.join("motion.bvh")).unwrap();
    let mut worst: f64 = 0.0;
    for (i, &f) in picks.iter().enumerate() {
        let world = world_pose(&m, f).unwrap();
        let fk = &u["fk"][i];
        for (j, joint) in m.skeleton().joints.iter().enumerate() {
            let p = world[j].position;
            let want = [p[2] * SCALE, p[0] * SCALE, p[1] * SCALE];
            let got: Vec<f64> = fk[&joint.name]
                .as_array()
                .unwrap_or_else(|| panic!("no link {}", joint.name))
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            for a in 0..3 {
                worst = worst.max((got[a] - want[a]).abs());
            }
        }
    }
    eprintln!("urdf forward kinematics against motion.bvh: worst {worst:.2e} m");
    assert!(worst < 1e-6, "worst joint position error {worst} m");
}

/// The joint-rotation puppet's URDF: the rig's eight channels as revolute joints with the
/// calibration's limits (parsed by urdf-parser-py), and, computed here as robot_state_publisher
/// would, every joint where the simulator's skeleton puts it for poses across the limits.
#[test]
fn puppet_urdf_has_the_rigs_joints_and_limits() {
    let s = setup();
    // The puppet in joint-rotation form (the shipped rig reads body measures; see below).
    let joints_blob = s.root.join("puppet-joints.blob");
    let opts = gesture_trainer::pack::PackOptions {
        rig: Some(workspace().join("host-sim/tests/data/puppet-8ch-joints.toml")),
        ..gesture_trainer::pack::PackOptions::default()
    };
    gesture_trainer::pack::pack(
        &s.root.join("model.json"),
        std::slice::from_ref(&s.corpus),
        &opts,
        &joints_blob,
    )
    .unwrap();
    let bytes = std::fs::read(&joints_blob).unwrap();
    let blob = Blob::parse(&bytes).unwrap();
    let cals: Vec<ChannelCal> = (0..blob.channels())
        .map(|c| blob.calibration(c).unwrap())
        .collect();
    let robot = Robot::from_blob(&blob, &cals).unwrap();
    let names: Vec<&str> = blob.channel_names().collect();
    assert_eq!(robot.movable(), names);
    // Pan and tilt are two twists on the head: a serial gimbal.
    assert_eq!(robot.approximate, ["Head"]);
    let ps = PoseSkeleton::from_blob(&blob.skeleton().unwrap()).unwrap();
    let mut worst = (0.0f64, String::new());
    for step in 0..=10 {
        let x = step as f32 / 10.0;
        let pose: Vec<f32> = cals
            .iter()
            .enumerate()
            .map(|(c, k)| {
                let t = if c % 2 == 0 { x } else { 1.0 - x };
                k.min_deg + t * (k.max_deg - k.min_deg)
            })
            .collect();
        let frame = ps.frame(&pose);
        let m = gesture_trainer::motion::Motion::new(ps.skeleton().clone(), 1.0 / 30.0, 1, frame)
            .unwrap();
        let world = world_pose(&m, 0).unwrap();
        let links = robot.link_positions(&pose);
        for (j, joint) in ps.skeleton().joints.iter().enumerate() {
            let p = world[j].position;
            let want = [p[2] * SCALE, p[0] * SCALE, p[1] * SCALE];
            let got = links.iter().find(|l| l.0 == joint.name).unwrap().1;
            for a in 0..3 {
                if (got[a] - want[a]).abs() > worst.0 {
                    worst = ((got[a] - want[a]).abs(), joint.name.clone());
                }
            }
        }
    }
    // Rounding only (the Euler shoulders pass through their decompositions).
    assert!(worst.0 < 1e-7, "worst joint position error {worst:?} m");
    eprintln!(
        "puppet urdf forward kinematics: worst {:.1e} m at {}",
        worst.0, worst.1
    );

    let Some(python) = e2e_tests::ros2_python("puppet_urdf_has_the_rigs_joints_and_limits") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("puppet.urdf");
    let o = common::sim(&[
        "urdf",
        "--blob",
        joints_blob.to_str().unwrap(),
        "--out",
        file.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("8 movable joints"),
        "{}",
        text(&o.stdout)
    );
    let u = python_json(&python, &[&script("read_urdf.py"), &file]);
    let movable: Vec<&Value> = u["joints"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|j| j["type"] != "fixed")
        .collect();
    assert_eq!(movable.len(), 8);
    for j in movable {
        let c = names.iter().position(|n| j["name"] == *n).unwrap();
        assert_eq!(j["type"], "revolute");
        let lim = j["limit"].as_array().unwrap();
        let close =
            |v: &Value, deg: f32| (v.as_f64().unwrap() - (deg as f64).to_radians()).abs() < 1e-9;
        assert!(
            close(&lim[0], cals[c].min_deg) && close(&lim[1], cals[c].max_deg),
            "{j}"
        );
        assert!(close(&lim[2], cals[c].max_slew_deg_per_s), "{j}");
    }
}

/// ROS axes from BVH axes (`ros = M bvh`), as the URDF's `base_link` turns them.
const ROS_FROM_BVH: Mat3 = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// The skeleton's world transforms (BVH axes and units) from a URDF's link frames in
/// `base_link` (ROS axes, metres), each BVH joint's link named as the joint.
fn bvh_world(sk: &Skeleton, link: impl Fn(&str) -> (Mat3, [f64; 3])) -> Vec<Transform> {
    let back = transpose(&ROS_FROM_BVH);
    sk.joints
        .iter()
        .map(|j| {
            let (r, p) = link(&j.name);
            Transform {
                rotation: mat_mul(&back, &r),
                position: mat_vec(&back, &p).map(|v| v / SCALE),
            }
        })
        .collect()
}

/// What the body channels of a frame show: each channel's body measure (deg), each upper
/// arm's unit direction in body axes, and the head's rotation relative to the chest in body
/// axes (`Aᵀ R_chestᵀ R_head A`).
struct Shown {
    measures: Vec<f64>,
    arms: [[f64; 3]; 2],
    head: Mat3,
}

fn shown(ps: &PoseSkeleton, measures: &[BodyMeasure], world: &[Transform]) -> Shown {
    let sk = ps.skeleton();
    let body = ps.body();
    let axes = ps.body_axes().expect("a body frame");
    let chest = world[body.chest.unwrap()].rotation;
    let frame = mat_mul(&chest, &axes);
    let arm = |s: usize| {
        let a = body.arms[s].unwrap();
        let p = Body::point(sk, world, Effector::Joint(a.upper)).unwrap();
        let q = Body::point(sk, world, a.elbow).unwrap();
        let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        mat_vec(&transpose(&frame), &d.map(|v| v / n))
    };
    let head = world[body.head.unwrap()].rotation;
    Shown {
        measures: measures
            .iter()
            .map(|&m| body.measure(sk, world, &axes, m).unwrap())
            .collect(),
        arms: [arm(0), arm(1)],
        head: mat_mul(
            &transpose(&frame),
            &mat_mul(&transpose(&chest), &mat_mul(&head, &axes)),
        ),
    }
}

/// The largest difference of the arm directions and head rotations of two frames.
fn shown_gap(a: &Shown, b: &Shown) -> f64 {
    let arms = a.arms.iter().flatten().zip(b.arms.iter().flatten());
    let head = a.head.iter().flatten().zip(b.head.iter().flatten());
    arms.chain(head)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The body measure each channel of `blob` reads (all of them must be body channels).
fn body_measures(blob: &Blob<'_>) -> Vec<BodyMeasure> {
    let v = blob.skeleton().unwrap();
    (0..v.drives())
        .map(|c| match v.drive(c).unwrap().mode {
            DriveMode::Body(k) => BodyMeasure::from_index(k).unwrap(),
            m => panic!("channel {c} is not a body measure: {m:?}"),
        })
        .collect()
}

/// The shipped puppet rig reads body measures: its URDF has the eight channels as revolute
/// joints with the calibration's limits, and its forward kinematics (computed here as
/// robot_state_publisher would) show every channel's value exactly, for poses across the
/// limits: each measure read back from the URDF's links equals the pose's value, and the arm
/// directions, head rotation and elbow flexes equal those of the simulator's skeleton.
#[test]
fn body_puppet_urdf_shows_the_measures_exactly() {
    let s = setup();
    let bytes = std::fs::read(&s.puppet).unwrap();
    let blob = Blob::parse(&bytes).unwrap();
    let cals: Vec<ChannelCal> = (0..blob.channels())
        .map(|c| blob.calibration(c).unwrap())
        .collect();
    let robot = Robot::from_blob(&blob, &cals).unwrap();
    let names: Vec<&str> = blob.channel_names().collect();
    assert_eq!(robot.movable(), names);
    assert!(robot.approximate.is_empty());
    for j in &robot.joints {
        if let Motion::Turn {
            channel, limits, ..
        } = j.motion
        {
            let k = &cals[channel];
            let want =
                [k.min_deg, k.max_deg, k.max_slew_deg_per_s].map(|d| (d as f64).to_radians());
            let (lo, hi, v) = limits.expect("revolute");
            assert!(
                (lo - want[0]).abs() + (hi - want[1]).abs() + (v - want[2]).abs() < 1e-12,
                "{}",
                j.name
            );
        }
    }
    let measures = body_measures(&blob);
    let ps = PoseSkeleton::from_blob(&blob.skeleton().unwrap()).unwrap();
    let (mut worst_measure, mut worst_shape) = (0.0f64, 0.0f64);
    let mut poses = 0;
    // Inside the limits by 5 % of the range, so no arm points straight forward (swing 90,
    // where raise is undefined).
    for step in 0..=12 {
        let x = 0.05 + 0.9 * step as f32 / 12.0;
        let pose: Vec<f32> = cals
            .iter()
            .enumerate()
            .map(|(c, k)| {
                let t = if c % 2 == 0 { x } else { 1.0 - x };
                k.min_deg + t * (k.max_deg - k.min_deg)
            })
            .collect();
        let frames = robot.link_frames(&pose);
        let urdf = bvh_world(ps.skeleton(), |n| {
            let f = frames.iter().find(|f| f.0 == n).unwrap();
            (f.1, f.2)
        });
        let urdf = shown(&ps, &measures, &urdf);
        let sim = shown(
            &ps,
            &measures,
            &world_transforms(ps.skeleton(), &ps.frame(&pose)),
        );
        for (c, &want) in pose.iter().enumerate() {
            let want = want as f64;
            worst_measure = worst_measure
                .max((urdf.measures[c] - want).abs())
                .max((sim.measures[c] - want).abs());
        }
        worst_shape = worst_shape.max(shown_gap(&urdf, &sim));
        poses += 1;
    }
    eprintln!(
        "body puppet urdf, {poses} poses across the limits: measures within {worst_measure:.1e} \
         deg of the pose, arm directions and head rotation within {worst_shape:.1e} of the \
         simulator's"
    );
    assert!(worst_measure < 1e-6, "{worst_measure} deg");
    assert!(worst_shape < 1e-6, "{worst_shape}");
}

/// A body measure is a fixed chain only if nothing inside it turns: a channel on the left
/// clavicle, between the chest and the upper arm whose raise and swing the rig reads, is
/// refused, naming the channel and the joint.
#[test]
fn body_urdf_refuses_a_turning_joint_inside_a_measure() {
    let s = setup();
    let rig = std::fs::read_to_string(workspace().join("rigs/puppet-8ch.toml")).unwrap();
    let rig = format!(
        "{rig}\n[[channel]]\nname = \"left_clavicle\"\njoint = [\"LeftShoulder\"]\naxis = \"Z\"\n\
         neutral_deg = 0.0\nmin_deg = -20.0\nmax_deg = 20.0\ndirection = 1\n\
         pulse_neutral_us = 1500\nus_per_deg = 10.0\nmax_slew_deg_per_s = 200.0\n"
    );
    let tmp = tempfile::tempdir().unwrap();
    let rig_path = tmp.path().join("clavicle.toml");
    std::fs::write(&rig_path, rig).unwrap();
    let blob_path = tmp.path().join("clavicle.blob");
    let opts = gesture_trainer::pack::PackOptions {
        rig: Some(rig_path),
        ..gesture_trainer::pack::PackOptions::default()
    };
    gesture_trainer::pack::pack(
        &s.root.join("model.json"),
        std::slice::from_ref(&s.corpus),
        &opts,
        &blob_path,
    )
    .unwrap();
    let bytes = std::fs::read(&blob_path).unwrap();
    let blob = Blob::parse(&bytes).unwrap();
    let cals: Vec<ChannelCal> = (0..blob.channels())
        .map(|c| blob.calibration(c).unwrap())
        .collect();
    let e = Robot::from_blob(&blob, &cals).unwrap_err().to_string();
    assert!(
        e.contains("channel `left_clavicle` moves joint \"LeftShoulder\""),
        "{e}"
    );
}

/// A run of the shipped puppet, through the URDF the run wrote, read by ROS tools
/// (urdf-parser-py, forward kinematics as robot_state_publisher computes it): with the body
/// measures of the run's motion.bvh (the played poses) as positions, the URDF shows
/// motion.bvh's arm directions and head rotation within 1e-6 and every measure (the elbow
/// flexes too) within 1e-6 rad, on every frame; with the positions of the run's MCAP file
/// (rosbags; what the servos are commanded, which trail the played pose by the slew limit),
/// it shows those positions within 1e-6 rad.
#[test]
fn body_puppet_run_urdf_shows_motion_bvh() {
    let test = "body_puppet_run_urdf_shows_motion_bvh";
    let Some(python) = e2e_tests::ros2_python(test) else {
        return;
    };
    let s = setup();
    let (tmp, dir, mcap) = mcap_run(&s.puppet, &s.wav);
    let bytes = std::fs::read(&s.puppet).unwrap();
    let blob = Blob::parse(&bytes).unwrap();
    let measures = body_measures(&blob);
    let ps = PoseSkeleton::from_blob(&blob.skeleton().unwrap()).unwrap();
    let m = read_bvh(dir.join("motion.bvh")).unwrap();
    let n = m.frames();
    let bvh: Vec<Shown> = (0..n)
        .map(|f| shown(&ps, &measures, &world_pose(&m, f).unwrap()))
        .collect();

    let v = python_json(&python, &[&script("read_mcap.py"), &mcap]);
    let msgs = v["rosbags"].as_array().unwrap();
    assert_eq!(msgs.len(), n, "messages against motion.bvh's frames");
    let num = |v: &Value| v.as_f64().unwrap();
    let sent: Vec<Vec<f64>> = msgs
        .iter()
        .map(|m| m["position"].as_array().unwrap().iter().map(num).collect())
        .collect();
    let played: Vec<Vec<f64>> = bvh
        .iter()
        .map(|b| b.measures.iter().map(|d| d.to_radians()).collect())
        .collect();
    // Frames 0..n: motion.bvh's measures; n..2n: the messages' positions.
    let positions = tmp.path().join("positions.json");
    let all: Vec<&Vec<f64>> = played.iter().chain(&sent).collect();
    std::fs::write(
        &positions,
        serde_json::json!({"name": msgs[0]["name"], "frames": all}).to_string(),
    )
    .unwrap();
    let u = python_json(
        &python,
        &[&script("read_urdf.py"), &dir.join("robot.urdf"), &positions],
    );
    let movable = u["joints"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|j| j["type"] != "fixed")
        .count();
    assert_eq!(movable, measures.len());
    let urdf = |f: usize| {
        let world = bvh_world(ps.skeleton(), |name| {
            let r = &u["fk_rot"][f][name];
            let p = &u["fk"][f][name];
            (
                [0, 1, 2].map(|i| [0, 1, 2].map(|k| num(&r[i][k]))),
                [0, 1, 2].map(|i| num(&p[i])),
            )
        });
        shown(&ps, &measures, &world)
    };
    let gap = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x.to_radians() - y).abs())
            .fold(0.0, f64::max)
    };
    let (mut worst_played, mut worst_shape, mut worst_sent) = (0.0f64, 0.0f64, 0.0f64);
    let mut following = 0;
    for f in 0..n {
        let shows = urdf(f);
        worst_played = worst_played.max(gap(&shows.measures, &played[f]));
        worst_shape = worst_shape.max(shown_gap(&shows, &bvh[f]));
        worst_sent = worst_sent.max(gap(&urdf(n + f).measures, &sent[f]));
        if sent[f]
            .iter()
            .zip(&played[f])
            .all(|(a, b)| (a - b).abs() < 1e-4)
        {
            following += 1;
        }
    }
    eprintln!(
        "body puppet run, {n} frames, URDF by urdf-parser-py: with motion.bvh's measures, \
         measures within {worst_played:.1e} rad and arm directions and head rotation within \
         {worst_shape:.1e} of motion.bvh's; with the MCAP's positions, within {worst_sent:.1e} \
         rad of them (the servos on the played pose within 1e-4 rad on {following} frames)"
    );
    assert!(worst_played < 1e-6, "{worst_played} rad");
    assert!(worst_shape < 1e-6, "{worst_shape}");
    assert!(worst_sent < 1e-6, "{worst_sent} rad");
}

/// `urdf` and `run --mcap` refuse bad input with one line and exit 2.
#[test]
fn bad_ros_options_are_one_line_and_exit_2() {
    let s = setup();
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    for (extra, want) in [
        (vec!["--mcap", tmp.path().to_str().unwrap()], "is a folder"),
        (
            vec!["--mcap", "/no/such/folder/x.mcap"],
            "its folder does not exist",
        ),
        (
            vec!["--mcap", "x.mcap", "--ros2-topic", "/a b"],
            "not allowed",
        ),
        (
            vec!["--mcap", "x.mcap", "--ros2-topic", "/1x"],
            "starts with a digit",
        ),
    ] {
        let o = run_into(&s.full, &s.wav, &dir, &extra);
        common::refused(&o, &dir, want);
    }
    // --ros2-topic alone is a usage error.
    let o = run_into(&s.full, &s.wav, &dir, &["--ros2-topic", "/x"]);
    assert_eq!(o.status.code(), Some(2));
    #[cfg(not(feature = "ros2"))]
    {
        let o = run_into(&s.full, &s.wav, &dir, &["--ros2"]);
        common::refused(&o, &dir, "needs the `ros2` feature");
    }
    #[cfg(feature = "ros2")]
    {
        let o = Command::new(env!("CARGO_BIN_EXE_gesture-sim"))
            .args(["run", "--blob", s.full.to_str().unwrap(), "--audio"])
            .args([
                s.wav.to_str().unwrap(),
                "--out",
                dir.to_str().unwrap(),
                "--ros2",
            ])
            .env("ROS_DOMAIN_ID", "300")
            .output()
            .unwrap();
        common::refused(&o, &dir, "ROS_DOMAIN_ID=\"300\"");
    }
    let o = common::sim(&["urdf", "--blob", s.wav.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert_eq!(text(&o.stderr).lines().count(), 1);
}

/// How to enter a network namespace of one's own here: `unshare -n` as root, `unshare -rn`
/// (a user namespace mapping us to root) otherwise; `None` if neither works.
#[cfg(feature = "ros2")]
fn unshare() -> Option<Vec<&'static str>> {
    [vec!["unshare", "-n"], vec!["unshare", "-rn"]]
        .into_iter()
        .find(|u| {
            Command::new(u[0])
                .args(&u[1..])
                .args(["ip", "link", "set", "lo", "up"])
                .output()
                .is_ok_and(|o| o.status.success())
        })
}

/// The DDS messages of a real-time run reach a Cyclone DDS subscriber (no ROS installed):
/// in a network namespace with only loopback (multicast on), domain 7, at least 95 % of the
/// messages sent after the first one it received arrive, in order, with the names and
/// positions of motion.bvh (within 1e-6 rad) and stamps 1/fps apart on the audio clock.
#[cfg(feature = "ros2")]
#[test]
fn joint_states_reach_a_cyclone_dds_subscriber() {
    let test = "joint_states_reach_a_cyclone_dds_subscriber";
    let Some(python) = e2e_tests::ros2_python(test) else {
        return;
    };
    let Some(unshare) = unshare() else {
        e2e_tests::skip_ros2(test, "neither `unshare -n` nor `unshare -rn` works here");
        return;
    };
    let s = setup();
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    let recv = tmp.path().join("received.jsonl");
    let ready = tmp.path().join("ready");
    let sh = format!(
        r#"set -e
ip link set lo up multicast on
ip route add 224.0.0.0/4 dev lo
export ROS_DOMAIN_ID=7
"{py}" "{sub}" --out "{recv}" --ready "{ready}" --idle 3 --timeout 120 &
sub=$!
i=0; while [ ! -f "{ready}" ] && [ $i -lt 300 ]; do sleep 0.1; i=$((i+1)); done
"{sim}" run --blob "{blob}" --audio "{wav}" --out "{dir}" --no-video --ros2 --realtime
wait $sub
"#,
        py = python.display(),
        sub = script("subscriber.py").display(),
        recv = recv.display(),
        ready = ready.display(),
        sim = env!("CARGO_BIN_EXE_gesture-sim"),
        blob = s.full.display(),
        wav = s.wav.display(),
        dir = dir.display(),
    );
    let o = Command::new("timeout")
        .arg("240")
        .args(&unshare)
        .args(["sh", "-c", &sh])
        .output()
        .unwrap();
    let stdout = text(&o.stdout);
    assert!(o.status.success(), "{stdout}\n{}", text(&o.stderr));
    eprintln!("{stdout}");
    let line = stdout
        .lines()
        .find(|l| l.starts_with("ros2: published"))
        .expect("the run's ros2 line");
    let sent: usize = line.split_whitespace().nth(2).unwrap().parse().unwrap();
    assert!(line.contains("/joint_states (domain 7"), "{line}");
    let origin = line
        .rsplit("Unix time ")
        .next()
        .unwrap()
        .trim_end_matches(" s)");
    let (sec, nano) = origin.split_once('.').unwrap();
    let origin_ns: i64 = sec.parse::<i64>().unwrap() * 1_000_000_000 + nano.parse::<i64>().unwrap();

    let (names, frames, fps) = bvh_states(&dir);
    assert_eq!(sent, frames.len(), "sent against motion.bvh's frames");
    let got: Vec<Value> = std::fs::read_to_string(&recv)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert!(!got.is_empty(), "nothing received");
    let tick = |m: &Value| -> usize {
        let t = (stamp_ns(m) - origin_ns) as f64 * fps / 1e9;
        assert!(
            (t - t.round()).abs() < 1e-3,
            "stamp off the frame grid: {t}"
        );
        t.round() as usize
    };
    let first = tick(&got[0]);
    let after = sent - first;
    eprintln!(
        "dds: sent {sent}, received {} ({:.1} % of the {after} sent from the first received, \
         message {first})",
        got.len(),
        100.0 * got.len() as f64 / after as f64
    );
    assert!(
        got.len() as f64 >= 0.95 * after as f64,
        "received {} of {after}",
        got.len()
    );
    let mut prev: Option<(usize, i64)> = None;
    for m in &got {
        let k = tick(m);
        check_message(m, k, &names, &frames);
        let t = stamp_ns(m);
        assert_eq!(t - origin_ns, (k as f64 * 1e9 / fps).round() as i64);
        if let Some((pk, pt)) = prev {
            assert!(k > pk, "out of order or repeated: {pk} then {k}");
            let dt = (t - pt) as f64 / (k - pk) as f64;
            assert!(
                (dt - 1e9 / fps).abs() <= 1.0,
                "stamps {dt} ns apart per frame"
            );
        }
        prev = Some((k, t));
    }
}
