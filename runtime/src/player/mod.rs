//! Playing library segments as rig poses, one frame per animation tick, with seamless cuts.
//!
//! **Inertialization at every cut** (and self-loop). Switching segments leaves the pose where
//! it was; the new segment's frames are played from their first frame, and the difference
//! (the *offset*: last pose shown minus the new segment's first frame, and its velocity) is
//! added on top and decays to zero over the blend time as a critically damped third-order
//! response: `x(n) = (x0 + (v0 + a x0) n + (a v0 + a^2 x0 / 2) n^2) e^(-a n)` for tick `n`
//! after the cut, `a = 8.41 / blend_ticks` (1 % left at the end, where the offset is
//! dropped). The pose and its velocity are continuous across the cut, the offset adds no
//! acceleration of its own there (its second derivative starts at 0: a second-order spring,
//! `(x0 + (v0 + a x0) n) e^(-a n)`, kicks by `a^2 x0` at once, which for a rest-to-gesture cut
//! of 30 degrees was several times the motion's own acceleration: on held-out speech the
//! hands' mean jerk fell by 6 % and their mean step at a cut from 0.37 to 0.28 cm), and after
//! the blend the library's frames come back exactly.
//! Unlike a crossfade, the new motion starts at once (its stroke is not delayed), and unlike a
//! linear blend, no frame jumps.
//!
//! **Speed cap.** Closing a large offset in the blend time is itself a fast swing. With
//! [`Player::set_speed_cap`] (the controller sets [`library_speed_cap`], the library's own
//! 99th percentile per-frame channel change), a cut whose spring would move faster than the
//! cap at its fastest (`2 a x0 / e^2` per tick for the largest offset `x0`, at `n = 2 / a`)
//! blends longer, up to
//! [`MAX_BLEND_STRETCH`] times the set time. The velocity a cut carries on is held within the
//! cap too: the offset's velocity decays with the blend, so a pose moving away from the new
//! frames keeps going for a while (about `0.84 v0 / a` further, the longer the blend the
//! further), and a pose already faster than the library ever moves (a cut during another
//! cut's blend, out of a fast stroke) swung a held-out run's arm 140 degrees past the new
//! frames and back, a hand step of 28 cm in one frame. Within the library's 99th-percentile
//! speed the pose's velocity is continuous across a cut as before. A cut into one of the
//! library's rest segments ([`Player::set_rest_segments`]: the character comes to rest in a
//! pause) drifts in at [`REST_BLEND`] of the cap, stretched up to [`REST_STRETCH`] times the
//! blend time, while the velocity it carries dies out over the blend time as at any cut (the
//! offset and the velocity then decay at two paces, each a third-order response): arms
//! lowered at a gesture's pace read as dropped, and moved a second into a pause as fast as a
//! gesture; carried over the long drift, the velocity would coast on for a second.
//!
//! Channels are blended as what they are:
//! - a single angle (a servo, a twist, one Euler angle of a puppet): offset in degrees, linear
//!   (a servo's 170 and -170 degrees are far apart, not neighbours);
//! - a **rotation group** (three channels holding one joint's rotation as Euler angles in a
//!   given order, as the full-skeleton rig stores BVH joints): the offset is a rotation
//!   (`q_out = exp(x) q_frame`, `x` a rotation vector), so the blend is quaternion-correct
//!   whatever the Euler angles do, and the output angles are the decomposition closest to the
//!   frame's own (no 360-degree flips).
//!
//! **Running on.** [`Player::run_on`] moves from a segment's last frame into the segment stored
//! after it (its recorded successor) without a cut, so the body keeps moving while the
//! controller waits for a syllable onset.
//!
//! **Playback rate.** [`Player::set_rate`] slows playback down to [`MIN_RATE`] (0.3 of the
//! library's pace) or speeds it up to [`MAX_RATE`], interpolating between frames: the
//! controller plays a calm segment slower while the character rests if the segment moves
//! faster than a rest should ([`crate::follow::rest_rate`], at least half the pace), and with
//! look-ahead it stretches or hurries a stroke's preparation so the stroke lands on a coming
//! syllable (the stroke itself at the library's pace).
//!
//! **Expression.** After the blend, [`Player::set_gain`] scales the quick part of the frames'
//! motion around its slow part (the posture), eased in, and leaves a cut's blend as it is
//! ([`expression`]): the controller aims it from the voice. A gain of 1 shows the frames.
//!
//! Invariants: fixed memory (a few arrays of [`MAX_CHANNELS`] values), no allocation, no panics;
//! every output value is finite (non-finite library values are replaced by the previous
//! output, non-finite offsets by none).

