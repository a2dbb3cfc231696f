//! `timeline.json`: what the controller heard, believed and chose, in time order.
//!
//! ```text
//! { "format": "gesture-sim-timeline", "version": 3,
//!   "audio": PATH, "blob": PATH, "sample_rate_hz", "fps", "duration_s", "ticks",
//!   "states", "segments", "exit_points", "chunk_s",
//!   "steps": [ { "kind": "syllable" | "pause", "start_s", "end_s", "f0_hz" (null when
//!                unvoiced), "intensity_db", "length_s", "detected_s", "latency_s" (null
//!                when "flushed"), "flushed", "belief": [S numbers] } ],
//!   "decisions": [ { "time_s", "tick", "exit", "exit_segment", "exit_frame",
//!                    "choice": "continue" | "enter", "segment" (entered, or null),
//!                    "candidates", "cost", "style": { NAME: WEIGHT } } ],
//!   "tones": [NAME...], "styles": [ { "time_s", "style": { NAME: WEIGHT } } ],
//!   "labels": [ { "time_s", "label", "source", "segment", "entry_frame", "entered_s",
//!                 "stroke_time_s", "outcome": "stroke" | "timed out" | "pending" |
//!                 "refused (queue full)" } ],
//!   "entries": [ { "tick", "time_s", "segment", "cut" } ],
//!   "latency": { "syllables", "median_s", "max_s" } }
//! ```
//!
//! Times are seconds on the audio's clock. `detected_s` is when the belief update happened:
//! the end of the audio chunk whose processing reported the step (see `run::sim`);
//! `latency_s = detected_s - end_s`; `flushed` steps were closed by the end of the audio and
//! have no latency. `belief` is the CRF forward belief after the step. The `latency` summary
//! is over the syllables that are not flushed. `entries` are the segment entries as shown
//! (a new segment, or one started over): `cut` unless the body moved on from a segment's last
//! frame into its recorded successor; `gesture-sim metrics` reads them with `motion.bvh`.
//! `style` is the style in force at a decision: `neutral` and every tone with a weight above 0
//! (the weights sum to 1); `styles` lists the changes given (`--style`, `--style-track`,
//! `--energy`), the first at time 0; `tones` the blob's tones (empty for a blob without).
//! `labels` are the semantic labels given (`--labels`): `time_s` when the label reached the
//! controller, `segment` the labelled segment entered for it (null if none was), entered at
//! `entry_frame` at `entered_s`, and `stroke_time_s` when its stroke frame played.

use serde::Serialize;

use super::sim::{median_max, Simulation};
use crate::style::describe;
use gesture_runtime::prosody::StepKind;
use gesture_trainer::evaluate::metrics::Entry;

/// The whole file.
#[derive(Debug, Serialize)]
pub struct Timeline<'a> {
    format: &'static str,
    version: u32,
    audio: &'a str,
    blob: &'a str,
    sample_rate_hz: u32,
    fps: f64,
    duration_s: f64,
    ticks: usize,
    states: usize,
    segments: usize,
    exit_points: usize,
    chunk_s: f64,
    steps: Vec<Step>,
    decisions: Vec<Decision>,
    tones: Vec<String>,
    styles: Vec<StyleRecord>,
    labels: Vec<LabelEntry>,
    entries: Vec<EntryRecord>,
    latency: Latency,
}

/// A style as written: name to weight, `neutral` included.
type StyleMap = std::collections::BTreeMap<String, f32>;

#[derive(Debug, Serialize)]
struct LabelEntry {
    time_s: f64,
    label: String,
    source: String,
    segment: Option<usize>,
    entry_frame: Option<usize>,
    entered_s: Option<f64>,
    stroke_time_s: Option<f64>,
    outcome: &'static str,
}

#[derive(Debug, Serialize)]
struct StyleRecord {
    time_s: f64,
    style: StyleMap,
}

/// One segment entry as written.
#[derive(Debug, Serialize, serde::Deserialize, Clone, Copy, PartialEq)]
pub struct EntryRecord {
    /// Animation tick of the segment's first frame shown.
    pub tick: usize,
    /// Its time (s).
    pub time_s: f64,
    /// Library segment.
    pub segment: usize,
    /// Whether it was a cut.
    pub cut: bool,
}

#[derive(Debug, Serialize)]
struct Step {
    kind: &'static str,
    start_s: f64,
    end_s: f64,
    f0_hz: Option<f32>,
    intensity_db: f32,
    length_s: f32,
    detected_s: f64,
    latency_s: Option<f64>,
    flushed: bool,
    belief: Vec<f32>,
}

