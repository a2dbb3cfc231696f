//! The control MDP and value iteration (docs/method.md "MDP" and "It factorizes; store it that
//! way"; the paper's section 7 and appendix).
//!
//! Decisions happen at exit points. At exit point `e` of segment `a`, in hidden state `s`, the
//! controller either continues `a` (interruption exits only) or enters a segment `c` at its
//! first frame, paying `S(e, c)`. Between decisions the state evolves without observations as
//! `P^n`, `P` the row-normalized CRF transition matrix and `n` the number of steps the played
//! frames span (their duration over the mean step duration). With discount `gamma` per
//! decision:
//!
//! ```text
//! U(c, s)      = w_enter(c) psi_c(s) + gamma * sum_s' P^n(c)(s, s') Q(first_exit(c), s')
//! U_cont(e, s) = w_cont(e) psi_a(s)  + gamma * sum_s' P^m(e)(s, s') Q(next_exit(e), s')
//! Q(e, s)      = min( U_cont(e, s) [interruption exits], min_c S(e, c) + U(c, s) )
//! ```
//!
//! **The fit is paid as the segment plays** (beyond the paper, where entering pays all of
//! `psi_c` and continuing is free): `w_enter(c)` is the share of `c`'s frames up to its first
//! exit, `w_cont(e)` the share from `e` to the next exit, so a segment played whole still pays
//! `psi` once. With the paper's rule, continuing a long segment at an interruption exit cost
//! nothing while leaving it paid a whole new `psi`, so the policy never left long segments: on
//! the 9-joint ZeroEGGS library a 9-second segment played on through every interruption exit
//! and took a third of 50 s of new speech. Paid per interval, continuing costs what the
//! segment's fit to the belief costs for that stretch, and a badly fitting long segment is
//! left at its next interruption. [`MdpParams::fit_as_played`] = `false` gives the paper's rule.
//!
//! The source exit enters the value of a candidate only through `S(e, c)`, so the full
//! `V(c, e, s) = S(e, c) + U(c, s)` never needs to be stored: `U` (segments x states),
//! `U_cont` (exit points x states) and the successor costs suffice. [`unfactorized_q`]
//! computes the recursion without this sharing and the tests check both agree. At run time,
//! with belief `b`, the choice is `argmin_c S(e, c) + b . U(c)` against `b . U_cont(e)`.

use rayon::prelude::*;

use super::library::Library;

/// Settings of the MDP.
#[derive(Clone, Copy, Debug)]
pub struct MdpParams {
    /// Discount per decision.
    pub discount: f64,
    /// Mean duration of one inference step (syllable or pause), seconds.
    pub step_s: f64,
    /// Iteration cap.
    pub max_iter: usize,
    /// Stop when no value changes by more than this.
    pub tol: f64,
    /// Pay a segment's fit `psi` over its exit intervals as it plays (default) instead of all
    /// on entering (the paper; see the module docs).
    pub fit_as_played: bool,
}

impl Default for MdpParams {
    fn default() -> Self {
        Self {
            discount: 0.9,
            step_s: 0.3,
            max_iter: 1000,
            tol: 1e-7,
            fit_as_played: true,
        }
    }
}

/// Row-normalized CRF transition matrix: `P[i][j] ~ exp(trans[i, j])`.
pub fn transition_matrix(trans: &[f64], states: usize) -> Vec<Vec<f64>> {
    (0..states)
        .map(|i| {
            let row = &trans[i * states..(i + 1) * states];
            let m = row.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            let e: Vec<f64> = row.iter().map(|v| (v - m).exp()).collect();
            let z: f64 = e.iter().sum();
            e.iter().map(|v| v / z).collect()
        })
        .collect()
}

/// `P^0 ..= P^max` by repeated multiplication.
pub fn powers(p: &[Vec<f64>], max: usize) -> Vec<Vec<Vec<f64>>> {
    let s = p.len();
    let mut out = vec![(0..s)
        .map(|i| (0..s).map(|j| (i == j) as u8 as f64).collect())
        .collect::<Vec<Vec<f64>>>()];
    for k in 1..=max {
        let prev = &out[k - 1];
        let next = (0..s)
            .map(|i| {
                (0..s)
                    .map(|j| (0..s).map(|m| prev[i][m] * p[m][j]).sum())
                    .collect()
            })
            .collect();
        out.push(next);
    }
    out
}

