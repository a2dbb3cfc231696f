//! Pruning the successor lists (docs/method.md "Pruning"; the paper removed ~98% of entries).
//!
//! At exit `e`, candidate `c` costs `C_c(s) = S(e, c) + U(c, s)` in state `s`. If another
//! candidate (or continuing, `U_cont(e, s)`) costs no more in *every* state, `c` can never be
//! the choice for any belief (beliefs average over states), so it is dropped: exact, no regret.
//! Found by a Pareto filter: candidates sorted by total cost, each checked only against the
//! ones kept so far (a dominator always has a smaller total, and domination is transitive).
//! Identical vectors keep the lowest index.
//!
//! Exact pruning can leave an exit with one or two successors when the model has few states (a
//! belief over two states has few corners), and then the variety costs of the runtime have
//! nothing to choose from: the controller loops. So every exit keeps at least
//! [`MIN_SUCCESSORS`] successors ([`pad`]): the survivors plus the next best by expected cost
//! under the state prior. The padding never changes the pure policy's choice (the added
//! candidates are dominated), so it costs no regret, only blob bytes.
//!
//! Then, if the blob must fit a budget, only the best `k` survivors per exit are kept (by cost
//! under the state prior); that is lossy, and the pack report measures its regret.

use rayon::prelude::*;

use super::mdp::Policy;

fn dominates(a: &[f64], b: &[f64]) -> bool {
    a.iter().zip(b).all(|(x, y)| x <= y)
}

/// Non-dominated successors of every exit point, sorted by segment index.
pub fn prune(policy: &Policy) -> Vec<Vec<usize>> {
    (0..policy.succ.len())
        .into_par_iter()
        .map(|e| {
            let n = policy.u.len();
            let costs: Vec<Vec<f64>> = (0..n)
                .map(|c| policy.u[c].iter().map(|u| policy.succ[e][c] + u).collect())
                .collect();
            let mut order: Vec<usize> = (0..n).collect();
            let total = |c: usize| costs[c].iter().sum::<f64>();
            order.sort_by(|&a, &b| total(a).total_cmp(&total(b)).then(a.cmp(&b)));
            let mut front: Vec<usize> = Vec::new();
            for c in order {
                if let Some(uc) = &policy.u_cont[e] {
                    if dominates(uc, &costs[c]) {
                        continue;
                    }
                }
                if front.iter().any(|&f| dominates(&costs[f], &costs[c])) {
                    continue;
                }
                front.push(c);
            }
            front.sort_unstable();
            front
        })
        .collect()
}

/// Fewest successors an exit keeps by default (see the module docs).
pub const MIN_SUCCESSORS: usize = 12;

/// `kept` with every exit padded to at least `min` successors (fewer if there are fewer
/// segments): the next best by expected cost under `prior`. Sorted by segment index.
pub fn pad(policy: &Policy, kept: &[Vec<usize>], prior: &[f64], min: usize) -> Vec<Vec<usize>> {
    kept.iter()
        .enumerate()
        .map(|(e, list)| {
            let mut out = list.clone();
            if out.len() < min {
                let mut rest: Vec<(f64, usize)> = (0..policy.u.len())
                    .filter(|c| !list.contains(c))
                    .map(|c| (policy.cost(e, super::mdp::Action::Enter(c), prior), c))
                    .filter(|(v, _)| v.is_finite())
                    .collect();
                rest.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                out.extend(rest.into_iter().take(min - out.len()).map(|(_, c)| c));
                out.sort_unstable();
            }
            out
        })
        .collect()
}

/// Keeps at most `k` successors per exit: the lowest expected cost under `prior`.
pub fn keep_best(policy: &Policy, kept: &[Vec<usize>], prior: &[f64], k: usize) -> Vec<Vec<usize>> {
    kept.iter()
        .enumerate()
        .map(|(e, list)| {
            let mut v: Vec<(f64, usize)> = list
                .iter()
                .map(|&c| (policy.cost(e, super::mdp::Action::Enter(c), prior), c))
                .collect();
            v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let mut out: Vec<usize> = v.into_iter().take(k.max(1)).map(|(_, c)| c).collect();
            out.sort_unstable();
            out
        })
        .collect()
}
