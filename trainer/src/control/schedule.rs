//! The reference methods' choices, frame by frame: random selection from the library and the
//! offline dynamic-programming sequence (posteriors that see the whole utterance), as
//! sequences of played library frames. The motion-quality evaluation plays them through the
//! runtime's player, as it plays the online controller (`crate::evaluate::motion`).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

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
