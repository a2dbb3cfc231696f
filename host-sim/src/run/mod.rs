//! `gesture-sim run`: a WAV file through the runtime's `Controller`, exactly as the board would
//! run it, and everything it did written to a folder.
//!
//! **Inputs, checked before anything is written.** The blob (read and validated by the
//! runtime's own loader: a refused blob is one line naming the file and the typed error); the
//! optional rig file (`--rig`), whose calibrations and PWM period replace the blob's for the
//! virtual servos: it must have exactly the blob's channel names, and it is bound to the blob's
//! skeleton so a channel naming a missing joint is refused as `pack` would refuse it; the WAV
//! file (any rate and format `gesture_trainer::audio` reads), resampled to the blob's front-end
//! rate. Any of these failing is one line on stderr and exit status 2, with `DIR` untouched.
//!
//! **Outputs** (in `DIR`, created if needed; all rendered in memory first, then each written
//! to a temporary file and renamed, so a file is either complete or absent, and on a write
//! failure no output file is left):
//!
//! - `motion.bvh`: the played poses on the library's skeleton ([`gesture_trainer::rig::PoseSkeleton`]), one frame
//!   per animation tick at the library's frame rate (needs the blob's skeleton section);
//! - `timeline.json`: steps, beliefs, decisions and detection latencies ([`timeline`]);
//! - `servo.csv`: `tick,time_s,<channel>...`, the duty cycle of every channel at every tick,
//!   as written by the runtime's `ServoRig` to virtual 16-bit PWM pins ([`crate::servo`]);
//! - `preview.png` and `preview.gif` ([`preview`]);
//! - `viewer.html`, a self-contained page that plays the skeleton with the speech ([`viewer`]);
//! - `preview.mp4`, the run as a video with the speech, through `ffmpeg` ([`video`]);
//! - with `--blender`, `blender.py` and `speech.wav` ([`blender`]);
//! - with `--vmc HOST:PORT`, the poses streamed to an avatar app ([`crate::vmc`]);
//! - with `--ros2` (feature `ros2`) or `--mcap FILE`, the joint states as
//!   `sensor_msgs/JointState` over DDS or in an MCAP file, and `robot.urdf` ([`crate::ros2`]).
//! - with `--show FILE`, the run's show file (its player commands; `gesture-sim play-show`
//!   plays it with no inference: [`show`]).
//!
//! The summary on stdout gives the files, the audio duration, the decisions, the median and
//! maximum syllable detection latency and the simulation speed as a multiple of real time
//! (simulation only, without rendering and writing).

pub mod bake;
pub mod blender;
pub mod body;
mod canvas;
pub mod preview;
pub mod servos;
pub use servos::servo_csv;
pub mod show;
pub mod sim;
pub mod timeline;
pub mod video;
pub mod viewer;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use gesture_runtime::blob::{Blob, BlobError};
use gesture_runtime::prosody::StepKind;
use gesture_runtime::rig::ChannelCal;
use gesture_trainer::audio::{load_wav_at, AudioError};
use gesture_trainer::motion::write_bvh;
use gesture_trainer::rig::{Rig, RigError};

use gesture_trainer::evaluate::metrics::entries_from_frames;
use gesture_trainer::evaluate::motion::Horizon;
use gesture_trainer::rig::PoseSkeleton;
use sim::{median_max, simulate, SimOptions, Simulation};

