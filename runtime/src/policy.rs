//! Choosing the next gesture segment at an exit point (docs/method.md "MDP" and "It factorizes").
//!
//! With belief `b` at exit point `e`, each allowed successor `c` costs `S(e, c) + b . U(c)`
//! and continuing the current segment (interruption exits only) costs `b . U_cont(e)`; the
//! cheapest wins. Ties go to continuing, then to the first successor in the list (lists are
//! sorted by segment index), exactly as the trainer's float policy decides, so host and
//! device agree whenever the quantized costs keep the same order.
//!
//! The tables come from a validated blob through [`PolicyTables`]; every index the selector
//! uses was range-checked at load, so nothing here can panic.

/// The policy tables as the selector needs them. Implementations must only be built from
/// validated data: every method is called with indices in range.
pub trait PolicyTables {
    /// Hidden states.
    fn states(&self) -> usize;
    /// Number of exit points.
    fn exit_count(&self) -> usize;
    /// Segment of exit point `e`.
    fn exit_segment(&self, e: usize) -> usize;
    /// Frame of exit point `e`, relative to its segment's start.
    fn exit_frame(&self, e: usize) -> usize;
    /// Whether `e` is its segment's last frame (no continuing).
    fn exit_is_end(&self, e: usize) -> bool;
    /// First exit point of segment `c` (exit points are grouped by segment, in frame order).
    fn first_exit(&self, c: usize) -> usize;
    /// `U(c, s)`.
    fn u(&self, c: usize, s: usize) -> f32;
    /// `U_cont(e, s)` (only read at interruption exits).
    fn u_cont(&self, e: usize, s: usize) -> f32;
    /// Number of allowed successors of exit `e`.
    fn successor_count(&self, e: usize) -> usize;
    /// The `k`-th successor of exit `e`: `(segment, S(e, segment))`.
    fn successor(&self, e: usize, k: usize) -> (usize, f32);
}

/// What to do at an exit point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Choice {
    /// Keep playing the current segment.
    Continue,
    /// Enter this segment at its first frame.
    Enter(usize),
}

/// A decision and what it weighed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decision {
    /// The exit point decided at.
    pub exit: usize,
    /// What was chosen.
    pub choice: Choice,
    /// Its expected cost under the belief.
    pub cost: f32,
    /// Candidates considered (successors plus continuing where allowed).
    pub candidates: usize,
}

fn dot<T: PolicyTables + ?Sized>(t: &T, b: &[f32], f: impl Fn(&T, usize) -> f32) -> f32 {
    let mut acc = 0.0f32;
    for (s, &bs) in b.iter().enumerate().take(t.states()) {
        acc += bs * f(t, s);
    }
    acc
}

/// The cheapest action at exit `e` under belief `b` (which has `t.states()` entries). At an
/// end exit with no successor (a blob whose pruning left none) the choice falls back to
/// entering segment 0, so playback never stalls.
pub fn select<T: PolicyTables + ?Sized>(t: &T, e: usize, b: &[f32]) -> Decision {
    let mut best = Decision {
        exit: e,
        choice: Choice::Continue,
        cost: f32::INFINITY,
        candidates: 0,
    };
    if !t.exit_is_end(e) {
        best.cost = dot(t, b, |t, s| t.u_cont(e, s));
        best.candidates = 1;
    }
    for k in 0..t.successor_count(e) {
        let (c, sc) = t.successor(e, k);
        let v = sc + dot(t, b, |t, s| t.u(c, s));
        best.candidates += 1;
        if v < best.cost {
            best.cost = v;
            best.choice = Choice::Enter(c);
        }
    }
    if t.exit_is_end(e) && best.choice == Choice::Continue {
        best.choice = Choice::Enter(0);
    }
    best
}
