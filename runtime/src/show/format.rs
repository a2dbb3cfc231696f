//! The show file's constants and its one variable-length number (docs/show-format.md,
//! sections 1 and 2): the header layout, the command kinds, and the LEB128 reader and writer.

/// The first four bytes of a show file: ASCII `GSTS`.
pub const SHOW_MAGIC: [u8; 4] = *b"GSTS";

/// The show format version this runtime reads and writes.
pub const SHOW_VERSION: u16 = 2;

/// Bytes before the records: magic, version, flags, blob CRC, sample rate, fps, ticks,
/// commands, records length.
pub const SHOW_HEADER_LEN: usize = 32;

/// Bytes after the records: the CRC-32 of everything before it.
pub const SHOW_CRC_LEN: usize = 4;

/// Lowest and highest sample rate a show may be clocked at (Hz).
pub const SHOW_RATE_RANGE: core::ops::RangeInclusive<u32> = 1_000..=192_000;

/// Highest frame rate, in thousandths of a frame per second (the blob's limit, 1000 fps).
pub const SHOW_MAX_FPS_MILLI: u32 = 1_000_000;

/// Record kinds (the low three bits of a record's head).
pub(crate) mod kind {
    /// `Enter { segment, frame }`: two `u16` follow.
    pub const ENTER: u8 = 0;
    /// `RunOn`.
    pub const RUN_ON: u8 = 1;
    /// `Turn`.
    pub const TURN: u8 = 2;
    /// `Rate(f32)`: an `f32` follows.
    pub const RATE: u8 = 3;
    /// `Hold`.
    pub const HOLD: u8 = 4;
    /// `Gain(f32)`: an `f32` follows.
    pub const GAIN: u8 = 5;
}

/// Reads an unsigned LEB128 number of at most 32 bits in its shortest form at `bytes[*pos..]`,
/// moving `pos` past it; `None` if it runs off the end, is longer than 5 bytes, overflows
/// 32 bits or is not the shortest form.
pub(crate) fn read_varint(bytes: &[u8], pos: &mut usize) -> Option<u32> {
    let mut value = 0u32;
    for i in 0..5 {
        let b = *bytes.get(*pos + i)?;
        let group = (b & 0x7F) as u32;
        if i == 4 && group > 0x0F {
            return None;
        }
        value |= group << (7 * i);
        if b & 0x80 == 0 {
            // Shortest form: a last byte of 0 only for the number 0 itself.
            if i > 0 && b == 0 {
                return None;
            }
            *pos += i + 1;
            return Some(value);
        }
    }
    None
}

/// Appends `v` as unsigned LEB128 in its shortest form.
#[cfg(feature = "encode")]
pub(crate) fn write_varint(out: &mut alloc::vec::Vec<u8>, mut v: u32) {
    while v >= 0x80 {
        out.push((v as u8 & 0x7F) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

/// Reads `N` bytes at `bytes[*pos..]`, moving `pos` past them.
pub(crate) fn read_array<const N: usize>(bytes: &[u8], pos: &mut usize) -> Option<[u8; N]> {
    let end = pos.checked_add(N)?;
    let a: [u8; N] = bytes.get(*pos..end)?.try_into().ok()?;
    *pos = end;
    Some(a)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn varints_read_their_shortest_form_only() {
        let read = |b: &[u8]| {
            let mut p = 0;
            read_varint(b, &mut p).map(|v| (v, p))
        };
        assert_eq!(read(&[0x00]), Some((0, 1)));
        assert_eq!(read(&[0x7f]), Some((127, 1)));
        assert_eq!(read(&[0x80, 0x7d]), Some((16000, 2)));
        assert_eq!(read(&[0xff, 0xff, 0xff, 0xff, 0x0f]), Some((u32::MAX, 5)));
        assert_eq!(read(&[0xff, 0xff, 0xff, 0xff, 0x1f]), None, "over 32 bits");
        assert_eq!(read(&[0x80, 0x00]), None, "not the shortest form");
        assert_eq!(read(&[0x80]), None, "runs off the end");
        assert_eq!(read(&[0x80, 0x80, 0x80, 0x80, 0x80, 0x01]), None);
    }
}
