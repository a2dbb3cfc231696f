//! The regret of a packed policy: what its pruning, budget cut and quantization cost against
//! the float, unpruned policy. Measured on the policy as the device reads it: the tables of the
//! packed blob (the runtime's [`PolicyTables`]), deciding through the runtime's own
//! [`select_styled`].
//!
//! Regret is measured on simulated belief traces: a hidden state path drawn from the CRF's
//! transition matrix, observed through a noisy channel (the true state gets 60% of the
//! likelihood), filtered into beliefs; the controller walks the library following the
//! quantized, pruned policy, and at every decision the float, unpruned expected cost of its
//! choice is compared with the best float choice. Regret = sum of the excess / sum of the
//! best, as a fraction. Seeded: the same inputs give the same figures.

use gesture_runtime::policy::{select_styled, Choice, Penalties, PolicyTables, Style};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::library::Library;
use super::mdp::{transition_matrix, Action, Policy};
use crate::inference::model::InferenceModel;

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
/// `policy` is the float unpruned policy to compare with (the neutral one, or a tone's), and
/// `style` the weights the packed tables `q` are read with (one-hot on that tone).
pub fn regret(
    lib: &Library,
    policy: &Policy,
    q: &impl PolicyTables,
    style: &Style,
    model: &InferenceModel,
    decisions: usize,
    seed: u64,
) -> RegretReport {
    let s = policy.states;
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
        let dq = select_styled(q, e, &bf, &Penalties::NONE, style);
        let chosen = match dq.choice {
            Choice::Continue => Action::Continue,
            Choice::Enter(c) => Action::Enter(c),
        };
        let best = policy.decide(e, &belief, 0..lib.segments.len());
        let cb = policy.cost(e, best, &belief);
        let cc = policy.cost(e, chosen, &belief);
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
