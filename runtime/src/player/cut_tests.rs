//! The player's tests of what a cut carries on: its velocity within the speed cap, and a
//! rest entered at a share of it.

use super::tests::FnLib;
use super::*;
use crate::testing::Energies;

/// A single angle and a rotation group (`Z, Y, X`), both turning 20 degrees per tick in
/// segment 0; segment 1 holds still where segment 0's fifth frame is.
struct Fast;

impl LibraryFrames for Fast {
    fn channels(&self) -> usize {
        4
    }
    fn fps(&self) -> f32 {
        30.0
    }
    fn segment_count(&self) -> usize {
        2
    }
    fn segment_len(&self, _: usize) -> usize {
        40
    }
    fn value(&self, c: usize, f: usize, ch: usize) -> f32 {
        match (c, ch) {
            (0, 0 | 1) => 20.0 * f as f32,
            (1, 0 | 1) => 80.0,
            _ => 0.0,
        }
    }
    fn group_count(&self) -> usize {
        1
    }
    fn group(&self, _: usize) -> (usize, [u8; 3]) {
        (1, [2, 1, 0])
    }
}

/// Known answer: a cut with no offset from a motion of `v0` per tick moves the pose on by
/// `v0 (t + a t^2) e^(-a t)`, at most `0.84 v0 / a` past the new frames (at `a t = 1.618`).
/// Out of 20 degrees per tick, 18 degrees past with no cap; with a cap of 5 the carried
/// velocity is 5 and the pose goes at most 4.5 degrees past, a single angle and a rotation
/// group alike; the first step after the cut is `0.76 v0` (`(1 + a) e^-a`).
#[test]
fn a_cut_carries_on_no_more_velocity_than_the_cap() {
    let a = SETTLE / 9.0;
    let furthest = |v0: f32| 0.8399 * v0 / a;
    let run_past = |cap: f32| {
        let mut p = Player::new();
        p.set_blend_ticks(9);
        p.set_speed_cap(cap);
        let mut out = [0.0; MAX_CHANNELS];
        for _ in 0..5 {
            p.tick(&Fast, &mut out); // frames 0..=4: at 80, moving 20 per tick
        }
        assert_eq!(out[0], 80.0);
        p.enter(&Fast, 1);
        let (mut most, mut first) = ([0.0f32; 2], None);
        for _ in 0..30 {
            p.tick(&Fast, &mut out);
            first.get_or_insert(out[0] - 80.0);
            most[0] = most[0].max(out[0] - 80.0);
            most[1] = most[1].max(wrap_deg(out[1] - 80.0));
        }
        assert_eq!([out[0], out[1]], [80.0, 80.0]);
        (most, first.unwrap_or(0.0))
    };
    let (free, first) = run_past(0.0);
    for m in free {
        assert!((m - furthest(20.0)).abs() < 0.3, "{free:?}");
    }
    assert!((first - 20.0 * (1.0 + a) * libm::expf(-a)).abs() < 1e-3);
    // A cap above the motion's speed changes nothing.
    assert_eq!(run_past(25.0), (free, first));
    let (capped, first) = run_past(5.0);
    for m in capped {
        assert!((m - furthest(5.0)).abs() < 0.1, "{capped:?}");
    }
    assert!((first - 5.0 * (1.0 + a) * libm::expf(-a)).abs() < 1e-3);
}

/// Two segments' energies (the rest set's source): segment 1 the calmer.
/// Known answer: a cut into a rest segment blends at [`REST_BLEND`] of the speed cap. From 0
/// to 100 degrees with a cap of 20, a gesture's blend takes `ceil(8.406 * 100 * 2 / (e^2 *
/// 20)) = 12` ticks; into a rest, at half the cap, 23, no step over 10; back out of the rest
/// into the gesture, 12 again.
#[test]
fn a_cut_into_a_rest_blends_at_a_share_of_the_cap() {
    let lib = FnLib {
        segs: 2,
        len: 60,
        f: |c, _| 100.0 * c as f32,
    };
    let blend = |rest: RestSet, into: usize| {
        let mut p = Player::new();
        p.set_blend_ticks(9);
        p.set_speed_cap(20.0);
        p.set_rest_segments(rest);
        let mut out = [0.0; MAX_CHANNELS];
        p.enter(&lib, 1 - into);
        for _ in 0..3 {
            p.tick(&lib, &mut out);
        }
        p.enter(&lib, into);
        let target = 100.0 * into as f32;
        let (mut prev, mut most, mut ticks) = (out[0], 0.0f32, 0);
        while out[0] != target && ticks < 100 {
            p.tick(&lib, &mut out);
            most = most.max((out[0] - prev).abs());
            prev = out[0];
            ticks += 1;
        }
        (most, ticks)
    };
    let rest = RestSet::of(&Energies(&[1.0, -1.0]), 2);
    assert_eq!(rest.segments(), &[1]);
    let (_, gesture) = blend(RestSet::EMPTY, 1);
    assert_eq!(gesture, 12 + 1);
    let (most, resting) = blend(rest, 1);
    assert_eq!(resting, 23 + 1);
    assert!(most <= 10.0, "{most}");
    assert_eq!(blend(rest, 0).1, 12 + 1);
}
