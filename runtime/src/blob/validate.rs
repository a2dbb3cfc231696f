//! Field validation of a decoded payload, in the order of docs/blob-format.md ("Validation"):
//! front_end, inference, library, rig, policy (the policy indexes into the library, so the
//! library is checked first), control, then the optional skeleton. Each check returns the
//! first rule broken; O(payload size), no allocation, no panics (all index arithmetic is
//! checked or bounded by the capacities).

use super::error::BlobError;
use super::field::Field;
use super::format::{
    MAX_BEAT_HOLD_MS, MAX_BLEND_MS, MAX_CHANNELS, MAX_DEFER_CUT_MS, MAX_EXITS, MAX_FPS, MAX_FRAMES,
    MAX_JOINTS, MAX_ONSET_WINDOW_MS, MAX_REST_MS, MAX_SEGMENTS, MAX_VARIETY_COST, MAX_WAIT_MS,
};
use super::payload::*;
use super::records::{calibration_from_record, f32_at, record, u16_at, u32_at};
use super::skeleton::Drive;
use crate::inference::{CrfWeights, I16Table, MAX_CLUSTERS, MAX_STATES, MAX_WINDOW};
use crate::rig::validate_period;

/// What the accessors need precomputed.
pub(super) struct Validated<'a> {
    pub crf: CrfWeights<'a>,
    pub u: I16Table<'a>,
    pub u_cont: I16Table<'a>,
    pub tone_u: I16Table<'a>,
    pub tone_u_cont: I16Table<'a>,
    pub label_u: I16Table<'a>,
    pub label_u_cont: I16Table<'a>,
}

pub(super) fn payload<'a>(p: &Payload<'a>) -> Result<Validated<'a>, BlobError> {
    front_end(&p.front_end)?;
    let crf = inference(&p.inference)?;
    library(&p.library)?;
    rig(&p.rig, p.library.channels as usize)?;
    let (u, u_cont) = policy(&p.policy, &p.inference, &p.library)?;
    control(&p.control)?;
    if let Some(sk) = &p.skeleton {
        skeleton(sk, p.library.channels as usize)?;
    }
    let (tone_u, tone_u_cont) = match &p.styles {
        Some(st) => styles(st, &p.policy)?,
        None => (I16Table::EMPTY, I16Table::EMPTY),
    };
    let (label_u, label_u_cont) = match &p.labels {
        Some(lb) => labels(lb, &p.policy, &p.library)?,
        None => (I16Table::EMPTY, I16Table::EMPTY),
    };
    Ok(Validated {
        crf,
        u,
        u_cont,
        tone_u,
        tone_u_cont,
        label_u,
        label_u_cont,
    })
}

/// The pieces of `s` between `'\n'`s, as `str::split('\n')` gives them, found byte by byte:
/// `split`'s search links about 700 bytes of code, and the boards' firmware is within a few
/// hundred bytes of its budget.
struct Lines<'a>(Option<&'a [u8]>);

impl<'a> Iterator for Lines<'a> {
    type Item = &'a [u8];

    // Not inlined: one small loop rather than one per caller.
    #[inline(never)]
    fn next(&mut self) -> Option<&'a [u8]> {
        let s = self.0?;
        let mut i = 0;
        while i < s.len() && s[i] != b'\n' {
            i += 1;
        }
        self.0 = s.get(i + 1..);
        Some(&s[..i])
    }
}

/// Whether `x` is in `codes`: `contains` on bytes links a 338-byte `memchr`.
#[allow(clippy::manual_contains)]
fn seen(codes: &[u8], x: u8) -> bool {
    codes.iter().any(|&y| y == x)
}

/// [`Lines`] of `s`.
fn lines(s: &str) -> Lines<'_> {
    Lines(Some(s.as_bytes()))
}

