//! The player's tests: cuts, blends, rates and rotation groups on small hand-built libraries.

use super::*;

/// Two segments on two single-angle channels and one rotation group.
struct Lib {
    groups: bool,
}

impl LibraryFrames for Lib {
    fn channels(&self) -> usize {
        5
    }
    fn fps(&self) -> f32 {
        30.0
    }
    fn segment_count(&self) -> usize {
        2
    }
    fn segment_len(&self, _: usize) -> usize {
        20
    }
    fn value(&self, c: usize, f: usize, ch: usize) -> f32 {
        let f = f as f32;
        match (c, ch) {
            (0, 0) => 10.0 + f,
            (1, 0) => -40.0 + 0.5 * f,
            (0, 1) => 170.0,
            (1, 1) => -170.0,
            // Group channels (Z, Y, X): segment 0 turns about Z, segment 1 rests at a
            // tilt about X.
            (0, 2) => 2.0 * f,
            (1, 4) => 60.0,
            _ => 0.0,
        }
    }
    fn group_count(&self) -> usize {
        self.groups as usize
    }
    fn group(&self, _: usize) -> (usize, [u8; 3]) {
        (2, [2, 1, 0])
    }
}

fn run(p: &mut Player, lib: &Lib, ticks: usize) -> [f32; MAX_CHANNELS] {
    let mut out = [0.0; MAX_CHANNELS];
    for _ in 0..ticks {
        p.tick(lib, &mut out);
    }
    out
}

/// One channel, `segs` segments of `len` frames, values from `f(segment, frame)`.
pub(super) struct FnLib {
    pub(super) segs: usize,
    pub(super) len: usize,
    pub(super) f: fn(usize, usize) -> f32,
}

impl LibraryFrames for FnLib {
    fn channels(&self) -> usize {
        1
    }
    fn fps(&self) -> f32 {
        30.0
    }
    fn segment_count(&self) -> usize {
        self.segs
    }
    fn segment_len(&self, _: usize) -> usize {
        self.len
    }
    fn value(&self, c: usize, f: usize, _: usize) -> f32 {
        (self.f)(c, f)
    }
}

/// Mean absolute third difference (per tick) of channel `ch` over `ticks` ticks at
/// `rate`; with `cut`, over the blend of a cut into segment 1 at tick 3 (9 ticks).
fn mean_jerk(lib: &impl LibraryFrames, rate: f32, ch: usize, cut: bool) -> f32 {
    let mut p = Player::new();
    p.set_blend_ticks(9);
    p.set_rate(rate);
    let mut out = [0.0; MAX_CHANNELS];
    let mut v = [0.0f32; 120];
    for (k, x) in v.iter_mut().enumerate() {
        if cut && k == 3 {
            p.enter(lib, 1);
        }
        p.tick(lib, &mut out);
        *x = out[ch];
    }
    // With a cut, over its blend only.
    let v = if cut { &v[3..16] } else { &v[5..] };
    let d3: f32 = v
        .windows(4)
        .map(|w| (w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]).abs())
        .sum();
    d3 / (v.len() - 3) as f32
}

