//! `gesture-sim soak --blob BLOB [--hours H]`: hours of hostile audio through the device loop,
//! checking what a board would suffer from over a long run.
//!
//! The audio is generated here, deterministically (seeded), in one-minute blocks cycling
//! through what a microphone meets: speech-like syllable trains at several levels, silence,
//! stationary loud noise, full-scale clipping square waves, DC offsets, and bursts of random
//! samples; each block is pushed in chunks of varying size (1 to 1024 samples). Nothing is kept
//! but counters, so memory must stay flat however long it runs.
//!
//! Reported: audio hours and wall time; ticks against the audio clock (the drift, which must
//! be at most one tick); decisions and steps per minute (the belief must keep updating);
//! poses out of the rig's limits or not finite and duty cycles outside the calibrated pulse
//! range (must be 0); resident memory (`VmRSS`, Linux) at the start, after the first minute
//! and at the end (must not grow). Exit status 1 when any check fails.

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{BlobController, ControllerEvent};
use gesture_runtime::device::{Device, DeviceEvent};
use gesture_runtime::rig::{duty_cycle, MAX_CHANNELS};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::error::SimError;
use crate::run::read_blob;
use crate::servo::VirtualPin;

/// What a soak run found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SoakReport {
    /// Seconds of audio pushed.
    pub audio_s: f64,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// Animation ticks played.
    pub ticks: u64,
    /// `ticks` minus the ticks the audio clock calls for.
    pub tick_drift: i64,
    /// Steps (syllables and pauses).
    pub steps: u64,
    /// Decisions.
    pub decisions: u64,
    /// Longest audio stretch without a step (s).
    pub longest_without_step_s: f64,
    /// Pose values outside the channel's limits or not finite.
    pub pose_violations: u64,
    /// Duty cycles outside the pulse range of the channel's limits.
    pub duty_violations: u64,
    /// Resident memory (KiB) at the start, after the first minute, at the end (0: unknown).
    pub rss_kib: [u64; 3],
}

impl SoakReport {
    /// Whether every check passed (see the module docs).
    pub fn ok(&self) -> bool {
        self.tick_drift.abs() <= 1
            && self.pose_violations == 0
            && self.duty_violations == 0
            && self.longest_without_step_s <= 2.0
            && (self.rss_kib[1] == 0 || self.rss_kib[2] <= self.rss_kib[1] + 1024)
    }
}

/// Resident memory of this process (KiB; 0 where `/proc` is not available).
fn rss_kib() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmRSS:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|v| v.parse().ok())
        })
        .unwrap_or(0)
}

/// One minute of audio of kind `block % 6` at `rate` (see the module docs).
fn minute(block: u64, rate: u32, rng: &mut ChaCha8Rng) -> Vec<i16> {
    let n = 60 * rate as usize;
    let t = |i: usize| i as f32 / rate as f32;
    match block % 6 {
        // Speech-like: 4 syllables a second with pitch and level varying, short pauses.
        0 | 3 => {
            let level = if block.is_multiple_of(6) {
                12_000.0
            } else {
                1_500.0
            };
            (0..n)
                .map(|i| {
                    let s = t(i);
                    let syl = (s * 4.0).fract();
                    let env = if (s * 0.25).fract() > 0.85 || syl > 0.7 {
                        0.0
                    } else {
                        (syl / 0.7 * core::f32::consts::PI).sin()
                    };
                    let f0 = 120.0 + 40.0 * (s * 0.7).sin();
                    (level * env * (2.0 * core::f32::consts::PI * f0 * s).sin()) as i16
                })
                .collect()
        }
        // Silence with a DC offset.
        1 => vec![-300; n],
        // Stationary loud noise.
        2 => (0..n).map(|_| rng.random_range(-20_000..20_000)).collect(),
        // Full-scale square wave (clipping).
        4 => (0..n)
            .map(|i| {
                if (t(i) * 150.0).fract() < 0.5 {
                    i16::MAX
                } else {
                    i16::MIN
                }
            })
            .collect(),
        // Bursts of arbitrary samples between silences.
        _ => (0..n)
            .map(|i| {
                if (t(i) * 2.0).fract() < 0.3 {
                    rng.random()
                } else {
                    0
                }
            })
            .collect(),
    }
}