/// The solved MDP in factorized form.
#[derive(Clone, Debug)]
pub struct Policy {
    /// States.
    pub states: usize,
    /// `U[c][s]`.
    pub u: Vec<Vec<f64>>,
    /// `U_cont[e][s]` (`None` at end exits).
    pub u_cont: Vec<Option<Vec<f64>>>,
    /// `S(e, c)`.
    pub succ: Vec<Vec<f64>>,
    /// `Q[e][s]`.
    pub q: Vec<Vec<f64>>,
    /// Discount per decision the values were computed with.
    pub discount: f64,
    /// Share of each segment's fit paid on entering it (see [`fit_shares`]).
    pub w_enter: Vec<f64>,
    /// Share of its segment's fit paid on continuing at each exit (see [`fit_shares`]).
    pub w_cont: Vec<f64>,
    /// Value-iteration sweeps.
    pub iterations: usize,
    /// Largest change in the last sweep.
    pub residual: f64,
}

/// What the controller does at an exit point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Keep playing the current segment (interruption exits).
    Continue,
    /// Enter segment `c` at its first frame.
    Enter(usize),
}

/// Steps spanned by `frames` frames.
pub fn steps_for(frames: usize, fps: f64, p: &MdpParams) -> usize {
    ((frames as f64 / fps) / p.step_s).round() as usize
}

/// Steps from entering segment `c` to its first exit, and from exit `e` to the next exit.
pub fn step_counts(lib: &Library, p: &MdpParams) -> (Vec<usize>, Vec<Option<usize>>) {
    let enter = (0..lib.segments.len())
        .map(|c| steps_for(lib.exits[lib.first_exit[c]].frame + 1, lib.fps, p))
        .collect();
    let cont = (0..lib.exits.len())
        .map(|e| {
            lib.next_exit(e)
                .map(|n| steps_for(lib.exits[n].frame - lib.exits[e].frame, lib.fps, p))
        })
        .collect();
    (enter, cont)
}

/// The share of a segment's fit paid on entering it (`w_enter`, per segment) and on
/// continuing at each exit (`w_cont`, per exit; 0 at end exits): the share of the segment's
/// frames up to the next exit (see the module docs); 1 and 0 with the paper's rule.
pub fn fit_shares(lib: &Library, p: &MdpParams) -> (Vec<f64>, Vec<f64>) {
    let len = |c: usize| (lib.segments[c].len() as f64).max(1.0);
    let enter = (0..lib.segments.len())
        .map(|c| {
            if p.fit_as_played {
                ((lib.exits[lib.first_exit[c]].frame + 1) as f64 / len(c)).min(1.0)
            } else {
                1.0
            }
        })
        .collect();
    let cont = (0..lib.exits.len())
        .map(|e| match lib.next_exit(e) {
            Some(n) if p.fit_as_played => {
                (lib.exits[n].frame - lib.exits[e].frame) as f64 / len(lib.exits[e].segment)
            }
            _ => 0.0,
        })
        .collect();
    (enter, cont)
}

/// Step counts (see [`step_counts`]), the powers of `p` they need, and the fit shares (see
/// [`fit_shares`]).
struct Propagation {
    enter: Vec<usize>,
    cont: Vec<Option<usize>>,
    pw: Vec<Vec<Vec<f64>>>,
    w_enter: Vec<f64>,
    w_cont: Vec<f64>,
}

fn propagation(lib: &Library, p: &[Vec<f64>], params: &MdpParams) -> Propagation {
    let (w_enter, w_cont) = fit_shares(lib, params);
    let (enter, cont) = step_counts(lib, params);
    let max_n = enter
        .iter()
        .chain(cont.iter().flatten())
        .copied()
        .max()
        .unwrap_or(0);
    let pw = powers(p, max_n);
    Propagation {
        enter,
        cont,
        pw,
        w_enter,
        w_cont,
    }
}

impl Propagation {
    /// `U(c, .)` given the exit values `q`: `w_enter(c) psi_c + gamma P^n(c) q(first_exit(c))`.
    fn enter_value(
        &self,
        lib: &Library,
        psi: &[Vec<f64>],
        gamma: f64,
        q: &[Vec<f64>],
        c: usize,
    ) -> Vec<f64> {
        let fut = propagate(&self.pw[self.enter[c]], &q[lib.first_exit[c]]);
        psi[c]
            .iter()
            .zip(fut)
            .map(|(p, f)| self.w_enter[c] * p + gamma * f)
            .collect()
    }

    /// `U_cont(e, .)` given `q` (`None` at end exits): `w_cont(e) psi_a + gamma P^m(e) q(e + 1)`.
    fn cont_value(
        &self,
        lib: &Library,
        psi: &[Vec<f64>],
        gamma: f64,
        q: &[Vec<f64>],
        e: usize,
    ) -> Option<Vec<f64>> {
        self.cont[e].map(|m| {
            let fut = propagate(&self.pw[m], &q[e + 1]);
            psi[lib.exits[e].segment]
                .iter()
                .zip(fut)
                .map(|(p, f)| self.w_cont[e] * p + gamma * f)
                .collect()
        })
    }
}