/// A smooth sway with a little capture noise (0.3 degrees), on one channel and on a
/// rotation group's first angle.
struct Sway;
impl LibraryFrames for Sway {
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
        300
    }
    fn value(&self, c: usize, f: usize, ch: usize) -> f32 {
        let noise = 0.3 * (((f * 2_654_435_761) % 1000) as f32 / 1000.0 - 0.5);
        let phase = if c == 1 { 1.0 } else { 0.0 };
        match ch {
            0 | 1 => 30.0 * libm::sinf(f as f32 * 0.2 + phase) + noise,
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

/// Between frames the pose follows the cubic through the frames around: played slower,
/// a motion is no jerkier than at its own pace (its third differences shrink with the
/// cube of the rate), on a single angle and on a rotation group, also through a cut's
/// blend (where the group's angles once stepped from whole frame to whole frame, and
/// jerk doubled).
#[test]
fn slower_playback_is_no_jerkier() {
    for ch in [0, 1] {
        for cut in [false, true] {
            let full = mean_jerk(&Sway, 1.0, ch, cut);
            let slow = mean_jerk(&Sway, 0.8, ch, cut);
            assert!(slow < full * 0.85, "ch {ch} cut {cut}: {slow} vs {full}");
        }
    }
}

#[test]
fn a_slower_rate_interpolates_and_a_turn_plays_back_to_the_start() {
    let lib = FnLib {
        segs: 1,
        len: 5,
        f: |_, f| 10.0 * f as f32,
    };
    let mut p = Player::new();
    let mut out = [0.0; MAX_CHANNELS];
    let mut play = |p: &mut Player| {
        let mut v = [0.0f32; 9];
        for x in v.iter_mut() {
            p.tick(&lib, &mut out);
            *x = out[0];
        }
        v
    };
    p.set_rate(0.5);
    let poses = play(&mut p);
    // Half a frame per tick, linearly between frames, up to the last frame.
    assert_eq!(poses, [0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0]);
    assert!(p.at_end(&lib) && !p.backward());
    p.turn();
    let back = play(&mut p);
    assert_eq!(back, [40.0, 35.0, 30.0, 25.0, 20.0, 15.0, 10.0, 5.0, 0.0]);
    // At the first frame it turns forward by itself (shown once, as the turn).
    assert!(!p.backward());
    assert_eq!(play(&mut p)[..2], [5.0, 10.0]);
    // Rates are clamped to MIN_RATE..=MAX_RATE; a non-finite one is 1. Entering plays
    // forward.
    p.set_rate(0.1);
    assert_eq!(p.rate(), MIN_RATE);
    p.set_rate(7.0);
    assert_eq!(p.rate(), MAX_RATE);
    p.set_rate(f32::NAN);
    assert_eq!(p.rate(), 1.0);
    p.turn();
    p.enter(&lib, 0);
    assert!(!p.backward());
    // At rate 1 playback is frame by frame, never between frames.
    assert_eq!(play(&mut p)[..5], [0.0, 10.0, 20.0, 30.0, 40.0]);
}

#[test]
fn the_speed_cap_is_the_99th_percentile_of_the_frame_steps() {
    // 198 steps of 1 degree and 2 of 50: the 99th percentile is 1, found to within a
    // bin (50 / 128) above it.
    let lib = FnLib {
        segs: 1,
        len: 201,
        f: |_, f| {
            if f <= 198 {
                f as f32
            } else {
                198.0 + 50.0 * (f - 198) as f32
            }
        },
    };
    let cap = library_speed_cap(&lib);
    assert!((1.0..=1.0 + 50.0 / 128.0).contains(&cap), "{cap}");
    // A library that does not move has no cap.
    let still = FnLib {
        segs: 2,
        len: 10,
        f: |_, _| 3.0,
    };
    assert_eq!(library_speed_cap(&still), 0.0);
}

#[test]
fn a_large_offset_blends_no_faster_than_the_cap() {
    // A cut from 0 to 100 degrees: blended over 9 ticks the offset moves up to
    // 2 a x0 / e^2 = 2 (8.406 / 9) 100 / e^2 = 25.3 degrees per tick; capped at 10, the
    // blend takes ceil(8.406 * 100 * 2 / (e^2 * 10)) = 23 ticks and no step exceeds 10.
    let lib = FnLib {
        segs: 2,
        len: 40,
        f: |c, _| 100.0 * c as f32,
    };
    let largest_step = |cap: f32| {
        let mut p = Player::new();
        p.set_blend_ticks(9);
        p.set_speed_cap(cap);
        let mut out = [0.0; MAX_CHANNELS];
        for _ in 0..3 {
            p.tick(&lib, &mut out);
        }
        p.enter(&lib, 1);
        let (mut prev, mut most, mut ticks) = (out[0], 0.0f32, 0);
        while out[0] != 100.0 && ticks < 100 {
            p.tick(&lib, &mut out);
            most = most.max((out[0] - prev).abs());
            prev = out[0];
            ticks += 1;
        }
        (most, ticks)
    };
    let (free, free_ticks) = largest_step(0.0);
    // (The frames come back exactly on the tick after the blend.)
    assert!(free > 24.0 && free_ticks == 9 + 1, "{free} {free_ticks}");
    let (capped, capped_ticks) = largest_step(10.0);
    assert!(capped <= 10.0, "{capped}");
    assert_eq!(capped_ticks, 23 + 1);
    // A cap the blend cannot meet within MAX_BLEND_STRETCH times the blend stops there.
    let (_, stretched) = largest_step(1.0);
    assert_eq!(stretched, 9 * MAX_BLEND_STRETCH + 1);
}

#[test]
fn a_hard_cut_plays_the_new_frames_at_once() {
    let lib = Lib { groups: false };
    let mut p = Player::new();
    run(&mut p, &lib, 5);
    p.enter(&lib, 1);
    let out = run(&mut p, &lib, 1);
    assert_eq!(out[0], -40.0);
}

#[test]
fn an_inertialized_cut_moves_like_the_spring_and_ends_exactly_on_the_frames() {
    let lib = Lib { groups: false };
    let mut p = Player::new();
    p.set_blend_ticks(9);
    run(&mut p, &lib, 5); // channel 0 at 14, moving +1 per tick
    p.enter(&lib, 1);
    // Offset against segment 1's first frame extrapolated one tick back: 14 - (-40.5).
    let (x0, v0, a) = (54.5f32, 0.5f32, SETTLE / 9.0);
    let mut out = [0.0; MAX_CHANNELS];
    let mut prev = 14.0f32;
    for k in 1..=12u32 {
        p.tick(&lib, &mut out);
        let t = k as f32;
        let spring = if k <= 9 {
            (x0 + (v0 + a * x0) * t + (a * v0 + 0.5 * a * a * x0) * t * t) * libm::expf(-a * t)
        } else {
            0.0
        };
        let frame = -40.0 + 0.5 * (k - 1) as f32;
        assert!(
            (out[0] - (frame + spring)).abs() < 1e-3,
            "tick {k}: {}",
            out[0]
        );
        // No step is larger than the offset's largest speed (2 x0 a / e^2) plus the
        // frames' and the velocity's share.
        assert!((out[0] - prev).abs() <= x0 * a * PEAK + 1.0);
        prev = out[0];
    }
    // After the blend, the library's frames exactly (frame 11 of segment 1).
    assert_eq!(out[0], -40.0 + 0.5 * 11.0);
    // A servo angle blends linearly: from 170 to -170 through 0, and arrives exactly.
    assert_eq!(out[1], -170.0);
}

#[test]
fn a_rotation_group_blends_as_a_rotation() {
    let lib = Lib { groups: true };
    let mut p = Player::new();
    p.set_blend_ticks(9);
    run(&mut p, &lib, 10); // Z = 18 deg, turning 2 deg per tick
    p.enter(&lib, 1);
    let mut out = run(&mut p, &lib, 1);
    // First frame after the cut: the old rotation carried on (Z ~ 20, X ~ 0).
    let rot = |o: &[f32; MAX_CHANNELS]| euler_matrix([2, 1, 0], [o[2], o[3], o[4]]);
    let angle = |a: &[f32; 4], b: &[f32; 4]| {
        let d: f32 = (0..4).map(|k| a[k] * b[k]).sum();
        2.0 * libm::acosf(d.abs().min(1.0)) * 57.2958
    };
    // The first frame after the cut has moved from the last pose (Z = 18) by the offset's
    // first step only: (1 - (1 + a + a^2 / 2) e^-a) of the 61-degree offset, about 4
    // degrees.
    let q0 = quaternion(&rot(&out));
    let last = quaternion(&euler_matrix([2usize, 1, 0], [18.0f32, 0.0, 0.0]));
    let a = SETTLE / 9.0;
    let first = 1.0 - (1.0 + a + 0.5 * a * a) * libm::expf(-a);
    assert!(angle(&q0, &last) < first * 61.0 + 3.0, "{:?}", &out[2..5]);
    // The rotation turns toward the target (60 degrees away) in steps no larger than the
    // offset allows (about 2 * 60 * a / e^2 per tick), never a snap.
    let mut prev = q0;
    for _ in 0..12 {
        out = run(&mut p, &lib, 1);
        let q = quaternion(&rot(&out));
        let step = angle(&q, &prev);
        assert!(step < 20.0, "step {step}");
        prev = q;
    }
    // Blend over: exactly the frame (X = 60).
    assert_eq!([out[2], out[3], out[4]], [0.0, 0.0, 60.0]);
}

#[test]
fn nearest_euler_prefers_the_solution_close_to_the_frame() {
    // Z=170, Y=100 (past 90), X=10 decomposes canonically with |Y| <= 90.
    let m = euler_matrix([2usize, 1, 0], [170.0f32, 100.0, 10.0]);
    let canon = euler_angles(&m, [2, 1, 0]);
    assert!(canon[1] <= 90.0);
    let near = nearest_euler(canon, [170.0, 100.0, 10.0], [2, 1, 0]);
    for (a, b) in near.iter().zip([170.0, 100.0, 10.0]) {
        assert!((a - b).abs() < 1e-2, "{near:?}");
    }
}

/// One 30 s segment at 30 fps: channel 0 a single angle `20 + 15 sin(w f)`, channels 1-3 a
/// rotation group (Z, Y, X) turning `30 + 15 sin(w f)` about its first axis only, `w` one
/// cycle per second.
struct Sine;

const SINE_W: f64 = 2.0 * core::f64::consts::PI / 30.0;

impl LibraryFrames for Sine {
    fn channels(&self) -> usize {
        4
    }
    fn fps(&self) -> f32 {
        30.0
    }
    fn segment_count(&self) -> usize {
        1
    }
    fn segment_len(&self, _: usize) -> usize {
        900
    }
    fn value(&self, _: usize, f: usize, ch: usize) -> f32 {
        let s = 15.0 * (SINE_W * f as f64).sin() as f32;
        match ch {
            0 => 20.0 + s,
            1 => 30.0 + s,
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

/// The mean and the amplitude of channel `ch` at the sine's frequency over ticks
/// `from..from + 300` (ten whole cycles: the projection is exact for a pure sine).
fn mean_and_amplitude(p: &mut Player, from: usize, ch: usize) -> (f64, f64) {
    let mut out = [0.0; MAX_CHANNELS];
    let (mut m, mut a, mut b) = (0.0f64, 0.0f64, 0.0f64);
    for k in 0..from + 300 {
        p.tick(&Sine, &mut out);
        if k >= from {
            let v = out[ch] as f64;
            m += v / 300.0;
            a += v * (SINE_W * k as f64).sin() * 2.0 / 300.0;
            b += v * (SINE_W * k as f64).cos() * 2.0 / 300.0;
        }
    }
    (m, (a * a + b * b).sqrt())
}

/// Known answer: with the slow part `s(n) = s(n-1) + k (x(n) - s(n-1))` and the shown
/// `x(n) + (g - 1) (x(n) - s(n-1))`, a sine of amplitude `A` is shown with amplitude
/// `A |1 + (g - 1) (1 - k e^-iw / (1 - (1 - k) e^-iw))|` around the same mean, for a single
/// angle and for a rotation about one axis alike; a gain of 1 shows the frames exactly.
#[test]
fn the_expression_gain_scales_the_quick_part_around_the_posture() {
    let k = 1.0 - (-1.0 / (expression::SLOW_S as f64 * 30.0)).exp();
    let response = |g: f64| {
        // e^-iw = (c, -s); the low-pass's delayed response k e^-iw / (1 - (1 - k) e^-iw).
        let (c, s) = (SINE_W.cos(), SINE_W.sin());
        let (dr, di) = (1.0 - (1.0 - k) * c, (1.0 - k) * s);
        let (nr, ni) = (k * c, -k * s);
        let den = dr * dr + di * di;
        let (lr, li) = ((nr * dr + ni * di) / den, (ni * dr - nr * di) / den);
        let (hr, hi) = (1.0 + (g - 1.0) * (1.0 - lr), -(g - 1.0) * li);
        (hr * hr + hi * hi).sqrt()
    };
    for g in [0.5f32, 1.3] {
        let mut p = Player::new();
        p.set_gain(g);
        for (ch, mean) in [(0, 20.0), (1, 30.0)] {
            let mut q = p;
            let (m, amp) = mean_and_amplitude(&mut q, 300, ch);
            let want = 15.0 * response(g as f64);
            assert!(
                (amp - want).abs() < 0.02,
                "gain {g} ch {ch}: {amp} vs {want}"
            );
            assert!((m - mean).abs() < 0.02, "gain {g} ch {ch}: mean {m}");
        }
        // The other two angles of the group stay at 0: a rotation about one axis, scaled.
        let mut out = [0.0; MAX_CHANNELS];
        let mut q = p;
        for _ in 0..400 {
            q.tick(&Sine, &mut out);
            assert!(
                out[2].abs() < 1e-3 && out[3].abs() < 1e-3,
                "{:?}",
                &out[..4]
            );
        }
    }
    assert!(response(1.3) > 1.15 && response(0.5) < 0.7);
    // A gain of 1: the frames themselves.
    let mut p = Player::new();
    p.set_gain(1.0);
    let mut out = [0.0; MAX_CHANNELS];
    for f in 0..100 {
        p.tick(&Sine, &mut out);
        for (ch, v) in out.iter().enumerate().take(4) {
            assert_eq!(*v, Sine.value(0, f, ch));
        }
    }
}

/// One 4 s segment at 30 fps, constant but for one frame: at frame 60 channel 0 (a single
/// angle) and the rotation group's outer angles (channels 1 and 3, middle angle 20) jump by
/// the given degrees, the group's the other way round in channel 3.
struct Swing(f32);

impl LibraryFrames for Swing {
    fn channels(&self) -> usize {
        4
    }
    fn fps(&self) -> f32 {
        30.0
    }
    fn segment_count(&self) -> usize {
        1
    }
    fn segment_len(&self, _: usize) -> usize {
        120
    }
    fn value(&self, _: usize, f: usize, ch: usize) -> f32 {
        let a = if f < 60 { -0.5 } else { 0.5 } * self.0;
        match ch {
            0 | 1 => a,
            2 => 20.0,
            _ => -a,
        }
    }
    fn group_count(&self) -> usize {
        1
    }
    fn group(&self, _: usize) -> (usize, [u8; 3]) {
        (1, [2, 1, 0])
    }
}

/// A rotation group's quick part is scaled less the further it is from its slow part
/// ([`expression::QUICK_FADE`]): a jump of 75 degrees gets half the gain's excess. A swing of
/// 160 degrees, further than any gesture moves in half a second (two Euler forms of about one
/// rotation), is not scaled, and the slow part starts again from the frames, so no average
/// across the swing is shown as motion afterwards: at a gain of 1.3 the group's angles are the
/// frames' at every tick. A single angle's jump is motion and is scaled in full (0.3 x 160
/// degrees past the frames at the jump).
#[test]
fn a_rotation_group_is_scaled_less_the_further_it_swings() {
    let (lo, hi) = expression::QUICK_FADE;
    for jump in [75.0f32, 160.0] {
        let lib = Swing(jump);
        let mut p = Player::new();
        p.set_gain(1.3);
        let mut out = [0.0; MAX_CHANNELS];
        for f in 0..120 {
            p.tick(&lib, &mut out);
            if f == 60 {
                assert!((out[0] - jump * (0.5 + 0.3)).abs() < 1.0, "{:?}", &out[..4]);
                let w = ((hi - jump) / (hi - lo)).clamp(0.0, 1.0);
                let want = jump * (0.5 + 0.3 * w);
                assert!((out[1] - want).abs() < 1.0, "jump {jump}: {:?}", &out[..4]);
                assert!((out[3] + want).abs() < 1.0, "jump {jump}: {:?}", &out[..4]);
            }
            if jump > hi {
                for ch in 1..4 {
                    let want = lib.value(0, f, ch);
                    assert!(
                        (out[ch] - want).abs() < 1e-3,
                        "tick {f} ch {ch}: {:?}",
                        &out[..4]
                    );
                }
            }
        }
    }
}

/// A change of gain changes the quick part's speed at once and its size over
/// [`expression::RELAX_S`]: aimed from 1 to 2 at a crest of the sine (where the frames hardly
/// move), over its first three ticks the shown pose steps less than half as far as
/// `slow + gain x quick` shown directly would (which pushes the hands out by the change of
/// gain times the quick part), and three seconds later it is that form again (a float
/// reference of the slow part).
#[test]
fn a_change_of_gain_does_not_push_the_pose() {
    let k = 1.0 - (-1.0 / (expression::SLOW_S as f64 * 30.0)).exp();
    let mut p = Player::new();
    let mut out = [0.0; MAX_CHANNELS];
    let (mut slow, mut last, mut last_direct) = ([0.0f64; 2], [0.0f64; 2], [0.0f64; 2]);
    let (mut step, mut step_direct) = (0.0f64, 0.0f64);
    // Tick 307 is 7 frames into a cycle: the crest of the sine.
    for n in 0..400usize {
        if n == 307 {
            p.set_gain(2.0);
        }
        p.tick(&Sine, &mut out);
        for (i, ch) in [0usize, 1].into_iter().enumerate() {
            let x = Sine.value(0, n, ch) as f64;
            let d = if n == 0 { 0.0 } else { x - slow[i] };
            slow[i] = if n == 0 { x } else { slow[i] + k * d };
            let direct = x + (p.gain() as f64 - 1.0) * d;
            let shown = out[ch] as f64;
            if (307..310).contains(&n) {
                step = step.max((shown - last[i]).abs());
                step_direct = step_direct.max((direct - last_direct[i]).abs());
            }
            if !(307..397).contains(&n) {
                assert!(
                    (shown - direct).abs() < 1e-3,
                    "tick {n} ch {ch}: {shown} vs {direct}"
                );
            }
            (last[i], last_direct[i]) = (shown, direct);
        }
    }
    assert!(
        step < 0.5 * step_direct && step_direct > 3.0,
        "largest step {step} vs {step_direct}"
    );
}

/// The gain eases to its aim through three first-order stages: it first moves by `k^3` of
/// the change (`k = 1 - e^(-1 / (GAIN_S fps))`), then monotonically, and is there (within
/// the snap of 0.001) in two thirds of a second; a non-finite aim is ignored and aims are
/// clamped.
#[test]
fn the_expression_gain_eases_to_its_aim() {
    let k = 1.0 - (-1.0f32 / (expression::GAIN_S * 30.0)).exp();
    let mut p = Player::new();
    let mut out = [0.0; MAX_CHANNELS];
    p.tick(&Sine, &mut out);
    p.set_gain(0.5);
    p.set_gain(f32::NAN);
    assert_eq!(p.gain_aim(), 0.5);
    p.tick(&Sine, &mut out);
    assert!(
        (p.gain() - (1.0 - 0.5 * k * k * k)).abs() < 1e-5,
        "{}",
        p.gain()
    );
    let mut last = p.gain();
    for _ in 0..19 {
        p.tick(&Sine, &mut out);
        assert!(p.gain() < last || p.gain() == 0.5);
        last = p.gain();
    }
    assert_eq!(p.gain(), 0.5);
    p.set_gain(7.0);
    assert_eq!(p.gain_aim(), expression::GAIN_RANGE.1);
}

/// Two still poses: a single angle and a rotation group about X (`Z, Y, X` order).
struct Still;

impl LibraryFrames for Still {
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
        60
    }
    fn value(&self, c: usize, _: usize, ch: usize) -> f32 {
        match (c, ch) {
            (0, 0) => 10.0,
            (1, 0) => -30.0,
            (1, 3) => 40.0,
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

/// A cut's blend is the player's, whatever the gain: between two still poses there is no
/// quick motion to scale, so a gain of 0.5 or 2 shows the very blend a gain of 1 shows (a
/// stage that took the blend's offset for quick motion would overshoot the new pose by the
/// gain's excess, or stop short of it).
#[test]
fn a_cuts_blend_is_not_scaled_by_the_gain() {
    let blend = |gain: f32| {
        let mut p = Player::new();
        p.set_blend_ticks(10);
        p.set_gain(gain);
        let mut out = [0.0; MAX_CHANNELS];
        let mut shown = [[0.0f32; 4]; 30];
        for _ in 0..30 {
            p.tick(&Still, &mut out);
        }
        p.enter(&Still, 1);
        for pose in shown.iter_mut() {
            p.tick(&Still, &mut out);
            pose.copy_from_slice(&out[..4]);
        }
        shown
    };
    let plain = blend(1.0);
    // The blend moves (it is not a hard cut) and arrives.
    assert!(plain[3][0] > -25.0 && plain[3][3] < 35.0, "{:?}", plain[3]);
    assert!((plain[29][0] + 30.0).abs() < 1e-3 && (plain[29][3] - 40.0).abs() < 1e-3);
    for gain in [0.5, 2.0] {
        for (t, (a, b)) in blend(gain).iter().zip(&plain).enumerate() {
            for ch in 0..4 {
                assert!(
                    (a[ch] - b[ch]).abs() < 1e-3,
                    "gain {gain}, tick {t}: {a:?} vs {b:?}"
                );
            }
        }
    }
}
