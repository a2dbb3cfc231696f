//! Stage 4 of packing: the policy fitted to the budget. The value tables and successor lists
//! of the solved control layer become the blob's `policy` section, with the tones' and the
//! labels' value tables (`styles`, `labels`). With a byte budget, the successor lists are cut
//! to the largest number per exit point (`k`, the best by cost under the state prior) whose
//! blob, encoded with the sections of stage 2, fits; bisection over `k`, since the size grows
//! with it, up to `--max-successors` when that is given (the budget only ever cuts further).
//! Without a budget, `--max-successors` bounds them as the control layer kept them.
//! The cut is lossy; the report (stage 6) measures its regret.

use gesture_runtime::blob::encode::{
    EncodeError, LabelsInput, OwnedLabels, OwnedPolicy, OwnedStyles, PolicyInput,
};

use crate::control::build::ControlModel;
use crate::control::prune::keep_best;
use crate::control::semantic::LabelParams;
use crate::control::Library;
use crate::inference::model::InferenceModel;

use super::error::PackError;
use super::options::PackOptions;
use super::sections::Sections;

/// The policy's sections, fitted to the budget.
pub struct PolicySections {
    /// Value tables and successor lists.
    pub policy: OwnedPolicy,
    /// The tones' value tables (`None` without tones).
    pub styles: Option<OwnedStyles>,
    /// The labels' value tables and entries (`None` without labels).
    pub labels: Option<OwnedLabels>,
    /// Successors per exit point kept by the budget or `--max-successors` (`None`: all
    /// non-dominated).
    pub successors_per_exit: Option<usize>,
}

impl PolicySections {
    /// The sections of `cm` (its `kept` lists cut to `opts.budget_bytes` as the module docs
    /// say) for the library `lib`, sized against `sections`.
    pub fn fit(
        model: &InferenceModel,
        lib: &Library,
        cm: &mut ControlModel,
        sections: &Sections,
        opts: &PackOptions,
    ) -> Result<Self, PackError> {
        let styles = styles_section(cm)?;
        let labels = labels_section(cm, &opts.label_params)?;
        let mut k = None;
        if let Some(budget) = opts.budget_bytes {
            let size = |c: &ControlModel| {
                policy_section(model, lib, c)
                    .and_then(|p| sections.encode(&p, styles.as_ref(), labels.as_ref()))
                    .map_or(usize::MAX, |b| b.len())
            };
            k = fit_budget(model, cm, budget, opts.control.max_successors, &size);
            if k.is_none() {
                return Err(PackError::Budget {
                    budget,
                    size: size(cm),
                });
            }
            if k == cm.pruned.iter().map(Vec::len).max() {
                k = None;
            }
        }
        if k.is_none() {
            let most = cm.pruned.iter().map(Vec::len).max().unwrap_or(0);
            k = opts.control.max_successors.filter(|&m| m < most);
        }
        Ok(Self {
            policy: policy_section(model, lib, cm)?,
            styles,
            labels,
            successors_per_exit: k,
        })
    }

    /// The blob's bytes: `sections` with these.
    pub fn encode(&self, sections: &Sections) -> Result<Vec<u8>, EncodeError> {
        sections.encode(&self.policy, self.styles.as_ref(), self.labels.as_ref())
    }
}

/// The policy section of the kept part of `cm`.
pub fn policy_section(
    model: &InferenceModel,
    lib: &Library,
    cm: &ControlModel,
) -> Result<OwnedPolicy, EncodeError> {
    let pol = &cm.policy;
    let s = pol.states;
    let u: Vec<f64> = pol.u.iter().flatten().copied().collect();
    let u_cont: Vec<f64> = pol
        .u_cont
        .iter()
        .flat_map(|o| o.clone().unwrap_or_else(|| vec![0.0; s]))
        .collect();
    let exits: Vec<(usize, usize)> = lib.exits.iter().map(|x| (x.segment, x.frame)).collect();
    let successors: Vec<Vec<(usize, f64)>> = cm
        .kept
        .iter()
        .enumerate()
        .map(|(e, l)| l.iter().map(|&c| (c, pol.succ[e][c])).collect())
        .collect();
    OwnedPolicy::new(&PolicyInput {
        states: model.states(),
        segments: lib.segments.len(),
        discount: pol.discount,
        u: &u,
        u_cont: &u_cont,
        exits: &exits,
        successors: &successors,
    })
}

