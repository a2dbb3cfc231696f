//! The policy tables as the selector reads them ([`PolicyTables`]): value tables, successor
//! lists and costs, tones, labels and energies of a validated blob.

/// Most semantic labels a blob defines.
pub const MAX_LABELS: usize = 16;
/// Most segments of a blob that carry a label.
pub const MAX_LABELLED: usize = 64;

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
    /// `b . U(c)` over the states (`b` has `states()` entries). The default sums
    /// `b[s] * u(c, s)` in state order; an implementation may read the row at once but must
    /// give the same number.
    fn u_dot(&self, c: usize, b: &[f32]) -> f32 {
        let mut acc = 0.0f32;
        for (s, &bs) in b.iter().enumerate().take(self.states()) {
            acc += bs * self.u(c, s);
        }
        acc
    }
    /// `b . U_cont(e)`, like [`u_dot`](Self::u_dot).
    fn u_cont_dot(&self, e: usize, b: &[f32]) -> f32 {
        let mut acc = 0.0f32;
        for (s, &bs) in b.iter().enumerate().take(self.states()) {
            acc += bs * self.u_cont(e, s);
        }
        acc
    }
    /// `b . U^m(c)`, like [`u_dot`](Self::u_dot).
    fn tone_u_dot(&self, m: usize, c: usize, b: &[f32]) -> f32 {
        let mut acc = 0.0f32;
        for (s, &bs) in b.iter().enumerate().take(self.states()) {
            acc += bs * self.tone_u(m, c, s);
        }
        acc
    }
    /// `b . U_cont^m(e)`, like [`u_dot`](Self::u_dot).
    fn tone_u_cont_dot(&self, m: usize, e: usize, b: &[f32]) -> f32 {
        let mut acc = 0.0f32;
        for (s, &bs) in b.iter().enumerate().take(self.states()) {
            acc += bs * self.tone_u_cont(m, e, s);
        }
        acc
    }
    /// Tones with tables of their own (0: the neutral tables only).
    fn tones(&self) -> usize {
        0
    }
    /// Semantic labels L (0: none; the methods below are then never called).
    fn labels(&self) -> usize {
        0
    }
    /// Segment `c`'s label: `w + 1` for label `w`, 0 for none.
    fn label_of(&self, _c: usize) -> u8 {
        0
    }
    /// Segment `c`'s stroke frame, if it has one.
    fn stroke_of(&self, _c: usize) -> Option<usize> {
        None
    }
    /// Cost added to a candidate that does not carry the waiting label.
    fn semantic_cost(&self) -> f32 {
        0.0
    }
    /// Segments that carry a label.
    fn labelled_count(&self) -> usize {
        0
    }
    /// The `k`-th segment that carries a label.
    fn labelled_segment(&self, _k: usize) -> usize {
        0
    }
    /// `b . U^w(c)`: the cost-to-go of entering `c` while label `w` waits.
    fn label_u_dot(&self, _w: usize, c: usize, b: &[f32]) -> f32 {
        self.u_dot(c, b)
    }
    /// `b . U_cont^w(e)`.
    fn label_u_cont_dot(&self, _w: usize, e: usize, b: &[f32]) -> f32 {
        self.u_cont_dot(e, b)
    }
    /// The entry from exit `e` into the `k`-th labelled segment: `(frame, cost)`.
    fn entry(&self, _e: usize, _k: usize) -> (usize, f32) {
        (0, f32::INFINITY)
    }
    /// Segment `c`'s energy (the log of its hands' mean speed over the library's median; 0:
    /// every segment alike), weighed by the voice ([`crate::follow`]).
    fn energy(&self, _c: usize) -> f32 {
        0.0
    }
    /// `U^m(c, s)` of tone `m < tones()`.
    fn tone_u(&self, _m: usize, c: usize, s: usize) -> f32 {
        self.u(c, s)
    }
    /// `U_cont^m(e, s)` of tone `m < tones()`.
    fn tone_u_cont(&self, _m: usize, e: usize, s: usize) -> f32 {
        self.u_cont(e, s)
    }
}
