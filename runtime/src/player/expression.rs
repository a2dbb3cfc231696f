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
//! - The gain eases to the value the controller aims it at through three stages of
//!   [`GAIN_S`] each.
//! - **A change of gain changes the speed at once and the size over [`RELAX_S`].** Shown
//!   directly, `slow + gain x quick` moves the hands by the change of gain times the quick
//!   part as the gain changes: where the frames hold a stroke's end, a rising gain pushes the
//!   hands further out, a push no speaker makes, and the faster the gain follows the voice the
//!   harder it pushes. So each channel keeps a *lag*: at each tick it takes up the step
//!   `dgain x quick` and relaxes towards none with time constant [`RELAX_S`]; the shown pose
//!   is `slow + gain x quick + lag`. While the gain holds, the lag is gone and the pose is
//!   `slow + gain x quick` exactly; as it changes, the quick part's motion is shown at the new
//!   gain at once and its reach follows. (Relaxing over 0.15 s brought part of the push
//!   back: on tuning speech the jerk rose 3 % and the mean step at cuts with it, for
//!   +0.005 speech coupling.)
//! - Every channel is scaled in degrees, as the player blends single angles. A rotation
//!   group's three Euler angles (which the player keeps continuous) are scaled alike: for a
//!   quick part of a few tens of degrees away from the group's gimbal lock that is the
//!   rotation scaled. Near the lock (the middle angle [`GIMBAL_FADE`] from 0 or 180 degrees) a
//!   small rotation swings the outer two angles far and in opposite ways, so the gain fades to
//!   none there; it fades too where the group's quick part is larger than a gesture's
//!   ([`QUICK_FADE`]), and past that the angles swung between two Euler forms of about one
//!   rotation (as Bandai Namco's spine does near its lock): an average across the swing is no
//!   posture, so the group's slow part starts again from the frames. Scaling the rotation
//!   vector itself (quaternions) was built first: the same motion, but 3.4 KB more code on the
//!   boards, past the 96 KiB budget.
//!
//! - A cut's blend is not quick motion and is not scaled. The stage comes after the player's
//!   blend and rate; at a cut the slow part moves by the blend's offset with the frames
//!   (`Expression::cut`), and the share of the offset the blend still adds is taken off the
//!   quick part. So the quick part goes on through the cut as the frames make it, and the
//!   blend closes the offset as at a gain of 1, within the player's speed cap. Scaled, a
//!   blend from a rest into a stroke as the gain rises with the speech overshoots the new
//!   frames and moves faster than the cap (on held-out speech the hands' largest step at a
//!   cut was 2.27 cm, over the capture's 99th-percentile step of 2.23; now 1.42).
//!
//! State: three values per channel and the gain; no allocation, no panics; a non-finite
//! result leaves the channel as the player gave it.

use super::library::LibraryFrames;
use crate::rig::MAX_CHANNELS;
use crate::rotation::wrap_deg;

/// Time constant of the slow part (s): a stroke (a quarter to half a second) is quick, the
/// posture held over a phrase is slow.
pub const SLOW_S: f32 = 0.5;

/// Time constant (s) of each of the three first-order stages the gain eases through towards
/// its aim (a third-order critically damped response: 75 ms to its centre). Through one
/// stage the gain's rate of change would jump at every new aim, and the motion's jerk with
/// it (on tuning speech, 1.8x the jerk of the frames).
pub const GAIN_S: f32 = 0.025;

/// Time constant (s) over which a change of gain moves the shown pose: at once it changes
/// the quick part's speed, and its size follows over this time, so the hands are not pushed
/// out or pulled in by the change itself.
pub const RELAX_S: f32 = 0.25;

/// A lag this small (degrees) is none, so a steady gain of 1 shows the frames exactly.
const LAG_EPSILON: f32 = 1.0e-4;

/// The lowest and highest gain the stage takes.
pub const GAIN_RANGE: (f32, f32) = (0.0, 2.0);

/// A rotation group's middle angle (degrees from its nearest 0 or 180) up to which the gain
/// applies in full, and from which it does not apply (faded linearly between).
pub const GIMBAL_FADE: (f32, f32) = (45.0, 70.0);

/// A rotation group's quick part (degrees, its largest angle) up to which the gain applies in
/// full, and from which it does not apply (faded linearly between).
pub const QUICK_FADE: (f32, f32) = (60.0, 90.0);

/// A gain this close to its aim is at its aim (so a steady gain of 1 shows the frames).
const GAIN_EPSILON: f32 = 1.0e-3;

/// The expression stage's state (inside [`Player`](super::Player)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Expression {
    /// The slow part per channel (degrees; a group's three slots hold Euler angles).
    slow: [f32; MAX_CHANNELS],
    /// The last cut's offset per channel (degrees), and the share of it the player's blend
    /// added at the last tick: that part of the pose is not scaled.
    cut: [f32; MAX_CHANNELS],
    /// Per channel, what a change of gain has not yet moved the shown pose by (degrees): it
    /// relaxes towards none over [`RELAX_S`].
    lag: [f32; MAX_CHANNELS],
    left: f32,
    /// Whether `slow` holds a pose yet.
    started: bool,
    /// The gain's three easing stages; the last is the gain.
    stages: [f32; 3],
    /// Per tick: the slow part's and each easing stage's step (from the library's fps, at
    /// the first tick).
    k_slow: f32,
    k_gain: f32,
    k_relax: f32,
    /// The gain at the tick before.
    before: f32,
    aim: f32,
}

