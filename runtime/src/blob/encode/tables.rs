//! The quantized tables: the inference layer ([`OwnedInference`]), the policy's value tables
//! and successor lists ([`OwnedPolicy`]), and the per-tone and per-label value tables
//! ([`OwnedStyles`], [`OwnedLabels`]). Every table is quantized by [`Quantization`], the
//! reader's own definition.

use alloc::string::String;
use alloc::vec::Vec;

use super::error::{fit, inconsistent, EncodeError};
use crate::blob::payload::*;
use crate::blob::quantize::{quantize_symmetric, Quantization};
use crate::blob::records::{gmm_from_record, gmm_record};
use crate::inference::{CrfWeights, GmmComponent, I16Table};

/// `{index: u16, cost: i16}` records of `rows`, the costs quantized together (symmetric over
/// their largest finite magnitude): the quantization and the bytes. `what` names the index for
/// errors.
fn records<'r>(
    rows: impl Iterator<Item = &'r (usize, f64)> + Clone,
    what: &'static str,
) -> Result<(Quantization, Vec<u8>), EncodeError> {
    let max = rows
        .clone()
        .map(|&(_, c)| c)
        .filter(|c| c.is_finite())
        .fold(0.0f64, |m, c| m.max(c.abs()));
    let q = Quantization::symmetric(max);
    let mut out = Vec::new();
    for &(index, cost) in rows {
        out.extend(fit::<u16>(what, index, "u16")?.to_le_bytes());
        out.extend(q.code(cost).to_le_bytes());
    }
    Ok((q, out))
}

/// An owned scaled `i16` table (`I16Section`).
#[derive(Clone, Debug, PartialEq)]
pub struct QTable {
    /// `2 * len` little-endian bytes.
    pub bytes: Vec<u8>,
    /// Value = `i16 * scale`.
    pub scale: f32,
}

impl QTable {
    /// Quantizes `w` symmetrically ([`quantize_symmetric`]).
    pub fn quantize(w: &[f64]) -> Self {
        let mut q = alloc::vec![0i16; w.len()];
        let scale = quantize_symmetric(w, &mut q);
        Self::from_codes(&q, scale)
    }

    /// A table of given codes and scale.
    pub fn from_codes(codes: &[i16], scale: f32) -> Self {
        Self {
            bytes: codes.iter().flat_map(|v| v.to_le_bytes()).collect(),
            scale,
        }
    }

    /// The runtime view of the table.
    pub fn view(&self) -> Option<I16Table<'_>> {
        I16Table::new(&self.bytes, self.scale, self.bytes.len() / 2)
    }

    /// The wire form, borrowing from `self`.
    pub fn section(&self) -> I16Section<'_> {
        I16Section {
            scale: self.scale,
            bytes: &self.bytes,
        }
    }
}

/// Owned `inference` section.
#[derive(Clone, Debug, PartialEq)]
pub struct OwnedInference {
    /// States S.
    pub states: u8,
    /// Clusters K.
    pub clusters: u8,
    /// Window W.
    pub window: u8,
    /// K GMM records.
    pub gmm: Vec<u8>,
    /// CRF initial weights.
    pub crf_init: QTable,
    /// CRF transition weights.
    pub crf_trans: QTable,
    /// CRF observation weights.
    pub crf_obs: QTable,
}

impl OwnedInference {
    /// The wire form, borrowing from `self`.
    pub fn section(&self) -> InferenceSection<'_> {
        InferenceSection {
            states: self.states,
            clusters: self.clusters,
            window: self.window,
            gmm: &self.gmm,
            crf_init: self.crf_init.section(),
            crf_trans: self.crf_trans.section(),
            crf_obs: self.crf_obs.section(),
        }
    }

    /// The section for GMM components `gmm` and CRF weights in nats (`init`: S, `trans`:
    /// S x S from-major, `obs`: S x W x K), quantized symmetrically per table.
    pub fn new(
        gmm: &[GmmComponent],
        window: usize,
        init: &[f64],
        trans: &[f64],
        obs: &[f64],
    ) -> Result<Self, EncodeError> {
        let s = init.len();
        if trans.len() != s * s || obs.len() != s * window * gmm.len() {
            return inconsistent(alloc::format!(
                "CRF tables of {} / {} / {} weights for S = {s}, W = {window}, K = {}",
                init.len(),
                trans.len(),
                obs.len(),
                gmm.len()
            ));
        }
        Ok(Self {
            states: fit("states", s, "u8")?,
            clusters: fit("clusters", gmm.len(), "u8")?,
            window: fit("window", window, "u8")?,
            gmm: gmm.iter().flat_map(gmm_record).collect(),
            crf_init: QTable::quantize(init),
            crf_trans: QTable::quantize(trans),
            crf_obs: QTable::quantize(obs),
        })
    }

    /// The GMM components as the device decodes them.
    pub fn components(&self) -> Vec<GmmComponent> {
        self.gmm
            .chunks_exact(GMM_RECORD_BYTES)
            .filter_map(|r| r.first_chunk::<GMM_RECORD_BYTES>())
            .map(gmm_from_record)
            .collect()
    }

    /// The quantized CRF weights as the device reads them (`None` only if the dimensions
    /// exceed the runtime's capacities).
    pub fn crf_weights(&self) -> Option<CrfWeights<'_>> {
        CrfWeights::new(
            self.states as usize,
            self.clusters as usize,
            self.window as usize,
            self.crf_init.view()?,
            self.crf_trans.view()?,
            self.crf_obs.view()?,
        )
    }
}

