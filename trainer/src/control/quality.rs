//! Motion quality of a controller on held-out audio, against references: the online policy
//! (decisions from the causal belief), random selection from the same library, the offline
//! dynamic-programming sequence (posteriors that see the whole utterance), and, where the
//! audio has its own motion capture, the real motion.
//!
//! The online sequence is what the device plays (`crate::evaluate::motion`): the packed
//! blob's bytes through the runtime's device loop, fed the audio's samples, with its decision
//! timing and its detection latencies.
//!
//! Each method yields a frame-by-frame sequence of library frames at the library's rate; its
//! effector positions are the library take's own positions for those frames (the motion the
//! rig would show, before servo limits). Metrics:
//!
//! - **Hellinger distance** between the hand-speed histograms of the method and the real
//!   motion (GENEA numerical evaluation: speeds pooled over both hands, fixed bins 0-250 cm/s in
//!   steps of 10 plus one overflow bin; `H = sqrt(1 - sum sqrt(p q))`);
//! - **mean jerk**: mean magnitude of the third finite difference of effector positions
//!   (units/s^3);
//! - **pose jump at cuts**: mean effector displacement (units) between the last frame before
//!   and the first frame after each cut (a switch other than to the recorded next segment);
//! - **beat alignment** (BEAT's beat consistency): for each syllable onset, `exp(-d^2 / (2
//!   sigma^2))` with `d` the distance to the nearest motion beat (local minimum of mean hand
//!   speed), `sigma = 0.3 s`, averaged over onsets.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::dp::best_sequence;
use super::library::Library;
use super::mdp::{Action, Policy};

/// One played frame: segment and frame within it; `cut` marks the first frame after a cut.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Played {
    /// Segment.
    pub segment: usize,
    /// Frame within the segment.
    pub frame: usize,
    /// Whether a cut happened just before this frame.
    pub cut: bool,
}

/// Metrics of one method.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Metrics {
    /// Hellinger distance of the hand-speed histogram to the real motion (None without it).
    pub hellinger: Option<f64>,
    /// Mean jerk magnitude (units/s^3).
    pub mean_jerk: f64,
    /// Mean pose jump at cuts (units).
    pub jump_at_cuts: f64,
    /// Cuts per second.
    pub cuts_per_s: f64,
    /// Beat consistency with syllable onsets (0-1).
    pub beat_alignment: f64,
}

/// Whether entering `to` from `from` (at its end exit, or at an interruption) is a cut: any
/// switch but to the recorded next segment at the end.
pub fn is_cut(lib: &Library, from: usize, to: usize, at_end: bool) -> bool {
    !(at_end && lib.segments[from].next == Some(to))
}

/// Plays `frames` frames from segment `start`, asking `choose(exit, frame)` at every exit point.
pub fn play(
    lib: &Library,
    frames: usize,
    start: usize,
    mut choose: impl FnMut(usize, usize) -> Action,
) -> Vec<Played> {
    let mut out = Vec::with_capacity(frames);
    let (mut seg, mut f, mut exit) = (start, 0usize, lib.first_exit[start]);
    let mut cut = false;
    for t in 0..frames {
        out.push(Played {
            segment: seg,
            frame: f,
            cut,
        });
        cut = false;
        if f >= lib.exits[exit].frame {
            match choose(exit, t) {
                Action::Continue if !lib.exits[exit].end => {
                    exit += 1;
                    f += 1;
                }
                Action::Continue => {
                    // An end exit cannot continue: restart the segment (never chosen by the
                    // policies here, which always enter at end exits).
                    f = 0;
                    exit = lib.first_exit[seg];
                    cut = true;
                }
                Action::Enter(c) => {
                    cut = is_cut(lib, seg, c, lib.exits[exit].end);
                    seg = c;
                    f = 0;
                    exit = lib.first_exit[c];
                }
            }
        } else {
            f += 1;
        }
    }
    out
}

/// Plays the offline DP plan.
pub fn play_plan(
    lib: &Library,
    frames: usize,
    start: usize,
    plan: &super::dp::Plan,
) -> Vec<Played> {
    let mut k = 0;
    play(lib, frames, start, |exit, t| {
        while k < plan.len() && plan[k].0 < t {
            k += 1;
        }
        match plan.get(k) {
            Some(&(pt, pe, a)) if pt == t && pe == exit => {
                k += 1;
                a
            }
            _ => {
                if lib.exits[exit].end {
                    Action::Enter(lib.segments[lib.exits[exit].segment].next.unwrap_or(0))
                } else {
                    Action::Continue
                }
            }
        }
    })
}

/// Effector positions of a played sequence (frames x effectors).
pub fn positions(lib: &Library, seq: &[Played]) -> Vec<Vec<[f64; 3]>> {
    seq.iter()
        .map(|p| lib.pose(p.segment, p.frame).to_vec())
        .collect()
}

fn speeds(pos: &[Vec<[f64; 3]>], fps: f64) -> Vec<Vec<f64>> {
    pos.windows(2)
        .map(|w| {
            w[0].iter()
                .zip(&w[1])
                .map(|(a, b)| {
                    ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt()
                        * fps
                })
                .collect()
        })
        .collect()
}

