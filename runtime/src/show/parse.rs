//! [`Show::parse`]: the one gate from bytes to a validated show, and [`Commands`], the
//! infallible walk over its records afterwards.

use super::error::ShowError;
use super::format::{
    kind, read_array, read_varint, SHOW_CRC_LEN, SHOW_HEADER_LEN, SHOW_MAGIC, SHOW_MAX_FPS_MILLI,
    SHOW_RATE_RANGE, SHOW_VERSION,
};
use crate::blob::{crc32, Blob};
use crate::player::expression::GAIN_RANGE;
use crate::player::{LibraryFrames, PlayerCommand, MAX_RATE, MIN_RATE};

/// The header's fields (docs/show-format.md, section 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShowHeader {
    /// Format version ([`SHOW_VERSION`](super::SHOW_VERSION)).
    pub version: u16,
    /// The payload CRC of the blob the show was baked against
    /// ([`Header::crc`](crate::blob::Header::crc)).
    pub blob_crc: u32,
    /// The sample clock the ticks are placed on (Hz).
    pub sample_rate_hz: u32,
    /// Ticks per second, in thousandths (the library's fps, rounded as the controller does).
    pub fps_milli: u32,
    /// Poses in the show.
    pub ticks: u32,
    /// Records in the show.
    pub commands: u32,
    /// Bytes of records.
    pub records_len: u32,
}

/// A validated show file: its header and its records, borrowed from the bytes. Once
/// [`parse`](Self::parse) returns it, walking its [`commands`](Self::commands) cannot fail.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Show<'a> {
    header: ShowHeader,
    records: &'a [u8],
}

/// One record decoded: its tick and command.
fn record(
    bytes: &[u8],
    pos: &mut usize,
    prev: u64,
    command: u32,
) -> Result<(u64, PlayerCommand), ShowError> {
    let bad = ShowError::BadRecord { command };
    let head = read_varint(bytes, pos).ok_or(bad)?;
    let tick = prev + (head >> 3) as u64;
    let cmd = match (head & 7) as u8 {
        kind::ENTER => {
            let a = read_array::<4>(bytes, pos).ok_or(bad)?;
            PlayerCommand::Enter {
                segment: u16::from_le_bytes([a[0], a[1]]),
                frame: u16::from_le_bytes([a[2], a[3]]),
            }
        }
        kind::RUN_ON => PlayerCommand::RunOn,
        kind::TURN => PlayerCommand::Turn,
        kind::RATE => {
            let r = f32::from_le_bytes(read_array::<4>(bytes, pos).ok_or(bad)?);
            if !(r.is_finite() && (MIN_RATE..=MAX_RATE).contains(&r)) {
                return Err(ShowError::BadRate { command });
            }
            PlayerCommand::Rate(r)
        }
        kind::HOLD => PlayerCommand::Hold,
        kind::GAIN => {
            let g = f32::from_le_bytes(read_array::<4>(bytes, pos).ok_or(bad)?);
            let (lo, hi) = GAIN_RANGE;
            if !(g.is_finite() && (lo..=hi).contains(&g)) {
                return Err(ShowError::BadGain { command });
            }
            PlayerCommand::Gain(g)
        }
        k => return Err(ShowError::UnknownKind { command, kind: k }),
    };
    Ok((tick, cmd))
}