#[derive(Debug, Serialize)]
struct Decision {
    time_s: f64,
    tick: u64,
    exit: usize,
    exit_segment: usize,
    exit_frame: usize,
    choice: &'static str,
    segment: Option<usize>,
    candidates: usize,
    cost: f32,
    style: StyleMap,
}

#[derive(Debug, Serialize)]
struct Latency {
    syllables: usize,
    median_s: Option<f64>,
    max_s: Option<f64>,
}

/// What the timeline says about the run besides the simulation.
#[derive(Clone, Copy, Debug)]
pub struct Context<'a> {
    /// Audio file as given.
    pub audio: &'a str,
    /// Blob file as given.
    pub blob: &'a str,
    /// Hidden states.
    pub states: usize,
    /// Library segments.
    pub segments: usize,
    /// Exit points.
    pub exit_points: usize,
    /// Chunk length (s).
    pub chunk_s: f64,
    /// Segment entries.
    pub entries: &'a [Entry],
    /// The blob's tone names.
    pub tones: &'a [&'a str],
    /// The blob's label names.
    pub label_names: &'a [&'a str],
}

/// Rounds to 6 decimals so the file stays readable (microsecond times).
fn r6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

impl<'a> Timeline<'a> {
    /// The timeline of `sim`.
    pub fn new(sim: &Simulation, cx: Context<'a>) -> Self {
        let lat = sim.syllable_latencies();
        let mm = median_max(&lat);
        Self {
            format: "gesture-sim-timeline",
            version: 3,
            audio: cx.audio,
            blob: cx.blob,
            sample_rate_hz: sim.sample_rate_hz,
            fps: sim.fps,
            duration_s: r6(sim.duration_s),
            ticks: sim.poses.len(),
            states: cx.states,
            segments: cx.segments,
            exit_points: cx.exit_points,
            chunk_s: r6(cx.chunk_s),
            steps: sim
                .steps
                .iter()
                .map(|s| Step {
                    kind: match s.kind {
                        StepKind::Syllable => "syllable",
                        StepKind::Pause => "pause",
                    },
                    start_s: r6(s.start_s),
                    end_s: r6(s.end_s),
                    f0_hz: s.f0_hz,
                    intensity_db: s.intensity_db,
                    length_s: s.length_s,
                    detected_s: r6(s.detected_s),
                    latency_s: (!s.flushed).then(|| r6(s.latency_s())),
                    flushed: s.flushed,
                    belief: s.belief.clone(),
                })
                .collect(),
            tones: cx.tones.iter().map(|t| t.to_string()).collect(),
            labels: sim
                .labels
                .iter()
                .map(|l| LabelEntry {
                    time_s: r6(l.time_s),
                    label: cx
                        .label_names
                        .get(l.label)
                        .map_or_else(|| l.label.to_string(), |n| n.to_string()),
                    source: l.source.clone(),
                    segment: l.segment.map(|s| s.0),
                    entry_frame: l.segment.map(|s| s.1),
                    entered_s: l.entered_s.map(r6),
                    stroke_time_s: l.stroke_s.map(r6),
                    outcome: if !l.accepted {
                        "refused (queue full)"
                    } else if l.stroke_s.is_some() {
                        "stroke"
                    } else if l.timed_out {
                        "timed out"
                    } else {
                        "pending"
                    },
                })
                .collect(),
            styles: sim
                .styles
                .iter()
                .map(|c| StyleRecord {
                    time_s: r6(c.time_s),
                    style: describe(&c.weights, cx.tones).into_iter().collect(),
                })
                .collect(),
            decisions: sim
                .decisions
                .iter()
                .enumerate()
                .map(|(k, d)| Decision {
                    time_s: r6(d.time_s),
                    tick: d.tick,
                    exit: d.exit,
                    exit_segment: d.exit_segment,
                    exit_frame: d.exit_frame,
                    choice: if d.entered.is_some() {
                        "enter"
                    } else {
                        "continue"
                    },
                    segment: d.entered,
                    candidates: d.candidates,
                    cost: d.cost,
                    style: describe(sim.style_at(k), cx.tones).into_iter().collect(),
                })
                .collect(),
            entries: cx
                .entries
                .iter()
                .map(|e| EntryRecord {
                    tick: e.frame,
                    time_s: r6(e.frame as f64 / sim.fps.max(1e-9)),
                    segment: e.segment,
                    cut: e.cut,
                })
                .collect(),
            latency: Latency {
                syllables: lat.len(),
                median_s: mm.map(|m| r6(m.0)),
                max_s: mm.map(|m| r6(m.1)),
            },
        }
    }

    /// The JSON text (pretty, one field per line).
    pub fn to_json(&self) -> String {
        // Serializing plain structs of numbers and strings cannot fail.
        serde_json::to_string_pretty(self).unwrap_or_default()
    }
}
