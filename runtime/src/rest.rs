//! The library's rest segments: its calmest, where a character that follows the voice rests
//! in a pause (`crate::follow`), and which the player enters at a calmer pace
//! (`crate::player::REST_BLEND`). A module of its own so that both can use it.

use crate::policy::{PolicyTables, REST_EXTRAS};

/// The calmest segments, candidates at every exit point while resting.
pub const REST_SET: usize = 6;

/// The calmest segments of `t` (lowest energy, ties to the lower index), in order of energy:
/// [`REST_SET`], or the calmer half of a smaller library (at least one), so a rest is never
/// any segment at all.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestSet {
    segments: [u16; REST_SET],
    len: usize,
    /// The highest energy among them (-inf when there are none).
    energy: f32,
}

impl RestSet {
    /// No rest segments.
    pub const EMPTY: Self = Self {
        segments: [0; REST_SET],
        len: 0,
        energy: f32::NEG_INFINITY,
    };

    /// The calmest segments of `t` (one pass per slot over the segments).
    pub fn of<T: PolicyTables + ?Sized>(t: &T, segments: usize) -> Self {
        let mut me = Self::EMPTY;
        let n = segments.min(u16::MAX as usize + 1);
        let want = REST_SET.min((n / 2).max(1)).min(n);
        while me.len < want {
            let mut best: Option<(usize, f32)> = None;
            for c in 0..n {
                if me.contains(c) {
                    continue;
                }
                let e = t.energy(c);
                if best.is_none_or(|(_, b)| e < b) {
                    best = Some((c, e));
                }
            }
            let Some((c, e)) = best else { break };
            me.segments[me.len] = c as u16;
            me.len += 1;
            me.energy = e;
        }
        me
    }

    /// The segments.
    pub fn segments(&self) -> &[u16] {
        &self.segments[..self.len]
    }

    /// The calmest [`REST_EXTRAS`] of them: candidates at every exit point while resting.
    pub fn extras(&self) -> &[u16] {
        &self.segments[..self.len.min(REST_EXTRAS)]
    }

    /// The highest energy among them: while speaking, any segment this calm costs as a rest
    /// (-inf when there are none).
    pub fn energy(&self) -> f32 {
        self.energy
    }

    /// The rest to hand over to from `current`: of the others, the one with the least `used`
    /// (its share of the recent frames), the calmer on a tie. `None` when there is no other.
    ///
    /// A rest held through long pauses shifts, now and then, to another of the calmest
    /// postures, as a speaker at rest does, rather than playing one segment to and fro for
    /// as long as the silences last (one segment held through a 9 s pause was 15 % of a
    /// minute).
    pub fn hand_over(&self, current: usize, used: impl Fn(usize) -> f32) -> Option<usize> {
        let mut best: Option<(usize, f32)> = None;
        for &c in self.segments() {
            let c = c as usize;
            if c == current {
                continue;
            }
            let u = used(c);
            if best.is_none_or(|(_, b)| u < b) {
                best = Some((c, u));
            }
        }
        best.map(|(c, _)| c)
    }

    /// Whether `c` is one of them.
    pub fn contains(&self, c: usize) -> bool {
        // An index loop: the boards' code is within a few hundred bytes of its budget.
        let mut k = 0;
        while k < self.len && k < REST_SET {
            if self.segments[k] as usize == c {
                return true;
            }
            k += 1;
        }
        false
    }
}
