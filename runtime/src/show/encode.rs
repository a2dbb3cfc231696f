//! The show writer (feature `encode`, host tools): a run's player commands and tick count to
//! show-file bytes, checked with the reader before they are returned.

use alloc::vec::Vec;
use core::fmt;

use super::error::ShowError;
use super::format::{kind, write_varint, SHOW_HEADER_LEN, SHOW_MAGIC, SHOW_VERSION};
use super::parse::Show;
use crate::blob::{crc32, Blob};
use crate::player::PlayerCommand;

/// What a show's header says besides its commands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShowInfo {
    /// The payload CRC of the blob the run used.
    pub blob_crc: u32,
    /// The sample clock (Hz).
    pub sample_rate_hz: u32,
    /// The library's frame rate in thousandths, rounded as the controller rounds it.
    pub fps_milli: u32,
    /// Poses in the run.
    pub ticks: u64,
}

impl ShowInfo {
    /// The header of a run of `ticks` poses of `blob`'s controller.
    pub fn of_blob(blob: &Blob<'_>, ticks: u64) -> Self {
        Self {
            blob_crc: blob.header().crc,
            sample_rate_hz: blob.prosody_config().sample_rate_hz,
            fps_milli: libm::roundf(blob.fps() * 1000.0) as u32,
            ticks,
        }
    }
}

/// Why a run could not be written as a show.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShowEncodeError {
    /// More ticks than a show holds (`u32::MAX`).
    TooManyTicks {
        /// The run's ticks.
        ticks: u64,
    },
    /// A command's tick is before the previous command's.
    NotInOrder {
        /// Index of the command in the input.
        command: usize,
    },
    /// 2^29 ticks or more between two commands (a record's head holds the gap in 29 bits).
    GapTooLong {
        /// Index of the command in the input.
        command: usize,
    },
    /// The written bytes were refused by the reader (a header field out of range, a rate
    /// outside the player's, too many commands).
    Refused(ShowError),
}

impl fmt::Display for ShowEncodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TooManyTicks { ticks } => {
                write!(f, "{ticks} ticks is more than a show holds ({})", u32::MAX)
            }
            Self::NotInOrder { command } => {
                write!(f, "command {command} comes before the one preceding it")
            }
            Self::GapTooLong { command } => write!(
                f,
                "command {command} comes 2^29 ticks or more after the one preceding it"
            ),
            Self::Refused(e) => write!(f, "the show would be refused: {e}"),
        }
    }
}

impl core::error::Error for ShowEncodeError {}

/// [`encode_show`] for a run of `ticks` poses of `blob`'s controller.
pub fn encode(
    ticks: u64,
    plays: &[(u64, PlayerCommand)],
    blob: &Blob<'_>,
) -> Result<Vec<u8>, ShowEncodeError> {
    encode_show(&ShowInfo::of_blob(blob, ticks), plays)
}

/// The show-file bytes of `plays` (the controller's `Play` events in order: the tick each
/// precedes and the command) over `info.ticks` poses. Commands at or after the last tick are
/// left out (they precede no pose).
pub fn encode_show(
    info: &ShowInfo,
    plays: &[(u64, PlayerCommand)],
) -> Result<Vec<u8>, ShowEncodeError> {
    let ticks = u32::try_from(info.ticks)
        .map_err(|_| ShowEncodeError::TooManyTicks { ticks: info.ticks })?;
    let mut records = Vec::new();
    let (mut prev, mut count) = (0u64, 0u32);
    for (i, &(tick, c)) in plays.iter().enumerate() {
        if tick < prev {
            return Err(ShowEncodeError::NotInOrder { command: i });
        }
        if tick >= info.ticks {
            continue;
        }
        // The head holds the gap in 29 bits (over 200 days at 30 fps).
        let delta = u32::try_from(tick - prev)
            .ok()
            .filter(|d| *d <= u32::MAX >> 3)
            .ok_or(ShowEncodeError::GapTooLong { command: i })?;
        let k = match c {
            PlayerCommand::Enter { .. } => kind::ENTER,
            PlayerCommand::RunOn => kind::RUN_ON,
            PlayerCommand::Turn => kind::TURN,
            PlayerCommand::Rate(_) => kind::RATE,
            PlayerCommand::Hold => kind::HOLD,
            PlayerCommand::Gain(_) => kind::GAIN,
        };
        write_varint(&mut records, delta << 3 | k as u32);
        match c {
            PlayerCommand::Enter { segment, frame } => {
                records.extend_from_slice(&segment.to_le_bytes());
                records.extend_from_slice(&frame.to_le_bytes());
            }
            PlayerCommand::Rate(r) | PlayerCommand::Gain(r) => {
                records.extend_from_slice(&r.to_le_bytes())
            }
            _ => {}
        }
        prev = tick;
        count = count.saturating_add(1);
    }
    let records_len = u32::try_from(records.len())
        .map_err(|_| ShowEncodeError::Refused(ShowError::BadRecord { command: count }))?;
    let mut out = Vec::with_capacity(SHOW_HEADER_LEN + records.len() + 4);
    out.extend_from_slice(&SHOW_MAGIC);
    out.extend_from_slice(&SHOW_VERSION.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    for v in [
        info.blob_crc,
        info.sample_rate_hz,
        info.fps_milli,
        ticks,
        count,
        records_len,
    ] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&records);
    let crc = crc32(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    Show::parse(&out).map_err(ShowEncodeError::Refused)?;
    Ok(out)
}