impl Expression {
    pub(super) const fn new() -> Self {
        Self {
            slow: [0.0; MAX_CHANNELS],
            cut: [0.0; MAX_CHANNELS],
            lag: [0.0; MAX_CHANNELS],
            left: 0.0,
            started: false,
            stages: [1.0; 3],
            k_slow: 0.0,
            k_gain: 0.0,
            k_relax: 0.0,
            before: 1.0,
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

    /// A cut on channel `ch` whose blend starts from `offset` (the last pose minus the new
    /// frames, in degrees): the slow part moves by it with the frames, so the quick part goes
    /// on as it was, and the offset, which the blend closes, is not scaled.
    pub(super) fn cut(&mut self, ch: usize, offset: f32) {
        if self.started && offset.is_finite() {
            self.slow[ch] -= offset - self.left * self.cut[ch];
            self.cut[ch] = offset;
        }
    }

    /// Channel `ch` with quick part `d` ([`Self::quick`]): its slow part `k` of the way to the
    /// frames, the quick part shown at the gain, with the gain's excess and its change this
    /// tick weighted by `w` (the group's fade), plus the channel's lag.
    fn channel(&mut self, out: &mut [f32; MAX_CHANNELS], ch: usize, k: f32, w: f32, d: f32) {
        let (g, dg) = (self.stages[2] - 1.0, self.stages[2] - self.before);
        let (g, dg) = (g * w, dg * w);
        if !d.is_finite() {
            self.slow[ch] = out[ch];
            self.lag[ch] = 0.0;
            return;
        }
        self.slow[ch] += k * d;
        let lag = (self.lag[ch] - dg * d) * (1.0 - self.k_relax);
        let lag = if lag.abs() < LAG_EPSILON { 0.0 } else { lag };
        let v = out[ch] + g * d + lag;
        if v.is_finite() {
            self.lag[ch] = lag;
            out[ch] = v;
        } else {
            self.lag[ch] = 0.0;
        }
    }

    /// Channel `ch`'s quick part: the frames (`out[ch]` without the blend's offset) less the
    /// slow part, wrapped for a group's angle (which may come back a turn away after a cut).
    fn quick(&self, out: &[f32; MAX_CHANNELS], ch: usize, wrap: bool) -> f32 {
        let (d, c) = (out[ch] - self.slow[ch], self.left * self.cut[ch]);
        if wrap {
            wrap_deg(d) - wrap_deg(c)
        } else {
            d - c
        }
    }

    /// Moves the slow part one tick towards `out[..n]` and scales `out`'s quick part; `left`
    /// is the share of the last cut's offset in `out` (the player's blend).
    pub(super) fn apply<L: LibraryFrames + ?Sized>(
        &mut self,
        lib: &L,
        out: &mut [f32; MAX_CHANNELS],
        n: usize,
        left: f32,
    ) {
        self.left = left;
        if !self.started {
            self.slow[..n].copy_from_slice(&out[..n]);
            self.started = true;
            let fps = lib.fps();
            let fps = if fps.is_finite() && fps > 0.0 {
                fps
            } else {
                1.0
            };
            self.k_gain = 1.0 - libm::expf(-1.0 / (GAIN_S * fps));
            self.k_slow = 1.0 - libm::expf(-1.0 / (SLOW_S * fps));
            self.k_relax = 1.0 - libm::expf(-1.0 / (RELAX_S * fps));
        }
        let (k_gain, k) = (self.k_gain, self.k_slow);
        self.before = self.stages[2];
        let mut towards = self.aim;
        for s in self.stages.iter_mut() {
            *s += (towards - *s) * k_gain;
            towards = *s;
        }
        // The first stage is the furthest from the aim (they move towards it in turn).
        let off = (self.stages[0] - self.aim).abs() + (self.stages[2] - self.aim).abs();
        if off < GAIN_EPSILON || !off.is_finite() {
            self.stages = [self.aim; 3];
        }
        // A rotation group's angles are scaled as a single angle's, but less near its gimbal
        // lock (see the module docs).
        let mut done = [0u32; MAX_CHANNELS.div_ceil(32)];
        for group in 0..lib.group_count() {
            let (first, _) = lib.group(group);
            if first.saturating_add(3) > n {
                continue;
            }
            let b = wrap_deg(out[first + 1]).abs();
            let b = if b > 90.0 { 180.0 - b } else { b };
            let mut d = [0.0f32; 3];
            for (i, d) in d.iter_mut().enumerate() {
                *d = self.quick(out, first + i, true);
            }
            let q = d.iter().fold(0.0f32, |q, d| q.max(d.abs()));
            let w = ((GIMBAL_FADE.1 - b) / (GIMBAL_FADE.1 - GIMBAL_FADE.0))
                .min((QUICK_FADE.1 - q) / (QUICK_FADE.1 - QUICK_FADE.0))
                .clamp(0.0, 1.0);
            if q >= QUICK_FADE.1 {
                // No gesture moves this far from its posture in half a second: the angles
                // swung between two Euler forms of about one rotation, and an average across
                // the swing is no posture. The slow part starts again from the frames.
                for (i, d) in d.iter_mut().enumerate() {
                    let ch = first + i;
                    self.slow[ch] = out[ch] - self.left * self.cut[ch];
                    self.lag[ch] = 0.0;
                    *d = self.quick(out, ch, true);
                }
            }
            for (i, &d) in d.iter().enumerate() {
                let ch = first + i;
                self.channel(out, ch, k, w, d);
                done[ch / 32] |= 1 << (ch % 32);
            }
        }
        // Single angles, in degrees as the player blends them (not wrapped: a servo's 170 and
        // -170 degrees are far apart).
        for ch in 0..n {
            if done[ch / 32] & (1 << (ch % 32)) == 0 {
                let d = self.quick(out, ch, false);
                self.channel(out, ch, k, 1.0, d);
            }
        }
    }
}
