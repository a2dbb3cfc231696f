//! The control layer (docs/method.md "Control layer", the paper's section 7 and appendix): from a
//! belief over hidden states, which gesture segment to show next.
//!
//! - [`library`]: segments, recorded order, exit points, pose features;
//! - [`costs`]: `psi` (segment fit per state) and successor costs;
//! - [`mdp`]: belief propagation between decisions, value iteration, the factorized tables
//!   and the decision rule;
//! - [`prune`]: dropping successors that are never optimal, and budget truncation;
//! - [`dp`]: the offline dynamic-programming reference;
//! - [`build`]: model + library to a solved, pruned policy (the control model);
//! - [`regret`]: what pruning and quantization cost, measured on the packed tables;
//! - [`schedule`]: what random selection and the offline DP reference play, frame by frame;
//! - [`style`]: tone transforms of the kinematic parameters (per-tone value tables);
//! - [`semantic`]: semantic labels, strokes and the entries before them.

// Index loops mirror the recursion's subscripts and are kept on purpose.
#![allow(clippy::needless_range_loop)]

pub mod build;
pub mod costs;
pub mod dp;
pub mod library;
pub mod mdp;
pub mod prune;
pub mod regret;
pub mod schedule;
pub mod semantic;
pub mod style;

pub use library::{ExitPoint, LibSegment, Library};
pub use mdp::{Action, MdpParams, Policy};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::{analyze, EffectorSpec, Normalization, SegmentParams};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn small_library(seconds: f64) -> Library {
        let speaker = crate::synth::speaker_for(5);
        let take = crate::synth::generate_take(5, 0, seconds, &speaker);
        let motion = take.motion();
        let analysis =
            analyze(&motion, &EffectorSpec::default(), &SegmentParams::default()).unwrap();
        let norm = Normalization::fit(&analysis.y_raw).unwrap();
        Library::from_takes(
            vec![library::LibTake {
                source: "synthetic".into(),
                motion,
                analysis,
            }],
            &norm,
            3,
        )
        .unwrap()
    }

    /// `(psi, successor costs, transition matrix)`.
    type Problem = (Vec<Vec<f64>>, Vec<Vec<f64>>, Vec<Vec<f64>>);

    fn random_problem(lib: &Library, s: usize, seed: u64) -> Problem {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let psi: Vec<Vec<f64>> = (0..lib.segments.len())
            .map(|_| (0..s).map(|_| rng.random_range(0.5..3.0)).collect())
            .collect();
        let sig = costs::Signatures::new(lib);
        let succ = costs::successor_costs(lib, &sig, &costs::CostParams::default());
        let p: Vec<Vec<f64>> = (0..s)
            .map(|i| {
                let mut row: Vec<f64> = (0..s)
                    .map(|j| {
                        if i == j {
                            5.0
                        } else {
                            rng.random_range(0.1..1.0)
                        }
                    })
                    .collect();
                let z: f64 = row.iter().sum();
                row.iter_mut().for_each(|v| *v /= z);
                row
            })
            .collect();
        (psi, succ, p)
    }

    #[test]
    fn factorized_tables_equal_the_unfactorized_recursion() {
        let lib = small_library(20.0);
        assert!(lib.segments.len() >= 5, "{} segments", lib.segments.len());
        let (psi, succ, p) = random_problem(&lib, 3, 1);
        for (sweeps, fit_as_played) in [1usize, 2, 5, 12]
            .into_iter()
            .flat_map(|n| [(n, true), (n, false)])
        {
            let params = MdpParams {
                max_iter: sweeps,
                tol: 0.0,
                fit_as_played,
                ..MdpParams::default()
            };
            let fact = mdp::solve(&lib, &psi, succ.clone(), &p, &params);
            let full = mdp::unfactorized_q(&lib, &psi, &succ, &p, &params, sweeps);
            for (a, b) in fact.q.iter().zip(&full) {
                for (x, y) in a.iter().zip(b) {
                    assert!(
                        (x - y).abs() < 1e-9 * (1.0 + y.abs()),
                        "{sweeps} sweeps: {x} vs {y}"
                    );
                }
            }
        }
    }

    /// A segment played whole pays its fit once, however it is split by exit points; the
    /// paper's rule pays it all on entering.
    #[test]
    fn fit_shares_of_a_segment_sum_to_one() {
        let lib = small_library(20.0);
        let (w_enter, w_cont) = mdp::fit_shares(&lib, &MdpParams::default());
        for c in 0..lib.segments.len() {
            let f = lib.first_exit[c];
            let sum: f64 = w_enter[c]
                + (f..lib.exits.len())
                    .take_while(|&e| lib.exits[e].segment == c)
                    .map(|e| w_cont[e])
                    .sum::<f64>();
            assert!((sum - 1.0).abs() < 1e-12, "segment {c}: {sum}");
            assert!(w_enter[c] > 0.0 && w_enter[c] <= 1.0);
        }
        let paper = MdpParams {
            fit_as_played: false,
            ..MdpParams::default()
        };
        let (w_enter, w_cont) = mdp::fit_shares(&lib, &paper);
        assert!(w_enter.iter().all(|&w| w == 1.0) && w_cont.iter().all(|&w| w == 0.0));
    }

    /// One state; the longest segment fits badly (psi 10), every other well (0.5). Under the
    /// paper's rule its fit is paid on entering, so at its first interruption exit continuing
    /// is free and wins; paid as it plays, continuing costs a share of 10 and it is left.
    #[test]
    fn a_badly_fitting_long_segment_is_left_at_an_interruption() {
        let lib = small_library(30.0);
        let long = (0..lib.segments.len())
            .max_by_key(|&c| lib.segments[c].len())
            .unwrap();
        let e = lib.first_exit[long];
        assert!(
            !lib.exits[e].end,
            "the longest segment has interruption exits"
        );
        let psi: Vec<Vec<f64>> = (0..lib.segments.len())
            .map(|c| vec![if c == long { 10.0 } else { 0.5 }])
            .collect();
        let sig = costs::Signatures::new(&lib);
        let succ = costs::successor_costs(&lib, &sig, &costs::CostParams::default());
        let p = vec![vec![1.0]];
        let all = 0..lib.segments.len();
        let paper = MdpParams {
            fit_as_played: false,
            ..MdpParams::default()
        };
        let pol = mdp::solve(&lib, &psi, succ.clone(), &p, &paper);
        assert_eq!(pol.decide(e, &[1.0], all.clone()), mdp::Action::Continue);
        let pol = mdp::solve(&lib, &psi, succ, &p, &MdpParams::default());
        assert!(matches!(
            pol.decide(e, &[1.0], all),
            mdp::Action::Enter(c) if c != long
        ));
    }

    #[test]
    fn value_iteration_converges_and_recorded_order_is_cheap() {
        let lib = small_library(30.0);
        let (psi, succ, p) = random_problem(&lib, 4, 2);
        let pol = mdp::solve(&lib, &psi, succ, &p, &MdpParams::default());
        assert!(pol.residual <= 1e-7, "residual {}", pol.residual);
        // Leaving a segment at its end for its recorded successor costs nothing.
        for (e, ex) in lib.exits.iter().enumerate() {
            if ex.end {
                if let Some(n) = lib.segments[ex.segment].next {
                    if lib.segments[n].prev.is_some() {
                        assert_eq!(pol.succ[e][n], 0.0);
                    }
                }
            }
        }
    }

    #[test]
    fn pruning_never_changes_a_decision() {
        let lib = small_library(40.0);
        let (psi, succ, p) = random_problem(&lib, 5, 3);
        let pol = mdp::solve(&lib, &psi, succ, &p, &MdpParams::default());
        let kept = prune::prune(&pol);
        let total: usize = lib.exits.len() * lib.segments.len();
        let left: usize = kept.iter().map(Vec::len).sum();
        assert!(left < total);
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        for _ in 0..2000 {
            let e = rng.random_range(0..lib.exits.len());
            let mut b: Vec<f64> = (0..5).map(|_| rng.random::<f64>().powi(3)).collect();
            let z: f64 = b.iter().sum();
            b.iter_mut().for_each(|v| *v /= z);
            let full = pol.decide(e, &b, 0..lib.segments.len());
            let pruned = pol.decide(e, &b, kept[e].iter().copied());
            assert_eq!(pol.cost(e, full, &b), pol.cost(e, pruned, &b), "exit {e}");
        }
    }

    /// A label that costs nothing to wait for and has no segment is the neutral problem: the
    /// same values.
    #[test]
    fn a_free_label_without_segments_is_the_neutral_policy() {
        let lib = small_library(20.0);
        let (psi, succ, p) = random_problem(&lib, 3, 6);
        let params = MdpParams::default();
        let pol = mdp::solve(&lib, &psi, succ, &p, &params);
        let carries = vec![false; lib.segments.len()];
        let entries = vec![Vec::new(); lib.exits.len()];
        let label = mdp::LabelProblem {
            carries: &carries,
            semantic_cost: 0.0,
            entries: &entries,
        };
        let lp = mdp::solve_label(&lib, &psi, &p, &params, &pol, &label);
        for (a, b) in lp.q.iter().zip(&pol.q) {
            for (x, y) in a.iter().zip(b) {
                assert!((x - y).abs() < 1e-6 * (1.0 + y.abs()), "{x} vs {y}");
            }
        }
    }

    /// Waiting is very dear and entering segment `x` at no cost serves the label from any exit
    /// point: outside `x`, the value of every exit is then exactly `x`'s neutral `U`.
    #[test]
    fn a_dear_label_is_served_at_once_through_its_entry() {
        let lib = small_library(20.0);
        let (psi, succ, p) = random_problem(&lib, 3, 7);
        let params = MdpParams::default();
        let pol = mdp::solve(&lib, &psi, succ, &p, &params);
        let x = lib.segments.len() / 2;
        let carries: Vec<bool> = (0..lib.segments.len()).map(|c| c == x).collect();
        let entries = vec![vec![(x, 0.0)]; lib.exits.len()];
        let label = mdp::LabelProblem {
            carries: &carries,
            semantic_cost: 1e6,
            entries: &entries,
        };
        let lp = mdp::solve_label(&lib, &psi, &p, &params, &pol, &label);
        for (e, ex) in lib.exits.iter().enumerate() {
            if ex.segment == x {
                continue;
            }
            for k in 0..3 {
                let want = pol.u[x][k].min(pol.succ[e][x] + pol.u[x][k]);
                assert!(
                    (lp.q[e][k] - want).abs() < 1e-9,
                    "exit {e}: {} vs {want}",
                    lp.q[e][k]
                );
            }
        }
        // The stored table keeps the neutral U for the segment that carries the label.
        assert_eq!(lp.u[x], pol.u[x]);
    }

    #[test]
    fn offline_dp_is_no_worse_than_following_the_policy() {
        let lib = small_library(20.0);
        let (psi, succ, p) = random_problem(&lib, 3, 5);
        let pol = mdp::solve(&lib, &psi, succ, &p, &MdpParams::default());
        let post = |t: usize| {
            let k = (t / 60) % 3;
            (0..3)
                .map(|i| if i == k { 0.8 } else { 0.1 })
                .collect::<Vec<f64>>()
        };
        let frames = 300;
        let start = lib.exits.len() - 1;
        let (dp_cost, plan) = dp::best_sequence(&lib, &pol, &psi, frames, start, 0, &post);
        assert!(!plan.is_empty());
        // Greedy online play with the same beliefs, same cost accounting.
        let (mut t, mut e, mut greedy) = (0usize, start, 0.0);
        while t <= frames {
            let b = post(t.min(frames - 1));
            match pol.decide(e, &b, 0..lib.segments.len()) {
                Action::Continue => {
                    let n = lib.next_exit(e).unwrap();
                    let a = lib.exits[e].segment;
                    greedy +=
                        pol.w_cont[e] * b.iter().zip(&psi[a]).map(|(x, y)| x * y).sum::<f64>();
                    t += (lib.exits[n].frame - lib.exits[e].frame).max(1);
                    e = n;
                }
                Action::Enter(c) => {
                    greedy += pol.w_enter[c]
                        * b.iter().zip(&psi[c]).map(|(x, y)| x * y).sum::<f64>()
                        + pol.succ[e][c];
                    t += lib.exits[lib.first_exit[c]].frame + 1;
                    e = lib.first_exit[c];
                }
            }
        }
        assert!(dp_cost <= greedy + 1e-9, "dp {dp_cost} > online {greedy}");
    }
}
