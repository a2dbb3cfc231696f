//! The fixed 16-byte header: magic, format version, flags, payload length and the payload's
//! CRC-32 (docs/blob-format.md, section 1). [`Header::check`] is the first gate of
//! [`Blob::parse`](super::Blob::parse): it never panics and never allocates.

use super::crc::crc32;
use super::error::BlobError;
use super::format::{FORMAT_VERSION, HEADER_LEN, MAGIC};

/// The fixed 16-byte header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    /// Format version ([`FORMAT_VERSION`]).
    pub version: u16,
    /// Flags (0: version 2 defines none).
    pub flags: u16,
    /// Payload length in bytes.
    pub payload_len: u32,
    /// CRC-32 of the payload.
    pub crc: u32,
}

impl Header {
    /// The current-version header for `payload`; `None` if it is 4 GiB or longer.
    pub fn for_payload(payload: &[u8]) -> Option<Self> {
        Some(Self {
            version: FORMAT_VERSION,
            flags: 0,
            payload_len: u32::try_from(payload.len()).ok()?,
            crc: crc32(payload),
        })
    }

    /// The header's bytes.
    pub fn to_bytes(&self) -> [u8; HEADER_LEN] {
        let mut b = [0u8; HEADER_LEN];
        b[0..4].copy_from_slice(&MAGIC);
        b[4..6].copy_from_slice(&self.version.to_le_bytes());
        b[6..8].copy_from_slice(&self.flags.to_le_bytes());
        b[8..12].copy_from_slice(&self.payload_len.to_le_bytes());
        b[12..16].copy_from_slice(&self.crc.to_le_bytes());
        b
    }

    /// Checks the header of `bytes` (length, magic, version, flags, payload length, CRC) and
    /// returns it with the payload bytes.
    pub fn check(bytes: &[u8]) -> Result<(Self, &[u8]), BlobError> {
        let (head, body) = match bytes.split_first_chunk::<HEADER_LEN>() {
            Some(x) => x,
            None => return Err(BlobError::BlobTooShort { len: bytes.len() }),
        };
        if head[0..4] != MAGIC {
            return Err(BlobError::BadMagic);
        }
        let h = Self {
            version: u16::from_le_bytes([head[4], head[5]]),
            flags: u16::from_le_bytes([head[6], head[7]]),
            payload_len: u32::from_le_bytes([head[8], head[9], head[10], head[11]]),
            crc: u32::from_le_bytes([head[12], head[13], head[14], head[15]]),
        };
        if h.version != FORMAT_VERSION {
            return Err(BlobError::UnsupportedVersion { found: h.version });
        }
        if h.flags != 0 {
            return Err(BlobError::UnsupportedFlags { found: h.flags });
        }
        let declared = h.payload_len;
        let available = body.len();
        match usize::try_from(declared) {
            Ok(n) if n == available => {}
            Ok(n) if n < available => {
                return Err(BlobError::TrailingBytes {
                    declared,
                    available,
                })
            }
            _ => {
                return Err(BlobError::Truncated {
                    declared,
                    available,
                })
            }
        }
        let computed = crc32(body);
        if computed != h.crc {
            return Err(BlobError::BadCrc {
                stored: h.crc,
                computed,
            });
        }
        Ok((h, body))
    }
}