/// Inputs of [`OwnedPolicy::new`], in float: the quantization happens there.
#[derive(Clone, Copy, Debug)]
pub struct PolicyInput<'a> {
    /// Hidden states S.
    pub states: usize,
    /// Library segments.
    pub segments: usize,
    /// Discount of the value iteration.
    pub discount: f64,
    /// U, segments x S, segment-major.
    pub u: &'a [f64],
    /// U_cont, exit points x S, exit-major (any value at end exits; never read).
    pub u_cont: &'a [f64],
    /// Exit points `(segment, frame within the segment)`, sorted by (segment, frame); every
    /// segment's last frame is one.
    pub exits: &'a [(usize, usize)],
    /// Per exit point, its successors `(segment, cost)`, sorted by segment.
    pub successors: &'a [Vec<(usize, f64)>],
}

/// Owned `policy` section.
#[derive(Clone, Debug, PartialEq)]
pub struct OwnedPolicy {
    /// States S.
    pub states: u8,
    /// Segments.
    pub segments: u16,
    /// Exit points.
    pub exit_points: u16,
    /// Discount.
    pub discount: f32,
    /// U.
    pub u: QTable,
    /// U_cont.
    pub u_cont: QTable,
    /// Exit records.
    pub exits: Vec<u8>,
    /// Successor offsets.
    pub succ_offsets: Vec<u8>,
    /// Successor records.
    pub succ: Vec<u8>,
    /// Successor cost scale.
    pub succ_cost_scale: f32,
}

impl OwnedPolicy {
    /// The wire form, borrowing from `self`.
    pub fn section(&self) -> PolicySection<'_> {
        PolicySection {
            states: self.states,
            segments: self.segments,
            exit_points: self.exit_points,
            discount: self.discount,
            u: self.u.section(),
            u_cont: self.u_cont.section(),
            exits: &self.exits,
            succ_offsets: &self.succ_offsets,
            succ: &self.succ,
            succ_cost_scale: self.succ_cost_scale,
        }
    }

    /// Quantizes and lays out the policy tables (checks that every number fits its field;
    /// the rules of the format are checked by [`encode`](super::encode)).
    pub fn new(p: &PolicyInput<'_>) -> Result<Self, EncodeError> {
        if p.successors.len() != p.exits.len() {
            return inconsistent(alloc::format!(
                "{} successor lists for {} exit points",
                p.successors.len(),
                p.exits.len()
            ));
        }
        if p.u.len() != p.segments * p.states || p.u_cont.len() != p.exits.len() * p.states {
            return inconsistent(alloc::format!(
                "value tables of {} and {} entries for {} segments, {} exits, {} states",
                p.u.len(),
                p.u_cont.len(),
                p.segments,
                p.exits.len(),
                p.states
            ));
        }
        let mut exits = Vec::with_capacity(4 * p.exits.len());
        for &(seg, frame) in p.exits {
            exits.extend(fit::<u16>("exit segment", seg, "u16")?.to_le_bytes());
            exits.extend(fit::<u16>("exit frame", frame, "u16")?.to_le_bytes());
        }
        let (q, succ) = records(p.successors.iter().flatten(), "successor segment")?;
        let mut succ_offsets = Vec::with_capacity(4 * (p.exits.len() + 1));
        let mut n = 0usize;
        succ_offsets.extend(0u32.to_le_bytes());
        for list in p.successors {
            n += list.len();
            succ_offsets.extend(fit::<u32>("successor entries", n, "u32")?.to_le_bytes());
        }
        Ok(Self {
            states: fit("policy states", p.states, "u8")?,
            segments: fit("policy segments", p.segments, "u16")?,
            exit_points: fit("exit points", p.exits.len(), "u16")?,
            discount: p.discount as f32,
            u: QTable::quantize(p.u),
            u_cont: QTable::quantize(p.u_cont),
            exits,
            succ_offsets,
            succ,
            succ_cost_scale: q.scale,
        })
    }
}

/// Owned `styles` section: one pair of value tables per tone (docs/blob-format.md).
#[derive(Clone, Debug, PartialEq)]
pub struct OwnedStyles {
    /// Tones M.
    pub tones: u8,
    /// Names joined by `'\n'`.
    pub names: String,
    /// U of every tone (M x segments x S), one scale for all tones.
    pub u: QTable,
    /// U_cont of every tone (M x exit points x S).
    pub u_cont: QTable,
}