/// `names` split on `'\n'` holds exactly `n` distinct non-empty names, none equal to
/// `reserved`; otherwise the index of the first bad one (`n` when there are more).
fn names_ok(names: &str, n: usize, reserved: &str) -> Result<(), u32> {
    let mut it = lines(names);
    let reserved = reserved.as_bytes();
    for k in 0..n {
        let name = it.next().ok_or(k as u32)?;
        if name.is_empty() || name == reserved || lines(names).take(k).any(|x| x == name) {
            return Err(k as u32);
        }
    }
    match it.next() {
        Some(_) => Err(n as u32),
        None => Ok(()),
    }
}

/// The labels section: the label count, names and cost; `labels.segments` is the increasing
/// list of exactly the segments whose `library.labels` byte is not 0 (each at most L, each with
/// a stroke, at most [`MAX_LABELLED`](crate::policy::MAX_LABELLED)); value tables of L
/// times the policy's shapes; E x N entry records, each frame at most its segment's stroke.
fn labels<'a>(
    lb: &LabelsSection<'a>,
    policy: &PolicySection<'a>,
    lib: &LibrarySection<'_>,
) -> Result<(I16Table<'a>, I16Table<'a>), BlobError> {
    let l = lb.labels as usize;
    count(
        l,
        crate::policy::MAX_LABELS,
        Field::LabelCount,
        BlobError::TooManyLabels { found: l as u32 },
    )?;
    names_ok(lb.names, l, "").map_err(|label| BlobError::BadLabelNames { label })?;
    if !(lb.semantic_cost.is_finite() && (0.0..=MAX_VARIETY_COST).contains(&lb.semantic_cost)) {
        return Err(BlobError::BadControl {
            field: Field::SemanticCost,
        });
    }
    if lb.segments.len() % 2 != 0 {
        return Err(BlobError::TableLength {
            field: Field::LabelSegments,
            expected: lb.segments.len() + 1,
            found: lb.segments.len(),
        });
    }
    let n = lb.segments.len() / 2;
    let segs = lib.segments as usize;
    let mut k = 0usize;
    for seg in 0..segs {
        let lab = lib.labels.get(seg).copied().unwrap_or(0) as usize;
        if lab == 0 {
            continue;
        }
        let stroke = u16_at(lib.strokes, seg).unwrap_or(NO_STROKE);
        if lab > l
            || stroke == NO_STROKE
            || k >= crate::policy::MAX_LABELLED
            || u16_at(lb.segments, k) != Some(seg as u16)
        {
            return Err(BlobError::BadLabelledSegment {
                segment: seg as u32,
            });
        }
        k += 1;
    }
    if k != n {
        return Err(BlobError::BadLabelledSegment {
            segment: segs as u32,
        });
    }
    let s = policy.states as usize;
    let e = policy.exit_points as usize;
    let u = i16_table(Field::LabelU, &lb.u, l * segs * s)?;
    let uc = i16_table(Field::LabelUCont, &lb.u_cont, l * e * s)?;
    length(Field::LabelEntries, lb.entries, e * n, ENTRY_RECORD_BYTES)?;
    if !scale_ok(lb.entry_cost_scale) {
        return Err(BlobError::NotFinite {
            field: Field::LabelEntries,
        });
    }
    for (i, r) in lb.entries.chunks_exact(ENTRY_RECORD_BYTES).enumerate() {
        let frame = u16::from_le_bytes([r[0], r[1]]);
        let seg = u16_at(lb.segments, i % n.max(1)).unwrap_or(0) as usize;
        if frame > u16_at(lib.strokes, seg).unwrap_or(0) {
            return Err(BlobError::EntryAfterStroke { entry: i as u32 });
        }
    }
    Ok((u, uc))
}

/// The styles section: a tone count within the capacity, one distinct non-empty name per tone
/// (none `neutral`), and value tables of `tones` times the policy's shapes.
fn styles<'a>(
    st: &StylesSection<'a>,
    policy: &PolicySection<'a>,
) -> Result<(I16Table<'a>, I16Table<'a>), BlobError> {
    let m = st.tones as usize;
    count(
        m,
        crate::policy::MAX_TONES,
        Field::Tones,
        BlobError::TooManyTones { found: m as u32 },
    )?;
    names_ok(st.names, m, "neutral").map_err(|tone| BlobError::BadToneNames { tone })?;
    let s = policy.states as usize;
    let u = i16_table(Field::ToneU, &st.u, m * policy.segments as usize * s)?;
    let uc = i16_table(
        Field::ToneUCont,
        &st.u_cont,
        m * policy.exit_points as usize * s,
    )?;
    Ok((u, uc))
}

