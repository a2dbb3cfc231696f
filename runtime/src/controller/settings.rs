//! The controller's settings: what it decides with (tables, belief), how it follows the
//! voice, varies, styles, serves labels, times its decisions and looks ahead.

use super::{Controller, DecisionTiming, LabelError, Lookahead};
use crate::follow::{rest_segments, Expressive, Voice, VoiceFollow};
use crate::inference::MAX_STATES;
use crate::player::LibraryFrames;
use crate::policy::{PolicyTables, Style, StyleError, Variety};
use crate::prosody::arith::Arith;

impl<'a, T: PolicyTables + ?Sized, L: LibraryFrames + ?Sized, A: Arith> Controller<'a, T, L, A> {
    /// The policy tables the controller decides with (for a blob controller, the blob).
    pub fn tables(&self) -> &'a T {
        self.tables
    }

    /// The current belief (uniform before the first step).
    pub fn belief(&self) -> &[f32] {
        let s = self.tables.states();
        if self.belief.steps() == 0 {
            &self.uniform[..s]
        } else {
            self.belief.probs(s)
        }
    }

    /// Makes every decision use `belief` (one value per state) instead of the CRF's, or the
    /// CRF's again with `None`. The belief still evolves and is reported; only the choice
    /// ignores it. For evaluations (the "belief held at the prior" ablation); a `belief` of
    /// another length is ignored.
    pub fn hold_belief(&mut self, belief: Option<&[f32]>) {
        self.held_belief = belief.filter(|b| b.len() == self.tables.states()).map(|b| {
            let mut h = [0.0; MAX_STATES];
            h[..b.len()].copy_from_slice(b);
            h
        });
    }

    /// Sets how the character follows the voice (the default is the blob's; docs in
    /// [`crate::follow`]).
    pub fn set_follow(&mut self, follow: VoiceFollow) {
        self.follow = follow;
        self.expression = Expressive::of(&follow);
        self.rest = rest_segments(self.tables, self.lib.segment_count(), &follow);
        if self.ticks == 0 {
            // Nobody has spoken yet.
            self.voice = Voice::silent(&follow);
        }
        self.player.set_rest_segments(self.rest);
    }

    /// How the character follows the voice.
    pub fn follow(&self) -> VoiceFollow {
        self.follow
    }

    /// Whether the character rests (the speech has been silent for the blob's `rest_ms`).
    pub fn resting(&self) -> bool {
        self.voice.resting()
    }

    /// Sets how decisions vary (the default is the blob's).
    pub fn set_variety(&mut self, variety: Variety) {
        self.variety = variety;
    }

    /// How decisions vary.
    pub fn variety(&self) -> Variety {
        self.variety
    }

    /// Sets the style: one weight per tone of the tables (in their order; fewer weights leave
    /// the rest at 0), applied from the next decision on. See [`Style::new`] for the rules;
    /// an empty slice is the neutral style. On an error the style in force is kept.
    pub fn set_style(&mut self, weights: &[f32]) -> Result<(), StyleError> {
        if weights.len() > self.tables.tones() {
            return Err(StyleError::TooManyWeights {
                given: weights.len().min(u32::MAX as usize) as u32,
                tones: self.tables.tones() as u32,
            });
        }
        self.style = Style::new(weights)?;
        self.voice_share =
            crate::follow::voice_share(self.tables, self.lib.segment_count(), &self.style);
        Ok(())
    }

    /// The style in force.
    pub fn style(&self) -> &Style {
        &self.style
    }

    /// Asks for the semantic label `label` (0-based, the blob's order; docs/method.md
    /// "Semantic labels"): from the next exit point on, the controller prefers the segments
    /// carrying it and may enter one just before its stroke; the label is served once that
    /// stroke plays, or dropped after the blob's timeout. A label that arrives while another
    /// is served waits (at most [`LABEL_QUEUE`](super::LABEL_QUEUE)). Reports `Received` through the next call's
    /// events.
    pub fn push_label(&mut self, label: usize) -> Result<(), LabelError> {
        self.labels.push(label, self.tables.labels(), self.ticks)
    }

    /// Drops the label being served and every waiting one.
    pub fn clear_labels(&mut self) {
        self.labels.clear();
    }

    /// The label being served (0-based), if any.
    pub fn active_label(&self) -> Option<usize> {
        self.labels.active()
    }

    /// Sets how far ahead of its playback the controller hears the audio ([`Lookahead`]; live
    /// by default). Set it before the first samples: ticks already played stay played.
    pub fn set_lookahead(&mut self, l: Lookahead) {
        self.ahead.set(l, self.rate, self.fps_milli);
    }

    /// How far ahead of its playback the controller hears the audio.
    pub fn lookahead(&self) -> Lookahead {
        self.ahead.settings()
    }

    /// Sets how long a cut blends (ms; a controller from a blob has the blob's, one over
    /// other tables none: hard cuts).
    pub fn set_blend_ms(&mut self, ms: u32) {
        let ticks = self.ms_ticks(ms);
        self.player.set_blend_ticks(ticks);
    }

    /// Sets when decisions happen (the default is [`DecisionTiming::DEFAULT`]).
    pub fn set_timing(&mut self, timing: DecisionTiming) {
        self.timing = timing;
    }

    /// When decisions happen.
    pub fn timing(&self) -> DecisionTiming {
        self.timing
    }
}
