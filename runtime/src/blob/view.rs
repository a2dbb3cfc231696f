//! The validated blob and its accessors: [`Blob::parse`] (header, CRC, postcard decoding of
//! each section in turn, then [`validate`](super::validate)) and the infallible views of every
//! section (docs/blob-format.md, section 3).
//!
//! Accessors that take an index return `None` (or `0.0` for scalar table lookups) when the
//! *caller's* index is out of range; every index stored in the blob was checked at load.

use core::num::NonZeroU8;

use super::error::BlobError;
use super::field::Section;
use super::header::Header;
use super::payload::*;
use super::records::{
    calibration_from_record, f32_at, gmm_from_record, i16_at, record, u16_at, u32_at,
};
use super::skeleton::SkeletonView;
use super::validate;
use crate::follow::VoiceFollow;
use crate::inference::{CrfWeights, GmmComponent, I16Table, MAX_CLUSTERS};
use crate::policy::DecisionTiming;
use crate::policy::Variety;
#[cfg(doc)]
use crate::prosody::FrontEnd;
use crate::prosody::ProsodyConfig;
use crate::rig::ChannelCal;

/// Encoded size of each payload section in bytes (they add up to the payload length).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SectionSizes {
    /// `front_end`.
    pub front_end: usize,
    /// `inference`.
    pub inference: usize,
    /// `policy`.
    pub policy: usize,
    /// `control`.
    pub control: usize,
    /// `library`.
    pub library: usize,
    /// `rig`.
    pub rig: usize,
    /// `skeleton` (1 byte when absent: postcard's `None`).
    pub skeleton: usize,
    /// `styles` (1 byte when absent).
    pub styles: usize,
    /// `labels` (1 byte when absent).
    pub labels: usize,
}

/// An exit point: a frame of a segment where the policy may switch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExitPoint {
    /// Segment index.
    pub segment: u16,
    /// Frame within the segment.
    pub frame: u16,
}

/// One allowed successor of an exit point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Successor {
    /// Segment to enter.
    pub segment: u16,
    /// State-independent successor cost S(source, segment) (dequantized).
    pub cost: f32,
}

/// The successors of one exit point, in stored order.
#[derive(Clone, Debug)]
pub struct Successors<'a> {
    chunks: core::slice::ChunksExact<'a, u8>,
    scale: f32,
}

impl Successors<'_> {
    fn decode(&self, c: &[u8]) -> Option<Successor> {
        match *c {
            [a, b, c, d] => Some(Successor {
                segment: u16::from_le_bytes([a, b]),
                cost: i16::from_le_bytes([c, d]) as f32 * self.scale,
            }),
            _ => None,
        }
    }
}

impl Iterator for Successors<'_> {
    type Item = Successor;

    fn next(&mut self) -> Option<Successor> {
        let c = self.chunks.next()?;
        self.decode(c)
    }

    fn nth(&mut self, n: usize) -> Option<Successor> {
        let c = self.chunks.nth(n)?;
        self.decode(c)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.chunks.size_hint()
    }
}

impl ExactSizeIterator for Successors<'_> {}

/// A library segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SegmentInfo {
    /// Index of its first frame in the frame table.
    pub start: u32,
    /// Length in frames (>= 1).
    pub len: u16,
    /// Stroke frame within the segment, if it has one.
    pub stroke: Option<u16>,
    /// Semantic label, if it has one.
    pub label: Option<NonZeroU8>,
}

/// The GMM components of a blob, as [`memberships`](crate::inference::memberships) takes them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GmmComponents {
    comps: [GmmComponent; MAX_CLUSTERS],
    len: usize,
}

impl GmmComponents {
    /// The components.
    pub fn as_slice(&self) -> &[GmmComponent] {
        &self.comps[..self.len.min(MAX_CLUSTERS)]
    }
}