/// A count in `1..=max`.
fn count(n: usize, max: usize, field: Field, too_large: BlobError) -> Result<usize, BlobError> {
    match n {
        0 => Err(BlobError::ZeroCount { field }),
        n if n > max => Err(too_large),
        n => Ok(n),
    }
}

/// `bytes` must be `records * size` long.
fn length(field: Field, bytes: &[u8], records: usize, size: usize) -> Result<(), BlobError> {
    // Dimensions are bounded by the capacities, so this cannot overflow on 32-bit targets.
    let expected = records.saturating_mul(size);
    if bytes.len() == expected {
        Ok(())
    } else {
        Err(BlobError::TableLength {
            field,
            expected,
            found: bytes.len(),
        })
    }
}

/// A scale whose largest multiple of an `i16` is finite.
fn scale_ok(scale: f32) -> bool {
    (scale * 32768.0).is_finite()
}

fn i16_table<'a>(field: Field, s: &I16Section<'a>, len: usize) -> Result<I16Table<'a>, BlobError> {
    length(field, s.bytes, len, 2)?;
    if !scale_ok(s.scale) {
        return Err(BlobError::NotFinite { field });
    }
    I16Table::new(s.bytes, s.scale, len).ok_or(BlobError::NotFinite { field })
}

fn front_end(f: &FrontEndSection) -> Result<(), BlobError> {
    // The settings check alone: no front-end is built (it would take ~9 KiB of stack).
    f.config().validate().map_err(BlobError::FrontEnd)
}

fn inference<'a>(p: &InferenceSection<'a>) -> Result<CrfWeights<'a>, BlobError> {
    let s = p.states as usize;
    let k = p.clusters as usize;
    let w = p.window as usize;
    count(
        s,
        MAX_STATES,
        Field::States,
        BlobError::StateCountTooLarge { found: s as u32 },
    )?;
    count(
        k,
        MAX_CLUSTERS,
        Field::Clusters,
        BlobError::ClusterCountTooLarge { found: k as u32 },
    )?;
    count(
        w,
        MAX_WINDOW,
        Field::Window,
        BlobError::WindowTooLarge { found: w as u32 },
    )?;
    length(Field::Gmm, p.gmm, k, GMM_RECORD_BYTES)?;
    if !p.gmm.chunks_exact(4).all(|c| {
        c.first_chunk::<4>()
            .is_some_and(|b| f32::from_le_bytes(*b).is_finite())
    }) {
        return Err(BlobError::NotFinite { field: Field::Gmm });
    }
    let init = i16_table(Field::CrfInit, &p.crf_init, s)?;
    let trans = i16_table(Field::CrfTrans, &p.crf_trans, s * s)?;
    let obs = i16_table(Field::CrfObs, &p.crf_obs, s * w * k)?;
    // Cannot fail after the checks above; mapped rather than unwrapped.
    CrfWeights::new(s, k, w, init, trans, obs).ok_or(BlobError::TableLength {
        field: Field::CrfObs,
        expected: 2 * s * w * k,
        found: p.crf_obs.bytes.len(),
    })
}