pub mod expression;
mod library;

use crate::rest::RestSet;
use expression::Expression;

pub use library::{library_speed_cap, within_limits, LibraryFrames};

use crate::rotation::{
    euler_angles, euler_matrix, quat_conj, quat_exp, quat_log, quat_matrix, quat_mul, quaternion,
    wrap_deg,
};

/// Most rig channels a pose can have.
pub const MAX_CHANNELS: usize = crate::rig::MAX_CHANNELS;

/// Decay of the blend's offset over the blend: `a * blend_ticks`, where
/// `(1 + s + s^2 / 2) e^-s` is 1 %.
const SETTLE: f32 = 8.406;

/// The blend's fastest step over `a x0`: `2 / e^2`.
const PEAK: f32 = 2.0 / (core::f32::consts::E * core::f32::consts::E);

/// The longest a cut's blend is stretched to keep the offset within the speed cap, as a
/// multiple of the set blend time.
pub const MAX_BLEND_STRETCH: u32 = 3;

/// The share of the speed cap a cut into a rest segment drifts in at (see the module docs):
/// the posture the gesture paused in is held and eases into the rest's over seconds. On the
/// shared takes, half the cap (stretched at most 3 times) moved the hands a second into each
/// pause as fast as a gesture; a twentieth (stretched at most [`REST_STRETCH`] times) and
/// holding the posture outright gave the same coupling and settling within 0.01 (30 runs;
/// docs/method.md), and 0.15 over at most 4 s left the hands drifting at 15-20 cm/s for
/// seconds (the 001 take with the 067 library: a third of their speaking speed).
pub const REST_BLEND: f32 = 0.05;

/// The longest a cut into a rest segment is stretched, as a multiple of the set blend time
/// (10 s at the default 400 ms).
pub const REST_STRETCH: u32 = 25;

/// The slowest playback rate (frames per tick): 0.3 of the library's pace, reached only on a
/// stroke's preparation when look-ahead lands it on a syllable (the preparation waits, as a
/// speaker's pre-stroke hold does; `controller::WARP_MIN`). Everything else plays at half
/// the pace or more ([`crate::follow::rest_rate`]).
pub const MIN_RATE: f32 = 0.3;

/// The fastest playback rate (frames per tick): half again the library's pace, reached only
/// on a stroke's preparation when look-ahead lands it on a syllable (`controller::WARP_MAX`).
pub const MAX_RATE: f32 = 1.5;

/// A phase this close to a whole frame counts as one (so a rate of 1 never interpolates).
const RATE_EPSILON: f32 = 1.0e-4;

/// What a controller asks of its player between two ticks, besides playing the next frame:
/// everything a show file records so that a bare player, given the same library, shows the
/// same poses ([`crate::controller::ControllerEvent::Play`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PlayerCommand {
    /// [`Player::enter_at`]: cut to `segment` at `frame`.
    Enter {
        /// The segment entered.
        segment: u16,
        /// Its first frame shown.
        frame: u16,
    },
    /// [`Player::run_on`]: into the recorded successor without a cut.
    RunOn,
    /// [`Player::turn`]: play the other way.
    Turn,
    /// [`Player::set_rate`]: frames per tick from this tick on.
    Rate(f32),
    /// [`Player::set_gain`]: the expression gain aimed at from this tick on.
    Gain(f32),
    /// This tick shows the same frame again ([`Player::tick_advancing`] with `advance` false).
    Hold,
}

