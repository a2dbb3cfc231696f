//! Semantic labels (docs/method.md "Semantic labels", the paper's section 8.1): which library
//! segments carry a meaning, where their stroke is, and how the controller may jump into them
//! just before it.
//!
//! **Labelling.** A label names library files by a pattern on their file names (`bye=*_bye_*`:
//! Bandai Namco's clips are named by meaning). A labelled clip is one gesture; its *stroke* is
//! the frame where the hands move fastest (the peak of the smoothed mean effector speed the
//! segmentation uses), unless a label file gives its time. The segment holding the stroke
//! carries the label, with the stroke's frame within it.
//!
//! **Entries before the stroke.** A recognizer knows a word only after it is said, so to land
//! the stroke close to the word the controller may enter a labelled segment not at its first
//! frame but later, at any frame up to the stroke and at most `max_entry_fraction` of the
//! segment (the paper's rule): from each exit point, the frame chosen minimizes the junction
//! distance (pose and velocity of the effectors, as for cuts) weighted like every transition,
//! plus `latency_weight` per second still to play before the stroke. With `stroke_entry` off,
//! the entry is the first frame (the reference the jump is measured against).
//!
//! **Value tables.** While a label waits, every decision that does not serve it costs
//! `semantic_cost`; serving it returns to the neutral policy (`super::mdp::solve_label`). The
//! blob stores one `U^w`, `U_cont^w` pair per label and the entries.

use super::costs::{CostParams, Signatures};
use super::library::Library;

/// Settings of semantic labels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LabelParams {
    /// Cost of a decision that does not serve a waiting label.
    pub semantic_cost: f64,
    /// A label not shown within this long is dropped (ms).
    pub timeout_ms: u32,
    /// Latest entry frame, as a fraction of the segment's length.
    pub max_entry_fraction: f64,
    /// Cost per second between an entry frame and the stroke.
    pub latency_weight: f64,
    /// Allow entries after the first frame (off: first frame only).
    pub stroke_entry: bool,
}

impl Default for LabelParams {
    fn default() -> Self {
        Self {
            semantic_cost: 10.0,
            timeout_ms: 3000,
            max_entry_fraction: 0.5,
            latency_weight: 2.0,
            stroke_entry: true,
        }
    }
}

/// A label and the library files it names.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelSpec {
    /// Label name.
    pub name: String,
    /// Pattern on the library's file names (`*`, `?`, `[...]`).
    pub pattern: String,
    /// The stroke's time in the clip (s), instead of the hands' speed peak.
    pub stroke_s: Option<f64>,
}

/// The library's labels.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Labelling {
    /// Label names (label `w` is stored as `w + 1`).
    pub names: Vec<String>,
    /// Per segment: its label `w + 1`, 0 for none.
    pub label_of: Vec<u8>,
    /// Per segment: its stroke frame (labelled segments only).
    pub stroke: Vec<Option<usize>>,
    /// The labelled segments, increasing.
    pub segments: Vec<usize>,
    /// Per labelled segment: the library file it came from.
    pub sources: Vec<String>,
}

/// The frame in `start..end` where `speed` peaks (the first of equal peaks).
pub fn stroke_frame(speed: &[f64], start: usize, end: usize) -> usize {
    let end = end.min(speed.len());
    (start..end)
        .max_by(|&a, &b| speed[a].total_cmp(&speed[b]).then(b.cmp(&a)))
        .unwrap_or(start)
}

