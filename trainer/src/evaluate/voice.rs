//! Does the body follow the voice: four figures of how the hands behave in the speech's
//! pauses and when it comes back, part of [`crate::evaluate::metrics::MotionMetrics`].
//!
//! **Voice activity** comes from the raw audio samples, not the front-end's steps
//! ([`activity`]): the loudness of each 10 ms frame (frame `j` covers `[j * 0.01, (j + 1) *
//! 0.01)` s) is the RMS of its samples in dB (`20 log10 rms`, full scale 1; an all-zero
//! frame counts as -200 dB), floored at 50 dB under the track's 99th percentile; smoothed by
//! a centred moving average over 0.2 s (20 frames: `j - 10 .. j + 10`, fewer at the ends);
//! a frame is *active* where the smoothed loudness is within 35 dB of the (unsmoothed,
//! floored) 99th percentile. A **pause** is an inactive run of at least 1.5 s ([`pauses`]).
//!
//! **Hand speed** ([`relative_hand_speed`]): per frame, the mean over the hands of the speed
//! of the hand relative to the *anchor*, the effectors' nearest common ancestor joint
//! ([`anchor_joint`](super::trace::anchor_joint): the chest on the shared skeletons), so that
//! a body swaying or walking does not count as gesturing; smoothed over about 1/6 s as
//! [`smoothed_hand_speed`] does. Without an anchor (fewer than two effectors, or a trace built
//! without one) the hands' world positions. Speed sample `i` (frame `i` to `i + 1`) is at time
//! `(i + 1) / fps`, and falls in the audio frame holding that time.
//!
//! The figures ([`figures`]; all `None` when the speech has no pause of 1.5 s, no active
//! frame or no loudness track, or the trace has no speed sample in a pause or in speech):
//!
//! - **speech_speed** `S`: the median hand speed over the samples in active frames (units/s:
//!   cm/s on the shared data);
//! - **pause_ratio** `P / S`: `P` the median hand speed inside pauses, counting each pause
//!   only from 0.5 s after its start to its end (the hands may take a moment to come to rest);
//!   `None` when `S` is 0;
//! - **settle_s**: the median, over the pauses that start after the trace's start (preceded
//!   by speech), of the time from the pause's start until the hand speed falls to or below
//!   `P + 0.25 (S - P)`; a pause in which it never does counts its whole length (within the
//!   trace);
//! - **react_s**: the median, over the pauses followed by speech (not ending at the track's
//!   or the trace's end), of the time from the speech's return (the pause's end) until the
//!   hand speed reaches `P + 0.5 (S - P)`; 0 when the first sample after the return is
//!   already there; when it never gets there before the next pause starts (or the trace
//!   ends), that whole time.
//!
//! Times are measured to the first speed sample at or after the event that meets the
//! threshold. A speaker rests in pauses (`pause_ratio` well below 1), settles soon after
//! the voice stops and moves again soon after it returns; a motion that ignores the voice
//! has a ratio near 1 and long settle and react times.

use super::signals::{quantile, smoothed_hand_speed};
use super::trace::Trace;
use crate::motion::fk::Vec3;

/// Length of a loudness frame (s).
pub const FRAME_S: f64 = 0.01;
/// Loudness is floored this far (dB) under its 99th percentile.
pub const FLOOR_BELOW_P99_DB: f64 = 50.0;
/// Frames of the centred moving average of the loudness (0.2 s).
pub const SMOOTH_FRAMES: usize = 20;
/// A frame is active within this many dB of the loudness's 99th percentile.
pub const ACTIVE_WITHIN_DB: f64 = 35.0;
/// Shortest inactive run that is a pause (s).
pub const MIN_PAUSE_S: f64 = 1.5;
/// The pause level counts from this long after a pause's start (s).
pub const PAUSE_LEVEL_FROM_S: f64 = 0.5;
/// `settle_s` waits for the speed to fall to this share of the way from the pause level to
/// the speech level.
pub const SETTLE_SHARE: f64 = 0.25;
/// `react_s` waits for the speed to reach this share of the way from the pause level to the
/// speech level.
pub const REACT_SHARE: f64 = 0.5;

