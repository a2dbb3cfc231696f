//! From a trained inference model and a library to a solved, pruned and quantized policy,
//! with the regret it costs (what `gesture-train pack` runs).
//!
//! The quantized policy implements the runtime's [`PolicyTables`] and decides through the
//! runtime's own [`select`], so the decisions measured here are the device's decisions.
//! Regret is measured on simulated belief traces: a hidden state path drawn from the CRF's
//! transition matrix, observed through a noisy channel (the true state gets 60% of the
//! likelihood), filtered into beliefs; the controller walks the library following the
//! quantized, pruned policy, and at every decision the float, unpruned expected cost of its
//! choice is compared with the best float choice. Regret = sum of the excess / sum of the
//! best, as a fraction.

use std::time::Instant;

use gesture_runtime::policy::{select, Choice, PolicyTables};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::costs::{psi, successor_costs, CostParams, Signatures};
use super::library::Library;
use super::mdp::{solve, transition_matrix, Action, MdpParams, Policy};
use super::prune::{keep_best, prune};
use crate::inference::model::InferenceModel;
use crate::inference::quantize::QTable;

/// Settings of the control layer.
#[derive(Clone, Copy, Debug, Default)]
pub struct ControlParams {
    /// Costs.
    pub cost: CostParams,
    /// MDP.
    pub mdp: MdpParams,
    /// Most successors kept per exit point (`None`: all non-dominated).
    pub max_successors: Option<usize>,
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
    /// Stage timings.
    pub timings: Timings,
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

/// Solves the control layer for `lib` under `model`.
pub fn build(model: &InferenceModel, lib: &Library, params: &ControlParams) -> ControlModel {
    let t0 = Instant::now();
    let psi = psi(lib, &model.hmm.emit, params.cost.psi_samples);
    let sig = Signatures::new(lib);
    let succ = successor_costs(lib, &sig, &params.cost);
    let t1 = Instant::now();
    let p = transition_matrix(&model.crf.trans, model.states());
    let policy = solve(lib, &psi, succ, &p, &params.mdp);
    let t2 = Instant::now();
    let pruned = prune(&policy);
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
        timings: Timings {
            costs: (t1 - t0).as_secs_f64(),
            value_iteration: (t2 - t1).as_secs_f64(),
            pruning: (t3 - t2).as_secs_f64(),
        },
    }
}

/// The policy in the blob's form: i16 tables with scales, successor lists with i16 costs.
#[derive(Clone, Debug)]
pub struct QuantizedPolicy {
    /// States.
    pub states: usize,
    /// Exit points: (segment, frame, end).
    pub exits: Vec<(usize, usize, bool)>,
    /// First exit point of each segment.
    pub first_exit: Vec<usize>,
    /// `U`, segments x states.
    pub u: QTable,
    /// `U_cont`, exit points x states (zeros at end exits).
    pub u_cont: QTable,
    /// Successors per exit: (segment, quantized cost).
    pub succ: Vec<Vec<(usize, i16)>>,
    /// Scale of the successor costs.
    pub succ_scale: f32,
}

impl QuantizedPolicy {
    /// Quantizes the kept part of `cm` for `lib`.
    pub fn new(lib: &Library, cm: &ControlModel) -> Self {
        let pol = &cm.policy;
        let s = pol.states;
        let u: Vec<f64> = pol.u.iter().flatten().copied().collect();
        let u_cont: Vec<f64> = pol
            .u_cont
            .iter()
            .flat_map(|o| o.clone().unwrap_or_else(|| vec![0.0; s]))
            .collect();
        let max_succ = cm
            .kept
            .iter()
            .enumerate()
            .flat_map(|(e, l)| l.iter().map(move |&c| pol.succ[e][c].abs()))
            .fold(0.0f64, f64::max);
        let succ_scale = if max_succ > 0.0 {
            max_succ / 32767.0
        } else {
            1.0
        };
        let succ = cm
            .kept
            .iter()
            .enumerate()
            .map(|(e, l)| {
                l.iter()
                    .map(|&c| {
                        (
                            c,
                            (pol.succ[e][c] / succ_scale)
                                .round()
                                .clamp(-32767.0, 32767.0) as i16,
                        )
                    })
                    .collect()
            })
            .collect();
        Self {
            states: s,
            exits: lib
                .exits
                .iter()
                .map(|x| (x.segment, x.frame, x.end))
                .collect(),
            first_exit: lib.first_exit.clone(),
            u: QTable::quantize(&u),
            u_cont: QTable::quantize(&u_cont),
            succ,
            succ_scale: succ_scale as f32,
        }
    }