impl Player {
    /// Carries out `command` (a show's playback; [`PlayerCommand::Hold`] is the tick's own
    /// business and does nothing here).
    pub fn apply<L: LibraryFrames + ?Sized>(&mut self, lib: &L, command: PlayerCommand) {
        match command {
            PlayerCommand::Enter { segment, frame } => {
                if (segment as usize) < lib.segment_count() {
                    self.enter_at(lib, segment as usize, frame as usize);
                }
            }
            PlayerCommand::RunOn => self.run_on(lib),
            PlayerCommand::Turn => self.turn(),
            PlayerCommand::Rate(r) => self.set_rate(r),
            PlayerCommand::Gain(g) => self.set_gain(g),
            PlayerCommand::Hold => {}
        }
    }
}

/// Segment playback with inertialized cuts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Player {
    segment: usize,
    frame: usize,
    last: [f32; MAX_CHANNELS],
    prev: [f32; MAX_CHANNELS],
    outputs: u32,
    /// Offset at the cut: degrees per channel, or a rotation vector (radians) in a group's
    /// three slots.
    off: [f32; MAX_CHANNELS],
    /// Offset velocity at the cut, per tick.
    vel: [f32; MAX_CHANNELS],
    /// Ticks since the cut (blending while below `cut_ticks`).
    since: u32,
    blend_ticks: u32,
    /// This cut's blend time: `blend_ticks`, stretched for a large offset.
    cut_ticks: u32,
    /// The time over which this cut's carried velocity decays: `cut_ticks`, or for a cut
    /// into a rest `blend_ticks` (the offset itself drifts out slower, [`REST_BLEND`]).
    vel_ticks: u32,
    /// Fastest the offset may move (degrees per tick at its start; 0: no cap).
    speed_cap: f32,
    blending: bool,
    /// Frames advanced per tick ([`MIN_RATE`]..=[`MAX_RATE`]).
    rate: f32,
    /// How far playback stands between `frame` and the next frame (0..1).
    phase: f32,
    /// Playing the segment backwards (see [`Player::turn`]).
    backward: bool,
    /// The expression stage after the blend ([`expression`]).
    expression: Expression,
    /// The library's rest segments (entered at [`REST_BLEND`] of the speed cap).
    rest: RestSet,
}

impl Player {
    /// At frame 0 of segment 0, all channels at 0 until the first frame is played; cuts are
    /// hard until [`set_blend_ticks`](Self::set_blend_ticks).
    pub const fn new() -> Self {
        Self {
            segment: 0,
            frame: 0,
            last: [0.0; MAX_CHANNELS],
            prev: [0.0; MAX_CHANNELS],
            outputs: 0,
            off: [0.0; MAX_CHANNELS],
            vel: [0.0; MAX_CHANNELS],
            since: 0,
            blend_ticks: 0,
            cut_ticks: 0,
            vel_ticks: 0,
            speed_cap: 0.0,
            blending: false,
            rate: 1.0,
            phase: 0.0,
            backward: false,
            expression: Expression::new(),
            rest: RestSet::EMPTY,
        }
    }

    /// Aims the expression gain: the quick part of the motion (around its slow part) is shown
    /// this many times its size from now on, eased in over [`expression::GAIN_S`]; 1 shows
    /// the frames. Clamped into [`expression::GAIN_RANGE`]; a non-finite gain is ignored.
    pub fn set_gain(&mut self, gain: f32) {
        self.expression.aim(gain);
    }

    /// The expression gain aimed at ([`set_gain`](Self::set_gain)).
    pub fn gain_aim(&self) -> f32 {
        self.expression.aimed()
    }

    /// The expression gain this tick (easing towards its aim).
    pub fn gain(&self) -> f32 {
        self.expression.gain()
    }

    /// Turns playback around: from a segment's last frame it plays back towards its first,
    /// where it turns forward again by itself (a rest played to and fro at its own pace, with
    /// no cut). Entering a segment plays it forward.
    pub fn turn(&mut self) {
        self.backward = !self.backward;
    }

    /// Whether the segment is played backwards.
    pub fn backward(&self) -> bool {
        self.backward
    }