impl Labelling {
    /// Labels the segments of `lib` by `specs` (in order; a file matched by several specs takes
    /// the first). Every pattern must match a file, and a label may not be given twice with
    /// different names for the same file.
    pub fn assign(lib: &Library, specs: &[LabelSpec]) -> Result<Labelling, String> {
        let mut names: Vec<String> = Vec::new();
        for sp in specs {
            if !names.contains(&sp.name) {
                names.push(sp.name.clone());
            }
        }
        if names.len() > gesture_runtime::controller::MAX_LABELS {
            return Err(format!(
                "{} labels, a blob holds at most {}",
                names.len(),
                gesture_runtime::controller::MAX_LABELS
            ));
        }
        let n = lib.segments.len();
        let mut out = Labelling {
            names,
            label_of: vec![0; n],
            stroke: vec![None; n],
            ..Labelling::default()
        };
        let mut matched = vec![false; specs.len()];
        for (t, take) in lib.takes.iter().enumerate() {
            let file = take
                .source
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_default();
            let Some(k) = specs
                .iter()
                .position(|sp| glob::Pattern::new(&sp.pattern).is_ok_and(|p| p.matches(&file)))
            else {
                continue;
            };
            matched[k] = true;
            let sp = &specs[k];
            let frames = take.analysis.speed.len();
            let f = match sp.stroke_s {
                Some(t_s) => ((t_s / take.analysis.frame_time).round().max(0.0) as usize)
                    .min(frames.saturating_sub(1)),
                None => stroke_frame(&take.analysis.speed, 0, frames),
            };
            let Some(c) = lib
                .segments
                .iter()
                .position(|s| s.take == t && s.start <= f && f < s.end)
            else {
                return Err(format!(
                    "{file}: the stroke (frame {f}) is in no motion segment of the clip"
                ));
            };
            let w = out.names.iter().position(|x| *x == sp.name).unwrap_or(0);
            out.label_of[c] = (w + 1) as u8;
            out.stroke[c] = Some(f - lib.segments[c].start);
        }
        if let Some(k) = matched.iter().position(|m| !m) {
            return Err(format!(
                "--label {}={}: matches no library file",
                specs[k].name, specs[k].pattern
            ));
        }
        out.segments = (0..n).filter(|&c| out.label_of[c] != 0).collect();
        if out.segments.len() > gesture_runtime::controller::MAX_LABELLED {
            return Err(format!(
                "{} labelled clips, a blob holds at most {}",
                out.segments.len(),
                gesture_runtime::controller::MAX_LABELLED
            ));
        }
        out.sources = out
            .segments
            .iter()
            .map(|&c| lib.takes[lib.segments[c].take].source.display().to_string())
            .collect();
        Ok(out)
    }

    /// Whether any segment carries a label.
    pub fn is_empty(&self) -> bool {
        self.segments.is_empty()
    }
}

/// The semantic entries: per exit point, per labelled segment (in `lab.segments` order), the
/// entry frame and its cost (see the module docs).
pub fn entries(
    lib: &Library,
    sig: &Signatures,
    cost: &CostParams,
    lab: &Labelling,
    p: &LabelParams,
) -> Vec<Vec<(usize, f64)>> {
    lib.exits
        .iter()
        .map(|ex| {
            lab.segments
                .iter()
                .map(|&c| {
                    let stroke = lab.stroke[c].unwrap_or(0);
                    let len = lib.segments[c].len().max(1);
                    let last = if p.stroke_entry {
                        stroke.min((p.max_entry_fraction * (len - 1) as f64).floor() as usize)
                    } else {
                        0
                    };
                    (0..=last)
                        .map(|g| {
                            let jump = sig.junction_at(lib, ex.segment, ex.frame, c, g);
                            let wait = (stroke - g) as f64 / lib.fps;
                            (g, cost.transition_weight * jump + p.latency_weight * wait)
                        })
                        .min_by(|a, b| a.1.total_cmp(&b.1))
                        .unwrap_or((0, 0.0))
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stroke_is_the_speed_peak() {
        let speed = [0.0, 1.0, 3.0, 2.0, 3.0, 0.5];
        assert_eq!(stroke_frame(&speed, 0, 6), 2, "first of equal peaks");
        assert_eq!(stroke_frame(&speed, 3, 6), 4);
        assert_eq!(stroke_frame(&speed, 5, 99), 5);
        assert_eq!(stroke_frame(&[], 0, 0), 0);
    }
}
