//! What a viewer sees, in numbers: the motion-quality metrics of one played (or captured)
//! motion (docs/method.md, "Beyond the paper: motion that looks alive").
//!
//! A [`Trace`] is a motion as shown: per frame, the world positions of the hands and the feet
//! and the joint rotation channels, and the list of segment entries (when which library
//! segment started, and whether it started with a cut). [`Trace::from_motion`] builds it from
//! any BVH motion (a capture, or the poses a controller played put back on the library's
//! skeleton), so the same figures come from `gesture-train eval-motion` and from a
//! `gesture-sim run` output folder. The figures ([`MotionMetrics`]):
//!
//! - **variety** (from the entries): distinct segments and their share of the library, the
//!   largest share of the frames any one segment takes, the entropy of the frame shares
//!   (bits), and the share of entries that repeat a segment entered less than 5 s before;
//! - **freezes**: the share of frames inside whole-body still runs: at least 0.2 s during
//!   which no rotation channel moves more than 0.05 degrees per frame at 30 fps (1.5 deg/s,
//!   scaled to the trace's frame rate);
//! - **feet**: the median speed of the foot and toe joints (skeleton units per second: cm/s on
//!   the shared data), when the skeleton has feet;
//! - **smoothness**: the mean magnitude of the hands' jerk (third difference, units/s^3); the
//!   hands' displacement across the frame of each cut (units, mean and largest); the 99th
//!   percentile of the hands' displacement per frame over the whole motion;
//! - **timing**: **beat alignment**, whether the gestures' strokes fall on syllables: each
//!   *stroke* (a prominent peak of the mean hand speed smoothed over 1/6 s, see
//!   [`stroke_frames`]) scores `exp(-d^2 / (2 * 0.1^2))` for the distance `d` (s) to the
//!   nearest syllable onset (AIST++'s and EDGE's form, kernel 0.1 s), averaged over the
//!   strokes; its **chance** level, the same strokes shifted by 0.35-1.5 s either way (so the
//!   speech around them stays as dense), and the **lift** over it. And the **speech
//!   coupling**: the Pearson correlation, frame by frame, between the mean hand speed
//!   smoothed over 1/6 s and the intensity (dB) of the syllable or pause being spoken (each
//!   step's mean intensity over its span, floored at [`COUPLING_FLOOR_DB`]).
//!
//!   Why strokes, not pauses of the hands: on the shared ZeroEGGS captures with their own
//!   speech, the strokes land near syllable onsets (alignment 0.80, 0.77 on the 9-joint
//!   take's two halves, 0.68, 0.66 on 067's; lift over the shifted strokes +0.17, +0.11,
//!   +0.16, +0.22; the phonological synchrony rule: the stroke goes with the syllable),
//!   while the hands' speed *minima*, which this figure used before (with BEAT's onset-side
//!   form and a 0.3 s kernel), scored no better than chance on the same captures (lift -0.02
//!   and +0.01): onsets come 3-4 per second and any motion's minima fall near one. A figure
//!   the real capture does not beat cannot judge a controller. The coupling is 0.53 and 0.64
//!   in the captures (9-joint take 90-121 s, 067 40-50 s; the motion moved by a third of the
//!   take correlates -0.19 and +0.01 with the 10 ms intensity): people move their hands
//!   faster while they speak louder;
//! - **the hands' speed distribution** against a reference (GENEA's Hellinger distance of
//!   hand-speed histograms, 10 units/s bins up to 250 and one overflow bin): the capture of
//!   the same speech when there is one; `eval-motion` otherwise builds one from the
//!   library's capture in speech like this ([`crate::evaluate::motion`]);
//! - **voice**: whether the body follows the voice: the hands' speed (relative to the chest)
//!   in the speech's pauses over their speed in speech, how soon they settle once the voice
//!   stops and how soon they move once it returns, and their speed in speech (voice activity
//!   from the audio's loudness; see [`crate::evaluate::voice`] for the definitions).
//!
//! Pure functions of their inputs; no panics on empty or short traces (figures of an empty
//! trace are 0).