    /// Plays `rate` frames per tick from the next tick on, clamped to
    /// [`MIN_RATE`]..=[`MAX_RATE`] (1:
    /// the library's own pace; a non-finite rate is 1). Between frames the pose is
    /// interpolated linearly (a channel whose two frames are more than 180 degrees apart, a
    /// wrap, holds the earlier frame), so slower playback stays smooth.
    pub fn set_rate(&mut self, rate: f32) {
        self.rate = if rate.is_finite() {
            rate.clamp(MIN_RATE, MAX_RATE)
        } else {
            1.0
        };
    }

    /// Where playback stands within the segment: the next frame plus the phase towards the one
    /// after it.
    pub fn position(&self) -> f32 {
        self.frame as f32 + self.phase
    }

    /// Frames advanced per tick.
    pub fn rate(&self) -> f32 {
        self.rate
    }

    /// Cuts blend over `ticks` animation ticks (0: hard cuts).
    pub fn set_blend_ticks(&mut self, ticks: u32) {
        self.blend_ticks = ticks;
    }

    /// The library's rest segments ([`RestSet`]): a cut into one blends at
    /// [`REST_BLEND`] of the speed cap (none by default).
    pub fn set_rest_segments(&mut self, rest: RestSet) {
        self.rest = rest;
    }

    /// The blend time of a cut (ticks), as set ([`set_blend_ticks`](Self::set_blend_ticks)).
    pub fn blend_ticks(&self) -> u32 {
        self.blend_ticks
    }

    /// Caps how fast a blend moves the pose: a cut whose offset (the largest over channels,
    /// in degrees; a rotation group's angle) would decay faster than `deg_per_tick` at its
    /// fastest gets a longer blend, up to [`MAX_BLEND_STRETCH`] times the set time (0 or a
    /// non-finite value: no cap), and the velocity a cut carries on is held within it (per
    /// single angle; a rotation group's turning about each axis). The controller sets
    /// [`library_speed_cap`].
    pub fn set_speed_cap(&mut self, deg_per_tick: f32) {
        self.speed_cap = if deg_per_tick.is_finite() && deg_per_tick > 0.0 {
            deg_per_tick
        } else {
            0.0
        };
    }

    /// Current segment.
    pub fn segment(&self) -> usize {
        self.segment
    }

    /// Current frame within the segment (the next one to be played).
    pub fn frame(&self) -> usize {
        self.frame
    }

    /// Whether the last frame of the segment has been played (the next tick holds it).
    pub fn at_end<L: LibraryFrames + ?Sized>(&self, lib: &L) -> bool {
        self.frame + 1 >= lib.segment_len(self.segment).max(1) && self.outputs > 0
    }

    /// Moves on into segment `segment + 1` at its first frame without a cut (it must be the
    /// recorded successor: [`LibraryFrames::continues`]); a blend in progress goes on.
    pub fn run_on<L: LibraryFrames + ?Sized>(&mut self, lib: &L) {
        if lib.continues(self.segment) && self.segment + 1 < lib.segment_count() {
            self.segment += 1;
            self.frame = 0;
            self.phase = 0.0;
            self.backward = false;
        }
    }

    /// Cuts to segment `c` at its first frame, inertializing from the last output pose.
    pub fn enter<L: LibraryFrames + ?Sized>(&mut self, lib: &L, c: usize) {
        self.enter_at(lib, c, 0);
    }

