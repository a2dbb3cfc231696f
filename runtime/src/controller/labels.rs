//! Semantic labels in the controller (docs/method.md "Semantic labels"): the label being
//! served and the fixed queue behind it, what became of each, and the bookkeeping after every
//! tick. Fixed memory (a few bytes and a queue of [`LABEL_QUEUE`]); nothing allocates or
//! panics.

use super::event::{ControllerEvent, LabelOutcome};
use super::Controller;
use crate::player::LibraryFrames;
use crate::policy::PolicyTables;
use crate::prosody::arith::Arith;

/// Most semantic labels a blob defines.
pub const MAX_LABELS: usize = 16;
/// Most segments of a blob that carry a label.
pub const MAX_LABELLED: usize = 64;
/// Labels that can wait behind the one being served.
pub const LABEL_QUEUE: usize = 4;

/// Why a label was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LabelError {
    /// The blob has no label with this index.
    Unknown {
        /// The index given.
        label: u32,
        /// Labels of the blob.
        labels: u32,
    },
    /// [`LABEL_QUEUE`] labels already wait.
    QueueFull,
}

impl core::fmt::Display for LabelError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::Unknown { label, labels } => {
                write!(f, "label {label} is not one of the blob's {labels} labels")
            }
            Self::QueueFull => write!(f, "{LABEL_QUEUE} labels already wait"),
        }
    }
}

impl core::error::Error for LabelError {}

/// The label being served.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct ActiveLabel {
    /// Label index (0-based).
    pub(super) label: u8,
    /// Tick it became active.
    pub(super) since: u64,
    /// The segment entered for it and its stroke frame, once entered.
    pub(super) serving: Option<(usize, usize)>,
}

impl<T: PolicyTables + ?Sized, L: LibraryFrames + ?Sized, A: Arith> Controller<'_, T, L, A> {
    /// Asks for the semantic label `label` (0-based, the blob's order; docs/method.md
    /// "Semantic labels"): from the next exit point on, the controller prefers the segments
    /// carrying it and may enter one just before its stroke; the label is served once that
    /// stroke plays, or dropped after the blob's timeout. A label that arrives while another
    /// is served waits (at most [`LABEL_QUEUE`]). Reports `Received` through the next call's
    /// events.
    pub fn push_label(&mut self, label: usize) -> Result<(), LabelError> {
        let labels = self.tables.labels();
        if label >= labels {
            return Err(LabelError::Unknown {
                label: label.min(u32::MAX as usize) as u32,
                labels: labels as u32,
            });
        }
        if self.active_label.is_none() {
            self.activate(label as u8);
            Ok(())
        } else {
            self.label_queue
                .push_back(label as u8)
                .map_err(|_| LabelError::QueueFull)
        }
    }

    /// Drops the label being served and every waiting one.
    pub fn clear_labels(&mut self) {
        self.active_label = None;
        self.label_queue.clear();
    }

    /// The label being served (0-based), if any.
    pub fn active_label(&self) -> Option<usize> {
        self.active_label.map(|a| a.label as usize)
    }

    pub(super) fn activate(&mut self, label: u8) {
        self.active_label = Some(ActiveLabel {
            label,
            since: self.ticks,
            serving: None,
        });
        self.label_received = true;
    }

    /// Whether a label waits for a segment (decisions then come at once).
    pub(super) fn label_waiting(&self) -> bool {
        self.active_label.is_some_and(|a| a.serving.is_none())
    }

    /// Label bookkeeping after a tick that played `frame` of `segment` (`tick`): announces a
    /// new label, serves it with the segment already playing if that carries it before its
    /// stroke, reports its stroke or its timeout, and moves on to the next waiting label.
    pub(super) fn labels_after_tick(
        &mut self,
        tick: u64,
        segment: usize,
        frame: usize,
        sink: &mut impl FnMut(ControllerEvent<'_>),
    ) {
        let Some(mut a) = self.active_label else {
            return;
        };
        let label = a.label as usize;
        if self.label_received {
            self.label_received = false;
            sink(ControllerEvent::Label {
                tick: a.since,
                label,
                outcome: LabelOutcome::Received,
            });
            if self.tables.label_of(segment) == a.label + 1 {
                if let Some(stroke) = self.tables.stroke_of(segment).filter(|&s| s >= frame) {
                    a.serving = Some((segment, stroke));
                    sink(ControllerEvent::Label {
                        tick,
                        label,
                        outcome: LabelOutcome::Entered { segment, frame },
                    });
                }
            }
        }
        let done = match a.serving {
            Some((seg, stroke)) if seg == segment && frame >= stroke => {
                sink(ControllerEvent::Label {
                    tick,
                    label,
                    outcome: LabelOutcome::Stroke,
                });
                true
            }
            // The segment was left before its stroke (a cut decided for another reason):
            // the label waits again.
            Some((seg, _)) if seg != segment => {
                a.serving = None;
                false
            }
            Some(_) => false,
            None => {
                let timeout = self.ms_ticks(self.label_timeout_ms) as u64;
                if timeout > 0 && tick.saturating_sub(a.since) >= timeout {
                    sink(ControllerEvent::Label {
                        tick,
                        label,
                        outcome: LabelOutcome::TimedOut,
                    });
                    true
                } else {
                    false
                }
            }
        };
        self.active_label = Some(a);
        if done {
            self.active_label = None;
            if let Some(next) = self.label_queue.pop_front() {
                self.activate(next);
            }
        }
    }
}
