//! The library's frames as the player reads them ([`LibraryFrames`]), and the blend's speed
//! cap measured on them ([`library_speed_cap`]).

use crate::rig::MAX_CHANNELS;

/// Bins of the histogram behind [`library_speed_cap`].
const SPEED_BINS: usize = 128;

/// The quantile of the library's per-frame channel changes that caps a blend's speed.
const SPEED_QUANTILE: f32 = 0.99;

/// The speed cap of a blend (degrees per tick): the 99th percentile of the library's own
/// per-frame channel changes (every channel, every pair of consecutive frames inside a
/// segment; non-finite values skipped), to within 1/128 of the largest change; 0 for a
/// library that does not move. Two passes over the frames, fixed memory.
pub fn library_speed_cap<L: LibraryFrames + ?Sized>(lib: &L) -> f32 {
    let n = lib.channels().min(MAX_CHANNELS);
    let each = |visit: &mut dyn FnMut(f32)| {
        for c in 0..lib.segment_count() {
            for f in 1..lib.segment_len(c) {
                for ch in 0..n {
                    let d = lib.value(c, f, ch) - lib.value(c, f - 1, ch);
                    if d.is_finite() {
                        visit(if d < 0.0 { -d } else { d });
                    }
                }
            }
        }
    };
    let mut top = 0.0f32;
    let mut count = 0u32;
    each(&mut |d| {
        top = top.max(d);
        count = count.saturating_add(1);
    });
    if top <= 0.0 || !top.is_finite() || count == 0 {
        return 0.0;
    }
    let mut bins = [0u32; SPEED_BINS];
    each(&mut |d| {
        let k = ((d / top) * SPEED_BINS as f32) as usize;
        bins[k.min(SPEED_BINS - 1)] += 1;
    });
    let want = (SPEED_QUANTILE * count as f32) as u32;
    let mut seen = 0u32;
    for (k, &b) in bins.iter().enumerate() {
        seen = seen.saturating_add(b);
        if seen >= want {
            return top * (k + 1) as f32 / SPEED_BINS as f32;
        }
    }
    top
}

/// Puts every channel of `pose` within its calibrated limits (a non-finite value becomes the
/// neutral angle), as the controller and a show's player do with every pose before it leaves
/// them, whatever the frames and the blends made of it (a board without the rig's own clamp
/// must not drive a servo into its stop); returns the channels of the pose.
pub fn within_limits<L: LibraryFrames + ?Sized>(lib: &L, pose: &mut [f32; MAX_CHANNELS]) -> usize {
    let channels = lib.channels().min(MAX_CHANNELS);
    for (ch, v) in pose[..channels].iter_mut().enumerate() {
        let (lo, hi, neutral) = lib.limits(ch);
        *v = if v.is_finite() {
            v.max(lo).min(hi)
        } else {
            neutral
        };
    }
    channels
}

/// The library's frames as the player needs them. Built only from validated data: indices
/// passed in are always in range.
pub trait LibraryFrames {
    /// Channels per pose.
    fn channels(&self) -> usize;
    /// Frames per second of the library.
    fn fps(&self) -> f32;
    /// Number of segments.
    fn segment_count(&self) -> usize;
    /// Frames in segment `c` (at least 1).
    fn segment_len(&self, c: usize) -> usize;
    /// Value of channel `ch` at frame `f` of segment `c` (degrees).
    fn value(&self, c: usize, f: usize, ch: usize) -> f32;
    /// Whether segment `c + 1` continues segment `c` (its recorded successor, played on into
    /// while waiting).
    fn continues(&self, _c: usize) -> bool {
        false
    }
    /// Whether frame `f` of segment `c` is a motion beat (the hands' speed at a minimum).
    fn is_beat(&self, _c: usize, _f: usize) -> bool {
        false
    }
    /// Whether frame `f` of segment `c` is a stroke (a prominent peak of the hands' speed).
    fn is_peak(&self, _c: usize, _f: usize) -> bool {
        false
    }
    /// Whether frame `f` of segment `c` is calm (the hands slow).
    fn is_calm(&self, _c: usize, _f: usize) -> bool {
        false
    }
    /// `(is_calm(c, f), is_beat(c, f))` at once (an implementation may read both with one
    /// lookup).
    fn calm_beat(&self, c: usize, f: usize) -> (bool, bool) {
        (self.is_calm(c, f), self.is_beat(c, f))
    }
    /// Rotation groups (three channels holding one rotation as Euler angles).
    fn group_count(&self) -> usize {
        0
    }
    /// Group `g`: first channel and Euler order (axis indices).
    fn group(&self, _g: usize) -> (usize, [u8; 3]) {
        (usize::MAX, [0, 1, 2])
    }
    /// Channel `ch`'s limits and neutral angle (degrees): what a pose may hand the rig.
    fn limits(&self, _ch: usize) -> (f32, f32, f32) {
        (f32::MIN, f32::MAX, 0.0)
    }
}
