//! Where a rest begins and what it plays: a rest holds the posture a gesture paused in
//! (docs/method.md, "A rest holds the posture"). A pure function of the library and the pose
//! shown, so the controller and the whole-file plan (`gesture-trainer`'s bake) begin their
//! rests alike.

use crate::player::{LibraryFrames, Player};
use crate::rotation::wrap_deg;

/// The most frames of a rest segment [`rest_entry`] compares with the pose shown (a longer
/// segment is sampled evenly).
pub const REST_PROBES: usize = 64;

/// The fewest frames a rest plays to and fro in (half a second of a 30 fps library).
pub const REST_SPAN: usize = 15;

/// Where a rest begins and what it plays ([`rest_entry`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RestEntry {
    /// The frame entered.
    pub frame: usize,
    /// The first and last frames it plays to and fro between.
    pub span: (usize, usize),
}

/// Where a rest in segment `c` of `lib` begins, `pose` shown before it: its calm frame
/// nearest `pose` (the least sum of squared channel differences, angles wrapped; the first of
/// equals; among [`REST_PROBES`] frames spread evenly over the segment), or its nearest frame
/// when it has no calm one; and the span it then plays to and fro in: the calm frames around
/// it, widened to at least [`REST_SPAN`] frames (the whole segment without calm frames).
///
/// A rest holds the posture a gesture paused in (docs/method.md, "A rest holds the
/// posture"): the rest's own frames nearest it, and only its calm ones, the capture's
/// breathing and drift rather than the segment's way into or out of them.
pub fn rest_entry<L: LibraryFrames + ?Sized>(lib: &L, c: usize, pose: &[f32]) -> RestEntry {
    let len = lib.segment_len(c).max(1);
    let calm = (0..len).any(|f| lib.is_calm(c, f));
    let n = lib.channels().min(pose.len());
    let stride = len.div_ceil(REST_PROBES).max(1);
    let mut best = (0, f32::INFINITY);
    for f in (0..len).step_by(stride) {
        if calm && !lib.is_calm(c, f) {
            continue;
        }
        let mut d = 0.0f32;
        for (ch, &p) in pose[..n].iter().enumerate() {
            let x = p - lib.value(c, f, ch);
            let x = if x.abs() > 180.0 { wrap_deg(x) } else { x };
            d += x * x;
        }
        if d < best.1 {
            best = (f, d);
        }
    }
    let frame = best.0;
    if !calm {
        return RestEntry {
            frame,
            span: (0, len - 1),
        };
    }
    let (mut lo, mut hi) = (frame, frame);
    while lo > 0 && lib.is_calm(c, lo - 1) {
        lo -= 1;
    }
    while hi + 1 < len && lib.is_calm(c, hi + 1) {
        hi += 1;
    }
    while hi - lo + 1 < REST_SPAN.min(len) {
        lo = lo.saturating_sub(1);
        if hi + 1 < len {
            hi += 1;
        }
    }
    RestEntry {
        frame,
        span: (lo, hi),
    }
}

/// Where `player` stands against a rest's `span` (from [`rest_entry`]): at its end while
/// playing forward (or at the segment's last frame), and at or before its start. A rest turns
/// at either (the player itself turns at frame 0); the controller and the whole-file plan
/// both ask here, so they turn on the same ticks.
pub fn span_ends<L: LibraryFrames + ?Sized>(
    lib: &L,
    player: &Player,
    span: (usize, usize),
) -> (bool, bool) {
    let at_end = !player.backward() && (player.at_end(lib) || player.frame() >= span.1);
    (at_end, player.position() <= span.0 as f32)
}
