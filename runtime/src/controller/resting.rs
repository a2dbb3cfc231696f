//! A rest held through a pause: played to and fro until the speech returns (see
//! `crate::follow`), and handed over to another rest once it has held for long
//! ([`HOLD_SHARE`]).

use super::rest_entry::{rest_entry, span_ends};
use super::{Controller, ControllerEvent};
use crate::player::{LibraryFrames, PlayerCommand};
use crate::policy::{Penalties, PolicyTables, HOLD_SHARE};
use crate::prosody::arith::Arith;

impl<T: PolicyTables + ?Sized, L: LibraryFrames + ?Sized, A: Arith> Controller<'_, T, L, A> {
    /// After the pose of `tick`, with rest segment `segment` playing while resting: turns at
    /// its last frame, or at a turn hands over to another rest ([`rest_hand_over`]).
    ///
    /// [`rest_hand_over`]: Self::rest_hand_over
    pub(super) fn hold_rest(
        &mut self,
        segment: usize,
        tick: u64,
        sink: &mut impl FnMut(ControllerEvent<'_>),
    ) {
        let (lo, hi) = self.rest_span;
        let (at_end, at_start) = span_ends(self.lib, &self.player, (lo as usize, hi as usize));
        let turning = at_end || at_start;
        if let Some(c) = turning
            .then(|| self.rest_hand_over(segment, tick))
            .flatten()
        {
            self.cut(c, 0, tick, sink);
        } else if at_end || (at_start && self.player.backward()) {
            self.player.turn();
            self.play(PlayerCommand::Turn, sink);
        }
    }

    /// The rest to hand `segment` over to at `tick`, once it has held a rest for
    /// [`HOLD_SHARE`] of the usage window: the one least played in that window (none without
    /// variety costs).
    fn rest_hand_over(&self, segment: usize, tick: u64) -> Option<usize> {
        let v = &self.variety;
        let window = self.ms_ticks(v.usage_ms);
        if v.usage_cost <= 0.0 || window == 0 {
            return None;
        }
        let now = tick.min(u32::MAX as u64) as u32;
        // Held since it was entered or since the rest began, whichever is later.
        let entered = self
            .history
            .recent()
            .filter(|h| h.segment as usize == segment)?;
        let since = entered.tick.max(self.rest_since);
        if (now.saturating_sub(since) as f32) < HOLD_SHARE * window as f32 {
            return None;
        }
        let p = Penalties::new(v, &self.history, now, 0, window);
        self.rest.hand_over(segment, |c| p.usage_of(c))
    }

    /// Where a rest in segment `c` begins ([`rest_entry`] from the pose just shown); the
    /// span it plays to and fro in is kept for [`hold_rest`](Self::hold_rest).
    pub(super) fn begin_rest(&mut self, c: usize) -> usize {
        let n = self.lib.channels().min(self.pose.len());
        let e = rest_entry(self.lib, c, &self.pose[..n]);
        let clip = |f: usize| f.min(u16::MAX as usize) as u16;
        self.rest_span = (clip(e.span.0), clip(e.span.1));
        e.frame
    }
}
