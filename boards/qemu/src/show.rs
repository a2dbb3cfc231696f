//! Plays a show file (docs/show-format.md) with the runtime's `ShowPlayer`: the run that
//! `gesture-sim run --show` baked from the speech input, with no front-end and no inference,
//! as a show board would play it. The sample clock counts the speech input's samples in
//! [`CHUNK`]-sample buffers, as [`drive`](crate::drive) feeds them to the controller.
//!
//! Shared, byte for byte, by the firmware's `show` build (`src/main.rs`) and the host
//! reference (`tests/examples/qemu_m4_host.rs show`); `check` compares their line
//!
//! ```text
//! show ticks=<n> pose_hash=<FNV-1a of every pose's bits, as drive.rs hashes them>
//! ```
//!
//! and both with the pose hash `gesture-sim run` printed when it baked the show. Every pose
//! must be finite and within the blob's limits ([`ShowRunError::Pose`]). `no_std`, no heap:
//! the player (about 6 KiB) is on the caller's stack.

use core::fmt::Write;

use gesture_runtime::blob::{Blob, BlobError};
use gesture_runtime::player::LibraryFrames;
use gesture_runtime::show::{Show, ShowError, ShowPlayer, ShowTick};

use crate::drive::{fnv, CHUNK, FNV_OFFSET};

/// Why a show could not be played.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShowRunError {
    /// The blob was refused.
    Blob(BlobError),
    /// The show was refused, or does not fit the blob.
    Show(ShowError),
    /// A pose was not finite or left the blob's limits.
    Pose {
        /// The tick.
        tick: u64,
    },
    /// The show did not play all its ticks over the samples.
    Ticks {
        /// Ticks played.
        played: u64,
    },
    /// Writing the line failed.
    Output,
}

impl ShowRunError {
    /// The error without formatting code (see `drive::RunError::name`).
    pub fn name(&self) -> &'static str {
        match self {
            Self::Blob(e) => e.name(),
            Self::Show(e) => e.name(),
            Self::Pose { .. } => "Pose",
            Self::Ticks { .. } => "Ticks",
            Self::Output => "Output",
        }
    }
}

/// Plays `show` over `blob` for `samples` samples of the clock and writes its line to `out`;
/// returns the ticks played and the pose hash.
pub fn run(
    blob: &[u8],
    show: &[u8],
    samples: usize,
    out: &mut impl Write,
) -> Result<(u64, u32), ShowRunError> {
    let blob = Blob::parse(blob).map_err(ShowRunError::Blob)?;
    let show = Show::parse(show).map_err(ShowRunError::Show)?;
    let mut player = ShowPlayer::from_blob(&show, &blob).map_err(ShowRunError::Show)?;
    let mut hash = FNV_OFFSET;
    let mut bad: Option<u64> = None;
    let mut sink = |t: ShowTick<'_>| {
        hash = fnv(hash, t.pose);
        for (ch, v) in t.pose.iter().enumerate() {
            let (lo, hi, _) = blob.limits(ch);
            if !(v.is_finite() && *v >= lo && *v <= hi) && bad.is_none() {
                bad = Some(t.tick);
            }
        }
    };
    let mut fed = 0;
    while fed < samples {
        let n = CHUNK.min(samples - fed);
        player.push(n, &mut sink);
        fed += n;
    }
    if let Some(tick) = bad {
        return Err(ShowRunError::Pose { tick });
    }
    let ticks = player.ticks_played();
    if !player.finished() {
        return Err(ShowRunError::Ticks { played: ticks });
    }
    writeln!(out, "show ticks={ticks} pose_hash={hash:08x}").map_err(|_| ShowRunError::Output)?;
    Ok((ticks, hash))
}
