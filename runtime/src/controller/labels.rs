//! Semantic labels in the controller (docs/method.md "Semantic labels"): the label being
//! served and the fixed queue behind it ([`Labels`]), what became of each, and the bookkeeping
//! after every tick. The controller owns one [`Labels`] and asks it whether a label waits for
//! a segment; the policy's tables say which segments carry a label and where their strokes
//! are. Fixed memory (a few bytes and a queue of [`LABEL_QUEUE`]); nothing allocates or
//! panics.

use super::event::{ControllerEvent, LabelOutcome};
use crate::policy::PolicyTables;

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
struct ActiveLabel {
    /// Label index (0-based).
    label: u8,
    /// Tick it became active.
    since: u64,
    /// The segment entered for it and its stroke frame, once entered.
    serving: Option<(usize, usize)>,
}

/// The label being served and those waiting behind it.
#[derive(Clone, Debug, Default)]
pub(super) struct Labels {
    active: Option<ActiveLabel>,
    queue: heapless::Deque<u8, LABEL_QUEUE>,
    /// A label became active and its `Received` event is still to be reported.
    received: bool,
}

impl Labels {
    /// Asks for `label` (0-based) of a blob with `labels` labels at tick `now`: it becomes
    /// active if none is, else it waits (at most [`LABEL_QUEUE`]).
    pub(super) fn push(&mut self, label: usize, labels: usize, now: u64) -> Result<(), LabelError> {
        if label >= labels {
            return Err(LabelError::Unknown {
                label: label.min(u32::MAX as usize) as u32,
                labels: labels.min(u32::MAX as usize) as u32,
            });
        }
        if self.active.is_none() {
            self.activate(label as u8, now);
            Ok(())
        } else {
            self.queue
                .push_back(label as u8)
                .map_err(|_| LabelError::QueueFull)
        }
    }

    /// Drops the label being served and every waiting one.
    pub(super) fn clear(&mut self) {
        self.active = None;
        self.queue.clear();
    }

    /// The label being served (0-based), if any.
    pub(super) fn active(&self) -> Option<usize> {
        self.active.map(|a| a.label as usize)
    }

    /// The active label while it waits for a segment (decisions then come at once and
    /// prefer the segments carrying it).
    pub(super) fn waiting(&self) -> Option<u8> {
        self.active.filter(|a| a.serving.is_none()).map(|a| a.label)
    }

    /// The active label is served by `segment`, just entered, whose stroke is at `stroke`.
    pub(super) fn serve(&mut self, segment: usize, stroke: usize) {
        if let Some(a) = self.active.as_mut() {
            a.serving = Some((segment, stroke));
        }
    }

    fn activate(&mut self, label: u8, now: u64) {
        self.active = Some(ActiveLabel {
            label,
            since: now,
            serving: None,
        });
        self.received = true;
    }

    /// Bookkeeping after a tick that played `frame` of `segment` (`tick`): announces a new
    /// label, serves it with the segment already playing if that carries it before its stroke
    /// (`tables` say which do), reports its stroke or its timeout (`timeout` ticks; 0: never),
    /// and moves on to the next waiting label.
    pub(super) fn after_tick<T: PolicyTables + ?Sized>(
        &mut self,
        tables: &T,
        (tick, segment, frame): (u64, usize, usize),
        timeout: u64,
        sink: &mut impl FnMut(ControllerEvent<'_>),
    ) {
        let Some(mut a) = self.active else {
            return;
        };
        let label = a.label as usize;
        if self.received {
            self.received = false;
            sink(ControllerEvent::Label {
                tick: a.since,
                label,
                outcome: LabelOutcome::Received,
            });
            if tables.label_of(segment) == a.label + 1 {
                if let Some(stroke) = tables.stroke_of(segment).filter(|&s| s >= frame) {
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
        self.active = Some(a);
        if done {
            self.active = None;
            if let Some(next) = self.queue.pop_front() {
                // It is active from the next tick on.
                self.activate(next, tick.saturating_add(1));
            }
        }
    }
}