/// A validated policy blob borrowing its bytes. See the module docs for the guarantees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blob<'a> {
    header: Header,
    sizes: SectionSizes,
    payload: Payload<'a>,
    crf: CrfWeights<'a>,
    u: I16Table<'a>,
    u_cont: I16Table<'a>,
    tone_u: I16Table<'a>,
    tone_u_cont: I16Table<'a>,
    label_u: I16Table<'a>,
    label_u_cont: I16Table<'a>,
}

/// Bit `f` of a per-frame bitset (bit `f % 8` of byte `f / 8`; false out of range).
fn frame_bit(bits: &[u8], f: usize) -> bool {
    bits.get(f / 8).is_some_and(|b| b & (1 << (f % 8)) != 0)
}

impl<'a> Blob<'a> {
    /// Checks `bytes` completely (header, CRC, decoding, every field) and returns the
    /// validated blob, or the first rule broken. Never panics, never allocates.
    pub fn parse(bytes: &'a [u8]) -> Result<Self, BlobError> {
        let (header, body) = Header::check(bytes)?;
        let (payload, sizes) = decode(body)?;
        let v = validate::payload(&payload)?;
        Ok(Self {
            header,
            sizes,
            payload,
            crf: v.crf,
            u: v.u,
            u_cont: v.u_cont,
            tone_u: v.tone_u,
            tone_u_cont: v.tone_u_cont,
            label_u: v.label_u,
            label_u_cont: v.label_u_cont,
        })
    }

    // --- the whole blob ---

    /// The header.
    pub fn header(&self) -> Header {
        self.header
    }

    /// Encoded size of each section.
    pub fn section_sizes(&self) -> SectionSizes {
        self.sizes
    }

