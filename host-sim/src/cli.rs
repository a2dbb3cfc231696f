//! The `gesture-sim` command line: argument definitions, dispatch, exit codes, error lines.
//!
//! Exit codes (the same convention as `gesture-train`): 0 success (also when stdout is closed
//! early, e.g. `| head`); 2 bad input (an unreadable or unsupported file, a malformed
//! reference, an option out of range, and, from clap, bad usage); 1 a failure of the machine
//! or the program (writing output failed, no audio backend). Every error is one line on
//! stderr: `gesture-sim: <file>: <reason>` ([`SimError::exit_code`]).
//!
//! Output goes through one `BufWriter` on the locked stdout; nothing here uses `println!`, so
//! a closed pipe is an ordinary error value and never a panic.

use std::io::{self, BufWriter, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::error::SimError;
use crate::live::{self, LiveOptions};
use crate::run::{self as run_cmd, RunConfig, RunError};
use crate::style::StyleFlags;
use crate::{bench, eval_cmd, prosody_cmd};
use gesture_trainer::evaluate::motion::Horizon;

/// Runs the gesture-controller runtime on the desktop.
#[derive(Debug, Parser)]
#[command(name = "gesture-sim", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Print a WAV file's per-frame prosody (or its syllables) as CSV.
    Prosody {
        /// The WAV file (8-48 kHz; 8/16/24/32-bit integer or 32-bit float; mono or stereo).
        #[arg(value_name = "WAV")]
        wav: PathBuf,
        /// One row per syllable instead of per 10 ms frame.
        #[arg(long)]
        syllables: bool,
    },
    /// Compare the front-end with Praat on the shared recordings (skips if they are absent).
    EvalProsody {
        /// Data folder [default: ../shared/data, else the one next to the workspace].
        #[arg(long, value_name = "DIR")]
        data: Option<PathBuf>,
        /// Print one JSON object instead of tables.
        #[arg(long)]
        json: bool,
        /// Also evaluate the fixed-point front-end (boards without an FPU) and compare.
        #[arg(long)]
        fixed: bool,
    },
    /// Time the front-end on generated speech-like audio (or a WAV file).
    BenchProsody {
        /// Seconds of generated audio.
        #[arg(long, default_value_t = 60.0, value_parser = parse_seconds)]
        seconds: f64,
        /// Number of timed runs.
        #[arg(long, default_value_t = 7, value_parser = clap::value_parser!(u32).range(1..=1000))]
        runs: u32,
        /// Analyse this WAV file instead of generated audio.
        #[arg(long, value_name = "FILE")]
        wav: Option<PathBuf>,
    },
    /// Run a policy blob on a WAV file and write motion.bvh, timeline.json, servo.csv and
    /// previews into a folder.
    #[command(group(clap::ArgGroup::new("ros_output").multiple(true).args(["ros2", "mcap"])))]
    Run {
        /// Policy blob (from `gesture-train pack`).
        #[arg(long, value_name = "BLOB")]
        blob: PathBuf,
        /// Speech audio (any common WAV; resampled to the blob's rate).
        #[arg(long, value_name = "WAV")]
        audio: PathBuf,
        /// Output folder (created if needed).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Rig file whose servo calibration replaces the blob's (same channel names).
        #[arg(long, value_name = "RIG")]
        rig: Option<PathBuf>,
        /// Pace the simulation in real time instead of running as fast as possible.
        #[arg(long)]
        realtime: bool,
        /// Audio chunk length in ms (how often the device would process samples).
        #[arg(long, default_value_t = 10.0, value_parser = parse_chunk_ms)]
        chunk_ms: f64,
        /// Known audio: the controller hears the speech this many ms (0-1000) before it is
        /// played, or `all` for the whole file (a recording, text-to-speech): strokes land on
        /// syllables, hands settle and prepare with the speech.
        #[arg(long, value_name = "MS|all", default_value = "0", value_parser = clap::value_parser!(Horizon))]
        lookahead_ms: Horizon,
        /// Do not write preview.mp4 (the video with the speech, made with ffmpeg).
        #[arg(long)]
        no_video: bool,
        /// Stream the played poses over the VMC protocol (OSC/UDP) to an avatar app at
        /// HOST:PORT (e.g. 127.0.0.1:39539); with --realtime at their times.
        #[arg(long, value_name = "HOST:PORT")]
        vmc: Option<String>,
        /// Humanoid bone map for --vmc (TOML lines `LeftUpperArm = "joint"`), overriding the
        /// built-in name aliases.
        #[arg(long, value_name = "FILE", requires = "vmc")]
        bone_map: Option<PathBuf>,
        /// Also write blender.py and speech.wav: `blender --python DIR/blender.py` opens the
        /// motion and its speech as one scene.
        #[arg(long)]
        blender: bool,
        /// Publish the joint states to ROS 2 as sensor_msgs/JointState over DDS (feature
        /// `ros2`; domain from ROS_DOMAIN_ID); with --realtime at their times. Also writes
        /// robot.urdf.
        #[arg(long)]
        ros2: bool,
        /// The topic of --ros2 and --mcap [default: /joint_states].
        #[arg(long, value_name = "TOPIC", requires = "ros_output")]
        ros2_topic: Option<String>,
        /// Also record the joint states as a ROS 2 MCAP file (Foxglove, ros2 bag, rosbags),
        /// stamped on the audio clock. Also writes robot.urdf.
        #[arg(long, value_name = "FILE")]
        mcap: Option<PathBuf>,
        /// The style (tones of the blob).
        #[command(flatten)]
        style: StyleFlags,
        /// Semantic labels at audio times: CSV with the header `time_s,label` (names of the
        /// blob's labels).
        #[arg(long, value_name = "CSV")]
        labels: Option<PathBuf>,
        /// Keyword spotting (feature `kws`): lines `phrase<TAB>label[<TAB>threshold]`; each
        /// key phrase heard brings its label.
        #[arg(long, value_name = "FILE")]
        keywords: Option<PathBuf>,
        /// Also write the run's show file (its player commands, for `play-show` and show
        /// boards; docs/show-format.md).
        #[arg(long, value_name = "FILE")]
        show: Option<PathBuf>,
    },
    /// Play a show file (from `run --show`) with the runtime's ShowPlayer, no inference, and
    /// write servo.csv and motion.bvh into a folder.
    PlayShow {
        /// The policy blob the show was baked against.
        #[arg(long, value_name = "BLOB")]
        blob: PathBuf,
        /// The show file.
        #[arg(long, value_name = "FILE")]
        show: PathBuf,
        /// Audio whose length sets the sample clock [default: just enough for every tick].
        #[arg(long, value_name = "WAV")]
        audio: Option<PathBuf>,
        /// Output folder (created if needed).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
    },
    /// Keyword spotting alone (feature `kws`): the key phrases PocketSphinx hears in a WAV
    /// file, as CSV `time_s,phrase,label` (time: when detected).
    Keywords {
        /// Speech (any common WAV; resampled to 16 kHz).
        #[arg(long, value_name = "WAV")]
        audio: PathBuf,
        /// Lines `phrase<TAB>label[<TAB>threshold]`.
        #[arg(long, value_name = "FILE")]
        keywords: PathBuf,
    },
    /// Write a blob's character as a URDF whose movable joints are named as the JointState
    /// messages of --ros2 and --mcap name them (robot_state_publisher, RViz, Foxglove).
    Urdf {
        /// Policy blob (with its skeleton section).
        #[arg(long, value_name = "BLOB")]
        blob: PathBuf,
        /// Rig file whose calibration (the joint limits) replaces the blob's.
        #[arg(long, value_name = "RIG")]
        rig: Option<PathBuf>,
        /// Output file [default: stdout].
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
    },
    /// The whole pipeline on a fresh clone: synthetic corpus, training, packing, a new
    /// utterance, and `run` on it; then real recorded speech driving a library of real motion
    /// capture (a few seconds after the build).
    Demo {
        /// Output folder.
        #[arg(long, value_name = "DIR", default_value = "gesture-demo")]
        out: PathBuf,
        /// Your own recording (WAV) instead of the shipped speech for the real-motion runs.
        #[arg(long, value_name = "WAV")]
        audio: Option<PathBuf>,
    },
    /// The motion-quality figures of a `run` output folder (motion.bvh and timeline.json):
    /// variety, freezes, feet, jerk, jumps at cuts, beats.
    Metrics {
        /// The folder `gesture-sim run --out` wrote.
        #[arg(value_name = "DIR")]
        dir: PathBuf,
        /// A motion capture to compare the hands' speeds with (Hellinger distance).
        #[arg(long, value_name = "BVH")]
        mocap: Option<PathBuf>,
        /// Print one JSON object instead of the table.
        #[arg(long)]
        json: bool,
    },
    /// Hours of hostile generated audio through a blob's device loop: tick drift, memory,
    /// limit violations (exit 1 when a check fails).
    Soak {
        /// Policy blob.
        #[arg(long, value_name = "BLOB")]
        blob: PathBuf,
        /// Hours of audio.
        #[arg(long, default_value_t = 1.0, value_parser = parse_hours)]
        hours: f64,
        /// Seed of the generated audio.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// List the audio input devices.
    Devices,
    /// Run a policy blob on the microphone, printing decisions and the belief.
    Live {
        /// Policy blob (from `gesture-train pack`).
        #[arg(long, value_name = "BLOB")]
        blob: PathBuf,
        /// Input device name (see `gesture-sim devices`) [default: the default input].
        #[arg(long, value_name = "NAME")]
        device: Option<String>,
        /// Stop after this many seconds of audio.
        #[arg(long, value_parser = parse_seconds)]
        seconds: Option<f64>,
        /// Stream the played poses over the VMC protocol (OSC/UDP) to HOST:PORT.
        #[arg(long, value_name = "HOST:PORT")]
        vmc: Option<String>,
        /// Humanoid bone map for --vmc (overrides the built-in aliases).
        #[arg(long, value_name = "FILE", requires = "vmc")]
        bone_map: Option<PathBuf>,
        /// Publish the joint states to ROS 2 as sensor_msgs/JointState over DDS as they play
        /// (feature `ros2`; domain from ROS_DOMAIN_ID).
        #[arg(long)]
        ros2: bool,
        /// The topic of --ros2 [default: /joint_states].
        #[arg(long, value_name = "TOPIC", requires = "ros2")]
        ros2_topic: Option<String>,
        /// The style (tones of the blob); a style track's times count from the start.
        #[command(flatten)]
        style: StyleFlags,
        /// Keyword spotting on the microphone (feature `kws`): lines
        /// `phrase<TAB>label[<TAB>threshold]`.
        #[arg(long, value_name = "FILE")]
        keywords: Option<PathBuf>,
    },
}

fn parse_chunk_ms(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if v.is_finite() && (0.1..=1000.0).contains(&v) {
        Ok(v)
    } else {
        Err("must be between 0.1 and 1000".into())
    }
}

fn parse_hours(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if v.is_finite() && v > 0.0 && v <= 1000.0 {
        Ok(v)
    } else {
        Err("must be more than 0 and at most 1000".into())
    }
}

fn parse_seconds(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if v.is_finite() && v > 0.0 && v <= 3600.0 {
        Ok(v)
    } else {
        Err("must be more than 0 and at most 3600".into())
    }
}

/// Runs a parsed command line, writing results to `out`.
pub fn execute(cli: &Cli, out: &mut impl Write) -> Result<(), SimError> {
    match &cli.command {
        Command::Prosody { wav, syllables } => prosody_cmd::run(wav, *syllables, out),
        Command::EvalProsody { data, json, fixed } => {
            eval_cmd::run(data.as_deref(), *json, *fixed, out)
        }
        Command::BenchProsody { seconds, runs, wav } => {
            bench::run(*seconds, *runs, wav.as_deref(), out)
        }
        Command::Run {
            blob,
            audio,
            out: dir,
            rig,
            realtime,
            chunk_ms,
            lookahead_ms,
            no_video,
            vmc,
            bone_map,
            blender,
            ros2,
            ros2_topic,
            mcap,
            style,
            labels,
            keywords,
            show,
        } => run_cmd::run(
            &RunConfig {
                blob: blob.clone(),
                audio: audio.clone(),
                out: dir.clone(),
                rig: rig.clone(),
                realtime: *realtime,
                chunk_ms: *chunk_ms,
                lookahead: *lookahead_ms,
                video: !*no_video,
                vmc: vmc.clone(),
                bone_map: bone_map.clone(),
                blender: *blender,
                ros2: *ros2,
                ros2_topic: ros2_topic.clone(),
                mcap: mcap.clone(),
                style: style.clone(),
                labels: labels.clone(),
                keywords: keywords.clone(),
                show: show.clone(),
            },
            out,
        )
        .map_err(SimError::from),
        Command::PlayShow {
            blob,
            show,
            audio,
            out: dir,
        } => crate::play_show::play_show(
            &crate::play_show::PlayShowConfig {
                blob: blob.clone(),
                show: show.clone(),
                audio: audio.clone(),
                out: dir.clone(),
            },
            out,
        )
        .map_err(SimError::from),
        Command::Devices => Ok(live::devices(out)?),
        Command::Soak { blob, hours, seed } => crate::soak::run(blob, *hours, *seed, out),
        Command::Metrics { dir, mocap, json } => {
            crate::metrics_cmd::run(dir, mocap.as_ref(), *json, out)
        }
        Command::Keywords { audio, keywords } => {
            let kw = crate::kws::read_keywords(keywords).map_err(RunError::Style)?;
            let pcm = gesture_trainer::audio::load_wav_at(audio, 16_000).map_err(RunError::from)?;
            let found = crate::kws::spot(&pcm.samples, 160, &kw).map_err(RunError::Style)?;
            writeln!(out, "time_s,phrase,label")?;
            for d in found {
                let k = &kw[d.keyword];
                writeln!(out, "{:.3},{},{}", d.time_s, k.phrase, k.label)?;
            }
            Ok(())
        }
        Command::Urdf {
            blob,
            rig,
            out: file,
        } => {
            crate::urdf_cmd::run(blob, rig.as_deref(), file.as_deref(), out).map_err(SimError::from)
        }
        Command::Demo { out: dir, audio } => Ok(crate::demo::demo(
            dir,
            crate::demo::DemoParams::default(),
            audio.as_deref(),
            out,
        )?),
        Command::Live {
            blob,
            device,
            seconds,
            vmc,
            bone_map,
            ros2,
            ros2_topic,
            style,
            keywords,
        } => {
            let bytes = run_cmd::read_blob(blob)?;
            let b =
                gesture_runtime::blob::Blob::parse(&bytes).map_err(|source| RunError::Blob {
                    path: blob.clone(),
                    source,
                })?;
            let tones: Vec<&str> = b.tone_names().collect();
            let styles = style.schedule(&tones).map_err(RunError::Style)?;
            let label_names: Vec<&str> = b.label_names().collect();
            let keywords = match keywords {
                Some(p) => {
                    if b.prosody_config().sample_rate_hz != 16_000 {
                        return Err(RunError::Style(
                            "--keywords: the recognizer listens at 16000 Hz, the blob does not"
                                .into(),
                        )
                        .into());
                    }
                    let (kw, index) = run_cmd::keyword_labels(p, &label_names)?;
                    Some((
                        crate::kws::Stream::new(&kw).map_err(RunError::Style)?,
                        index,
                    ))
                }
                None => None,
            };
            let mut sender = match vmc {
                Some(addr) => Some(run_cmd::vmc_sender(&b, addr, bone_map.as_deref())?),
                None => None,
            };
            let mut publisher = if *ros2 {
                Some(crate::ros2::start(ros2_topic.as_deref())?)
            } else {
                None
            };
            let stream = crate::ros2::JointStream::new(&b);
            let mut source = live::CpalSource::open(device.as_deref())?;
            let opts = LiveOptions {
                seconds: *seconds,
                redraw: io::IsTerminal::is_terminal(&io::stdout()),
                styles,
                // Number keys fire the blob's labels (typed on the terminal).
                keys: (b.labels() > 0 && io::IsTerminal::is_terminal(&io::stdin()))
                    .then(|| live::read_keys(io::BufReader::new(io::stdin()))),
                keywords,
            };
            // Stamps: the audio clock, from the wall-clock time listening started.
            if let Some(p) = &mut publisher {
                p.set_origin_ns(crate::ros2::unix_nanos());
            }
            live::live_loop_with(&b, &mut source, opts, out, &mut |tick| {
                if let Some(v) = &mut sender {
                    v.send(tick.time_s, tick.pose).map_err(|e| e.to_string())?;
                }
                if let Some(p) = &mut publisher {
                    let msg = stream.message(tick.tick, p.origin_ns(), tick.angles);
                    p.publish(msg).map_err(|e| e.to_string())?;
                }
                Ok(())
            })?;
            if let Some(p) = &mut publisher {
                p.finish();
                writeln!(
                    out,
                    "ros2: published {} sensor_msgs/JointState messages on {} (domain {})",
                    p.sent(),
                    p.topic(),
                    p.domain()
                )?;
            }
            Ok(())
        }
    }
}

/// Runs a parsed command line on stdout and turns the outcome into an exit code (see the
/// module docs).
pub fn run(cli: &Cli) -> ExitCode {
    let mut out = BufWriter::new(io::stdout().lock());
    let result = execute(cli, &mut out).and_then(|()| out.flush().map_err(SimError::Output));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(SimError::Output(e)) if e.kind() == io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
        Err(e) => {
            // If stderr is gone too there is nobody left to tell.
            let _ = writeln!(io::stderr(), "gesture-sim: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