/// What `run` was asked to do.
#[derive(Clone, Debug)]
pub struct RunConfig {
    /// Policy blob.
    pub blob: PathBuf,
    /// Audio file.
    pub audio: PathBuf,
    /// Output folder.
    pub out: PathBuf,
    /// Rig file overriding the blob's calibration.
    pub rig: Option<PathBuf>,
    /// Pace the simulation on the wall clock.
    pub realtime: bool,
    /// Audio chunk length (ms).
    pub chunk_ms: f64,
    /// How long before it is played the controller hears the audio.
    pub lookahead: Horizon,
    /// Write `preview.mp4` (when `ffmpeg` is on `PATH`).
    pub video: bool,
    /// Stream the poses over VMC to this `HOST:PORT` ([`crate::vmc`]).
    pub vmc: Option<String>,
    /// Bone-map file for `vmc`.
    pub bone_map: Option<PathBuf>,
    /// Also write `blender.py` and `speech.wav` ([`blender`]).
    pub blender: bool,
    /// Publish the joint states over ROS 2 DDS ([`crate::ros2`]).
    pub ros2: bool,
    /// The topic of `ros2` and `mcap` (default `/joint_states`).
    pub ros2_topic: Option<String>,
    /// Record the joint states in this MCAP file.
    pub mcap: Option<PathBuf>,
    /// The style and its changes over time ([`crate::style`]).
    pub style: crate::style::StyleFlags,
    /// Semantic labels at audio times (`--labels CSV`; [`crate::labels`]).
    pub labels: Option<PathBuf>,
    /// Keyword spotting (`--keywords FILE`; [`crate::kws`]).
    pub keywords: Option<PathBuf>,
    /// Also write the run's show file here (`--show FILE`; [`show`]).
    pub show: Option<PathBuf>,
}