fn library(l: &LibrarySection<'_>) -> Result<(), BlobError> {
    let ch = l.channels as usize;
    let frames = l.frames as usize;
    let segs = l.segments as usize;
    count(
        ch,
        MAX_CHANNELS,
        Field::Channels,
        BlobError::TooManyChannels { found: ch as u32 },
    )?;
    if !(l.fps.is_finite() && l.fps > 0.0 && l.fps <= MAX_FPS) {
        return Err(BlobError::BadFrameRate);
    }
    count(
        frames,
        MAX_FRAMES,
        Field::Frames,
        BlobError::TooManyFrames { found: l.frames },
    )?;
    count(
        segs,
        MAX_SEGMENTS,
        Field::Segments,
        BlobError::TooManySegments { found: segs as u32 },
    )?;
    length(Field::SegStart, l.seg_start, segs, 4)?;
    length(Field::SegLen, l.seg_len, segs, 2)?;
    length(
        Field::FrameScales,
        l.frame_scales,
        ch,
        FRAME_SCALE_RECORD_BYTES,
    )?;
    length(Field::FrameValues, l.frame_values, frames * ch, 2)?;
    length(Field::Strokes, l.strokes, segs, 2)?;
    length(Field::Labels, l.labels, segs, 1)?;
    length(Field::Continues, l.continues, segs, 1)?;
    length(Field::Beats, l.beats, frames.div_ceil(8), 1)?;
    length(Field::Calm, l.calm, frames.div_ceil(8), 1)?;
    length(Field::Energy, l.energy, segs, 1)?;
    length(Field::Peaks, l.peaks, frames.div_ceil(8), 1)?;
    if l.groups.len() % GROUP_RECORD_BYTES != 0 {
        return Err(BlobError::TableLength {
            field: Field::Groups,
            expected: l.groups.len() - l.groups.len() % GROUP_RECORD_BYTES,
            found: l.groups.len(),
        });
    }
    for c in 0..ch {
        let (scale, offset) = (
            f32_at(l.frame_scales, 2 * c).unwrap_or(f32::NAN),
            f32_at(l.frame_scales, 2 * c + 1).unwrap_or(f32::NAN),
        );
        if !(scale_ok(scale)
            && offset.is_finite()
            && (offset.abs() + scale.abs() * 32768.0).is_finite())
        {
            return Err(BlobError::NotFinite {
                field: Field::FrameScales,
            });
        }
    }
    for s in 0..segs {
        let segment = s as u32;
        let start = u32_at(l.seg_start, s).unwrap_or(u32::MAX) as u64;
        let len = u16_at(l.seg_len, s).unwrap_or(0);
        if len == 0 {
            return Err(BlobError::EmptySegment { segment });
        }
        if start + len as u64 > l.frames as u64 {
            return Err(BlobError::SegmentOutOfFrames { segment });
        }
        let stroke = u16_at(l.strokes, s).unwrap_or(NO_STROKE);
        if stroke != NO_STROKE && stroke >= len {
            return Err(BlobError::StrokeOutOfRange { segment });
        }
    }
    for s in 0..segs {
        match l.continues.get(s).copied().unwrap_or(0) {
            0 => {}
            1 => {
                let end = u32_at(l.seg_start, s).unwrap_or(0) as u64
                    + u16_at(l.seg_len, s).unwrap_or(0) as u64;
                let next = u32_at(l.seg_start, s + 1).map(u64::from);
                if next != Some(end) {
                    return Err(BlobError::BadContinuation { segment: s as u32 });
                }
            }
            _ => return Err(BlobError::BadContinuation { segment: s as u32 }),
        }
    }
    let mut free = 0usize;
    for g in 0..l.groups.len() / GROUP_RECORD_BYTES {
        let bad = BlobError::BadGroup { group: g as u32 };
        let r = record::<GROUP_RECORD_BYTES>(l.groups, g).ok_or(bad)?;
        let first = u16::from_le_bytes([r[0], r[1]]) as usize;
        if first < free || first + 3 > ch || r[2] as usize >= super::skeleton::EULER_ORDERS.len() {
            return Err(bad);
        }
        free = first + 3;
    }
    Ok(())
}

