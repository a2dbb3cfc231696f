//! `gesture-sim play-show`: a show file (docs/show-format.md; `gesture-sim run --show`,
//! [`crate::run::show`]) played with the runtime's `ShowPlayer` (no front-end, no inference:
//! what a show board runs), writing `servo.csv` and `motion.bvh` as a run writes them. Played
//! with the blob and audio it was baked from, both files are byte for byte the run's.
//!
//! **Inputs, checked before anything is written** (one line on stderr, exit 2, nothing
//! written): the blob (the runtime's loader), the show file (`Show::parse`, then checked
//! against the blob: its CRC, sample rate, frame rate and every segment it names), the
//! optional audio (any WAV the loader reads, resampled to the blob's rate: it sets how many
//! samples the clock counts; without it, just enough for every tick).

use std::io::Write;
use std::path::{Path, PathBuf};

use gesture_runtime::blob::Blob;
use gesture_runtime::rig::{ChannelCal, MAX_CHANNELS};
use gesture_runtime::show::{Show, ShowError, ShowPlayer};
use gesture_trainer::audio::load_wav_at;
use gesture_trainer::motion::write_bvh;
use gesture_trainer::rig::PoseSkeleton;

use crate::run::sim::Simulation;
use crate::run::{read_blob, servo_csv, write_all, RunError};

/// What `play-show` was asked to do.
#[derive(Clone, Debug)]
pub struct PlayShowConfig {
    /// The blob the show was baked against.
    pub blob: PathBuf,
    /// The show file.
    pub show: PathBuf,
    /// The audio that sets the sample clock (optional).
    pub audio: Option<PathBuf>,
    /// Output folder.
    pub out: PathBuf,
}

/// Why `play-show` failed.
#[derive(Debug, thiserror::Error)]
pub enum PlayShowError {
    /// The blob, the audio or an output (as for `run`).
    #[error(transparent)]
    Run(#[from] RunError),
    /// The show file could not be read.
    #[error("{}: cannot read the show: {source}", path.display())]
    ReadShow {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The runtime refused the show, or it does not fit the blob.
    #[error("{}: {source}", path.display())]
    Show {
        /// The file.
        path: PathBuf,
        /// The runtime's reason.
        source: ShowError,
    },
}

impl PlayShowError {
    /// Exit status: 2 for bad input, 1 for failures of our own or of the file system.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Run(e) => e.exit_code(),
            Self::ReadShow { .. } | Self::Show { .. } => 2,
        }
    }
}

/// The files `play-show` writes into its folder.
pub const PLAY_SHOW_OUTPUTS: [&str; 2] = ["servo.csv", "motion.bvh"];

/// Runs `play-show`; the summary goes to `out`.
pub fn play_show(cfg: &PlayShowConfig, out: &mut impl Write) -> Result<(), PlayShowError> {
    if cfg.out.exists() && !cfg.out.is_dir() {
        return Err(RunError::OutNotDir {
            path: cfg.out.clone(),
        }
        .into());
    }
    let outputs: Vec<PathBuf> = PLAY_SHOW_OUTPUTS.iter().map(|n| cfg.out.join(n)).collect();
    let outputs: Vec<&Path> = outputs.iter().map(PathBuf::as_path).collect();
    let mut inputs: Vec<&Path> = vec![&cfg.blob, &cfg.show];
    inputs.extend(cfg.audio.as_deref());
    gesture_trainer::output::refuse_inputs(&outputs, &inputs).map_err(RunError::from)?;
    let blob_bytes = read_blob(&cfg.blob)?;
    let blob = Blob::parse(&blob_bytes).map_err(|source| RunError::Blob {
        path: cfg.blob.clone(),
        source,
    })?;
    let show_bytes = std::fs::read(&cfg.show).map_err(|source| PlayShowError::ReadShow {
        path: cfg.show.clone(),
        source,
    })?;
    let refused = |source| PlayShowError::Show {
        path: cfg.show.clone(),
        source,
    };
    let show = Show::parse(&show_bytes).map_err(refused)?;
    let mut player = ShowPlayer::from_blob(&show, &blob).map_err(refused)?;
    let h = show.header();
    let rate = h.sample_rate_hz;
    let samples = match &cfg.audio {
        Some(a) => load_wav_at(a, rate).map_err(RunError::from)?.samples.len() as u64,
        // Tick ticks - 1 is due at ceil((ticks - 1) * rate * 1000 / fps_milli) samples.
        None => ((h.ticks as u64 - 1) * rate as u64 * 1000).div_ceil(h.fps_milli as u64),
    };
    let sim = play(&mut player, &blob, samples, rate)?;
    let mut files = Vec::new();
    let names: Vec<&str> = blob.channel_names().collect();
    files.push(("servo.csv", servo_csv(&sim, &names).into_bytes()));
    if let Some(view) = blob.skeleton() {
        let bvh_err = |e: String| RunError::Render {
            what: "motion.bvh",
            reason: e,
        };
        let sk = PoseSkeleton::from_blob(&view).map_err(|e| bvh_err(e.to_string()))?;
        let motion = sk
            .motion(&sim.poses, sim.fps)
            .map_err(|e| bvh_err(e.to_string()))?;
        let mut bytes = Vec::new();
        write_bvh(&motion, &mut bytes).map_err(|e| bvh_err(e.to_string()))?;
        files.push(("motion.bvh", bytes));
    }
    let written = write_all(&cfg.out, &files)?;
    let mut summary = || -> std::io::Result<()> {
        writeln!(
            out,
            "played {} ({} ticks, {} commands, {:.2} s) through {} (rig {:?}, {} channels): no \
             inference",
            cfg.show.display(),
            sim.poses.len(),
            h.commands,
            sim.duration_s,
            cfg.blob.display(),
            blob.rig_name(),
            blob.channels()
        )?;
        for p in &written {
            writeln!(out, "wrote {}", p.display())?;
        }
        if blob.skeleton().is_none() {
            writeln!(out, "no motion.bvh: the blob has no skeleton section")?;
        }
        Ok(())
    };
    summary().map_err(RunError::Summary)?;
    Ok(())
}

/// Plays `samples` samples of the clock through `player` in 10 ms chunks, each pose through
/// the runtime's `ServoRig` on virtual pins as the device loop drives it (neutral at power-up,
/// `dt = 1 / fps`).
fn play(
    player: &mut ShowPlayer<'_, Blob<'_>>,
    blob: &Blob<'_>,
    samples: u64,
    rate: u32,
) -> Result<Simulation, RunError> {
    let mut cals = [ChannelCal::HOBBY; MAX_CHANNELS];
    for (ch, c) in cals.iter_mut().enumerate().take(blob.channels()) {
        *c = blob.calibration(ch).unwrap_or(ChannelCal::HOBBY);
    }
    crate::run::bake::play_on(player, blob, samples, rate, &cals, blob.period_us())
        .map_err(RunError::Sim)
}
