//! Fixed-size records inside the payload's byte tables, and the little-endian readers every
//! accessor uses (docs/blob-format.md, sections 2 and 3). Encoding and decoding of one record
//! sit side by side so they cannot drift apart. Readers take any index and return `None` when
//! it is out of range: they never panic.

use super::payload::{CALIBRATION_RECORD_BYTES, GMM_RECORD_BYTES};
use crate::inference::GmmComponent;
use crate::rig::ChannelCal;

/// Encodes a channel calibration as its 28-byte `rig.calibration` record (7 little-endian
/// `f32` in [`ChannelCal`] field order).
pub fn calibration_record(c: &ChannelCal) -> [u8; CALIBRATION_RECORD_BYTES] {
    let v = [
        c.neutral_deg,
        c.min_deg,
        c.max_deg,
        c.direction,
        c.pulse_neutral_us,
        c.us_per_deg,
        c.max_slew_deg_per_s,
    ];
    let mut b = [0u8; CALIBRATION_RECORD_BYTES];
    for (c, x) in b.chunks_exact_mut(4).zip(v) {
        c.copy_from_slice(&x.to_le_bytes());
    }
    b
}

/// Decodes a 28-byte calibration record.
pub fn calibration_from_record(b: &[u8; CALIBRATION_RECORD_BYTES]) -> ChannelCal {
    let v: [f32; 7] = f32s(b);
    ChannelCal {
        neutral_deg: v[0],
        min_deg: v[1],
        max_deg: v[2],
        direction: v[3],
        pulse_neutral_us: v[4],
        us_per_deg: v[5],
        max_slew_deg_per_s: v[6],
    }
}

/// Encodes a [`GmmComponent`] as its 52-byte record (13 little-endian `f32` in field order).
pub fn gmm_record(c: &GmmComponent) -> [u8; GMM_RECORD_BYTES] {
    let v = [
        c.log_voiced,
        c.log_unvoiced,
        c.mean[0],
        c.mean[1],
        c.inv_chol[0],
        c.inv_chol[1],
        c.inv_chol[2],
        c.log_norm,
        c.coef[0],
        c.coef[1],
        c.coef[2],
        c.inv_sd,
        c.log_norm_f0,
    ];
    let mut b = [0u8; GMM_RECORD_BYTES];
    for (c, x) in b.chunks_exact_mut(4).zip(v) {
        c.copy_from_slice(&x.to_le_bytes());
    }
    b
}

/// Decodes a 52-byte GMM record.
pub fn gmm_from_record(b: &[u8; GMM_RECORD_BYTES]) -> GmmComponent {
    let v: [f32; 13] = f32s(b);
    GmmComponent {
        log_voiced: v[0],
        log_unvoiced: v[1],
        mean: [v[2], v[3]],
        inv_chol: [v[4], v[5], v[6]],
        log_norm: v[7],
        coef: [v[8], v[9], v[10]],
        inv_sd: v[11],
        log_norm_f0: v[12],
    }
}

/// Little-endian `f32`s of `b` (`N` of them; missing ones are 0).
pub(crate) fn f32s<const N: usize>(b: &[u8]) -> [f32; N] {
    let mut v = [0.0f32; N];
    for (x, c) in v.iter_mut().zip(b.chunks_exact(4)) {
        if let &[p, q, r, s] = c {
            *x = f32::from_le_bytes([p, q, r, s]);
        }
    }
    v
}

/// Record `i` of `N` bytes in `b`, if it is there (never panics, whatever `i`).
#[inline]
pub(crate) fn record<const N: usize>(b: &[u8], i: usize) -> Option<&[u8; N]> {
    let s = i.checked_mul(N)?;
    b.get(s..s.checked_add(N)?)?.first_chunk::<N>()
}

#[inline]
pub(crate) fn u16_at(b: &[u8], i: usize) -> Option<u16> {
    record::<2>(b, i).map(|r| u16::from_le_bytes(*r))
}

#[inline]
pub(crate) fn i16_at(b: &[u8], i: usize) -> Option<i16> {
    record::<2>(b, i).map(|r| i16::from_le_bytes(*r))
}

#[inline]
pub(crate) fn u32_at(b: &[u8], i: usize) -> Option<u32> {
    record::<4>(b, i).map(|r| u32::from_le_bytes(*r))
}

#[inline]
pub(crate) fn f32_at(b: &[u8], i: usize) -> Option<f32> {
    record::<4>(b, i).map(|r| f32::from_le_bytes(*r))
}
