//! Show files: a baked run played by the runtime with no inference (docs/show-format.md).
//!
//! An animatronic show or a museum figure plays a recording; its board needs only the
//! player. A controller reports every command it gives its player
//! ([`ControllerEvent::Play`](crate::controller::ControllerEvent::Play): cuts, run-ons,
//! turns, rate changes, holds, each stamped with the tick whose pose it precedes); with the
//! blob's library these alone give the poses again. A show file holds them, with the blob's
//! CRC (so a show cannot be played against another blob), the sample clock and the tick
//! count.
//!
//! **Layout: plain little-endian, not postcard.** A show is a header of fixed fields and a
//! long run of tiny records. Fixed offsets let a reader (or a person with a hex dump) find
//! the header's fields without decoding, and a record is a single LEB128 number holding the
//! tick's delta and the kind (`delta << 3 | kind`: most records are one byte) followed by
//! the kind's fixed arguments; postcard would give the same bytes for the records only
//! through a hand-written serializer, and its zero-copy reading of a borrowed sequence of
//! enums needs a decoder per record anyway. The reader is about as small as the blob's
//! header check.
//!
//! **Check once, then trust.** [`Show::parse`] checks every rule of the format (header, CRC,
//! every record; typed [`ShowError`], never a panic on any bytes) and
//! [`Show::check_against`] (or [`ShowPlayer::from_blob`], which calls it) checks the show
//! against the blob it is played with: the blob's CRC, sample rate, frame rate, every
//! segment and frame named. After that nothing fails: [`Show::commands`] walks the records
//! and [`ShowPlayer`] plays them.
//!
//! **The same poses, bit for bit.** [`ShowPlayer`] sets its [`Player`](crate::player::Player)
//! up as the controller does (the blob's blend time and the library's speed cap), counts
//! samples on the same clock (tick `k` is due once `ceil(k * rate * 1000 / fps_milli)`
//! samples have arrived), applies the commands stamped for a tick before that tick's frame
//! (a `Hold` makes the tick show its frame again) and clamps every pose to the rig's limits
//! as the controller does. The poses are the controller's, whatever the chunking. After the
//! last tick it reports nothing more and [`ShowPlayer::pose`] holds the last pose. The clock
//! is the played audio's: a controller with look-ahead
//! ([`Controller::set_lookahead`](crate::controller::Controller::set_lookahead)) plays tick
//! `k` once it has been fed the lead beyond those samples, that is when they are played.
//!
//! Memory: a [`ShowPlayer`] is a player and one pose (5 248 bytes on a Cortex-M4F); the
//! show stays where its bytes are (flash). Nothing here allocates but the writer
//! (the `encode` module, feature `encode`).
//!
//! Files: `format` (the constants, [`SHOW_MAGIC`] and the rest), `error` ([`ShowError`]), `parse` ([`Show`],
//! [`Commands`]), `player` ([`ShowPlayer`]), `encode` (the writer).

#[cfg(feature = "encode")]
mod encode;
mod error;
mod format;
mod parse;
mod player;

#[cfg(feature = "encode")]
pub use encode::{encode, encode_show, ShowEncodeError, ShowInfo};
pub use error::ShowError;
pub use format::{
    SHOW_CRC_LEN, SHOW_HEADER_LEN, SHOW_MAGIC, SHOW_MAX_FPS_MILLI, SHOW_RATE_RANGE, SHOW_VERSION,
};
pub use parse::{Commands, Show, ShowHeader};
pub use player::{ShowPlayer, ShowTick};
