//! Speech-motion alignment: the runtime front-end's steps (syllables and pause steps), each with
//! its normalized prosody features and the time-weighted kinematic target of the motion it
//! overlaps (docs/method.md, "Time step = syllable (or pause step)").
//!
//! The target of step `[a, b)` is `sum_s w_s y_s / sum_s w_s` over the motion segments `s` it
//! overlaps, `w_s` the overlap in seconds and `y_s` the segment's log-scale kinematic vector.
//! Steps that overlap no motion (past the end of a slightly shorter BVH) are dropped. Prosody
//! features come from the runtime's [`StepNormalizer`], the code the device runs.

use gesture_runtime::inference::{StepFeatures, StepNormalizer};
use gesture_runtime::prosody::Step;

use crate::motion::TakeAnalysis;

/// One step with its features and kinematic target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlignedStep {
    /// The front-end's step.
    pub step: Step,
    /// Normalized prosody features (what the GMM sees).
    pub features: StepFeatures,
    /// Time-weighted log-scale kinematic vector (not yet normalized).
    pub y_raw: [f64; 6],
    /// Fraction of the step covered by motion.
    pub coverage: f64,
}

/// Aligns `steps` with the segments of `motion` (which has `frames` frames).
pub fn align(steps: &[Step], motion: &TakeAnalysis, frames: usize) -> Vec<AlignedStep> {
    let dt = motion.frame_time;
    let end_s = frames as f64 * dt;
    let mut norm = StepNormalizer::new();
    let mut out = Vec::with_capacity(steps.len());
    let mut first_seg = 0usize;
    for step in steps {
        // Features are computed for every step, in order, as the device does.
        let features = norm.push(step);
        let (a, b) = (step.start_s(), step.end_s());
        let len = (b - a).max(1e-9);
        if a >= end_s {
            continue;
        }
        while first_seg < motion.segments.len()
            && motion.segments[first_seg].end_frame as f64 * dt <= a
        {
            first_seg += 1;
        }
        let mut y = [0.0f64; 6];
        let mut wsum = 0.0;
        for (seg, ys) in motion.segments[first_seg..]
            .iter()
            .zip(&motion.y_raw[first_seg..])
        {
            let (s0, s1) = (seg.start_frame as f64 * dt, seg.end_frame as f64 * dt);
            if s0 >= b {
                break;
            }
            let w = (b.min(s1) - a.max(s0)).max(0.0);
            if w > 0.0 {
                for d in 0..6 {
                    y[d] += w * ys[d];
                }
                wsum += w;
            }
        }
        if wsum <= 0.0 {
            continue;
        }
        y.iter_mut().for_each(|v| *v /= wsum);
        out.push(AlignedStep {
            step: *step,
            features,
            y_raw: y,
            coverage: (wsum / len).min(1.0),
        });
    }
    out
}