    /// The decoded (and validated) sections, for tools that print or re-encode them.
    pub fn payload(&self) -> &Payload<'a> {
        &self.payload
    }

    // --- front_end ---

    /// The front-end configuration (accepted by [`FrontEnd::new`]).
    pub fn prosody_config(&self) -> ProsodyConfig {
        self.payload.front_end.config()
    }

    // --- inference ---

    /// Hidden states S (1..=[`MAX_STATES`](crate::inference::MAX_STATES)).
    pub fn states(&self) -> usize {
        self.payload.inference.states as usize
    }

    /// Prosody clusters K (1..=[`MAX_CLUSTERS`]).
    pub fn clusters(&self) -> usize {
        self.payload.inference.clusters as usize
    }

    /// CRF window W (1..=[`MAX_WINDOW`](crate::inference::MAX_WINDOW)).
    pub fn window(&self) -> usize {
        self.payload.inference.window as usize
    }

    /// GMM component `k` (`None` if `k >= clusters()`).
    pub fn gmm_component(&self, k: usize) -> Option<GmmComponent> {
        record::<GMM_RECORD_BYTES>(self.payload.inference.gmm, k).map(gmm_from_record)
    }

    /// All GMM components, decoded.
    pub fn gmm(&self) -> GmmComponents {
        let mut g = GmmComponents {
            comps: [GmmComponent::default(); MAX_CLUSTERS],
            len: self.clusters().min(MAX_CLUSTERS),
        };
        for (c, r) in g
            .comps
            .iter_mut()
            .zip(self.payload.inference.gmm.chunks_exact(GMM_RECORD_BYTES))
        {
            if let Some(r) = r.first_chunk::<GMM_RECORD_BYTES>() {
                *c = gmm_from_record(r);
            }
        }
        g
    }

    /// The CRF weights.
    pub fn crf_weights(&self) -> CrfWeights<'a> {
        self.crf
    }

    // --- policy ---

    /// Library segments (1..=[`MAX_SEGMENTS`](super::MAX_SEGMENTS)).
    pub fn segments(&self) -> usize {
        self.payload.policy.segments as usize
    }

    /// Exit points (1..=[`MAX_EXITS`](super::MAX_EXITS)).
    pub fn exit_points(&self) -> usize {
        self.payload.policy.exit_points as usize
    }

    /// Successor entries over all exit points.
    pub fn successor_entries(&self) -> usize {
        self.payload.policy.succ.len() / SUCCESSOR_RECORD_BYTES
    }

    /// The value iteration's discount.
    pub fn discount(&self) -> f32 {
        self.payload.policy.discount
    }

    /// U(segment, state): cost-to-go of entering `segment` in `state` (0 out of range).
    #[inline]
    pub fn u(&self, segment: usize, state: usize) -> f32 {
        if segment >= self.segments() || state >= self.states() {
            return 0.0;
        }
        self.u.get(segment * self.states() + state)
    }

    /// U_cont(exit, state): cost-to-go of continuing past `exit` in `state` (0 out of range).
    #[inline]
    pub fn u_cont(&self, exit: usize, state: usize) -> f32 {
        if exit >= self.exit_points() || state >= self.states() {
            return 0.0;
        }
        // Bounded by the capacities, so the index arithmetic cannot overflow.
        self.u_cont.get(exit * self.states() + state)
    }

    /// `b . U(segment)` over the first `states()` entries of `b`, read as one row (the same
    /// number as summing `b[s] * u(segment, s)` in order); 0 out of range.
    #[inline]
    pub fn u_dot(&self, segment: usize, b: &[f32]) -> f32 {
        let s = self.states();
        if segment >= self.segments() {
            return 0.0;
        }
        self.u.dot(segment * s, &b[..b.len().min(s)])
    }

    /// `b . U_cont(exit)`, like [`u_dot`](Self::u_dot).
    #[inline]
    pub fn u_cont_dot(&self, exit: usize, b: &[f32]) -> f32 {
        let s = self.states();
        if exit >= self.exit_points() {
            return 0.0;
        }
        self.u_cont.dot(exit * s, &b[..b.len().min(s)])
    }

    /// Exit point `e`.
    pub fn exit(&self, e: usize) -> Option<ExitPoint> {
        let r = record::<EXIT_RECORD_BYTES>(self.payload.policy.exits, e)?;
        Some(ExitPoint {
            segment: u16::from_le_bytes([r[0], r[1]]),
            frame: u16::from_le_bytes([r[2], r[3]]),
        })
    }

    /// Whether exit point `e` is at its segment's last frame (no continuing there).
    pub fn exit_is_end(&self, e: usize) -> bool {
        match self.exit(e) {
            Some(x) => self
                .segment(x.segment as usize)
                .is_some_and(|s| x.frame == s.len - 1),
            None => false,
        }
    }

    /// The exit points of `segment`: a range of exit indices in frame order, never empty for a
    /// segment in range (its last element is the segment's end exit). Binary search.
    pub fn exits_of(&self, segment: usize) -> core::ops::Range<usize> {
        let first = |seg: usize| {
            let (mut lo, mut hi) = (0usize, self.exit_points());
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                match self.exit(mid) {
                    Some(e) if (e.segment as usize) < seg => lo = mid + 1,
                    _ => hi = mid,
                }
            }
            lo
        };
        first(segment)..first(segment.saturating_add(1))
    }

    /// The exit point at `frame` of `segment`, if there is one (binary search).
    pub fn find_exit(&self, segment: u16, frame: u16) -> Option<usize> {
        let key = (segment, frame);
        let (mut lo, mut hi) = (0usize, self.exit_points());
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            let e = self.exit(mid)?;
            match (e.segment, e.frame).cmp(&key) {
                core::cmp::Ordering::Less => lo = mid + 1,
                core::cmp::Ordering::Greater => hi = mid,
                core::cmp::Ordering::Equal => return Some(mid),
            }
        }
        None
    }

    /// The allowed successors of exit point `exit` (empty if out of range).
    pub fn successors(&self, exit: usize) -> Successors<'a> {
        let p = &self.payload.policy;
        let range = (|| {
            let a = u32_at(p.succ_offsets, exit)? as usize;
            let b = u32_at(p.succ_offsets, exit.checked_add(1)?)? as usize;
            p.succ.get(
                a.checked_mul(SUCCESSOR_RECORD_BYTES)?..b.checked_mul(SUCCESSOR_RECORD_BYTES)?,
            )
        })();
        Successors {
            chunks: range.unwrap_or(&[]).chunks_exact(SUCCESSOR_RECORD_BYTES),
            scale: p.succ_cost_scale,
        }
    }

    /// Number of successors of exit point `exit` (0 if out of range).
    pub fn successor_count(&self, exit: usize) -> usize {
        self.successors(exit).len()
    }

    /// The `k`-th successor of exit point `exit`, in stored (segment) order; O(1).
    pub fn successor(&self, exit: usize, k: usize) -> Option<Successor> {
        self.successors(exit).nth(k)
    }

    // --- control ---

    /// When the controller decides (the `control` section).
    pub fn timing(&self) -> DecisionTiming {
        let c = &self.payload.control;
        DecisionTiming {
            sync_to_onsets: c.sync_to_onsets != 0,
            onset_window_ms: c.onset_window_ms as u32,
            max_wait_ms: c.max_wait_ms as u32,
            beat_hold_ms: c.beat_hold_ms as u32,
            defer_cut_ms: c.defer_cut_ms as u32,
        }
    }

    /// How the character follows the voice (the `control` section).
    pub fn follow(&self) -> VoiceFollow {
        let c = &self.payload.control;
        VoiceFollow {
            rest_ms: c.rest_ms as u32,
            rest_cost: c.rest_cost,
            energy_cost: c.energy_cost,
        }
    }

    /// How the controller varies its choices (the `control` section).
    pub fn variety(&self) -> Variety {
        let c = &self.payload.control;
        Variety {
            recency_cost: c.recency_cost,
            recency_ms: c.recency_ms as u32,
            usage_cost: c.usage_cost,
            usage_ms: c.usage_ms as u32,
        }
    }

    /// The player's inertialization time at cuts (ms).
    pub fn blend_ms(&self) -> u32 {
        self.payload.control.blend_ms as u32
    }

    // --- library ---

    /// Output channels (1..=[`MAX_CHANNELS`](super::MAX_CHANNELS)).
    pub fn channels(&self) -> usize {
        self.payload.library.channels as usize
    }

    /// Library frame rate (frames per second).
    pub fn fps(&self) -> f32 {
        self.payload.library.fps
    }

    /// Frames in the frame table (1..=[`MAX_FRAMES`](super::MAX_FRAMES)).
    pub fn frames(&self) -> usize {
        self.payload.library.frames as usize
    }

    /// Segment `s`.
    pub fn segment(&self, s: usize) -> Option<SegmentInfo> {
        let l = &self.payload.library;
        let stroke = u16_at(l.strokes, s)?;
        Some(SegmentInfo {
            start: u32_at(l.seg_start, s)?,
            len: u16_at(l.seg_len, s)?,
            stroke: (stroke != NO_STROKE).then_some(stroke),
            label: NonZeroU8::new(*l.labels.get(s)?),
        })
    }

    /// Whether segment `s + 1` continues segment `s` (stored right after it: the recorded
    /// successor); false out of range.
    pub fn continues(&self, s: usize) -> bool {
        self.payload.library.continues.get(s) == Some(&1)
    }

    /// Whether frame `f` of the frame table is a motion beat (false out of range).
    pub fn is_beat_frame(&self, f: usize) -> bool {
        frame_bit(self.payload.library.beats, f)
    }

    /// Whether frame `f` of the frame table is a stroke (`library.peaks`; false out of range).
    pub fn is_peak_frame(&self, f: usize) -> bool {
        frame_bit(self.payload.library.peaks, f)
    }

    /// Whether frame `f` of the frame table is calm (false out of range).
    pub fn is_calm_frame(&self, f: usize) -> bool {
        frame_bit(self.payload.library.calm, f)
    }

    /// Segment `s`'s energy (`library.energy`; 0 out of range).
    pub fn segment_energy(&self, s: usize) -> f32 {
        self.payload.library.energy.get(s).map_or(0.0, |&q| {
            q as i8 as f32 * (1.0 / super::format::ENERGY_SCALE)
        })
    }

    /// Rotation groups (records of `library.groups`).
    pub fn group_count(&self) -> usize {
        self.payload.library.groups.len() / GROUP_RECORD_BYTES
    }

    /// Rotation group `g`: its first channel and its Euler order (axis indices), `None` out of
    /// range.
    pub fn group(&self, g: usize) -> Option<(usize, [u8; 3])> {
        let r = record::<GROUP_RECORD_BYTES>(self.payload.library.groups, g)?;
        let order = *super::skeleton::EULER_ORDERS.get(r[2] as usize)?;
        Some((u16::from_le_bytes([r[0], r[1]]) as usize, order))
    }

    /// Value of channel `ch` at frame `f` of the frame table (degrees; 0 out of range).
    #[inline]
    pub fn frame(&self, ch: usize, f: usize) -> f32 {
        let l = &self.payload.library;
        let n = self.channels();
        if ch >= n {
            return 0.0;
        }
        let v = f
            .checked_mul(n)
            .and_then(|i| i.checked_add(ch))
            .and_then(|i| i16_at(l.frame_values, i));
        match (
            v,
            f32_at(l.frame_scales, 2 * ch),
            f32_at(l.frame_scales, 2 * ch + 1),
        ) {
            (Some(v), Some(scale), Some(offset)) => offset + scale * v as f32,
            _ => 0.0,
        }
    }

    /// Value of channel `ch` at frame `f` of segment `seg` (degrees; 0 out of range).
    #[inline]
    pub fn segment_value(&self, seg: usize, f: usize, ch: usize) -> f32 {
        self.table_frame(seg, f).map_or(0.0, |t| self.frame(ch, t))
    }

    /// Frame `f` of segment `seg` as an index into the frame table (`None` out of range).
    pub fn table_frame(&self, seg: usize, f: usize) -> Option<usize> {
        self.segment(seg)
            .filter(|s| f < s.len as usize)
            .map(|s| s.start as usize + f)
    }

    /// The pose at frame `f` of the frame table into `out` (as many channels as fit); returns
    /// the number of channels written (0 if `f` is out of range).
    pub fn pose(&self, f: usize, out: &mut [f32]) -> usize {
        if f >= self.frames() {
            return 0;
        }
        let n = self.channels().min(out.len());
        for (ch, o) in out.iter_mut().enumerate().take(n) {
            *o = self.frame(ch, f);
        }
        n
    }

    // --- rig ---

    /// The rig's name.
    pub fn rig_name(&self) -> &'a str {
        self.payload.rig.name
    }

    /// PWM period (microseconds; accepted by [`ServoRig::new`](crate::rig::ServoRig::new)).
    pub fn period_us(&self) -> f32 {
        self.payload.rig.period_us
    }

    /// Calibration of channel `ch` (passes [`ChannelCal::validate`]).
    pub fn calibration(&self, ch: usize) -> Option<ChannelCal> {
        record::<CALIBRATION_RECORD_BYTES>(self.payload.rig.calibration, ch)
            .map(calibration_from_record)
    }

    /// Name of channel `ch`.
    pub fn channel_name(&self, ch: usize) -> Option<&'a str> {
        self.channel_names().nth(ch)
    }

    /// Channel names in order (one per channel).
    pub fn channel_names(&self) -> core::str::Split<'a, char> {
        self.payload.rig.channel_names.split('\n')
    }

    // --- skeleton ---

    /// The library's skeleton and the rig channels' drives, if the blob carries them (host
    /// tools only; validated like every other section).
    pub fn skeleton(&self) -> Option<SkeletonView<'a>> {
        self.payload.skeleton.map(SkeletonView::new)
    }

    // --- styles ---

    /// Tones in the `styles` section (0 without one).
    pub fn tones(&self) -> usize {
        self.payload.styles.map_or(0, |s| s.tones as usize)
    }

    /// Tone names in order (empty without a `styles` section).
    pub fn tone_names(&self) -> core::str::Split<'a, char> {
        let names = match &self.payload.styles {
            Some(s) => s.names,
            // An iterator over nothing: `"".split` yields one empty item, so skip it.
            None => "",
        };
        let mut it = names.split('\n');
        if names.is_empty() {
            it.next();
        }
        it
    }

    /// The index of the tone named `name` (`None`: no such tone).
    pub fn tone_index(&self, name: &str) -> Option<usize> {
        self.tone_names().position(|n| n == name)
    }

    /// U^m(segment, state) of tone `tone` (0 out of range).
    #[inline]
    pub fn tone_u(&self, tone: usize, segment: usize, state: usize) -> f32 {
        if tone >= self.tones() || segment >= self.segments() || state >= self.states() {
            return 0.0;
        }
        // Bounded by the capacities, so the index arithmetic cannot overflow.
        self.tone_u
            .get((tone * self.segments() + segment) * self.states() + state)
    }

    /// `b . U^m(segment)` of tone `tone`, like [`u_dot`](Self::u_dot).
    #[inline]
    pub fn tone_u_dot(&self, tone: usize, segment: usize, b: &[f32]) -> f32 {
        let s = self.states();
        if tone >= self.tones() || segment >= self.segments() {
            return 0.0;
        }
        self.tone_u
            .dot((tone * self.segments() + segment) * s, &b[..b.len().min(s)])
    }

    /// `b . U_cont^m(exit)` of tone `tone`, like [`u_dot`](Self::u_dot).
    #[inline]
    pub fn tone_u_cont_dot(&self, tone: usize, exit: usize, b: &[f32]) -> f32 {
        let s = self.states();
        if tone >= self.tones() || exit >= self.exit_points() {
            return 0.0;
        }
        self.tone_u_cont
            .dot((tone * self.exit_points() + exit) * s, &b[..b.len().min(s)])
    }

    /// U_cont^m(exit, state) of tone `tone` (0 out of range).
    #[inline]
    pub fn tone_u_cont(&self, tone: usize, exit: usize, state: usize) -> f32 {
        if tone >= self.tones() || exit >= self.exit_points() || state >= self.states() {
            return 0.0;
        }
        self.tone_u_cont
            .get((tone * self.exit_points() + exit) * self.states() + state)
    }

    // --- labels ---

    /// Semantic labels L (0 without a `labels` section).
    pub fn labels(&self) -> usize {
        self.payload.labels.map_or(0, |l| l.labels as usize)
    }

    /// Label names in order (label `w` is `library.labels` value `w + 1`; empty without).
    pub fn label_names(&self) -> core::str::Split<'a, char> {
        let names = self.payload.labels.map_or("", |l| l.names);
        let mut it = names.split('\n');
        if names.is_empty() {
            it.next();
        }
        it
    }

    /// The index of the label named `name`.
    pub fn label_index(&self, name: &str) -> Option<usize> {
        self.label_names().position(|n| n == name)
    }

    /// Cost added to candidates that do not carry the waiting label (0 without labels).
    pub fn semantic_cost(&self) -> f32 {
        self.payload.labels.map_or(0.0, |l| l.semantic_cost)
    }

    /// How long a label may wait to be shown (ms; 0 without labels).
    pub fn label_timeout_ms(&self) -> u32 {
        self.payload.labels.map_or(0, |l| l.timeout_ms as u32)
    }

    /// Labelled segments N.
    pub fn labelled_count(&self) -> usize {
        self.payload.labels.map_or(0, |l| l.segments.len() / 2)
    }

    /// The `k`-th labelled segment (`None` out of range).
    pub fn labelled_segment(&self, k: usize) -> Option<usize> {
        u16_at(self.payload.labels?.segments, k).map(usize::from)
    }

    /// The label of segment `c`: `w + 1` for label `w`, 0 for none (and without a `labels`
    /// section, whatever `library.labels` holds).
    pub fn label_of(&self, c: usize) -> u8 {
        if self.payload.labels.is_none() {
            return 0;
        }
        self.payload.library.labels.get(c).copied().unwrap_or(0)
    }

    /// `b . U^w(segment)` of label `w` (0-based), like [`u_dot`](Self::u_dot).
    #[inline]
    pub fn label_u_dot(&self, w: usize, segment: usize, b: &[f32]) -> f32 {
        let s = self.states();
        if w >= self.labels() || segment >= self.segments() {
            return 0.0;
        }
        self.label_u
            .dot((w * self.segments() + segment) * s, &b[..b.len().min(s)])
    }

    /// `b . U_cont^w(exit)` of label `w`, like [`u_dot`](Self::u_dot).
    #[inline]
    pub fn label_u_cont_dot(&self, w: usize, exit: usize, b: &[f32]) -> f32 {
        let s = self.states();
        if w >= self.labels() || exit >= self.exit_points() {
            return 0.0;
        }
        self.label_u_cont
            .dot((w * self.exit_points() + exit) * s, &b[..b.len().min(s)])
    }

    /// The semantic entry from exit `exit` into the `k`-th labelled segment: its entry frame
    /// and cost (`None` out of range).
    pub fn entry(&self, exit: usize, k: usize) -> Option<(usize, f32)> {
        let l = self.payload.labels?;
        let n = l.segments.len() / 2;
        if k >= n {
            return None;
        }
        let r = record::<ENTRY_RECORD_BYTES>(l.entries, exit.checked_mul(n)?.checked_add(k)?)?;
        Some((
            u16::from_le_bytes([r[0], r[1]]) as usize,
            i16::from_le_bytes([r[2], r[3]]) as f32 * l.entry_cost_scale,
        ))
    }
}