impl OwnedStyles {
    /// The section for tones named `names`, tone `m` having `u[m]` (segments x S,
    /// segment-major) and `u_cont[m]` (exit points x S; any value at end exits). The tables are
    /// quantized together, one scale for all tones, so a mix of tones is the mix of their
    /// stored codes. Names must not contain `'\n'`; the other rules are checked by [`encode`](super::encode).
    pub fn new(names: &[&str], u: &[Vec<f64>], u_cont: &[Vec<f64>]) -> Result<Self, EncodeError> {
        if u.len() != names.len() || u_cont.len() != names.len() {
            return inconsistent(alloc::format!(
                "{} tone names for {} U and {} U_cont tables",
                names.len(),
                u.len(),
                u_cont.len()
            ));
        }
        if let Some(n) = names.iter().find(|n| n.contains('\n')) {
            return inconsistent(alloc::format!("tone name {n:?} contains a line break"));
        }
        let flat_u: Vec<f64> = u.iter().flatten().copied().collect();
        let flat_uc: Vec<f64> = u_cont.iter().flatten().copied().collect();
        Ok(Self {
            tones: fit("tones", names.len(), "u8")?,
            names: names.join("\n"),
            u: QTable::quantize(&flat_u),
            u_cont: QTable::quantize(&flat_uc),
        })
    }

    /// The wire form, borrowing from `self`.
    pub fn section(&self) -> StylesSection<'_> {
        StylesSection {
            tones: self.tones,
            names: &self.names,
            u: self.u.section(),
            u_cont: self.u_cont.section(),
        }
    }
}

/// Inputs of [`OwnedLabels::new`], in float.
#[derive(Clone, Copy, Debug)]
pub struct LabelsInput<'a> {
    /// Label names (label `w` is `library.labels` value `w + 1`).
    pub names: &'a [&'a str],
    /// Cost added to candidates that do not carry the waiting label.
    pub semantic_cost: f64,
    /// A label not shown within this long is dropped (ms).
    pub timeout_ms: u32,
    /// The labelled segments, increasing.
    pub segments: &'a [usize],
    /// Per label, U^w (segments x S, segment-major).
    pub u: &'a [Vec<f64>],
    /// Per label, U_cont^w (exit points x S).
    pub u_cont: &'a [Vec<f64>],
    /// Per exit point, per labelled segment: `(entry frame, cost)`.
    pub entries: &'a [Vec<(usize, f64)>],
}

/// Owned `labels` section.
#[derive(Clone, Debug, PartialEq)]
pub struct OwnedLabels {
    /// Labels L.
    pub labels: u8,
    /// Names joined by `'\n'`.
    pub names: String,
    /// Semantic cost.
    pub semantic_cost: f32,
    /// Timeout (ms).
    pub timeout_ms: u16,
    /// `u16` per labelled segment.
    pub segments: Vec<u8>,
    /// U^w of every label, one scale.
    pub u: QTable,
    /// U_cont^w of every label.
    pub u_cont: QTable,
    /// Entry records.
    pub entries: Vec<u8>,
    /// Entry cost scale.
    pub entry_cost_scale: f32,
}

impl OwnedLabels {
    /// Quantizes and lays out the labels section (the format's rules are checked by
    /// [`encode`](super::encode)).
    pub fn new(p: &LabelsInput<'_>) -> Result<Self, EncodeError> {
        let l = p.names.len();
        if p.u.len() != l || p.u_cont.len() != l {
            return inconsistent(alloc::format!(
                "{l} label names for {} U and {} U_cont tables",
                p.u.len(),
                p.u_cont.len()
            ));
        }
        if let Some(n) = p.names.iter().find(|n| n.contains('\n')) {
            return inconsistent(alloc::format!("label name {n:?} contains a line break"));
        }
        if let Some(r) = p.entries.iter().find(|r| r.len() != p.segments.len()) {
            return inconsistent(alloc::format!(
                "{} entries for {} labelled segments",
                r.len(),
                p.segments.len()
            ));
        }
        let mut segments = Vec::with_capacity(2 * p.segments.len());
        for &c in p.segments {
            segments.extend(fit::<u16>("labelled segment", c, "u16")?.to_le_bytes());
        }
        let (q, entries) = records(p.entries.iter().flatten(), "entry frame")?;
        let flat_u: Vec<f64> = p.u.iter().flatten().copied().collect();
        let flat_uc: Vec<f64> = p.u_cont.iter().flatten().copied().collect();
        Ok(Self {
            labels: fit("labels", l, "u8")?,
            names: p.names.join("\n"),
            semantic_cost: p.semantic_cost as f32,
            timeout_ms: fit("label timeout (ms)", p.timeout_ms as usize, "u16")?,
            segments,
            u: QTable::quantize(&flat_u),
            u_cont: QTable::quantize(&flat_uc),
            entries,
            entry_cost_scale: q.scale,
        })
    }

    /// The wire form, borrowing from `self`.
    pub fn section(&self) -> LabelsSection<'_> {
        LabelsSection {
            labels: self.labels,
            names: &self.names,
            semantic_cost: self.semantic_cost,
            timeout_ms: self.timeout_ms,
            segments: &self.segments,
            u: self.u.section(),
            u_cont: self.u_cont.section(),
            entries: &self.entries,
            entry_cost_scale: self.entry_cost_scale,
        }
    }
}
