//! Choosing the next gesture segment at an exit point (docs/method.md "MDP" and "It
//! factorizes"), with costs for variety.
//!
//! With belief `b` at exit point `e`, each allowed successor `c` costs `S(e, c) + b . U(c)`
//! and continuing the current segment (interruption exits only) costs `b . U_cont(e)`; the
//! cheapest wins. Ties go to continuing, then to the first successor in the list (lists are
//! sorted by segment index), exactly as the trainer's float policy decides, so host and
//! device agree whenever the quantized costs keep the same order.
//!
//! **Variety** (docs/method.md, "Beyond the paper"). The value tables are optimal for the
//! paper's cost, which has no memory: with a small library and a weak belief the pure policy
//! settles on the few segments that are cheapest on average and loops them. Motion-matching
//! practice adds a cost for what was just shown; so does this selector, at selection time, from
//! a fixed-capacity [`History`] of the last [`HISTORY`] segment entries:
//!
//! - **recency**: `recency_cost * (1 - age / recency)` for a candidate entered `age < recency`
//!   ago (a repeat within seconds reads as a loop);
//! - **usage**: `usage_cost * share` where `share` is the candidate's share of the frames
//!   played in the last `usage` window (no segment should dominate the minute).
//!
//! Both are added to the candidates' costs. Continuing the current segment at an interruption
//! exit is charged a quarter of its usage ([`CONTINUE_USAGE_SHARE`]) and no recency: playing on
//! is not a repeat, but a long segment that plays on at every interruption exit is what comes
//! to dominate the minute (on the 9-joint ZeroEGGS library a 9-second segment took a third of
//! 50 s of new speech). Only a quarter, because leaving a segment that has played long is a cut
//! in the middle of its motion, which waits for a pause of its hands that may be far from calm:
//! charged in full, a usage cost high enough to spread the entries over half the library also
//! raised the hands' speed at cuts above random choices'. Once a segment has filled more than
//! [`HOLD_SHARE`] of what the run has played, though (the variety line, no segment over 15 % of
//! a run, less a margin), continuing it pays its whole usage, so it gives way before it breaks
//! the line. A run younger than half the usage window counts as half of it: one gesture of
//! ordinary length is never over the line, only a segment that comes back or plays on long.
//! Under a style that leans calm the usage cost falls to half ([`Variety::under_style`]): a
//! calm tone asks for fewer segments, and spreading it over the library took its effect away.
//! The value tables are unchanged, so with [`Variety::NONE`] the choice is the paper's. The
//! cost of variety against the pure policy (its regret) is measured by `gesture-train
//! eval-motion`. All arithmetic is on integer ticks and the same `f32` operations on host and
//! device, so both choose alike.
//!
//! **Style** (docs/method.md "Style control", the paper's section 8.2). A blob may carry value
//! tables per tone (`U^m`, `U_cont^m`, solved by the trainer with each tone's transform of the
//! kinematic parameters) beside the neutral ones. A [`Style`] holds the user's weights `d`;
//! the selector uses `U = d_0 U + sum_m d_m U^m` (and likewise `U_cont`), `d_0 = 1 - sum d_m`
//! the neutral weight, computed per candidate as `d_0 (b . U) + sum_m d_m (b . U^m)` from the
//! stored tables, so no mixed copy is kept in RAM. The neutral style reads the neutral tables alone, exactly as a blob without tones.
//!
//! **The voice** ([`crate::follow`]). [`Penalties::set_voice`] adds an energy weight per
//! decision (`w * energy(c)` for every candidate, continuing included) and the rest segments:
//! while resting they are candidates at every exit point beside its successors (at the
//! exit's largest successor cost), while speaking each costs a flat penalty more.
//!
//! The tables come from a validated blob through [`PolicyTables`]; every index the selector
//! uses was range-checked at load, so nothing here can panic.

mod style;
mod tables;
mod timing;

pub use style::{Style, StyleError, MAX_TONES};
pub use tables::{PolicyTables, MAX_LABELLED, MAX_LABELS};
pub use timing::DecisionTiming;

use heapless::HistoryBuffer;

/// Most rest segments ([`crate::follow::RestSet`]) a decision adds as candidates while
/// resting (each candidate costs a dot product per value table mixed: six under a three-tone
/// style took the worst decision past 50 k instructions on a Cortex-M4F).
pub const REST_EXTRAS: usize = 3;