fn rig(r: &RigSection<'_>, channels: usize) -> Result<(), BlobError> {
    // The rule of `ServoRig::new`, so a loaded blob always builds a rig.
    if validate_period(r.period_us).is_err() {
        return Err(BlobError::BadPwmPeriod);
    }
    length(
        Field::Calibration,
        r.calibration,
        channels,
        CALIBRATION_RECORD_BYTES,
    )?;
    for (ch, rec) in r
        .calibration
        .chunks_exact(CALIBRATION_RECORD_BYTES)
        .enumerate()
    {
        let cal = rec
            .first_chunk::<CALIBRATION_RECORD_BYTES>()
            .map(calibration_from_record);
        if let Some(Err(error)) = cal.map(|c| c.validate()) {
            return Err(BlobError::BadCalibration {
                channel: ch as u32,
                error,
            });
        }
    }
    let names = lines(r.channel_names).count();
    if names != channels {
        return Err(BlobError::ChannelNameCount {
            expected: channels as u32,
            found: names as u32,
        });
    }
    Ok(())
}

fn exit_at(exits: &[u8], e: usize) -> (u16, u16) {
    match record::<EXIT_RECORD_BYTES>(exits, e) {
        Some(r) => (
            u16::from_le_bytes([r[0], r[1]]),
            u16::from_le_bytes([r[2], r[3]]),
        ),
        None => (u16::MAX, u16::MAX),
    }
}

fn policy<'a>(
    p: &PolicySection<'a>,
    inf: &InferenceSection<'_>,
    lib: &LibrarySection<'_>,
) -> Result<(I16Table<'a>, I16Table<'a>), BlobError> {
    if p.states != inf.states {
        return Err(BlobError::StateCountMismatch {
            inference: inf.states as u32,
            policy: p.states as u32,
        });
    }
    if p.segments != lib.segments {
        return Err(BlobError::SegmentCountMismatch {
            library: lib.segments as u32,
            policy: p.segments as u32,
        });
    }
    let s = p.states as usize;
    let segs = p.segments as usize;
    let n = p.exit_points as usize;
    count(
        n,
        MAX_EXITS,
        Field::ExitPoints,
        BlobError::TooManyExits { found: n as u32 },
    )?;
    if !(p.discount.is_finite() && (0.0..=1.0).contains(&p.discount)) {
        return Err(BlobError::BadDiscount);
    }
    let u = i16_table(Field::U, &p.u, segs * s)?;
    let u_cont = i16_table(Field::UCont, &p.u_cont, n * s)?;
    length(Field::Exits, p.exits, n, EXIT_RECORD_BYTES)?;
    length(Field::SuccOffsets, p.succ_offsets, n + 1, 4)?;
    let seg_len = |seg: usize| u16_at(lib.seg_len, seg).unwrap_or(0);

    // Exit points: in range, strictly increasing by (segment, frame).
    let mut prev: Option<(u16, u16)> = None;
    for e in 0..n {
        let (seg, frame) = exit_at(p.exits, e);
        let exit = e as u32;
        if seg as usize >= segs {
            return Err(BlobError::ExitSegmentOutOfRange {
                exit,
                segment: seg as u32,
            });
        }
        if frame >= seg_len(seg as usize) {
            return Err(BlobError::ExitFrameOutOfRange {
                exit,
                frame: frame as u32,
            });
        }
        if prev.is_some_and(|q| q >= (seg, frame)) {
            return Err(BlobError::ExitsNotSorted { exit });
        }
        prev = Some((seg, frame));
    }
    // Every segment ends in an exit point: its last exit is at its last frame.
    let mut e = 0;
    for seg in 0..segs {
        let mut last = None;
        while e < n && exit_at(p.exits, e).0 as usize == seg {
            last = Some(exit_at(p.exits, e).1);
            e += 1;
        }
        if last != Some(seg_len(seg).wrapping_sub(1)) {
            return Err(BlobError::MissingEndExit {
                segment: seg as u32,
            });
        }
    }

    // Successor lists: offsets from 0, never decreasing, ending at the entry count.
    let off = |i: usize| u32_at(p.succ_offsets, i).unwrap_or(u32::MAX);
    if off(0) != 0 {
        return Err(BlobError::SuccessorOffsetsNotMonotone { exit: 0 });
    }
    for i in 1..=n {
        if off(i) < off(i - 1) {
            return Err(BlobError::SuccessorOffsetsNotMonotone { exit: i as u32 });
        }
    }
    let entries = off(n) as u64;
    if p.succ.len() as u64 != entries * SUCCESSOR_RECORD_BYTES as u64 {
        return Err(BlobError::TableLength {
            field: Field::Succ,
            expected: usize::try_from(entries * SUCCESSOR_RECORD_BYTES as u64)
                .unwrap_or(usize::MAX),
            found: p.succ.len(),
        });
    }
    if !scale_ok(p.succ_cost_scale) {
        return Err(BlobError::NotFinite { field: Field::Succ });
    }
    for (i, c) in p.succ.chunks_exact(SUCCESSOR_RECORD_BYTES).enumerate() {
        let seg = u16::from_le_bytes([c[0], c[1]]);
        if seg as usize >= segs {
            return Err(BlobError::SuccessorSegmentOutOfRange {
                entry: i as u32,
                segment: seg as u32,
            });
        }
    }
    let succ_seg = |i: usize| u16_at(p.succ, 2 * i).unwrap_or(u16::MAX);
    for e in 0..n {
        let (a, b) = (off(e) as usize, off(e + 1) as usize);
        if (a + 1..b).any(|i| succ_seg(i) <= succ_seg(i - 1)) {
            return Err(BlobError::SuccessorsNotSorted { exit: e as u32 });
        }
        let (seg, frame) = exit_at(p.exits, e);
        if frame == seg_len(seg as usize).wrapping_sub(1) && a == b {
            return Err(BlobError::NoSuccessors { exit: e as u32 });
        }
    }
    Ok((u, u_cont))
}

