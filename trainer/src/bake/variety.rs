//! The variety lines as constraints on the whole-file plan: no segment over [`SHARE_CAP`] of
//! the run, and at least [`DISTINCT_MIN`] of the library played. The plan's own costs are the
//! live policy's, whose variety costs (recency, usage) only discourage repeats; these two
//! lines are asked of the whole run, which only the whole file can see. They are met by dual
//! ascent, a price per tick played on each segment ([`Prices`]) and the file planned again:
//!
//! - a segment over the cap pays more per tick, in proportion to how far over it is;
//! - while the plan plays fewer distinct segments than asked, each segment it does not play
//!   earns a prize per tick (a negative price), in proportion to the shortfall, so the next
//!   plan reaches for the ones it left out where they cost least.
//!
//! Both are counted over the run: the whole file, or from the end of a lead of silence that
//! is not part of it ([`super::bake_after`]: `eval-motion` delays its runs by up to six
//! seconds to vary where the speech meets the frames, and a plan that counted that silence
//! held its waiting rest against the cap: on a ten-second span, planned within the 14 % cap,
//! one segment played up to 21 % of the ten seconds).
//!
//! A plan cannot play more distinct segments than it enters, so of a short run, or a library
//! larger than its entries, it is asked no more than one segment per entry
//! ([`Played::distinct_target`]): prizes there would only buy entries the speech has no room
//! for. Of the plans made, the one nearest the lines is kept, the share before the distinct
//! count ([`Played::violation`]): the distinct line never costs the share line.

use super::plan::{Act, Planned};

/// The largest share of the run a plan may give one segment: the variety line (15 %) less a
/// margin for the ticks a blend adds.
pub const SHARE_CAP: f32 = 0.14;
/// The smallest share of the library a plan plays: the variety line (half of it).
pub const DISTINCT_MIN: f32 = 0.5;
/// How much a segment's price rises per unit of its share over the cap (relative).
const PRICE_STEP: f32 = 1.0;
/// How much an unplayed segment's prize rises per unit of the distinct shortfall (relative).
const PRIZE_STEP: f32 = 2.0;
/// Plans made while raising prices, for a run of [`BUDGET_TICKS`] ticks or more.
pub const PRICE_ROUNDS: usize = 8;
/// Most plans made for a shorter run.
pub const MAX_PRICE_ROUNDS: usize = 32;
/// The ticks (two minutes at 30 frames per second, one at 60) of the run whose
/// [`PRICE_ROUNDS`] plans set the planning work allowed.
pub const BUDGET_TICKS: u64 = 3600;

/// How many plans the ascent may make for a run of `ticks` ticks: as many as the work of
/// [`PRICE_ROUNDS`] plans of [`BUDGET_TICKS`] ticks allows (a plan's work grows with its ticks), from
/// [`PRICE_ROUNDS`] to [`MAX_PRICE_ROUNDS`]. A short run's ascent, which meets the lines
/// less easily (one long pause is a large share of ten seconds), gets more plans for the same
/// time.
pub fn price_rounds(ticks: u64) -> usize {
    let allowed = PRICE_ROUNDS as u64 * BUDGET_TICKS / ticks.max(1);
    allowed.clamp(PRICE_ROUNDS as u64, MAX_PRICE_ROUNDS as u64) as usize
}

/// What a plan plays over the run: each segment's share of its ticks, and how many segment
/// entries it makes there (the segment playing at the run's start counts as one).
#[derive(Clone, Debug, PartialEq)]
pub struct Played {
    /// Each segment's share of the run's ticks ([`shares`]).
    pub shares: Vec<f32>,
    /// Segment entries in the run, the segment playing at its start included.
    pub entries: usize,
}

impl Played {
    /// What `plan` plays over ticks `from..ticks` (the run, after a lead of `from` ticks) of a
    /// library of `segments` segments.
    pub fn of(plan: &[Planned], from: u64, ticks: u64, segments: usize) -> Self {
        let entered = plan
            .iter()
            .filter(|d| d.tick >= from)
            .filter(|d| matches!(d.act, Act::Enter { .. } | Act::Rest { .. }))
            .count();
        Self {
            shares: shares(plan, from, ticks, segments),
            entries: entered + 1,
        }
    }

    /// The largest share of one segment.
    pub fn largest(&self) -> f32 {
        self.shares.iter().copied().fold(0.0, f32::max)
    }