/// The most of the variety costs' usage window (`usage_ms`) one segment may fill: the variety
/// line (no segment over 15 % of a run) less a margin for the blend; 6.3 s of the default
/// 45 s. A rest that holds a pause this long hands over to another
/// (`crate::rest::RestSet::hand_over`), and past this share of what a run has played,
/// continuing any segment pays its whole usage ([`Penalties::continuing`]).
pub const HOLD_SHARE: f32 = 0.14;

/// What to do at an exit point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Choice {
    /// Keep playing the current segment.
    Continue,
    /// Enter this segment (at [`Decision::entry_frame`]: its first frame, or for a semantic
    /// entry a frame before its stroke).
    Enter(usize),
}

/// A decision and what it weighed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decision {
    /// The exit point decided at.
    pub exit: usize,
    /// What was chosen.
    pub choice: Choice,
    /// Its expected cost under the belief, variety costs included.
    pub cost: f32,
    /// Candidates considered (successors plus continuing where allowed).
    pub candidates: usize,
    /// The frame an entered segment starts at (0 but for semantic entries).
    pub entry_frame: usize,
}

/// Variety costs (see the module docs); all zero: the paper's decision rule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Variety {
    /// Cost of a candidate entered just now (cost units), falling linearly to 0 at
    /// `recency_ms`.
    pub recency_cost: f32,
    /// Recency window (ms).
    pub recency_ms: u32,
    /// Cost per unit of a candidate's share of the frames played in the last `usage_ms`.
    pub usage_cost: f32,
    /// Usage window (ms).
    pub usage_ms: u32,
}

impl Variety {
    /// These costs under a style whose voice share is `share` ([`crate::follow::voice_share`]:
    /// 1 for the neutral style and tones that lean energetic, 0 for calm ones): the usage cost
    /// scaled by `TONE_USAGE_FLOOR + (1 - TONE_USAGE_FLOOR) * share`. A calm tone favours
    /// fewer segments; the full usage cost spread it back over the library and took away a
    /// third of its effect (see the module docs).
    pub fn under_style(&self, share: f32) -> Self {
        let share = if share.is_finite() {
            share.clamp(0.0, 1.0)
        } else {
            1.0
        };
        Self {
            usage_cost: self.usage_cost * (TONE_USAGE_FLOOR + (1.0 - TONE_USAGE_FLOOR) * share),
            ..*self
        }
    }

    /// No variety costs: the pure policy.
    pub const NONE: Self = Self {
        recency_cost: 0.0,
        recency_ms: 0,
        usage_cost: 0.0,
        usage_ms: 0,
    };
}

/// The share of the usage cost a style of calm tones keeps ([`Variety::under_style`]).
pub const TONE_USAGE_FLOOR: f32 = 0.5;

/// Segment entries the controller remembers.
pub const HISTORY: usize = 32;

/// One segment entry: the segment and the tick it was entered at.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Visit {
    /// Segment entered.
    pub segment: u16,
    /// Animation tick of the entry.
    pub tick: u32,
}

/// The last [`HISTORY`] segment entries, oldest first (fixed memory).
pub type History = HistoryBuffer<Visit, HISTORY>;

/// The variety cost of every recently visited segment at one decision, computed once from the
/// history (at most [`HISTORY`] distinct segments; any other segment costs nothing).
#[derive(Clone, Copy, Debug)]
pub struct Penalties {
    segment: [u16; HISTORY],
    cost: [f32; HISTORY],
    usage: [f32; HISTORY],
    /// The usage of a segment that has filled [`HOLD_SHARE`] of what the run has played (its
    /// age, at least half and at most the whole usage window): continuing a segment with more
    /// pays its whole usage.
    line: f32,
    len: usize,
    /// Cost per unit of a candidate's energy ([`crate::follow`]).
    energy_weight: f32,
    /// The rest segments ([`crate::follow::RestSet`]).
    rest: [u16; REST_EXTRAS],
    rest_len: usize,
    /// Whether the rest segments are candidates beside the exit's successors (resting).
    rest_extra: bool,
    /// Cost added to a rest segment as a candidate (speaking).
    rest_penalty: f32,
    /// The rest set's highest energy: a candidate this calm is a rest (speaking).
    rest_energy: f32,
}

impl Penalties {
    /// No penalties.
    pub const NONE: Self = Self {
        segment: [0; HISTORY],
        cost: [0.0; HISTORY],
        usage: [0.0; HISTORY],
        line: f32::INFINITY,
        len: 0,
        energy_weight: 0.0,
        rest: [0; REST_EXTRAS],
        rest_len: 0,
        rest_extra: false,
        rest_penalty: 0.0,
        rest_energy: f32::NEG_INFINITY,
    };

