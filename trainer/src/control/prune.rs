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
//! [`MIN_SUCCESSORS`] successors ([`pad`]): the survivors plus, taking turns, each state's
//! next best and the next best transition. The padding never changes the pure policy's
//! choice (the added candidates are dominated), so it costs no regret, only blob bytes.
//!
//! The padding used to be the next best by expected cost under the state prior. With two
//! states that is a mix of both, and it kept choosing the same middling segments and the rest
//! segments that the rest state's corner keeps anyway: on the 9-joint ZeroEGGS library the
//! long expressive gestures were successors at 1-15 of 196 exits, the five rest segments at
//! 145-196, so in continuous speech the variety costs had few active gestures to turn to and
//! dropped the arms to rest mid-sentence; on 067's library its three fastest gestures were
//! successors at 1-4 of 147 exits and never played. Each state's own best gives every belief
//! options of its kind, and the best transitions spread the rest of the library over the
//! exits it follows well.
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
/// segments): the policy's states and the transition take turns, each adding its next best
/// successor not yet in the list (a state: by the cost in that state alone; the transition:
/// by `S(e, c)` alone, the segments that follow this exit best). Sorted by segment index.
pub fn pad(policy: &Policy, kept: &[Vec<usize>], min: usize) -> Vec<Vec<usize>> {
    kept.iter()
        .enumerate()
        .map(|(e, list)| {
            let mut out = list.clone();
            if out.len() >= min {
                return out;
            }
            // Per state, the other segments from best to worst in that state; and last, from
            // the best transition to the worst.
            let rank = |cost: &dyn Fn(usize) -> f64| -> Vec<usize> {
                let mut v: Vec<(f64, usize)> = (0..policy.u.len())
                    .filter(|c| !list.contains(c))
                    .map(|c| (cost(c), c))
                    .filter(|(v, _)| v.is_finite())
                    .collect();
                v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                v.into_iter().map(|(_, c)| c).collect()
            };
            let mut ranked: Vec<Vec<usize>> = (0..policy.states)
                .map(|s| {
                    let corner: Vec<f64> = (0..policy.states).map(|i| f64::from(i == s)).collect();
                    rank(&|c| policy.cost(e, super::mdp::Action::Enter(c), &corner))
                })
                .collect();
            ranked.push(rank(&|c| policy.succ[e][c]));
            let mut next = vec![0usize; ranked.len()];
            while out.len() < min {
                let mut added = false;
                for s in 0..ranked.len() {
                    if out.len() >= min {
                        break;
                    }
                    while let Some(&c) = ranked[s].get(next[s]) {
                        next[s] += 1;
                        if !out.contains(&c) {
                            out.push(c);
                            added = true;
                            break;
                        }
                    }
                }
                if !added {
                    break;
                }
            }
            out.sort_unstable();
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Two states, one end exit, eight segments: `U[c] = (u0, u1)` and transition costs
    /// `S(0, c)`.
    fn policy(u: &[(f64, f64)], succ: &[f64]) -> Policy {
        Policy {
            states: 2,
            u: u.iter().map(|&(a, b)| vec![a, b]).collect(),
            u_cont: vec![None],
            succ: vec![succ.to_vec()],
            q: vec![vec![0.0, 0.0]],
            discount: 0.9,
            w_enter: vec![1.0; u.len()],
            w_cont: vec![1.0],
            iterations: 0,
            residual: 0.0,
        }
    }

    #[test]
    fn padding_takes_each_states_best_and_the_best_transitions_in_turn() {
        // Segment 0 is best in state 0, segment 1 in state 1: the Pareto front is {0, 1}
        // (2 and 3 are dominated by 1, the rest by 0, transition costs included). In state
        // 0 the next best are 4, 5; in state 1, 2, 3; the cheapest transitions are 7, 6.
        let p = policy(
            &[
                (0.0, 9.0),
                (9.0, 0.0),
                (9.5, 1.0),
                (9.6, 2.0),
                (1.0, 9.8),
                (2.0, 9.9),
                (5.0, 9.5),
                (5.1, 9.6),
            ],
            &[0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.05, 0.01],
        );
        let front = prune(&p);
        assert_eq!(front, vec![vec![0, 1]]);
        // Turns: state 0 adds 4, state 1 adds 2, the transition adds 7.
        assert_eq!(pad(&p, &front, 5), vec![vec![0, 1, 2, 4, 7]]);
        // Next turn: state 0 adds 5, state 1 adds 3, the transition adds 6.
        assert_eq!(pad(&p, &front, 8), vec![vec![0, 1, 2, 3, 4, 5, 6, 7]]);
        // Never more than there are segments, and a long enough list is left alone.
        assert_eq!(pad(&p, &front, 20)[0].len(), 8);
        assert_eq!(pad(&p, &front, 2), front);
        // The added candidates are dominated: the pure choice is the same for any belief.
        let padded = pad(&p, &front, 8);
        for k in 0..=10 {
            let b = [k as f64 / 10.0, 1.0 - k as f64 / 10.0];
            assert_eq!(
                p.decide(0, &b, front[0].iter().copied()),
                p.decide(0, &b, padded[0].iter().copied())
            );
        }
    }
}
