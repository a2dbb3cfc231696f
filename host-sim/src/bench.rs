//! `gesture-sim bench-prosody`: how fast the front-end runs on this machine (a report, not a
//! test).
//!
//! The audio is the synthetic corpus speech of `gesture-train synth` (seeded, in memory) or a WAV file. Each run
//! creates a fresh front-end, pushes the whole signal in 256-sample chunks (a typical DMA
//! buffer; results do not depend on chunking) and ends the stream, on one thread, timed with
//! `std::time::Instant`. Reported: median and minimum wall time, the real-time multiple
//! (audio seconds / median seconds) and the median nanoseconds per input sample.

use std::hint::black_box;
use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};

use gesture_runtime::prosody::{Event, FrontEnd, ProsodyConfig};
use gesture_trainer::audio;

use crate::error::SimError;
use gesture_trainer::synth;

/// Seed of the synthetic benchmark signal.
pub const SEED: u64 = 0x6765_7374_7572_6521;
/// Samples per `push`.
pub const CHUNK: usize = 256;

/// Timings of one benchmark.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchReport {
    /// What was analysed.
    pub source: String,
    /// Its length (s).
    pub audio_s: f64,
    /// Its length (samples).
    pub samples: usize,
    /// Frames and steps the front-end reported per run.
    pub frames: u64,
    /// Steps per run.
    pub steps: u64,
    /// Wall time of each run, sorted.
    pub runs: Vec<Duration>,
}

impl BenchReport {
    /// Median run (the upper one for an even count).
    pub fn median(&self) -> Duration {
        self.runs[self.runs.len() / 2]
    }
    /// Fastest run.
    pub fn min(&self) -> Duration {
        self.runs[0]
    }
    /// Audio seconds per median second.
    pub fn realtime_multiple(&self) -> f64 {
        self.audio_s / self.median().as_secs_f64()
    }
    /// Median nanoseconds per input sample.
    pub fn ns_per_sample(&self) -> f64 {
        self.median().as_secs_f64() * 1e9 / self.samples.max(1) as f64
    }
}

/// Runs the front-end `runs` (>= 1) times over `samples`.
pub fn measure(
    samples: &[i16],
    config: &ProsodyConfig,
    runs: u32,
    source: String,
) -> Result<BenchReport, SimError> {
    let mut times = Vec::with_capacity(runs as usize);
    let (mut frames, mut steps) = (0u64, 0u64);
    for _ in 0..runs.max(1) {
        let (mut f, mut s) = (0u64, 0u64);
        let mut sink = |e: Event| match e {
            Event::Frame(_) => f += 1,
            Event::Step(_) => s += 1,
            Event::Onset(_) => {}
        };
        let start = Instant::now();
        let mut fe = FrontEnd::new(config)?;
        for chunk in black_box(samples).chunks(CHUNK) {
            fe.push(chunk, &mut sink);
        }
        fe.finish(&mut sink);
        times.push(start.elapsed());
        (frames, steps) = (black_box(f), black_box(s));
    }
    times.sort();
    Ok(BenchReport {
        source,
        audio_s: samples.len() as f64 / config.sample_rate_hz as f64,
        samples: samples.len(),
        frames,
        steps,
        runs: times,
    })
}

/// Runs the subcommand and prints the report.
pub fn run(
    seconds: f64,
    runs: u32,
    wav: Option<&Path>,
    out: &mut impl Write,
) -> Result<(), SimError> {
    let config = ProsodyConfig::DEFAULT;
    let rate = config.sample_rate_hz;
    let (samples, source) = match wav {
        Some(p) => (
            audio::load_wav_at(p, rate)?.samples,
            p.display().to_string(),
        ),
        None => (
            synth::generate_take(SEED, 0, seconds, &synth::speaker_for(SEED)).audio,
            format!("synthetic speech (gesture-train synth, seed {SEED})"),
        ),
    };
    let r = measure(&samples, &config, runs, source)?;
    writeln!(
        out,
        "front-end: {:.1} s of {} at {rate} Hz, {} runs on one thread ({} frames, {} steps per run)",
        r.audio_s,
        r.source,
        r.runs.len(),
        r.frames,
        r.steps
    )?;
    writeln!(
        out,
        "median {:.4} s   min {:.4} s   real-time x{:.1}   {:.1} ns/sample",
        r.median().as_secs_f64(),
        r.min().as_secs_f64(),
        r.realtime_multiple(),
        r.ns_per_sample()
    )?;
    Ok(())
}