/// The largest change between two value tables.
fn max_change(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
        .fold(0.0, f64::max)
}

fn propagate(pn: &[Vec<f64>], q: &[f64]) -> Vec<f64> {
    pn.iter()
        .map(|row| row.iter().zip(q).map(|(a, b)| a * b).sum())
        .collect()
}

/// Value iteration. `psi[c][s]`, `succ[e][c]`, `p` the per-step state transition matrix.
pub fn solve(
    lib: &Library,
    psi: &[Vec<f64>],
    succ: Vec<Vec<f64>>,
    p: &[Vec<f64>],
    params: &MdpParams,
) -> Policy {
    let s = p.len();
    let prop = propagation(lib, p, params);
    let gamma = params.discount;
    let n_seg = lib.segments.len();
    let n_exit = lib.exits.len();
    let mut q = vec![vec![0.0; s]; n_exit];
    let mut u = vec![vec![0.0; s]; n_seg];
    let mut u_cont: Vec<Option<Vec<f64>>> = vec![None; n_exit];
    let mut iterations = 0;
    let mut residual = f64::INFINITY;
    while iterations < params.max_iter && residual > params.tol {
        u = (0..n_seg)
            .into_par_iter()
            .map(|c| prop.enter_value(lib, psi, gamma, &q, c))
            .collect();
        u_cont = (0..n_exit)
            .into_par_iter()
            .map(|e| prop.cont_value(lib, psi, gamma, &q, e))
            .collect();
        let new_q: Vec<Vec<f64>> = (0..n_exit)
            .into_par_iter()
            .map(|e| {
                let mut best: Vec<f64> =
                    u_cont[e].clone().unwrap_or_else(|| vec![f64::INFINITY; s]);
                for (c, uc) in u.iter().enumerate() {
                    let sc = succ[e][c];
                    for k in 0..s {
                        let v = sc + uc[k];
                        if v < best[k] {
                            best[k] = v;
                        }
                    }
                }
                best
            })
            .collect();
        residual = max_change(&new_q, &q);
        q = new_q;
        iterations += 1;
    }
    Policy {
        states: s,
        u,
        u_cont,
        succ,
        q,
        discount: params.discount,
        w_enter: prop.w_enter,
        w_cont: prop.w_cont,
        iterations,
        residual,
    }
}

/// What a waiting semantic label changes in the MDP (docs/method.md "Semantic labels").
pub struct LabelProblem<'a> {
    /// Per segment, whether it carries the label.
    pub carries: &'a [bool],
    /// Cost of a decision that does not serve the label.
    pub semantic_cost: f64,
    /// Per exit point, the semantic entries: `(segment, entry cost)` for each segment carrying
    /// the label (entered before its stroke).
    pub entries: &'a [Vec<(usize, f64)>],
}