    /// Cuts to segment `c` at frame `f` (clamped into the segment), inertializing from the
    /// last output pose.
    pub fn enter_at<L: LibraryFrames + ?Sized>(&mut self, lib: &L, c: usize, f: usize) {
        let len = lib.segment_len(c).max(1);
        let f = f.min(len - 1);
        self.segment = c;
        self.frame = f;
        self.phase = 0.0;
        self.backward = false;
        self.since = 0;
        self.cut_ticks = self.blend_ticks;
        self.vel_ticks = self.blend_ticks;
        self.blending = self.blend_ticks > 0 && self.outputs > 0;
        let n = lib.channels().min(MAX_CHANNELS);
        let moving = self.outputs > 1;
        let next = (f + 1).min(len - 1);
        // The offset is taken at the time of the last output, one tick before the new
        // segment's first frame shows: against that frame extrapolated one tick back.
        for ch in 0..n {
            let t0 = self.target(lib, c, f, ch);
            let t1 = self.target(lib, c, next, ch);
            let x0 = self.last[ch] - (t0 - (t1 - t0));
            self.expression.cut(ch, x0);
            if !self.blending {
                continue;
            }
            let src_v = if moving {
                self.last[ch] - self.prev[ch]
            } else {
                0.0
            };
            let v0 = src_v - (t1 - t0);
            self.off[ch] = if x0.is_finite() { x0 } else { 0.0 };
            self.vel[ch] = if v0.is_finite() { v0 } else { 0.0 };
        }
        if !self.blending {
            return;
        }
        // The largest offset (degrees), for the speed cap: scalar channels as they are, a
        // rotation group as its angle.
        let mut grouped = [0u8; MAX_CHANNELS / 8];
        let mut largest = 0.0f32;
        for g in 0..lib.group_count() {
            let (first, order) = lib.group(g);
            if first.saturating_add(3) > n {
                continue;
            }
            let o = [order[0] as usize, order[1] as usize, order[2] as usize];
            let q = |v: [f32; 3]| quaternion(&euler_matrix(o, v));
            let angles = |src: &[f32; MAX_CHANNELS]| [src[first], src[first + 1], src[first + 2]];
            let frame_angles = |fr: usize| {
                [
                    self.target(lib, c, fr, first),
                    self.target(lib, c, fr, first + 1),
                    self.target(lib, c, fr, first + 2),
                ]
            };
            let (q_last, q_t0, q_t1) = (
                q(angles(&self.last)),
                q(frame_angles(f)),
                q(frame_angles(next)),
            );
            let w_t = quat_log(&quat_mul(&q_t1, &quat_conj(&q_t0)));
            let back = quat_mul(&quat_exp(&[-w_t[0], -w_t[1], -w_t[2]]), &q_t0);
            let x0 = quat_log(&quat_mul(&q_last, &quat_conj(&back)));
            let w_s = if moving {
                let q_prev = q(angles(&self.prev));
                quat_log(&quat_mul(&q_last, &quat_conj(&q_prev)))
            } else {
                [0.0; 3]
            };
            // The offset's velocity within the speed cap (its turning speed about each axis,
            // radians per tick; see the module docs).
            let cap = if self.speed_cap > 0.0 {
                self.speed_cap * (core::f32::consts::PI / 180.0)
            } else {
                f32::INFINITY
            };
            for k in 0..3 {
                let v0 = (w_s[k] - w_t[k]).max(-cap).min(cap);
                self.off[first + k] = if x0[k].is_finite() { x0[k] } else { 0.0 };
                self.vel[first + k] = if v0.is_finite() { v0 } else { 0.0 };
                grouped[(first + k) / 8] |= 1 << ((first + k) % 8);
            }
            let (a, b, c) = (self.off[first], self.off[first + 1], self.off[first + 2]);
            largest =
                largest.max(libm::sqrtf(a * a + b * b + c * c) * (180.0 / core::f32::consts::PI));
        }
        if self.speed_cap > 0.0 {
            let cap = self.speed_cap;
            for ch in 0..n {
                if grouped[ch / 8] & (1 << (ch % 8)) == 0 {
                    largest = largest.max(self.off[ch].abs());
                    self.vel[ch] = self.vel[ch].max(-cap).min(cap);
                }
            }
            // The spring x0 (1 + a t) e^(-a t) moves fastest at t = 1/a, by a x0 / e per
            // tick: keep that within the cap.
            // The offset x0 (1 + a t + (a t)^2 / 2) e^(-a t) moves fastest at t = 2 / a, by
            // 2 a x0 / e^2 per tick: keep that within the cap.
            let rest = self.rest.contains(c);
            let (cap, stretch) = if rest {
                (self.speed_cap * REST_BLEND, REST_STRETCH)
            } else {
                (self.speed_cap, MAX_BLEND_STRETCH)
            };
            let need = SETTLE * largest * PEAK / cap;
            let most = self.blend_ticks.saturating_mul(stretch);
            if need.is_finite() && need > self.blend_ticks as f32 {
                // Between blend_ticks (need is above it) and most.
                self.cut_ticks = libm::ceilf(need.min(most as f32)) as u32;
            }
            if !rest {
                self.vel_ticks = self.cut_ticks;
            }
        }
    }

