//! Segmentation of a take into gesture phases by end-effector speed.
//!
//! Owns the per-frame speed signal and the cut rule. Segments are cut where the mean effector
//! speed crosses a threshold (docs/method.md, "Data and time steps"): fast segments are strokes or
//! retractions, slow ones holds and rests.
//!
//! ## The signal
//!
//! Per frame, the mean over effectors of `|dp/dt|` in skeleton units per second, `dp/dt` by
//! central differences (one-sided at the first and last frame). It is then smoothed by a
//! centred moving average of [`SegmentParams::smoothing_s`] (default 1/6 s, 5 frames at 30 fps;
//! the average is taken over the frames that exist at the ends). Why: differencing amplifies
//! capture jitter, and a speed that wobbles around the threshold would cut many one-frame
//! segments; 1/6 s is shorter than the shortest gesture phase (about 0.2 s) so it moves a cut by
//! at most two frames, yet flattens frame-to-frame noise. The window is set in seconds so a
//! 120 fps take gets the same smoothing as a 30 fps one.
//!
//! ## The rule
//!
//! - Threshold `c`: by default the **median** of the take's smoothed speed
//!   ([`Threshold::Quantile`]`(0.5)`). A quantile scales with the data, so the same setting
//!   works for takes in centimetres or metres and for calm or animated speakers; the median
//!   splits the take's time evenly between "faster than usual" and "slower than usual", which
//!   is what separates strokes from holds. [`Threshold::Absolute`] fixes `c` in units/s.
//! - Hysteresis: a slow phase ends only when the speed rises above `high = c * (1 + h)`, a fast
//!   phase only when it falls below `low = c / (1 + h)` ([`SegmentParams::hysteresis`],
//!   default `h = 0.25`). This decides *whether* a crossing counts; the cut itself is placed
//!   where the speed crossed `c` (the last crossing before the confirmation), so cuts sit at
//!   the threshold crossing the paper describes rather than lagging behind it.
//! - Minimum length ([`SegmentParams::min_segment_s`], default 0.2 s): repeatedly, the
//!   shortest segment under the minimum is absorbed: inside the take it merges with both
//!   neighbours (a blip of stillness inside a stroke is part of the stroke), at either end it
//!   joins its only neighbour. Phases keep alternating.
//!
//! ## Invariants
//!
//! The output tiles the take: segments are in order, non-empty, contiguous, start at frame 0
//! and end at the last frame (a take with no frames has no segments). Every segment is at least
//! the minimum length unless the whole take is shorter. Never panics; parameters are checked
//! by [`SegmentParams::validate`].

use super::fk::{Positions, Vec3};

/// How the centre threshold is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Threshold {
    /// This quantile (0..=1) of the take's smoothed speed distribution.
    Quantile(f64),
    /// A fixed speed in skeleton units per second.
    Absolute(f64),
}

/// Segmentation settings. See the module docs for the defaults and why.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentParams {
    /// Centre threshold.
    pub threshold: Threshold,
    /// Relative hysteresis `h`: thresholds `c * (1 + h)` and `c / (1 + h)`.
    pub hysteresis: f64,
    /// Minimum segment duration in seconds.
    pub min_segment_s: f64,
    /// Moving-average window in seconds (rounded to an odd number of frames, at least 1).
    pub smoothing_s: f64,
}

impl Default for SegmentParams {
    fn default() -> Self {
        SegmentParams {
            threshold: Threshold::Quantile(0.5),
            hysteresis: 0.25,
            min_segment_s: 0.2,
            smoothing_s: 1.0 / 6.0,
        }
    }
}

/// A parameter is out of range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    /// Which parameter, and what it must be.
    #[error("segmentation parameter `{name}` = {value} is invalid: {must}")]
    Invalid {
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The allowed range.
        must: &'static str,
    },
}