    /// Charges every candidate `weight` times its energy (continuing
    /// too) and the rest segments `rest` (at most [`REST_EXTRAS`]) treated as the voice asks
    /// ([`crate::follow`]): `resting`, they are candidates at every exit point beside its
    /// successors, at the largest successor cost of that exit; speaking, every candidate as
    /// calm as the calmest of them (energy at most `rest_energy`) costs `rest_penalty` more
    /// (continuing included).
    pub fn set_voice(
        &mut self,
        weight: f32,
        rest: &[u16],
        rest_energy: f32,
        resting: bool,
        rest_penalty: f32,
    ) {
        self.energy_weight = if weight.is_finite() { weight } else { 0.0 };
        let n = rest.len().min(REST_EXTRAS);
        self.rest[..n].copy_from_slice(&rest[..n]);
        self.rest_len = n;
        self.rest_extra = resting;
        let speaking = !resting && rest_penalty.is_finite() && rest_penalty != 0.0;
        self.rest_penalty = if speaking { rest_penalty } else { 0.0 };
        self.rest_energy = if speaking && !rest_energy.is_nan() {
            rest_energy
        } else {
            f32::NEG_INFINITY
        };
    }

    /// The voice's cost of segment `c`: its energy term, and the rest penalty if it is as calm
    /// as a rest (one read of its energy).
    #[inline]
    fn voice<T: PolicyTables + ?Sized>(&self, t: &T, c: usize) -> f32 {
        if self.energy_weight == 0.0 && self.rest_penalty == 0.0 {
            return 0.0;
        }
        let e = t.energy(c);
        let rest = if e <= self.rest_energy {
            self.rest_penalty
        } else {
            0.0
        };
        self.energy_weight * e + rest
    }

    /// The penalties at tick `now` given `history` and the windows in ticks (`recency_ticks`,
    /// `usage_ticks`; 0 disables a term).
    pub fn new(
        v: &Variety,
        history: &History,
        now: u32,
        recency_ticks: u32,
        usage_ticks: u32,
    ) -> Self {
        let mut p = Self::NONE;
        if v.recency_cost <= 0.0 && v.usage_cost <= 0.0 {
            return p;
        }
        let window_start = now.saturating_sub(usage_ticks);
        if usage_ticks > 0 {
            let span = now.clamp(usage_ticks / 2, usage_ticks);
            p.line = v.usage_cost * HOLD_SHARE * span as f32 / usage_ticks as f32;
        }
        // Newest first: the first visit of a segment met is its latest entry.
        let mut end = now;
        let (older, newer) = history.as_slices();
        for visit in newer.iter().rev().chain(older.iter().rev()) {
            let k = match p.segment[..p.len].iter().position(|&s| s == visit.segment) {
                Some(k) => k,
                None => {
                    if p.len == HISTORY {
                        break;
                    }
                    p.segment[p.len] = visit.segment;
                    p.cost[p.len] = 0.0;
                    p.usage[p.len] = 0.0;
                    p.len += 1;
                    let k = p.len - 1;
                    let age = now.saturating_sub(visit.tick);
                    if recency_ticks > 0 && age < recency_ticks {
                        let left = 1.0 - age as f32 / recency_ticks as f32;
                        p.cost[k] += v.recency_cost * left;
                    }
                    k
                }
            };
            if usage_ticks > 0 && end > window_start {
                let played = end - visit.tick.max(window_start);
                let u = v.usage_cost * played as f32 / usage_ticks as f32;
                p.cost[k] += u;
                p.usage[k] += u;
            }
            end = visit.tick;
            if end <= window_start && visit.tick.saturating_add(recency_ticks) <= now {
                // Older visits can no longer add anything.
                break;
            }
        }
        p
    }

    /// Where segment `c` sits among the visited segments.
    fn slot(&self, c: usize) -> Option<usize> {
        self.segment[..self.len]
            .iter()
            .position(|&s| s as usize == c)
    }

    /// The penalty of segment `c`.
    pub fn of(&self, c: usize) -> f32 {
        self.slot(c).map_or(0.0, |k| self.cost[k])
    }

    /// The usage part of the penalty of segment `c`.
    pub fn usage_of(&self, c: usize) -> f32 {
        self.slot(c).map_or(0.0, |k| self.usage[k])
    }