use std::collections::{BTreeMap, HashMap};

use serde::Serialize;

use crate::motion::fk::{FkError, FkPlan, Target, Vec3};
use crate::motion::{EffectorSpec, Motion, Skeleton};

/// Seconds within which entering a segment again counts as a repeat.
pub const REPEAT_WINDOW_S: f64 = 5.0;
/// Shortest still run counted as a freeze (s).
pub const STILL_RUN_S: f64 = 0.2;
/// A channel moving less than this per frame at 30 fps is still (degrees).
pub const STILL_DEG_PER_FRAME_30FPS: f64 = 0.05;

/// Intensities below this count as this (dB): silence's exact -300 dB would otherwise
/// dominate the correlation of [`speech_coupling`].
pub const COUPLING_FLOOR_DB: f64 = 20.0;

/// The speech a trace was played to, as the figures need it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Speech {
    /// Syllable onsets (s from the trace's start).
    pub onsets: Vec<f64>,
    /// Steps (syllables and pauses): start (s), end (s), mean intensity (dB).
    pub spans: Vec<(f64, f64, f64)>,
    /// Per 10 ms audio frame from the trace's start, whether the voice is active
    /// ([`crate::evaluate::voice::activity`]); empty without the audio (the voice figures are
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
        self.active = crate::evaluate::voice::activity(samples, rate);
        self
    }
}

/// A segment entry: at frame `frame`, segment `segment` started; `cut` unless it went on from
/// its recorded predecessor.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Entry {
    /// First frame of the segment in the trace.
    pub frame: usize,
    /// Library segment.
    pub segment: usize,
    /// Whether the entry was a cut (including a segment re-entered from its own end).
    pub cut: bool,
}

/// A motion as shown, ready to measure (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct Trace {
    /// Frames per second.
    pub fps: f64,
    /// Per frame, the hands' world positions.
    pub hands: Vec<Vec<Vec3>>,
    /// Per frame, the world position of the hands' nearest common ancestor joint
    /// ([`crate::evaluate::voice::anchor_joint`]); empty when unknown.
    pub anchor: Vec<Vec3>,
    /// Per frame, the foot and toe joints' world positions (empty rows: no feet).
    pub feet: Vec<Vec<Vec3>>,
    /// Per frame, every joint rotation channel (degrees).
    pub rotations: Vec<Vec<f64>>,
    /// Segment entries in frame order (the first one at frame 0).
    pub entries: Vec<Entry>,
}

/// The foot and toe joints of a skeleton: every joint whose name contains "foot", "toe" or
/// "ankle" (ignoring case).
pub fn feet(skeleton: &Skeleton) -> Vec<usize> {
    skeleton
        .joints
        .iter()
        .enumerate()
        .filter(|(_, j)| {
            let n = j.name.to_ascii_lowercase();
            n.contains("foot") || n.contains("toe") || n.contains("ankle")
        })
        .map(|(i, _)| i)
        .collect()
}

/// The segment entries of a playback given, per frame, the library segment and frame shown:
/// a new entry where the segment changes or a segment starts over at frame 0. An entry is a
/// cut unless it moves on from the last frame of a segment into its recorded successor
/// (`continues(s)`: segment `s + 1` continues `s`; `len(s)`: frames of `s`).
pub fn entries_from_frames(
    shown: &[(usize, usize)],
    continues: impl Fn(usize) -> bool,
    len: impl Fn(usize) -> usize,
) -> Vec<Entry> {
    let mut out = Vec::new();
    for (t, &(seg, frame)) in shown.iter().enumerate() {
        let Some(&(ps, pf)) = t.checked_sub(1).and_then(|p| shown.get(p)) else {
            out.push(Entry {
                frame: 0,
                segment: seg,
                cut: false,
            });
            continue;
        };
        // A segment entered again shows its first frame after a later one; one frame back to
        // the first is a rest played to and fro (`Player::turn`), not an entry.
        if seg != ps || (frame == 0 && pf >= 2) {
            let on = seg == ps + 1 && continues(ps) && pf + 1 >= len(ps) && frame == 0;
            out.push(Entry {
                frame: t,
                segment: seg,
                cut: !on,
            });
        }
    }
    out
}