    /// The share of the library played (segments with any ticks).
    pub fn distinct(&self) -> f32 {
        let n = self.shares.iter().filter(|&&s| s > 0.0).count();
        n as f32 / self.shares.len().max(1) as f32
    }

    /// The share of the library asked of this plan: [`DISTINCT_MIN`], or one segment per
    /// entry when it enters fewer than that.
    pub fn distinct_target(&self) -> f32 {
        DISTINCT_MIN.min(self.entries as f32 / self.shares.len().max(1) as f32)
    }

    /// How far the plan is from the lines: the largest share over the cap, then the distinct
    /// share short of its target (0 and 0 when it meets both). Tuples compare in that order.
    pub fn violation(&self) -> (f32, f32) {
        (
            (self.largest() - SHARE_CAP).max(0.0),
            (self.distinct_target() - self.distinct()).max(0.0),
        )
    }
}

/// The ascent's prices, per segment, in the plan's cost units per mean interval between exit
/// points played (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Prices {
    over: Vec<f32>,
    prize: Vec<f32>,
}

impl Prices {
    /// No prices for `segments` segments.
    pub fn new(segments: usize) -> Self {
        Self {
            over: vec![0.0; segments],
            prize: vec![0.0; segments],
        }
    }

    /// Each segment's price: what it pays for being over the cap less what it earns for being
    /// left out.
    pub fn per_segment(&self) -> Vec<f32> {
        self.over
            .iter()
            .zip(&self.prize)
            .map(|(o, p)| o - p)
            .collect()
    }

    /// Raises the prices after a plan that played `p`.
    pub fn raise(&mut self, p: &Played) {
        for (o, &sh) in self.over.iter_mut().zip(&p.shares) {
            if sh > SHARE_CAP {
                *o += PRICE_STEP * (sh - SHARE_CAP) / SHARE_CAP;
            }
        }
        let (target, distinct) = (p.distinct_target(), p.distinct());
        if distinct < target {
            let step = PRIZE_STEP * (target - distinct) / target;
            for (z, &sh) in self.prize.iter_mut().zip(&p.shares) {
                if sh <= 0.0 {
                    *z += step;
                }
            }
        }
    }
}