impl SegmentParams {
    /// Checks every field's range.
    pub fn validate(&self) -> Result<(), ParamError> {
        let check = |name, value: f64, ok: bool, must| {
            if ok && value.is_finite() {
                Ok(())
            } else {
                Err(ParamError::Invalid { name, value, must })
            }
        };
        match self.threshold {
            Threshold::Quantile(q) => check(
                "threshold (quantile)",
                q,
                (0.0..=1.0).contains(&q),
                "between 0 and 1",
            )?,
            Threshold::Absolute(a) => check("threshold (absolute)", a, a >= 0.0, "a speed >= 0")?,
        }
        check(
            "hysteresis",
            self.hysteresis,
            self.hysteresis >= 0.0,
            ">= 0",
        )?;
        check(
            "min_segment_s",
            self.min_segment_s,
            self.min_segment_s >= 0.0,
            "seconds >= 0",
        )?;
        check(
            "smoothing_s",
            self.smoothing_s,
            self.smoothing_s >= 0.0,
            "seconds >= 0",
        )
    }

    /// Moving-average window in frames (odd, >= 1) for a given frame time.
    pub fn smoothing_frames(&self, frame_time: f64) -> usize {
        let n = (self.smoothing_s / frame_time).round();
        // Guarded cast: huge or NaN ratios give a window as long as any take.
        let n = if n.is_finite() && n >= 1.0 {
            n.min(1e9) as usize
        } else {
            1
        };
        n | 1
    }

    /// Minimum segment length in frames (>= 1) for a given frame time.
    pub fn min_frames(&self, frame_time: f64) -> usize {
        let n = (self.min_segment_s / frame_time - 1e-9).ceil();
        if n.is_finite() && n >= 1.0 {
            n.min(1e12) as usize
        } else {
            1
        }
    }
}

/// Speed class of a segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Phase {
    /// Above the threshold: a stroke or retraction.
    Moving,
    /// Below the threshold: a hold or rest.
    Still,
}

/// A run of frames `start_frame..end_frame` (end exclusive).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Segment {
    /// First frame.
    pub start_frame: usize,
    /// One past the last frame.
    pub end_frame: usize,
    /// Speed class.
    pub phase: Phase,
}

impl Segment {
    /// Number of frames.
    pub fn len(&self) -> usize {
        self.end_frame.saturating_sub(self.start_frame)
    }

    /// True for a segment without frames (never produced by [`segment`]).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Duration in seconds.
    pub fn duration(&self, frame_time: f64) -> f64 {
        self.len() as f64 * frame_time
    }
}

/// Result of [`segment`].
#[derive(Clone, Debug, PartialEq)]
pub struct Segmentation {
    /// The segments, tiling the take.
    pub segments: Vec<Segment>,
    /// The smoothed mean effector speed per frame (units/s).
    pub speed: Vec<f64>,
    /// Centre threshold `c` actually used (units/s).
    pub threshold: f64,
    /// Lower hysteresis threshold.
    pub low: f64,
    /// Upper hysteresis threshold.
    pub high: f64,
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: Vec3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// Velocity of every point by central differences (one-sided at the ends; zero for a single
/// frame), frames x points like `positions`.
pub fn velocities(positions: &Positions, frame_time: f64) -> Vec<Vec3> {
    let (n, k) = (positions.frames(), positions.points());
    let mut out = vec![[0.0; 3]; n * k];
    if n < 2 {
        return out;
    }
    for f in 0..n {
        let (a, b) = (f.saturating_sub(1), (f + 1).min(n - 1));
        let dt = (b - a) as f64 * frame_time;
        for e in 0..k {
            let d = sub(positions.get(b, e), positions.get(a, e));
            out[f * k + e] = [d[0] / dt, d[1] / dt, d[2] / dt];
        }
    }
    out
}

/// Mean over points of the speed `|v|` per frame (unsmoothed).
pub fn mean_speed(positions: &Positions, frame_time: f64) -> Vec<f64> {
    let k = positions.points();
    if k == 0 {
        return vec![0.0; positions.frames()];
    }
    velocities(positions, frame_time)
        .chunks(k)
        .map(|row| row.iter().map(|&v| norm(v)).sum::<f64>() / k as f64)
        .collect()
}

/// Centred moving average over `window` frames (odd; the ends average what exists).
pub fn moving_average(x: &[f64], window: usize) -> Vec<f64> {
    let half = window / 2;
    let mut prefix = Vec::with_capacity(x.len() + 1);
    prefix.push(0.0);
    let mut acc = 0.0;
    for &v in x {
        acc += v;
        prefix.push(acc);
    }
    (0..x.len())
        .map(|i| {
            let a = i.saturating_sub(half);
            let b = (i + half + 1).min(x.len());
            (prefix[b] - prefix[a]) / (b - a) as f64
        })
        .collect()
}

/// The `q` quantile (linear interpolation) of `x`; 0 for an empty slice.
pub fn quantile(x: &[f64], q: f64) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    let mut s = x.to_vec();
    s.sort_by(f64::total_cmp);
    let pos = q.clamp(0.0, 1.0) * (s.len() - 1) as f64;
    let i = pos.floor() as usize;
    let frac = pos - i as f64;
    match s.get(i + 1) {
        Some(&next) => s[i] + frac * (next - s[i]),
        None => s[i],
    }
}

