//! `gesture-sim prosody`: a WAV file's prosody as CSV, exactly as the runtime computes it.
//!
//! Formats (those of the Praat reference CSVs, so the two can be compared line by line):
//!
//! - frames: `time_s,f0_hz,intensity_db`, time with 4 decimals, F0 and intensity with 2, F0
//!   empty when unvoiced;
//! - syllables: `start_s,end_s,f0_hz,intensity_db,length_s`, one row per syllable (pause steps
//!   are not listed), times with 4 decimals, F0 empty when the syllable has no voiced frame.
//!
//! The writers only format; errors are the writer's (a closed pipe is handled by the caller).

use std::io::{self, Write};
use std::path::Path;

use gesture_runtime::prosody::{Frame, ProsodyConfig, Step, StepKind};
use gesture_trainer::{audio, features};

use crate::error::SimError;

/// Header of the per-frame CSV.
pub const FRAME_HEADER: &str = "time_s,f0_hz,intensity_db";
/// Header of the syllable CSV.
pub const SYLLABLE_HEADER: &str = "start_s,end_s,f0_hz,intensity_db,length_s";

/// Writes the per-frame CSV (header and one row per frame).
pub fn write_frames_csv(out: &mut impl Write, frames: &[Frame]) -> io::Result<()> {
    writeln!(out, "{FRAME_HEADER}")?;
    for f in frames {
        write!(out, "{:.4},", f.time_s())?;
        if let Some(f0) = f.f0_hz {
            write!(out, "{f0:.2}")?;
        }
        writeln!(out, ",{:.2}", f.intensity_db)?;
    }
    Ok(())
}

/// Writes the syllable CSV (header and one row per syllable step; pauses skipped).
pub fn write_syllables_csv(out: &mut impl Write, steps: &[Step]) -> io::Result<()> {
    writeln!(out, "{SYLLABLE_HEADER}")?;
    for s in steps.iter().filter(|s| s.kind == StepKind::Syllable) {
        write!(out, "{:.4},{:.4},", s.start_s(), s.end_s())?;
        if let Some(f0) = s.f0_hz {
            write!(out, "{f0:.2}")?;
        }
        writeln!(out, ",{:.2},{:.4}", s.intensity_db, s.length_s())?;
    }
    Ok(())
}

/// Loads `wav` at the default front-end rate, runs the front-end and writes the frame CSV (or
/// the syllable CSV when `syllables`) to `out`.
pub fn run(wav: &Path, syllables: bool, out: &mut impl Write) -> Result<(), SimError> {
    let config = ProsodyConfig::DEFAULT;
    let pcm = audio::load_wav_at(wav, config.sample_rate_hz)?;
    let (frames, steps) = features::prosody_of(&pcm.samples, &config)?;
    if syllables {
        write_syllables_csv(out, &steps)?;
    } else {
        write_frames_csv(out, &frames)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_rows_match_the_reference_format() {
        let frames = [
            Frame {
                index: 1,
                f0_hz: None,
                intensity_db: -300.0,
            },
            Frame {
                index: 53,
                f0_hz: Some(123.454),
                intensity_db: 67.886,
            },
        ];
        let mut out = Vec::new();
        write_frames_csv(&mut out, &frames).unwrap();
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "time_s,f0_hz,intensity_db\n0.0100,,-300.00\n0.5300,123.45,67.89\n"
        );
    }

    #[test]
    fn syllable_rows_skip_pauses() {
        let step = |kind, start, end, f0| Step {
            kind,
            start_frame: start,
            end_frame: end,
            f0_hz: f0,
            intensity_db: 55.5,
        };
        let steps = [
            step(StepKind::Syllable, 3, 20, Some(150.0)),
            step(StepKind::Pause, 20, 45, None),
            step(StepKind::Syllable, 45, 52, None),
        ];
        let mut out = Vec::new();
        write_syllables_csv(&mut out, &steps).unwrap();
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "start_s,end_s,f0_hz,intensity_db,length_s\n\
             0.0300,0.2000,150.00,55.50,0.1700\n\
             0.4500,0.5200,,55.50,0.0700\n"
        );
    }
}