/// The speech a trace was played to, as the figures need it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Speech {
    /// Syllable onsets (s from the trace's start).
    pub onsets: Vec<f64>,
    /// Steps (syllables and pauses): start (s), end (s), mean intensity (dB).
    pub spans: Vec<(f64, f64, f64)>,
    /// Per 10 ms audio frame from the trace's start, whether the voice is active
    /// ([`activity`]); empty without the audio (the voice figures are
    /// then `None`).
    pub active: Vec<bool>,
}

impl Speech {
    /// From the front end's steps.
    pub fn from_steps(steps: &[gesture_runtime::prosody::Step]) -> Self {
        use gesture_runtime::prosody::StepKind;
        Self {
            onsets: steps
                .iter()
                .filter(|s| s.kind == StepKind::Syllable)
                .map(|s| s.start_s())
                .collect(),
            spans: steps
                .iter()
                .map(|s| (s.start_s(), s.end_s(), s.intensity_db as f64))
                .collect(),
            active: Vec::new(),
        }
    }

    /// With the voice activity of `samples` (at `rate` Hz, starting where the trace starts).
    pub fn with_audio(mut self, samples: &[i16], rate: u32) -> Self {
        self.active = activity(samples, rate);
        self
    }
}

/// The four figures (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VoiceFigures {
    /// Median hand speed in pauses over the median in speech.
    pub pause_ratio: Option<f64>,
    /// Median time (s) from a pause's start until the hands settle.
    pub settle_s: Option<f64>,
    /// Median time (s) from the speech's return until the hands move.
    pub react_s: Option<f64>,
    /// Median hand speed in speech (units/s).
    pub speech_speed: Option<f64>,
}

/// The median of `v` (the mean of the two middle values for an even count; `None` when empty).
pub fn median(v: &[f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    Some(if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    })
}

/// The 99th percentile by nearest rank (as [`quantile`]).
fn p99(v: &[f64]) -> f64 {
    quantile(v, 0.99)
}

/// Samples per loudness frame at `rate` Hz.
fn frame_len(rate: u32) -> usize {
    ((rate as f64 * FRAME_S).round() as usize).max(1)
}

/// Loudness (dB, full scale 1) of each 10 ms frame of `samples` at `rate` Hz, floored at
/// [`FLOOR_BELOW_P99_DB`] under its 99th percentile (the last frame may be shorter).
pub fn loudness_db(samples: &[i16], rate: u32) -> Vec<f64> {
    let raw: Vec<f64> = samples
        .chunks(frame_len(rate))
        .map(|c| {
            let ms = c.iter().map(|&x| (x as f64 / 32768.0).powi(2)).sum::<f64>() / c.len() as f64;
            10.0 * ms.max(1e-20).log10()
        })
        .collect();
    let floor = p99(&raw) - FLOOR_BELOW_P99_DB;
    raw.into_iter().map(|d| d.max(floor)).collect()
}

/// Per 10 ms frame of `samples` (at `rate` Hz), whether the voice is active (see the module
/// docs).
pub fn activity(samples: &[i16], rate: u32) -> Vec<bool> {
    let db = loudness_db(samples, rate);
    let level = p99(&db) - ACTIVE_WITHIN_DB;
    let half = SMOOTH_FRAMES / 2;
    (0..db.len())
        .map(|j| {
            let (a, b) = (j.saturating_sub(half), (j + half).min(db.len()));
            db[a..b].iter().sum::<f64>() / (b - a) as f64 >= level
        })
        .collect()
}