/// The `styles` section of a solved control layer with tones (`None` without tones).
pub fn styles_section(cm: &ControlModel) -> Result<Option<OwnedStyles>, EncodeError> {
    if cm.tones.is_empty() {
        return Ok(None);
    }
    let s = cm.policy.states;
    let names: Vec<&str> = cm.tones.iter().map(|t| t.transform.name.as_str()).collect();
    let u: Vec<Vec<f64>> = cm
        .tones
        .iter()
        .map(|t| t.policy.u.iter().flatten().copied().collect())
        .collect();
    let u_cont: Vec<Vec<f64>> = cm
        .tones
        .iter()
        .map(|t| {
            t.policy
                .u_cont
                .iter()
                .flat_map(|o| o.clone().unwrap_or_else(|| vec![0.0; s]))
                .collect()
        })
        .collect();
    OwnedStyles::new(&names, &u, &u_cont).map(Some)
}

/// The `labels` section of a solved control layer with labels (`None` without).
pub fn labels_section(
    cm: &ControlModel,
    p: &LabelParams,
) -> Result<Option<OwnedLabels>, EncodeError> {
    let lab = &cm.labelling;
    if lab.is_empty() {
        return Ok(None);
    }
    let s = cm.policy.states;
    let names: Vec<&str> = lab.names.iter().map(String::as_str).collect();
    let u: Vec<Vec<f64>> = cm
        .label_policies
        .iter()
        .map(|pol| pol.u.iter().flatten().copied().collect())
        .collect();
    let u_cont: Vec<Vec<f64>> = cm
        .label_policies
        .iter()
        .map(|pol| {
            pol.u_cont
                .iter()
                .flat_map(|o| o.clone().unwrap_or_else(|| vec![0.0; s]))
                .collect()
        })
        .collect();
    OwnedLabels::new(&LabelsInput {
        names: &names,
        semantic_cost: p.semantic_cost,
        timeout_ms: p.timeout_ms,
        segments: &lab.segments,
        u: &u,
        u_cont: &u_cont,
        entries: &cm.entries,
    })
    .map(Some)
}

/// Truncates `cm` to the largest number of successors per exit, at most `cap`, whose blob fits
/// `budget` bytes, as measured by `size(kept)`; returns that number (`None` if even one
/// successor per exit does not fit). Bisection over `k`, since the size grows with `k`.
fn fit_budget(
    model: &InferenceModel,
    cm: &mut ControlModel,
    budget: usize,
    cap: Option<usize>,
    size: &dyn Fn(&ControlModel) -> usize,
) -> Option<usize> {
    let most = cm.pruned.iter().map(Vec::len).max().unwrap_or(1).max(1);
    let max_k = cap.map_or(most, |m| m.clamp(1, most));
    cm.kept = if max_k < most {
        keep_best(&cm.policy, &cm.pruned, &model.state_prior, max_k)
    } else {
        cm.pruned.clone()
    };
    if size(cm) <= budget {
        return Some(max_k);
    }
    let (mut lo, mut hi) = (0usize, max_k);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        cm.kept = keep_best(&cm.policy, &cm.pruned, &model.state_prior, mid);
        if size(cm) <= budget {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    if lo == 0 {
        cm.kept = keep_best(&cm.policy, &cm.pruned, &model.state_prior, 1);
        return None;
    }
    cm.kept = keep_best(&cm.policy, &cm.pruned, &model.state_prior, lo);
    Some(lo)
}
