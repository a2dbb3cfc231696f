//! `gesture-sim run ... --show FILE`: the run's player commands baked into a show file
//! (docs/show-format.md), which `gesture-sim play-show` ([`crate::play_show`]) and show
//! boards play with the runtime's `ShowPlayer`, no inference.

use std::path::Path;

use gesture_runtime::blob::Blob;
use gesture_runtime::show::{encode, Show};

use super::sim::Simulation;

/// Writes the show file of `sim` (a run of `blob`) to `path`, all or nothing; returns its
/// summary line, or why it could not be made or written.
pub fn write_show(path: &Path, sim: &Simulation, blob: &Blob<'_>) -> Result<String, String> {
    let bytes = encode(sim.poses.len() as u64, &sim.plays, blob).map_err(|e| e.to_string())?;
    gesture_trainer::output::write_atomic(path, &bytes)
        .map_err(|e| format!("{}: {}", e.path.display(), e.source))?;
    Ok(format!(
        "show {}: {} ticks, {} commands, {} bytes, for the blob with CRC {:08x} \
         (pose_hash={:08x})",
        path.display(),
        sim.poses.len(),
        Show::parse(&bytes).map_or(0, |s| s.header().commands),
        bytes.len(),
        blob.header().crc,
        pose_hash(&sim.poses)
    ))
}

/// FNV-1a over the bits of every pose value, in order (the hash of the QEMU firmware's trace,
/// `boards/qemu/src/drive.rs`, which its `check` compares with a show played on the device).
pub fn pose_hash(poses: &[Vec<f32>]) -> u32 {
    let mut h = 0x811c_9dc5u32;
    for v in poses.iter().flatten() {
        for b in v.to_bits().to_le_bytes() {
            h ^= b as u32;
            h = h.wrapping_mul(0x0100_0193);
        }
    }
    h
}