fn control(c: &ControlSection) -> Result<(), BlobError> {
    let bad = |field| Err(BlobError::BadControl { field });
    let cost_ok = |v: f32| v.is_finite() && (0.0..=MAX_VARIETY_COST).contains(&v);
    if c.sync_to_onsets > 1 {
        return bad(Field::SyncToOnsets);
    }
    if c.onset_window_ms > MAX_ONSET_WINDOW_MS {
        return bad(Field::OnsetWindow);
    }
    if c.max_wait_ms > MAX_WAIT_MS {
        return bad(Field::MaxWait);
    }
    if !cost_ok(c.recency_cost) {
        return bad(Field::Recency);
    }
    if !cost_ok(c.usage_cost) {
        return bad(Field::Usage);
    }
    if c.blend_ms > MAX_BLEND_MS {
        return bad(Field::Blend);
    }
    if c.beat_hold_ms > MAX_BEAT_HOLD_MS {
        return bad(Field::BeatHold);
    }
    if c.defer_cut_ms > MAX_DEFER_CUT_MS {
        return bad(Field::DeferCut);
    }
    if c.rest_ms > MAX_REST_MS {
        return bad(Field::RestAfter);
    }
    if !cost_ok(c.rest_cost) {
        return bad(Field::RestCost);
    }
    if !cost_ok(c.energy_cost) {
        return bad(Field::EnergyCost);
    }
    Ok(())
}

fn all_finite(bytes: &[u8]) -> bool {
    bytes.chunks_exact(4).all(|c| {
        c.first_chunk::<4>()
            .is_some_and(|b| f32::from_le_bytes(*b).is_finite())
    })
}

