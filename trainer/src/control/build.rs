//! The control model: from a trained inference model and a library to a solved, pruned
//! policy ([`build`]: `psi` and successor costs, value iteration per tone and per label,
//! exact pruning, padding, and `--max-successors`). Stage 3 of `gesture-train pack`
//! ([`crate::pack`]); the regret of its packed tables is [`super::regret`]'s.

use std::time::Instant;

use super::costs::{psi, psi_of, successor_costs, CostParams, Signatures};
use super::library::Library;
use super::mdp::{solve, solve_label, transition_matrix, LabelProblem, MdpParams, Policy};
use super::prune::{keep_best, pad, prune};
use super::semantic::{entries, LabelParams, Labelling};
use super::style::ToneTransform;
use crate::inference::model::InferenceModel;

/// Settings of the control layer.
#[derive(Clone, Copy, Debug, Default)]
pub struct ControlParams {
    /// Costs.
    pub cost: CostParams,
    /// MDP.
    pub mdp: MdpParams,
    /// Most successors kept per exit point (`None`: all non-dominated).
    pub max_successors: Option<usize>,
    /// Fewest successors kept per exit point (padding, see `prune`; `None`:
    /// [`super::prune::MIN_SUCCESSORS`]).
    pub min_successors: Option<usize>,
}

/// Timings of the stages (s).
#[derive(Clone, Copy, Debug, Default)]
pub struct Timings {
    /// psi and successor costs.
    pub costs: f64,
    /// Value iteration.
    pub value_iteration: f64,
    /// Pruning and truncation.
    pub pruning: f64,
}

/// The solved control layer.
#[derive(Clone, Debug)]
pub struct ControlModel {
    /// `psi[c][s]`.
    pub psi: Vec<Vec<f64>>,
    /// The float policy.
    pub policy: Policy,
    /// Non-dominated successors per exit.
    pub pruned: Vec<Vec<usize>>,
    /// Successors kept in the blob per exit (pruned, then truncated to the budget).
    pub kept: Vec<Vec<usize>>,
    /// The tones' policies (same successor costs, each tone's `psi`).
    pub tones: Vec<TonePolicy>,
    /// The library's labels (empty: none).
    pub labelling: Labelling,
    /// Per label, the policy while it waits (`u`, `u_cont`: `U^w`, `U_cont^w`).
    pub label_policies: Vec<Policy>,
    /// Per exit point, per labelled segment: the semantic entry `(frame, cost)`.
    pub entries: Vec<Vec<(usize, f64)>>,
    /// Stage timings.
    pub timings: Timings,
}

/// One tone's solved control layer.
#[derive(Clone, Debug)]
pub struct TonePolicy {
    /// Its transform.
    pub transform: ToneTransform,
    /// `psi^m[c][s]`: the library's segments scored through the transform's inverse.
    pub psi: Vec<Vec<f64>>,
    /// The float policy under the tone.
    pub policy: Policy,
}

impl ControlModel {
    /// Entries before pruning (exit points x segments).
    pub fn entries_total(&self) -> usize {
        self.policy.succ.len() * self.policy.u.len()
    }
    /// Entries kept.
    pub fn entries_kept(&self) -> usize {
        self.kept.iter().map(Vec::len).sum()
    }
}

/// Solves the control layer for `lib` under `model`, and one policy per tone of `tones`
/// (docs/method.md "Style control"). The successor lists kept are the union of every tone's
/// non-dominated successors (a successor dominated under every tone is dominated under any
/// mix of them, since the mixed cost is a convex combination), padded under the neutral policy.
pub fn build(
    model: &InferenceModel,
    lib: &Library,
    params: &ControlParams,
    tones: &[ToneTransform],
    labels: Option<(&Labelling, &LabelParams)>,
) -> ControlModel {
    let t0 = Instant::now();
    let psi = psi(lib, &model.hmm.emit, params.cost.psi_samples);
    let tone_psi: Vec<Vec<Vec<f64>>> = tones
        .iter()
        .map(|t| {
            let ys: Vec<[f64; 6]> = lib.segments.iter().map(|s| t.invert(&s.y)).collect();
            psi_of(&ys, &model.hmm.emit, params.cost.psi_samples)
        })
        .collect();
    let sig = Signatures::new(lib);
    let succ = successor_costs(lib, &sig, &params.cost);
    let t1 = Instant::now();
    let p = transition_matrix(&model.crf.trans, model.states());
    let policy = solve(lib, &psi, succ.clone(), &p, &params.mdp);
    let tones: Vec<TonePolicy> = tones
        .iter()
        .zip(tone_psi)
        .map(|(t, psi)| TonePolicy {
            transform: t.clone(),
            policy: solve(lib, &psi, succ.clone(), &p, &params.mdp),
            psi,
        })
        .collect();
    let (labelling, label_policies, entries) = match labels {
        Some((lab, lp)) if !lab.is_empty() => {
            let ent = entries(lib, &sig, &params.cost, lab, lp);
            let pols: Vec<Policy> = (0..lab.names.len())
                .map(|w| {
                    let code = (w + 1) as u8;
                    let carries: Vec<bool> = lab.label_of.iter().map(|&l| l == code).collect();
                    let mine: Vec<Vec<(usize, f64)>> = ent
                        .iter()
                        .map(|row| {
                            lab.segments
                                .iter()
                                .zip(row)
                                .filter(|(&c, _)| carries[c])
                                .map(|(&c, &(_, x))| (c, x))
                                .collect()
                        })
                        .collect();
                    let problem = LabelProblem {
                        carries: &carries,
                        semantic_cost: lp.semantic_cost,
                        entries: &mine,
                    };
                    solve_label(lib, &psi, &p, &params.mdp, &policy, &problem)
                })
                .collect();
            (lab.clone(), pols, ent)
        }
        _ => (Labelling::default(), Vec::new(), Vec::new()),
    };
    let t2 = Instant::now();
    let min = params
        .min_successors
        .unwrap_or(super::prune::MIN_SUCCESSORS);
    let mut front = prune(&policy);
    let more_fronts: Vec<Vec<Vec<usize>>> = tones.iter().map(|t| prune(&t.policy)).collect();
    // Labels add no successors: while one waits, the candidates are the shared lists and the
    // label's entries, so a labelled blob given no label decides exactly as one packed without
    // labels (the lists, and the quantization of their costs, are the same).
    for more_front in more_fronts {
        for (all, more) in front.iter_mut().zip(more_front) {
            all.extend(more);
            all.sort_unstable();
            all.dedup();
        }
    }
    let pruned = pad(&policy, &front, min);
    let kept = match params.max_successors {
        Some(k) => keep_best(&policy, &pruned, &model.state_prior, k),
        None => pruned.clone(),
    };
    let t3 = Instant::now();
    ControlModel {
        psi,
        policy,
        pruned,
        kept,
        tones,
        labelling,
        label_policies,
        entries,
        timings: Timings {
            costs: (t1 - t0).as_secs_f64(),
            value_iteration: (t2 - t1).as_secs_f64(),
            pruning: (t3 - t2).as_secs_f64(),
        },
    }
}
