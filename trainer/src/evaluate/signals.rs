//! The signals the motion figures are computed from ([`super::metrics`]): the hands' speed
//! (per frame, smoothed, as a histogram), their strokes and pauses, how strokes align with
//! syllable onsets and with chance, the correlation of speed with the voice's intensity, and
//! the share of still frames. Pure functions of slices; no panics on empty or short input.

use crate::motion::fk::Vec3;

/// Shortest still run counted as a freeze (s).
pub const STILL_RUN_S: f64 = 0.2;
/// A channel moving less than this per frame at 30 fps is still (degrees).
pub const STILL_DEG_PER_FRAME_30FPS: f64 = 0.05;

/// Intensities below this count as this (dB): silence's exact -300 dB would otherwise
/// dominate the correlation of [`speech_coupling`].
pub const COUPLING_FLOOR_DB: f64 = 20.0;

/// Distance between two points.
fn dist(a: &Vec3, b: &Vec3) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Mean hand displacement from frame `f - 1` to frame `f`.
pub fn hand_step(hands: &[Vec<Vec3>], f: usize) -> f64 {
    let (a, b) = (&hands[f - 1], &hands[f]);
    a.iter().zip(b).map(|(x, y)| dist(x, y)).sum::<f64>() / a.len().max(1) as f64
}