    /// What continuing (or holding) segment `c` is charged: [`CONTINUE_USAGE_SHARE`] of its
    /// usage, or all of it once `c` has filled more than [`HOLD_SHARE`] of what the run has
    /// played (see the module docs).
    pub fn continuing(&self, c: usize) -> f32 {
        let u = self.usage_of(c);
        if u > self.line {
            u
        } else {
            CONTINUE_USAGE_SHARE * u
        }
    }
}

/// The share of a segment's usage cost that continuing it pays while it is under the variety
/// line ([`HOLD_SHARE`]; see the module docs): with the default usage cost of 24 it pays at
/// most 6 of a whole window (12 when it paid the whole of a usage cost of 12).
pub const CONTINUE_USAGE_SHARE: f32 = 0.25;

/// The cheapest action at exit `e` under belief `b` (which has `t.states()` entries), each
/// candidate segment `c` charged `penalty.of(c)` on top and continuing charged
/// `penalty.continuing(..)` of the exit's segment. At an end exit with no successor (a
/// blob whose pruning left none) the choice falls back to entering segment 0, so playback
/// never stalls.
pub fn select<T: PolicyTables + ?Sized>(
    t: &T,
    e: usize,
    b: &[f32],
    penalty: &Penalties,
) -> Decision {
    select_styled(t, e, b, penalty, &Style::NEUTRAL)
}