/// The pauses of an activity track as frame ranges `a..b` (inactive runs of at least
/// [`MIN_PAUSE_S`]).
pub fn pause_frames(active: &[bool]) -> Vec<(usize, usize)> {
    let min = (MIN_PAUSE_S / FRAME_S).round() as usize;
    let mut out = Vec::new();
    let mut start = None;
    for (j, &on) in active.iter().chain(std::iter::once(&true)).enumerate() {
        match (on, start) {
            (false, None) => start = Some(j),
            (true, Some(a)) => {
                if j - a >= min {
                    out.push((a, j));
                }
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// The pauses of an activity track: start and end (s).
pub fn pauses(active: &[bool]) -> Vec<(f64, f64)> {
    pause_frames(active)
        .into_iter()
        .map(|(a, b)| (a as f64 * FRAME_S, b as f64 * FRAME_S))
        .collect()
}

/// The trace's hand speed relative to its anchor (see the module docs), smoothed: sample `i`
/// from frame `i` to `i + 1`. The hands' world positions when the trace has no anchor.
pub fn relative_hand_speed(t: &Trace) -> Vec<f64> {
    if t.anchor.is_empty() || t.anchor.len() != t.hands.len() {
        return smoothed_hand_speed(&t.hands, t.fps);
    }
    let rel: Vec<Vec<Vec3>> = t
        .hands
        .iter()
        .zip(&t.anchor)
        .map(|(hs, a)| {
            hs.iter()
                .map(|h| [h[0] - a[0], h[1] - a[1], h[2] - a[2]])
                .collect()
        })
        .collect();
    smoothed_hand_speed(&rel, t.fps)
}

/// The four figures of hand speeds `speed` (sample `i` at `(i + 1) / fps` s) against the
/// activity track `active` (10 ms frames from the same time 0); see the module docs.
pub fn figures(speed: &[f64], fps: f64, active: &[bool]) -> VoiceFigures {
    let none = VoiceFigures::default();
    let runs = pause_frames(active);
    if speed.is_empty() || fps.is_nan() || fps <= 0.0 || runs.is_empty() {
        return none;
    }
    let time = |i: usize| (i + 1) as f64 / fps;
    // The audio frame holding each speed sample.
    let frame: Vec<usize> = (0..speed.len())
        .map(|i| (time(i) / FRAME_S + 1e-6).floor() as usize)
        .collect();
    let skip = (PAUSE_LEVEL_FROM_S / FRAME_S).round() as usize;
    let (mut in_pause, mut in_speech) = (Vec::new(), Vec::new());
    for (i, &v) in speed.iter().enumerate() {
        match active.get(frame[i]) {
            Some(true) => in_speech.push(v),
            Some(false) => {
                let j = frame[i];
                if runs.iter().any(|&(a, b)| j >= a + skip && j < b) {
                    in_pause.push(v);
                }
            }
            None => {}
        }
    }
    let (Some(p), Some(s)) = (median(&in_pause), median(&in_speech)) else {
        return none;
    };
    let end = time(speed.len() - 1);
    // From the first sample at or after frame `from`, the time (s) until `hit` holds, looked
    // for before frame `until` (or the trace's end); `None` when the trace ends before `from`.
    let wait = |from: usize, until: usize, hit: &dyn Fn(f64) -> bool| -> Option<f64> {
        let i0 = frame.partition_point(|&j| j < from);
        if i0 >= speed.len() {
            return None;
        }
        let t0 = from as f64 * FRAME_S;
        let found = (i0..speed.len())
            .take_while(|&i| frame[i] < until)
            .find(|&i| hit(speed[i]));
        Some(match found {
            Some(i) if i == i0 => 0.0,
            Some(i) => time(i) - t0,
            None => ((until as f64 * FRAME_S).min(end) - t0).max(0.0),
        })
    };
    let settle_at = p + SETTLE_SHARE * (s - p);
    let settle: Vec<f64> = runs
        .iter()
        .filter(|&&(a, _)| a > 0)
        .filter_map(|&(a, b)| wait(a, b, &|v| v <= settle_at))
        .collect();
    let react_at = p + REACT_SHARE * (s - p);
    let react: Vec<f64> = runs
        .iter()
        .enumerate()
        .filter(|&(_, &(_, b))| b < active.len())
        .filter_map(|(k, &(_, b))| {
            let next = runs.get(k + 1).map_or(active.len(), |r| r.0);
            wait(b, next, &|v| v >= react_at)
        })
        .collect();
    VoiceFigures {
        pause_ratio: (s > 0.0).then(|| p / s),
        settle_s: median(&settle),
        react_s: median(&react),
        speech_speed: Some(s),
    }
}

/// The four figures of trace `t` against the activity track `active`.
pub fn measure_voice(t: &Trace, active: &[bool]) -> VoiceFigures {
    figures(&relative_hand_speed(t), t.fps, active)
}

#[cfg(test)]
mod tests {
    use super::*;

    const RATE: u32 = 16_000;

    /// Audio of (seconds, loud) parts: loud is a 200 Hz sine at amplitude 0.3 (-13.5 dBFS),
    /// quiet is digital silence or, with `noise`, a +-10 LSB pseudo-random hiss (about -75
    /// dBFS).
    fn audio(parts: &[(f64, bool)], noise: bool) -> Vec<i16> {
        let mut out = Vec::new();
        let mut seed = 12345u32;
        for &(secs, loud) in parts {
            for k in 0..(secs * RATE as f64).round() as usize {
                let t = k as f64 / RATE as f64;
                out.push(if loud {
                    (0.3 * 32767.0 * (2.0 * std::f64::consts::PI * 200.0 * t).sin()) as i16
                } else if noise {
                    seed = seed.wrapping_mul(1_103_515_245).wrapping_add(12345);
                    ((seed >> 16) % 21) as i16 - 10
                } else {
                    0
                });
            }
        }
        out
    }

    /// A trace at `fps` for `secs`: two hands moving apart from the anchor at `speed(t)`
    /// units/s (the step from frame `i` to `i + 1` at time `(i + 1) / fps`), the anchor at
    /// `anchor(t)`.
    fn trace(
        fps: f64,
        secs: f64,
        speed: impl Fn(f64) -> f64,
        anchor: impl Fn(f64) -> Vec3,
    ) -> Trace {
        let n = (secs * fps).round() as usize + 1;
        let mut x = 0.0;
        let (mut hands, mut anchors) = (Vec::new(), Vec::new());
        for f in 0..n {
            if f > 0 {
                x += speed(f as f64 / fps) / fps;
            }
            let a = anchor(f as f64 / fps);
            hands.push(vec![[a[0] + x, a[1], a[2]], [a[0], a[1] + x, a[2] + 5.0]]);
            anchors.push(a);
        }
        Trace {
            fps,
            hands,
            anchor: anchors,
            feet: vec![Vec::new(); n],
            rotations: vec![vec![0.0]; n],
            entries: Vec::new(),
        }
    }

    /// A body walking at 100 units/s along X and swaying.
    fn walking(t: f64) -> Vec3 {
        [100.0 * t, 20.0 * (3.0 * t).sin(), 2.0 * t]
    }

    /// Activity of (seconds, active) parts.
    fn active(parts: &[(f64, bool)]) -> Vec<bool> {
        parts
            .iter()
            .flat_map(|&(secs, on)| std::iter::repeat_n(on, (secs / FRAME_S).round() as usize))
            .collect()
    }

    #[test]
    fn two_seconds_of_silence_between_speech_is_one_pause_and_one_second_is_none() {
        for noise in [false, true] {
            let a = activity(
                &audio(&[(2.0, true), (2.0, false), (2.0, true)], noise),
                RATE,
            );
            assert_eq!(a.len(), 600);
            let p = pauses(&a);
            assert_eq!(p.len(), 1, "{p:?}");
            assert!(
                (p[0].0 - 2.0).abs() < 0.1 && (p[0].1 - 4.0).abs() < 0.1,
                "{p:?}"
            );
            // The speech around it is active.
            assert!(a[..190].iter().all(|&v| v) && a[410..].iter().all(|&v| v));
            let a = activity(
                &audio(&[(2.0, true), (1.0, false), (2.0, true)], noise),
                RATE,
            );
            assert!(pauses(&a).is_empty());
        }
        // The floor: a frame of zeros is -200 dB, floored at 50 dB under the sine's level.
        let db = loudness_db(&audio(&[(1.0, true), (1.0, false)], false), RATE);
        let sine = 20.0 * (0.3f64 / 2f64.sqrt()).log10();
        assert!((db[10] - sine).abs() < 0.1, "{}", db[10]);
        assert!((db[150] - (db[10] - 50.0)).abs() < 1e-9, "{}", db[150]);
    }

    #[test]
    fn hands_resting_in_the_pause_have_a_tenth_of_their_speed_in_speech() {
        // Speech 0-2 s and 4-6 s around silence; hands at 50 units/s relative to a walking
        // body while the voice is on, 5 in the silence.
        let samples = audio(&[(2.0, true), (2.0, false), (2.0, true)], true);
        let speech = Speech::default().with_audio(&samples, RATE);
        let speed = |t: f64| if (2.0..4.0).contains(&t) { 5.0 } else { 50.0 };
        let t = trace(30.0, 6.0, speed, walking);
        let m = measure_voice(&t, &speech.active);
        let ratio = m.pause_ratio.unwrap();
        assert!((ratio - 0.1).abs() < 0.02, "{ratio}");
        let s = m.speech_speed.unwrap();
        assert!((s - 50.0).abs() < 1.0, "{s}");
        // In the world the walk dominates.
        let mut world = t.clone();
        world.anchor.clear();
        assert!(measure_voice(&world, &speech.active).speech_speed.unwrap() > 90.0);
    }

    #[test]
    fn hands_settle_and_react_when_they_do() {
        // 2 s of speech, a 3 s pause, 3 s of speech. The hands keep 50 units/s for 0.6 s into
        // the pause, rest at 5, and move again 0.3 s after the voice returns.
        let a = active(&[(2.0, true), (3.0, false), (3.0, true)]);
        let speed = |t: f64| {
            if t > 2.6 + 1e-9 && t <= 5.3 + 1e-9 {
                5.0
            } else {
                50.0
            }
        };
        let v = measure_voice(&trace(30.0, 8.0, speed, walking), &a);
        let (settle, react) = (v.settle_s.unwrap(), v.react_s.unwrap());
        assert!((settle - 0.6).abs() < 0.1, "{settle}");
        assert!((react - 0.3).abs() < 0.1, "{react}");
        // Hands already moving when the voice returns react at once.
        let early = |t: f64| if t > 2.0 && t <= 4.5 { 5.0 } else { 50.0 };
        let v = measure_voice(&trace(30.0, 8.0, early, walking), &a);
        assert_eq!(v.react_s, Some(0.0));
        // Hands that never move again count the time to the trace's end (1 s).
        let a = active(&[(4.0, true), (3.0, false), (1.0, true)]);
        let never = |t: f64| if t > 4.0 { 5.0 } else { 50.0 };
        let v = measure_voice(&trace(30.0, 8.0, never, walking), &a);
        assert!((v.react_s.unwrap() - 1.0).abs() < 1e-9, "{v:?}");
    }

    #[test]
    fn hands_that_never_slow_down_take_the_whole_pause_to_settle() {
        // A 4 s pause in which the hands rest (the pause level) and two of 1.6 s in which they
        // keep going: the median settling time is those pauses' length.
        let a = active(&[
            (1.0, true),
            (4.0, false),
            (1.0, true),
            (1.6, false),
            (1.0, true),
            (1.6, false),
            (1.0, true),
        ]);
        let speed = |t: f64| if t > 1.0 && t <= 5.0 { 5.0 } else { 50.0 };
        let v = measure_voice(&trace(30.0, 11.2, speed, walking), &a);
        assert!((v.pause_ratio.unwrap() - 0.1).abs() < 0.02, "{v:?}");
        assert!((v.settle_s.unwrap() - 1.6).abs() < 1e-9, "{v:?}");
        // A pause at the trace's start follows no speech: no settling time from it.
        let a = active(&[(2.0, false), (2.0, true)]);
        let v = measure_voice(&trace(30.0, 4.0, |_| 10.0, walking), &a);
        assert_eq!(v.settle_s, None);
        assert!(v.react_s.is_some());
    }

    #[test]
    fn a_body_moving_with_its_hands_has_no_hand_speed() {
        let t = trace(30.0, 6.0, |_| 0.0, walking);
        assert!(relative_hand_speed(&t).iter().all(|v| v.abs() < 1e-9));
        let a = active(&[(2.0, true), (2.0, false), (2.0, true)]);
        let v = measure_voice(&t, &a);
        assert!(v.speech_speed.unwrap().abs() < 1e-9, "{v:?}");
        // No speed in speech: no ratio.
        assert_eq!(v.pause_ratio, None);
        // The same through a BVH: a body translating 3 units per frame with a chest and two
        // hands; the anchor is the chest and the hands do not move relative to it.
        let text = "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 6 Xposition Yposition \
                    Zposition Zrotation Yrotation Xrotation\n\tJOINT Chest\n\t{\n\t\tOFFSET \
                    0 10 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tJOINT LeftHand\n\
                    \t\t{\n\t\t\tOFFSET 5 0 0\n\t\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\
                    \t\t\tEnd Site\n\t\t\t{\n\t\t\t\tOFFSET 1 0 0\n\t\t\t}\n\t\t}\n\t\t\
                    JOINT RightHand\n\t\t{\n\t\t\tOFFSET -5 0 0\n\t\t\tCHANNELS 3 Zrotation \
                    Xrotation Yrotation\n\t\t\tEnd Site\n\t\t\t{\n\t\t\t\tOFFSET -1 0 0\n\
                    \t\t\t}\n\t\t}\n\t}\n}\nMOTION\nFrames: 3\nFrame Time: 0.1\n\
                    0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n3 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n\
                    6 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n";
        let m = crate::motion::parse_bvh(text, "walk.bvh").unwrap();
        let t = Trace::from_motion(&m, &crate::motion::EffectorSpec::Hands, Vec::new()).unwrap();
        for f in 0..3 {
            let x = 3.0 * f as f64;
            assert!(dist(t.anchor[f], [x, 10.0, 0.0]) < 1e-9, "{:?}", t.anchor);
            assert!(dist(t.hands[f][0], [x + 5.0, 10.0, 0.0]) < 1e-9);
            assert!(dist(t.hands[f][1], [x - 5.0, 10.0, 0.0]) < 1e-9);
        }
        assert!(relative_hand_speed(&t).iter().all(|v| v.abs() < 1e-9));
    }

    fn dist(a: Vec3, b: Vec3) -> f64 {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    }

    #[test]
    fn without_a_pause_or_audio_there_are_no_voice_figures() {
        let t = trace(30.0, 6.0, |t| 10.0 + t, walking);
        // All speech, a 1 s gap, no track at all.
        let loud = Speech::default().with_audio(&audio(&[(6.0, true)], false), RATE);
        let gap = Speech::default().with_audio(
            &audio(&[(2.0, true), (1.0, false), (3.0, true)], false),
            RATE,
        );
        for speech in [loud, gap, Speech::default()] {
            let m = measure_voice(&t, &speech.active);
            assert_eq!(
                (m.pause_ratio, m.settle_s, m.react_s, m.speech_speed),
                (None, None, None, None)
            );
        }
        // Only silence: a pause but no speech.
        assert_eq!(
            measure_voice(&t, &active(&[(6.0, false)])),
            VoiceFigures::default()
        );
        assert_eq!(median(&[]), None);
        assert_eq!(median(&[3.0, 1.0, 2.0, 10.0]), Some(2.5));
    }
}
