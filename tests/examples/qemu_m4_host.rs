//! The host side of the QEMU firmware's check (`boards/qemu`, run as `boards/qemu-m4` and
//! `boards/qemu-m33`).
//!
//! - `audio --wav TAKE.wav --seconds S --out DIR` writes the firmware's two inputs as raw
//!   little-endian i16 at 16 kHz: `DIR/speech.raw` (the first `S` seconds of the take) and
//!   `DIR/stress.raw` (the same length in four equal parts: digital silence, the speech
//!   amplified 16x into hard clipping, full-scale white noise from a fixed seed, and a
//!   full-scale 200 Hz square wave from `i16::MIN` to `i16::MAX`).
//!   Each also as a 16 kHz mono 16-bit WAV (`speech.wav`, `stress.wav`) for `gesture-sim run`.
//! - `trace --blob BLOB --input NAME=FILE ... [--fixed]` prints the reference decision trace:
//!   the firmware's own drive loop (`boards/qemu/src/drive.rs`, included below) over the same
//!   samples in the same 256-sample chunks, so its output must equal the firmware's stdout
//!   byte for byte. `--fixed` runs the fixed-point front-end (`prosody::arith::Fixed`), as the
//!   ARMv6-M firmware (`boards/qemu-m0`) does; without it, the `f32` one.
//! - `sim-decisions --timeline timeline.json` prints the decisions of a `gesture-sim run`
//!   (its `timeline.json`) as the trace's `decision` lines, for the same comparison against the
//!   simulator itself.
//! - `show --blob BLOB --show SHOW --input FILE` prints the line the firmware's `show` build
//!   must print: the show played by the runtime's `ShowPlayer` over `FILE`'s sample count
//!   (`boards/qemu/src/show.rs`, included below).
//!
//! Exit status: 0 on success, 1 on any error (one line on stderr naming the file).

#[path = "../../boards/qemu/src/drive.rs"]
mod drive;
#[path = "../../boards/qemu/src/show.rs"]
mod show;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use gesture_runtime::prosody::arith::Fixed;

#[derive(Debug, Parser)]
#[command(
    name = "qemu_m4_host",
    about = "Inputs and reference traces for boards/qemu (qemu-m4, qemu-m33, qemu-m0)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Write speech.raw and stress.raw from a WAV take.
    Audio {
        /// The take (any WAV the trainer reads; converted to 16 kHz mono).
        #[arg(long)]
        wav: PathBuf,
        /// Seconds to keep from the start of the take.
        #[arg(long, default_value_t = 6.0)]
        seconds: f64,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
    },
    /// Print the decisions of a `gesture-sim run` timeline as trace lines.
    SimDecisions {
        /// `timeline.json` from `gesture-sim run`.
        #[arg(long)]
        timeline: PathBuf,
    },
    /// Print the decision trace the firmware must print.
    Trace {
        /// The policy blob.
        #[arg(long)]
        blob: PathBuf,
        /// `NAME=FILE`: an input (raw i16 LE, 16 kHz), in the firmware's order.
        #[arg(long = "input", required = true)]
        inputs: Vec<String>,
        /// Run the fixed-point front-end (the ARMv6-M firmware's) instead of the f32 one.
        #[arg(long)]
        fixed: bool,
    },
    /// Print the line the firmware's `show` build must print.
    Show {
        /// The policy blob.
        #[arg(long)]
        blob: PathBuf,
        /// The show file (`gesture-sim run --show`).
        #[arg(long)]
        show: PathBuf,
        /// The input (raw i16 LE, 16 kHz) whose sample count the clock counts.
        #[arg(long)]
        input: PathBuf,
    },
}

fn read(path: &Path) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))
}

/// Writes `samples` as `DIR/NAME.raw` (i16 LE) and `DIR/NAME.wav` (16 kHz mono 16-bit).
fn write_input(dir: &Path, name: &str, samples: &[i16]) -> Result<(), String> {
    let raw = dir.join(format!("{name}.raw"));
    let bytes: Vec<u8> = samples.iter().flat_map(|s| s.to_le_bytes()).collect();
    std::fs::write(&raw, bytes).map_err(|e| format!("{}: {e}", raw.display()))?;
    let wav = dir.join(format!("{name}.wav"));
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: drive::AUDIO_RATE_HZ,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let fail = |e: hound::Error| format!("{}: {e}", wav.display());
    let mut w = hound::WavWriter::create(&wav, spec).map_err(fail)?;
    for &s in samples {
        w.write_sample(s).map_err(fail)?;
    }
    w.finalize().map_err(fail)
}