    fn q(t: &QTable, i: usize) -> f32 {
        t.bytes
            .get(2 * i..2 * i + 2)
            .map_or(0.0, |b| i16::from_le_bytes([b[0], b[1]]) as f32 * t.scale)
    }
}

impl PolicyTables for QuantizedPolicy {
    fn states(&self) -> usize {
        self.states
    }
    fn exit_count(&self) -> usize {
        self.exits.len()
    }
    fn exit_segment(&self, e: usize) -> usize {
        self.exits[e].0
    }
    fn exit_frame(&self, e: usize) -> usize {
        self.exits[e].1
    }
    fn exit_is_end(&self, e: usize) -> bool {
        self.exits[e].2
    }
    fn first_exit(&self, c: usize) -> usize {
        self.first_exit[c]
    }
    fn u(&self, c: usize, s: usize) -> f32 {
        Self::q(&self.u, c * self.states + s)
    }
    fn u_cont(&self, e: usize, s: usize) -> f32 {
        Self::q(&self.u_cont, e * self.states + s)
    }
    fn successor_count(&self, e: usize) -> usize {
        self.succ[e].len()
    }
    fn successor(&self, e: usize, k: usize) -> (usize, f32) {
        let (c, q) = self.succ[e][k];
        (c, q as f32 * self.succ_scale)
    }
}

/// Regret and agreement of the quantized policy on simulated belief traces.
#[derive(Clone, Copy, Debug, Default)]
pub struct RegretReport {
    /// Decisions simulated.
    pub decisions: usize,
    /// Fraction where the quantized pruned choice equals the float unpruned one.
    pub agreement: f64,
    /// Excess float expected cost over the best, as a fraction of the best.
    pub regret: f64,
}

/// Simulates `decisions` decisions (seeded) and measures regret; see the module docs.
pub fn regret(
    lib: &Library,
    cm: &ControlModel,
    q: &QuantizedPolicy,
    model: &InferenceModel,
    decisions: usize,
    seed: u64,
) -> RegretReport {
    let s = cm.policy.states;
    let p = transition_matrix(&model.crf.trans, s);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let sample = |row: &[f64], rng: &mut ChaCha8Rng| {
        let u: f64 = rng.random();
        let mut acc = 0.0;
        for (j, v) in row.iter().enumerate() {
            acc += v;
            if u < acc {
                return j;
            }
        }
        row.len() - 1
    };
    let mut state = sample(&model.state_prior, &mut rng);
    let mut belief = model.state_prior.clone();
    let mut e = lib.first_exit[rng.random_range(0..lib.segments.len())];
    let (mut same, mut excess, mut best_total) = (0usize, 0.0, 0.0);
    for _ in 0..decisions {
        // A few steps of hidden evolution and noisy observation between decisions.
        for _ in 0..rng.random_range(1..4) {
            state = sample(&p[state], &mut rng);
            let mut nb: Vec<f64> = (0..s)
                .map(|j| (0..s).map(|i| belief[i] * p[i][j]).sum::<f64>())
                .collect();
            for (j, v) in nb.iter_mut().enumerate() {
                *v *= if j == state {
                    0.6
                } else {
                    0.4 / (s.max(2) - 1) as f64
                };
            }
            let z: f64 = nb.iter().sum();
            belief = nb.iter().map(|v| v / z).collect();
        }
        let bf: Vec<f32> = belief.iter().map(|&v| v as f32).collect();
        let dq = select(q, e, &bf);
        let chosen = match dq.choice {
            Choice::Continue => Action::Continue,
            Choice::Enter(c) => Action::Enter(c),
        };
        let best = cm.policy.decide(e, &belief, 0..lib.segments.len());
        let cb = cm.policy.cost(e, best, &belief);
        let cc = cm.policy.cost(e, chosen, &belief);
        same += (best == chosen) as usize;
        excess += (cc - cb).max(0.0);
        best_total += cb.abs();
        e = match chosen {
            Action::Continue => e + 1,
            Action::Enter(c) => lib.first_exit[c],
        };
    }
    RegretReport {
        decisions,
        agreement: same as f64 / decisions.max(1) as f64,
        regret: excess / best_total.max(1e-12),
    }
}

/// Truncates `cm` to the largest number of successors per exit whose blob fits `budget`
/// bytes, as measured by `size(kept)`; returns that number (`None` if even one successor per
/// exit does not fit). Bisection over `k`, since the size grows with `k`.
pub fn fit_budget(
    model: &InferenceModel,
    cm: &mut ControlModel,
    budget: usize,
    size: &dyn Fn(&ControlModel) -> usize,
) -> Option<usize> {
    let max_k = cm.pruned.iter().map(Vec::len).max().unwrap_or(1).max(1);
    cm.kept = cm.pruned.clone();
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
