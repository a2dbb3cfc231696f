//! The expression stage: the quick part of the motion scaled by the voice.
//!
//! A gesture's size follows the voice within a syllable or two in a speaker; segment choices
//! follow it only at exit points (a second or more apart), so on their own they underplay a
//! loud phrase and go on gesturing at full size into a pause. The stage splits each channel
//! into its **slow part** (an exponential moving average over [`SLOW_S`]) and its **quick
//! part** (the pose minus the slow part: the strokes, beats and holds of the gesture) and
//! shows `slow + gain x quick`: the *cartoon animation filter* of Wang et al. (SIGGRAPH 2006)
//! with a low-pass in place of its Laplacian of Gaussian, which would need future frames.
//! - The posture (where the hands hover, the lean, a rest's pose) is the slow part and is
//!   never moved: a gain below 1 shrinks the gesture around where it is, not towards some
//!   neutral pose, and a gain of 1 shows the frames exactly.
//! - The gain eases to the value the controller aims it at with a time constant of
//!   [`GAIN_S`]; a change of gain moves the hands by at most the quick part's size, smoothly.
//! - A rotation group (a joint's three Euler angles) is scaled as a rotation: the quick part is
//!   the rotation vector from the slow rotation to the pose's, scaled and applied to the pose
//!   (`exp((g - 1) d) q`), and the slow rotation moves along it (`exp(k d) q_slow`); single
//!   angles are scaled in degrees, the wrapped difference.
//!
//! The stage comes after the player's blend and rate, so a cut's inertialization and the
//! speed cap work on the library's frames as before; the slow part is continuous across cuts.
//! State: one value per channel and the gain; no allocation, no panics; a non-finite result
//! leaves the channel as the player gave it.

use super::{nearest_euler, LibraryFrames, MAX_CHANNELS};
use crate::rotation::{
    euler_angles, euler_matrix, quat_conj, quat_exp, quat_log, quat_matrix, quat_mul, quaternion,
    wrap_deg,
};

/// Time constant of the slow part (s): a stroke (a quarter to half a second) is quick, the
/// posture held over a phrase is slow.
pub const SLOW_S: f32 = 0.5;

/// Time constant (s) of each of the three first-order stages the gain eases through towards
/// its aim (a third-order critically damped response: 0.15 s to its centre). Through one
/// stage the gain's rate of change would jump at every new aim, and the motion's jerk with
/// it (on tuning speech, 1.8x the jerk of the frames).
pub const GAIN_S: f32 = 0.05;

/// The lowest and highest gain the stage takes.
pub const GAIN_RANGE: (f32, f32) = (0.0, 2.0);

/// A gain this close to its aim is at its aim (so a steady gain of 1 shows the frames).
const GAIN_EPSILON: f32 = 1.0e-3;

/// The expression stage's state (inside [`Player`](super::Player)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Expression {
    /// The slow part per channel (degrees; a group's three slots hold Euler angles).
    slow: [f32; MAX_CHANNELS],
    /// Whether `slow` holds a pose yet.
    started: bool,
    /// The gain's three easing stages; the last is the gain.
    stages: [f32; 3],
    aim: f32,
}

impl Expression {
    pub(super) const fn new() -> Self {
        Self {
            slow: [0.0; MAX_CHANNELS],
            started: false,
            stages: [1.0; 3],
            aim: 1.0,
        }
    }

    /// Aims the gain at `gain` (clamped into [`GAIN_RANGE`]; a non-finite one is ignored).
    pub(super) fn aim(&mut self, gain: f32) {
        if gain.is_finite() {
            self.aim = gain.clamp(GAIN_RANGE.0, GAIN_RANGE.1);
        }
    }

    /// The gain now.
    pub(super) fn gain(&self) -> f32 {
        self.stages[2]
    }

    /// The gain aimed at.
    pub(super) fn aimed(&self) -> f32 {
        self.aim
    }

    /// Moves the slow part one tick towards `out[..n]` and scales `out`'s quick part.
    pub(super) fn apply<L: LibraryFrames + ?Sized>(
        &mut self,
        lib: &L,
        out: &mut [f32; MAX_CHANNELS],
        n: usize,
    ) {
        let fps = lib.fps();
        let fps = if fps.is_finite() && fps > 0.0 {
            fps
        } else {
            1.0
        };
        if !self.started {
            self.slow[..n].copy_from_slice(&out[..n]);
            self.started = true;
        }
        let k_gain = 1.0 - libm::expf(-1.0 / (GAIN_S * fps));
        let mut towards = self.aim;
        for s in self.stages.iter_mut() {
            *s += (towards - *s) * k_gain;
            towards = *s;
        }
        if self
            .stages
            .iter()
            .all(|s| (s - self.aim).abs() < GAIN_EPSILON)
            || !self.stages.iter().all(|s| s.is_finite())
        {
            self.stages = [self.aim; 3];
        }
        let k = 1.0 - libm::expf(-1.0 / (SLOW_S * fps));
        let g = self.stages[2] - 1.0;
        // The channels of rotation groups, scaled as rotations first.
        let mut grouped = [0u32; MAX_CHANNELS.div_ceil(32)];
        for group in 0..lib.group_count() {
            let (first, order) = lib.group(group);
            if first.saturating_add(3) > n {
                continue;
            }
            for ch in first..first + 3 {
                grouped[ch / 32] |= 1 << (ch % 32);
            }
            let o = [order[0] as usize, order[1] as usize, order[2] as usize];
            let here = [out[first], out[first + 1], out[first + 2]];
            let before = [self.slow[first], self.slow[first + 1], self.slow[first + 2]];
            let q = quaternion(&euler_matrix(o, here));
            let qs = quaternion(&euler_matrix(o, before));
            let d = quat_log(&quat_mul(&q, &quat_conj(&qs)));
            let moved = quat_mul(&quat_exp(&d.map(|v| k * v)), &qs);
            let slow = nearest_euler(euler_angles(&quat_matrix(&moved), o), before, o);
            let slow = if slow.iter().all(|v| v.is_finite()) {
                slow
            } else {
                here
            };
            self.slow[first..first + 3].copy_from_slice(&slow);
            if g != 0.0 {
                let r = quat_mul(&quat_exp(&d.map(|v| g * v)), &q);
                let shown = nearest_euler(euler_angles(&quat_matrix(&r), o), here, o);
                if shown.iter().all(|v| v.is_finite()) {
                    out[first..first + 3].copy_from_slice(&shown);
                }
            }
        }
        // Single angles.
        for (ch, o) in out.iter_mut().enumerate().take(n) {
            if grouped[ch / 32] & (1 << (ch % 32)) != 0 {
                continue;
            }
            let d = wrap_deg(*o - self.slow[ch]);
            if !d.is_finite() {
                self.slow[ch] = *o;
                continue;
            }
            self.slow[ch] += k * d;
            let v = *o + g * d;
            if g != 0.0 && v.is_finite() {
                *o = v;
            }
        }
    }
}