impl Trace {
    /// The trace of `motion` (hands found by `hands`, their anchor by
    /// [`crate::evaluate::voice::anchor_joint`], feet by [`feet`]) with `entries`.
    pub fn from_motion(
        motion: &Motion,
        hands: &EffectorSpec,
        entries: Vec<Entry>,
    ) -> Result<Self, String> {
        let sk = motion.skeleton();
        let eff = hands
            .resolve(sk, motion.source())
            .map_err(|e| e.to_string())?;
        let fk = |targets: &[Target]| -> Result<Vec<Vec<Vec3>>, FkError> {
            if targets.is_empty() {
                return Ok(vec![Vec::new(); motion.frames()]);
            }
            let p = FkPlan::new(sk, targets)?.positions(motion)?;
            Ok((0..p.frames()).map(|f| p.frame(f).to_vec()).collect())
        };
        let foot_targets: Vec<Target> = feet(sk).into_iter().map(Target::Joint).collect();
        // The anchor rides along with the hands' FK as one more target.
        let anchor = crate::evaluate::voice::anchor_joint(sk, &eff.targets);
        let mut hand_targets = eff.targets.clone();
        hand_targets.extend(anchor.map(Target::Joint));
        let mut hands = fk(&hand_targets).map_err(|e| e.to_string())?;
        let anchor: Vec<Vec3> = match anchor {
            Some(_) => hands.iter_mut().filter_map(|row| row.pop()).collect(),
            None => Vec::new(),
        };
        let rot: Vec<usize> = {
            let mut v = Vec::new();
            let mut k = 0;
            for j in &sk.joints {
                for c in &j.channels {
                    if c.is_rotation() {
                        v.push(k);
                    }
                    k += 1;
                }
            }
            v
        };
        Ok(Self {
            fps: motion.fps(),
            hands,
            anchor,
            feet: fk(&foot_targets).map_err(|e| e.to_string())?,
            rotations: (0..motion.frames())
                .map(|f| {
                    let row = motion.frame(f).unwrap_or(&[]);
                    rot.iter()
                        .map(|&k| row.get(k).copied().unwrap_or(0.0))
                        .collect()
                })
                .collect(),
            entries,
        })
    }

    /// Frames in the trace.
    pub fn frames(&self) -> usize {
        self.hands.len()
    }
}

/// The figures of one motion (see the module docs for each).
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq)]
pub struct MotionMetrics {
    /// Seconds of motion.
    pub seconds: f64,
    /// Segment entries.
    pub entries: usize,
    /// Distinct segments entered.
    pub distinct_segments: usize,
    /// `distinct_segments` over the library's segments (`None` without a library size).
    pub library_share: Option<f64>,
    /// Largest share of the frames one segment takes.
    pub max_segment_share: f64,
    /// Entropy of the segments' frame shares (bits).
    pub usage_entropy_bits: f64,
    /// Share of entries that enter a segment entered less than 5 s before.
    pub repeat_5s_share: f64,
    /// Cuts per second.
    pub cuts_per_s: f64,
    /// Share of frames inside whole-body still runs of at least 0.2 s.
    pub still_share: f64,
    /// Median foot and toe speed (units/s), `None` without feet.
    pub foot_speed: Option<f64>,
    /// Mean magnitude of the hands' jerk (units/s^3).
    pub mean_jerk: f64,
    /// Mean hand displacement across the frame of each cut (units).
    pub jump_at_cuts: f64,
    /// Largest hand displacement across the frame of a cut (units).
    pub max_jump_at_cuts: f64,
    /// 99th percentile of the hands' displacement per frame (units).
    pub p99_step: f64,
    /// How close the strokes fall to syllable onsets (0-1; see the module docs).
    pub beat_alignment: f64,
    /// Strokes ([`stroke_frames`]) per second.
    pub beats_per_s: f64,
    /// Beat alignment of the same strokes shifted by each of [`chance_shifts`]: what
    /// strokes not timed on the syllables score in speech this dense.
    pub beat_chance: f64,
    /// `beat_alignment - beat_chance`: how much better the strokes fall on the onsets than
    /// chance.
    pub beat_lift: f64,
    /// Correlation of the smoothed hand speed with the speech's step intensity (-1..1; see
    /// the module docs).
    pub speech_coupling: f64,
    /// Hellinger distance of the hand-speed histogram to the reference (`None` without one).
    pub hellinger: Option<f64>,
    /// Median hand speed (relative to the anchor) in the speech's pauses over that in speech
    /// ([`crate::evaluate::voice`]; `None` without pauses or audio).
    pub pause_ratio: Option<f64>,
    /// Median time (s) from a pause's start until the hands settle.
    pub settle_s: Option<f64>,
    /// Median time (s) from the speech's return after a pause until the hands move.
    pub react_s: Option<f64>,
    /// Median hand speed (relative to the anchor) while the voice is active (units/s).
    pub speech_speed: Option<f64>,
}