/// Why `run` failed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The blob file could not be read.
    #[error("{}: cannot read the blob: {source}", path.display())]
    ReadBlob {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The runtime refused the blob.
    #[error("{}: {source}", path.display())]
    Blob {
        /// The file.
        path: PathBuf,
        /// The runtime's reason.
        source: BlobError,
    },
    /// The rig file is unusable or does not fit the blob's skeleton (boxed: it is large).
    #[error(transparent)]
    Rig(Box<RigError>),
    /// The rig file's channels are not the blob's.
    #[error("{}: {reason}", path.display())]
    RigMismatch {
        /// The rig file.
        path: PathBuf,
        /// What differs.
        reason: String,
    },
    /// The audio file could not be loaded.
    #[error(transparent)]
    Audio(#[from] AudioError),
    /// The style or label options do not fit the blob.
    #[error("{0}")]
    Style(String),
    /// The MCAP path is a folder, or its folder does not exist.
    #[error("--mcap {}: {reason}", path.display())]
    McapPath {
        /// The path.
        path: PathBuf,
        /// What is wrong.
        reason: &'static str,
    },
    /// The output path exists and is not a folder.
    #[error("{}: exists and is not a folder (give a folder for the outputs)", path.display())]
    OutNotDir {
        /// The path.
        path: PathBuf,
    },
    /// An output file would replace an input.
    #[error(transparent)]
    Overwrite(#[from] gesture_trainer::output::OverwriteError),
    /// The simulation could not be set up (a bug: the blob was validated).
    #[error("simulation: {0}")]
    Sim(String),
    /// An output could not be rendered.
    #[error("rendering {what}: {reason}")]
    Render {
        /// The file.
        what: &'static str,
        /// Why.
        reason: String,
    },
    /// An output could not be written.
    #[error("{}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// `--vmc` could not start or send.
    #[error(transparent)]
    Vmc(#[from] crate::vmc::VmcError),
    /// The summary could not be written.
    #[error("writing output: {0}")]
    Summary(#[from] std::io::Error),
    /// `--ros2` or `--mcap` could not start, be made or be sent.
    #[error(transparent)]
    Ros2(#[from] crate::ros2::Ros2Error),
}

impl From<RigError> for RunError {
    fn from(e: RigError) -> Self {
        Self::Rig(Box::new(e))
    }
}

impl RunError {
    /// Exit status: 2 for bad input, 1 for failures of our own or of the file system.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::ReadBlob { .. }
            | Self::Blob { .. }
            | Self::Rig(_)
            | Self::RigMismatch { .. }
            | Self::Audio(_)
            | Self::OutNotDir { .. }
            | Self::McapPath { .. }
            | Self::Style(_)
            | Self::Overwrite(_) => 2,
            Self::Sim(_) | Self::Render { .. } | Self::Write { .. } | Self::Summary(_) => 1,
            Self::Vmc(crate::vmc::VmcError::Send(_)) => 1,
            Self::Vmc(_) => 2,
            Self::Ros2(e) => e.exit_code(),
        }
    }
}

/// Reads and validates a blob file (the bytes; parse them with [`Blob::parse`]).
pub fn read_blob(path: &Path) -> Result<Vec<u8>, RunError> {
    let bytes = std::fs::read(path).map_err(|source| RunError::ReadBlob {
        path: path.to_owned(),
        source,
    })?;
    Blob::parse(&bytes).map_err(|source| RunError::Blob {
        path: path.to_owned(),
        source,
    })?;
    Ok(bytes)
}

/// The servo calibrations and PWM period for the virtual rig: the blob's, or those of the rig
/// file at `rig` (same channel names; bound to the blob's skeleton when it has one).
pub fn calibrations(
    blob: &Blob<'_>,
    blob_path: &Path,
    rig: Option<&Path>,
) -> Result<(Vec<ChannelCal>, f32), RunError> {
    let Some(path) = rig else {
        let cals = (0..blob.channels())
            .map(|c| blob.calibration(c).unwrap_or(ChannelCal::HOBBY))
            .collect();
        return Ok((cals, blob.period_us()));
    };
    let r = Rig::load(path)?;
    if let Some(sk) = blob.skeleton() {
        let pose = PoseSkeleton::from_blob(&sk).map_err(|e| RunError::Sim(e.to_string()))?;
        r.bind(
            pose.skeleton(),
            &format!("{} (the blob's skeleton)", blob_path.display()),
        )?;
    }
    let names: Vec<&str> = blob.channel_names().collect();
    let mismatch = |reason: String| RunError::RigMismatch {
        path: path.to_owned(),
        reason,
    };
    let mut cals = Vec::with_capacity(names.len());
    for n in &names {
        match r.channels.iter().find(|c| c.name == *n) {
            Some(c) => cals.push(c.cal),
            None => {
                return Err(mismatch(format!(
                    "rig `{}` has no channel `{n}`, which the blob drives (the blob's channels: \
                     {}); use a rig file with the blob's channel names",
                    r.name,
                    names.join(", ")
                )))
            }
        }
    }
    if let Some(extra) = r
        .channels
        .iter()
        .find(|c| !names.contains(&c.name.as_str()))
    {
        return Err(mismatch(format!(
            "rig channel `{}` is not in the blob (the blob's channels: {}); use a rig file \
             with the blob's channel names",
            extra.name,
            names.join(", ")
        )));
    }
    Ok((cals, r.period_us))
}

/// The rendered output files, in memory.
pub struct Outputs {
    /// `(file name, bytes)`.
    pub files: Vec<(&'static str, Vec<u8>)>,
    /// Frames in `motion.bvh` (0 if not written).
    pub bvh_frames: usize,
    /// Lines for the summary about outputs that were not made (e.g. no `ffmpeg`).
    pub notes: Vec<String>,
    /// What the summary says after `robot.urdf` and after the MCAP file.
    pub ros_details: (String, String),
}

/// Every file a run may write into its folder.
pub const OUTPUT_NAMES: [&str; 10] = [
    "motion.bvh",
    "timeline.json",
    "servo.csv",
    "preview.png",
    "preview.gif",
    "viewer.html",
    "preview.mp4",
    "speech.wav",
    "blender.py",
    "robot.urdf",
];

/// Renders every output of a run (`samples`: the speech at the blob's rate, for
/// `viewer.html`); with `video_audio`, also `preview.mp4` with that sound track.
pub fn render(
    sim: &Simulation,
    blob: &Blob<'_>,
    cx: timeline::Context<'_>,
    samples: &[i16],
    video_audio: Option<&Path>,
) -> Result<Outputs, RunError> {
    let render_err = |what| move |reason: String| RunError::Render { what, reason };
    let skeleton = match blob.skeleton() {
        Some(v) => {
            Some(PoseSkeleton::from_blob(&v).map_err(|e| render_err("motion.bvh")(e.to_string()))?)
        }
        None => None,
    };
    let mut files = Vec::new();
    let mut bvh_frames = 0;
    if let Some(sk) = &skeleton {
        let motion = sk
            .motion(&sim.poses, sim.fps)
            .map_err(|e| render_err("motion.bvh")(e.to_string()))?;
        let mut bytes = Vec::new();
        write_bvh(&motion, &mut bytes).map_err(|e| render_err("motion.bvh")(e.to_string()))?;
        bvh_frames = motion.frames();
        files.push(("motion.bvh", bytes));
    }
    files.push((
        "timeline.json",
        timeline::Timeline::new(sim, cx).to_json().into_bytes(),
    ));
    let names: Vec<&str> = blob.channel_names().collect();
    files.push(("servo.csv", servo_csv(sim, &names).into_bytes()));
    let servo_bars = servos::ServoBars::new(blob);
    files.push((
        "preview.png",
        preview::contact_sheet(sim, skeleton.as_ref()).map_err(render_err("preview.png"))?,
    ));
    files.push((
        "preview.gif",
        preview::animation(sim, skeleton.as_ref(), servo_bars.as_ref())
            .map_err(render_err("preview.gif"))?,
    ));
    let title = format!("gesture-sim run: {} through {}", cx.audio, cx.blob);
    let page = viewer::page(
        &viewer::data(sim, skeleton.as_ref(), servo_bars.as_ref(), &title),
        samples,
        blob.prosody_config().sample_rate_hz,
    )
    .map_err(render_err("viewer.html"))?;
    files.push(("viewer.html", page.into_bytes()));
    let mut notes = Vec::new();
    if let Some(audio) = video_audio {
        if !video::ffmpeg_available() {
            notes.push(video::NO_FFMPEG.to_string());
        } else {
            match video::render_mp4(sim, skeleton.as_ref(), servo_bars.as_ref(), audio) {
                Ok(bytes) => files.push(("preview.mp4", bytes)),
                Err(e) => notes.push(format!("no preview.mp4: {e}")),
            }
        }
    }
    Ok(Outputs {
        files,
        bvh_frames,
        notes,
        ros_details: Default::default(),
    })
}

/// Writes `files` into `dir` (created if needed), all or nothing
/// ([`gesture_trainer::output::write_all_atomic`]).
pub fn write_all(dir: &Path, files: &[(&'static str, Vec<u8>)]) -> Result<Vec<PathBuf>, RunError> {
    gesture_trainer::output::write_all_atomic(dir, files).map_err(|e| RunError::Write {
        path: e.path,
        source: e.source,
    })
}

/// The keywords of `path` and, per keyword, the index of its label among `label_names`.
pub fn keyword_labels(
    path: &Path,
    label_names: &[&str],
) -> Result<(Vec<crate::kws::Keyword>, Vec<usize>), RunError> {
    let kw = crate::kws::read_keywords(path).map_err(RunError::Style)?;
    let index = kw
        .iter()
        .map(|k| {
            label_names
                .iter()
                .position(|n| *n == k.label)
                .ok_or_else(|| {
                    RunError::Style(format!(
                        "{}: keyword `{}` brings the label `{}`, which the blob does not have \
                         (its labels: {})",
                        path.display(),
                        k.phrase,
                        k.label,
                        if label_names.is_empty() {
                            "none".to_string()
                        } else {
                            label_names.join(", ")
                        }
                    ))
                })
        })
        .collect::<Result<Vec<usize>, RunError>>()?;
    Ok((kw, index))
}

/// Runs the command; the summary goes to `out`.
pub fn run(cfg: &RunConfig, out: &mut impl Write) -> Result<(), RunError> {
    let total = Instant::now();
    // Inputs first: nothing is written unless all of them are usable.
    if cfg.out.exists() && !cfg.out.is_dir() {
        return Err(RunError::OutNotDir {
            path: cfg.out.clone(),
        });
    }
    // No output may replace an input (e.g. --out the audio's folder with the audio named
    // speech.wav, which --blender writes).
    let mut outputs: Vec<PathBuf> = OUTPUT_NAMES.iter().map(|n| cfg.out.join(n)).collect();
    if let Some(m) = &cfg.mcap {
        check_mcap_path(m)?;
        outputs.push(m.clone());
    }
    outputs.extend(cfg.show.clone());
    let outputs: Vec<&Path> = outputs.iter().map(PathBuf::as_path).collect();
    let mut inputs: Vec<&Path> = vec![&cfg.blob, &cfg.audio];
    inputs.extend(cfg.rig.as_deref());
    inputs.extend(cfg.bone_map.as_deref());
    inputs.extend(cfg.style.style_track.as_deref());
    inputs.extend(cfg.labels.as_deref());
    inputs.extend(cfg.keywords.as_deref());
    gesture_trainer::output::refuse_inputs(&outputs, &inputs).map_err(RunError::from)?;
    let bytes = read_blob(&cfg.blob)?;
    let blob = Blob::parse(&bytes).map_err(|source| RunError::Blob {
        path: cfg.blob.clone(),
        source,
    })?;
    let (cals, period_us) = calibrations(&blob, &cfg.blob, cfg.rig.as_deref())?;
    let tones: Vec<&str> = blob.tone_names().collect();
    let styles = cfg.style.schedule(&tones).map_err(RunError::Style)?;
    if cfg.lookahead == Horizon::All {
        bake::check_plannable(&styles, cfg.labels.is_some() || cfg.keywords.is_some())
            .map_err(RunError::Style)?;
    }
    let label_names: Vec<&str> = blob.label_names().collect();
    let mut labels = match &cfg.labels {
        Some(p) => crate::labels::read_label_track(p, &label_names).map_err(RunError::Style)?,
        None => Vec::new(),
    };
    let keywords = match &cfg.keywords {
        Some(p) => Some(keyword_labels(p, &label_names)?),
        None => None,
    };
    let rate = blob.prosody_config().sample_rate_hz;
    let pcm = load_wav_at(&cfg.audio, rate).map_err(RunError::from)?;
    let mut vmc = match &cfg.vmc {
        Some(addr) => Some(vmc_sender(&blob, addr, cfg.bone_map.as_deref())?),
        None => None,
    };
    let topic = crate::ros2::full_topic(cfg.ros2_topic.as_deref())?;
    // Started before the simulation, so DDS discovery runs meanwhile.
    let mut publisher = if cfg.ros2 {
        Some(crate::ros2::start(Some(&topic))?)
    } else {
        None
    };
    let chunk = ((cfg.chunk_ms / 1000.0 * rate as f64).round() as usize).max(1);
    if let Some((kw, index)) = &keywords {
        if rate != 16_000 {
            return Err(RunError::Style(format!(
                "--keywords: the recognizer listens at 16000 Hz, the blob at {rate} Hz"
            )));
        }
        for d in crate::kws::spot(&pcm.samples, chunk, kw).map_err(RunError::Style)? {
            labels.push(crate::run::sim::LabelPush {
                time_s: d.time_s,
                label: index[d.keyword],
                source: format!("keyword `{}`", kw[d.keyword].phrase),
            });
        }
        labels.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    }
    let sim = simulate(
        &blob,
        &pcm.samples,
        &cals,
        period_us,
        SimOptions {
            chunk,
            // With --vmc or --ros2 the poses are paced as they are sent instead.
            realtime: cfg.realtime && vmc.is_none() && publisher.is_none(),
            lookahead: cfg.lookahead.lookahead(),
        },
        &styles,
        &labels,
    )
    .map_err(RunError::Sim)?;
    let sim = if cfg.lookahead == Horizon::All {
        bake::baked(sim, &blob, &pcm.samples, &cals, period_us).map_err(RunError::Sim)?
    } else {
        sim
    };
    let audio_name = cfg.audio.display().to_string();
    let blob_name = cfg.blob.display().to_string();
    let mut outputs = render(
        &sim,
        &blob,
        timeline::Context {
            audio: &audio_name,
            blob: &blob_name,
            states: blob.states(),
            segments: blob.segments(),
            exit_points: blob.exit_points(),
            chunk_s: chunk as f64 / rate as f64,
            entries: &entries_from_frames(
                &sim.shown,
                |s| blob.continues(s),
                |s| blob.segment(s).map_or(1, |x| x.len as usize),
            ),
            tones: &tones,
            label_names: &label_names,
        },
        &pcm.samples,
        cfg.video.then_some(cfg.audio.as_path()),
    )?;
    if cfg.blender {
        if blob.skeleton().is_none() {
            outputs
                .notes
                .push("no blender.py: the blob has no skeleton, so there is no motion.bvh".into());
        } else {
            let wav = viewer::wav_bytes(&pcm.samples, rate).map_err(|reason| RunError::Render {
                what: "speech.wav",
                reason,
            })?;
            outputs.files.push(("speech.wav", wav));
            outputs
                .files
                .push(("blender.py", blender::SCRIPT.as_bytes().to_vec()));
        }
    }
    let stream = crate::ros2::JointStream::new(&blob);
    if cfg.ros2 || cfg.mcap.is_some() {
        match crate::ros2::urdf::Robot::from_blob(&blob, &cals) {
            Ok(robot) => {
                outputs.ros_details.0 = format!(
                    " ({} movable joints{})",
                    robot.movable().len(),
                    robot.note()
                );
                outputs
                    .files
                    .push(("robot.urdf", robot.to_xml().into_bytes()));
            }
            Err(e) => outputs.notes.push(format!("no robot.urdf: {e}")),
        }
    }
    outputs.ros_details.1 = format!(
        " ({} sensor_msgs/JointState messages on {topic}, stamped on the audio clock)",
        sim.angles.len()
    );
    let mcap = match &cfg.mcap {
        Some(path) => Some((
            path,
            crate::ros2::recording::mcap_bytes(&stream, &topic, &sim.angles).map_err(|reason| {
                crate::ros2::Ros2Error::Mcap {
                    path: path.clone(),
                    reason,
                }
            })?,
        )),
        None => None,
    };
    if vmc.is_some() || publisher.is_some() {
        stream_out(
            &sim,
            cfg.realtime,
            vmc.as_mut(),
            publisher.as_mut().map(|p| (p, &stream)),
        )?;
    }
    let mut written = write_all(&cfg.out, &outputs.files)?;
    if let Some((path, bytes)) = &mcap {
        gesture_trainer::output::write_atomic(path, bytes).map_err(|e| RunError::Write {
            path: e.path,
            source: e.source,
        })?;
        written.push(path.to_path_buf());
    }
    let show_line = match &cfg.show {
        Some(path) => {
            Some(
                show::write_show(path, &sim, &blob).map_err(|reason| RunError::Render {
                    what: "the show file",
                    reason,
                })?,
            )
        }
        None => None,
    };
    if let Some(p) = &publisher {
        writeln!(
            out,
            "ros2: published {} sensor_msgs/JointState messages of {} joints on {} (domain {}, \
             {}; stamps: the audio clock from Unix time {}.{:09} s)",
            p.sent(),
            stream.names().len(),
            p.topic(),
            p.domain(),
            crate::ros2::QOS,
            p.origin_ns().div_euclid(1_000_000_000),
            p.origin_ns().rem_euclid(1_000_000_000)
        )?;
    }
    if let (Some(v), Some(addr)) = (&vmc, &cfg.vmc) {
        writeln!(
            out,
            "vmc: sent {} bundles of {} bones ({}) to {addr}",
            v.sent,
            v.stream.bones().count(),
            v.stream.bones().collect::<Vec<_>>().join(" ")
        )?;
    }
    summary(
        out,
        cfg,
        &blob,
        &sim,
        &outputs,
        &written,
        total.elapsed().as_secs_f64(),
    )?;
    if let Some(line) = show_line {
        writeln!(out, "{line}")?;
    }
    Ok(())
}

/// Refuses an MCAP path that is a folder or whose folder does not exist.
fn check_mcap_path(path: &Path) -> Result<(), RunError> {
    let bad = |reason| RunError::McapPath {
        path: path.to_path_buf(),
        reason,
    };
    if path.is_dir() {
        return Err(bad("is a folder (give a file name such as run.mcap)"));
    }
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() && !d.is_dir() => {
            Err(bad("its folder does not exist"))
        }
        _ => Ok(()),
    }
}

/// A VMC sender for the blob's skeleton.
pub fn vmc_sender(
    blob: &Blob<'_>,
    addr: &str,
    bone_map: Option<&Path>,
) -> Result<crate::vmc::VmcSender, crate::vmc::VmcError> {
    use crate::vmc::{BoneMap, VmcError, VmcSender, VmcStream};
    let view = blob.skeleton().ok_or(VmcError::NoSkeleton)?;
    let sk = PoseSkeleton::from_blob(&view).map_err(|_| VmcError::NoSkeleton)?;
    let map = BoneMap::new(&sk, bone_map)?;
    VmcSender::new(addr, VmcStream::new(sk, map))
}

/// Sends every tick of `sim` over VMC (its pose) and ROS 2 (its commanded angles, stamped on
/// the audio clock from the publisher's origin), at its time when `realtime`, else as fast as
/// possible.
fn stream_out(
    sim: &Simulation,
    realtime: bool,
    mut vmc: Option<&mut crate::vmc::VmcSender>,
    mut ros: Option<(&mut crate::ros2::Publisher, &crate::ros2::JointStream)>,
) -> Result<(), RunError> {
    let start = Instant::now();
    if let Some((p, _)) = &mut ros {
        p.set_origin_ns(crate::ros2::unix_nanos());
    }
    for (k, (pose, angles)) in sim.poses.iter().zip(&sim.angles).enumerate() {
        let t = k as f64 / sim.fps.max(1e-9);
        if realtime {
            if let Some(wait) = std::time::Duration::from_secs_f64(t).checked_sub(start.elapsed()) {
                std::thread::sleep(wait);
            }
        }
        if let Some(v) = &mut vmc {
            v.send(t, pose)?;
        }
        if let Some((p, stream)) = &mut ros {
            let msg = stream.message(k as u64, p.origin_ns(), angles);
            p.publish(msg)?;
        }
    }
    if let Some((p, _)) = &mut ros {
        p.finish();
    }
    Ok(())
}

fn summary(
    out: &mut impl Write,
    cfg: &RunConfig,
    blob: &Blob<'_>,
    sim: &Simulation,
    outputs: &Outputs,
    written: &[PathBuf],
    total_s: f64,
) -> std::io::Result<()> {
    let syllables = sim
        .steps
        .iter()
        .filter(|s| s.kind == StepKind::Syllable)
        .count();
    let entered = sim.decisions.iter().filter(|d| d.entered.is_some()).count();
    writeln!(
        out,
        "ran {} ({:.2} s) through {} (rig {:?}, {} channels, {} states, {} segments){}",
        cfg.audio.display(),
        sim.duration_s,
        cfg.blob.display(),
        blob.rig_name(),
        blob.channels(),
        blob.states(),
        blob.segments(),
        if cfg.realtime {
            ", paced in real time"
        } else {
            ""
        }
    )?;
    for p in written {
        let extra = match p.file_name().and_then(|n| n.to_str()) {
            Some("motion.bvh") => format!(" ({} frames at {:.2} fps)", outputs.bvh_frames, sim.fps),
            Some("servo.csv") => format!(" ({} ticks)", sim.duties.len()),
            Some("robot.urdf") => outputs.ros_details.0.clone(),
            _ if cfg.mcap.as_deref() == Some(p.as_path()) => outputs.ros_details.1.clone(),
            _ => String::new(),
        };
        writeln!(out, "wrote {}{extra}", p.display())?;
    }
    if blob.skeleton().is_none() {
        writeln!(
            out,
            "no motion.bvh: the blob has no skeleton section (packed with --no-skeleton)"
        )?;
    }
    for note in &outputs.notes {
        writeln!(out, "{note}")?;
    }
    writeln!(
        out,
        "steps: {} syllables, {} pause steps; decisions: {} ({} entered a segment, {} continued)",
        syllables,
        sim.steps.len() - syllables,
        sim.decisions.len(),
        entered,
        sim.decisions.len() - entered
    )?;
    match median_max(&sim.syllable_latencies()) {
        Some((med, max)) => writeln!(
            out,
            "detection latency (syllable end -> belief update): median {:.3} s, max {:.3} s",
            med, max
        )?,
        None => writeln!(out, "detection latency: no syllables detected")?,
    }
    writeln!(
        out,
        "speed: {:.1}x real time ({:.3} s to simulate {:.2} s of audio; {:.2} s in all with \
         rendering and writing)",
        sim.speed(),
        sim.wall_s,
        sim.duration_s,
        total_s
    )
}