impl<'a> Show<'a> {
    /// Checks `bytes` completely (header, CRC, every record) and returns the validated show,
    /// or the first rule broken (docs/show-format.md, section 4). Never panics, never
    /// allocates; one pass over the bytes for the CRC and one over the records.
    pub fn parse(bytes: &'a [u8]) -> Result<Self, ShowError> {
        let Some((head, rest)) = bytes.split_first_chunk::<SHOW_HEADER_LEN>() else {
            return Err(ShowError::TooShort { len: bytes.len() });
        };
        if rest.len() < SHOW_CRC_LEN {
            return Err(ShowError::TooShort { len: bytes.len() });
        }
        if head[0..4] != SHOW_MAGIC {
            return Err(ShowError::BadMagic);
        }
        let u16_at = |i: usize| u16::from_le_bytes([head[i], head[i + 1]]);
        let u32_at =
            |i: usize| u32::from_le_bytes([head[i], head[i + 1], head[i + 2], head[i + 3]]);
        let header = ShowHeader {
            version: u16_at(4),
            blob_crc: u32_at(8),
            sample_rate_hz: u32_at(12),
            fps_milli: u32_at(16),
            ticks: u32_at(20),
            commands: u32_at(24),
            records_len: u32_at(28),
        };
        if header.version != SHOW_VERSION {
            return Err(ShowError::UnsupportedVersion {
                found: header.version,
            });
        }
        if u16_at(6) != 0 {
            return Err(ShowError::UnsupportedFlags { found: u16_at(6) });
        }
        let declared = header.records_len;
        let available = rest.len();
        let need = (declared as usize).checked_add(SHOW_CRC_LEN);
        match need {
            Some(n) if n == available => {}
            Some(n) if n < available => {
                return Err(ShowError::TrailingBytes {
                    declared,
                    available,
                })
            }
            _ => {
                return Err(ShowError::Truncated {
                    declared,
                    available,
                })
            }
        }
        let (covered, stored) = bytes.split_at(bytes.len() - SHOW_CRC_LEN);
        let stored = u32::from_le_bytes([stored[0], stored[1], stored[2], stored[3]]);
        let computed = crc32(covered);
        if stored != computed {
            return Err(ShowError::BadCrc { stored, computed });
        }
        if !SHOW_RATE_RANGE.contains(&header.sample_rate_hz) {
            return Err(ShowError::BadSampleRate {
                found: header.sample_rate_hz,
            });
        }
        if header.fps_milli == 0 || header.fps_milli > SHOW_MAX_FPS_MILLI {
            return Err(ShowError::BadFrameRate {
                found: header.fps_milli,
            });
        }
        if header.ticks == 0 {
            return Err(ShowError::NoTicks);
        }
        let records = &covered[SHOW_HEADER_LEN..];
        let (mut pos, mut tick, mut found) = (0usize, 0u64, 0u32);
        while pos < records.len() {
            let (t, _) = record(records, &mut pos, tick, found)?;
            if t >= header.ticks as u64 {
                return Err(ShowError::TickOutOfRange {
                    command: found,
                    tick: t.min(u32::MAX as u64) as u32,
                });
            }
            tick = t;
            // The records are at most 4 GiB and each is at least one byte.
            found = found.saturating_add(1);
        }
        if found != header.commands {
            return Err(ShowError::CommandCount {
                declared: header.commands,
                found,
            });
        }
        Ok(Self { header, records })
    }

    /// The header.
    pub fn header(&self) -> ShowHeader {
        self.header
    }

    /// Poses in the show.
    pub fn ticks(&self) -> u64 {
        self.header.ticks as u64
    }

    /// The commands in order, each with the tick whose pose it precedes.
    pub fn commands(&self) -> Commands<'a> {
        Commands {
            records: self.records,
            pos: 0,
            tick: 0,
            index: 0,
        }
    }

    /// Checks that the show was baked against `blob`: its CRC, its sample rate and its
    /// library (frame rate, every `Enter` within it; [`check_library`](Self::check_library)).
    pub fn check_against(&self, blob: &Blob<'_>) -> Result<(), ShowError> {
        let crc = blob.header().crc;
        if self.header.blob_crc != crc {
            return Err(ShowError::OtherBlob {
                show: self.header.blob_crc,
                blob: crc,
            });
        }
        let rate = blob.prosody_config().sample_rate_hz;
        if self.header.sample_rate_hz != rate {
            return Err(ShowError::SampleRateMismatch {
                show: self.header.sample_rate_hz,
                blob: rate,
            });
        }
        self.check_library(blob)
    }

    /// Checks that the show fits `lib`: the same frame rate (rounded to thousandths as the
    /// controller rounds it), at most [`MAX_CHANNELS`](crate::player::MAX_CHANNELS)
    /// channels, and every `Enter` naming a segment and frame of it.
    pub fn check_library<L: LibraryFrames + ?Sized>(&self, lib: &L) -> Result<(), ShowError> {
        let fps = lib.fps();
        let library = if fps.is_finite() && fps > 0.0 {
            libm::roundf(fps * 1000.0) as u32
        } else {
            0
        };
        if library != self.header.fps_milli {
            return Err(ShowError::FrameRateMismatch {
                show: self.header.fps_milli,
                library,
            });
        }
        if lib.channels() > crate::player::MAX_CHANNELS {
            return Err(ShowError::TooManyChannels {
                found: lib.channels(),
            });
        }
        for (i, (_, c)) in self.commands().enumerate() {
            let command = i.min(u32::MAX as usize) as u32;
            if let PlayerCommand::Enter { segment, frame } = c {
                let s = segment as usize;
                if s >= lib.segment_count() {
                    return Err(ShowError::SegmentOutOfRange { command, segment });
                }
                if frame as usize >= lib.segment_len(s) {
                    return Err(ShowError::FrameOutOfRange { command, frame });
                }
            }
        }
        Ok(())
    }
}

/// The commands of a validated [`Show`], in order: `(tick, command)`.
#[derive(Clone, Debug)]
pub struct Commands<'a> {
    records: &'a [u8],
    pos: usize,
    tick: u64,
    index: u32,
}

impl Iterator for Commands<'_> {
    type Item = (u64, PlayerCommand);

    fn next(&mut self) -> Option<Self::Item> {
        if self.pos >= self.records.len() {
            return None;
        }
        // Validated by `Show::parse`: this cannot fail; if it did, the walk would end.
        let (tick, c) = record(self.records, &mut self.pos, self.tick, self.index).ok()?;
        self.tick = tick;
        self.index = self.index.wrapping_add(1);
        Some((tick, c))
    }
}
