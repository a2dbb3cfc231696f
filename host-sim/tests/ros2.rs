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
use gesture_runtime::blob::Blob;
use gesture_runtime::rig::ChannelCal;
use gesture_trainer::motion::fk::world_pose;
use gesture_trainer::motion::read_bvh;
use gesture_trainer::rig::PoseSkeleton;
use host_sim::ros2::urdf::{Robot, SCALE};
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
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    let mcap = tmp.path().join("run.mcap");
    let o = run_into(
        &s.full,
        &s.wav,
        &dir,
        &["--no-video", "--mcap", mcap.to_str().unwrap()],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    assert!(stdout.contains("robot.urdf ("), "{stdout}");
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

/// The puppet's URDF: the rig's eight channels as revolute joints with the calibration's
/// limits (parsed by urdf-parser-py), and, computed here as robot_state_publisher would, every
/// joint where the simulator's skeleton puts it for poses across the limits.
#[test]
fn puppet_urdf_has_the_rigs_joints_and_limits() {
    let s = setup();
    // The shipped rig's channels are body measures, which a URDF cannot show (refused, with
    // the reason); the same puppet in joint-rotation form can.
    let shipped_bytes = std::fs::read(&s.puppet).unwrap();
    let shipped = Blob::parse(&shipped_bytes).unwrap();
    let cals0: Vec<ChannelCal> = (0..shipped.channels())
        .map(|c| shipped.calibration(c).unwrap())
        .collect();
    let refused = Robot::from_blob(&shipped, &cals0).unwrap_err().to_string();
    assert!(refused.contains("is a body measure"), "{refused}");
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
