//! `gesture-sim metrics DIR`: the motion-quality figures of a `gesture-sim run` output folder
//! (`motion.bvh`, the played poses on the library's skeleton, and `timeline.json`, the
//! syllables and the segment entries), the same figures `gesture-train eval-motion` gives
//! (`gesture_trainer::evaluate::metrics`). Any device that writes the same two files can be
//! judged this way. With `--mocap`, the hands' speeds are compared with a capture's, as the
//! character shows it (no walking: `gesture_trainer::evaluate::motion::shown_speed_histogram`).

use std::io::Write;
use std::path::{Path, PathBuf};

use gesture_trainer::evaluate::metrics::{measure, Entry, MotionMetrics, Speech, Trace};
use gesture_trainer::evaluate::motion::shown_speed_histogram;
use gesture_trainer::evaluate::table::motion_table;
use gesture_trainer::motion::{read_bvh, EffectorSpec};
use serde::Deserialize;

use crate::error::SimError;

/// The parts of `timeline.json` the figures need.
#[derive(Debug, Deserialize)]
struct TimelineIn {
    format: String,
    version: u32,
    segments: usize,
    steps: Vec<StepIn>,
    entries: Vec<EntryIn>,
}

#[derive(Debug, Deserialize)]
struct StepIn {
    kind: String,
    start_s: f64,
    length_s: f64,
    intensity_db: f64,
}

#[derive(Debug, Deserialize)]
struct EntryIn {
    tick: usize,
    segment: usize,
    cut: bool,
}

fn bad(path: &Path, reason: impl std::fmt::Display) -> SimError {
    SimError::Metrics(format!("{}: {reason}", path.display()))
}

/// The figures of the run in `dir`; `mocap` compares the hands' speeds with a capture.
pub fn run_metrics(dir: &Path, mocap: Option<&Path>) -> Result<MotionMetrics, SimError> {
    let tl_path = dir.join("timeline.json");
    let text = std::fs::read_to_string(&tl_path).map_err(|e| bad(&tl_path, e))?;
    let tl: TimelineIn = serde_json::from_str(&text).map_err(|e| bad(&tl_path, e))?;
    if tl.format != "gesture-sim-timeline" || tl.version < 2 {
        return Err(bad(
            &tl_path,
            format!(
                "a {} version {} timeline has no segment entries: run it again with this \
                 gesture-sim",
                tl.format, tl.version
            ),
        ));
    }
    let bvh = dir.join("motion.bvh");
    let motion = read_bvh(&bvh).map_err(|e| SimError::Metrics(e.to_string()))?;
    let entries: Vec<Entry> = tl
        .entries
        .iter()
        .map(|e| Entry {
            frame: e.tick,
            segment: e.segment,
            cut: e.cut,
        })
        .collect();
    let trace =
        Trace::from_motion(&motion, &EffectorSpec::default(), entries).map_err(|e| bad(&bvh, e))?;
    let speech = Speech {
        onsets: tl
            .steps
            .iter()
            .filter(|s| s.kind == "syllable")
            .map(|s| s.start_s)
            .collect(),
        spans: tl
            .steps
            .iter()
            .map(|s| (s.start_s, s.start_s + s.length_s, s.intensity_db))
            .collect(),
        // No audio read yet: no voice figures.
        active: Vec::new(),
    };
    let reference = match mocap {
        Some(p) => {
            let m = read_bvh(p).map_err(|e| SimError::Metrics(e.to_string()))?;
            Some(shown_speed_histogram(&m, &EffectorSpec::default()).map_err(|e| bad(p, e))?)
        }
        None => None,
    };
    Ok(measure(
        &trace,
        &speech,
        Some(tl.segments),
        reference.as_deref(),
    ))
}

/// `gesture-sim metrics`: prints the table (or JSON) for the run in `dir`.
pub fn run(
    dir: &Path,
    mocap: Option<&PathBuf>,
    json: bool,
    out: &mut impl Write,
) -> Result<(), SimError> {
    let m = run_metrics(dir, mocap.map(PathBuf::as_path))?;
    if json {
        writeln!(out, "{}", serde_json::to_string(&m).unwrap_or_default())?;
        return Ok(());
    }
    for line in motion_table(&[("run", &m)]) {
        writeln!(out, "{line}")?;
    }
    Ok(())
}
