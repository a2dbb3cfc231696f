//! The motion pipeline on the real captures in `../shared/data` (ZeroEGGS and the 69 Bandai
//! Namco clips): parsing, round trips, FK bone lengths, hand lookup, segmentation figures.
//! Each test prints a message and passes when the data folder is absent.

use gesture_trainer::motion::fk::{self, FkPlan, Target};
use gesture_trainer::motion::segment::quantile;
use gesture_trainer::motion::{
    self, parse_bvh, read_bvh, write_bvh, Channel, EffectorSpec, Motion, Phase, SegmentParams,
};
use std::path::{Path, PathBuf};
use std::time::Instant;

fn data_dir() -> Option<PathBuf> {
    e2e_tests::shared_data("motion_real", "")
}

fn zeroeggs(dir: &Path) -> PathBuf {
    dir.join("zeroeggs-067-speech2/067_Speech_2_first50s.bvh")
}

fn bandai_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for sub in ["dataset-1", "dataset-2"] {
        let d = dir.join("bandai-namco-gestures").join(sub);
        for entry in std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display())) {
            let p = entry.unwrap().path();
            if p.extension().is_some_and(|e| e == "bvh") {
                files.push(p);
            }
        }
    }
    files.sort();
    files
}

const ZYX: [Channel; 3] = [Channel::Zrotation, Channel::Yrotation, Channel::Xrotation];
const ZXY: [Channel; 3] = [Channel::Zrotation, Channel::Xrotation, Channel::Yrotation];

#[test]
fn zeroeggs_parses() {
    let Some(dir) = data_dir() else { return };
    let t = Instant::now();
    let m = read_bvh(zeroeggs(&dir)).unwrap();
    eprintln!("ZeroEGGS parsed in {:?}", t.elapsed());
    let s = m.skeleton();
    assert_eq!(s.joints.len(), 75);
    assert_eq!(s.joints[0].name, "Hips");
    assert_eq!(s.joints[0].channels.len(), 6);
    assert!(s.joints[1..].iter().all(|j| j.channels[..] == ZYX));
    assert_eq!(m.channel_count(), 6 + 74 * 3);
    assert_eq!(m.frames(), 1500);
    assert!((m.fps() - 30.0).abs() < 1e-9);
    assert!((m.duration() - 50.0).abs() < 1e-9);
}

#[test]
fn all_bandai_clips_parse() {
    let Some(dir) = data_dir() else { return };
    let files = bandai_files(&dir);
    assert_eq!(files.len(), 69);
    for f in &files {
        let m = read_bvh(f).unwrap_or_else(|e| panic!("{e}"));
        let s = m.skeleton();
        assert_eq!(s.joints.len(), 22, "{}", f.display());
        assert_eq!(s.joints[0].name, "joint_Root");
        for j in &s.joints {
            assert_eq!(j.channels.len(), 6);
            assert_eq!(j.channels[3..], ZXY);
        }
        assert!(m.frames() > 0);
        assert!((m.frame_time() - 0.0333333).abs() < 1e-12);
    }
}

fn assert_round_trip(m: &Motion) {
    let mut out = Vec::new();
    write_bvh(m, &mut out).unwrap();
    let back = parse_bvh(std::str::from_utf8(&out).unwrap(), "rewritten.bvh").unwrap();
    assert_eq!(back.skeleton(), m.skeleton());
    assert_eq!(back.frames(), m.frames());
    assert_eq!(back.frame_time(), m.frame_time());
    for (a, b) in m.data().iter().zip(back.data()) {
        assert!(
            (a - b).abs() <= 1e-6 * a.abs().max(b.abs()) + 1e-24,
            "{a} vs {b}"
        );
    }
}

#[test]
fn real_files_round_trip() {
    let Some(dir) = data_dir() else { return };
    assert_round_trip(&read_bvh(zeroeggs(&dir)).unwrap());
    for f in bandai_files(&dir) {
        assert_round_trip(&read_bvh(&f).unwrap());
    }
}