/// Soaks the blob's device loop in `hours` of generated audio.
pub fn soak(blob: &Blob<'_>, hours: f64, seed: u64) -> Result<SoakReport, String> {
    let mut rep = SoakReport {
        rss_kib: [rss_kib(), 0, 0],
        ..SoakReport::default()
    };
    let rate = blob.prosody_config().sample_rate_hz;
    let fps = blob.fps() as f64;
    let channels = blob.channels();
    let period = blob.period_us();
    let limits: Vec<(f32, f32, u16, u16)> = (0..channels)
        .map(|ch| {
            let c = blob
                .calibration(ch)
                .unwrap_or(gesture_runtime::rig::ChannelCal::HOBBY);
            let (a, b) = (c.pulse_us(c.min_deg), c.pulse_us(c.max_deg));
            let max = crate::servo::MAX_DUTY;
            let (lo, hi) = (a.min(b), a.max(b));
            (
                c.min_deg,
                c.max_deg,
                duty_cycle(lo, period, max),
                duty_cycle(hi, period, max),
            )
        })
        .collect();
    let mut slot = Box::new(None);
    let controller = BlobController::from_blob_in(&mut slot, blob).map_err(|e| e.to_string())?;
    let mut device: Device<'_, '_, VirtualPin, MAX_CHANNELS> =
        Device::new(controller, [VirtualPin::default(); MAX_CHANNELS])
            .map_err(|e| e.to_string())?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let minutes = (hours * 60.0).ceil().max(1.0) as u64;
    let start = Instant::now();
    let mut pushed = 0u64;
    let mut last_step_sample = 0u64;
    for block in 0..minutes {
        let audio = minute(block, rate, &mut rng);
        let mut pos = 0;
        while pos < audio.len() {
            let n = rng.random_range(1..=1024usize).min(audio.len() - pos);
            let chunk = &audio[pos..pos + n];
            pos += n;
            pushed += n as u64;
            let now = pushed;
            let _ = device.push(chunk, &mut |e| match e {
                DeviceEvent::Controller(ControllerEvent::Step { .. }) => {
                    rep.steps += 1;
                    let gap = (now - last_step_sample) as f64 / rate as f64;
                    rep.longest_without_step_s = rep.longest_without_step_s.max(gap);
                    last_step_sample = now;
                }
                DeviceEvent::Controller(ControllerEvent::Decision { .. }) => rep.decisions += 1,
                DeviceEvent::Controller(ControllerEvent::Pose { pose, .. }) => {
                    rep.ticks += 1;
                    for (v, (lo, hi, _, _)) in pose.iter().zip(&limits) {
                        if !(v.is_finite() && (*lo..=*hi).contains(v)) {
                            rep.pose_violations += 1;
                        }
                    }
                }
                DeviceEvent::Servos { rig, .. } => {
                    for (pin, (_, _, dlo, dhi)) in rig.pins().iter().zip(&limits) {
                        let d = pin.duty();
                        // One count of rounding either way.
                        if d + 1 < *dlo || d > dhi.saturating_add(1) {
                            rep.duty_violations += 1;
                        }
                    }
                }
                _ => {}
            });
        }
        if block == 0 {
            rep.rss_kib[1] = rss_kib();
        }
    }
    rep.rss_kib[2] = rss_kib();
    rep.audio_s = pushed as f64 / rate as f64;
    rep.wall_s = start.elapsed().as_secs_f64();
    // The audio clock as the device keeps it: tick k is due once ceil(k * rate / fps)
    // samples have come, fps in milli-frames per second (so a 1/60.0001 s frame time runs at
    // exactly 60 fps), tick 0 at the first sample.
    let fps_milli = (fps * 1000.0).round() as u64;
    let due = (pushed as u128 * fps_milli as u128 / (rate as u128 * 1000).max(1)) as i64 + 1;
    rep.tick_drift = rep.ticks as i64 - due;
    Ok(rep)
}

/// `gesture-sim soak`: prints the report; exit status 1 when a check fails.
pub fn run(blob_path: &Path, hours: f64, seed: u64, out: &mut impl Write) -> Result<(), SimError> {
    let bytes = read_blob(blob_path)?;
    let blob = Blob::parse(&bytes).map_err(|source| crate::run::RunError::Blob {
        path: blob_path.to_path_buf(),
        source,
    })?;
    let r = soak(&blob, hours, seed).map_err(|e| SimError::Soak(e.to_string()))?;
    let minutes = r.audio_s / 60.0;
    writeln!(
        out,
        "soaked {:.2} h of audio in {:.1} s ({:.0}x real time)",
        r.audio_s / 3600.0,
        r.wall_s,
        r.audio_s / r.wall_s.max(1e-9)
    )?;
    writeln!(
        out,
        "ticks {} (drift {} against the audio clock); steps {:.1}/min, decisions {:.1}/min; \
         longest stretch without a step {:.2} s",
        r.ticks,
        r.tick_drift,
        r.steps as f64 / minutes.max(1e-9),
        r.decisions as f64 / minutes.max(1e-9),
        r.longest_without_step_s
    )?;
    writeln!(
        out,
        "limit violations: {} poses, {} duty cycles; resident memory {} KiB at start, {} after \
         one minute, {} at the end",
        r.pose_violations, r.duty_violations, r.rss_kib[0], r.rss_kib[1], r.rss_kib[2]
    )?;
    if r.ok() {
        writeln!(out, "soak passed")?;
        Ok(())
    } else {
        Err(SimError::Soak("soak failed (see the figures above)".into()))
    }
}
