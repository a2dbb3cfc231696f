//! What leaves the controller is within the rig's limits and finite: a validated blob whose
//! frames are enormous (a huge frame scale) and whose cuts are inertialized used to hand the rig
//! infinite poses, and poses past a channel's limits reached the rig before its clamp.

use gesture_runtime::blob::encode::{OwnedLibrary, OwnedPayload, SegmentSpec};
use gesture_runtime::blob::{Blob, ControlSection};
use gesture_runtime::controller::{BlobController, ControllerEvent, DecisionTiming};
use gesture_runtime::policy::Variety;
use gesture_runtime::rig::ChannelCal;

fn poses(bytes: &[u8]) -> Vec<f32> {
    let blob = Blob::parse(bytes).unwrap();
    let mut ctl = BlobController::from_blob(&blob).unwrap();
    // Two seconds of a loud, syllable-like signal (decisions and cuts happen).
    let samples: Vec<i16> = (0..32_000)
        .map(|i| {
            let t = i as f32 / 16_000.0;
            let env = if (t * 4.0).fract() < 0.6 { 1.0 } else { 0.0 };
            (env * 12_000.0 * (t * 2.0 * core::f32::consts::PI * 180.0).sin()) as i16
        })
        .collect();
    let mut out = Vec::new();
    ctl.push(&samples, &mut |e| {
        if let ControllerEvent::Pose { pose, .. } = e {
            out.extend_from_slice(pose);
        }
    });
    out
}

#[test]
fn enormous_frames_and_blends_give_finite_poses_within_the_limits() {
    let mut p = OwnedPayload::example();
    let frames: Vec<Vec<f32>> = [1e30f32, -1e30, 1e30, -1e30, 3e30, -3e30]
        .iter()
        .map(|&v| vec![v])
        .collect();
    let seg = |start| SegmentSpec {
        start,
        len: 3,
        stroke: None,
        label: 0,
        continues: false,
    };
    p.library = OwnedLibrary::new(30.0, 1, &frames, &[seg(0), seg(3)], &[], &[]).unwrap();
    p.control = ControlSection::new(
        &DecisionTiming::DEFAULT,
        &Variety::NONE,
        &gesture_runtime::follow::VoiceFollow::NONE,
        400,
    );
    let out = poses(&p.encode().unwrap());
    assert!(out.len() > 50, "{} poses", out.len());
    let cal = ChannelCal::HOBBY;
    for v in &out {
        assert!(
            v.is_finite() && (cal.min_deg..=cal.max_deg).contains(v),
            "{v}"
        );
    }
    // Both limits are reached: the values were clamped, not zeroed.
    assert!(out.contains(&cal.max_deg) && out.contains(&cal.min_deg));
}

#[test]
fn poses_within_the_limits_pass_unchanged() {
    // The example's frames (0..20 degrees, quantized to 16 bits) are inside the hobby servo's
    // +-90 and come out as stored (no blend in the example).
    let out = poses(&OwnedPayload::example().encode().unwrap());
    let frames = [0.0f32, 10.0, 20.0, 20.0, 0.0, -20.0];
    assert!(
        out.iter()
            .all(|v| frames.iter().any(|f| (f - v).abs() < 1e-3)),
        "{out:?}"
    );
}