fn skeleton(s: &SkeletonSection<'_>, rig_channels: usize) -> Result<(), BlobError> {
    let j = s.joints as usize;
    count(
        j,
        MAX_JOINTS,
        Field::Joints,
        BlobError::TooManyJoints { found: j as u32 },
    )?;
    let names = lines(s.joint_names).count();
    if names != j {
        return Err(BlobError::JointNameCount {
            expected: j as u32,
            found: names as u32,
        });
    }
    length(Field::Parents, s.parents, j, 2)?;
    length(Field::Offsets, s.offsets, j, 12)?;
    length(Field::ChannelCounts, s.channel_counts, j, 1)?;
    let n: usize = s.channel_counts.iter().map(|&c| c as usize).sum();
    length(Field::ChannelCodes, s.channel_codes, n, 1)?;
    length(Field::Rest, s.rest, n, 4)?;
    let sites = s.end_sites.len() / END_SITE_RECORD_BYTES;
    length(Field::EndSites, s.end_sites, sites, END_SITE_RECORD_BYTES)?;
    length(Field::Drives, s.drives, rig_channels, DRIVE_RECORD_BYTES)?;
    if !all_finite(s.offsets) {
        return Err(BlobError::NotFinite {
            field: Field::Offsets,
        });
    }
    if !all_finite(s.rest) {
        return Err(BlobError::NotFinite { field: Field::Rest });
    }
    let parent = |k: usize| match u16_at(s.parents, k) {
        Some(ROOT_PARENT) | None => None,
        Some(p) => Some(p as usize),
    };
    // Depth-first order: each joint's parent precedes it and is the previous joint or one of
    // its ancestors (the stack rule of a pre-order walk). The walk up is bounded by `k`
    // because every parent precedes its child.
    for k in 0..j {
        let Some(p) = parent(k) else { continue };
        let mut ok = false;
        if p < k {
            let mut cur = Some(k - 1);
            while let Some(c) = cur {
                if c <= p {
                    ok = c == p;
                    break;
                }
                cur = parent(c).filter(|&q| q < c);
            }
        }
        if !ok {
            return Err(BlobError::BadParent { joint: k as u32 });
        }
    }
    let mut start = 0usize;
    for (k, &c) in s.channel_counts.iter().enumerate() {
        let codes = s
            .channel_codes
            .get(start..start + c as usize)
            .unwrap_or(&[]);
        let bad = c > 6
            || codes
                .iter()
                .enumerate()
                .any(|(i, &x)| x > 5 || seen(&codes[..i], x));
        if bad {
            return Err(BlobError::BadJointChannels { joint: k as u32 });
        }
        start += c as usize;
    }
    let mut prev: Option<u16> = None;
    for (i, r) in s.end_sites.chunks_exact(END_SITE_RECORD_BYTES).enumerate() {
        let joint = u16::from_le_bytes([r[0], r[1]]);
        if joint as usize >= j || prev.is_some_and(|p| p >= joint) {
            return Err(BlobError::BadEndSite { entry: i as u32 });
        }
        if !all_finite(&r[2..]) {
            return Err(BlobError::NotFinite {
                field: Field::EndSites,
            });
        }
        prev = Some(joint);
    }
    for ch in 0..rig_channels {
        let d = record::<DRIVE_RECORD_BYTES>(s.drives, ch).and_then(Drive::from_record);
        let ok = d.is_some_and(|d| {
            let (joint, top) = (d.joint as usize, d.chain_top as usize);
            // The chain top is the joint or one of its ancestors.
            let mut cur = Some(joint);
            while let Some(c) = cur {
                if c == top {
                    break;
                }
                cur = parent(c).filter(|&q| q < c);
            }
            joint < j && cur == Some(top)
        });
        if !ok {
            return Err(BlobError::BadDrive { channel: ch as u32 });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_are_the_pieces_split_gives() {
        for s in ["", "\n", "a", "a\n", "\na", "ab\ncd\n\nef", "\n\n", "é\nü"] {
            let ours: heapless::Vec<&[u8], 8> = lines(s).collect();
            let theirs: heapless::Vec<&[u8], 8> = s.split('\n').map(str::as_bytes).collect();
            assert_eq!(ours, theirs, "{s:?}");
        }
        assert_eq!(names_ok("a\nb", 2, "x"), Ok(()));
        assert_eq!(names_ok("a\na", 2, "x"), Err(1));
        assert_eq!(names_ok("a\nx", 2, "x"), Err(1));
        assert_eq!(names_ok("a\n", 2, "x"), Err(1));
        assert_eq!(names_ok("a\nb\nc", 2, "x"), Err(2));
        assert_eq!(names_ok("a", 2, "x"), Err(1));
    }
}