    /// The library value of channel `ch` at frame `f` of segment `c`, or the last output if
    /// it is not finite.
    fn target<L: LibraryFrames + ?Sized>(&self, lib: &L, c: usize, f: usize, ch: usize) -> f32 {
        let v = lib.value(c, f, ch);
        if v.is_finite() {
            v
        } else {
            self.last[ch]
        }
    }

    /// Plays the current frame into `out[..channels]`, then advances one frame (holding the
    /// last frame if the segment ends without a new decision). Returns the frame played.
    pub fn tick<L: LibraryFrames + ?Sized>(
        &mut self,
        lib: &L,
        out: &mut [f32; MAX_CHANNELS],
    ) -> usize {
        self.tick_advancing(lib, out, true)
    }

    /// [`tick`](Self::tick), staying on the same frame when `advance` is false (a hold; a
    /// blend in progress goes on).
    pub fn tick_advancing<L: LibraryFrames + ?Sized>(
        &mut self,
        lib: &L,
        out: &mut [f32; MAX_CHANNELS],
        advance: bool,
    ) -> usize {
        let n = lib.channels().min(MAX_CHANNELS);
        let len = lib.segment_len(self.segment).max(1);
        let f = self.frame.min(len - 1);
        let c = self.segment;
        for (ch, o) in out.iter_mut().enumerate().take(n) {
            *o = self.target(lib, c, f, ch);
        }
        if self.phase > 0.0 && f + 1 < len {
            // The cubic through the four frames around (extrapolated linearly past the
            // segment's ends): smooth data stays smooth at any rate, with the third
            // differences (jerk) of the frames themselves; Catmull-Rom's tangents triple
            // them, and a linear blend's velocity jumps at every frame. A straight run of
            // frames stays straight.
            let t = self.phase;
            let (w0, w2, w3) = (
                -t * (t - 1.0) * (t - 2.0) / 6.0,
                -(t + 1.0) * t * (t - 2.0) / 2.0,
                (t + 1.0) * t * (t - 1.0) / 6.0,
            );
            for (ch, o) in out.iter_mut().enumerate().take(n) {
                let p1 = *o;
                let p2 = self.target(lib, c, f + 1, ch) - p1;
                let p0 = if f > 0 {
                    self.target(lib, c, f - 1, ch) - p1
                } else {
                    -p2
                };
                let p3 = if f + 2 < len {
                    self.target(lib, c, f + 2, ch) - p1
                } else {
                    2.0 * p2
                };
                if p0.abs() <= 180.0 && p2.abs() <= 180.0 && p3.abs() <= 180.0 {
                    *o += w0 * p0 + w2 * p2 + w3 * p3;
                }
            }
        }
        if self.blending && self.since >= self.cut_ticks {
            self.blending = false;
        }
        // The share of the cut's offset (without its velocity's part) in the pose.
        let mut left = 0.0;
        if self.blending {
            let a = SETTLE / self.cut_ticks.max(1) as f32;
            // Tick 1 is the first frame of the new segment (the offset is from tick 0).
            let t = (self.since + 1) as f32;
            let decay = libm::expf(-a * t);
            // A cut into a rest: the velocity decays at the blend's own pace (`b`), the offset
            // slower; otherwise both at `a`, as one response.
            let split = self.vel_ticks != self.cut_ticks;
            let b = SETTLE / self.vel_ticks.max(1) as f32;
            let fast = if split { libm::expf(-b * t) } else { decay };
            let spring = |x0: f32, v0: f32| {
                if split {
                    (x0 + a * x0 * t + 0.5 * a * a * x0 * t * t) * decay
                        + (v0 * t + b * v0 * t * t) * fast
                } else {
                    (x0 + (v0 + a * x0) * t + (a * v0 + 0.5 * a * a * x0) * t * t) * decay
                }
            };
            left = spring(1.0, 0.0);
            for (ch, o) in out.iter_mut().enumerate().take(n) {
                *o += spring(self.off[ch], self.vel[ch]);
            }
            for g in 0..lib.group_count() {
                let (first, order) = lib.group(g);
                if first.saturating_add(3) > n {
                    continue;
                }
                let o = [order[0] as usize, order[1] as usize, order[2] as usize];
                let x = [
                    spring(self.off[first], self.vel[first]),
                    spring(self.off[first + 1], self.vel[first + 1]),
                    spring(self.off[first + 2], self.vel[first + 2]),
                ];
                // The pose the frames give at this tick: between frames, the interpolated one
                // (the scalar spring just added taken off again; a whole frame would step).
                let frame = if self.phase > 0.0 {
                    [
                        out[first] - x[0],
                        out[first + 1] - x[1],
                        out[first + 2] - x[2],
                    ]
                } else {
                    [
                        self.target(lib, c, f, first),
                        self.target(lib, c, f, first + 1),
                        self.target(lib, c, f, first + 2),
                    ]
                };
                let q = quat_mul(&quat_exp(&x), &quaternion(&euler_matrix(o, frame)));
                let angles = nearest_euler(euler_angles(&quat_matrix(&q), o), frame, o);
                out[first..first + 3].copy_from_slice(&angles);
            }
            self.since += 1;
        }
        for (ch, o) in out.iter_mut().enumerate().take(n) {
            if !o.is_finite() {
                *o = self.last[ch];
            }
            self.prev[ch] = self.last[ch];
            self.last[ch] = *o;
        }
        // `last` is the player's own pose (what the next cut blends from); what is shown has
        // the expression stage on top.
        self.expression.apply(lib, out, n, left);
        self.outputs = self.outputs.saturating_add(1);
        if advance {
            // Frame counts stay far below 2^24, so the position is exact in f32.
            let last = (len - 1) as f32;
            let here = self.frame.min(len - 1) as f32 + self.phase;
            let mut to = if self.backward {
                here - self.rate
            } else {
                here + self.rate
            };
            if to <= RATE_EPSILON {
                to = 0.0;
                self.backward = false;
            }
            if to >= last - RATE_EPSILON {
                to = last;
            }
            let whole = libm::floorf(to + RATE_EPSILON);
            self.frame = (whole as usize).min(len - 1);
            self.phase = (to - whole).max(0.0);
        }
        f
    }
}

/// Of the two Euler decompositions of one rotation (`(a, b, c)` and
/// `(a + 180, 180 - b, c + 180)`, wrapped), the one closer to `near`, each angle then moved by
/// whole turns to lie within 180 degrees of `near`'s.
fn nearest_euler(angles: [f32; 3], near: [f32; 3], order: [usize; 3]) -> [f32; 3] {
    // The second solution's middle angle: 180 - b for cyclic orders (b = asin(+-m)), which is
    // the same rotation because R_i(a + 180) R_j(180 - b) R_k(c + 180) = R_i(a) R_j(b) R_k(c).
    let _ = order;
    let alt = [angles[0] + 180.0, 180.0 - angles[1], angles[2] + 180.0];
    let close = |v: [f32; 3]| {
        let mut w = [0.0f32; 3];
        let mut d = 0.0f32;
        for k in 0..3 {
            w[k] = near[k] + wrap_deg(v[k] - near[k]);
            d += (w[k] - near[k]).abs();
        }
        (w, d)
    };
    let (a, da) = close(angles);
    let (b, db) = close(alt);
    if db < da {
        b
    } else {
        a
    }
}

impl Default for Player {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod cut_tests;
#[cfg(test)]
mod tests;
