//! The offline reference (docs/method.md "Offline reference"): with the whole utterance known, the
//! best sequence of segments by dynamic programming over time, using the forward-backward
//! state posteriors (which see the future) instead of the online belief.
//!
//! The timeline is in motion frames. From exit point `e` reached at frame `t`, the choices are
//! to continue (interruption exits) to the next exit, paying `w_cont(e) post(t) . psi_a`, or
//! to enter segment `c`, paying `w_enter(c) post(t) . psi_c + S(e, c)` and reaching `c`'s
//! first exit after its frames: the same fit shares as the policy's
//! ([`super::mdp::fit_shares`]), so the reference optimizes what the online policy does. The
//! cost of the sequence is the sum; the DP finds its minimum exactly (states: frame x exit point). It is
//! `O(frames x exits x segments)`: meant for evaluation on small libraries, not for packing.

use super::library::Library;
use super::mdp::{Action, Policy};

/// A chosen sequence: `(frame, exit point, action)` at every decision.
pub type Plan = Vec<(usize, usize, Action)>;

/// Best sequence for an utterance of `frames` motion frames, standing at exit `start` at
/// frame `t0`; `post(t)` is the state posterior at frame `t`.
pub fn best_sequence(
    lib: &Library,
    policy: &Policy,
    psi: &[Vec<f64>],
    frames: usize,
    start: usize,
    t0: usize,
    post: &dyn Fn(usize) -> Vec<f64>,
) -> (f64, Plan) {
    let n_exit = lib.exits.len();
    // cost[t][e]: best cost to stand at exit e at frame t; back pointers for the plan.
    let mut cost = vec![vec![f64::INFINITY; n_exit]; frames + 1];
    let mut back: Vec<Vec<Option<(usize, usize, Action)>>> = vec![vec![None; n_exit]; frames + 1];
    cost[t0.min(frames)][start] = 0.0;
    // Best complete sequence: (cost, frame, exit, final action crossing the end).
    let mut best_end: (f64, usize, usize, Option<Action>) = (f64::INFINITY, 0, start, None);
    for t in 0..=frames {
        let b = post(t.min(frames.saturating_sub(1)));
        for e in 0..n_exit {
            let here = cost[t][e];
            if !here.is_finite() {
                continue;
            }
            let ex = lib.exits[e];
            let mut relax = |t2: usize, e2: usize, v: f64, a: Action| {
                if t2 > frames {
                    if v < best_end.0 {
                        best_end = (v, t, e, Some(a));
                    }
                } else if v < cost[t2][e2] {
                    cost[t2][e2] = v;
                    back[t2][e2] = Some((t, e, a));
                }
            };
            if let Some(n) = lib.next_exit(e) {
                let dt = lib.exits[n].frame - ex.frame;
                let fit: f64 = b.iter().zip(&psi[ex.segment]).map(|(x, y)| x * y).sum();
                relax(
                    t + dt.max(1),
                    n,
                    here + policy.w_cont[e] * fit,
                    Action::Continue,
                );
            }
            for c in 0..lib.segments.len() {
                let fit: f64 =
                    policy.w_enter[c] * b.iter().zip(&psi[c]).map(|(x, y)| x * y).sum::<f64>();
                let v = here + fit + policy.succ[e][c];
                let first = lib.first_exit[c];
                relax(t + lib.exits[first].frame + 1, first, v, Action::Enter(c));
            }
        }
    }
    // A sequence may also end exactly on the last frame.
    for e in 0..n_exit {
        if cost[frames][e] < best_end.0 {
            best_end = (cost[frames][e], frames, e, None);
        }
    }
    let (total, mut t, mut e, last) = best_end;
    let mut plan = Vec::new();
    if let Some(a) = last {
        plan.push((t, e, a));
    }
    while let Some((pt, pe, a)) = back[t][e] {
        plan.push((pt, pe, a));
        t = pt;
        e = pe;
    }
    plan.reverse();
    (total, plan)
}