/// Segments a take from its effector positions (frames x effectors).
pub fn segment(
    positions: &Positions,
    frame_time: f64,
    params: &SegmentParams,
) -> Result<Segmentation, ParamError> {
    params.validate()?;
    let raw = mean_speed(positions, frame_time);
    let speed = moving_average(&raw, params.smoothing_frames(frame_time));
    segment_speed(speed, frame_time, params)
}

/// Segments a take from an already smoothed speed signal.
pub fn segment_speed(
    speed: Vec<f64>,
    frame_time: f64,
    params: &SegmentParams,
) -> Result<Segmentation, ParamError> {
    params.validate()?;
    let c = match params.threshold {
        Threshold::Quantile(q) => quantile(&speed, q),
        Threshold::Absolute(a) => a,
    };
    let high = c * (1.0 + params.hysteresis);
    let low = c / (1.0 + params.hysteresis);
    let mut segments = hysteresis_cuts(&speed, c, low, high);
    merge_short(&mut segments, params.min_frames(frame_time));
    Ok(Segmentation {
        segments,
        speed,
        threshold: c,
        low,
        high,
    })
}

/// Alternating segments from threshold crossings (see the module docs).
fn hysteresis_cuts(speed: &[f64], c: f64, low: f64, high: f64) -> Vec<Segment> {
    let Some(&first) = speed.first() else {
        return Vec::new();
    };
    let mut phase = if first > c {
        Phase::Moving
    } else {
        Phase::Still
    };
    let mut start = 0;
    let mut crossing = 0;
    let mut segments = Vec::new();
    for f in 1..speed.len() {
        let (prev, s) = (speed[f - 1], speed[f]);
        match phase {
            Phase::Still => {
                if s > c && prev <= c {
                    crossing = f;
                }
                if s > high {
                    // `crossing > start` holds: speed was <= c at `start` and rose past it since.
                    let cut = crossing.max(start + 1);
                    segments.push(Segment {
                        start_frame: start,
                        end_frame: cut,
                        phase,
                    });
                    start = cut;
                    phase = Phase::Moving;
                }
            }
            Phase::Moving => {
                if s <= c && prev > c {
                    crossing = f;
                }
                if s < low {
                    let cut = crossing.max(start + 1);
                    segments.push(Segment {
                        start_frame: start,
                        end_frame: cut,
                        phase,
                    });
                    start = cut;
                    phase = Phase::Still;
                }
            }
        }
    }
    segments.push(Segment {
        start_frame: start,
        end_frame: speed.len(),
        phase,
    });
    segments
}