/// [`select`] with the value tables mixed by `style` (see the module docs); a style with more
/// weights than `t` has tones reads only the first `t.tones()`.
pub fn select_styled<T: PolicyTables + ?Sized>(
    t: &T,
    e: usize,
    b: &[f32],
    penalty: &Penalties,
    style: &Style,
) -> Decision {
    let mut best = Decision {
        exit: e,
        choice: Choice::Continue,
        cost: f32::INFINITY,
        candidates: 0,
        entry_frame: 0,
    };
    if !t.exit_is_end(e) {
        let a = t.exit_segment(e);
        best.cost = style.u_cont_dot(t, e, b) + penalty.continuing(a) + penalty.voice(t, a);
        best.candidates = 1;
    }
    let mut worst_junction = 0.0f32;
    for k in 0..t.successor_count(e) {
        let (c, sc) = t.successor(e, k);
        if penalty.rest_extra {
            worst_junction = worst_junction.max(sc);
        }
        let v = sc + style.u_dot(t, c, b) + penalty.of(c) + penalty.voice(t, c);
        best.candidates += 1;
        if v < best.cost {
            best.cost = v;
            best.choice = Choice::Enter(c);
        }
    }
    let extra = if penalty.rest_extra {
        &penalty.rest[..penalty.rest_len]
    } else {
        &[]
    };
    for &c in extra {
        let c = c as usize;
        let v = worst_junction + style.u_dot(t, c, b) + penalty.of(c) + penalty.voice(t, c);
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

/// [`select`] while label `w` (0-based) waits to be shown (docs/method.md "Semantic labels"):
/// the value tables are the label's (`U^w`, `U_cont^w`: the cost-to-go while it waits, solved
/// for the neutral tone, so no style applies), a candidate that does not carry `w` costs
/// `t.semantic_cost()` more (continuing included), and every segment carrying `w` is also a
/// candidate entered at its entry frame before the stroke, at the entry's cost plus its
/// neutral `U` (the label is served from then on). Ties go as in [`select`], semantic entries
/// last.
pub fn select_labelled<T: PolicyTables + ?Sized>(
    t: &T,
    e: usize,
    b: &[f32],
    penalty: &Penalties,
    w: usize,
) -> Decision {
    let code = (w + 1).min(u8::MAX as usize) as u8;
    let sem = t.semantic_cost();
    let other = |c: usize| if t.label_of(c) == code { 0.0 } else { sem };
    let mut best = Decision {
        exit: e,
        choice: Choice::Continue,
        cost: f32::INFINITY,
        candidates: 0,
        entry_frame: 0,
    };
    if !t.exit_is_end(e) {
        let a = t.exit_segment(e);
        best.cost = t.label_u_cont_dot(w, e, b) + penalty.continuing(a) + other(a);
        best.candidates = 1;
    }
    for k in 0..t.successor_count(e) {
        let (c, sc) = t.successor(e, k);
        let v = sc + t.label_u_dot(w, c, b) + penalty.of(c) + other(c);
        best.candidates += 1;
        if v < best.cost {
            best.cost = v;
            best.choice = Choice::Enter(c);
        }
    }
    for k in 0..t.labelled_count() {
        let c = t.labelled_segment(k);
        if t.label_of(c) != code {
            continue;
        }
        let (frame, ec) = t.entry(e, k);
        let v = ec + t.u_dot(c, b) + penalty.of(c);
        best.candidates += 1;
        if v < best.cost {
            best.cost = v;
            best.choice = Choice::Enter(c);
            best.entry_frame = frame;
        }
    }
    if t.exit_is_end(e) && best.choice == Choice::Continue {
        best.choice = Choice::Enter(0);
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn history(visits: &[(u16, u32)]) -> History {
        let mut h = History::new();
        for &(segment, tick) in visits {
            h.write(Visit { segment, tick });
        }
        h
    }

    #[test]
    fn recency_falls_linearly_and_usage_counts_frames_in_the_window() {
        let v = Variety {
            recency_cost: 2.0,
            recency_ms: 0,
            usage_cost: 10.0,
            usage_ms: 0,
        };
        // Segment 3 entered at tick 0, segment 5 at 60, segment 3 again at 80; now 100.
        let h = history(&[(3, 0), (5, 60), (3, 80)]);
        let p = Penalties::new(&v, &h, 100, 50, 100);
        // Recency of 3: age 20 of 50 -> 2 * 0.6; usage: 60 + 20 frames of 100.
        assert!((p.of(3) - (1.2 + 10.0 * 0.8)).abs() < 1e-5, "{}", p.of(3));
        // 5: age 40 -> 2 * 0.2; 20 frames.
        assert!((p.of(5) - (0.4 + 10.0 * 0.2)).abs() < 1e-5, "{}", p.of(5));
        assert_eq!(p.of(7), 0.0);
        // A usage window of 30 ticks: only 3 (ticks 80..100) and 5 (70..80) count.
        let p = Penalties::new(&v, &h, 100, 0, 30);
        assert!((p.of(3) - 10.0 * 20.0 / 30.0).abs() < 1e-5);
        assert!((p.of(5) - 10.0 * 10.0 / 30.0).abs() < 1e-5);
    }

    #[test]
    fn a_calm_style_keeps_half_the_usage_cost() {
        let v = Variety {
            recency_cost: 2.0,
            recency_ms: 8000,
            usage_cost: 24.0,
            usage_ms: 45000,
        };
        assert_eq!(v.under_style(1.0), v);
        assert_eq!(v.under_style(f32::NAN), v);
        let calm = v.under_style(0.0);
        assert_eq!((calm.usage_cost, calm.recency_cost), (12.0, 2.0));
        assert_eq!(v.under_style(0.5).usage_cost, 18.0);
        assert_eq!(v.under_style(-3.0).usage_cost, 12.0);
    }

    #[test]
    fn no_variety_is_no_penalty() {
        let h = history(&[(1, 0), (1, 5)]);
        let p = Penalties::new(&Variety::NONE, &h, 10, 100, 100);
        assert_eq!(p.of(1), 0.0);
    }

    struct Two;
    impl PolicyTables for Two {
        fn states(&self) -> usize {
            1
        }
        fn exit_count(&self) -> usize {
            1
        }
        fn exit_segment(&self, _: usize) -> usize {
            0
        }
        fn exit_frame(&self, _: usize) -> usize {
            0
        }
        fn exit_is_end(&self, _: usize) -> bool {
            true
        }
        fn first_exit(&self, _: usize) -> usize {
            0
        }
        fn u(&self, c: usize, _: usize) -> f32 {
            [1.0, 1.5][c]
        }
        fn u_cont(&self, _: usize, _: usize) -> f32 {
            0.0
        }
        fn successor_count(&self, _: usize) -> usize {
            2
        }
        fn successor(&self, _: usize, k: usize) -> (usize, f32) {
            (k, 0.0)
        }
    }

    #[test]
    fn a_recent_segment_gives_way_to_the_next_best() {
        assert_eq!(
            select(&Two, 0, &[1.0], &Penalties::NONE).choice,
            Choice::Enter(0)
        );
        let v = Variety {
            recency_cost: 1.0,
            recency_ms: 0,
            usage_cost: 0.0,
            usage_ms: 0,
        };
        let p = Penalties::new(&v, &history(&[(0, 95)]), 100, 50, 0);
        // Segment 0 costs 1 + 0.9 > 1.5.
        let d = select(&Two, 0, &[1.0], &p);
        assert_eq!(d.choice, Choice::Enter(1));
        assert_eq!(d.cost, 1.5);
    }

    /// Segment 0 at an interruption exit: continuing costs 1.0, entering segment 1 costs 1.5.
    struct Playing;
    impl PolicyTables for Playing {
        fn states(&self) -> usize {
            1
        }
        fn exit_count(&self) -> usize {
            2
        }
        fn exit_segment(&self, _: usize) -> usize {
            0
        }
        fn exit_frame(&self, e: usize) -> usize {
            10 * e
        }
        fn exit_is_end(&self, e: usize) -> bool {
            e == 1
        }
        fn first_exit(&self, _: usize) -> usize {
            0
        }
        fn u(&self, _: usize, _: usize) -> f32 {
            1.5
        }
        fn u_cont(&self, _: usize, _: usize) -> f32 {
            1.0
        }
        fn successor_count(&self, _: usize) -> usize {
            1
        }
        fn successor(&self, _: usize, _: usize) -> (usize, f32) {
            (1, 0.0)
        }
    }

    /// Continuing is charged a quarter of the playing segment's usage, not its recency: just
    /// entered, it plays on; after dominating the usage window it gives way, later than an
    /// entry of it would.
    #[test]
    fn continuing_pays_a_quarter_of_the_usage_but_no_recency() {
        let v = |usage_cost| Variety {
            recency_cost: 5.0,
            recency_ms: 0,
            usage_cost,
            usage_ms: 0,
        };
        // Entered 5 ticks ago: recency 5 * 0.95, usage 4 * 5/100, continuing a quarter of it.
        let p = Penalties::new(&v(4.0), &history(&[(0, 95)]), 100, 100, 100);
        assert!((p.usage_of(0) - 0.2).abs() < 1e-6);
        assert!((p.continuing(0) - 0.05).abs() < 1e-6);
        let d = select(&Playing, 0, &[1.0], &p);
        assert_eq!(d.choice, Choice::Continue);
        assert!((d.cost - 1.05).abs() < 1e-6, "{}", d.cost);
        // Played 12 of the 100-tick window (under the line, 14) at a usage cost of 10:
        // continuing costs 1 + 1.2 / 4 = 1.3 < 1.5 and plays on.
        let p = Penalties::new(&v(10.0), &history(&[(0, 88)]), 100, 100, 100);
        let d = select(&Playing, 0, &[1.0], &p);
        assert_eq!(d.choice, Choice::Continue);
        assert!((d.cost - 1.3).abs() < 1e-6, "{}", d.cost);
    }

    /// A segment that has filled more than [`HOLD_SHARE`] of what the run has played pays its
    /// whole usage for continuing: it gives way before it breaks the variety line. A young run
    /// counts as half the usage window, so one gesture of ordinary length is never over it.
    #[test]
    fn continuing_over_the_variety_line_pays_the_whole_usage() {
        let v = Variety {
            recency_cost: 0.0,
            recency_ms: 0,
            usage_cost: 10.0,
            usage_ms: 0,
        };
        // 16 of 100 ticks (over 14): continuing pays all of 1.6, 1 + 1.6 > 1.5, and it leaves
        // (a quarter, 1.4, would have played on).
        let p = Penalties::new(&v, &history(&[(0, 84)]), 100, 100, 100);
        assert!((p.continuing(0) - 1.6).abs() < 1e-6, "{}", p.continuing(0));
        assert_eq!(select(&Playing, 0, &[1.0], &p).choice, Choice::Enter(1));
        // Two plays of 8 ticks add up the same way.
        let p = Penalties::new(&v, &history(&[(0, 60), (1, 68), (0, 92)]), 100, 100, 100);
        assert!((p.continuing(0) - 1.6).abs() < 1e-6, "{}", p.continuing(0));
        // A run 30 ticks old is measured as 50 (half the window): the line is 7 ticks. Six
        // ticks (a fifth of the run) pay a quarter, eight the whole.
        let p = Penalties::new(&v, &history(&[(0, 24)]), 30, 100, 100);
        assert!((p.continuing(0) - 0.15).abs() < 1e-6, "{}", p.continuing(0));
        let p = Penalties::new(&v, &history(&[(0, 22)]), 30, 100, 100);
        assert!((p.continuing(0) - 0.8).abs() < 1e-6, "{}", p.continuing(0));
        // The whole window played: the whole usage cost.
        let p = Penalties::new(&v, &history(&[(0, 0)]), 100, 100, 100);
        assert!((p.continuing(0) - 10.0).abs() < 1e-6, "{}", p.continuing(0));
    }
}