fn histogram(sp: &[Vec<f64>]) -> Vec<f64> {
    let mut h = vec![0.0; 26];
    let mut n = 0.0;
    for v in sp.iter().flatten() {
        let b = ((v / 10.0) as usize).min(25);
        h[b] += 1.0;
        n += 1.0;
    }
    h.iter_mut().for_each(|x| *x /= f64::max(n, 1.0));
    h
}

/// Hellinger distance between two normalized histograms.
pub fn hellinger(p: &[f64], q: &[f64]) -> f64 {
    let bc: f64 = p.iter().zip(q).map(|(a, b)| (a * b).sqrt()).sum();
    (1.0 - bc).max(0.0).sqrt()
}

/// Times (s) of motion beats: local minima of the mean effector speed, smoothed over 1/6 s
/// (the segmentation's smoothing) so that single-frame spikes (e.g. a jump at a cut) do not
/// create beats of their own.
pub fn motion_beats(pos: &[Vec<[f64; 3]>], fps: f64) -> Vec<f64> {
    let raw: Vec<f64> = speeds(pos, fps)
        .iter()
        .map(|v| v.iter().sum::<f64>() / v.len().max(1) as f64)
        .collect();
    let half = ((fps / 6.0) as usize / 2).max(1);
    let sp: Vec<f64> = (0..raw.len())
        .map(|i| {
            let (a, b) = (i.saturating_sub(half), (i + half + 1).min(raw.len()));
            raw[a..b].iter().sum::<f64>() / (b - a) as f64
        })
        .collect();
    (1..sp.len().saturating_sub(1))
        .filter(|&i| sp[i] < sp[i - 1] && sp[i] <= sp[i + 1])
        .map(|i| (i as f64 + 0.5) / fps)
        .collect()
}

/// Beat consistency of `onsets` with `beats` (BEAT's definition, sigma in seconds).
pub fn beat_alignment(onsets: &[f64], beats: &[f64], sigma: f64) -> f64 {
    if onsets.is_empty() {
        return 0.0;
    }
    onsets
        .iter()
        .map(|o| {
            let d = beats
                .iter()
                .map(|b| (b - o).abs())
                .fold(f64::INFINITY, f64::min);
            if d.is_finite() {
                (-d * d / (2.0 * sigma * sigma)).exp()
            } else {
                0.0
            }
        })
        .sum::<f64>()
        / onsets.len() as f64
}

/// All metrics of a position sequence with its cut frames.
pub fn metrics(
    pos: &[Vec<[f64; 3]>],
    cuts: &[usize],
    fps: f64,
    onsets: &[f64],
    real: Option<&[Vec<[f64; 3]>]>,
) -> Metrics {
    let sp = speeds(pos, fps);
    let jerk: Vec<f64> = pos
        .windows(4)
        .flat_map(|w| {
            (0..w[0].len()).map(move |k| {
                let j: Vec<f64> = (0..3)
                    .map(|c| {
                        (w[3][k][c] - 3.0 * w[2][k][c] + 3.0 * w[1][k][c] - w[0][k][c])
                            * fps
                            * fps
                            * fps
                    })
                    .collect();
                (j[0] * j[0] + j[1] * j[1] + j[2] * j[2]).sqrt()
            })
        })
        .collect();
    let jumps: Vec<f64> = cuts
        .iter()
        .filter(|&&t| t > 0 && t < pos.len())
        .map(|&t| {
            pos[t - 1]
                .iter()
                .zip(&pos[t])
                .map(|(a, b)| {
                    ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt()
                })
                .sum::<f64>()
                / pos[t].len().max(1) as f64
        })
        .collect();
    Metrics {
        hellinger: real.map(|r| hellinger(&histogram(&sp), &histogram(&speeds(r, fps)))),
        mean_jerk: jerk.iter().sum::<f64>() / jerk.len().max(1) as f64,
        // (+ 0.0: an empty f64 sum is -0.0)
        jump_at_cuts: jumps.iter().sum::<f64>() / jumps.len().max(1) as f64 + 0.0,
        cuts_per_s: cuts.len() as f64 / (pos.len().max(1) as f64 / fps),
        beat_alignment: beat_alignment(onsets, &motion_beats(pos, fps), 0.3),
    }
}

/// The cut frames of a played sequence.
pub fn cut_frames(seq: &[Played]) -> Vec<usize> {
    seq.iter()
        .enumerate()
        .filter(|(_, p)| p.cut)
        .map(|(i, _)| i)
        .collect()
}

/// Random selection: at end exits a uniformly random segment, otherwise continue.
pub fn play_random(lib: &Library, frames: usize, start: usize, seed: u64) -> Vec<Played> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let n = lib.segments.len();
    play(lib, frames, start, |e, _| {
        if lib.exits[e].end {
            Action::Enter(rng.random_range(0..n))
        } else {
            Action::Continue
        }
    })
}

/// The offline reference.
pub fn play_dp(
    lib: &Library,
    policy: &Policy,
    psi: &[Vec<f64>],
    frames: usize,
    start: usize,
    post: &dyn Fn(usize) -> Vec<f64>,
) -> Vec<Played> {
    let first = lib.first_exit[start];
    let (_, plan) = best_sequence(
        lib,
        policy,
        psi,
        frames,
        first,
        lib.exits[first].frame,
        post,
    );
    play_plan(lib, frames, start, &plan)
}
