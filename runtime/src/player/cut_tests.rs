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

/// Known answer: a cut into a rest segment drifts into it at [`REST_BLEND`] of the speed
/// cap, stretched up to [`REST_STRETCH`] times the blend time. From 0 to 100 degrees with a
/// cap of 20, a gesture's blend takes `ceil(8.406 * 100 * 2 / (e^2 * 20)) = 12` ticks; into a
/// rest (segment 1, the calmer of the two) it would need 228 at a twentieth of the cap and
/// takes the most, `25 * 9 = 225`, no step over 1.02; back out of the rest into the gesture,
/// 12 again.
#[test]
fn a_cut_into_a_rest_drifts_in_at_a_share_of_the_cap() {
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
        while out[0] != target && ticks < 400 {
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
    assert_eq!(resting, 225 + 1);
    // The fastest step of the drift: 2 a x0 / e^2 with a = 8.406 / 225.
    let fastest = 2.0 * (SETTLE / 225.0) * 100.0 * PEAK / 2.0;
    assert!(
        (most - fastest).abs() < 0.01 && most <= 1.02,
        "{most} {fastest}"
    );
    assert_eq!(blend(rest, 0).1, 12 + 1);
}

/// Float reference: into a rest, the offset drifts out over the stretched blend while the
/// velocity the cut carries dies out over the blend's own time, each a critically damped
/// third-order response: `x(t) = x0 (1 + A t + A^2 t^2 / 2) e^(-A t) + v0 (t + b t^2)
/// e^(-b t)`, `A` from the stretched time, `b = 8.406 / blend_ticks`. Segment 0 moves 2
/// degrees per tick; the rest (segment 1) holds 30 degrees below where segment 0 stands, so
/// the cut starts 30 degrees off, moving away from the rest at 2 per tick. Within a tenth of
/// a degree of the reference over the whole drift, the pose goes on past the cut by at most
/// `0.84 v0 / b` (1.8 degrees: carried over the long drift, the velocity would take it some
/// 50 degrees on).
#[test]
fn a_rest_drifts_in_slowly_and_the_velocity_dies_out_at_the_blend_pace() {
    let lib = FnLib {
        segs: 2,
        len: 400,
        f: |c, f| if c == 0 { 2.0 * f as f32 } else { -20.0 },
    };
    let mut p = Player::new();
    p.set_blend_ticks(9);
    p.set_speed_cap(20.0);
    p.set_rest_segments(RestSet::of(&Energies(&[1.0, -1.0]), 2));
    let mut out = [0.0; MAX_CHANNELS];
    for _ in 0..6 {
        p.tick(&lib, &mut out); // frames 0..=5: at 10, moving 2 per tick
    }
    assert_eq!(out[0], 10.0);
    p.enter(&lib, 1);
    let (x0, v0) = (30.0f64, 2.0f64);
    // The stretched time the cap asks for: ceil(8.406 * 30 * PEAK / (20 * REST_BLEND)).
    let need = (SETTLE * 30.0 * PEAK / (20.0 * REST_BLEND)).ceil() as f64;
    let cut_ticks = need.min(9.0 * REST_STRETCH as f64);
    let (a, b) = (SETTLE as f64 / cut_ticks, SETTLE as f64 / 9.0);
    let mut most = 0.0f64;
    for k in 1..=cut_ticks as usize {
        p.tick(&lib, &mut out);
        let t = k as f64;
        let want = -20.0
            + x0 * (1.0 + a * t + 0.5 * a * a * t * t) * (-a * t).exp()
            + v0 * (t + b * t * t) * (-b * t).exp();
        assert!(
            (out[0] as f64 - want).abs() < 0.1,
            "tick {k}: {} {want}",
            out[0]
        );
        most = most.max(out[0] as f64 - 10.0);
    }
    assert!(most < 0.8399 * v0 / b + 0.05, "{most}");
}