/// Absorbs segments shorter than `min_frames`, shortest first.
fn merge_short(segments: &mut Vec<Segment>, min_frames: usize) {
    while segments.len() > 1 {
        let Some((i, _)) = segments
            .iter()
            .enumerate()
            .filter(|(_, s)| s.len() < min_frames)
            .min_by_key(|(i, s)| (s.len(), *i))
        else {
            break;
        };
        let last = segments.len() - 1;
        if i == 0 {
            segments[1].start_frame = segments[0].start_frame;
            segments.remove(0);
        } else if i == last {
            segments[last - 1].end_frame = segments[last].end_frame;
            segments.pop();
        } else {
            segments[i - 1].end_frame = segments[i + 1].end_frame;
            segments.drain(i..=i + 1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiles(segs: &[Segment], n: usize) -> bool {
        segs.first().is_some_and(|s| s.start_frame == 0)
            && segs.last().is_some_and(|s| s.end_frame == n)
            && segs.windows(2).all(|w| w[0].end_frame == w[1].start_frame)
            && segs.iter().all(|s| !s.is_empty())
            && segs.windows(2).all(|w| w[0].phase != w[1].phase)
    }

    #[test]
    fn cuts_at_threshold_crossings() {
        // Still (1) for 10 frames, moving (10) for 10, still again for 10.
        let speed: Vec<f64> = (0..30)
            .map(|f| if (10..20).contains(&f) { 10.0 } else { 1.0 })
            .collect();
        let params = SegmentParams {
            threshold: Threshold::Absolute(5.0),
            min_segment_s: 0.2,
            ..SegmentParams::default()
        };
        let s = segment_speed(speed, 0.1, &params).unwrap();
        let bounds: Vec<_> = s
            .segments
            .iter()
            .map(|s| (s.start_frame, s.end_frame, s.phase))
            .collect();
        assert_eq!(
            bounds,
            vec![
                (0, 10, Phase::Still),
                (10, 20, Phase::Moving),
                (20, 30, Phase::Still)
            ]
        );
    }

    #[test]
    fn hysteresis_ignores_wobble_and_cut_sits_at_centre_crossing() {
        // Rises slowly through c = 5 at frame 5, confirms above 6.25 at frame 7.
        let speed = vec![
            1.0, 2.0, 3.0, 4.0, 5.0, 5.5, 6.0, 7.0, 8.0, 4.5, 5.2, 8.0, 8.0,
        ];
        let params = SegmentParams {
            threshold: Threshold::Absolute(5.0),
            min_segment_s: 0.2,
            ..SegmentParams::default()
        };
        let s = segment_speed(speed, 0.1, &params).unwrap();
        assert_eq!(s.segments.len(), 2, "{:?}", s.segments);
        assert_eq!(s.segments[0].end_frame, 5);
        assert!(tiles(&s.segments, 13));
    }

    #[test]
    fn merges_short_segments_and_tiles() {
        // Deterministic pseudo-random speed with many short excursions.
        let mut x = 12345u64;
        let speed: Vec<f64> = (0..2000)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                (x % 1000) as f64 / 100.0
            })
            .collect();
        for min_s in [0.0, 0.1, 0.2, 0.5, 3.0, 1000.0] {
            let params = SegmentParams {
                min_segment_s: min_s,
                ..SegmentParams::default()
            };
            let s = segment_speed(moving_average(&speed, 5), 1.0 / 30.0, &params).unwrap();
            assert!(tiles(&s.segments, 2000), "min {min_s}");
            let min_frames = params.min_frames(1.0 / 30.0);
            if s.segments.len() > 1 {
                assert!(s.segments.iter().all(|seg| seg.len() >= min_frames));
            }
        }
    }

    #[test]
    fn degenerate_takes() {
        let p = SegmentParams::default();
        assert!(segment_speed(vec![], 0.1, &p).unwrap().segments.is_empty());
        let one = segment_speed(vec![0.0], 0.1, &p).unwrap();
        assert_eq!(one.segments.len(), 1);
        let flat = segment_speed(vec![0.0; 100], 0.1, &p).unwrap();
        assert_eq!(flat.segments.len(), 1);
        assert_eq!(flat.segments[0].phase, Phase::Still);
        let bad = SegmentParams {
            hysteresis: f64::NAN,
            ..p
        };
        assert!(segment_speed(vec![0.0], 0.1, &bad).is_err());
    }

    #[test]
    fn window_and_min_length_in_frames() {
        let p = SegmentParams::default();
        assert_eq!(p.smoothing_frames(1.0 / 30.0), 5);
        assert_eq!(p.smoothing_frames(0.0333333), 5);
        assert_eq!(p.smoothing_frames(1.0 / 120.0), 21);
        assert_eq!(p.min_frames(1.0 / 30.0), 6);
        assert_eq!(moving_average(&[0.0, 3.0, 6.0], 3), vec![1.5, 3.0, 4.5]);
        assert_eq!(quantile(&[3.0, 1.0, 2.0], 0.5), 2.0);
    }
}