/// Every bone keeps its length in every frame: |p_child - p_parent| equals the length of the
/// child's local translation (its offset, with translation channels replacing components),
/// and every end site stays at |end offset| from its joint.
fn assert_bone_lengths(m: &Motion) -> usize {
    let s = m.skeleton();
    let targets = fk::all_targets(s, true);
    let p = fk::target_positions(m, &targets).unwrap();
    let starts = s.channel_starts();
    let dist = |a: [f64; 3], b: [f64; 3]| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    let len = |v: [f64; 3]| dist(v, [0.0; 3]);
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * b.abs() + 1e-9;
    let mut checked = 0;
    for f in 0..m.frames() {
        let row = m.frame(f).unwrap();
        for (k, t) in targets.iter().enumerate() {
            let (got, want) = match *t {
                Target::Joint(j) => {
                    let Some(parent) = s.joints[j].parent else {
                        continue;
                    };
                    let joint = &s.joints[j];
                    let mut local = joint.offset;
                    for (c, ch) in joint.channels.iter().enumerate() {
                        if !ch.is_rotation() {
                            local[ch.axis()] = row[starts[j] + c];
                        }
                    }
                    (dist(p.get(f, k), p.get(f, parent)), len(local))
                }
                Target::EndSite(j) => (
                    dist(p.get(f, k), p.get(f, j)),
                    len(s.joints[j].end_site.unwrap()),
                ),
            };
            assert!(
                close(got, want),
                "{} frame {f} target {t:?}: {got} vs {want}",
                m.source()
            );
            checked += 1;
        }
    }
    checked
}

#[test]
fn fk_keeps_bone_lengths_on_real_data() {
    let Some(dir) = data_dir() else { return };
    let m = read_bvh(zeroeggs(&dir)).unwrap();
    // Without translation channels below the root, the bone is exactly the offset.
    assert!(m.skeleton().joints[1..]
        .iter()
        .all(|j| j.channels.iter().all(|c| c.is_rotation())));
    let n = assert_bone_lengths(&m);
    eprintln!("ZeroEGGS: {n} bone lengths checked");
    let mut total = 0;
    for f in bandai_files(&dir).iter().step_by(7) {
        total += assert_bone_lengths(&read_bvh(f).unwrap());
    }
    eprintln!("Bandai (every 7th clip): {total} bone lengths checked");
}

#[test]
fn fast_path_matches_full_fk() {
    let Some(dir) = data_dir() else { return };
    let m = read_bvh(zeroeggs(&dir)).unwrap();
    let hands = EffectorSpec::Hands
        .resolve(m.skeleton(), m.source())
        .unwrap();
    let plan = FkPlan::new(m.skeleton(), &hands.targets).unwrap();
    eprintln!("hands need {} of 75 joints", plan.evaluated_joints());
    assert!(plan.evaluated_joints() < 20);
    let t = Instant::now();
    let fast = plan.positions(&m).unwrap();
    let t_fast = t.elapsed();
    let t = Instant::now();
    let full = fk::joint_positions(&m);
    eprintln!("hands FK {t_fast:?}, full FK {:?}", t.elapsed());
    for f in 0..m.frames() {
        for (k, t) in hands.targets.iter().enumerate() {
            let Target::Joint(j) = *t else { unreachable!() };
            assert_eq!(fast.get(f, k), full.get(f, j));
        }
    }
}

#[test]
fn hands_resolve_on_both_skeletons() {
    let Some(dir) = data_dir() else { return };
    let m = read_bvh(zeroeggs(&dir)).unwrap();
    let e = EffectorSpec::Hands
        .resolve(m.skeleton(), m.source())
        .unwrap();
    assert_eq!(e.names, ["LeftHand", "RightHand"]);
    for f in bandai_files(&dir) {
        let m = read_bvh(&f).unwrap();
        let e = EffectorSpec::Hands
            .resolve(m.skeleton(), m.source())
            .unwrap();
        assert_eq!(e.names, ["Hand_L", "Hand_R"]);
    }
    // An explicit list, including end sites (the Bandai hands end in one).
    let m = read_bvh(&bandai_files(&dir)[0]).unwrap();
    let spec = EffectorSpec::joints(["Hand_L/end", "Toes_R", "head"]);
    let e = spec.resolve(m.skeleton(), m.source()).unwrap();
    assert_eq!(e.names, ["Hand_L/end", "Toes_R", "Head"]);
}