/// Value iteration while a label waits: entering a segment that carries it (at its first frame
/// or by a semantic entry) serves the label, and from then on the `neutral` policy's values
/// hold; every other choice costs `semantic_cost` more and the label goes on waiting.
///
/// ```text
/// U^w(c, s)      = U(c, s)                                                  c carries w
///                = w_enter(c) psi_c(s) + gamma sum P^n(c)(s, s') Q^w(first_exit(c), s')  else
/// U_cont^w(e, s) = U_cont(e, s) if e's segment carries w, else as U_cont with Q^w
/// Q^w(e, s)      = min( U_cont^w(e, s) + C [e's segment does not carry w],
///                       min_c S(e, c) + U^w(c, s) + C [c does not carry w],
///                       min_(c, x) in entries(e)  x + U(c, s) )
/// ```
///
/// The returned policy's `u`/`u_cont` are `U^w`/`U_cont^w` (what the blob stores); its `q` is
/// `Q^w`.
pub fn solve_label(
    lib: &Library,
    psi: &[Vec<f64>],
    p: &[Vec<f64>],
    params: &MdpParams,
    neutral: &Policy,
    label: &LabelProblem<'_>,
) -> Policy {
    let s = p.len();
    let prop = propagation(lib, p, params);
    let gamma = params.discount;
    let n_seg = lib.segments.len();
    let n_exit = lib.exits.len();
    let c_sem = label.semantic_cost;
    let mut q = neutral.q.clone();
    let mut u = neutral.u.clone();
    let mut u_cont = neutral.u_cont.clone();
    let mut iterations = 0;
    let mut residual = f64::INFINITY;
    while iterations < params.max_iter && residual > params.tol {
        u = (0..n_seg)
            .into_par_iter()
            .map(|c| match label.carries[c] {
                true => neutral.u[c].clone(),
                false => prop.enter_value(lib, psi, gamma, &q, c),
            })
            .collect();
        u_cont = (0..n_exit)
            .into_par_iter()
            .map(|e| match label.carries[lib.exits[e].segment] {
                true => neutral.u_cont[e].clone(),
                false => prop.cont_value(lib, psi, gamma, &q, e),
            })
            .collect();
        let new_q: Vec<Vec<f64>> = (0..n_exit)
            .into_par_iter()
            .map(|e| {
                let a = lib.exits[e].segment;
                let extra = if label.carries[a] { 0.0 } else { c_sem };
                let mut best: Vec<f64> = match &u_cont[e] {
                    Some(uc) => uc.iter().map(|v| v + extra).collect(),
                    None => vec![f64::INFINITY; s],
                };
                for (c, uc) in u.iter().enumerate() {
                    let sc = neutral.succ[e][c] + if label.carries[c] { 0.0 } else { c_sem };
                    for k in 0..s {
                        best[k] = best[k].min(sc + uc[k]);
                    }
                }
                for &(c, x) in &label.entries[e] {
                    for k in 0..s {
                        best[k] = best[k].min(x + neutral.u[c][k]);
                    }
                }
                best
            })
            .collect();
        residual = max_change(&new_q, &q);
        q = new_q;
        iterations += 1;
    }
    Policy {
        states: s,
        u,
        u_cont,
        succ: neutral.succ.clone(),
        q,
        discount: params.discount,
        w_enter: prop.w_enter,
        w_cont: prop.w_cont,
        iterations,
        residual,
    }
}

impl Policy {
    /// Expected cost of `action` at exit `e` under belief `b`.
    pub fn cost(&self, e: usize, action: Action, b: &[f64]) -> f64 {
        match action {
            Action::Continue => match &self.u_cont[e] {
                Some(uc) => b.iter().zip(uc).map(|(x, y)| x * y).sum(),
                None => f64::INFINITY,
            },
            Action::Enter(c) => {
                self.succ[e][c] + b.iter().zip(&self.u[c]).map(|(x, y)| x * y).sum::<f64>()
            }
        }
    }

    /// The best action at exit `e` under belief `b` among `candidates` (and continuing,
    /// where allowed). Ties go to continuing, then to the lowest segment index.
    pub fn decide(
        &self,
        e: usize,
        b: &[f64],
        candidates: impl IntoIterator<Item = usize>,
    ) -> Action {
        let mut best = (self.cost(e, Action::Continue, b), Action::Continue);
        for c in candidates {
            let v = self.cost(e, Action::Enter(c), b);
            if v < best.0 {
                best = (v, Action::Enter(c));
            }
        }
        best.1
    }
}

/// The same recursion without the factorization: `V(c, e, s)` evaluated in full for every
/// exit, candidate and state (for the tests; `O(E N S)` memory per sweep).
pub fn unfactorized_q(
    lib: &Library,
    psi: &[Vec<f64>],
    succ: &[Vec<f64>],
    p: &[Vec<f64>],
    params: &MdpParams,
    sweeps: usize,
) -> Vec<Vec<f64>> {
    let s = p.len();
    let Propagation {
        enter,
        cont,
        pw,
        w_enter,
        w_cont,
    } = propagation(lib, p, params);
    let mut q = vec![vec![0.0; s]; lib.exits.len()];
    for _ in 0..sweeps {
        let mut v = vec![vec![vec![0.0; s]; lib.segments.len()]; lib.exits.len()];
        for e in 0..lib.exits.len() {
            for c in 0..lib.segments.len() {
                for k in 0..s {
                    let fut: f64 = (0..s)
                        .map(|j| pw[enter[c]][k][j] * q[lib.first_exit[c]][j])
                        .sum();
                    v[e][c][k] = succ[e][c] + w_enter[c] * psi[c][k] + params.discount * fut;
                }
            }
        }
        let mut next = vec![vec![f64::INFINITY; s]; lib.exits.len()];
        for e in 0..lib.exits.len() {
            for k in 0..s {
                if let Some(m) = cont[e] {
                    let fut: f64 = (0..s).map(|j| pw[m][k][j] * q[e + 1][j]).sum();
                    let a = lib.exits[e].segment;
                    next[e][k] = w_cont[e] * psi[a][k] + params.discount * fut;
                }
                for c in 0..lib.segments.len() {
                    next[e][k] = next[e][k].min(v[e][c][k]);
                }
            }
        }
        q = next;
    }
    q
}