/// Decodes the sections one after the other, recording their encoded sizes. Postcard encodes a
/// struct as the concatenation of its fields, so this is exactly `Payload`'s encoding.
fn decode(body: &[u8]) -> Result<(Payload<'_>, SectionSizes), BlobError> {
    fn take<'a, T: serde::Deserialize<'a>>(
        rest: &mut &'a [u8],
        section: Section,
    ) -> Result<(T, usize), BlobError> {
        let before = rest.len();
        let (v, r) =
            postcard::take_from_bytes::<T>(rest).map_err(|_| BlobError::Malformed { section })?;
        *rest = r;
        Ok((v, before - r.len()))
    }
    let mut rest = body;
    let (front_end, fe) = take(&mut rest, Section::FrontEnd)?;
    let (inference, inf) = take(&mut rest, Section::Inference)?;
    let (policy, pol) = take(&mut rest, Section::Policy)?;
    let (control, ctl) = take(&mut rest, Section::Control)?;
    let (library, lib) = take(&mut rest, Section::Library)?;
    let (rig, rg) = take(&mut rest, Section::Rig)?;
    let (skeleton, sk) = take(&mut rest, Section::Skeleton)?;
    let (styles, st) = take(&mut rest, Section::Styles)?;
    let (labels, lb) = take(&mut rest, Section::Labels)?;
    if !rest.is_empty() {
        return Err(BlobError::Malformed {
            section: Section::Labels,
        });
    }
    Ok((
        Payload {
            front_end,
            inference,
            policy,
            control,
            library,
            rig,
            skeleton,
            styles,
            labels,
        },
        SectionSizes {
            front_end: fe,
            inference: inf,
            policy: pol,
            control: ctl,
            library: lib,
            rig: rg,
            skeleton: sk,
            styles: st,
            labels: lb,
        },
    ))
}