/// The `q` quantile (0..=1) of `v` by nearest rank (0 for an empty slice).
pub fn quantile(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[((s.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize]
}

/// Per frame (from the second), the speed of every point (units/s).
pub fn speeds(pos: &[Vec<Vec3>], fps: f64) -> Vec<Vec<f64>> {
    pos.windows(2)
        .map(|w| {
            w[0].iter()
                .zip(&w[1])
                .map(|(a, b)| dist(a, b) * fps)
                .collect()
        })
        .collect()
}

/// Normalized hand-speed histogram (see the module docs).
pub fn speed_histogram(hands: &[Vec<Vec3>], fps: f64) -> Vec<f64> {
    speed_histogram_where(hands, fps, |_| true)
}

/// The hand-speed histogram of the frame steps (frame `i` to `i + 1`, at time `(i + 1) /
/// fps`) whose time `keep` accepts, normalized (all zero when none is).
pub fn speed_histogram_where(
    hands: &[Vec<Vec3>],
    fps: f64,
    keep: impl Fn(f64) -> bool,
) -> Vec<f64> {
    let mut h = vec![0.0; 26];
    let mut n = 0.0;
    for (i, step) in speeds(hands, fps).iter().enumerate() {
        if !keep((i + 1) as f64 / fps) {
            continue;
        }
        for v in step {
            h[((v / 10.0) as usize).min(25)] += 1.0;
            n += 1.0;
        }
    }
    h.iter_mut().for_each(|x| *x /= f64::max(n, 1.0));
    h
}

/// Hellinger distance between two normalized histograms.
pub fn hellinger(p: &[f64], q: &[f64]) -> f64 {
    let bc: f64 = p.iter().zip(q).map(|(a, b)| (a * b).sqrt()).sum();
    (1.0 - bc).max(0.0).sqrt()
}

/// Times (s) of the motion's strokes ([`stroke_frames`]).
pub fn motion_beats(hands: &[Vec<Vec3>], fps: f64) -> Vec<f64> {
    stroke_frames(hands, fps)
        .into_iter()
        .map(|i| (i as f64 + 0.5) / fps)
        .collect()
}

/// Mean hand speed from frame `i` to `i + 1` (units/s), smoothed by a centred moving average
/// over about 1/6 s.
pub fn smoothed_hand_speed(hands: &[Vec<Vec3>], fps: f64) -> Vec<f64> {
    let raw: Vec<f64> = speeds(hands, fps)
        .iter()
        .map(|v| v.iter().sum::<f64>() / v.len().max(1) as f64)
        .collect();
    let half = ((fps / 6.0) as usize / 2).max(1);
    (0..raw.len())
        .map(|i| {
            let (a, b) = (i.saturating_sub(half), (i + half + 1).min(raw.len()));
            raw[a..b].iter().sum::<f64>() / (b - a) as f64
        })
        .collect()
}

/// Pearson correlation of two equally long series (0 when either is constant or empty).
pub fn correlation(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len().min(y.len());
    if n < 2 {
        return 0.0;
    }
    let (mx, my) = (
        x[..n].iter().sum::<f64>() / n as f64,
        y[..n].iter().sum::<f64>() / n as f64,
    );
    let (mut c, mut vx, mut vy) = (0.0, 0.0, 0.0);
    for (a, b) in x[..n].iter().zip(&y[..n]) {
        c += (a - mx) * (b - my);
        vx += (a - mx) * (a - mx);
        vy += (b - my) * (b - my);
    }
    if vx <= 0.0 || vy <= 0.0 {
        return 0.0;
    }
    c / (vx * vy).sqrt()
}

/// [`MotionMetrics::speech_coupling`](super::metrics::MotionMetrics::speech_coupling): the correlation of the smoothed hand speed (frame `i`
/// to `i + 1`, at time `(i + 1) / fps`) with the intensity of the step spoken then; frames
/// outside every step are left out.
pub fn speech_coupling(hands: &[Vec<Vec3>], fps: f64, spans: &[(f64, f64, f64)]) -> f64 {
    let sp = smoothed_hand_speed(hands, fps);
    let (mut x, mut y) = (Vec::new(), Vec::new());
    let mut k = 0usize;
    for (i, v) in sp.iter().enumerate() {
        let t = (i + 1) as f64 / fps;
        while k < spans.len() && spans[k].1 <= t {
            k += 1;
        }
        if let Some(&(a, _, db)) = spans.get(k) {
            if a <= t {
                x.push(*v);
                y.push(db.max(COUPLING_FLOOR_DB));
            }
        }
    }
    correlation(&x, &y)
}

/// The pauses of the hands: frame `i` where the smoothed mean hand speed from frame `i` to
/// `i + 1` is a local minimum (where `pack` lets a beat hold wait for an onset).
pub fn beat_frames(hands: &[Vec<Vec3>], fps: f64) -> Vec<usize> {
    speed_minima(&smoothed_hand_speed(hands, fps))
}

/// The frames `i` where `sp[i]` is a local minimum ([`beat_frames`] of a smoothed speed).
pub fn speed_minima(sp: &[f64]) -> Vec<usize> {
    (1..sp.len().saturating_sub(1))
        .filter(|&i| sp[i] < sp[i - 1] && sp[i] <= sp[i + 1])
        .collect()
}

/// A stroke stands out from the hand speed around it by at least this share of the trace's
/// median smoothed hand speed.
pub const STROKE_PROMINENCE: f64 = 0.5;
/// Strokes closer than this (s) to a higher one are not counted.
pub const STROKE_GAP_S: f64 = 1.0 / 6.0;
/// How far (s) on each side the prominence of a stroke is looked for.
pub const STROKE_WINDOW_S: f64 = 2.0;
/// Width (s) of the beat-alignment kernel (AIST++ and EDGE use 3 frames at 30 fps).
pub const BEAT_SIGMA_S: f64 = 0.1;
/// The shifts (s) of the strokes behind [`MotionMetrics::beat_chance`](super::metrics::MotionMetrics::beat_chance): 12 each way, from
/// 0.35 s (farther than the kernel reaches) to 1.5 s (near enough that the speech is as dense).
pub fn chance_shifts() -> impl Iterator<Item = f64> {
    (0..12).flat_map(|k| {
        let d = 0.35 + (1.5 - 0.35) * k as f64 / 11.0;
        [d, -d]
    })
}

/// The frames of the motion's strokes: local maxima of the smoothed mean hand speed
/// ([`smoothed_hand_speed`]) whose prominence (their height above the higher of the lowest
/// speeds on either side before a higher speed, looked for within [`STROKE_WINDOW_S`]) is at
/// least [`STROKE_PROMINENCE`] times the trace's median speed, and that are not within
/// [`STROKE_GAP_S`] of a higher stroke (SciPy's `find_peaks` with `prominence`, `wlen` and
/// `distance`, written out: no crate here does it for `f64` slices).
pub fn stroke_frames(hands: &[Vec<Vec3>], fps: f64) -> Vec<usize> {
    speed_peaks(&smoothed_hand_speed(hands, fps), fps)
}

/// [`stroke_frames`] of a smoothed hand speed `sp` (per frame, at `fps`).
pub fn speed_peaks(sp: &[f64], fps: f64) -> Vec<usize> {
    let n = sp.len();
    let min_prom = STROKE_PROMINENCE * quantile(sp, 0.5);
    let reach = (STROKE_WINDOW_S * fps).round().max(1.0) as usize;
    let gap = (STROKE_GAP_S * fps).round() as usize;
    // Local maxima (the first frame of a plateau).
    let mut peaks: Vec<usize> = Vec::new();
    let mut i = 1;
    while i + 1 < n {
        if sp[i] > sp[i - 1] {
            let mut j = i;
            while j + 1 < n && sp[j + 1] == sp[i] {
                j += 1;
            }
            if j + 1 < n && sp[j + 1] < sp[i] {
                peaks.push(i);
            }
            i = j + 1;
        } else {
            i += 1;
        }
    }
    let side_min = |p: usize, step: isize| -> f64 {
        let mut lo = sp[p];
        let mut k = p as isize;
        for _ in 0..reach {
            k += step;
            if k < 0 || k as usize >= n || sp[k as usize] > sp[p] {
                break;
            }
            lo = lo.min(sp[k as usize]);
        }
        lo
    };
    peaks.retain(|&p| sp[p] - side_min(p, -1).max(side_min(p, 1)) >= min_prom.max(1e-12));
    // Highest first; drop those near a kept one.
    peaks.sort_by(|&a, &b| sp[b].total_cmp(&sp[a]).then(a.cmp(&b)));
    let mut kept: Vec<usize> = Vec::new();
    for p in peaks {
        if kept.iter().all(|&q| p.abs_diff(q) >= gap.max(1)) {
            kept.push(p);
        }
    }
    kept.sort_unstable();
    kept
}

/// The mean beat alignment of `beats` shifted by each of [`chance_shifts`] (beats shifted
/// outside `0..seconds` are left out).
pub fn beat_chance(onsets: &[f64], beats: &[f64], seconds: f64, sigma: f64) -> f64 {
    let shifts: Vec<f64> = chance_shifts().collect();
    shifts
        .iter()
        .map(|d| {
            let shifted: Vec<f64> = beats
                .iter()
                .map(|b| b + d)
                .filter(|b| (0.0..seconds).contains(b))
                .collect();
            beat_alignment(onsets, &shifted, sigma)
        })
        .sum::<f64>()
        / shifts.len() as f64
}

/// Beat alignment of the motion `beats` with the speech's `onsets`: the mean over the beats
/// of `exp(-d^2 / (2 sigma^2))`, `d` the distance (s) to the nearest onset (AIST++'s and
/// EDGE's form, each motion beat scored; 0 without beats or onsets).
pub fn beat_alignment(onsets: &[f64], beats: &[f64], sigma: f64) -> f64 {
    if onsets.is_empty() || beats.is_empty() {
        return 0.0;
    }
    let mut sorted = onsets.to_vec();
    sorted.sort_by(f64::total_cmp);
    beats
        .iter()
        .map(|b| {
            let k = sorted.partition_point(|o| o < b);
            let d = [k.checked_sub(1), Some(k)]
                .into_iter()
                .flatten()
                .filter_map(|j| sorted.get(j))
                .map(|o| (o - b).abs())
                .fold(f64::INFINITY, f64::min);
            (-d * d / (2.0 * sigma * sigma)).exp()
        })
        .sum::<f64>()
        / beats.len() as f64
}

/// Share of frames inside still runs (see the module docs).
pub fn still_share(rotations: &[Vec<f64>], fps: f64) -> f64 {
    let n = rotations.len();
    if n < 2 {
        return 0.0;
    }
    let threshold = STILL_DEG_PER_FRAME_30FPS * 30.0 / fps.max(1e-9);
    let min_run = (STILL_RUN_S * fps).ceil().max(1.0) as usize;
    // still[f]: nothing moved from frame f-1 to f (frame 0 counts with frame 1).
    let still: Vec<bool> = (0..n)
        .map(|f| {
            let (a, b) = if f == 0 { (0, 1) } else { (f - 1, f) };
            rotations[a]
                .iter()
                .zip(&rotations[b])
                .all(|(x, y)| (x - y).abs() <= threshold)
        })
        .collect();
    let mut counted = 0usize;
    let mut run = 0usize;
    for (f, &s) in still.iter().enumerate() {
        if s {
            run += 1;
        }
        if !s || f + 1 == n {
            if run >= min_run {
                counted += run;
            }
            run = 0;
        }
    }
    counted as f64 / n as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_histogram_of_chosen_frames_counts_only_them() {
        // Still for 1 s, then 55 units/s for 1 s, at 30 fps.
        let fps = 30.0;
        let hands: Vec<Vec<Vec3>> = (0..61)
            .map(|f| {
                let x = if f <= 30 {
                    0.0
                } else {
                    55.0 * (f - 30) as f64 / fps
                };
                vec![[x, 0.0, 0.0]]
            })
            .collect();
        let late = speed_histogram_where(&hands, fps, |t| t > 1.0 + 1e-9);
        assert!((late[5] - 1.0).abs() < 1e-9, "{late:?}");
        let early = speed_histogram_where(&hands, fps, |t| t <= 1.0 + 1e-9);
        assert!((early[0] - 1.0).abs() < 1e-9, "{early:?}");
        let all = speed_histogram(&hands, fps);
        assert!((all[0] - 0.5).abs() < 1e-9 && (all[5] - 0.5).abs() < 1e-9);
        assert!(speed_histogram_where(&hands, fps, |_| false)
            .iter()
            .all(|&v| v == 0.0));
    }

    #[test]
    fn small_wiggles_are_not_strokes() {
        // A speed signal (units/s along x) with two big peaks 1 s apart and a 2 Hz ripple
        // whose peaks stand 0.4 above their troughs (less than half the median speed, about 1).
        let fps = 60.0;
        let speed = |f: usize| -> f64 {
            let t = f as f64 / fps;
            let bump = |c: f64, h: f64| h * (-(t - c) * (t - c) / (2.0 * 0.05 * 0.05)).exp();
            1.0 + bump(1.0, 4.0)
                + bump(2.0, 4.0)
                + 0.2 * (2.0 * std::f64::consts::PI * 2.0 * t).sin()
        };
        let mut x = 0.0;
        let hands: Vec<Vec<Vec3>> = (0..180)
            .map(|f| {
                x += speed(f) / fps;
                vec![[x, 0.0, 0.0]]
            })
            .collect();
        let strokes = motion_beats(&hands, fps);
        assert_eq!(strokes.len(), 2, "{strokes:?}");
        assert!((strokes[0] - 1.0).abs() < 0.05 && (strokes[1] - 2.0).abs() < 0.05);
    }

    #[test]
    fn correlation_has_known_answers() {
        let x = [1.0, 2.0, 3.0, 4.0];
        assert!((correlation(&x, &[2.0, 4.0, 6.0, 8.0]) - 1.0).abs() < 1e-12);
        assert!((correlation(&x, &[8.0, 6.0, 4.0, 2.0]) + 1.0).abs() < 1e-12);
        // x against (x - 2.5)^2: symmetric about the mean, uncorrelated.
        assert!(correlation(&x, &[2.25, 0.25, 0.25, 2.25]).abs() < 1e-12);
        assert_eq!(correlation(&x, &[5.0; 4]), 0.0);
        assert_eq!(correlation(&[], &[]), 0.0);
    }

    #[test]
    fn hands_that_move_in_the_loud_steps_are_coupled_and_the_reverse_anticoupled() {
        // 10 s at 30 fps: 1 s steps alternating loud (70 dB) and quiet (-300 dB, floored).
        let fps = 30.0;
        let spans: Vec<(f64, f64, f64)> = (0..10)
            .map(|k| {
                (
                    k as f64,
                    k as f64 + 1.0,
                    if k % 2 == 0 { 70.0 } else { -300.0 },
                )
            })
            .collect();
        let moving = |loud: bool| -> Vec<Vec<Vec3>> {
            let mut x = 0.0;
            (0..300)
                .map(|f| {
                    let step = (f as f64 / fps) as usize;
                    if step.is_multiple_of(2) == loud {
                        x += 1.0;
                    }
                    vec![[x, 0.0, 0.0]]
                })
                .collect()
        };
        let on = speech_coupling(&moving(true), fps, &spans);
        let off = speech_coupling(&moving(false), fps, &spans);
        // Square waves in phase, smoothed over 1/6 s at the edges only: close to +1 and -1.
        assert!(on > 0.9, "{on}");
        assert!(off < -0.9, "{off}");
        assert!((on + off).abs() < 0.05, "{on} {off}");
        // Steady motion has no coupling at all.
        let steady: Vec<Vec<Vec3>> = (0..300).map(|f| vec![[f as f64, 0.0, 0.0]]).collect();
        assert_eq!(speech_coupling(&steady, fps, &spans), 0.0);
        // Frames outside every step are left out: no spans, nothing to correlate.
        assert_eq!(speech_coupling(&moving(true), fps, &[]), 0.0);
    }
}
