//! `gesture-sim metrics DIR`: the motion-quality figures of a `gesture-sim run` output folder
//! (`motion.bvh`, the played poses on the library's skeleton, and `timeline.json`, the
//! syllables and the segment entries), the same figures `gesture-train eval-motion` gives
//! (`gesture_trainer::evaluate::metrics`). Any device that writes the same two files can be
//! judged this way. With `--mocap`, the hands' speeds are compared with a capture's, as the
//! character shows it (no walking: `gesture_trainer::evaluate::reference::shown_speed_histogram`).
//!
//! The voice figures (`gesture_trainer::evaluate::voice`) need the speech's samples: the
//! run's `speech.wav` when the folder has one (`run --blender` writes it), else the audio file
//! the timeline names (`"audio"`, as it was given to `run`: relative to where `run` ran, or to
//! the folder), read at the timeline's sample rate. When neither can be read the four figures
//! are `None` ("-" in the table, with a note saying why); nothing stands in for the audio.

use std::io::Write;
use std::path::{Path, PathBuf};

use gesture_trainer::audio::load_wav_at;
use gesture_trainer::evaluate::metrics::{measure, Entry, MotionMetrics, Speech, Trace};
use gesture_trainer::evaluate::reference::shown_speed_histogram;
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
    /// The audio file given to `run`.
    #[serde(default)]
    audio: Option<String>,
    /// The blob's sample rate (the samples the device heard).
    #[serde(default)]
    sample_rate_hz: Option<u32>,
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

/// The speech's samples at the run's rate (see the module docs), or why there are none.
fn run_audio(dir: &Path, tl: &TimelineIn) -> Result<(Vec<i16>, u32), String> {
    let rate = tl
        .sample_rate_hz
        .ok_or("the timeline does not give the sample rate")?;
    let mut tried = vec![dir.join("speech.wav")];
    if let Some(a) = &tl.audio {
        let p = PathBuf::from(a);
        if p.is_relative() {
            tried.push(dir.join(&p));
        }
        tried.insert(1, p);
    }
    for p in &tried {
        if p.is_file() {
            return load_wav_at(p, rate)
                .map(|pcm| (pcm.samples, rate))
                .map_err(|e| e.to_string());
        }
    }
    Err(format!(
        "no speech audio: looked for {}",
        tried
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    ))
}

/// The figures of the run in `dir`; `mocap` compares the hands' speeds with a capture.
/// Without the run's audio (see the module docs) the voice figures are `None`.
pub fn run_metrics(dir: &Path, mocap: Option<&Path>) -> Result<MotionMetrics, SimError> {
    run_metrics_noted(dir, mocap).map(|(m, _)| m)
}

/// [`run_metrics`], and why the voice figures are missing when they are for want of audio.
pub fn run_metrics_noted(
    dir: &Path,
    mocap: Option<&Path>,
) -> Result<(MotionMetrics, Option<String>), SimError> {
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
    let mut speech = Speech {
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
        active: Vec::new(),
    };
    // motion.bvh's tick 0 is the audio's time 0, as the steps' times are.
    let note = match run_audio(dir, &tl) {
        Ok((samples, rate)) => {
            speech = speech.with_audio(&samples, rate);
            None
        }
        Err(why) => Some(why),
    };
    let reference = match mocap {
        Some(p) => {
            let m = read_bvh(p).map_err(|e| SimError::Metrics(e.to_string()))?;
            Some(shown_speed_histogram(&m, &EffectorSpec::default()).map_err(|e| bad(p, e))?)
        }
        None => None,
    };
    let m = measure(&trace, &speech, Some(tl.segments), reference.as_deref());
    Ok((m, note))
}

/// `gesture-sim metrics`: prints the table (or JSON) for the run in `dir`.
pub fn run(
    dir: &Path,
    mocap: Option<&PathBuf>,
    json: bool,
    out: &mut impl Write,
) -> Result<(), SimError> {
    let (m, note) = run_metrics_noted(dir, mocap.map(PathBuf::as_path))?;
    if json {
        writeln!(out, "{}", serde_json::to_string(&m).unwrap_or_default())?;
        return Ok(());
    }
    for line in motion_table(&[("run", &m)]) {
        writeln!(out, "{line}")?;
    }
    if let Some(why) = note {
        writeln!(out, "(no voice figures: {why})")?;
    }
    Ok(())
}