/// The stress input: silence, clipping, white noise and a full-scale square wave, each a
/// quarter of `speech`'s length.
fn stress(speech: &[i16]) -> Vec<i16> {
    let quarter = speech.len() / 4;
    let mut out = Vec::with_capacity(speech.len());
    out.extend(std::iter::repeat_n(0i16, quarter));
    // The loudest quarter of the speech, amplified into the rails.
    let loud = (0..4)
        .map(|q| &speech[q * quarter..(q + 1) * quarter])
        .max_by_key(|s| s.iter().map(|&v| (v as i64).abs()).sum::<i64>())
        .unwrap_or(&[]);
    out.extend(
        loud.iter()
            .map(|&v| (v as i32 * 16).clamp(i16::MIN as i32, i16::MAX as i32) as i16),
    );
    // xorshift32 with a fixed seed: uniform over the whole i16 range.
    let mut x = 0x2545_f491u32;
    out.extend((0..quarter).map(|_| {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        (x >> 16) as u16 as i16
    }));
    // 200 Hz at 16 kHz: 40 samples per half period.
    out.extend((0..speech.len() - out.len()).map(|i| {
        if (i / 40) % 2 == 0 {
            i16::MAX
        } else {
            i16::MIN
        }
    }));
    out
}

fn audio(wav: &Path, seconds: f64, out: &Path) -> Result<(), String> {
    let pcm = gesture_trainer::audio::load_wav_at(wav, drive::AUDIO_RATE_HZ)
        .map_err(|e| e.to_string())?;
    let n = ((seconds * drive::AUDIO_RATE_HZ as f64) as usize).min(pcm.samples.len());
    let speech = &pcm.samples[..n];
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    write_input(out, "speech", speech)?;
    write_input(out, "stress", &stress(speech))
}

fn sim_decisions(timeline: &Path) -> Result<(), String> {
    let text =
        std::fs::read_to_string(timeline).map_err(|e| format!("{}: {e}", timeline.display()))?;
    let bad = |what: &str| format!("{}: {what}", timeline.display());
    let json: serde_json::Value = serde_json::from_str(&text).map_err(|e| bad(&e.to_string()))?;
    let decisions = json["decisions"]
        .as_array()
        .ok_or_else(|| bad("no \"decisions\" array"))?;
    for d in decisions {
        let (Some(tick), Some(exit), Some(choice)) =
            (d["tick"].as_u64(), d["exit"].as_u64(), d["choice"].as_str())
        else {
            return Err(bad(&format!("malformed decision {d}")));
        };
        match (choice, d["segment"].as_u64()) {
            ("continue", _) => println!("decision tick={tick} exit={exit} choice=continue"),
            ("enter", Some(c)) => println!("decision tick={tick} exit={exit} choice=segment {c}"),
            _ => return Err(bad(&format!("malformed decision {d}"))),
        }
    }
    Ok(())
}

fn trace(blob: &Path, inputs: &[String], fixed: bool) -> Result<(), String> {
    let blob_bytes = read(blob)?;
    for input in inputs {
        let (name, file) = input
            .split_once('=')
            .ok_or_else(|| format!("--input {input}: expected NAME=FILE"))?;
        let audio = read(Path::new(file))?;
        let mut text = String::new();
        let probe = &mut drive::NoProbe;
        let result = if fixed {
            drive::run_with::<Fixed>(name, &blob_bytes, &audio, &mut text, probe)
        } else {
            // The build's arithmetic: f32 (the host never turns on the runtime's `fixed`).
            drive::run(name, &blob_bytes, &audio, &mut text, probe)
        };
        print!("{text}");
        result.map_err(|e| {
            format!(
                "input {name} ({file}, blob {}): {e} ({})",
                blob.display(),
                e.name()
            )
        })?;
    }
    Ok(())
}

fn play_show(blob: &Path, show: &Path, input: &Path) -> Result<(), String> {
    let samples = read(input)?.len() / 2;
    let mut text = String::new();
    let result = show::run(&read(blob)?, &read(show)?, samples, &mut text);
    print!("{text}");
    result.map(|_| ()).map_err(|e| {
        format!(
            "{} with {}: {:?} ({})",
            show.display(),
            blob.display(),
            e,
            e.name()
        )
    })
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Audio { wav, seconds, out } => audio(wav, *seconds, out),
        Command::SimDecisions { timeline } => sim_decisions(timeline),
        Command::Trace {
            blob,
            inputs,
            fixed,
        } => trace(blob, inputs, *fixed),
        Command::Show { blob, show, input } => play_show(blob, show, input),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("qemu_m4_host: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stress_has_the_four_parts() {
        let speech: Vec<i16> = (0..16_000).map(|i| ((i % 100) * 50) as i16).collect();
        let s = stress(&speech);
        assert_eq!(s.len(), speech.len());
        assert!(s[..4000].iter().all(|&v| v == 0));
        assert!(s[4000..8000].contains(&i16::MAX));
        assert!(s[12_000..].contains(&i16::MIN));
    }
}