fn dist(a: &Vec3, b: &Vec3) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Mean hand displacement from frame `f - 1` to frame `f`.
fn hand_step(hands: &[Vec<Vec3>], f: usize) -> f64 {
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
fn speeds(pos: &[Vec<Vec3>], fps: f64) -> Vec<Vec<f64>> {
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

/// [`MotionMetrics::speech_coupling`]: the correlation of the smoothed hand speed (frame `i`
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
/// The shifts (s) of the strokes behind [`MotionMetrics::beat_chance`]: 12 each way, from
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
    let sp = smoothed_hand_speed(hands, fps);
    let n = sp.len();
    let min_prom = STROKE_PROMINENCE * quantile(&sp, 0.5);
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

/// Every figure of `t` (see the module docs): `speech` what it was played to (times in seconds
/// from the trace's start), `library` the library's segment count, `reference` the
/// hand-speed histogram ([`speed_histogram`]) to compare the hands' speeds with.
pub fn measure(
    t: &Trace,
    speech: &Speech,
    library: Option<usize>,
    reference: Option<&[f64]>,
) -> MotionMetrics {
    let n = t.frames();
    let fps = t.fps.max(1e-9);
    let seconds = n as f64 / fps;
    let mut m = MotionMetrics {
        seconds,
        ..MotionMetrics::default()
    };
    if n == 0 {
        return m;
    }
    // Variety: frames per segment from the entries.
    let entries: Vec<Entry> = t.entries.iter().copied().filter(|e| e.frame < n).collect();
    let mut frames_of: BTreeMap<usize, usize> = BTreeMap::new();
    for (k, e) in entries.iter().enumerate() {
        let end = entries.get(k + 1).map_or(n, |x| x.frame).max(e.frame);
        *frames_of.entry(e.segment).or_default() += end - e.frame;
    }
    let covered: usize = frames_of.values().sum();
    m.entries = entries.len();
    m.distinct_segments = frames_of.len();
    m.library_share = library.map(|l| m.distinct_segments as f64 / l.max(1) as f64);
    if covered > 0 {
        m.max_segment_share =
            frames_of.values().copied().max().unwrap_or(0) as f64 / covered as f64;
        m.usage_entropy_bits = -frames_of
            .values()
            .map(|&c| c as f64 / covered as f64)
            .filter(|&p| p > 0.0)
            .map(|p| p * p.log2())
            .sum::<f64>()
            + 0.0;
    }
    let window = (REPEAT_WINDOW_S * fps).round() as usize;
    let mut last_entry: HashMap<usize, usize> = HashMap::new();
    let mut repeats = 0usize;
    for e in &entries {
        if last_entry
            .get(&e.segment)
            .is_some_and(|&f| e.frame - f < window)
        {
            repeats += 1;
        }
        last_entry.insert(e.segment, e.frame);
    }
    m.repeat_5s_share = repeats as f64 / entries.len().max(1) as f64;
    let cuts: Vec<usize> = entries
        .iter()
        .filter(|e| e.cut && e.frame > 0)
        .map(|e| e.frame)
        .collect();
    m.cuts_per_s = cuts.len() as f64 / seconds.max(1e-9);
    // Freezes, feet.
    m.still_share = still_share(&t.rotations, fps);
    let foot: Vec<f64> = speeds(&t.feet, fps).into_iter().flatten().collect();
    m.foot_speed = (!foot.is_empty()).then(|| quantile(&foot, 0.5));
    // Smoothness.
    let h = &t.hands;
    let jerk: Vec<f64> = h
        .windows(4)
        .flat_map(|w| {
            (0..w[0].len()).map(move |k| {
                let j: Vec<f64> = (0..3)
                    .map(|c| w[3][k][c] - 3.0 * w[2][k][c] + 3.0 * w[1][k][c] - w[0][k][c])
                    .collect();
                (j[0] * j[0] + j[1] * j[1] + j[2] * j[2]).sqrt() * fps * fps * fps
            })
        })
        .collect();
    m.mean_jerk = jerk.iter().sum::<f64>() / jerk.len().max(1) as f64;
    let jumps: Vec<f64> = cuts.iter().map(|&f| hand_step(h, f)).collect();
    m.jump_at_cuts = jumps.iter().sum::<f64>() / jumps.len().max(1) as f64 + 0.0;
    m.max_jump_at_cuts = jumps.iter().copied().fold(0.0, f64::max);
    let steps: Vec<f64> = (1..n).map(|f| hand_step(h, f)).collect();
    m.p99_step = quantile(&steps, 0.99);
    // Timing and speed distribution.
    let onsets = &speech.onsets;
    let beats = motion_beats(h, fps);
    m.speech_coupling = speech_coupling(h, fps, &speech.spans);
    m.beat_alignment = beat_alignment(onsets, &beats, BEAT_SIGMA_S);
    m.beats_per_s = beats.len() as f64 / seconds.max(1e-9);
    m.beat_chance = beat_chance(onsets, &beats, seconds, BEAT_SIGMA_S);
    m.beat_lift = m.beat_alignment - m.beat_chance;
    m.hellinger = reference.map(|r| hellinger(&speed_histogram(h, fps), r));
    // Does the body follow the voice.
    let v = crate::evaluate::voice::measure_voice(t, &speech.active);
    m.pause_ratio = v.pause_ratio;
    m.settle_s = v.settle_s;
    m.react_s = v.react_s;
    m.speech_speed = v.speech_speed;
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trace(frames: usize, entries: Vec<Entry>) -> Trace {
        Trace {
            fps: 30.0,
            hands: (0..frames)
                .map(|f| vec![[f as f64, 0.0, 0.0], [0.0, f as f64, 0.0]])
                .collect(),
            anchor: Vec::new(),
            feet: vec![Vec::new(); frames],
            rotations: (0..frames).map(|f| vec![f as f64]).collect(),
            entries,
        }
    }

    fn entry(frame: usize, segment: usize) -> Entry {
        Entry {
            frame,
            segment,
            cut: true,
        }
    }

    #[test]
    fn a_planted_loop_has_one_segment_all_the_frames_and_only_repeats() {
        // One 30-frame segment entered every second for 10 s.
        let t = trace(300, (0..10).map(|k| entry(30 * k, 4)).collect());
        let m = measure(&t, &Speech::default(), Some(40), None);
        assert_eq!(m.distinct_segments, 1);
        assert_eq!(m.library_share, Some(1.0 / 40.0));
        assert_eq!(m.max_segment_share, 1.0);
        assert_eq!(m.usage_entropy_bits, 0.0);
        // Every entry but the first repeats one from a second before.
        assert!((m.repeat_5s_share - 0.9).abs() < 1e-12);
        assert!((m.cuts_per_s - 0.9).abs() < 1e-9);
    }

    #[test]
    fn four_equal_segments_have_two_bits_and_repeats_only_within_5_s() {
        // Segments 0..4 in turn, 3 s each: a segment comes back after 12 s, never within 5.
        let t = trace(30 * 24, (0..8).map(|k| entry(90 * k, k % 4)).collect());
        let m = measure(&t, &Speech::default(), Some(8), None);
        assert_eq!(m.distinct_segments, 4);
        assert!((m.usage_entropy_bits - 2.0).abs() < 1e-12);
        assert!((m.max_segment_share - 0.25).abs() < 1e-12);
        assert_eq!(m.repeat_5s_share, 0.0);
        // Every 2 s: repeats after 4 s (within 5).
        let t = trace(30 * 16, (0..8).map(|k| entry(60 * k, k % 2)).collect());
        assert!(
            (measure(&t, &Speech::default(), None, None).repeat_5s_share - 6.0 / 8.0).abs() < 1e-12
        );
    }

    #[test]
    fn a_known_slide_has_its_speed_and_a_planted_foot_none() {
        // A foot sliding 0.5 units per frame at 30 fps: 15 units/s; the other planted.
        let mut t = trace(60, vec![entry(0, 0)]);
        t.feet = (0..60)
            .map(|f| vec![[0.5 * f as f64, 0.0, 0.0], [3.0, 0.0, 0.0]])
            .collect();
        let m = measure(&t, &Speech::default(), None, None);
        // Half the foot samples are 15, half 0: the median is one of them.
        let s = m.foot_speed.unwrap();
        assert!(s == 0.0 || (s - 15.0).abs() < 1e-9, "{s}");
        t.feet = (0..60).map(|f| vec![[0.5 * f as f64, 0.0, 0.0]]).collect();
        assert!(
            (measure(&t, &Speech::default(), None, None)
                .foot_speed
                .unwrap()
                - 15.0)
                .abs()
                < 1e-9
        );
        t.feet = vec![Vec::new(); 60];
        assert_eq!(measure(&t, &Speech::default(), None, None).foot_speed, None);
    }

    #[test]
    fn still_runs_count_only_from_a_fifth_of_a_second() {
        // 90 frames: moving, then still for 10 frames (1/3 s), moving, still for 3 frames.
        let mut v = 0.0;
        let rot: Vec<Vec<f64>> = (0..90)
            .map(|f| {
                let still = (30..40).contains(&f) || (60..63).contains(&f);
                if !still {
                    v += 1.0;
                }
                vec![v]
            })
            .collect();
        // Frames 30..40 repeat frame 29's value: 10 still frames (>= 6 at 30 fps); 60..63: 3.
        assert!((still_share(&rot, 30.0) - 10.0 / 90.0).abs() < 1e-12);
        // Below the threshold (0.05 deg per frame) counts as still: all of it.
        let slow: Vec<Vec<f64>> = (0..90).map(|f| vec![0.01 * f as f64]).collect();
        assert_eq!(still_share(&slow, 30.0), 1.0);
    }

    #[test]
    fn jumps_at_cuts_and_the_step_percentile() {
        // Hands move 1 unit per frame; at frame 50 (a cut) they jump 10 units.
        let mut t = trace(100, vec![entry(0, 0), entry(50, 1)]);
        for f in 50..100 {
            for h in &mut t.hands[f] {
                h[2] += 10.0;
            }
        }
        let m = measure(&t, &Speech::default(), None, None);
        assert!((m.max_jump_at_cuts - (1.0f64 + 100.0).sqrt()).abs() < 1e-9);
        assert!((m.jump_at_cuts - m.max_jump_at_cuts).abs() < 1e-12);
        // 98 of the 99 steps are 1 unit: the 99th percentile is 1.
        assert!((m.p99_step - 1.0).abs() < 1e-12);
        // A continuation (not a cut) is not a jump.
        t.entries[1].cut = false;
        assert_eq!(
            measure(&t, &Speech::default(), None, None).jump_at_cuts,
            0.0
        );
    }

    #[test]
    fn strokes_on_the_onsets_score_one_and_identical_speeds_have_no_distance() {
        // Hands whose speed is 3 |sin(pi t)| per frame: strokes (speed peaks) at every half
        // second past a whole one, pauses at the whole seconds.
        let fps = 30.0;
        let hands: Vec<Vec<Vec3>> = {
            let mut x = 0.0;
            (0..300)
                .map(|f| {
                    let t = f as f64 / fps;
                    x += (std::f64::consts::PI * t).sin().abs() * 3.0;
                    vec![[x, 0.0, 0.0]]
                })
                .collect()
        };
        let strokes = motion_beats(&hands, fps);
        assert_eq!(strokes.len(), 10, "{strokes:?}");
        for (k, s) in strokes.iter().enumerate() {
            assert!((s - (k as f64 + 0.5)).abs() < 0.05, "{strokes:?}");
        }
        // Onsets on the strokes score about 1; on the pauses, 0.5 s away, about
        // exp(-0.5^2 / (2 * 0.1^2)) = 3.7e-6.
        let on: Vec<f64> = (0..10).map(|k| k as f64 + 0.5).collect();
        assert!(beat_alignment(&on, &strokes, BEAT_SIGMA_S) > 0.9);
        let off: Vec<f64> = (0..=10).map(|k| k as f64).collect();
        assert!(beat_alignment(&off, &strokes, BEAT_SIGMA_S) < 1e-3);
        // Strokes 0.1 s after each onset: exp(-1/2) each.
        let late: Vec<f64> = on.iter().map(|o| o + 0.1).collect();
        assert!((beat_alignment(&on, &late, BEAT_SIGMA_S) - (-0.5f64).exp()).abs() < 1e-12);
        // Shifted by 0.35-1.5 s the strokes miss the onsets: chance is low, the lift large.
        let chance = beat_chance(&on, &strokes, 10.0, BEAT_SIGMA_S);
        assert!(chance < 0.4, "{chance}");
        let h = speed_histogram(&hands, fps);
        assert!((h.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert_eq!(hellinger(&h, &h), 0.0);
    }

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

    #[test]
    fn entries_come_from_segment_changes_and_restarts() {
        // Segment 0 (3 frames) runs on into its successor 1; 1 is cut into 5; 5 restarts from
        // its last frame, then plays back to its first and turns (a rest played to and fro:
        // no entry).
        let shown = [
            (0, 0),
            (0, 1),
            (0, 2),
            (1, 0),
            (1, 1),
            (5, 0),
            (5, 1),
            (5, 2),
            (5, 0),
            (5, 1),
            (5, 2),
            (5, 1),
            (5, 0),
            (5, 1),
        ];
        let e = entries_from_frames(&shown, |s| s == 0, |_| 3);
        let got: Vec<(usize, usize, bool)> =
            e.iter().map(|e| (e.frame, e.segment, e.cut)).collect();
        assert_eq!(
            got,
            [(0, 0, false), (3, 1, false), (5, 5, true), (8, 5, true)]
        );
        // Entering the successor from the middle of a segment is a cut.
        let shown = [(0, 0), (1, 0)];
        assert!(entries_from_frames(&shown, |_| true, |_| 3)[1].cut);
    }

    #[test]
    fn an_empty_trace_is_all_zero() {
        let speech = Speech {
            onsets: vec![1.0],
            spans: vec![(0.0, 2.0, 60.0)],
            active: vec![false; 300],
        };
        let m = measure(&Trace::default(), &speech, Some(3), None);
        assert_eq!(m.entries, 0);
        assert_eq!(m.seconds, 0.0);
        assert_eq!(m.speech_coupling, 0.0);
        assert_eq!(m.pause_ratio, None);
    }
}