/// Each segment's share of ticks `start..ticks` of a plan (a segment plays from the decision
/// that enters it to the next that leaves it; before the first, segment 0).
pub fn shares(plan: &[Planned], start: u64, ticks: u64, segments: usize) -> Vec<f32> {
    let start = start.min(ticks);
    let mut played = vec![0u64; segments];
    let (mut seg, mut from) = (0usize, start);
    for d in plan {
        let next = match d.act {
            Act::Continue { .. } | Act::Hold => continue,
            Act::Enter { segment, .. } | Act::Rest { segment } => segment,
        };
        let at = d.tick.clamp(start, ticks);
        if let Some(p) = played.get_mut(seg) {
            *p += at.saturating_sub(from);
        }
        seg = next;
        from = at;
    }
    if let Some(p) = played.get_mut(seg) {
        *p += ticks.saturating_sub(from);
    }
    let span = (ticks - start).max(1) as f32;
    played.iter().map(|&p| p as f32 / span).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn planned(tick: u64, act: Act) -> Planned {
        Planned {
            tick,
            exit: 0,
            act,
            until: 0,
            candidates: 1,
            cost: 0.0,
        }
    }

    fn enter(tick: u64, segment: usize) -> Planned {
        planned(tick, Act::Enter { segment, rate: 1.0 })
    }

    /// 3600 ticks or more (two minutes at 30 fps): 8 plans; 2400: 12; one minute at 30 fps:
    /// 16; 30 s and less: 32 (the most).
    #[test]
    fn a_short_run_gets_more_plans_for_the_same_work() {
        assert_eq!(price_rounds(3600), 8);
        assert_eq!(price_rounds(7200), 8);
        assert_eq!(price_rounds(2400), 12);
        assert_eq!(price_rounds(1800), 16);
        assert_eq!(price_rounds(900), 32);
        assert_eq!(price_rounds(300), 32);
        assert_eq!(price_rounds(0), 32);
    }

    /// Segment 1 entered at tick 10 and continued at 20, rest segment 2 from 60.
    fn three_segments() -> [Planned; 3] {
        [
            enter(10, 1),
            planned(20, Act::Continue { rate: 0.9 }),
            planned(60, Act::Rest { segment: 2 }),
        ]
    }

    /// Shares of a plan, counted by hand: segment 0 until tick 10, segment 1 (continued at 20)
    /// until 60, segment 2 to the end (100 ticks); three entries, the first segment included.
    #[test]
    fn shares_count_each_segment_from_its_entry_to_the_next() {
        let plan = three_segments();
        assert_eq!(shares(&plan, 0, 100, 3), vec![0.1, 0.5, 0.4]);
        let p = Played::of(&plan, 0, 100, 3);
        assert_eq!(p.entries, 3);
        assert_eq!(p.largest(), 0.5);
        assert_eq!(p.distinct(), 1.0);
    }

    /// The same plan counted from tick 40 (after a lead of 40 ticks; 60 ticks): segment 1 plays
    /// 20 of them, segment 2 the other 40; segment 0, left during the lead, plays none. Two
    /// entries: segment 1, playing at the start, and the rest.
    #[test]
    fn shares_count_from_the_end_of_a_lead() {
        let plan = three_segments();
        let want = [0.0, 20.0 / 60.0, 40.0 / 60.0];
        let got = shares(&plan, 40, 100, 3);
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-6, "{got:?}");
        }
        let p = Played::of(&plan, 40, 100, 3);
        assert_eq!(p.entries, 2);
        assert!((p.distinct() - 2.0 / 3.0).abs() < 1e-6);
        // A start past the end counts nothing (and divides by no zero).
        assert_eq!(shares(&plan, 200, 100, 3), vec![0.0, 0.0, 0.0]);
    }

    /// Ten segments, a plan that enters three of them four times (five entries with the
    /// first): 3 of 10 played against a target of 5 of 10. Entering only twice (three
    /// entries), it is asked for 3 of 10, which it plays.
    #[test]
    fn the_distinct_target_is_half_the_library_or_one_per_entry() {
        let p = Played::of(
            &[enter(10, 1), enter(20, 2), enter(30, 1), enter(40, 2)],
            0,
            100,
            10,
        );
        assert_eq!(p.entries, 5);
        assert!((p.distinct() - 0.3).abs() < 1e-6);
        assert_eq!(p.distinct_target(), 0.5);
        let v = p.violation();
        assert!((v.1 - 0.2).abs() < 1e-6, "{v:?}");
        let short = Played::of(&[enter(10, 1), enter(20, 2)], 0, 100, 10);
        assert!((short.distinct_target() - 0.3).abs() < 1e-6);
        assert_eq!(short.violation().1, 0.0);
    }

    /// Known prices after one plan: segment 0 plays 40 % (over the 14 % cap by 26 points:
    /// it pays 1.0 x 0.26 / 0.14), the plan plays 3 of 10 segments against a target of 5, so
    /// the seven it left out earn 2.0 x 0.2 / 0.5 = 0.8 each; the others pay nothing.
    #[test]
    fn prices_rise_over_the_cap_and_prizes_for_the_segments_left_out() {
        let p = Played {
            shares: vec![0.4, 0.3, 0.3, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            entries: 8,
        };
        let mut prices = Prices::new(10);
        prices.raise(&p);
        let got = prices.per_segment();
        let over0 = 0.26 / 0.14;
        let want = [
            over0,
            (0.3 - 0.14) / 0.14,
            (0.3 - 0.14) / 0.14,
            -0.8,
            -0.8,
            -0.8,
            -0.8,
            -0.8,
            -0.8,
            -0.8,
        ];
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-5, "{got:?}");
        }
        // A plan that meets both lines changes no price.
        let ok = Played {
            shares: vec![0.1; 10],
            entries: 12,
        };
        assert_eq!(ok.violation(), (0.0, 0.0));
        let before = prices.clone();
        prices.raise(&ok);
        assert_eq!(prices, before);
    }

    /// The share line comes first: a plan within the cap but short of distinct segments (8
    /// of 20 at 12.5 % each) is nearer the lines than one over the cap (one at 30 %) that plays
    /// the whole library.
    #[test]
    fn the_share_line_is_weighed_before_the_distinct_line() {
        let mut shares = vec![0.125; 8];
        shares.resize(20, 0.0);
        let within = Played {
            shares,
            entries: 12,
        };
        let mut shares = vec![0.7 / 19.0; 19];
        shares.insert(0, 0.3);
        let over = Played {
            shares,
            entries: 30,
        };
        assert_eq!(within.violation().0, 0.0);
        assert!((within.violation().1 - 0.1).abs() < 1e-6);
        assert!((over.violation().0 - 0.16).abs() < 1e-6);
        assert_eq!(over.violation().1, 0.0);
        assert!(within.violation() < over.violation());
    }
}