#[test]
fn zeroeggs_segmentation() {
    let Some(dir) = data_dir() else { return };
    let m = read_bvh(zeroeggs(&dir)).unwrap();
    let params = SegmentParams::default();
    let a = motion::analyze(&m, &EffectorSpec::Hands, &params).unwrap();
    let n = m.frames();
    assert_eq!(a.segments.first().unwrap().start_frame, 0);
    assert_eq!(a.segments.last().unwrap().end_frame, n);
    assert!(a
        .segments
        .windows(2)
        .all(|w| w[0].end_frame == w[1].start_frame));
    let min_frames = params.min_frames(m.frame_time());
    assert!(a.segments.iter().all(|s| s.len() >= min_frames));
    let durations: Vec<f64> = a
        .segments
        .iter()
        .map(|s| s.duration(m.frame_time()))
        .collect();
    let moving = a
        .segments
        .iter()
        .filter(|s| s.phase == Phase::Moving)
        .count();
    let q = |p| quantile(&durations, p);
    eprintln!(
        "ZeroEGGS: {} segments ({moving} moving) in {:.1} s; threshold {:.1} cm/s (speed median); \
         duration min {:.2} q10 {:.2} q25 {:.2} median {:.2} q75 {:.2} q90 {:.2} max {:.2} s; floor {:.2} cm",
        a.segments.len(),
        m.duration(),
        a.threshold,
        q(0.0),
        q(0.1),
        q(0.25),
        q(0.5),
        q(0.75),
        q(0.9),
        q(1.0),
        a.floor
    );
    assert!(
        (0.2..=1.5).contains(&q(0.5)),
        "median segment {:.2} s",
        q(0.5)
    );
    // Kinematic vectors: one per segment, finite, T adds up to the take.
    assert_eq!(a.y_raw.len(), a.segments.len());
    assert!(a.y_raw.iter().flatten().all(|v| v.is_finite()));
    let total_t: f64 = a.kinematics.iter().map(|k| k.t).sum();
    assert!((total_t - m.duration()).abs() < 1e-9);
    // Moving segments are faster than still ones on average.
    let mean_v = |phase| {
        let v: Vec<f64> = a
            .segments
            .iter()
            .zip(&a.kinematics)
            .filter(|(s, _)| s.phase == phase)
            .map(|(_, k)| k.v)
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    assert!(mean_v(Phase::Moving) > 1.5 * mean_v(Phase::Still));
    // Hands of a talking speaker are above a hanging arm (0) and mostly below the shoulder
    // (1), in limb lengths above the shoulder; the limb is 53.5 cm.
    assert!((a.limb_length - 53.5).abs() < 0.1, "limb {}", a.limb_length);
    assert!(a.kinematics.iter().all(|k| k.h > 0.0 && k.h < 2.0));
    let mean_h = a.kinematics.iter().map(|k| k.h).sum::<f64>() / a.kinematics.len() as f64;
    assert!(mean_h > 0.05 && mean_h < 1.0, "mean H {mean_h}");
    for k in ["T", "D", "V", "A", "C", "H"].iter().enumerate() {
        let col: Vec<f64> = a.y_raw.iter().map(|y| y[k.0]).collect();
        eprintln!(
            "  ln {}: median {:.3}, range {:.3}..{:.3}",
            k.1,
            quantile(&col, 0.5),
            quantile(&col, 0.0),
            quantile(&col, 1.0)
        );
    }
}

#[test]
fn bandai_clips_analyze_and_normalize() {
    let Some(dir) = data_dir() else { return };
    let mut corpus = Vec::new();
    for f in bandai_files(&dir) {
        let m = read_bvh(&f).unwrap();
        let a = motion::analyze(&m, &EffectorSpec::Hands, &SegmentParams::default()).unwrap();
        assert_eq!(a.segments.last().unwrap().end_frame, m.frames());
        assert!(a.floor.abs() < 1e-9, "the Bandai root sits on the floor");
        corpus.extend(a.y_raw);
    }
    let norm = motion::Normalization::fit(&corpus).unwrap();
    eprintln!(
        "Bandai: {} segments; mean {:?}; scale {:?}",
        corpus.len(),
        norm.mean,
        norm.scale
    );
    for d in 0..6 {
        let z: Vec<f64> = corpus.iter().map(|y| norm.apply(y)[d]).collect();
        let mean = z.iter().sum::<f64>() / z.len() as f64;
        let var = z.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / z.len() as f64;
        assert!(mean.abs() < 1e-9 && (var - 1.0).abs() < 1e-9);
    }
}
